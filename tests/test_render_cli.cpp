// The `render` executable end to end: every flag through the built
// binary, checked by exit code, message and output image; determinism across
// threads, tiles and frame ranges; every kind of bad input; the static
// link. Also the option parser directly (apps/render_options.h).

// GCC 12 reports -Wmaybe-uninitialized inside libstdc++'s <regex> (its
// std::function moves) when this file is built at -O1 for the sanitizers: a
// false positive in the library's code, not in ours.
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#endif

#include <doctest/doctest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <regex>
#include <string>
#include <vector>

#include <unistd.h>

#include "apps/render_options.h"
#include "scene/write_image.h"
#include "shading/isa.h"
#include "tests/cli_util.h"

using namespace prast;
using namespace prast::cli_test;

namespace {

// Parses a command line given as one string (split on spaces).
std::string parse(const std::string& line, RenderOptions& out, std::uint64_t budget = std::uint64_t(8) << 30) {
    std::vector<std::string> words = {"render"};
    std::size_t begin = 0;
    while (begin < line.size()) {
        std::size_t end = line.find(' ', begin);
        if (end == std::string::npos) end = line.size();
        if (end > begin) words.push_back(line.substr(begin, end - begin));
        begin = end + 1;
    }
    std::vector<const char*> argv;
    for (const std::string& w : words) argv.push_back(w.c_str());
    return parse_render_args(int(argv.size()), argv.data(), out, budget);
}

std::string parse(const std::string& line) {
    RenderOptions o;
    return parse(line, o);
}

} // namespace

TEST_SUITE("cli") {

// ---------------------------------------------------------------- parsing

TEST_CASE("parser: the documented defaults") {
    RenderOptions o;
    REQUIRE(parse("", o) == "");
    CHECK(o.scene.empty());
    CHECK(o.output == "render.png");
    CHECK(o.width == 1280);
    CHECK(o.height == 720);
    CHECK(o.fov_deg == 45.0f);
    CHECK(!o.eye);
    CHECK(!o.near_plane);
    CHECK(o.ambient == glm::vec3(0.03f));
    CHECK(o.lights.empty());
    CHECK(o.brdf == BrdfModel::Default);
    CHECK(o.exposure == 1.0f);
    CHECK(o.effective_tonemap() == ToneMap::Aces);
    CHECK(o.view == DebugView::None);
    CHECK(o.threads == 0);
    CHECK(o.tile_size == 64);
    CHECK(o.frames == 1);
    CHECK(o.first_frame == 0);
    CHECK(o.last_frame == 0);
    CHECK(o.repeat == 1);
}

TEST_CASE("parser: every flag reaches the options") {
    RenderOptions o;
    REQUIRE(parse("scene.glb -o out%03d.hdr --size 96x64 --eye 1,2,3 --target=0,1,0 --up 0,0,1 --fov 30 "
                  "--near 0.5 --far 50 --sun 0,2,0:1,2,3 --point 1,1,1:4,4,4 --ambient 0.1,0.2,0.3 "
                  "--no-default-lights --brdf gltf --exposure 2.5 --tonemap neutral --view normal "
                  "--threads 3 --tile 16 --frames 8 --orbit -90 --frame-range 2-5 --repeat 4 --stats --pixel 5,6 "
                  "--allow-outside-paths",
                  o) == "");
    CHECK(o.scene == "scene.glb");
    CHECK(o.allow_outside_paths);
    CHECK(o.output == "out%03d.hdr");
    CHECK(o.hdr_output());
    CHECK(o.width == 96);
    CHECK(o.height == 64);
    CHECK(*o.eye == glm::vec3(1, 2, 3));
    CHECK(*o.target == glm::vec3(0, 1, 0));
    CHECK(*o.up == glm::vec3(0, 0, 1));
    CHECK(o.fov_deg == 30.0f);
    CHECK(*o.near_plane == 0.5f);
    CHECK(*o.far_plane == 50.0f);
    REQUIRE(o.lights.size() == 2);
    CHECK(!o.lights[0].point);
    CHECK(o.lights[0].direction == glm::vec3(0, 1, 0));  // normalised
    CHECK(o.lights[0].radiance == glm::vec3(1, 2, 3));
    CHECK(o.lights[1].point);
    CHECK(o.lights[1].position == glm::vec3(1, 1, 1));
    CHECK(o.ambient == glm::vec3(0.1f, 0.2f, 0.3f));
    CHECK(o.no_default_lights);
    CHECK(o.brdf == BrdfModel::Gltf);
    CHECK(o.exposure == 2.5f);
    CHECK(o.effective_tonemap() == ToneMap::Neutral);
    CHECK(o.view == DebugView::Normal);
    CHECK(o.threads == 3);
    CHECK(o.tile_size == 16);
    CHECK(o.frames == 8);
    CHECK(o.orbit_deg == -90.0);
    CHECK(o.first_frame == 2);
    CHECK(o.last_frame == 5);
    CHECK(o.repeat == 4);
    CHECK(o.repeat_given);
    CHECK(o.stats);
    CHECK(*o.pixel == glm::ivec2(5, 6));
}

TEST_CASE("parser: a debug view turns the tone map off unless one is given") {
    RenderOptions o;
    REQUIRE(parse("--view depth", o) == "");
    CHECK(o.effective_tonemap() == ToneMap::None);
    RenderOptions p;
    REQUIRE(parse("--view depth --tonemap aces", p) == "");
    CHECK(p.effective_tonemap() == ToneMap::Aces);
}

TEST_CASE("parser: errors name the flag and the bad value") {
    struct Case { const char* line; const char* expect; };
    const Case cases[] = {
        {"--bogus", "unknown option '--bogus'"},
        {"--size", "--size: missing value"},
        {"--size 0x0", "--size 0x0"},
        {"--size -5x10", "--size -5x10"},
        {"--size 96", "--size '96'"},
        {"--size 100000x100000", "240000000000 bytes"},
        {"--fov nan", "--fov 'nan': not a finite number"},
        {"--fov inf", "--fov 'inf'"},
        {"--fov -5", "--fov '-5'"},
        {"--fov 180", "--fov '180'"},
        {"--fov 0.0001", "--fov '0.0001': must be at least 0.001"},
        {"--eye 0,0,2e18", "--eye '0,0,2e18': coordinates beyond +-1e18"},
        {"--target -1e19,0,0", "--target '-1e19,0,0': coordinates beyond +-1e18"},
        {"--allow-outside-paths=yes", "--allow-outside-paths: takes no value"},
        {"--near -1", "--near '-1'"},
        {"--near 5 --far 1", "--near/--far"},
        {"--exposure -1", "--exposure '-1'"},
        {"--exposure 1e999", "--exposure '1e999'"},
        {"--ambient nan,0,0", "--ambient 'nan,0,0'"},
        {"--ambient -1,0,0", "--ambient '-1,0,0'"},
        {"--ambient 1,2", "--ambient '1,2'"},
        {"--sun 0,0,0:1,1,1", "the direction must not be zero"},
        {"--sun 0,1,0:-1,1,1", "must not be negative"},
        {"--sun 0,1,0", "--sun '0,1,0'"},
        {"--point nan,0,0:1,1,1", "--point 'nan,0,0:1,1,1'"},
        {"--up 0,0,0", "--up '0,0,0'"},
        {"--eye 1,2,x", "--eye '1,2,x'"},
        {"--threads 0", "--threads '0'"},
        {"--threads -2", "--threads '-2'"},
        {"--threads abc", "--threads 'abc': not an integer"},
        {"--tile 48", "--tile '48'"},
        {"--tile 512", "--tile '512'"},
        {"--frames 0", "--frames '0'"},
        {"--frames 4", "frame number in the file name"},
        {"--frames 4 -o a%04d.png --frame-range 3-1", "--frame-range '3-1'"},
        {"--frames 4 -o a%04d.png --frame-range 0-9", "--frame-range '0-9'"},
        {"--frame-range x", "--frame-range 'x'"},
        {"--orbit 90", "--orbit: needs --frames"},
        {"--frames 2 -o a%04d.png --orbit nan", "--orbit 'nan'"},
        {"--repeat 0", "--repeat '0'"},
        {"--brdf phong", "--brdf 'phong'"},
        {"--tonemap reinhard", "--tonemap 'reinhard'"},
        {"--view bogus", "--view 'bogus'"},
        {"-o out.jpg", "-o 'out.jpg': unknown output format"},
        {"-o out%s.png", "-o 'out%s.png'"},
        {"--size 96x64 --pixel 96,0", "--pixel '96,0': outside the 96x64 image"},
        {"a.obj b.obj", "unexpected argument 'b.obj'"},
        {"--stats=yes", "--stats: takes no value"},
        {"--env sky.png", "--env 'sky.png': expected an equirectangular Radiance .hdr file"},
    };
    for (const Case& c : cases) {
        CAPTURE(c.line);
        const std::string err = parse(c.line);
        CHECK(err.find(c.expect) != std::string::npos);
        CHECK(err.find('\n') == std::string::npos);
    }
}

TEST_CASE("parser: --size refuses what does not fit the memory budget, with the bytes") {
    CHECK(check_image_size(96, 64, 1000000) == "");
    const std::string err = check_image_size(10000, 10000, std::uint64_t(1) << 30);
    CHECK(err.find("2400000000 bytes") != std::string::npos);
    CHECK(err.find("half the physical memory") != std::string::npos);
    CHECK(check_image_size(16385, 1, ~std::uint64_t(0)).find("16384 pixels per side") != std::string::npos);
    CHECK(check_image_size(0, 0, 100).find("at least 1") != std::string::npos);
}

TEST_CASE("parser: frame-number patterns") {
    cli::FramePattern p("out/f%04d.png");
    CHECK(p.has_number);
    CHECK(p.format(7) == "out/f0007.png");
    CHECK(p.format(12345) == "out/f12345.png");
    CHECK(cli::FramePattern("f%d.png").format(42) == "f42.png");
    CHECK(cli::FramePattern("f%3d.png").format(5) == "f  5.png");
    CHECK(cli::FramePattern("100%%_%02d.png").format(3) == "100%_03.png");
    cli::FramePattern plain("render.png");
    CHECK(!plain.has_number);
    CHECK(plain.format(3) == "render.png");
    CHECK(!cli::FramePattern("a%d%d.png").error.empty());
    CHECK(!cli::FramePattern("a%n.png").error.empty());
}

// ---------------------------------------------------------------- end to end

#ifdef PRAST_RENDER_EXE

namespace {

CliRun render(const CliSandbox& box, const std::vector<std::string>& args) {
    return box.run_exe(PRAST_RENDER_EXE, args);
}

// A unit quad in z = 0 facing +Z (counter-clockwise seen from +Z), no lights,
// the default material.
const char* const kQuadObj =
    "v -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\n"
    "vn 0 0 1\n"
    "f 1//1 2//1 3//1 4//1\n";

// Small renders stay fast: the whole suite runs in seconds.
const std::vector<std::string> kSmall = {"--size", "96x64"};

std::vector<std::string> with(std::vector<std::string> a, const std::vector<std::string>& b) {
    a.insert(a.end(), b.begin(), b.end());
    return a;
}

// A usage or file error: the exit code, one line "render: ...", the expected
// words in it, and nothing written.
void check_error(const CliSandbox& box, const CliRun& r, int code, const std::string& expect) {
    CHECK(r.code == code);
    CHECK(lines_of(r.err).size() == 1);
    CHECK(r.err.rfind("render: ", 0) == 0);
    CHECK(r.err.find(expect) != std::string::npos);
    CHECK(r.out.empty());
    CHECK(box.work_files().empty());
}

constexpr const char* kDefaultRigLine =
    "render: no lights in the scene or flags: using the default key+fill rig (--no-default-lights to disable)";

} // namespace

TEST_CASE("--help fits a 80x24 screen and --version prints the version") {
    CliSandbox box;
    CliRun help = render(box, {"--help"});
    CHECK(help.code == 0);
    CHECK(help.err.empty());
    const std::vector<std::string> lines = lines_of(help.out);
    CHECK(lines.size() <= 23);  // and the shell prompt after it
    for (const std::string& l : lines) {
        CAPTURE(l);
        CHECK(l.size() < 80);
    }
    for (const char* flag : {"--output", "--size", "--eye", "--fov", "--near", "--sun", "--point", "--ambient",
                             "--no-default-lights", "--env", "--brdf", "--exposure", "--tonemap", "--view",
                             "--threads", "--tile", "--frames", "--orbit", "--frame-range", "--repeat", "--stats",
                             "--pixel", "--allow-outside-paths", "--version"})
        CHECK(help.out.find(flag) != std::string::npos);
    for (const char* flag : {"--env-intensity", "--env-rotate", "--background", "--ibl", "--samples", "--energy"})
        CHECK(help.out.find(flag) != std::string::npos);
    CliRun h = render(box, {"-h"});
    CHECK(h.code == 0);
    CHECK(h.out == help.out);

    CliRun version = render(box, {"--version"});
    CHECK(version.code == 0);
    CHECK(version.out == std::string("render (prast) ") + kRenderVersion + "\n");
    CHECK(box.work_files().empty());
}

TEST_CASE("without arguments the default scene renders to render.png") {
    CliSandbox box;
    CliRun r = render(box, kSmall);
    CHECK(r.code == 0);
    CHECK(r.err.empty());  // the default scene has its own lights: no rig message
    CHECK(r.out.empty());
    CHECK(box.work_files() == std::vector<std::string>{"render.png"});
    Rgb8 img = load_rgb8(box.path("render.png"));
    REQUIRE(!img.empty());
    CHECK(img.width == 96);
    CHECK(img.height == 64);
    CHECK(img.mean() > 20.0);
    // The top-left corner is above the spheres and the floor: the built-in
    // scene's sky, blue.
    CHECK(img.at(0, 0)[2] > img.at(0, 0)[0]);
    CHECK(img.at(0, 0)[2] > 40);
}

TEST_CASE("the same frame is byte-identical for any --threads and --tile") {
    CliSandbox box;
    const std::vector<std::string> runs[] = {
        {"--threads", "1", "-o", "t1.png"}, {"--threads", "2", "-o", "t2.png"}, {"--threads", "3", "-o", "t3.png"},
        {"--tile", "16", "-o", "tile16.png"}, {"--tile", "256", "--threads", "3", "-o", "tile256.png"},
    };
    for (const auto& args : runs) REQUIRE(render(box, with(kSmall, args)).code == 0);
    const std::vector<std::uint8_t> ref = read_bytes(box.path("t1.png"));
    REQUIRE(!ref.empty());
    for (const char* name : {"t2.png", "t3.png", "tile16.png", "tile256.png"}) {
        CAPTURE(name);
        CHECK(read_bytes(box.path(name)) == ref);
    }
}

TEST_CASE("--msaa: the default is 4 samples; every count is byte-identical for any --threads and --tile") {
    RenderOptions o;
    REQUIRE(parse("", o) == "");
    CHECK(o.msaa == 4);
    for (const char* bad : {"--msaa 3", "--msaa 16", "--msaa 0", "--msaa x"}) {
        CAPTURE(bad);
        const std::string err = parse(bad);
        CHECK(err.find("must be 1, 2, 4 or 8") != std::string::npos);
    }
    CliSandbox box;
    REQUIRE(render(box, with(kSmall, {"-o", "default.png"})).code == 0);
    std::vector<std::uint8_t> previous;
    for (const char* n : {"1", "2", "4", "8"}) {
        CAPTURE(n);
        const std::string a = std::string("a") + n + ".png", b = std::string("b") + n + ".png";
        REQUIRE(render(box, with(kSmall, {"--msaa", n, "--threads", "1", "-o", a})).code == 0);
        REQUIRE(render(box, with(kSmall, {"--msaa", n, "--threads", "3", "--tile", "16", "-o", b})).code == 0);
        const std::vector<std::uint8_t> bytes = read_bytes(box.path(a));
        REQUIRE(!bytes.empty());
        CHECK(read_bytes(box.path(b)) == bytes);
        if (std::string(n) == "4") CHECK(read_bytes(box.path("default.png")) == bytes);
        CHECK(bytes != previous);  // the edges change with the sample count
        previous = bytes;
    }
}

TEST_CASE("a turntable split in two --frame-range runs equals a single run") {
    CliSandbox box;
    fs::create_directories(box.work() / "one");
    fs::create_directories(box.work() / "split");
    const std::vector<std::string> turn = {"--frames", "4", "--orbit", "90"};
    REQUIRE(render(box, with(with(kSmall, turn), {"-o", "one/f%04d.png"})).code == 0);
    REQUIRE(render(box, with(with(kSmall, turn), {"-o", "split/f%04d.png", "--frame-range", "0-1"})).code == 0);
    REQUIRE(render(box, with(with(kSmall, turn), {"-o", "split/f%04d.png", "--frame-range", "2-3",
                                                  "--threads", "1"})).code == 0);
    std::vector<std::vector<std::uint8_t>> frames;
    for (const char* name : {"f0000.png", "f0001.png", "f0002.png", "f0003.png"}) {
        CAPTURE(name);
        frames.push_back(read_bytes(box.work() / "one" / name));
        REQUIRE(!frames.back().empty());
        CHECK(read_bytes(box.work() / "split" / name) == frames.back());
    }
    CHECK(!fs::exists(box.work() / "one" / "f0004.png"));
    // The camera moves: every frame differs from the next.
    for (std::size_t i = 0; i + 1 < frames.size(); ++i) CHECK(frames[i] != frames[i + 1]);
    // Frame 0 is the plain render.
    REQUIRE(render(box, with(kSmall, {"-o", "still.png"})).code == 0);
    CHECK(read_bytes(box.path("still.png")) == frames[0]);
    // A full turn of 4 frames: frame i at i * 360 / 4, so 2 frames of 180 give frame 2 as frame 1.
    REQUIRE(render(box, with(kSmall, {"--frames", "4", "-o", "full%d.png", "--frame-range", "2-2"})).code == 0);
    REQUIRE(render(box, with(kSmall, {"--frames", "2", "--orbit", "360", "-o", "half%d.png",
                                      "--frame-range", "1-1"})).code == 0);
    CHECK(read_bytes(box.path("full2.png")) == read_bytes(box.path("half1.png")));
}

TEST_CASE("--repeat prints frame_ms min/median/max and --stats the counters") {
    CliSandbox box;
    CliRun r = render(box, with(kSmall, {"--repeat", "3"}));
    CHECK(r.code == 0);
    CHECK(std::regex_match(r.out, std::regex("frame_ms min=[0-9.]+ median=[0-9.]+ max=[0-9.]+\n")));

    CliRun s = render(box, with(kSmall, {"--stats"}));
    CHECK(s.code == 0);
    for (const char* key : {"scene ", "triangles in", "culled (back face)", "bin entries", "fragments covered",
                            "time vertex", "time setup+bin", "time raster+shade", "time frame", "time load"})
        CHECK(s.out.find(key) != std::string::npos);
    CHECK(s.out.find("frame_ms") == std::string::npos);
    // The lane code that ran: the build's, or AVX-512's copy where the CPU
    // has it, which PRAST_AVX512=0 turns off (and its fetch's VBMI copy,
    // which PRAST_VBMI=0 turns off).
    const std::string lanes = std::string("lanes                  ") + lane_isa() + "\n";
    CHECK(s.out.find(lanes) != std::string::npos);
#ifndef PRAST_SIMD16
    if (std::string(lane_isa()).rfind("avx512", 0) == 0) {
        CliRun off = box.run_exe(PRAST_RENDER_EXE, with(kSmall, {"--stats"}), "export PRAST_AVX512=0");
        CHECK(off.out.find("lanes                  avx2\n") != std::string::npos);
    }
    if (std::string(lane_isa()) == "avx512-vbmi") {
        CliRun off = box.run_exe(PRAST_RENDER_EXE, with(kSmall, {"--stats"}), "export PRAST_VBMI=0");
        CHECK(off.out.find("lanes                  avx512\n") != std::string::npos);
    }
#endif
    // The repeated and the single render wrote the same image.
    CHECK(s.err.empty());
}

TEST_CASE("-o .hdr writes linear radiance") {
    CliSandbox box;
    REQUIRE(render(box, with(kSmall, {"-o", "out.hdr"})).code == 0);
    CHECK(read_text(box.path("out.hdr")).rfind("#?RADIANCE", 0) == 0);
    RgbFloat hdr = load_hdr(box.path("out.hdr"));
    REQUIRE(hdr.width == 96);
    REQUIRE(hdr.height == 64);
    float most = 0.0f;
    for (float v : hdr.rgb) {
        REQUIRE(std::isfinite(v));
        most = std::max(most, v);
    }
    // Specular highlights of the default scene exceed display white: not tone mapped.
    CHECK(most > 1.0f);
    // --exposure and --tonemap only concern the 8-bit image.
    REQUIRE(render(box, with(kSmall, {"-o", "out2.hdr", "--exposure", "4", "--tonemap", "none"})).code == 0);
    CHECK(read_bytes(box.path("out2.hdr")) == read_bytes(box.path("out.hdr")));
}

TEST_CASE("lights: the default rig only when neither the scene nor the flags give one") {
    CliSandbox box;
    write_text(box.path("quad.obj"), kQuadObj);
    auto run = [&](const std::vector<std::string>& args) {
        return render(box, with(with({"quad.obj"}, kSmall), args));
    };

    CliRun rig = run({"-o", "rig.png"});
    CHECK(rig.code == 0);
    CHECK(rig.err == std::string(kDefaultRigLine) + "\n");
    Rgb8 rig_img = load_rgb8(box.path("rig.png"));
    CHECK(rig_img.mean() > 30.0);

    CliRun sun = run({"-o", "sun.png", "--sun", "0,0,1:1,1,1"});
    CHECK(sun.code == 0);
    CHECK(sun.err.empty());
    // The sun's direction is normalised: its length does not matter.
    REQUIRE(run({"-o", "sun5.png", "--sun", "0,0,5:1,1,1"}).code == 0);
    CHECK(read_bytes(box.path("sun5.png")) == read_bytes(box.path("sun.png")));
    CHECK(read_bytes(box.path("sun.png")) != read_bytes(box.path("rig.png")));
    // A sun from behind the quad leaves only the ambient term.
    REQUIRE(run({"-o", "back.png", "--sun", "0,0,-1:1,1,1"}).code == 0);
    CHECK(load_rgb8(box.path("back.png")).mean() < load_rgb8(box.path("sun.png")).mean() / 2);

    CliRun none = run({"-o", "none.png", "--no-default-lights"});
    CHECK(none.code == 0);
    CHECK(none.err.empty());
    Rgb8 ambient_only = load_rgb8(box.path("none.png"));
    CHECK(ambient_only.mean() > 0.0);
    CHECK(ambient_only.mean() < rig_img.mean() / 2);
    REQUIRE(run({"-o", "black.png", "--no-default-lights", "--ambient", "0,0,0"}).code == 0);
    CHECK(load_rgb8(box.path("black.png")).mean() == 0.0);
    REQUIRE(run({"-o", "ambient.png", "--no-default-lights", "--ambient", "0.5,0.5,0.5"}).code == 0);
    CHECK(load_rgb8(box.path("ambient.png")).mean() > ambient_only.mean());
    // Only the red channel of a red ambient light.
    REQUIRE(run({"-o", "red.png", "--no-default-lights", "--ambient", "0.5,0,0"}).code == 0);
    Rgb8 red = load_rgb8(box.path("red.png"));
    CHECK(red.at(48, 32)[0] > 50);
    CHECK(red.at(48, 32)[1] == 0);

    // A point light close to the centre: the centre is brighter than a corner of the quad.
    CliRun point = run({"-o", "point.png", "--point", "0,0,0.5:1,1,1", "--ambient", "0,0,0", "--eye", "0,0,3",
                        "--target", "0,0,0", "--fov", "30"});
    CHECK(point.code == 0);
    CHECK(point.err.empty());
    Rgb8 p = load_rgb8(box.path("point.png"));
    CHECK(p.at(48, 32)[0] > p.at(30, 16)[0] + 20);
}

TEST_CASE("camera flags: --eye --target --up --fov --near --far") {
    CliSandbox box;
    write_text(box.path("quad.obj"), kQuadObj);
    auto run = [&](const std::string& out, const std::vector<std::string>& args) {
        CliRun r = render(box, with(with({"quad.obj", "--sun", "0,0,1:1,1,1", "-o", out}, kSmall), args));
        CHECK(r.code == 0);
        CHECK(r.err.empty());
        return load_rgb8(box.path(out));
    };
    const std::vector<std::string> front = {"--eye", "0,0,3", "--target", "0,0,0"};
    Rgb8 framed = run("framed.png", {});
    Rgb8 seen = run("front.png", front);
    CHECK(seen.mean() > 30.0);
    CHECK(seen.rgb != framed.rgb);
    // From behind, the single-sided quad is culled.
    CHECK(run("behind.png", {"--eye", "0,0,-3", "--target", "0,0,0"}).mean() == 0.0);
    // Only --target: the eye comes from the framing, so the quad leaves the frame's centre.
    Rgb8 aside = run("aside.png", {"--target", "5,0,0"});
    CHECK(aside.at(48, 32)[0] == 0);
    // A narrower field of view fills more of the frame.
    Rgb8 narrow = run("narrow.png", with(front, {"--fov", "30"}));
    Rgb8 wide = run("wide.png", with(front, {"--fov", "90"}));
    CHECK(narrow.mean() > wide.mean() * 1.5);
    // Rolling the camera by --up moves the off-centre quad from the left of the image to the top.
    const std::vector<std::string> off = {"--eye", "1.5,0,3", "--target", "1.5,0,0", "--fov", "90"};
    Rgb8 upright = run("upright.png", off);
    Rgb8 rolled = run("rolled.png", with(off, {"--up", "-1,0,0"}));
    CHECK(upright.at(30, 32)[0] > 0);
    CHECK(upright.at(48, 15)[0] == 0);
    CHECK(rolled.at(30, 32)[0] == 0);
    CHECK(rolled.at(48, 15)[0] > 0);
    // Clip planes: the quad at distance 3 is cut by a far plane at 2 or a near plane at 4.
    CHECK(run("far.png", with(front, {"--far", "2"})).mean() == 0.0);
    CHECK(run("near.png", with(front, {"--near", "4", "--far", "10"})).mean() == 0.0);
    CHECK(run("planes.png", with(front, {"--near", "1", "--far", "10"})).mean() > 30.0);
}

TEST_CASE("shading flags: --brdf --exposure --tonemap --view") {
    CliSandbox box;
    auto run = [&](const std::string& out, const std::vector<std::string>& args) {
        CliRun r = render(box, with(with(kSmall, {"-o", out}), args));
        CHECK(r.code == 0);
        CHECK(r.err.empty());
        return load_rgb8(box.path(out));
    };
    Rgb8 lit = run("lit.png", {});
    CHECK(run("default.png", {"--brdf", "default", "--exposure", "1", "--tonemap", "aces"}).rgb == lit.rgb);
    CHECK(run("gltf.png", {"--brdf", "gltf"}).rgb != lit.rgb);
    CHECK(run("bright.png", {"--exposure", "2"}).mean() > lit.mean() + 10.0);
    Rgb8 none = run("none.png", {"--tonemap", "none"});
    Rgb8 neutral = run("neutral.png", {"--tonemap", "neutral"});
    CHECK(none.rgb != lit.rgb);
    CHECK(neutral.rgb != lit.rgb);
    CHECK(neutral.rgb != none.rgb);
    // Every debug view renders, and shows something other than the lit image.
    for (const char* view : {"albedo", "normal", "roughness", "metallic", "uv", "depth", "overdraw", "tiles",
                             "ndf", "fresnel", "geometry", "diffuse", "specular"}) {
        CAPTURE(view);
        Rgb8 img = run(std::string("view_") + view + ".png", {"--view", view});
        CHECK(img.width == 96);
        CHECK(img.mean() > 0.0);
        CHECK(img.rgb != lit.rgb);
    }
    // The normal view of the floor (facing +Y) is mostly green.
    Rgb8 normal = load_rgb8(box.path("view_normal.png"));
    const std::uint8_t* floor = normal.at(48, 62);
    CHECK(floor[1] > floor[0]);
    CHECK(floor[1] > floor[2]);
}

TEST_CASE("--pixel reports the depth, the colour and the triangle") {
    CliSandbox box;
    CliRun r = render(box, with(kSmall, {"--pixel", "48,50", "--pixel", "0,0"}));  // the last one wins
    CHECK(r.code == 0);
    CHECK(r.out.find("pixel 0,0 frame 0: depth 1.000000") != std::string::npos);
    CHECK(r.out.find("(background)") != std::string::npos);
    CliRun floor = render(box, with(kSmall, {"--pixel", "48,50"}));
    CHECK(floor.code == 0);
    CHECK(floor.out.find("pixel 48,50 frame 0: depth 0.") != std::string::npos);
    CHECK(floor.out.find("material 'tiles'") != std::string::npos);
    // --pixel keeps the linear framebuffer for its report; without it the
    // frame's tiles stay tile-local (FrameOptions::transient): the same PNG.
    for (const char* n : {"1", "4"}) {
        CAPTURE(n);
        REQUIRE(render(box, with(kSmall, {"--msaa", n, "--pixel", "48,50", "-o", "kept.png"})).code == 0);
        REQUIRE(render(box, with(kSmall, {"--msaa", n, "-o", "transient.png"})).code == 0);
        const std::vector<std::uint8_t> kept = read_bytes(box.path("kept.png"));
        REQUIRE(!kept.empty());
        CHECK(read_bytes(box.path("transient.png")) == kept);
    }
}

// A small equirect .hdr: a gradient sky (blue up, warm below) with a bright
// spot, written with the project's own HDR writer.
void write_test_env(const std::string& path) {
    const int w = 64, h = 32;
    std::vector<float> rgba(std::size_t(w) * h * 4, 1.0f);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            float* p = &rgba[(std::size_t(y) * w + x) * 4];
            const float up = 1.0f - float(y) / float(h);
            p[0] = 0.3f + 0.5f * (1.0f - up);
            p[1] = 0.4f;
            p[2] = 0.3f + 0.6f * up;
            if (x == 40 && y == 10) p[0] = p[1] = p[2] = 80.0f;
        }
    write_hdr_atomic(path, w, h, rgba.data());
}

TEST_CASE("--env lights the scene and is the background; its flags end to end") {
    CliSandbox box;
    write_text(box.path("quad.obj"), kQuadObj);
    write_test_env(box.path("sky.hdr"));
    // No light in the scene or the flags: the environment alone, no rig message.
    CliRun r = render(box, with({"quad.obj", "--env", "sky.hdr", "-o", "env.png"}, kSmall));
    CHECK(r.code == 0);
    CHECK(r.err.empty());
    Rgb8 env = load_rgb8(box.path("env.png"));
    REQUIRE(!env.empty());
    // The quad (centre) is lit, the corner shows the sky.
    CHECK(env.at(48, 32)[0] > 20);
    CHECK(env.at(0, 0)[0] + env.at(0, 0)[1] + env.at(0, 0)[2] > 60);
    // Byte-identical for any thread count and tile size.
    REQUIRE(render(box, with({"quad.obj", "--env", "sky.hdr", "--threads", "1", "--tile", "16", "-o", "t1.png"},
                             kSmall)).code == 0);
    CHECK(read_bytes(box.path("t1.png")) == read_bytes(box.path("env.png")));
    // A full turn is no turn; half a turn moves the sky.
    REQUIRE(render(box, with({"quad.obj", "--env", "sky.hdr", "--env-rotate", "360", "-o", "r360.png"}, kSmall)).code == 0);
    CHECK(read_bytes(box.path("r360.png")) == read_bytes(box.path("env.png")));
    REQUIRE(render(box, with({"quad.obj", "--env", "sky.hdr", "--env-rotate", "180", "-o", "r180.png"}, kSmall)).code == 0);
    CHECK(read_bytes(box.path("r180.png")) != read_bytes(box.path("env.png")));
    // Intensity 0: an unlit quad in front of a black sky.
    REQUIRE(render(box, with({"quad.obj", "--env", "sky.hdr", "--env-intensity", "0", "-o", "dark.png"}, kSmall)).code == 0);
    CHECK(load_rgb8(box.path("dark.png")).mean() == 0.0);
    // Backgrounds: black, a colour, the blurred map.
    REQUIRE(render(box, with({"quad.obj", "--env", "sky.hdr", "--background", "black", "-o", "black.png"}, kSmall)).code == 0);
    Rgb8 black = load_rgb8(box.path("black.png"));
    CHECK(black.at(0, 0)[0] == 0);
    CHECK(black.at(48, 32)[0] == env.at(48, 32)[0]);  // lighting unchanged
    REQUIRE(render(box, with({"quad.obj", "--env", "sky.hdr", "--background", "1,0,0", "--tonemap", "none",
                              "-o", "red.png"}, kSmall)).code == 0);
    Rgb8 red = load_rgb8(box.path("red.png"));
    CHECK(red.at(0, 0)[0] == 255);
    CHECK(red.at(0, 0)[1] == 0);
    REQUIRE(render(box, with({"quad.obj", "--env", "sky.hdr", "--background", "blur", "-o", "blur.png"}, kSmall)).code == 0);
    CHECK(read_bytes(box.path("blur.png")) != read_bytes(box.path("env.png")));
    // Energy conservation changes the lit pixels, not the sky.
    REQUIRE(render(box, with({"quad.obj", "--env", "sky.hdr", "--energy", "conserve", "-o", "energy.png"}, kSmall)).code == 0);
    Rgb8 energy = load_rgb8(box.path("energy.png"));
    CHECK(energy.at(0, 0)[2] == env.at(0, 0)[2]);
    // The reference integral renders too (few samples: it is slow).
    REQUIRE(render(box, with({"quad.obj", "--env", "sky.hdr", "--ibl", "reference", "--samples", "16",
                              "-o", "ref.png"}, kSmall)).code == 0);
    Rgb8 ref = load_rgb8(box.path("ref.png"));
    CHECK(std::abs(int(ref.at(48, 32)[0]) - int(env.at(48, 32)[0])) <= 40);
    // --ambient is replaced by the environment: a warning, and the same image.
    CliRun amb = render(box, with({"quad.obj", "--env", "sky.hdr", "--ambient", "1,1,1", "-o", "amb.png"}, kSmall));
    CHECK(amb.code == 0);
    CHECK(amb.err.find("--ambient is not used") != std::string::npos);
    CHECK(read_bytes(box.path("amb.png")) == read_bytes(box.path("env.png")));
}

TEST_CASE("--pixel with an environment prints the split sum's terms and the reference") {
    CliSandbox box;
    write_text(box.path("quad.obj"), kQuadObj);
    write_test_env(box.path("sky.hdr"));
    CliRun r = render(box, with({"quad.obj", "--env", "sky.hdr", "--pixel", "48,32", "--samples", "256"}, kSmall));
    CHECK(r.code == 0);
    CHECK(r.out.find("ibl split-sum ") != std::string::npos);
    CHECK(r.out.find("ibl terms: irradiance ") != std::string::npos);
    CHECK(r.out.find(" level ") != std::string::npos);
    CHECK(r.out.find("dfg scale ") != std::string::npos);
    CHECK(r.out.find("ibl reference (256 samples) ") != std::string::npos);
    // The split sum and the reference agree on this diffuse quad within 10%.
    std::smatch m;
    const std::regex split("ibl split-sum ([0-9.e+-]+)"), reference("ibl reference \\(256 samples\\) ([0-9.e+-]+)");
    REQUIRE(std::regex_search(r.out, m, split));
    const double a = std::stod(m[1]);
    REQUIRE(std::regex_search(r.out, m, reference));
    const double b = std::stod(m[1]);
    CHECK(a > 0.0);
    CHECK(std::fabs(a - b) <= 0.1 * b);
    // The built-in scene has its own sky: --pixel shows the terms there too.
    CliRun builtin = render(box, with(kSmall, {"--pixel", "48,50", "--samples", "64"}));
    CHECK(builtin.out.find("ibl reference (64 samples)") != std::string::npos);
}

TEST_CASE("--env errors: bad files exit 1, bad values exit 2, one line each") {
    CliSandbox box;
    write_text(box.path("quad.obj"), kQuadObj);
    write_text(box.path("fake.hdr"), "\x89PNG\r\n\x1a\n not an hdr at all");
    write_text(box.path("corrupt.hdr"), "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 100000 +X 100000\ngarbage");
    write_text(box.path("empty.hdr"), "");
    fs::create_directories(box.work() / "dir.hdr");
    auto files_before = box.work_files();
    struct Case { std::vector<std::string> args; int code; const char* expect; };
    const Case cases[] = {
        {{"--env", "missing.hdr"}, 1, "missing.hdr: no such file"},
        {{"--env", "fake.hdr"}, 1, "fake.hdr: not a Radiance HDR file"},
        {{"--env", "corrupt.hdr"}, 1, "corrupt.hdr: "},
        {{"--env", "empty.hdr"}, 1, "empty.hdr: empty file"},
        {{"--env", "dir.hdr"}, 1, "dir.hdr: is a directory"},
        {{"--env", "sky.png"}, 2, "--env 'sky.png': expected an equirectangular Radiance .hdr file"},
        {{"--env", "missing.hdr", "--env-intensity", "nan"}, 2, "--env-intensity 'nan': not a finite number"},
        {{"--env", "missing.hdr", "--env-intensity", "-1"}, 2, "--env-intensity '-1'"},
        {{"--env", "missing.hdr", "--env-rotate", "inf"}, 2, "--env-rotate 'inf'"},
        {{"--env", "missing.hdr", "--background", "grey"}, 2, "--background 'grey'"},
        {{"--env", "missing.hdr", "--background", "1,nan,0"}, 2, "--background '1,nan,0'"},
        {{"--env", "missing.hdr", "--ibl", "exact"}, 2, "--ibl 'exact'"},
        {{"--env", "missing.hdr", "--ibl", "reference", "--samples", "0"}, 2, "--samples '0'"},
        {{"--env", "missing.hdr", "--samples", "64"}, 2, "--samples: only used with --ibl reference"},
        {{"--energy", "yes"}, 2, "--energy 'yes'"},
        {{"--env-intensity", "2"}, 2, "--env-intensity '2': needs --env FILE.hdr"},
        {{"--background", "blur"}, 2, "--background blur: needs --env FILE.hdr"},
        {{"--ibl", "reference"}, 2, "--ibl reference: needs --env FILE.hdr"},
    };
    for (const Case& c : cases) {
        CAPTURE(c.expect);
        CliRun r = render(box, with(with({"quad.obj"}, kSmall), c.args));
        CHECK(r.code == c.code);
        CHECK(lines_of(r.err).size() == 1);
        CHECK(r.err.rfind("render: ", 0) == 0);
        CHECK(r.err.find(c.expect) != std::string::npos);
        CHECK(box.work_files() == files_before);
    }
}

TEST_CASE("usage errors: exit code 2, one line naming the flag and value, no output") {
    CliSandbox box;
    struct Case { std::vector<std::string> args; const char* expect; };
    const Case cases[] = {
        {{"--bogus"}, "unknown option '--bogus'"},
        {{"--size"}, "--size: missing value"},
        {{"--size", "0x0"}, "--size 0x0"},
        {{"--size", "100000x100000"}, "240000000000 bytes"},
        {{"--fov", "nan"}, "--fov 'nan'"},
        {{"--fov", "-5"}, "--fov '-5'"},
        {{"--exposure", "-1"}, "--exposure '-1'"},
        {{"--exposure", "inf"}, "--exposure 'inf'"},
        {{"--ambient", "nan,0,0"}, "--ambient 'nan,0,0'"},
        {{"--ambient", "-0.5,0,0"}, "--ambient '-0.5,0,0'"},
        {{"--sun", "0,1,0:nan,1,1"}, "--sun '0,1,0:nan,1,1'"},
        {{"--point", "0,1,0:-1,1,1"}, "--point '0,1,0:-1,1,1'"},
        {{"--near", "-1"}, "--near '-1'"},
        {{"--threads", "-2"}, "--threads '-2'"},
        {{"--tile", "48"}, "--tile '48'"},
        {{"--frames", "-3"}, "--frames '-3'"},
        {{"--frames", "3"}, "frame number in the file name"},
        {{"--frames", "3", "-o", "f%04d.png", "--frame-range", "1-5"}, "--frame-range '1-5'"},
        {{"--repeat", "nan"}, "--repeat 'nan'"},
        {{"--view", "bogus"}, "--view 'bogus'"},
        {{"-o", "out.jpg"}, "-o 'out.jpg'"},
        {{"--pixel", "200,1"}, "--pixel '200,1'"},
        // Found after loading: the camera cannot look anywhere.
        {{"--eye", "1,1,1", "--target", "1,1,1"}, "the eye and the target are the same point"},
        {{"--eye", "0,5,0", "--target", "0,0,0", "--up", "0,1,0"}, "--up: parallel to the viewing direction"},
        {{"--near", "1000"}, "--near/--far"},
    };
    for (const Case& c : cases) {
        CAPTURE(c.args[0]);
        check_error(box, render(box, with(kSmall, c.args)), 2, c.expect);
    }
}

TEST_CASE("bad files: exit code 1, one line naming the file and the problem, no output") {
    CliSandbox box;
    fs::create_directories(box.work() / "dir.obj");
    write_text(box.path("model.stl"), "solid x\nendsolid x\n");
    write_text(box.path("points.obj"), "v 0 0 0\nv 1 0 0\nv 0 1 0\n");
    write_text(box.path("empty.obj"), "");
    static const char kCorruptGlb[] = "glTF\x02\0\0\0\xff\xff\xff\x7f garbage";
    write_text(box.path("corrupt.glb"), std::string(kCorruptGlb, sizeof kCorruptGlb - 1));
    write_text(box.path("nobin.gltf"),
               R"({"asset":{"version":"2.0"},"scene":0,"scenes":[{"nodes":[0]}],"nodes":[{"mesh":0}],)"
               R"("meshes":[{"primitives":[{"attributes":{"POSITION":0}}]}],)"
               R"("buffers":[{"uri":"missing.bin","byteLength":36}],)"
               R"("bufferViews":[{"buffer":0,"byteLength":36}],)"
               R"("accessors":[{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3",)"
               R"("min":[0,0,0],"max":[1,1,0]}]})");
    auto files_before = box.work_files();
    struct Case { std::string scene; const char* expect; };
    const Case cases[] = {
        {"missing.obj", "missing.obj: cannot open file"},
        {"dir.obj", "dir.obj: is a directory"},
        {"model.stl", "model.stl: unknown extension"},
        {"points.obj", "points.obj: no triangles"},
        {"empty.obj", "empty.obj: empty file"},
        {"corrupt.glb", "corrupt.glb: "},
        {"nobin.gltf", "nobin.gltf: "},
    };
    for (const Case& c : cases) {
        CAPTURE(c.scene);
        CliRun r = render(box, with(with({c.scene}, kSmall), {"-o", "out.png"}));
        CHECK(r.code == 1);
        CHECK(lines_of(r.err).size() == 1);
        CHECK(r.err.rfind("render: ", 0) == 0);
        CHECK(r.err.find(c.expect) != std::string::npos);
        CHECK(box.work_files() == files_before);  // no out.png, no temporary file
    }
    // The missing buffer is named.
    CliRun nobin = render(box, with({"nobin.gltf"}, kSmall));
    CHECK(nobin.err.find("missing.bin") != std::string::npos);

    if (geteuid() != 0) {  // root reads anything
        write_text(box.path("secret.obj"), kQuadObj);
        fs::permissions(box.path("secret.obj"), fs::perms::none);
        CliRun r = render(box, with({"secret.obj"}, kSmall));
        CHECK(r.code == 1);
        CHECK(r.err.find("secret.obj") != std::string::npos);
    }
}

TEST_CASE("loader warnings go to stderr, one line each, and the render goes on") {
    CliSandbox box;
    write_text(box.path("red.mtl"), "newmtl red\nKd 1 0 0\nmap_Kd nothere.png\n");
    write_text(box.path("quad.obj"), std::string("mtllib red.mtl\nusemtl red\n") + kQuadObj);
    CliRun r = render(box, with({"quad.obj", "--sun", "0,0,1:1,1,1", "-o", "quad.png"}, kSmall));
    CHECK(r.code == 0);
    const std::vector<std::string> lines = lines_of(r.err);
    REQUIRE(lines.size() == 1);
    CHECK(lines[0].rfind("render: warning: quad.obj: ", 0) == 0);
    CHECK(lines[0].find("nothere.png") != std::string::npos);
    Rgb8 img = load_rgb8(box.path("quad.png"));
    REQUIRE(!img.empty());
    // Kd alone: red, with the white specular highlight of F0 = 0.04 on top.
    CHECK(img.at(48, 32)[0] > 100);
    CHECK(img.at(48, 32)[0] > 2 * img.at(48, 32)[1]);
}

TEST_CASE("running out of memory is a message, not a crash") {
#ifdef PRAST_SANITIZE_BUILD
    MESSAGE("skipped: AddressSanitizer reserves terabytes of address space, so ulimit -v cannot apply");
    return;
#endif
    CliSandbox box;
    // A 10000x10000 image: 400 MB of 8-bit output and its PNG encoding (the
    // float framebuffer, 2 GB, is never allocated for a PNG). Address space
    // that runs out while loading, or while encoding on 1 or 2 threads.
    struct Run { const char* limit; const char* threads; };
    for (const Run& run : {Run{"ulimit -v 300000", "2"}, Run{"ulimit -v 1000000", "1"}, Run{"ulimit -v 1000000", "2"}}) {
        CAPTURE(run.limit);
        CAPTURE(run.threads);
        CliRun r = box.run_exe(PRAST_RENDER_EXE, {"--size", "10000x10000", "--threads", run.threads}, run.limit);
        CHECK(r.code == 1);
        CHECK(r.err.rfind("render: ", 0) == 0);
        CHECK(r.err.find("out of memory") != std::string::npos);
        CHECK(lines_of(r.err).size() == 1);
        CHECK(box.work_files().empty());
    }
}

TEST_CASE("an unwritable output path fails before rendering and leaves no file") {
    CliSandbox box;
    CliRun no_dir = render(box, with(kSmall, {"-o", "no/such/dir/out.png"}));
    CHECK(no_dir.code == 1);
    CHECK(no_dir.err.find("no/such/dir/out.png") != std::string::npos);
    CHECK(no_dir.err.find("does not exist") != std::string::npos);
    CHECK(lines_of(no_dir.err).size() == 1);

    fs::create_directories(box.work() / "taken.png");
    CliRun is_dir = render(box, with(kSmall, {"-o", "taken.png"}));
    CHECK(is_dir.code == 1);
    CHECK(is_dir.err.find("taken.png: is a directory") != std::string::npos);
    CHECK(fs::is_empty(box.work() / "taken.png"));

    write_text(box.path("file"), "x");
    CliRun under_file = render(box, with(kSmall, {"-o", "file/out.png"}));
    CHECK(under_file.code == 1);
    CHECK(under_file.err.find("is not a directory") != std::string::npos);

    // A directory nobody may write in: a read-only one, or /proc for root.
    std::string locked;
    if (geteuid() != 0) {
        fs::create_directories(box.work() / "locked");
        fs::permissions(box.work() / "locked", fs::perms::owner_read | fs::perms::owner_exec);
        locked = box.path("locked/out.png");
    } else {
        locked = "/proc/prast_render_test.png";
    }
    CliRun r = render(box, with(kSmall, {"-o", locked}));
    CHECK(r.code == 1);
    CHECK(r.err.find("cannot write") != std::string::npos);
    CHECK(lines_of(r.err).size() == 1);
    CHECK(!fs::exists(locked));
    if (geteuid() != 0) CHECK(fs::is_empty(box.work() / "locked"));
    // A turntable is checked too.
    CliRun turn = render(box, with(kSmall, {"--frames", "2", "-o", "gone/f%04d.png"}));
    CHECK(turn.code == 1);
    CHECK(turn.err.find("gone/f0000.png") != std::string::npos);
}

namespace {

// A binary glTF with `triangles` triangles over a (grid+1)^2 vertex height
// field; the triangle list repeats the grid's triangles as often as needed,
// so the file stays near 12 bytes per triangle.
void write_big_glb(const std::string& path, std::size_t triangles, int grid) {
    const int side = grid + 1;
    std::vector<float> positions;
    positions.reserve(std::size_t(side) * side * 3);
    for (int y = 0; y < side; ++y)
        for (int x = 0; x < side; ++x) {
            float fx = float(x) / float(grid) * 2.0f - 1.0f, fy = float(y) / float(grid) * 2.0f - 1.0f;
            positions.insert(positions.end(), {fx, fy, 0.1f * std::sin(6.0f * fx) * std::cos(6.0f * fy)});
        }
    std::vector<std::uint32_t> cell_tris;
    for (int y = 0; y < grid; ++y)
        for (int x = 0; x < grid; ++x) {
            std::uint32_t a = std::uint32_t(y * side + x), b = a + 1, c = a + std::uint32_t(side), d = c + 1;
            cell_tris.insert(cell_tris.end(), {a, b, d, a, d, c});
        }
    std::vector<std::uint32_t> indices(triangles * 3);
    for (std::size_t i = 0; i < indices.size(); ++i) indices[i] = cell_tris[i % cell_tris.size()];

    const std::size_t pos_bytes = positions.size() * 4, idx_bytes = indices.size() * 4;
    std::string json =
        R"({"asset":{"version":"2.0"},"scene":0,"scenes":[{"nodes":[0]}],"nodes":[{"mesh":0}],)"
        R"("meshes":[{"primitives":[{"attributes":{"POSITION":0},"indices":1}]}],)"
        R"("buffers":[{"byteLength":)" + std::to_string(pos_bytes + idx_bytes) + "}],"
        R"("bufferViews":[{"buffer":0,"byteOffset":0,"byteLength":)" + std::to_string(pos_bytes) + "},"
        R"({"buffer":0,"byteOffset":)" + std::to_string(pos_bytes) + R"(,"byteLength":)" +
        std::to_string(idx_bytes) + "}],"
        R"("accessors":[{"bufferView":0,"componentType":5126,"count":)" + std::to_string(positions.size() / 3) +
        R"(,"type":"VEC3","min":[-1,-1,-0.1],"max":[1,1,0.1]},)"
        R"({"bufferView":1,"componentType":5125,"count":)" + std::to_string(indices.size()) +
        R"(,"type":"SCALAR"}]})";
    while (json.size() % 4) json += ' ';
    const std::uint32_t bin_len = std::uint32_t(pos_bytes + idx_bytes);
    const std::uint32_t json_len = std::uint32_t(json.size());
    const std::uint32_t header[3] = {0x46546C67u, 2u, 12u + 8u + json_len + 8u + bin_len};
    const std::uint32_t json_head[2] = {json_len, 0x4E4F534Au};
    const std::uint32_t bin_head[2] = {bin_len, 0x004E4942u};
    std::FILE* f = std::fopen(path.c_str(), "wb");
    REQUIRE(f);
    std::fwrite(header, 4, 3, f);
    std::fwrite(json_head, 4, 2, f);
    std::fwrite(json.data(), 1, json.size(), f);
    std::fwrite(bin_head, 4, 2, f);
    std::fwrite(positions.data(), 4, positions.size(), f);
    std::fwrite(indices.data(), 4, indices.size(), f);
    REQUIRE(std::fclose(f) == 0);
}

} // namespace

TEST_CASE("a model with 10 million triangles renders") {
    CliSandbox box;
    constexpr std::size_t kTriangles = 10000000;
    const auto t0 = std::chrono::steady_clock::now();
    write_big_glb(box.path("big.glb"), kTriangles, 1000);
    const auto t1 = std::chrono::steady_clock::now();
    CliRun r = render(box, {"big.glb", "--size", "64x64", "--stats", "--eye", "0,0,3", "--target", "0,0,0"});
    const auto t2 = std::chrono::steady_clock::now();
    MESSAGE("10M triangles: write " << std::chrono::duration<double>(t1 - t0).count() << " s, render "
                                    << std::chrono::duration<double>(t2 - t1).count() << " s");
    CHECK(r.code == 0);
    CHECK(r.err == std::string(kDefaultRigLine) + "\n");
    CHECK(r.out.find("10000000 triangles") != std::string::npos);
    Rgb8 img = load_rgb8(box.path("render.png"));
    REQUIRE(img.width == 64);
    CHECK(img.at(32, 32)[0] > 0);
}

TEST_CASE("the executable needs only the C library (ldd)") {
#ifdef PRAST_SANITIZE_BUILD
    MESSAGE("skipped: a sanitizer build links the sanitizer runtimes");
    return;
#endif
    std::FILE* p = popen("ldd " PRAST_RENDER_EXE " 2>&1", "r");
    REQUIRE(p);
    std::string text;
    char buf[512];
    while (std::fgets(buf, sizeof buf, p)) text += buf;
    pclose(p);
    INFO(text);
    for (const char* lib : {"libstdc++", "libgcc_s", "libtinyobj", "libstb", "libtinygltf", "libjson"})
        CHECK(text.find(lib) == std::string::npos);
    // Every line is a part of glibc or the kernel's vDSO.
    const std::regex allowed(R"(\s*(linux-(vdso|gate)\.so\.[0-9]+|/lib[^ ]*/ld-linux[^ ]*|)"
                             R"(lib(c|m|pthread|dl|rt)\.so\.[0-9]+)( .*)?)");
    const std::vector<std::string> lines = lines_of(text);
    CHECK(!lines.empty());
    for (const std::string& l : lines) {
        CAPTURE(l);
        CHECK(std::regex_match(l, allowed));
    }
}

TEST_CASE("real assets: the tea set (glTF and OBJ) and the bunny") {
    const fs::path assets = PRAST_SHARED_ASSETS;
    const fs::path gltf = assets / "tea-set-01/gltf/tea_set_01_1k.gltf";
    const fs::path obj = assets / "tea-set-01/obj/tea_set_01.obj";
    const fs::path bunny = assets / "stanford-bunny/stanford-bunny.obj";
    if (!fs::exists(gltf) || !fs::exists(obj) || !fs::exists(bunny)) {
        MESSAGE("shared assets not found: skipped");
        return;
    }
    CliSandbox box;
    // The camera the shared assets' README gives for the whole set, 4:3.
    const std::vector<std::string> camera = {"--size", "160x120", "--eye", "0.02,0.60,1.35", "--target",
                                             "0.02,0.04,-0.04", "--up", "0,1,0", "--fov", "32"};
    for (const fs::path& scene : {gltf, obj}) {
        CAPTURE(scene);
        const std::string stem = scene.extension().string().substr(1);
        CliRun r = render(box, with(with({scene.string()}, camera), {"-o", stem + ".png"}));
        CHECK(r.code == 0);
        CHECK(r.err == std::string(kDefaultRigLine) + "\n");  // no warnings, no lights in the file
        Rgb8 img = load_rgb8(box.path(stem + ".png"));
        REQUIRE(img.width == 160);
        CHECK(img.mean() > 5.0);
        CliRun hdr = render(box, with(with({scene.string()}, camera), {"-o", stem + ".hdr"}));
        CHECK(hdr.code == 0);
        RgbFloat radiance = load_hdr(box.path(stem + ".hdr"));
        REQUIRE(radiance.width == 160);
        std::size_t non_finite = 0;
        for (float v : radiance.rgb) non_finite += !std::isfinite(v);
        CHECK(non_finite == 0);
    }
    // The two files hold the same set and the same camera fits both (assets
    // README): their images agree except for small differences.
    Rgb8 a = load_rgb8(box.path("gltf.png")), b = load_rgb8(box.path("obj.png"));
    REQUIRE(a.rgb.size() == b.rgb.size());
    double diff = 0.0;
    for (std::size_t i = 0; i < a.rgb.size(); ++i) diff += std::abs(int(a.rgb[i]) - int(b.rgb[i]));
    diff /= double(a.rgb.size());
    MESSAGE("tea set glTF vs OBJ: mean absolute difference " << diff << " / 255");
    CHECK(diff < 4.0);

    CliRun rb = render(box, {bunny.string(), "--size", "160x120", "--eye", "-0.017,0.13,0.36", "--target",
                             "-0.017,0.108,0", "--fov", "35", "-o", "bunny.png"});
    CHECK(rb.code == 0);
    Rgb8 img = load_rgb8(box.path("bunny.png"));
    REQUIRE(img.width == 160);
    CHECK(img.at(80, 60)[0] > 50);  // the bunny's body is in the middle
}

#endif  // PRAST_RENDER_EXE

} // TEST_SUITE

// The `step` executable end to end, through the built binary:
// every explained pixel equals render's output (the 8-bit PNG exactly, the
// linear colour as render's .hdr stores it) over grids of pixels on the
// built-in scene, the tea set and NormalTangentTest; `verify` finds every
// recomputed number equal to the pipeline's; scripted sessions against the
// expected transcripts in tests/step/ (the same for 1 and 2 threads); bad
// commands and bad flags.
//
// Regenerate the transcripts only deliberately, after reading the diff:
//   PRAST_STEP_REGENERATE=1 build/prast_tests -ts=step
#include <doctest/doctest.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "tests/cli_util.h"

using namespace prast::cli_test;

namespace {

const std::string kStep = PRAST_STEP_EXE;
const std::string kRender = PRAST_RENDER_EXE;
const std::string kAssets = PRAST_SHARED_ASSETS;
const std::string kTranscripts = std::string(PRAST_SOURCE_DIR) + "/tests/step/";

// Runs step in the sandbox with `commands` on standard input.
CliRun run_step(CliSandbox& box, const std::vector<std::string>& args, const std::string& commands) {
    const fs::path dir = box.work().parent_path();
    write_text(dir / "stdin.txt", commands);
    std::string cmd = "cd " + shell_quote(box.work().string()) + " && " + shell_quote(kStep);
    for (const std::string& a : args) cmd += " " + shell_quote(a);
    cmd += " <" + shell_quote((dir / "stdin.txt").string()) + " >" + shell_quote((dir / "stdout.txt").string()) +
           " 2>" + shell_quote((dir / "stderr.txt").string());
    const int status = std::system(cmd.c_str());
    CliRun r;
    if (status != -1 && WIFEXITED(status)) r.code = WEXITSTATUS(status);
    else if (status != -1 && WIFSIGNALED(status)) r.code = 128 + WTERMSIG(status);
    r.out = read_text(dir / "stdout.txt");
    r.err = read_text(dir / "stderr.txt");
    return r;
}

// stb_image_write's RGBE encoding and stb_image's decoding of it: what a
// linear colour becomes in render's .hdr.
void rgbe_round_trip(const float in[3], float out[3]) {
    float maxcomp = std::max(in[0], std::max(in[1], in[2]));
    if (maxcomp < 1e-32f) {
        out[0] = out[1] = out[2] = 0.0f;
        return;
    }
    int exponent;
    const float normalize = float(std::frexp(maxcomp, &exponent)) * 256.0f / maxcomp;
    unsigned char rgbe[4] = {(unsigned char)(in[0] * normalize), (unsigned char)(in[1] * normalize),
                             (unsigned char)(in[2] * normalize), (unsigned char)(exponent + 128)};
    const float f1 = float(std::ldexp(1.0f, rgbe[3] - (128 + 8)));
    for (int k = 0; k < 3; ++k) out[k] = float(rgbe[k]) * f1;
}

struct PixelAnswer {
    int srgb[3] = {-1, -1, -1};
    float linear[3] = {0, 0, 0};
    bool background = false;
};

// The answers of a transcript of `pixel` commands, in order.
std::vector<PixelAnswer> pixel_answers(const std::string& out) {
    std::vector<PixelAnswer> answers;
    PixelAnswer cur;
    for (const std::string& l : lines_of(out)) {
        if (l.rfind("no fragment was written", 0) == 0) cur.background = true;
        if (l.rfind("linear (", 0) == 0)
            std::sscanf(l.c_str(), "linear (%f, %f, %f)", &cur.linear[0], &cur.linear[1], &cur.linear[2]);
        if (l.rfind("srgb8 ", 0) == 0) {
            std::sscanf(l.c_str(), "srgb8 %d %d %d", &cur.srgb[0], &cur.srgb[1], &cur.srgb[2]);
            answers.push_back(cur);
            cur = PixelAnswer{};
        }
    }
    return answers;
}

// A grid of pixels over a render: step's srgb8 equals the PNG, its linear
// colour the .hdr (after the same RGBE encoding). Returns the pixels that
// a fragment reached.
int check_pixels_against_render(const std::vector<std::string>& flags, int cols, int rows) {
    CliSandbox box;
    std::vector<std::string> png_args = flags, hdr_args = flags;
    png_args.insert(png_args.end(), {"-o", "r.png"});
    hdr_args.insert(hdr_args.end(), {"-o", "r.hdr"});
    REQUIRE(box.run_exe(kRender, png_args).code == 0);
    REQUIRE(box.run_exe(kRender, hdr_args).code == 0);
    const Rgb8 png = load_rgb8(box.path("r.png"));
    const RgbFloat hdr = load_hdr(box.path("r.hdr"));
    REQUIRE(!png.empty());
    REQUIRE(hdr.width == png.width);
    std::string commands;
    std::vector<std::pair<int, int>> pixels;
    for (int j = 0; j < rows; ++j)
        for (int i = 0; i < cols; ++i) {
            const int x = int((i + 0.5) * png.width / cols) + (j % 3), y = int((j + 0.5) * png.height / rows) + (i % 2);
            pixels.push_back({x, y});
            commands += "pixel " + std::to_string(x) + " " + std::to_string(y) + "\n";
        }
    const CliRun r = run_step(box, flags, commands);
    REQUIRE(r.code == 0);
    const std::vector<PixelAnswer> answers = pixel_answers(r.out);
    REQUIRE(answers.size() == pixels.size());
    int reached = 0;
    for (std::size_t i = 0; i < pixels.size(); ++i) {
        const auto [x, y] = pixels[i];
        const PixelAnswer& a = answers[i];
        const std::uint8_t* p = png.at(x, y);
        INFO("pixel " << x << " " << y);
        CHECK(a.srgb[0] == p[0]);
        CHECK(a.srgb[1] == p[1]);
        CHECK(a.srgb[2] == p[2]);
        float rt[3];
        rgbe_round_trip(a.linear, rt);
        const float* h = &hdr.rgb[(std::size_t(y) * hdr.width + x) * 3];
        CHECK(rt[0] == h[0]);
        CHECK(rt[1] == h[1]);
        CHECK(rt[2] == h[2]);
        reached += !a.background;
    }
    return reached;
}

bool have_asset(const std::string& path) {
    if (std::FILE* f = std::fopen(path.c_str(), "rb")) {
        std::fclose(f);
        return true;
    }
    MESSAGE("skipped: " << path << " is absent (PRAST_SHARED_ASSETS)");
    return false;
}

const std::string kTea = kAssets + "/tea-set-01/gltf/tea_set_01_1k.gltf";
const std::string kNormalTangent = kAssets + "/normal-tangent-test/NormalTangentTest.glb";
const std::vector<std::string> kTeaFlags = {kTea, "--eye", "-0.20,0.20,0.42", "--target", "-0.347,0.065,0.061",
                                            "--fov", "35"};
const std::vector<std::string> kNormalTangentFlags = {kNormalTangent, "--eye", "0,-0.125,3.9", "--target",
                                                      "0,-0.125,0", "--size", "640x480"};

// A scripted session against its expected transcript.
void check_transcript(const std::string& name, const std::vector<std::string>& flags) {
    const std::string commands = read_text(kTranscripts + name + ".cmd");
    REQUIRE(!commands.empty());
    std::string first;
    for (const char* threads : {"1", "2"}) {
        CliSandbox box;
        std::vector<std::string> args = flags;
        args.insert(args.end(), {"--threads", threads});
        const CliRun r = run_step(box, args, commands);
        INFO("stderr: " << r.err);
        if (first.empty()) {
            first = r.out;
        } else {
            CHECK(r.out == first);  // any thread count: the same transcript
        }
    }
    const std::string expected_path = kTranscripts + name + ".txt";
    if (std::getenv("PRAST_STEP_REGENERATE")) write_text(expected_path, first);
    const std::string expected = read_text(expected_path);
    REQUIRE_MESSAGE(!expected.empty(), "missing " << expected_path << " (PRAST_STEP_REGENERATE=1 writes it)");
    const std::vector<std::string> got = lines_of(first), want = lines_of(expected);
    for (std::size_t i = 0; i < std::min(got.size(), want.size()); ++i) {
        INFO("line " << i + 1 << " of " << expected_path);
        REQUIRE(got[i] == want[i]);
    }
    CHECK(got.size() == want.size());
}

} // namespace

TEST_SUITE("step") {

TEST_CASE("pixel: the built-in scene's explained pixels are render's, byte for byte") {
    const int reached = check_pixels_against_render({}, 16, 9);
    CHECK(reached > 60);  // most of the grid lands on the spheres and the floor
}

TEST_CASE("pixel: the tea set's explained pixels are render's") {
    if (!have_asset(kTea)) return;
    CHECK(check_pixels_against_render(kTeaFlags, 12, 8) > 15);  // the teapot fills the middle
}

TEST_CASE("pixel: NormalTangentTest's explained pixels are render's") {
    if (!have_asset(kNormalTangent)) return;
    CHECK(check_pixels_against_render(kNormalTangentFlags, 10, 8) > 30);
}

TEST_CASE("pixel: under an --env map with --energy conserve, the explained pixels are render's") {
    const std::string venice = kAssets + "/venice-sunset-1k/venice_sunset_1k.hdr";
    if (!have_asset(venice)) return;
    const std::vector<std::string> flags = {"--size", "160x90", "--env", venice, "--env-rotate", "40",
                                            "--energy", "conserve", "--brdf", "gltf"};
    CHECK(check_pixels_against_render(flags, 12, 6) > 20);  // --msaa 4: edge samples resolve to the sky
    std::vector<std::string> one = flags;
    for (const char* f : {"--msaa", "1", "--background", "blur"}) one.push_back(f);
    CHECK(check_pixels_against_render(one, 12, 6) > 20);
}

TEST_CASE("pixel: with shadows on and blended glass, the explained pixels are render's, with the shadow lookups and the blend order") {
    CHECK(check_pixels_against_render({"--size", "320x180", "--shadows", "on", "--shadow-size", "512",
                                       "--point", "0.5,2.5,1.5:4,4,4"}, 12, 7) > 40);
    const std::string glass = std::string(PRAST_SOURCE_DIR) + "/docs/glass.obj";
    const std::vector<std::string> flags = {glass, "--size", "320x180", "--shadows", "on", "--shadow-size", "512",
                                            "--eye", "0.6,2.4,4.4", "--target", "0,0.5,-0.3"};
    CHECK(check_pixels_against_render(flags, 12, 7) > 40);
    // The green pane over the floor: one blended fragment over the floor,
    // whose sun is looked up in its shadow map.
    CliSandbox box;
    const CliRun r = run_step(box, flags, "pixel 160 125\n");
    REQUIRE(r.code == 0);
    CHECK(r.out.find("blend #1, shader out") != std::string::npos);
    CHECK(r.out.find("out * alpha + previous * (1 - alpha) = ") != std::string::npos);
    CHECK(r.out.find("shadow map: texel (") != std::string::npos);
    CHECK(r.out.find("PCF: 3x3 bilinear taps") != std::string::npos);
}

TEST_CASE("pixel: with 1 and 8 samples per pixel too, the explained pixels are render's") {
    for (const char* msaa : {"1", "8"}) {
        INFO("--msaa " << msaa);
        CHECK(check_pixels_against_render({"--size", "480x270", "--msaa", msaa}, 16, 9) > 60);
    }
}

TEST_CASE("verify: every recomputed number equals the pipeline's") {
    std::vector<std::vector<std::string>> scenes = {{}, {"--near", "6.5", "--far", "20"}, {"--msaa", "1"},
                                                    {"--msaa", "8", "--size", "640x360"}};
    if (have_asset(kTea)) scenes.push_back(kTeaFlags);
    if (have_asset(kNormalTangent)) scenes.push_back(kNormalTangentFlags);
    for (const auto& flags : scenes) {
        CliSandbox box;
        const CliRun r = run_step(box, flags, "verify\n");
        INFO(r.out << r.err);
        CHECK(r.code == 0);
        CHECK(r.out.find("verify: ok, all identical") != std::string::npos);
    }
}

TEST_CASE("upto: all triangles give render's image, none the cleared frame") {
    CliSandbox box;
    // With a black background (the built-in sky otherwise), no triangle is a black frame.
    REQUIRE(box.run_exe(kRender, {"--size", "320x180", "--background", "black", "-o", "r.png"}).code == 0);
    const CliRun r = run_step(box, {"--size", "320x180", "--background", "black"},
                              "upto 98432 all.png\nupto 0 none.png\nupto 50000\n");
    REQUIRE(r.code == 0);
    CHECK(r.out.find("upto 50000: wrote upto-50000.png") != std::string::npos);
    const Rgb8 want = load_rgb8(box.path("r.png")), all = load_rgb8(box.path("all.png"));
    const Rgb8 none = load_rgb8(box.path("none.png")), half = load_rgb8(box.path("upto-50000.png"));
    REQUIRE(!all.empty());
    CHECK(all.rgb == want.rgb);
    CHECK(none.mean() == 0.0);
    CHECK(half.mean() > 0.0);
    CHECK(half.rgb != want.rgb);
}

TEST_CASE("--out: every stage as a PNG and an index.html; the final stage is render's image") {
    CliSandbox box;
    // A magenta background (the built-in sky otherwise), so that render's
    // empty pixels can be told from drawn ones below (a metal seen exactly
    // edge-on under the sky alone is black).
    REQUIRE(box.run_exe(kRender, {"--size", "320x180", "--background", "1,0,1", "-o", "r.png"}).code == 0);
    const CliRun r = box.run_exe(kStep, {"--size", "320x180", "--background", "1,0,1", "--out", "stages"});
    REQUIRE(r.code == 0);
    const std::string index = read_text(box.work() / "stages" / "index.html");
    const char* kStages[] = {"vertices", "wireframe", "bins", "depth", "overdraw", "shaded", "msaa", "quad_overdraw",
                             "triangle_size",
                             "nan", "albedo", "normal", "roughness", "metallic", "occlusion", "mip", "D", "F", "G",
                             "diffuse", "specular", "final"};
    for (const char* name : kStages) {
        INFO(name);
        const Rgb8 img = load_rgb8(box.path(std::string("stages/") + name + ".png"));
        CHECK(img.width == 320);
        CHECK(img.height == 180);
        CHECK(index.find(std::string("src=\"") + name + ".png\"") != std::string::npos);
    }
    CHECK(index.find("http") == std::string::npos);  // nothing to fetch: opens offline
    const Rgb8 want = load_rgb8(box.path("r.png")), final = load_rgb8(box.path("stages/final.png"));
    CHECK(final.rgb == want.rgb);
    // No NaN, infinity or negative value in the built-in frame: all grey.
    const Rgb8 nan = load_rgb8(box.path("stages/nan.png"));
    for (std::size_t i = 0; i < nan.rgb.size(); ++i) REQUIRE(nan.rgb[i] == 64);
    // Depth and albedo are black exactly where render drew the background.
    const Rgb8 depth = load_rgb8(box.path("stages/depth.png")), albedo = load_rgb8(box.path("stages/albedo.png"));
    int background = 0;
    for (int y = 0; y < 180; ++y)
        for (int x = 0; x < 320; ++x) {
            const std::uint8_t* bg = want.at(0, 0);  // the top-left corner shows the background
            const bool empty = want.at(x, y)[0] == bg[0] && want.at(x, y)[1] == bg[1] && want.at(x, y)[2] == bg[2];
            background += empty;
            if (empty) CHECK(albedo.at(x, y)[0] + albedo.at(x, y)[1] + albedo.at(x, y)[2] == 0);
            else CHECK(albedo.at(x, y)[0] + albedo.at(x, y)[1] + albedo.at(x, y)[2] > 0);
            if (empty) CHECK(depth.at(x, y)[0] == 0);
        }
    CHECK(background > 1000);
    // A file where the directory should be: one line, exit 1.
    write_text(box.work() / "afile", "x");
    const CliRun bad = box.run_exe(kStep, {"--size", "32x18", "--out", "afile"});
    CHECK(bad.code == 1);
    CHECK(bad.err.find("afile") != std::string::npos);
}

TEST_CASE("stage wireframe: set-up triangles white, clipped pieces orange, culled dark blue, degenerate magenta") {
    // The colours as stepper/stages.cpp writes them (linear * 255, no sRGB).
    const std::uint8_t kWhite[3] = {255, 255, 255}, kOrange[3] = {255, 140, 26}, kBlue[3] = {38, 51, 153},
                       kMagenta[3] = {255, 0, 255};
    auto count = [](const Rgb8& img, const std::uint8_t* c) {
        int n = 0;
        for (std::size_t i = 0; i < img.rgb.size(); i += 3) n += std::memcmp(&img.rgb[i], c, 3) == 0;
        return n;
    };
    CliSandbox box;
    REQUIRE(run_step(box, {"--size", "320x180"}, "stage wireframe whole.png\n").code == 0);
    REQUIRE(run_step(box, {"--size", "320x180", "--near", "6.5", "--far", "20"}, "stage wireframe cut.png\n").code == 0);
    const Rgb8 whole = load_rgb8(box.path("whole.png")), cut = load_rgb8(box.path("cut.png"));
    REQUIRE(!whole.empty());
    REQUIRE(!cut.empty());
    // Nothing is clipped in the built-in frame; the near plane through the
    // floor clips some triangles, drawn in their own colour.
    CHECK(count(whole, kOrange) == 0);
    CHECK(count(cut, kOrange) > 100);
    for (const Rgb8* img : {&whole, &cut}) {
        CHECK(count(*img, kWhite) > 1000);
        CHECK(count(*img, kBlue) > 0);     // back faces seen past the silhouettes
        CHECK(count(*img, kMagenta) > 0);  // the scene's degenerate triangles
    }
}

TEST_CASE("--out: names from the model reach index.html escaped") {
    CliSandbox box;
    write_text(box.work() / "<i>&x.obj", "o <script>alert(1)</script>\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
    const CliRun r = box.run_exe(kStep, {"--size", "32x18", "<i>&x.obj", "--out", "o"});
    REQUIRE(r.code == 0);
    const std::string index = read_text(box.work() / "o" / "index.html");
    CHECK(index.find("<i>") == std::string::npos);
    CHECK(index.find("&lt;i&gt;&amp;x.obj") != std::string::npos);
}

TEST_CASE("sessions: the built-in scene, step by step") {
    check_transcript("builtin", {});
}

TEST_CASE("sessions: a near plane through the scene clips triangles") {
    check_transcript("clipped", {"--near", "6.5", "--far", "20"});
}

TEST_CASE("sessions: spheres in front of spheres, the visibility pass and the samples") {
    check_transcript("side", {"--size", "320x180", "--eye", "8,2.2,0.6", "--target", "0,1.9,0"});
}

TEST_CASE("sessions: bad commands get one line each and the session goes on") {
    CliSandbox box;
    const std::string long_word(5000, 'x');
    const CliRun r = run_step(box, {"--size", "160x90"},
                              "bogus\npixel\npixel 1\npixel -1 0\npixel 160 0\npixel 0 90\npixel a b\n"
                              "pixel 99999999999999999999 0\ntri\ntri 1e3\ntri -5\ntri 98432\ntile 3 0\n"
                              "upto 98433\nupto 5 /nonexistent-dir/x.png\nstage nope\nframe extra\n" +
                                  long_word + "\n\n   \n# a comment\npixel 80 45\n");
    CHECK(r.code == 1);
    const std::vector<std::string> lines = lines_of(r.out);
    int errors = 0;
    for (const std::string& l : lines)
        if (l.rfind("error: ", 0) == 0) {
            ++errors;
            CHECK(l.size() < 200);
        }
    CHECK(errors == 18);
    CHECK(r.out.find("srgb8 ") != std::string::npos);  // the last command still ran
    CHECK(r.err.empty());
}

TEST_CASE("flags: step takes every flag of render's --help, or refuses it") {
    // A render flag step neither lists nor refuses would be parsed and then
    // ignored, and step would explain a frame render does not draw: a new
    // flag must reach FrameRequest (apps/frame_request.h) and step's --help,
    // or join kNotForStep in apps/step.cpp.
    auto flags = [](const std::string& help) {
        std::vector<std::string> out;
        for (std::size_t i = help.find("--"); i != std::string::npos; i = help.find("--", i + 2)) {
            std::size_t e = i + 2;
            while (e < help.size() && (std::isalnum(static_cast<unsigned char>(help[e])) || help[e] == '-')) ++e;
            if (e > i + 2) out.push_back(help.substr(i, e - i));
        }
        return out;
    };
    CliSandbox box;
    const CliRun render_help = box.run_exe(kRender, {"--help"}), step_help = box.run_exe(kStep, {"--help"});
    REQUIRE(render_help.code == 0);
    REQUIRE(step_help.code == 0);
    const std::vector<std::string> listed = flags(step_help.out);
    // render-only: one frame has no turntable, output file, repeat, stats or
    // debug view; --samples belongs to --ibl reference, which step refuses;
    // step never reads outside the model's folder (it may serve what it reads).
    const std::vector<std::string> refused = {"--output", "--frames", "--orbit", "--frame-range", "--repeat",
                                              "--view", "--stats", "--allow-outside-paths", "--fps", "--list"};
    for (const std::string& f : flags(render_help.out)) {
        INFO("render flag " << f);
        if (std::find(listed.begin(), listed.end(), f) != listed.end() || f == "--samples") continue;
        REQUIRE(std::find(refused.begin(), refused.end(), f) != refused.end());
        const CliRun r = box.run_exe(kStep, {f, "1"});
        CHECK(r.code == 2);
        CHECK(r.err.find("not a step option") != std::string::npos);
    }
}

TEST_CASE("flags: render's flags that make no sense for one frame, and bad files") {
    CliSandbox box;
    for (const char* flag : {"--frames", "--view", "-o", "--repeat", "--stats"}) {
        const CliRun r = box.run_exe(kStep, {flag, "2"});
        CHECK(r.code == 2);
        CHECK(r.err.find("not a step option") != std::string::npos);
    }
    CHECK(box.run_exe(kStep, {"--port", "80"}).code == 2);
    CHECK(box.run_exe(kStep, {"--size", "0x5"}).code == 2);
    const CliRun missing = box.run_exe(kStep, {"no-such-file.glb"});
    CHECK(missing.code == 1);
    CHECK(missing.err.find("no-such-file.glb") != std::string::npos);
    const CliRun help = box.run_exe(kStep, {"--help"});
    CHECK(help.code == 0);
    CHECK(help.out.find("usage: step") == 0);
    const CliRun pixel = box.run_exe(kStep, {"--size", "160x90", "--pixel", "80,60"});
    CHECK(pixel.code == 0);
    CHECK(pixel_answers(pixel.out).size() == 1);
}

} // TEST_SUITE

TEST_SUITE("readme") {

// The README's first paragraph names what scripts/install-deps.sh installs:
// the same packages, so a reader who installs by hand gets a working build.
TEST_CASE("README: the install paragraph lists exactly the packages of scripts/install-deps.sh") {
    const std::string readme = read_text(std::string(PRAST_SOURCE_DIR) + "/README.md");
    const std::string script = read_text(std::string(PRAST_SOURCE_DIR) + "/scripts/install-deps.sh");
    auto words = [](const std::string& text) {
        std::vector<std::string> out;
        std::string w;
        for (char c : text + " ") {
            if (c == ' ' || c == '\n' || c == '`' || c == '\t') {
                if (!w.empty()) out.push_back(w);
                w.clear();
            } else {
                w += c;
            }
        }
        return out;
    };
    // The script: the words between PACKAGES=" and the closing quote.
    const std::size_t a = script.find("PACKAGES=\"");
    REQUIRE(a != std::string::npos);
    const std::size_t b = script.find('"', a + 10);
    REQUIRE(b != std::string::npos);
    std::vector<std::string> want = words(script.substr(a + 10, b - a - 10));
    // The README: the words after "it installs" up to the sentence's end.
    const std::size_t c = readme.find("it installs ");
    REQUIRE(c != std::string::npos);
    const std::size_t d = readme.find('.', c);
    std::vector<std::string> got = words(readme.substr(c + 12, d - c - 12));
    std::sort(want.begin(), want.end());
    std::sort(got.begin(), got.end());
    CHECK(want.size() >= 12);
    CHECK(got == want);
}

} // TEST_SUITE

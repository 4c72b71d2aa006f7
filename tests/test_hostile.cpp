// Hostile input: every class of attack we know of, each made
// by the test itself in a scratch directory and run where a user meets it,
// mostly through the built `render` binary: references that leave the
// model's folder (../, percent-encoded, backslashes, absolute, symbolic
// links, /etc/passwd, /dev/zero, /proc/self/pagemap), FIFOs, a truncated
// run-length .hdr, a 2^28-element accessor, 200 spellings of one MTL, 100,000
// missing MTLs, control characters in names, 255-byte output names, signals
// during a render, thread creation failing, running out of memory inside a
// pool task, absurd coordinates; and the fuzzers' findings
// (tests/fuzz-regressions/). Anything that could hang runs under a watchdog
// (timeout(1) or alarm(2) in a child), so a hang fails the case instead of
// stalling the suite; no case measures time.
#include <doctest/doctest.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <csignal>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <functional>
#include <new>
#include <stdexcept>
#include <string>
#include <tuple>
#include <vector>

#include <fcntl.h>
#include <poll.h>
#include <sys/inotify.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <stb_image.h>
#include <stb_image_write.h>

#include "fuzz/png_craft.h"
#include "fuzz/targets.h"
#include "raster/thread_pool.h"
#include "scene/camera.h"
#include "scene/file_access.h"
#include "scene/hdr_guard.h"
#include "scene/image.h"
#include "scene/load_scene.h"
#include "scene/messages.h"
#include "tests/cli_util.h"
#include "tests/scratch.h"

using namespace prast;
using namespace prast::cli_test;

namespace {

namespace fs = std::filesystem;

// ---------------------------------------------------------------- helpers

// Runs fn in a forked child under alarm(seconds): returns the child's exit
// code, or 128 + the signal that ended it (SIGALRM: it hung).
int in_child(const std::function<int()>& fn, unsigned seconds = 60) {
    std::fflush(nullptr);
    const pid_t pid = fork();
    REQUIRE(pid >= 0);
    if (pid == 0) {
        alarm(seconds);
        int code = 3;
        try {
            code = fn();
        } catch (...) {
            code = 4;  // anything but LoadError escaping is a defect
        }
        _exit(code);
    }
    int status = 0;
    while (waitpid(pid, &status, 0) < 0 && errno == EINTR) {}
    if (WIFEXITED(status)) return WEXITSTATUS(status);
    return 128 + WTERMSIG(status);
}

// render with a watchdog: killed after 60 s (exit 137), so a hang fails.
CliRun render(const CliSandbox& box, const std::vector<std::string>& args, const std::string& setup = "") {
    std::vector<std::string> all = {"-s", "KILL", "60", PRAST_RENDER_EXE};
    all.insert(all.end(), args.begin(), args.end());
    return box.run_exe("timeout", all, setup);
}

// A triangle with UVs facing +Z that fills the middle of a framed image,
// using material `a` (from m.mtl in kTriangleObj).
#define PRAST_TRIANGLE_BODY                 \
    "v -1 -1 0\nv 1 -1 0\nv 0 1 0\n"        \
    "vt 0 0\nvt 1 0\nvt 0.5 1\n"            \
    "vn 0 0 1\n"                            \
    "usemtl a\n"                            \
    "f 1/1/1 2/2/1 3/3/1\n"
const char* const kTriangleBody = PRAST_TRIANGLE_BODY;
const char* const kTriangleObj = "mtllib m.mtl\n" PRAST_TRIANGLE_BODY;

const std::vector<std::string> kSmall = {"--size", "48x48", "--sun", "0,0,1:1,1,1", "--ambient", "0.2,0.2,0.2"};

std::vector<std::string> with(std::vector<std::string> a, const std::vector<std::string>& b) {
    a.insert(a.end(), b.begin(), b.end());
    return a;
}

// A w x h PNG of one colour.
void write_png(const std::string& path, int w, int h, unsigned char r, unsigned char g, unsigned char b) {
    std::vector<unsigned char> px(std::size_t(w) * h * 3);
    for (std::size_t i = 0; i < px.size(); i += 3) {
        px[i] = r;
        px[i + 1] = g;
        px[i + 2] = b;
    }
    REQUIRE(stbi_write_png(path.c_str(), w, h, 3, px.data(), w * 3) != 0);
}

// The centre pixel of a render: red when the (red) texture was read.
bool centre_is_red(const std::string& png) {
    const Rgb8 img = load_rgb8(png);
    REQUIRE(!img.empty());
    const std::uint8_t* c = img.at(img.width / 2, img.height / 2);
    return c[0] > 40 && c[0] > 3 * c[1] && c[0] > 3 * c[2];
}

bool has_line_with(const std::string& text, const std::string& a, const std::string& b = "") {
    for (const std::string& line : lines_of(text))
        if (line.find(a) != std::string::npos && line.find(b) != std::string::npos) return true;
    return false;
}

// Every stderr line is one of render's own: no forged line, no raw control byte.
void check_clean_stderr(const std::string& err) {
    for (const std::string& line : lines_of(err)) {
        CAPTURE(line);
        CHECK(line.rfind("render: ", 0) == 0);
        CHECK(line.rfind("render: error", 0) != 0);
        for (char c : line) CHECK((static_cast<unsigned char>(c) >= 0x20 && c != 0x7F));
    }
}

// A glTF triangle (positions in a data URI), optionally with an image uri
// used as base colour, and an extra buffer uri that must load.
std::string gltf_triangle(const std::string& image_uri, const std::string& extra_buffer_uri = "",
                          const std::string& material_name = "m") {
    // base64 of the 36 bytes of (-1,-1,0), (1,-1,0), (0,1,0) as floats.
    const std::string positions = "AACAvwAAgL8AAAAAAACAPwAAgL8AAAAAAAAAAAAAgD8AAAAA";
    std::string j = R"({"asset":{"version":"2.0"},"scenes":[{"nodes":[0]}],"nodes":[{"mesh":0}],)"
                    R"("meshes":[{"primitives":[{"attributes":{"POSITION":0,"TEXCOORD_0":1},"material":0}]}],)"
                    R"("buffers":[{"byteLength":60,"uri":"data:application/octet-stream;base64,)" +
                    positions + R"(AAAAAAAAAAAAAIA/AAAAAAAAAD8AAIA/"})";
    if (!extra_buffer_uri.empty()) j += R"(,{"byteLength":4,"uri":")" + extra_buffer_uri + R"("})";
    j += R"(],"bufferViews":[{"buffer":0,"byteLength":36},{"buffer":0,"byteOffset":36,"byteLength":24}],)"
         R"("accessors":[{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3"},)"
         R"({"bufferView":1,"componentType":5126,"count":3,"type":"VEC2"}],)";
    j += R"("materials":[{"name":")" + material_name + R"(","pbrMetallicRoughness":{"metallicFactor":0)";
    if (!image_uri.empty()) j += R"(,"baseColorTexture":{"index":0})";
    j += "}}]";
    if (!image_uri.empty()) j += R"(,"textures":[{"source":0}],"images":[{"uri":")" + image_uri + R"("}])";
    return j + "}";
}

// Radiance bytes as stb_image_write makes them (run-length scanlines for
// widths 8 and up).
std::vector<unsigned char> hdr_bytes(int w, int h) {
    std::vector<float> px(std::size_t(w) * h * 3);
    for (std::size_t i = 0; i < px.size(); ++i) px[i] = (i / 3 % 4 == 0) ? 2.0f : 0.25f * float(i % 5);
    std::vector<unsigned char> out;
    stbi_write_hdr_to_func(
        [](void* ctx, void* data, int size) {
            auto* o = static_cast<std::vector<unsigned char>*>(ctx);
            o->insert(o->end(), static_cast<unsigned char*>(data), static_cast<unsigned char*>(data) + size);
        },
        &out, w, h, 3, px.data());
    return out;
}

std::size_t header_end(const std::vector<unsigned char>& hdr) {
    // After the resolution line, the line after the blank one.
    const std::string s(hdr.begin(), hdr.end());
    const std::size_t blank = s.find("\n\n");
    return s.find('\n', blank + 2) + 1;
}

} // namespace

TEST_SUITE("hostile") {

// ---------------------------------------------------------------- messages

TEST_CASE("printable escapes control characters, keeps UTF-8, and is idempotent") {
    CHECK(printable("plain name.png") == "plain name.png");
    CHECK(printable("a\nb") == "a\\nb");
    CHECK(printable("\x1b[31mred") == "\\e[31mred");
    CHECK(printable(std::string("nul\0x", 5)) == "nul\\x00x");
    CHECK(printable("tab\tcr\r\x7f") == "tab\\tcr\\r\\x7F");
    CHECK(printable("caf\xc3\xa9") == "caf\xc3\xa9");          // U+00E9 stays
    CHECK(printable("\xc2\x9b" "2J") == "\\xC2\\x9B2J");        // U+009B (C1 CSI) does not
    CHECK(printable("\xe2\x80\xae" "gnp.exe") == "\\xE2\\x80\\xAEgnp.exe");  // bidi override
    CHECK(printable("\xff\xfe") == "\\xFF\\xFE");               // not UTF-8
    CHECK(printable("\xe2\x82") == "\\xE2\\x82");                // truncated sequence
    const std::string nasty = "x\n\x1b]0;title\x07\xc2\x85y\\z";
    CHECK(printable(printable(nasty)) == printable(nasty));
}

TEST_CASE("warnings: five of a kind, then one line with the count") {
    WarningLog log;
    for (int i = 0; i < 1000; ++i) log.add("m.obj: texture 'f" + std::to_string(i) + ".png' not found");
    log.add("m.obj: material 'x': unknown conductor 'Pc tin' ignored");
    const std::vector<std::string> lines = log.lines();
    REQUIRE(lines.size() == 7);
    CHECK(lines[0] == "m.obj: texture 'f0.png' not found");
    CHECK(lines[4] == "m.obj: texture 'f4.png' not found");
    CHECK(lines[5] == "m.obj: material 'x': unknown conductor 'Pc tin' ignored");
    CHECK(lines[6] == "995 more warnings like: m.obj: texture 'f5.png' not found");
    CHECK(log.total() == 1001);
    CHECK(warning_kind("node 12: light 3 out of range") == warning_kind("node 7: light 99 out of range"));
    CHECK(warning_kind("image 'a' bad") != warning_kind("image 'a' missing"));
}

// ---------------------------------------------------------------- confinement

TEST_CASE("OBJ/MTL references that leave the model's folder are refused; --allow-outside-paths reads them") {
    CliSandbox box;
    fs::create_directories(box.work() / "model" / "sub");
    const std::string secret = box.path("secret.png");
    write_png(secret, 4, 4, 255, 0, 0);
    write_png(box.path("model/inside.png"), 4, 4, 255, 0, 0);
    write_text(box.path("model/m.obj"), kTriangleObj);
    fs::create_symlink("../secret.png", box.work() / "model" / "link.png");
    fs::create_directory_symlink("..", box.work() / "model" / "up");
    fs::create_symlink(secret, box.work() / "model" / "sub" / "abslink.png");
    fs::create_symlink("inside.png", box.work() / "model" / "good-link.png");

    struct Case {
        std::string ref;
        const char* rule;  // words of the refusal
    };
    const Case cases[] = {
        {"../secret.png", "climbs out of the model's folder"},
        {"..\\secret.png", "climbs out of the model's folder"},
        {"sub/../../secret.png", "climbs out of the model's folder"},
        {"sub\\..\\..\\secret.png", "climbs out of the model's folder"},
        {secret, "an absolute path outside the model's folder"},
        {"link.png", "a symbolic link leads outside the model's folder"},
        {"up/secret.png", "a symbolic link leads outside the model's folder"},
        {"sub/abslink.png", "a symbolic link leads outside the model's folder"},
        {"/etc/passwd", "an absolute path outside"},
        {"/dev/zero", "an absolute path outside"},
        {"/proc/self/pagemap", "an absolute path outside"},
    };
    for (const Case& c : cases) {
        CAPTURE(c.ref);
        write_text(box.path("model/m.mtl"), "newmtl a\nmap_Kd " + c.ref + "\n");
        const CliRun r = render(box, with({"model/m.obj", "-o", "out.png"}, kSmall));
        CHECK(r.code == 0);
        CHECK(has_line_with(r.err, "render: warning: model/m.obj: material 'a': map_Kd '" + c.ref + "' refused: ",
                            c.rule));
        CHECK(has_line_with(r.err, "--allow-outside-paths"));
        CHECK(!centre_is_red(box.path("out.png")));  // nothing of the file reached the pixels
    }

    // Inside the folder, also through a symbolic link that stays inside: read.
    for (const std::string& ref : std::vector<std::string>{"inside.png", "sub/../inside.png", "good-link.png", "./sub/..\\inside.png"}) {
        CAPTURE(ref);
        write_text(box.path("model/m.mtl"), "newmtl a\nmap_Kd " + ref + "\n");
        const CliRun r = render(box, with({"model/m.obj", "-o", "out.png"}, kSmall));
        CHECK(r.code == 0);
        CHECK(r.err.find("warning") == std::string::npos);
        CHECK(centre_is_red(box.path("out.png")));
    }

    // --allow-outside-paths lifts the folder rule, never the regular-file rule.
    for (const std::string& ref : std::vector<std::string>{"../secret.png", "link.png", secret}) {
        CAPTURE(ref);
        write_text(box.path("model/m.mtl"), "newmtl a\nmap_Kd " + ref + "\n");
        const CliRun r = render(box, with({"model/m.obj", "-o", "out.png", "--allow-outside-paths"}, kSmall));
        CHECK(r.code == 0);
        CHECK(r.err.find("warning") == std::string::npos);
        CHECK(centre_is_red(box.path("out.png")));
    }
    const std::pair<const char*, const char*> specials[] = {
        {"/dev/zero", "not a regular file (a character device)"},
        {"/proc/self/pagemap", "on a kernel pseudo file system"},
        {"/proc/self/environ", "on a kernel pseudo file system"},
        {"/tmp", "not a regular file (a directory)"},
    };
    for (const auto& [ref, rule] : specials) {
        CAPTURE(ref);
        write_text(box.path("model/m.mtl"), std::string("newmtl a\nmap_Kd ") + ref + "\n");
        const CliRun r = render(box, with({"model/m.obj", "-o", "out.png", "--allow-outside-paths"}, kSmall));
        CHECK(r.code == 0);
        CHECK(has_line_with(r.err, std::string("map_Kd '") + ref + "' refused: ", rule));
    }

    // mtllib follows the same rule.
    write_text(box.path("evil.mtl"), "newmtl a\nmap_Kd model/inside.png\n");
    write_text(box.path("model/e.obj"), std::string("mtllib ../evil.mtl\n") + kTriangleBody);
    const CliRun r = render(box, with({"model/e.obj", "-o", "out.png"}, kSmall));
    CHECK(r.code == 0);
    CHECK(has_line_with(r.err, "material library '../evil.mtl' refused: climbs out of the model's folder"));
}

TEST_CASE("the library: LoadOptions and FileScope apply the same rule") {
    test::TempDir dir("hostile_lib");
    fs::create_directories(dir.path / "m");
    write_png(dir.file("out.png"), 2, 2, 1, 2, 3);
    write_png(dir.file("m/in.png"), 2, 2, 1, 2, 3);
    test::write_text(dir.file("m/m.mtl"), "newmtl a\nmap_Kd ../out.png\nnewmtl b\nmap_Kd in.png\nmap_Ke ./in.png\n");
    test::write_text(dir.file("m/m.obj"), std::string(kTriangleObj) + "usemtl b\nf 3 2 1\n");
    const Scene confined = load_obj(dir.file("m/m.obj"));
    REQUIRE(confined.images.size() == 1);  // in.png once, however spelled
    CHECK(confined.images[0].path == fs::canonical(dir.path / "m" / "in.png").string());
    REQUIRE(confined.warnings.size() == 1);
    CHECK(confined.warnings[0].find("map_Kd '../out.png' refused: climbs out of the model's folder") !=
          std::string::npos);
    LoadOptions allow;
    allow.allow_outside_paths = true;
    const Scene open = load_obj(dir.file("m/m.obj"), allow);
    CHECK(open.images.size() == 2);
    CHECK(open.warnings.empty());

    FileScope scope(dir.file("m/m.obj"), false);
    CHECK(scope.root() == fs::canonical(dir.path / "m").string());
    CHECK(scope.resolve(scope.root(), "in.png").ok());
    CHECK(scope.resolve(scope.root(), "nope.png").missing);
    const FileScope::Resolved out = scope.resolve(scope.root(), "..\\out.png");
    CHECK(!out.ok());
    CHECK(out.outside);
    CHECK(scope.resolve(scope.root(), std::string("in.png\0x", 8)).refused == "the name holds a NUL byte");
}

TEST_CASE("glTF buffer and image uris stay in the model's folder, percent-encoded or not, and never in the current directory") {
    CliSandbox box;
    fs::create_directories(box.work() / "model");
    write_png(box.path("secret.png"), 4, 4, 255, 0, 0);
    write_png(box.path("model/inside.png"), 4, 4, 255, 0, 0);
    write_text(box.path("four.bin"), "abcd");
    write_text(box.path("model/four.bin"), "abcd");

    // Images: a warning, the render goes on without the texture.
    const std::string secret_abs = box.path("secret.png");
    for (const std::string& uri : std::vector<std::string>{"../secret.png", "%2e%2e%2fsecret.png", "%2E%2E/secret.png", "..%5csecret.png",
                                  "..\\\\secret.png", "sub%2F..%2F..%2Fsecret.png", secret_abs,
                                  "%2F" + secret_abs.substr(1)}) {
        CAPTURE(uri);
        write_text(box.path("model/t.gltf"), gltf_triangle(uri));
        const CliRun r = render(box, with({"model/t.gltf", "-o", "out.png"}, kSmall));
        CHECK(r.code == 0);
        CHECK(has_line_with(r.err, "render: warning: model/t.gltf: image 0 '", "' refused: "));
        CHECK(has_line_with(r.err, "the model's folder"));
        CHECK(!centre_is_red(box.path("out.png")));
    }
    write_text(box.path("model/t.gltf"), gltf_triangle("inside.png"));
    CliRun ok = render(box, with({"model/t.gltf", "-o", "out.png"}, kSmall));
    CHECK(ok.code == 0);
    CHECK(ok.err.find("warning") == std::string::npos);
    CHECK(centre_is_red(box.path("out.png")));
    write_text(box.path("model/t.gltf"), gltf_triangle("../secret.png"));
    ok = render(box, with({"model/t.gltf", "-o", "out.png", "--allow-outside-paths"}, kSmall));
    CHECK(ok.code == 0);
    CHECK(centre_is_red(box.path("out.png")));

    // Buffers: a buffer cannot be done without, so the load fails with the rule.
    for (const std::string& uri : std::vector<std::string>{"../four.bin", "%2e%2e%2ffour.bin", "..%5Cfour.bin", box.path("four.bin")}) {
        CAPTURE(uri);
        write_text(box.path("model/b.gltf"), gltf_triangle("", uri));
        const CliRun r = render(box, with({"model/b.gltf", "-o", "out2.png"}, kSmall));
        CHECK(r.code == 1);
        CHECK(lines_of(r.err).size() == 1);
        CHECK(r.err.find("render: model/b.gltf: buffer uri '") == 0);
        CHECK(r.err.find("refused: ") != std::string::npos);
        CHECK(!fs::exists(box.path("out2.png")));
    }
    write_text(box.path("model/b.gltf"), gltf_triangle("", "four.bin"));
    CHECK(render(box, with({"model/b.gltf", "-o", "out2.png"}, kSmall)).code == 0);

    // Missing next to the model but present in the current directory: not used.
    fs::create_directories(box.work() / "other");
    write_text(box.path("other/b.gltf"), gltf_triangle("", "four.bin"));
    write_text(box.path("other/t.gltf"), gltf_triangle("secret.png"));
    const CliRun cwd_buffer = render(box, with({"other/b.gltf", "-o", "out3.png"}, kSmall));
    CHECK(cwd_buffer.code == 1);
    CHECK(cwd_buffer.err.find("four.bin") != std::string::npos);
    const CliRun cwd_image = render(box, with({"other/t.gltf", "-o", "out3.png"}, kSmall));
    CHECK(cwd_image.code == 0);
    CHECK(has_line_with(cwd_image.err, "image 0 'secret.png' not found"));
    CHECK(!centre_is_red(box.path("out3.png")));
}

TEST_CASE("data: URIs stay allowed") {
    test::TempDir dir("hostile_data");
    // A 1x1 red PNG as a data URI: inside no folder, always fine.
    std::vector<unsigned char> png;
    const unsigned char red[3] = {255, 0, 0};
    stbi_write_png_to_func(
        [](void* ctx, void* data, int size) {
            auto* o = static_cast<std::vector<unsigned char>*>(ctx);
            o->insert(o->end(), static_cast<unsigned char*>(data), static_cast<unsigned char*>(data) + size);
        },
        &png, 1, 1, 3, red, 3);
    static const char* b64 = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    std::string enc;
    for (std::size_t i = 0; i < png.size(); i += 3) {
        const unsigned v = unsigned(png[i]) << 16 | (i + 1 < png.size() ? unsigned(png[i + 1]) << 8 : 0u) |
                           (i + 2 < png.size() ? unsigned(png[i + 2]) : 0u);
        enc += b64[v >> 18];
        enc += b64[v >> 12 & 63];
        enc += i + 1 < png.size() ? b64[v >> 6 & 63] : '=';
        enc += i + 2 < png.size() ? b64[v & 63] : '=';
    }
    test::write_text(dir.file("d.gltf"), gltf_triangle("data:image/png;base64," + enc));
    const Scene s = load_gltf(dir.file("d.gltf"));
    CHECK(s.warnings.empty());
    REQUIRE(s.images.size() == 1);
    CHECK(s.images[0].bytes == png);
}

TEST_CASE("FIFOs are never opened: buffer, image, mtllib, map and the model itself") {
    CliSandbox box;
    for (const char* name : {"fifo.bin", "fifo.png", "fifo.mtl", "fifo.obj"})
        REQUIRE(mkfifo(box.path(name).c_str(), 0600) == 0);
    write_png(box.path("t.png"), 2, 2, 9, 9, 9);

    write_text(box.path("b.gltf"), gltf_triangle("", "fifo.bin"));
    CliRun r = render(box, with({"b.gltf", "-o", "o.png"}, kSmall));
    CHECK(r.code == 1);
    CHECK(r.err == "render: b.gltf: buffer uri 'fifo.bin' refused: not a regular file (a FIFO)\n");

    write_text(box.path("i.gltf"), gltf_triangle("fifo.png"));
    r = render(box, with({"i.gltf", "-o", "o.png"}, kSmall));
    CHECK(r.code == 0);
    CHECK(has_line_with(r.err, "image 0 'fifo.png' refused: not a regular file (a FIFO)"));

    write_text(box.path("m.mtl"), "newmtl a\nmap_Kd fifo.png\n");
    write_text(box.path("m.obj"), kTriangleObj);
    r = render(box, with({"m.obj", "-o", "o.png"}, kSmall));
    CHECK(r.code == 0);
    CHECK(has_line_with(r.err, "map_Kd 'fifo.png' refused: not a regular file (a FIFO)"));

    write_text(box.path("f.obj"), std::string("mtllib fifo.mtl\n") + kTriangleBody);
    r = render(box, with({"f.obj", "-o", "o.png"}, kSmall));
    CHECK(r.code == 0);
    CHECK(has_line_with(r.err, "material library 'fifo.mtl' refused: not a regular file (a FIFO)"));

    r = render(box, with({"fifo.obj", "-o", "o.png"}, kSmall));
    CHECK(r.code == 1);
    CHECK(r.err == "render: fifo.obj: not a regular file (a FIFO), not read\n");

    // The library's reader, directly: no hang, a LoadError.
    CHECK(in_child([&] {
              try {
                  read_regular_file(box.path("fifo.bin"));
              } catch (const LoadError& e) {
                  return std::string(e.what()).find("a FIFO") != std::string::npos ? 0 : 1;
              }
              return 2;
          }) == 0);
}

TEST_CASE("the huge-page reader gives the vector reader's bytes and its messages") {
    prast::test::TempDir dir("huge_read");
    // Across 2 MiB (allocate_huge's aligned, rounded case) and below it.
    for (std::size_t n : {std::size_t(1), std::size_t(4097), (std::size_t(2) << 20) + 12345}) {
        std::vector<unsigned char> bytes(n);
        std::uint32_t x = 12345u + std::uint32_t(n);
        for (unsigned char& b : bytes) b = (x = x * 1664525u + 1013904223u) >> 24;
        const std::string path = dir.file("f" + std::to_string(n));
        prast::test::write_bytes(path, bytes);
        HugeBytes huge;
        read_regular_file(path, kMaxReadBytes, "", huge);
        CHECK(std::vector<unsigned char>(huge.begin(), huge.end()) == bytes);
        CHECK(read_regular_file(path) == bytes);
        if (n >= (std::size_t(2) << 20))
            CHECK(reinterpret_cast<std::uintptr_t>(huge.data()) % (std::uintptr_t(2) << 20) == 0);
    }
    prast::test::write_bytes(dir.file("empty"), {});
    const auto message = [](auto&& read) {
        try {
            read();
        } catch (const LoadError& e) {
            return std::string(e.what());
        }
        return std::string("no error");
    };
    HugeBytes huge;
    CHECK(message([&] { read_regular_file(dir.file("empty"), kMaxReadBytes, "e", huge); }) == "e: empty file");
    CHECK(message([&] { read_regular_file(dir.file("f4097"), 4096, "big", huge); }) ==
          "big: file too large (4097 bytes; the limit is 4096)");
    CHECK(message([&] { read_regular_file(dir.file("f4097"), 4096, "big"); }) ==
          message([&] { read_regular_file(dir.file("f4097"), 4096, "big", huge); }));
}

// ---------------------------------------------------------------- limits

TEST_CASE("a truncated run-length .hdr (CVE-2021-42715 in stb_image 2.27) is refused before stb sees it") {
    const std::vector<unsigned char> good = hdr_bytes(16, 4);
    int w = 0, h = 0;
    REQUIRE(check_hdr_data(good.data(), good.size(), w, h) == "");
    CHECK(w == 16);
    CHECK(h == 4);
    ImageSource src;
    src.bytes = good;
    src.name = "good.hdr";
    CHECK(decode_image(src, false).width == 16);

    // Every truncation inside the pixel data is refused, in a child with a
    // watchdog: before the guard, stb spun forever on these.
    const std::size_t data_start = header_end(good);
    REQUIRE(data_start < good.size());
    CHECK(in_child([&] {
              for (std::size_t n = data_start; n < good.size(); ++n) {
                  ImageSource cut;
                  cut.bytes.assign(good.begin(), good.begin() + std::ptrdiff_t(n));
                  cut.name = "cut.hdr";
                  try {
                      decode_image(cut, false);
                      return 1;  // decoded from missing data
                  } catch (const LoadError& e) {
                      if (std::string(e.what()).find("cut.hdr: cannot decode HDR image: ") != 0) return 2;
                  }
              }
              return 0;
          }) == 0);

    // A run of length 0, then nothing: the loop of the CVE.
    std::vector<unsigned char> zero(good.begin(), good.begin() + std::ptrdiff_t(data_start));
    for (unsigned char b : {2, 2, 0, 16, 0}) zero.push_back(b);
    CHECK(check_hdr_data(zero.data(), zero.size(), w, h).find("CVE-2021-42715") != std::string::npos);
    // A flat scanline after a run-length one (stb decodes it from the wrong
    // place): one run-length line of a 16x1 file, then 16 flat pixels.
    std::vector<unsigned char> two = hdr_bytes(16, 1);
    const std::size_t s2 = header_end(two);
    std::string header(two.begin(), two.begin() + std::ptrdiff_t(s2));
    header.replace(header.find("-Y 1"), 4, "-Y 2");
    std::vector<unsigned char> bad(header.begin(), header.end());
    bad.insert(bad.end(), two.begin() + std::ptrdiff_t(s2), two.end());
    for (int i = 0; i < 16; ++i) bad.insert(bad.end(), {200, 100, 50, 128});
    CHECK(check_hdr_data(bad.data(), bad.size(), w, h).find("flat after run-length") != std::string::npos);

    // Through render: a truncated .hdr as a texture is one warning, no hang.
    CliSandbox box;
    std::vector<unsigned char> cut(good.begin(), good.begin() + std::ptrdiff_t(data_start + 7));
    test::write_bytes(box.path("t.hdr"), cut);
    write_text(box.path("m.mtl"), "newmtl a\nmap_Kd t.hdr\n");
    write_text(box.path("m.obj"), kTriangleObj);
    const CliRun r = render(box, with({"m.obj", "-o", "o.png"}, kSmall));
    CHECK(r.code == 0);
    CHECK(has_line_with(r.err, "t.hdr: cannot decode HDR image: truncated pixel data", "(texture ignored)"));
}

namespace {

// A valid 16x16 baseline JPEG (stb_image_write, quality 90) and the offset
// of its first Huffman table segment (DHT), whose 16 code counts start 5
// bytes in.
std::vector<unsigned char> small_jpeg(std::size_t& dht) {
    std::vector<unsigned char> jpg;
    std::vector<unsigned char> px(16 * 16 * 3, 0);
    for (std::size_t i = 0; i < px.size(); ++i) px[i] = (unsigned char)(i * 7);
    stbi_write_jpg_to_func(
        [](void* ctx, void* data, int size) {
            auto* o = static_cast<std::vector<unsigned char>*>(ctx);
            o->insert(o->end(), static_cast<unsigned char*>(data), static_cast<unsigned char*>(data) + size);
        },
        &jpg, 16, 16, 3, px.data(), 90);
    dht = 0;
    for (std::size_t i = 0; i + 1 < jpg.size(); ++i)
        if (jpg[i] == 0xFF && jpg[i + 1] == 0xC4) {
            dht = i;
            break;
        }
    return jpg;
}

} // namespace

TEST_CASE("a JPEG whose Huffman table declares more than 256 codes is refused by libjpeg-turbo") {
    // A valid baseline JPEG, then the same with one DHT count raised (what
    // made stb_image 2.27 write past its tables, stb issue #1289).
    std::size_t dht = 0;
    const std::vector<unsigned char> jpg = small_jpeg(dht);
    ImageSource src;
    src.name = "ok.jpg";
    src.bytes = jpg;
    CHECK(decode_image(src, true).width == 16);

    REQUIRE(dht > 0);
    std::vector<unsigned char> bad = jpg;
    bad[dht + 5 + 15] = 255;  // the 16-bit code count of the first table
    src.bytes = bad;
    src.name = "bad.jpg";
    CHECK_THROWS_WITH_AS(decode_image(src, true), "bad.jpg: cannot decode JPEG image: Bogus Huffman table definition",
                         LoadError);
    int w = 0, h = 0;
    CHECK(!image_dimensions(src, w, h));  // the header read meets the table first
    // A small file claiming millions of texels (found by fuzz_jpeg: a decoder
    // fills made-up data for seconds) is refused from its header.
    src.name = "dense.jpg";
    src.bytes = test::read_bytes(std::string(PRAST_SOURCE_DIR) +
                                 "/tests/fuzz-regressions/jpeg/small-file-claims-3.7-million-texels");
    REQUIRE(src.bytes.size() == 1406);
    CHECK_THROWS_WITH_AS(decode_image(src, true),
                         "dense.jpg: cannot decode JPEG image: 2081x1791 texels from only 1406 bytes (a JPEG holds "
                         "at most 1024 texels a byte)",
                         LoadError);
}

// ---------------------------------------------------------------- PNG

namespace {

// fuzz/png_craft.h under the names used below.
using png_craft::zlib_stored;
const std::string& kPngSignature = png_craft::kSignature;
std::string png_chunk(const std::string& type, const std::string& data) { return png_craft::chunk(type, data); }
std::string png_ihdr(std::uint32_t w, std::uint32_t h, int depth, int colour, int interlace = 0) {
    return png_craft::ihdr(w, h, depth, colour, interlace);
}
std::string be32_bytes(std::uint32_t v) { return png_craft::be32(v); }
std::string png_rows(int w, int h, int bits, bool interlaced, const std::function<std::uint64_t(int, int)>& sample) {
    return png_craft::rows(w, h, bits, interlaced, sample);
}

std::vector<unsigned char> bytes_of(const std::string& s) { return {s.begin(), s.end()}; }

// decode_image on `png` named `name`: "" when it decodes, else the message.
std::string png_error(const std::string& name, const std::string& png) {
    ImageSource src;
    src.name = name;
    src.bytes = bytes_of(png);
    try {
        decode_image(src, false);
        return "";
    } catch (const LoadError& e) {
        return e.what();
    }
}

} // namespace

TEST_CASE("PNG kinds beyond the fast path decode to the right texels: interlaced, 16-bit, palette, 1-bit, tRNS") {
    const int w = 13, h = 11;
    const auto rgb = [](int x, int y) { return std::uint64_t((x * 19) & 0xFF) << 16 | std::uint64_t((y * 23) & 0xFF) << 8 | std::uint64_t((x * y) & 0xFF); };
    ImageSource src;
    src.name = "kinds.png";
    // Adam7 RGB: the same texels as the plain file (which takes the fast path).
    for (int interlace : {0, 1}) {
        CAPTURE(interlace);
        src.bytes = bytes_of(kPngSignature + png_ihdr(w, h, 8, 2, interlace) +
                             png_chunk("IDAT", zlib_stored(png_rows(w, h, 24, interlace == 1, rgb))) +
                             png_chunk("IEND", ""));
        const Image img = decode_image(src, false);
        REQUIRE(img.width == w);
        REQUIRE(img.height == h);
        REQUIRE(img.channels == 3);
        bool same = true;
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x)
                for (int c = 0; c < 3; ++c)
                    same = same && img.pixels[(std::size_t(y) * w + x) * 3 + c] == ((rgb(x, y) >> (16 - 8 * c)) & 0xFF);
        CHECK(same);
    }
    // 16-bit grey+alpha: linear floats v / 65535.
    const auto ga16 = [](int x, int y) { return std::uint64_t(x * 5000 + y) << 16 | std::uint64_t(65535 - y * 999); };
    src.bytes = bytes_of(kPngSignature + png_ihdr(w, h, 16, 4) +
                         png_chunk("IDAT", zlib_stored(png_rows(w, h, 32, false, ga16))) + png_chunk("IEND", ""));
    {
        const Image img = decode_image(src, false);
        REQUIRE(img.channels == 0);
        CHECK(img.at(7, 3).x == doctest::Approx((7 * 5000 + 3) / 65535.0).epsilon(1e-6));
        CHECK(img.at(7, 3).w == doctest::Approx((65535 - 3 * 999) / 65535.0).epsilon(1e-6));
    }
    // A 4-bit palette, then the same with tRNS (alpha per entry).
    std::string plte;
    for (int i = 0; i < 16; ++i) plte += {char(i * 16), char(255 - i * 16), char(i * 3)};
    const auto index = [](int x, int y) { return std::uint64_t((x + 3 * y) % 16); };
    const std::string pixels = png_chunk("IDAT", zlib_stored(png_rows(w, h, 4, false, index)));
    for (bool trns : {false, true}) {
        CAPTURE(trns);
        src.bytes = bytes_of(kPngSignature + png_ihdr(w, h, 4, 3) + png_chunk("PLTE", plte) +
                             (trns ? png_chunk("tRNS", std::string("\x00\x40\x80", 3)) : std::string()) + pixels +
                             png_chunk("IEND", ""));
        const Image img = decode_image(src, false);
        REQUIRE(img.channels == (trns ? 4 : 3));
        const std::size_t at = (std::size_t(5) * w + 4) * std::size_t(img.channels);  // index (4 + 15) % 16 = 3
        CHECK(int(img.pixels[at]) == 48);
        CHECK(int(img.pixels[at + 1]) == 207);
        CHECK(int(img.pixels[at + 2]) == 9);
        if (trns) {
            CHECK(int(img.pixels[3]) == 0);        // index 0: alpha 0
            CHECK(int(img.pixels[at + 3]) == 255);  // index 3: past the tRNS entries
        }
    }
    // 1-bit grey: 0 or 255.
    src.bytes = bytes_of(kPngSignature + png_ihdr(w, h, 1, 0) +
                         png_chunk("IDAT", zlib_stored(png_rows(w, h, 1, false, [](int x, int y) { return std::uint64_t((x + y) & 1); }))) +
                         png_chunk("IEND", ""));
    {
        const Image img = decode_image(src, false);
        REQUIRE(img.channels == 1);
        CHECK(int(img.pixels[0]) == 0);
        CHECK(int(img.pixels[1]) == 255);
        CHECK(int(img.pixels[std::size_t(w)]) == 255);
    }
}

TEST_CASE("hostile PNGs: one clean line naming the file and the problem, never a crash, a hang or a huge allocation") {
    const int w = 16, h = 8;
    const auto grey = [](int x, int y) { return std::uint64_t((x * 16 + y) & 0xFF); };
    const std::string rows = png_rows(w, h, 8, false, grey);
    const std::string head = kPngSignature + png_ihdr(w, h, 8, 0);
    const std::string good = head + png_chunk("IDAT", zlib_stored(rows)) + png_chunk("IEND", "");
    REQUIRE(png_error("good.png", good) == "");
    const std::string interlaced_head = kPngSignature + png_ihdr(w, h, 8, 0, 1);
    const std::string interlaced_idat = png_chunk("IDAT", zlib_stored(png_rows(w, h, 8, true, grey)));
    REQUIRE(png_error("good.png", interlaced_head + interlaced_idat + png_chunk("IEND", "")) == "");

    std::string bad_crc = good;
    bad_crc[head.size() + 8 + 20] ^= 0x10;  // a pixel byte inside the IDAT data
    std::string bad_crc_interlaced = interlaced_head + interlaced_idat;
    bad_crc_interlaced[interlaced_head.size() + 8 + 20] ^= 0x10;
    std::string bad_zlib_block = zlib_stored(rows);
    bad_zlib_block[2] = 0x07;  // block type 3: reserved
    std::string short_stream = zlib_stored(rows.substr(0, rows.size() / 2));
    const std::string absurd_length = be32_bytes(0x7FFFFFF0) + "tEXt" + "Comment";

    // name, file, what the message must say after "NAME: cannot decode PNG image: "
    const std::vector<std::tuple<std::string, std::string, std::string>> cases = {
        {"truncated-idat.png", good.substr(0, head.size() + 8 + 40), "truncated: the IDAT chunk at byte 33 claims 147 bytes, 36 are left"},
        {"truncated-interlaced.png", (interlaced_head + interlaced_idat).substr(0, interlaced_head.size() + 8 + 40), "truncated: the IDAT chunk at byte 33 claims"},
        {"huge-ihdr.png", kPngSignature + png_ihdr(16384, 16384, 8, 6) + png_chunk("IDAT", zlib_stored(rows)) + png_chunk("IEND", ""),
         "16384x16384 texels need at least 1073741824 bytes of pixel data, and 147 compressed bytes hold at most 152728"},
        {"huge-palette.png", kPngSignature + png_ihdr(16384, 16384, 1, 3) + png_chunk("PLTE", std::string(6, '\x7f')) + png_chunk("IDAT", zlib_stored(rows)) + png_chunk("IEND", ""),
         "16384x16384 texels need at least 33554432 bytes"},
        {"bad-crc.png", bad_crc, "CRC error in the IDAT chunk"},
        {"bad-crc-interlaced.png", bad_crc_interlaced, "IDAT"},
        {"bad-zlib-header.png", head + png_chunk("IDAT", "\x78\x02" + rows) + png_chunk("IEND", ""), "bad zlib header"},
        {"bad-zlib-block.png", head + png_chunk("IDAT", bad_zlib_block) + png_chunk("IEND", ""), "corrupt image data (zlib: invalid block type)"},
        {"short-zlib-stream.png", head + png_chunk("IDAT", short_stream) + png_chunk("IEND", ""), "not enough image data"},
        {"absurd-chunk-length.png", head + absurd_length + png_chunk("IDAT", zlib_stored(rows)), "truncated: the tEXt chunk at byte 33 claims 2147483632 bytes"},
        {"absurd-idat-length.png", head + be32_bytes(0xFFFFFFFF) + "IDAT" + zlib_stored(rows), "truncated: the IDAT chunk at byte 33 claims 4294967295 bytes"},
        {"empty-idat.png", head + png_chunk("IDAT", "") + png_chunk("IEND", ""), "truncated image data"},
        {"no-idat.png", head + png_chunk("IEND", ""), "IEND: out of place"},
        {"palette-without-plte.png", kPngSignature + png_ihdr(w, h, 8, 3) + png_chunk("IDAT", zlib_stored(rows)) + png_chunk("IEND", ""), "corrupt or truncated header"},
        {"bad-bit-depth.png", kPngSignature + png_ihdr(w, h, 5, 0) + png_chunk("IDAT", zlib_stored(rows)) + png_chunk("IEND", ""), "corrupt or truncated header"},
        {"truncated-16-bit.png", (kPngSignature + png_ihdr(w, h, 16, 0) + png_chunk("IDAT", zlib_stored(png_rows(w, h, 16, false, grey)))).substr(0, 90), "truncated: the IDAT chunk at byte 33 claims"},
        {"zero-width.png", kPngSignature + png_ihdr(0, h, 8, 0) + png_chunk("IDAT", zlib_stored(rows)) + png_chunk("IEND", ""), "corrupt or truncated header"},
        {"width-2-to-31.png", kPngSignature + png_ihdr(0x80000000u, 1, 8, 0) + png_chunk("IDAT", zlib_stored(rows)) + png_chunk("IEND", ""), "corrupt or truncated header"},
        {"bad-filter.png", head + png_chunk("IDAT", zlib_stored(std::string(1, '\x09') + rows.substr(1))) + png_chunk("IEND", ""), "bad row filter type 9"},
    };
    for (const auto& [name, file, why] : cases) {
        CAPTURE(name);
        std::string message;
        // In a child under a watchdog: a crash or a hang fails the case.
        const int code = in_child([&, name = name, file = file, why = why] {
            const std::string m = png_error(name, file);
            if (m.empty()) return 10;                                  // decoded from bad data
            if (m.find('\n') != std::string::npos) return 11;          // one line
            if (m.rfind(name + ": ", 0) != 0) return 12;               // names the file
            if (m.find(why) == std::string::npos) return 13;           // names the problem
            return 0;
        }, 30);
        CHECK(code == 0);
        if (code != 0) MESSAGE(png_error(name, file));
    }
}

TEST_CASE("a huge PNG header with little data is refused from the chunk lengths, also through render") {
    CliSandbox box;
    std::string rows(17, '\0');
    const std::string png = kPngSignature + png_ihdr(16384, 16384, 8, 6) + png_chunk("IDAT", zlib_stored(rows)) +
                            png_chunk("IEND", "");
    test::write_bytes(box.path("huge.png"), bytes_of(png));
    write_text(box.path("m.mtl"), "newmtl a\nmap_Kd huge.png\n");
    write_text(box.path("m.obj"), kTriangleObj);
    // The check comes before any decoder allocates the 1 GiB image.
    const CliRun r = render(box, with({"m.obj", "-o", "o.png"}, kSmall));
    CHECK(r.code == 0);
    CHECK(lines_of(r.err).size() == 1);
    CHECK(has_line_with(r.err, "huge.png: cannot decode PNG image: 16384x16384 texels need at least 1073741824 bytes",
                        "(texture ignored)"));
}

TEST_CASE("other formats stb_image reads (TGA) decode without a PNG signature to compare against") {
    // sniff_format() names no format for TGA: that path once compared a null
    // pointer with a string.
    std::vector<unsigned char> tga;
    const unsigned char px[2 * 2 * 3] = {255, 0, 0, 0, 255, 0, 0, 0, 255, 9, 9, 9};
    stbi_write_tga_to_func(
        [](void* ctx, void* data, int size) {
            auto* o = static_cast<std::vector<unsigned char>*>(ctx);
            o->insert(o->end(), static_cast<unsigned char*>(data), static_cast<unsigned char*>(data) + size);
        },
        &tga, 2, 2, 3, px);
    ImageSource src;
    src.name = "t.tga";
    src.bytes = tga;
    const Image img = decode_image(src, false);
    REQUIRE(img.channels == 3);
    CHECK(std::vector<unsigned char>(img.pixels.begin(), img.pixels.end()) ==
          std::vector<unsigned char>(px, px + sizeof px));
}

// ---------------------------------------------------------------- step and prast-diff

namespace {

// step with a watchdog, like render() above.
CliRun step(const CliSandbox& box, const std::vector<std::string>& args, const std::string& setup = "") {
    std::vector<std::string> all = {"-s", "KILL", "60", PRAST_STEP_EXE};
    all.insert(all.end(), args.begin(), args.end());
    return box.run_exe("timeout", all, setup);
}

CliRun prast_diff(const CliSandbox& box, const std::vector<std::string>& args) {
    std::vector<std::string> all = {"-s", "KILL", "60", PRAST_DIFF_EXE};
    all.insert(all.end(), args.begin(), args.end());
    return box.run_exe("timeout", all);
}

const std::vector<std::string> kStepSmall = {"--size", "48x48", "--sun", "0,0,1:1,1,1", "--pixel", "24,24"};

} // namespace

TEST_CASE("step loads scenes under render's rules: confined references, FIFOs, accessor budgets, hostile images") {
    CliSandbox box;
    fs::create_directories(box.work() / "model");
    write_png(box.path("secret.png"), 4, 4, 255, 0, 0);
    write_png(box.path("model/t.png"), 4, 4, 255, 0, 0);
    REQUIRE(mkfifo(box.path("model/fifo.png").c_str(), 0600) == 0);
    // OBJ+MTL: the texture outside the folder, a FIFO, and one inside that loads.
    write_text(box.path("model/m.mtl"), "newmtl a\nmap_Kd ../secret.png\nmap_Ke fifo.png\nmap_Pr t.png\n");
    write_text(box.path("model/m.obj"), kTriangleObj);
    CliRun r = step(box, with({"model/m.obj"}, kStepSmall));
    CHECK(r.code == 0);
    CHECK(has_line_with(r.err, "step: warning: ", "map_Kd '../secret.png' refused: climbs out of the model's folder"));
    CHECK(has_line_with(r.err, "step: warning: ", "map_Ke 'fifo.png' refused: not a regular file (a FIFO)"));
    CHECK(lines_of(r.err).size() == 2);
    CHECK(r.out.rfind("pixel 24 24: ", 0) == 0);
    CHECK(r.err.find("--allow-outside-paths") == std::string::npos);  // step does not take it

    // glTF: a buffer outside the folder is an error, as in render.
    std::vector<unsigned char> four(4, 0);
    test::write_bytes(box.path("b.bin"), four);
    write_text(box.path("model/b.gltf"), gltf_triangle("", "..%2Fb.bin"));
    r = step(box, with({"model/b.gltf"}, kStepSmall));
    CHECK(r.code == 1);
    CHECK(lines_of(r.err).size() == 1);
    CHECK(has_line_with(r.err, "step: ", "buffer uri '../b.bin' refused: climbs out of the model's folder"));
    CHECK(r.err.find("--allow-outside-paths") == std::string::npos);
    CHECK(r.out.empty());

    // The accessor budget.
    write_text(box.path("model/huge.gltf"),
               R"({"asset":{"version":"2.0"},"scenes":[{"nodes":[0]}],"nodes":[{"mesh":0}],)"
               R"("meshes":[{"primitives":[{"attributes":{"POSITION":0}}]}],)"
               R"("accessors":[{"componentType":5126,"count":268435456,"type":"VEC3"}]})");
    r = step(box, with({"model/huge.gltf"}, kStepSmall));
    CHECK(r.code == 1);
    CHECK(has_line_with(r.err, "step: ", "268435456 elements without a bufferView"));
    CHECK(lines_of(r.err).size() == 1);

    // A hostile PNG as a texture: one warning, the frame is still recorded.
    const std::string rows(17, '\0');
    test::write_bytes(box.path("model/huge.png"),
                      bytes_of(kPngSignature + png_ihdr(16384, 16384, 8, 6) + png_chunk("IDAT", zlib_stored(rows)) +
                               png_chunk("IEND", "")));
    write_text(box.path("model/m.mtl"), "newmtl a\nmap_Kd huge.png\n");
    r = step(box, with({"model/m.obj"}, kStepSmall));
    CHECK(r.code == 0);
    CHECK(has_line_with(r.err, "step: warning: ", "huge.png: cannot decode PNG image: 16384x16384 texels"));
    CHECK(lines_of(r.err).size() == 1);

    // step may serve what it reads to a browser: the way out stays shut.
    r = step(box, with({"model/m.obj", "--allow-outside-paths"}, kStepSmall));
    CHECK(r.code == 2);
    CHECK(r.err == "step: --allow-outside-paths: not a step option (step reads only files inside the model's "
                   "folder: it may show them in a web page)\n");
}

TEST_CASE("prast-diff on hostile and mismatched images: one line, exit 2, never a crash or a hang") {
    CliSandbox box;
    write_png(box.path("a.png"), 12, 8, 10, 20, 30);
    // A JPEG whose Huffman table declares more than 256 codes.
    std::size_t dht = 0;
    std::vector<unsigned char> jpg = small_jpeg(dht);
    REQUIRE(dht > 0);
    jpg[dht + 5 + 15] = 255;
    test::write_bytes(box.path("dht.jpg"), jpg);
    const std::string rows(17, '\0');
    test::write_bytes(box.path("huge.png"), bytes_of(kPngSignature + png_ihdr(16384, 16384, 8, 6) +
                                                      png_chunk("IDAT", zlib_stored(rows)) + png_chunk("IEND", "")));
    const std::string grey_rows = png_rows(16, 8, 8, false, [](int x, int) { return std::uint64_t(x); });
    std::string cut = kPngSignature + png_ihdr(16, 8, 8, 0) + png_chunk("IDAT", zlib_stored(grey_rows));
    test::write_bytes(box.path("cut.png"), bytes_of(cut.substr(0, cut.size() - 30)));
    test::write_bytes(box.path("empty.png"), {});
    REQUIRE(mkfifo(box.path("fifo.png").c_str(), 0600) == 0);
    const std::vector<std::pair<std::string, std::string>> cases = {
        {"dht.jpg", "prast-diff: dht.jpg: cannot decode JPEG image: Bogus Huffman table definition"},
        {"huge.png", "prast-diff: huge.png: cannot decode PNG image: 16384x16384 texels need at least 1073741824 bytes"},
        {"cut.png", "prast-diff: cut.png: cannot decode PNG image: "},
        {"empty.png", "prast-diff: empty.png: empty file"},
        {"fifo.png", "prast-diff: fifo.png: not a regular file (a FIFO)"},
        {"/dev/zero", "prast-diff: /dev/zero: not a regular file"},
        {"/proc/self/status", "prast-diff: /proc/self/status: "},
    };
    for (const auto& [file, message] : cases) {
        CAPTURE(file);
        for (const bool first : {true, false}) {
            const CliRun r = prast_diff(box, first ? std::vector<std::string>{file, "a.png"}
                                                   : std::vector<std::string>{"a.png", file});
            CHECK(r.code == 2);
            CHECK(r.err.rfind(message, 0) == 0);
            CHECK(lines_of(r.err).size() == 1);
            CHECK(r.out.empty());
        }
    }
    // Mismatched but readable: the same texels as grey, RGB, RGBA, 16-bit and
    // Adam7 interlaced files all match; another size differs (exit 1).
    const auto grey = [](int x, int y) { return std::uint64_t((x * 13 + y * 7) & 0xFF); };
    const auto put = [&](const std::string& name, int depth, int colour, int interlace, int bits,
                         const std::function<std::uint64_t(int, int)>& f) {
        test::write_bytes(box.path(name), bytes_of(kPngSignature + png_ihdr(16, 8, depth, colour, interlace) +
                                                   png_chunk("IDAT", zlib_stored(png_rows(16, 8, bits, interlace == 1, f))) +
                                                   png_chunk("IEND", "")));
    };
    put("grey.png", 8, 0, 0, 8, grey);
    put("rgb.png", 8, 2, 1, 24, [&](int x, int y) { return grey(x, y) * 0x010101u; });
    put("rgba.png", 8, 6, 0, 32, [&](int x, int y) { return grey(x, y) * 0x01010100u + 0xFF; });
    put("grey16.png", 16, 0, 0, 16, [&](int x, int y) { return grey(x, y) * 0x0101u; });
    for (const char* other : {"rgb.png", "rgba.png", "grey16.png"}) {
        CAPTURE(other);
        const CliRun r = prast_diff(box, {"grey.png", other});
        CHECK(r.code == 0);
        CHECK(r.err.empty());
    }
    put("alpha.png", 8, 6, 0, 32, [&](int x, int y) { return grey(x, y) * 0x01010100u + (x == 3 && y == 2 ? 0x80 : 0xFF); });
    const CliRun alpha = prast_diff(box, {"grey.png", "alpha.png"});
    CHECK(alpha.code == 1);
    CAPTURE(alpha.out);
    CHECK(alpha.out.find("max difference: 127 at 3,2\n") != std::string::npos);
    const CliRun sizes = prast_diff(box, {"grey.png", "a.png", "--heatmap", "h.png"});
    CHECK(sizes.code == 1);
    CHECK(sizes.err == "prast-diff: sizes differ: grey.png is 16x8, a.png is 12x8 (no heat map written)\n");
}

TEST_CASE("fuzz regressions: every input the fuzzers found is handled cleanly, in bounded time") {
    const fs::path root = fs::path(PRAST_SOURCE_DIR) / "tests" / "fuzz-regressions";
    const std::pair<const char*, fuzz::Target> folders[] = {
        {"obj", fuzz::Target::Obj}, {"gltf", fuzz::Target::Gltf}, {"png", fuzz::Target::Png},
        {"jpeg", fuzz::Target::Jpeg}, {"hdr", fuzz::Target::Hdr},  {"cli", fuzz::Target::Cli}};
    int files = 0;
    for (const auto& [folder, target] : folders) {
        if (!fs::is_directory(root / folder)) continue;
        for (const auto& entry : fs::directory_iterator(root / folder)) {
            CAPTURE(entry.path().string());
            const std::vector<unsigned char> bytes = test::read_bytes(entry.path().string());
            ++files;
            const fuzz::Target t = target;
            // In a child under a 60 s alarm: a crash or hang fails the case, not the suite.
            CHECK(in_child([&] {
                      const std::uint8_t* d = bytes.data();
                      switch (t) {
                      case fuzz::Target::Obj:
                      case fuzz::Target::Gltf: {
                          const std::string dir = fuzz::make_model_dir("regression");
                          if (t == fuzz::Target::Obj) fuzz::run_obj(dir, d, bytes.size());
                          else fuzz::run_gltf(dir, d, bytes.size());
                          std::error_code ec;
                          fs::remove_all(dir, ec);
                          return 0;
                      }
                      case fuzz::Target::Cli: return fuzz::run_cli(d, bytes.size()) ? 0 : 5;
                      default: return fuzz::run_image(t, d, bytes.size()) ? 0 : 5;
                      }
                  }) == 0);
        }
    }
    CHECK(files >= 2);
}

TEST_CASE("a 400-byte glTF asking for 2^28 elements fails at once, with the numbers") {
    const std::string json =
        R"({"asset":{"version":"2.0"},"scenes":[{"nodes":[0]}],"nodes":[{"mesh":0}],)"
        R"("meshes":[{"primitives":[{"attributes":{"POSITION":0}}]}],)"
        R"("accessors":[{"componentType":5126,"count":268435456,"type":"VEC3"}]})";
    CHECK(json.size() < 400);
    CliSandbox box;
    write_text(box.path("huge.gltf"), json);
    // 256 MB of address space is plenty for a refusal and far too little for
    // the 3 GB the accessor asks for (not in a sanitizer build: see below).
#ifdef PRAST_SANITIZE_BUILD
    const std::string cap = "";
#else
    const std::string cap = "ulimit -v 262144";
#endif
    const CliRun r = render(box, {"huge.gltf", "-o", "o.png"}, cap);
    CHECK(r.code == 1);
    CHECK(r.err ==
          "render: huge.gltf: mesh 0 primitive 0 POSITION: accessor 0: 268435456 elements without a bufferView "
          "bring the zero-filled elements to 268435456, more than the limit of 4194304 (2^22)\n");
}

TEST_CASE("200 spellings of one MTL load it once; 100,000 missing ones print a few lines and a count") {
    test::TempDir dir("hostile_spell");
    fs::create_directories(dir.path / "sub");
    test::write_text(dir.file("m.mtl"), "newmtl a\nKd 1 0 0\nnewmtl b\nKd 0 1 0\n");
    std::string obj;
    for (int i = 0; i < 200; ++i) {
        std::string spelling = "m.mtl";
        for (int k = 0; k < i % 7; ++k) spelling = "./" + spelling;
        if (i % 3 == 1) spelling = "sub/../" + spelling;
        if (i % 5 == 2) spelling = "sub/./../" + spelling;
        if (i % 11 == 3) spelling = dir.file("m.mtl");
        obj += "mtllib " + spelling + "\n";
    }
    obj += kTriangleBody;
    test::write_text(dir.file("s.obj"), obj);
    const Scene s = load_obj(dir.file("s.obj"));
    CHECK(s.materials.size() == 2);
    CHECK(s.warnings.empty());

    CliSandbox box;
    std::string many;
    for (int i = 0; i < 100000; ++i) many += "mtllib missing" + std::to_string(i) + ".mtl\n";
    many += kTriangleBody;
    write_text(box.path("many.obj"), many);
    const CliRun r = render(box, with({"many.obj", "-o", "o.png"}, kSmall));
    CHECK(r.code == 0);
    const std::vector<std::string> lines = lines_of(r.err);
    CHECK(lines.size() <= 13);
    // Shown lines plus the counts add up to all 100,000 references.
    long shown = 0, counted = 0;
    for (const std::string& line : lines) {
        const std::string more = "render: warning: ";
        if (line.find("more warnings like: ") != std::string::npos)
            counted += std::stol(line.substr(more.size()));
        else if (line.find("material library") != std::string::npos)
            ++shown;
    }
    CHECK(shown + counted == 100000);
    CHECK(has_line_with(r.err, "material library 'missing0.mtl' not found"));
    CHECK(has_line_with(r.err, "refused: the model names more than 4096 files"));
}

TEST_CASE("the thread pool runs with the threads it could start and carries task exceptions to run()") {
    ThreadPool pool(4);
    CHECK(pool.size() == 4);
    CHECK(pool.started_fewer().empty());
    std::atomic<int> done{0};
    CHECK_THROWS_AS(pool.run(1000,
                             [&](int task, int) {
                                 if (task == 37) throw std::bad_alloc();
                                 ++done;
                             }),
                    std::bad_alloc);
    CHECK(done < 1000);
    // The pool is whole afterwards.
    std::vector<int> hits(500, 0);
    pool.run(500, [&](int task, int) { ++hits[std::size_t(task)]; });
    CHECK(std::count(hits.begin(), hits.end(), 1) == 500);
    CHECK_THROWS_AS(pool.run(8, [](int, int worker) {
        if (worker >= 0) throw std::runtime_error("every task fails");
    }),
                    std::runtime_error);
}

TEST_CASE("--threads 1024 when threads cannot be made: fewer threads, a warning, the same image") {
    CliSandbox box;
    const CliRun one = render(box, {"--size", "64x48", "--threads", "1", "-o", "one.png"});
    REQUIRE(one.code == 0);
    // At most 12 processes (threads count) for the user render runs as
    // (prlimit: dash's ulimit has no -u). The limit does not bind root, so
    // as root render runs as nobody.
    std::vector<std::string> args = {"-s", "KILL", "60", "prlimit", "--nproc=12:12"};
    if (geteuid() == 0) {
        fs::permissions(box.work(), fs::perms::all, fs::perm_options::add);
        args.insert(args.end(), {"setpriv", "--reuid=nobody", "--regid=nogroup", "--clear-groups", "--inh-caps=-all",
                                 "--bounding-set=-all"});
    }
    args.insert(args.end(), {PRAST_RENDER_EXE, "--size", "64x48", "--threads", "1024", "-o", "many.png"});
    const CliRun r = box.run_exe("timeout", args);
    CAPTURE(r.err);
    CHECK(r.code == 0);
    CHECK(has_line_with(r.err, "render: warning: could start only ", " of 1024 threads ("));
    CHECK(has_line_with(r.err, "; rendering with "));
    CHECK(read_bytes(box.work() / "many.png") == read_bytes(box.work() / "one.png"));
}

TEST_CASE("running out of memory inside a pool task is one line, not terminate") {
#ifdef PRAST_SANITIZE_BUILD
    MESSAGE("skipped: AddressSanitizer reserves terabytes of address space, so ulimit -v cannot apply");
    return;
#endif
    // 20,000 copies of a triangle that covers a 4096x4096 frame: binning
    // needs 20,000 x 4,096 tile entries (over 1 GB) in its tasks, the scene
    // and the framebuffer (400 MB) far less.
    CliSandbox box;
    std::string obj = "v -100 -100 0\nv 100 -100 0\nv 0 100 0\n";
    for (int i = 0; i < 20000; ++i) obj += "f 1 2 3\n";
    write_text(box.path("cover.obj"), obj);
    const CliRun r = render(box, {"cover.obj", "--size", "4096x4096", "--threads", "2", "--eye", "0,0,1", "--target",
                                  "0,0,0", "--near", "0.5", "--far", "2", "--no-default-lights", "-o", "o.png"},
                            "ulimit -v 1100000");
    CHECK(r.code == 1);
    CHECK(r.err == "render: out of memory while rendering frame 0 (try a smaller --size or a smaller scene)\n");
    CHECK(box.work_files() == std::vector<std::string>{"cover.obj"});
}

TEST_CASE("a render whose textures cannot fit in memory is refused before anything is decoded") {
    // 16384 x 8192 Radiance files (2^27 texels; stb_image decodes no more
    // than 2 GB of floats): 2.9 GB each decoded with mips, twice when used as
    // colour and as data. Enough hard links to one 8 MB file pass half the
    // physical memory.
    const long pages = sysconf(_SC_PHYS_PAGES), page = sysconf(_SC_PAGE_SIZE);
    REQUIRE(pages > 0);
    const double budget = double(pages) * double(page) / 2.0;
    const double per_file = 2.0 * double(std::int64_t(1) << 27) * 16.0 * 4.0 / 3.0;
    const int files = int(budget / per_file) + 1;
    if (files > 64) {
        MESSAGE("skipped: this machine has so much memory that " << files << " huge textures would be needed");
        return;
    }
    CliSandbox box;
    constexpr int kWidth = 16384, kHeight = 8192;
    std::string hdr = "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y " + std::to_string(kHeight) + " +X " +
                      std::to_string(kWidth) + "\n";
    std::string line = {2, 2, char(kWidth >> 8), char(kWidth & 0xFF)};
    for (unsigned char value : {128, 64, 32, 129})
        for (int left = kWidth; left > 0; left -= 127) {
            line += char(128 + std::min(left, 127));
            line += char(value);
        }
    for (int y = 0; y < kHeight; ++y) hdr += line;
    write_text(box.path("h0.hdr"), hdr);
    hdr = {};
    std::string mtl, obj = "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\n";
    for (int i = 0; i < files; ++i) {
        const std::string name = "h" + std::to_string(i) + ".hdr";
        if (i > 0) fs::create_hard_link(box.work() / "h0.hdr", box.work() / name);
        mtl += "newmtl m" + std::to_string(i) + "\nmap_Kd " + name + "\nmap_Pr " + name + "\n";
        obj += "usemtl m" + std::to_string(i) + "\nf 1/1 2/2 3/3\n";
    }
    write_text(box.path("m.mtl"), mtl);
    write_text(box.path("m.obj"), obj);
    const CliRun r = render(box, {"m.obj", "--size", "16x16", "-o", "o.png"});
    CHECK(r.code == 1);
    CHECK(lines_of(r.err).size() == 1);
    CHECK(r.err.find("render: m.obj: the render needs about ") == 0);
    CHECK(r.err.find(" for " + std::to_string(std::int64_t(2 * files) << 27) + " texels in " + std::to_string(files) +
                     " images, ") !=
          std::string::npos);
    CHECK(r.err.find("bytes allowed (half the physical memory)") != std::string::npos);
    CHECK(!fs::exists(box.path("o.png")));
}

// ---------------------------------------------------------------- output

TEST_CASE("output names of 255 bytes work, and no temporary file is left") {
    CliSandbox box;
    const std::string name = std::string(251, 'n') + ".png";
    const CliRun r = render(box, {"--size", "32x32", "-o", name});
    CHECK(r.code == 0);
    CHECK(r.err.empty());
    CHECK(box.work_files() == std::vector<std::string>{name});
    CHECK(!load_rgb8(box.path(name)).empty());
}

TEST_CASE("a turntable checks every output directory before the first frame") {
    CliSandbox box;
    fs::create_directories(box.work() / "d0");
    fs::create_directories(box.work() / "d1");
    const CliRun r = render(box, {"--size", "32x32", "--frames", "3", "-o", "d%d/f.png"});
    CHECK(r.code == 1);
    CHECK(r.err == "render: d2/f.png: cannot write: directory 'd2' does not exist\n");
    CHECK(fs::is_empty(box.work() / "d0"));
    CHECK(fs::is_empty(box.work() / "d1"));
}

namespace {

// Starts render in `dir` (SIGINT and SIGTERM at their defaults), waits with
// inotify for the first event of `mask` on a name ending in `suffix`, sends
// `sig`, and returns the wait status. The watch starts before the render.
int signal_render_when(const fs::path& dir, const std::vector<std::string>& args, std::uint32_t mask,
                       const std::string& suffix, int sig) {
    const int in = inotify_init1(IN_CLOEXEC);
    REQUIRE(in >= 0);
    REQUIRE(inotify_add_watch(in, dir.c_str(), mask) >= 0);
    std::vector<std::string> argv_s = {PRAST_RENDER_EXE};
    argv_s.insert(argv_s.end(), args.begin(), args.end());
    std::vector<char*> argv;
    for (std::string& a : argv_s) argv.push_back(a.data());
    argv.push_back(nullptr);
    std::fflush(nullptr);
    const pid_t pid = fork();
    REQUIRE(pid >= 0);
    if (pid == 0) {
        signal(SIGINT, SIG_DFL);
        signal(SIGTERM, SIG_DFL);
        if (chdir(dir.c_str()) != 0) _exit(99);
        const int null = open("/dev/null", O_RDWR);
        dup2(null, 0);
        dup2(null, 1);
        dup2(null, 2);
        execv(argv[0], argv.data());
        _exit(98);
    }
    bool sent = false;
    alignas(inotify_event) char buf[4096];
    for (int waited = 0; !sent && waited < 120;) {
        pollfd p{in, POLLIN, 0};
        const int ready = poll(&p, 1, 1000);
        if (ready == 0) {
            ++waited;
            continue;
        }
        const ssize_t n = read(in, buf, sizeof buf);
        for (ssize_t off = 0; off < n && !sent;) {
            const auto* ev = reinterpret_cast<const inotify_event*>(buf + off);
            const std::string name = ev->len ? ev->name : "";
            if (name.size() >= suffix.size() && name.compare(name.size() - suffix.size(), suffix.size(), suffix) == 0) {
                kill(pid, sig);
                sent = true;
            }
            off += ssize_t(sizeof(inotify_event) + ev->len);
        }
    }
    if (!sent) kill(pid, SIGKILL);
    close(in);
    int status = 0;
    while (waitpid(pid, &status, 0) < 0 && errno == EINTR) {}
    return status;
}

} // namespace

TEST_CASE("SIGTERM while the output is written removes the temporary file; exit status 143") {
    CliSandbox box;
    // A large frame, so the temporary file exists for a while.
    const int status = signal_render_when(box.work(), {"--size", "2400x2400", "-o", "big.png"}, IN_CREATE, ".tmp",
                                          SIGTERM);
    CHECK(WIFSIGNALED(status));
    CHECK((WIFSIGNALED(status) ? 128 + WTERMSIG(status) : -1) == 143);
    const std::vector<std::string> left = box.work_files();
    for (const std::string& f : left) CHECK(f.find(".tmp") == std::string::npos);
    if (!left.empty()) MESSAGE("the rename won the race against the signal: " << left.size() << " file(s)");
}

TEST_CASE("SIGINT during a turntable stops it, leaves no temporary file; exit status 130") {
    CliSandbox box;
    const int status = signal_render_when(box.work(), {"--size", "320x240", "--frames", "200", "-o", "t%04d.png"},
                                          IN_MOVED_TO, ".png", SIGINT);
    CHECK(WIFSIGNALED(status));
    CHECK((WIFSIGNALED(status) ? 128 + WTERMSIG(status) : -1) == 130);
    const std::vector<std::string> left = box.work_files();
    CHECK(!left.empty());
    CHECK(left.size() < 200);
    for (const std::string& f : left) {
        CAPTURE(f);
        CHECK(f.find(".tmp") == std::string::npos);
        CHECK(!load_rgb8(box.path(f)).empty());  // every frame there is whole
    }
}

// ---------------------------------------------------------------- messages from files

TEST_CASE("control characters and newlines in names never reach the terminal raw") {
    CliSandbox box;
    // A material name and an image uri with escape sequences and a newline
    // that would forge an error line.
    const std::string evil_name = "m\x1b[2J\\u001b\nrender: error: forged";
    std::string name_json, uri_json;
    for (char c : evil_name) {
        if (c == '\n') name_json += "\\n";
        else if (c == '\x1b') name_json += "\\u001b";
        else if (c == '\\') name_json += "\\\\";
        else name_json += c;
    }
    write_text(box.path("e.gltf"), gltf_triangle("x\\nrender: error: forged\\u0007.png", "", name_json + "\\u0085"));
    // Make the material warn: an unknown alpha mode.
    std::string text = read_text(box.work() / "e.gltf");
    text.replace(text.find(R"("pbrMetallicRoughness")"), 0, R"("alphaMode":"X\u001b]0;pwned\u0007",)");
    write_text(box.path("e.gltf"), text);
    const CliRun r = render(box, with({"e.gltf", "-o", "o.png"}, kSmall));
    CHECK(r.code == 0);
    check_clean_stderr(r.err);
    CHECK(has_line_with(r.err, "image 0 'x\\nrender: error: forged\\x07.png' not found"));
    CHECK(has_line_with(r.err, "unknown alphaMode 'X\\e]0;pwned\\x07'"));

    // OBJ: material names in warnings, and the scene path itself.
    write_text(box.path("m.mtl"), "newmtl a\x1b[31m\nPc tin\x07\n");
    write_text(box.path("o.obj"), std::string("mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl a\x1b[31m\nf 1 2 3\n"));
    const CliRun o = render(box, with({"o.obj", "-o", "o.png"}, kSmall));
    CHECK(o.code == 0);
    check_clean_stderr(o.err);
    CHECK(has_line_with(o.err, "material 'a\\e[31m': unknown conductor 'Pc tin\\x07' ignored"));

    const std::string bad_path = "no\nrender: error: such\x1b[0m.obj";
    const CliRun p = render(box, {bad_path});
    CHECK(p.code == 1);
    check_clean_stderr(p.err);
    CHECK(p.err == "render: no\\nrender: error: such\\e[0m.obj: cannot open file (no such file)\n");
}

TEST_CASE("a texture that does not fit in memory is named in its warning, not as std::bad_alloc") {
#ifdef PRAST_SANITIZE_BUILD
    MESSAGE("skipped: AddressSanitizer reserves terabytes of address space, so ulimit -v cannot apply");
    return;
#endif
    CliSandbox box;
    // An 8192 x 8192 Radiance file of one colour: 4 MB of runs of 127, 1 GiB
    // once decoded to float RGBA.
    constexpr int kSide = 8192;
    std::string hdr = "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y " + std::to_string(kSide) + " +X " +
                      std::to_string(kSide) + "\n";
    std::string line = {2, 2, char(kSide >> 8), char(kSide & 0xFF)};
    for (unsigned char value : {128, 64, 32, 129}) {
        for (int left = kSide; left > 0; left -= 127) {
            line += char(128 + std::min(left, 127));
            line += char(value);
        }
    }
    for (int y = 0; y < kSide; ++y) hdr += line;
    write_text(box.path("big.hdr"), hdr);
    write_text(box.path("m.mtl"), "newmtl a\nmap_Kd big.hdr\n");
    write_text(box.path("m.obj"), kTriangleObj);
    const CliRun r = render(box, with({"m.obj", "-o", "o.png", "--threads", "2"}, kSmall), "ulimit -v 800000");
    CHECK(r.code == 0);
    CHECK(has_line_with(r.err, "big.hdr: ", "(texture ignored)"));
    CHECK(has_line_with(r.err, "big.hdr: ", "out of memory"));
    CHECK(r.err.find("std::") == std::string::npos);
    CHECK(r.err.find("outofmem") == std::string::npos);
    check_clean_stderr(r.err);
}

// ---------------------------------------------------------------- coordinates

TEST_CASE("absurd coordinates: the scene's bounds are blamed, or the flag that is wrong; step says the same") {
    CliSandbox box;
    // step takes render's camera (scene/camera_request.h): the same lines, its own prefix.
    for (const std::string tool : {"render", "step"}) {
    CAPTURE(tool);
    const auto render = [&](const CliSandbox& b, const std::vector<std::string>& args) {
        return tool == "render" ? ::render(b, args) : step(b, args);
    };
    const std::string p = tool + ": ";
    const std::pair<const char*, const char*> scenes[] = {
        {"far.obj", "v 1e19 0 0\nv 1e19 1 0\nv 1e19 0 1\nf 1 2 3\n"},
        {"huge.obj", "v -1e38 -1e38 0\nv 1e38 -1e38 0\nv 0 1e38 0\nf 1 2 3\n"},
        {"wide.obj", "v 0 0 0\nv 1e19 0 0\nv 0 1 0\nf 1 2 3\n"},
    };
    for (const auto& [name, text] : scenes) {
        CAPTURE(name);
        write_text(box.path(name), text);
        const CliRun r = render(box, {name, "--size", "16x16"});
        CHECK(r.code == 1);
        CHECK(lines_of(r.err).size() == 1);
        CHECK(r.err.find(p + name + ": cannot frame the scene: its bounds (") == 0);
        CHECK(r.err.find("same point") == std::string::npos);
    }
    // A node matrix of 1e38.
    std::string g = gltf_triangle("");
    g.replace(g.find(R"({"mesh":0})"), 10, R"({"mesh":0,"matrix":[1e38,0,0,0,0,1e38,0,0,0,0,1e38,0,0,0,0,1]})");
    write_text(box.path("m.gltf"), g);
    CliRun r = render(box, {"m.gltf", "--size", "16x16"});
    CHECK(r.code == 1);
    CHECK(r.err.find(p + "m.gltf: cannot frame the scene: its bounds (") == 0);
    // With a camera but fitted clip planes: the bounds again, asking for --near/--far.
    r = render(box, {"huge.obj", "--size", "16x16", "--eye", "0,0,10", "--target", "0,0,0"});
    CHECK(r.code == 1);
    CHECK(r.err.find("give --near and --far") != std::string::npos);
    // And with everything given, it renders.
    r = render(box, {"huge.obj", "--size", "16x16", "--eye", "0,0,10", "--target", "0,0,0", "--near", "1", "--far",
                     "100"});
    CHECK(r.code == 0);

    // Flags beyond what single precision can take name themselves.
    write_text(box.path("t.obj"), "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
    r = render(box, {"t.obj", "--fov", "1e-30"});
    CHECK(r.code == 2);
    CHECK(r.err == p + "--fov '1e-30': must be at least 0.001 and less than 180 degrees\n");
    r = render(box, {"t.obj", "--eye", "0,0,1e21"});
    CHECK(r.code == 2);
    CHECK(r.err == p + "--eye '0,0,1e21': coordinates beyond +-1e18 cannot be rendered in single precision\n");
    r = render(box, {"t.obj", "--target", "1e19,0,0"});
    CHECK(r.code == 2);
    CHECK(r.err.find(p + "--target '1e19,0,0'") == 0);
    // A narrow field of view that pushes the framed eye out of range.
    write_text(box.path("big.obj"), "v -1e14 -1e14 0\nv 1e14 -1e14 0\nv 0 1e14 0\nf 1 2 3\n");
    r = render(box, {"big.obj", "--fov", "0.001", "--size", "16x16"});
    CHECK(r.code == 2);
    CHECK(r.err.find(p + "--fov 0.001000: framing the scene") == 0);
    // The eye on the framed target: --eye is blamed, not --up.
    const glm::vec3 framed = frame_scene(load_scene(box.path("t.obj")), 45.0f, 1.0f).target;
    char at[96];
    std::snprintf(at, sizeof at, "%.9g,%.9g,%.9g", double(framed.x), double(framed.y), double(framed.z));
    r = render(box, {"t.obj", "--eye", at, "--size", "16x16"});
    CHECK(r.code == 2);
    CHECK(r.err.find(p + "--eye ") == 0);
    // Looking straight down without --up: the camera flags, with a way out.
    r = render(box, {"t.obj", "--eye", "0,5,0", "--target", "0,0,0", "--size", "16x16"});
    CHECK(r.code == 2);
    CHECK(r.err == p + "--eye/--target: the view is vertical, along the default up 0,1,0; give --up\n");
    }
}

TEST_CASE("the memory plan counts shadow maps and step's recording, before anything is drawn") {
    // Point lights with 8192-texel shadow cubes: 6 x 4100^2 x 8 bytes each,
    // planned from the flags alone, so enough of them exceed any budget.
    const long pages = sysconf(_SC_PHYS_PAGES), page = sysconf(_SC_PAGE_SIZE);
    REQUIRE(pages > 0);
    const double budget = double(pages) * double(page) / 2.0;
    const double per_light = 6.0 * 4100.0 * 4100.0 * 8.0;
    const int lights = int(budget / per_light) + 1;
    if (lights > 200) {
        MESSAGE("skipped: this machine has so much memory that " << lights << " shadowed lights would be needed");
        return;
    }
    CliSandbox box;
    write_text(box.path("t.obj"), "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");  // no lights of its own
    std::vector<std::string> args = {"t.obj", "--size", "16x16", "--shadows", "on", "--shadow-size", "8192"};
    for (int i = 0; i < lights; ++i) args.insert(args.end(), {"--point", "0,2,0:1,1,1"});
    CliRun r = render(box, with(args, {"-o", "o.png"}));
    CHECK(r.code == 1);
    CHECK(lines_of(r.err).size() == 1);
    CHECK(r.err.find("render: t.obj: the render needs about ") == 0);
    CHECK(r.err.find(", shadow maps " + std::to_string(std::uint64_t(lights) * 6 * 4100 * 4100 * 8) + ")") !=
          std::string::npos);
    CHECK(!fs::exists(box.path("o.png")));
    r = step(box, with(args, {"--pixel", "8,8"}));
    CHECK(r.code == 1);
    CHECK(lines_of(r.err).size() == 1);
    CHECK(r.err.find("step: t.obj: recording the frame needs about ") == 0);
    CHECK(r.err.find(", recording ") != std::string::npos);
    CHECK(r.out.empty());
    // A single shadowed point light renders: the plan does not simply refuse shadows.
    args.resize(7);
    r = render(box, with(args, {"--point", "0,2,0:1,1,1", "--shadow-size", "512", "-o", "o.png"}));
    CHECK(r.code == 0);
}

TEST_CASE("--env names a FIFO, a device or a directory: one line, never a hang") {
    CliSandbox box;
    REQUIRE(mkfifo(box.path("sky.hdr").c_str(), 0600) == 0);
    fs::create_symlink("/dev/zero", box.work() / "zero.hdr");
    for (const std::string tool : {"render", "step"}) {
        CAPTURE(tool);
        const std::vector<std::string> args = {"--size", "16x16", "--env", "sky.hdr", "--pixel", "8,8"};
        CliRun r = tool == "render" ? render(box, with(args, {"-o", "o.png"})) : step(box, args);
        CHECK(r.code == 1);
        CHECK(r.err == tool + ": sky.hdr: not a regular file (a FIFO), not read\n");
        r = tool == "render" ? render(box, {"--size", "16x16", "--env", "zero.hdr", "-o", "o.png"})
                             : step(box, {"--size", "16x16", "--env", "zero.hdr"});
        CHECK(r.code == 1);
        CHECK(r.err == tool + ": zero.hdr: not a regular file (a character device), not read\n");
    }
}

} // TEST_SUITE

// Loader limits that hostile or merely unusual files reach: image headers
// read before any decoding (a top-down BMP's negative height, sizes the
// per-image limit refuses, which the memory plan must not count), PNGs of any
// shape within the texel limit, required glTF extensions checked before any
// buffer is loaded, names and numbers from a file in messages, and threads
// under an address-space limit. Most cases run through the built `render`,
// as a user meets them: the exit code and every stderr line are checked.
#include <doctest/doctest.h>

#include <cerrno>
#include <climits>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include <pthread.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include "fuzz/png_craft.h"
#include "raster/thread_pool.h"
#include "scene/image.h"
#include "scene/load_scene.h"
#include "scene/messages.h"
#include "tests/cli_util.h"
#include "tests/load_error.h"

using namespace prast;
using prast::test::load_error;
using namespace prast::cli_test;

namespace {

namespace fs = std::filesystem;
namespace craft = prast::png_craft;

// render and step with a watchdog: killed after 60 s (exit 137), so a hang fails.
CliRun render(const CliSandbox& box, const std::vector<std::string>& args, const std::string& setup = "") {
    std::vector<std::string> all = {"-s", "KILL", "60", PRAST_RENDER_EXE};
    all.insert(all.end(), args.begin(), args.end());
    return box.run_exe("timeout", all, setup);
}

CliRun step(const CliSandbox& box, const std::vector<std::string>& args) {
    std::vector<std::string> all = {"-s", "KILL", "60", PRAST_STEP_EXE};
    all.insert(all.end(), args.begin(), args.end());
    return box.run_exe("timeout", all);
}

CliRun prast_diff(const CliSandbox& box, const std::vector<std::string>& args) {
    std::vector<std::string> all = {"-s", "KILL", "60", PRAST_DIFF_EXE};
    all.insert(all.end(), args.begin(), args.end());
    return box.run_exe("timeout", all);
}

const std::vector<std::string> kSmall = {"--size", "48x48", "--sun", "0,0,1:1,1,1", "--ambient", "0.2,0.2,0.2"};

std::vector<std::string> with(std::vector<std::string> a, const std::vector<std::string>& b) {
    a.insert(a.end(), b.begin(), b.end());
    return a;
}

// A triangle with UVs facing +Z that fills the middle of a framed image, with
// material `a` of m.mtl.
const char* const kTriangleObj =
    "mtllib m.mtl\nv -1 -1 0\nv 1 -1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0.5 1\nvn 0 0 1\nusemtl a\nf 1/1/1 2/2/1 3/3/1\n";

// A model whose material `a` has `map` as its base colour map.
void write_textured_triangle(const CliSandbox& box, const std::string& map) {
    write_text(box.path("m.mtl"), "newmtl a\nKd 1 1 1\nmap_Kd " + map + "\n");
    write_text(box.path("m.obj"), kTriangleObj);
}

std::vector<unsigned char> bytes_of(const std::string& s) { return std::vector<unsigned char>(s.begin(), s.end()); }

void write_file(const CliSandbox& box, const std::string& name, const std::string& bytes) {
    write_text(box.path(name), bytes);
}

std::string le16(unsigned v) { return {char(v & 0xFF), char(v >> 8 & 0xFF)}; }
std::string le32(std::uint32_t v) { return {char(v & 0xFF), char(v >> 8 & 0xFF), char(v >> 16 & 0xFF), char(v >> 24)}; }

// A 24-bit BMP (BITMAPINFOHEADER) of `rows` given top first, each a list of
// RGB triples; stored bottom-up (positive height) or top-down (negative).
std::string bmp(const std::vector<std::vector<std::uint32_t>>& rows, bool top_down) {
    const int w = int(rows[0].size()), h = int(rows.size());
    const int stride = (w * 3 + 3) / 4 * 4;
    std::string pixels;
    for (int i = 0; i < h; ++i) {
        const auto& row = rows[std::size_t(top_down ? i : h - 1 - i)];
        std::string line;
        for (std::uint32_t rgb : row) line += {char(rgb & 0xFF), char(rgb >> 8 & 0xFF), char(rgb >> 16 & 0xFF)};
        line.resize(std::size_t(stride), '\0');
        pixels += line;
    }
    const std::uint32_t height = top_down ? std::uint32_t(-h) : std::uint32_t(h);
    return "BM" + le32(std::uint32_t(54 + pixels.size())) + le32(0) + le32(54) + le32(40) + le32(std::uint32_t(w)) +
           le32(height) + le16(1) + le16(24) + le32(0) + le32(std::uint32_t(pixels.size())) + le32(2835) +
           le32(2835) + le32(0) + le32(0) + pixels;
}

// A BMP header claiming w x h (as 32-bit fields) with 16 bytes of pixels.
std::string bmp_header(std::uint32_t w, std::uint32_t h) {
    return "BM" + le32(54 + 16) + le32(0) + le32(54) + le32(40) + le32(w) + le32(h) + le16(1) + le16(24) + le32(0) +
           le32(16) + le32(2835) + le32(2835) + le32(0) + le32(0) + std::string(16, '\0');
}

std::string hdr_header(const std::string& size_line) {
    return "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n" + size_line + "\n" + std::string(64, '\0');
}

Image decode_bytes(const std::string& bytes, const std::string& name, bool srgb = false) {
    ImageSource src;
    src.name = name;
    src.bytes = bytes_of(bytes);
    return decode_image(src, srgb);
}

std::string decode_error(const std::string& bytes, const std::string& name) {
    try {
        decode_bytes(bytes, name);
    } catch (const LoadError& e) {
        return e.what();
    }
    return "";
}

bool dimensions_of(const std::string& bytes, int& w, int& h, int* texel_bytes = nullptr) {
    ImageSource src;
    src.bytes = bytes_of(bytes);
    return image_dimensions(src, w, h, texel_bytes);
}

// Texel (x, y) of an 8-bit RGB image as 0xRRGGBB; 0xFFFFFFFF for another layout.
std::uint32_t rgb8_at(const Image& img, int x, int y) {
    if (img.channels != 3) return 0xFFFFFFFFu;
    const std::uint8_t* p = &img.pixels[(std::size_t(y) * std::size_t(img.width) + std::size_t(x)) * 3];
    return std::uint32_t(p[0]) << 16 | std::uint32_t(p[1]) << 8 | p[2];
}

bool has_line_with(const std::string& text, const std::string& a, const std::string& b = "") {
    for (const std::string& line : lines_of(text))
        if (line.find(a) != std::string::npos && line.find(b) != std::string::npos) return true;
    return false;
}

// Runs fn in a forked child under alarm(60): its exit code, or 128 + signal.
int in_child(const std::function<int()>& fn) {
    std::fflush(nullptr);
    const pid_t pid = fork();
    REQUIRE(pid >= 0);
    if (pid == 0) {
        alarm(60);
        int code = 3;
        try {
            code = fn();
        } catch (...) {
            code = 4;
        }
        _exit(code);
    }
    int status = 0;
    while (waitpid(pid, &status, 0) < 0 && errno == EINTR) {}
    return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
}

// A data-URI buffer.
std::string base64(const std::string& in) {
    static const char* table = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    std::string out;
    for (std::size_t i = 0; i < in.size(); i += 3) {
        const auto byte = [&](std::size_t k) { return k < in.size() ? std::uint32_t(std::uint8_t(in[k])) : 0u; };
        const std::uint32_t b = byte(i) << 16 | byte(i + 1) << 8 | byte(i + 2);
        out += table[b >> 18 & 63];
        out += table[b >> 12 & 63];
        out += i + 1 < in.size() ? table[b >> 6 & 63] : '=';
        out += i + 2 < in.size() ? table[b & 63] : '=';
    }
    return out;
}

// A one-triangle glTF (positions in a data-URI buffer) whose root object
// also holds `extra` (members with a trailing comma) and whose material is
// `material` (a JSON object).
std::string triangle_gltf(const std::string& extra, const std::string& material = "{}") {
    std::string positions;
    for (float v : {-1.0f, -1.0f, 0.0f, 1.0f, -1.0f, 0.0f, 0.0f, 1.0f, 0.0f}) {
        char b[4];
        std::memcpy(b, &v, 4);
        positions.append(b, 4);
    }
    return "{" + extra + R"("asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}],
  "nodes": [{"mesh": 0}],
  "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "material": 0}]}],
  "materials": [)" + material + R"(],
  "buffers": [{"uri": "data:application/octet-stream;base64,)" + base64(positions) + R"(", "byteLength": 36}],
  "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 36}],
  "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
                 "min": [-1, -1, 0], "max": [1, 1, 0]}]
})";
}

} // namespace

TEST_SUITE("loader") {

// ---------------------------------------------------------------- image headers

TEST_CASE("a top-down BMP (negative height) decodes right way up, like the same picture stored bottom-up") {
    const std::vector<std::vector<std::uint32_t>> picture = {
        {0xFF0000, 0x00FF00, 0x0000FF}, {0x102030, 0x405060, 0x708090}, {0xFFFFFF, 0x000000, 0x808080}};
    const std::string top_down = bmp(picture, true), bottom_up = bmp(picture, false);
    for (const std::string* file : {&top_down, &bottom_up}) {
        const Image img = decode_bytes(*file, file == &top_down ? "top-down.bmp" : "bottom-up.bmp");
        CHECK(img.width == 3);
        CHECK(img.height == 3);
        for (int y = 0; y < 3; ++y)
            for (int x = 0; x < 3; ++x) CHECK(rgb8_at(img, x, y) == picture[std::size_t(y)][std::size_t(x)]);
        int w = 0, h = 0, texel_bytes = 0;
        CHECK(dimensions_of(*file, w, h, &texel_bytes));
        CHECK(w == 3);
        CHECK(h == 3);
        CHECK(texel_bytes == 3);
    }

    CliSandbox box;
    write_file(box, "top.bmp", top_down);
    write_file(box, "bottom.bmp", bottom_up);
    CliRun r = prast_diff(box, {"top.bmp", "bottom.bmp"});
    CHECK(r.code == 0);
    CHECK(r.out.find("size: 3x3") != std::string::npos);
    CHECK(r.out.find("result: match") != std::string::npos);
    CHECK(r.err.empty());

    // As a texture: the render takes it, no warning, no absurd memory plan.
    write_file(box, "red.bmp", bmp({{0xFF0000, 0xFF0000}, {0xFF0000, 0xFF0000}}, true));
    write_textured_triangle(box, "red.bmp");
    r = render(box, with({"m.obj", "-o", "o.png"}, kSmall));
    CHECK(r.code == 0);
    CHECK(r.err.empty());
    const Rgb8 out = load_rgb8(box.path("o.png"));
    REQUIRE(!out.empty());
    const std::uint8_t* c = out.at(24, 28);
    CHECK(c[0] > 40);
    CHECK(c[0] > 3 * c[1]);
    CHECK(c[0] > 3 * c[2]);
}

TEST_CASE("every size stbi_info gives is checked: negative, zero and absurd sizes are refused by name") {
    struct Case {
        const char* name;
        std::string bytes;
        const char* message;  // after "NAME: "
    };
    const std::vector<Case> cases = {
        {"negative-width.bmp", bmp_header(std::uint32_t(-4), 4), "bad image size (-4x4) in the header"},
        {"int-min-height.bmp", bmp_header(4, 0x80000000u), "bad image size (4x-2147483648) in the header"},
        {"zero-height.bmp", bmp_header(4, 0), "image has zero size (4x0)"},
        {"wide.bmp", bmp_header(40000, 1),
         "image too large: 40000x1, more than 32768 pixels a side (BMP images are decoded by stb_image)"},
        {"huge.bmp", bmp_header(40000, 40000),
         "image too large: 40000x40000 = 1600000000 texels, more than the limit of 268435456 (2^28)"},
        {"huge.pnm", "P6\n100000 100000\n255\n" + std::string(64, '\0'),
         "image too large: 100000x100000 = 10000000000 texels, more than the limit of 268435456 (2^28)"},
        {"garbage.hdr", hdr_header("-Y -1 +X 1"), "cannot decode HDR image: bad size 1x-1 (each side 1 to 32768)"},
        {"huge.hdr", hdr_header("-Y 100000 +X 100000"),
         "cannot decode HDR image: bad size 100000x100000 (each side 1 to 32768)"},
    };
    for (const Case& c : cases) {
        CAPTURE(c.name);
        CHECK(decode_error(c.bytes, c.name) == std::string(c.name) + ": " + c.message);
        int w = -1, h = -1;
        CHECK(!dimensions_of(c.bytes, w, h));
    }
}

TEST_CASE("the memory plan leaves out images the per-image limit refuses: one warning each, the same for every format") {
    // Each would have been planned at its header's size (up to 10^10 texels,
    // or a wrapped negative one) and failed the whole render.
    std::string tga(18, '\0');
    tga[2] = 2;  // uncompressed true-colour
    tga[12] = tga[13] = tga[14] = tga[15] = char(0xFF);  // 65535 x 65535
    tga[16] = 24;
    tga += std::string(64, '\0');
    const std::vector<std::pair<std::string, std::string>> files = {
        {"huge.hdr", hdr_header("-Y 100000 +X 100000")},
        {"big.hdr", hdr_header("-Y 40000 +X 40000")},
        {"garbage.hdr", hdr_header("-Y -1 +X 1")},
        {"wrapped.hdr", hdr_header("-Y 4294967295 +X 4294967295")},
        {"big.bmp", bmp_header(40000, 40000)},
        {"huge.pnm", "P6\n100000 100000\n255\n" + std::string(64, '\0')},
        {"huge.tga", tga},
        {"thin.png", craft::kSignature + craft::ihdr(std::uint32_t(kMaxImageTexels) + 1, 1, 8, 2) +
                         craft::chunk("IDAT", craft::zlib_stored(std::string(64, '\0'))) + craft::chunk("IEND", "")},
    };
    CliSandbox box;
    for (const auto& [name, bytes] : files) {
        CAPTURE(name);
        write_file(box, name, bytes);
        write_textured_triangle(box, name);
        const CliRun r = render(box, with({"m.obj", "-o", "o.png"}, kSmall));
        CHECK(r.code == 0);
        CHECK(lines_of(r.err).size() == 1);
        CHECK(has_line_with(r.err, "render: warning: ", name + ": "));
        CHECK(has_line_with(r.err, "(texture ignored)"));
        CHECK(r.err.find("needs about") == std::string::npos);
        CHECK(r.err.find("18446744") == std::string::npos);
        CHECK(fs::exists(box.path("o.png")));
        fs::remove(box.path("o.png"));
    }
    // step plans the same way.
    write_textured_triangle(box, "huge.hdr");
    const CliRun s = step(box, {"m.obj", "--size", "48x48", "--sun", "0,0,1:1,1,1", "--pixel", "24,24"});
    CHECK(s.code == 0);
    CHECK(has_line_with(s.err, "huge.hdr: cannot decode HDR image: bad size 100000x100000", "(texture ignored)"));
    CHECK(s.err.find("needs about") == std::string::npos);
}

TEST_CASE("a small PNG whose header claims far more pixels than its data holds is not planned either") {
    // 40 files of 16384 x 16384 RGBA would plan 40 GiB; each fails on its own.
    CliSandbox box;
    const std::string png = craft::kSignature + craft::ihdr(16384, 16384, 8, 6) +
                            craft::chunk("IDAT", craft::zlib_stored(std::string(17, '\0'))) + craft::chunk("IEND", "");
    std::string mtl, obj = "mtllib m.mtl\nv -1 -1 0\nv 1 -1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0.5 1\n";
    for (int i = 0; i < 40; ++i) {
        write_file(box, "p" + std::to_string(i) + ".png", png);
        mtl += "newmtl m" + std::to_string(i) + "\nmap_Kd p" + std::to_string(i) + ".png\n";
        obj += "usemtl m" + std::to_string(i) + "\nf 1/1 2/2 3/3\n";
    }
    write_text(box.path("m.mtl"), mtl);
    write_text(box.path("m.obj"), obj);
    int w = 0, h = 0;
    CHECK(!dimensions_of(png, w, h));
    const CliRun r = render(box, with({"m.obj", "-o", "o.png"}, kSmall));
    CHECK(r.code == 0);
    CHECK(r.err.find("needs about") == std::string::npos);
    CHECK(has_line_with(r.err, "p0.png: cannot decode PNG image: 16384x16384 texels need at least"));
}

// ---------------------------------------------------------------- PNG shapes

TEST_CASE("PNGs of any shape within the texel limit decode, 8-bit and 16-bit, with the pixels they hold") {
    // 40000 x 1 and 1 x 40000 are beyond stb_image's 32768-pixel side;
    // libpng decodes them.
    const auto rgb_at = [](int x, int y) { return std::uint64_t((x * 7 + y * 3) & 0xFF) << 16 | std::uint64_t(x & 0xFF) << 8 | std::uint64_t(y & 0xFF); };
    const std::string wide = craft::file(40000, 1, 8, 2, 0, 24, rgb_at);
    Image img = decode_bytes(wide, "wide.png");
    CHECK(img.width == 40000);
    CHECK(img.height == 1);
    int mismatches = 0;
    for (int x = 0; x < 40000; ++x) mismatches += rgb8_at(img, x, 0) != std::uint32_t(rgb_at(x, 0));
    CHECK(mismatches == 0);
    int w = 0, h = 0, texel_bytes = 0;
    CHECK(dimensions_of(wide, w, h, &texel_bytes));
    CHECK(w == 40000);
    CHECK(h == 1);
    CHECK(texel_bytes == 3);

    const auto grey_at = [](int, int y) { return std::uint64_t(y % 251); };
    const std::string tall = craft::file(1, 40000, 8, 0, 1, 8, grey_at);  // interlaced
    img = decode_bytes(tall, "tall.png");
    CHECK(img.width == 1);
    CHECK(img.height == 40000);
    REQUIRE(img.channels == 1);
    mismatches = 0;
    for (int y = 0; y < 40000; ++y) mismatches += img.pixels[std::size_t(y)] != grey_at(0, y);
    CHECK(mismatches == 0);

    // 16-bit RGBA: the same floats as stb_image gives for the same texels in
    // a 32768-wide file, colour and data alike.
    const auto rgba16_at = [](int x, int) {
        const std::uint64_t v = std::uint64_t(x) * 2654435761u;
        return (v & 0xFFFF) << 48 | (v >> 16 & 0xFFFF) << 32 | (v >> 32 & 0xFFFF) << 16 | 0x8001;
    };
    const std::string wide16 = craft::file(40000, 1, 16, 6, 0, 64, rgba16_at);
    const std::string stb16 = craft::file(32768, 1, 16, 6, 0, 64, rgba16_at);
    for (bool srgb : {false, true}) {
        CAPTURE(srgb);
        const Image a = decode_bytes(wide16, "wide16.png", srgb), b = decode_bytes(stb16, "stb16.png", srgb);
        REQUIRE(a.width == 40000);
        REQUIRE(b.width == 32768);
        REQUIRE(a.channels == 0);
        REQUIRE(b.channels == 0);
        CHECK(std::memcmp(a.rgba.data(), b.rgba.data(), b.rgba.size() * sizeof(float)) == 0);
        CHECK(a.at(39999, 0).a == doctest::Approx(0x8001 / 65535.0));
    }
    CHECK(dimensions_of(wide16, w, h, &texel_bytes));
    CHECK(texel_bytes == 16);

    // Beyond the texel limit in a thin shape: refused by its size, not as corrupt.
    const std::string too_many = craft::kSignature + craft::ihdr(std::uint32_t(kMaxImageTexels) + 1, 1, 8, 0) +
                                 craft::chunk("IDAT", craft::zlib_stored(std::string(64, '\0'))) +
                                 craft::chunk("IEND", "");
    CHECK(decode_error(too_many, "thin.png") ==
          "thin.png: image too large: 268435457x1 = 268435457 texels, more than the limit of 268435456 (2^28)");
    // A width the format does not allow (2^31) stays a bad header.
    const std::string bad_width = craft::kSignature + craft::ihdr(0x80000000u, 1, 8, 0) +
                                  craft::chunk("IDAT", craft::zlib_stored(std::string(64, '\0'))) +
                                  craft::chunk("IEND", "");
    CHECK(decode_error(bad_width, "bad.png") == "bad.png: cannot decode PNG image: corrupt or truncated header");
}

TEST_CASE("a 40000 x 1 PNG texture renders") {
    CliSandbox box;
    write_file(box, "wide.png", craft::file(40000, 1, 8, 2, 0, 24, [](int, int) { return std::uint64_t(0xFF0000); }));
    write_textured_triangle(box, "wide.png");
    const CliRun r = render(box, with({"m.obj", "-o", "o.png"}, kSmall));
    CHECK(r.code == 0);
    CHECK(r.err.empty());
    const Rgb8 out = load_rgb8(box.path("o.png"));
    REQUIRE(!out.empty());
    const std::uint8_t* c = out.at(24, 28);
    CHECK(c[0] > 40);
    CHECK(c[0] > 3 * c[1]);
}

// ---------------------------------------------------------------- glTF

TEST_CASE("a required extension is checked before buffers load: a uri-less fallback buffer names the extension") {
    CliSandbox box;
    // As gltfpack writes it: the compressed data in buffer 1, buffer 0 a
    // fallback with no uri that only a decoder of the extension fills.
    std::string json = triangle_gltf(
        R"("extensionsUsed": ["EXT_meshopt_compression"], "extensionsRequired": ["EXT_meshopt_compression"],)");
    const std::string buffers = R"("buffers": [)";
    json.replace(json.find(buffers), buffers.size(),
                 buffers + R"({"byteLength": 36, "extensions": {"EXT_meshopt_compression": {"fallback": true}}}, )");
    write_text(box.path("m.gltf"), json);
    // The extension is implemented, but no bufferView decodes into the
    // fallback: the file is refused naming the view, before any buffer is read.
    const std::string why = ": bufferView 0: buffer 0 is a uri-less meshopt fallback (no data), and the bufferView "
                            "has no EXT_meshopt_compression to decode";
    CHECK(load_error(box.path("m.gltf")) == box.path("m.gltf") + why);
    const CliRun r = render(box, with({"m.gltf", "-o", "o.png"}, kSmall));
    CHECK(r.code == 1);
    CHECK(r.err == "render: m.gltf" + why + "\n");

    // No buffer file is even opened: a FIFO as the buffer does not matter.
    REQUIRE(mkfifo(box.path("data.bin").c_str(), 0600) == 0);
    json = triangle_gltf(R"("extensionsRequired": ["KHR_texture_basisu"],)");
    const std::string data_uri = json.substr(json.find("\"uri\": \""), json.find("\", \"byteLength\": 36") -
                                                                            json.find("\"uri\": \"") + 1);
    json.replace(json.find(data_uri), data_uri.size(), "\"uri\": \"data.bin\"");
    write_text(box.path("d.gltf"), json);
    CHECK(load_error(box.path("d.gltf")) ==
          box.path("d.gltf") + ": required extension KHR_texture_basisu is not supported");

    // The key however it is escaped; a nested "extensionsRequired" is not the model's.
    write_text(box.path("e.gltf"), triangle_gltf(R"("extensions\u0052equired": ["KHR_texture_basisu"],)"));
    CHECK(load_error(box.path("e.gltf")) ==
          box.path("e.gltf") + ": required extension KHR_texture_basisu is not supported");
    write_text(box.path("n.gltf"), triangle_gltf(R"("extras": {"extensionsRequired": ["EXT_meshopt_compression"]},)"));
    CHECK(load_error(box.path("n.gltf")).empty());
    // Implemented requirements load; one prast does not implement is refused, a material one too.
    write_text(box.path("ok.gltf"),
               triangle_gltf(R"("extensionsRequired": ["KHR_mesh_quantization", "KHR_materials_pbrSpecularGlossiness"],)"));
    Scene ok = load_scene(box.path("ok.gltf"));
    CHECK(ok.meshes.size() == 1);
    CHECK(ok.warnings.empty());
    write_text(box.path("tt.gltf"),
               triangle_gltf(R"("extensionsRequired": ["KHR_mesh_quantization", "KHR_materials_iridescence"],)"));
    CHECK(load_error(box.path("tt.gltf")) ==
          box.path("tt.gltf") + ": required extension KHR_materials_iridescence is not supported");
}

// ---------------------------------------------------------------- names and numbers

TEST_CASE("cut() shortens a name as printed, never inside a character or an escape") {
    CHECK(cut("short") == "short");
    const std::string exact(kMaxShownChars, 'x');
    CHECK(cut(exact) == exact);
    CHECK(cut(exact + "y") == exact + "...");
    CHECK(cut("abcdef", 3) == "abc...");
    // A 2-byte character counts once; a control byte as its escape (4).
    CHECK(cut("\xC3\xA9\xC3\xA9\xC3\xA9", 2) == "\xC3\xA9\xC3\xA9...");
    CHECK(cut("ab\x01" "cd", 4) == "ab...");
    CHECK(cut("ab\x01" "cd", 6) == "ab\x01...");
    CHECK(cut("ab\ncd", 4) == "ab\n...");
    // An invalid byte is never joined to what follows.
    CHECK(cut("a\xC3", 1) == "a...");
    for (const std::string& s : {std::string(10000, 'n'), std::string(5000, '\x1b'), std::string(3000, '\xff'),
                                 [] { std::string u; for (int i = 0; i < 4000; ++i) u += "\xE2\x82\xAC"; return u; }()}) {
        const std::string shown = printable(cut(s));
        CHECK(shown.size() <= 3 * kMaxShownChars + 3);  // a euro sign is 3 bytes, one character
        CHECK(shown.substr(shown.size() - 3) == "...");
        CHECK(printable(shown) == shown);
    }
}

TEST_CASE("long names from a model are cut in messages, and texCoord is printed as the file writes it") {
    CliSandbox box;
    const std::string long_ext = "EXT_" + std::string(10000, 'x');
    write_text(box.path("x.gltf"), triangle_gltf("\"extensionsRequired\": [\"" + long_ext + "\"],"));
    CliRun r = render(box, with({"x.gltf", "-o", "o.png"}, kSmall));
    CHECK(r.code == 1);
    REQUIRE(lines_of(r.err).size() == 1);
    CHECK(r.err.size() < 300);
    CHECK(r.err == "render: x.gltf: required extension " + long_ext.substr(0, kMaxShownChars) +
                       "... is not supported\n");

    // A material name, its alphaMode, an extension of it, a texture's uri.
    const std::string name(10000, 'm');
    write_text(box.path("t.gltf"),
               triangle_gltf(R"("textures": [{"source": 0}], "images": [{"uri": ")" + std::string(10000, 'u') +
                                 R"(.png"}],)",
                             R"({"name": ")" + name + R"(", "alphaMode": ")" + std::string(10000, 'a') +
                                 R"(", "extensions": {")" + long_ext + R"(": {}},
                  "pbrMetallicRoughness": {"baseColorTexture": {"index": 0}},
                  "normalTexture": {"index": 0, "texCoord": 2147483648},
                  "occlusionTexture": {"index": 0, "texCoord": 4294967295},
                  "emissiveTexture": {"index": 0, "texCoord": 1}})"));
    r = render(box, with({"t.gltf", "-o", "o.png"}, kSmall));
    CHECK(r.code == 0);
    const std::vector<std::string> lines = lines_of(r.err);
    CHECK(lines.size() >= 5);
    for (const std::string& line : lines) {
        CAPTURE(line);
        CHECK(line.size() < 3 * kMaxShownChars);
    }
    const std::string m = "material '" + name.substr(0, kMaxShownChars) + "...'";
    CHECK(has_line_with(r.err, m + ": unknown alphaMode '" + std::string(kMaxShownChars, 'a') + "...', drawn opaque"));
    CHECK(has_line_with(r.err, m + ": extension " + long_ext.substr(0, kMaxShownChars) + "... ignored"));
    CHECK(has_line_with(r.err, m + " normalTexture uses TEXCOORD_2147483648 (only TEXCOORD_0 and TEXCOORD_1 are supported)"));
    CHECK(has_line_with(r.err, m + " occlusionTexture uses TEXCOORD_4294967295 (only TEXCOORD_0 and TEXCOORD_1 are supported)"));
    CHECK(!has_line_with(r.err, m + " emissiveTexture uses TEXCOORD_1"));  // a set prast reads
    CHECK(has_line_with(r.err, "image 0 '" + std::string(kMaxShownChars, 'u') + "...' "));
    CHECK(r.err.find("-2147483648") == std::string::npos);

    // OBJ: a map name and a material name.
    write_text(box.path("l.mtl"), "newmtl " + name + "\nmap_Kd " + std::string(10000, 'k') + ".png\n");
    write_text(box.path("l.obj"), "mtllib l.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl " + name + "\nf 1 2 3\n");
    r = render(box, with({"l.obj", "-o", "o.png"}, kSmall));
    CHECK(r.code == 0);
    REQUIRE(lines_of(r.err).size() == 1);
    CHECK(r.err.size() < 3 * kMaxShownChars);
    CHECK(r.err.find("material '" + name.substr(0, kMaxShownChars) + "...': map_Kd '" +
                     std::string(kMaxShownChars, 'k') + "...'") != std::string::npos);
}

// ---------------------------------------------------------------- threads

TEST_CASE("under an address-space limit the pool starts only the threads whose stacks fit, and says so") {
#ifdef PRAST_SANITIZE_BUILD
    MESSAGE("skipped: AddressSanitizer reserves terabytes of address space, so ulimit -v cannot apply");
    return;
#endif
    rlimit limit{};
    REQUIRE(getrlimit(RLIMIT_AS, &limit) == 0);
    if (limit.rlim_max != RLIM_INFINITY && limit.rlim_max < (rlim_t(8) << 30)) {
        MESSAGE("skipped: the hard address-space limit is below the 8 GiB this case sets");
        return;
    }
    // 1000 threads of 8 MiB stacks reserve 8 GiB: the whole limit.
    const int code = in_child([] {
        pthread_attr_t attr;
        if (pthread_attr_init(&attr) != 0 || pthread_attr_setstacksize(&attr, std::size_t(8) << 20) != 0 ||
            pthread_setattr_default_np(&attr) != 0)
            return 19;
        pthread_attr_destroy(&attr);
        rlimit as{};
        if (getrlimit(RLIMIT_AS, &as) != 0) return 20;
        as.rlim_cur = rlim_t(8) << 30;
        if (setrlimit(RLIMIT_AS, &as) != 0) return 20;
        ThreadPool pool(1000);
        if (pool.size() >= 1000 || pool.size() < 2) return 21;
        if (pool.started_fewer().find("could start only " + std::to_string(pool.size()) + " of 1000 threads (") != 0)
            return 22;
        if (pool.started_fewer().find("stacks") == std::string::npos) return 23;
        if (pool.started_fewer().find("ulimit -v") == std::string::npos) return 24;
        std::vector<int> hits(5000, 0);
        pool.run(5000, [&](int task, int) { ++hits[std::size_t(task)]; });
        for (int h : hits)
            if (h != 1) return 25;
        return 0;
    });
    CHECK(code == 0);

    CliSandbox box;
    const CliRun one = render(box, {"--size", "64x48", "--threads", "1", "-o", "one.png"});
    REQUIRE(one.code == 0);
    const CliRun r = render(box, {"--size", "64x48", "--threads", "1000", "-o", "many.png"},
                            "ulimit -s 8192 && ulimit -v 8388608");
    CAPTURE(r.err);
    CHECK(r.code == 0);
    CHECK(has_line_with(r.err, "render: warning: could start only ", " of 1000 threads (their 8 MiB stacks would"));
    CHECK(r.err.find("out of memory") == std::string::npos);
    CHECK(read_bytes(box.work() / "many.png") == read_bytes(box.work() / "one.png"));
}

} // TEST_SUITE

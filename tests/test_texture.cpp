// Textures: mip chain, bilinear/trilinear sampling and wrap modes, the LOD
// formula, image decoding (sRGB, grey, 16-bit, HDR) and hostile image files.
#include <doctest/doctest.h>

#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include <stb_image.h>
#include <stb_image_write.h>
#include <turbojpeg.h>

#include "tests/scratch.h"

#include "scene/encode_png.h"
#include "scene/image.h"
#include "scene/procedural_images.h"
#include "shading/texture.h"

namespace fs = std::filesystem;
using namespace prast;
using prast::test::TempDir;
using prast::test::read_bytes;
using prast::test::write_bytes;
using prast::test::write_text;

namespace {




ImageSource file_source(const std::string& path) {
    ImageSource s;
    s.path = path;
    s.name = path;
    return s;
}

// Decoding must fail with a LoadError that names the file.
void require_load_error(const ImageSource& src, const std::string& must_contain) {
    bool threw = false;
    try {
        decode_image(src, true);
    } catch (const LoadError& e) {
        threw = true;
        const std::string what = e.what();
        INFO("message: " << what);
        CHECK(what.find(must_contain) != std::string::npos);
        CHECK(what.find('\n') == std::string::npos);
    }
    CHECK_MESSAGE(threw, "no LoadError for " << src.name);
}

// A minimal PNG encoder (zlib "stored" blocks, no compression) for what
// stb_image_write cannot produce: 16-bit samples and hand-made headers.
std::uint32_t crc32(const unsigned char* p, std::size_t n) {
    std::uint32_t c = 0xFFFFFFFFU;
    for (std::size_t i = 0; i < n; ++i) {
        c ^= p[i];
        for (int k = 0; k < 8; ++k) c = (c >> 1) ^ (0xEDB88320U & (0U - (c & 1U)));
    }
    return c ^ 0xFFFFFFFFU;
}

void put_u32(std::vector<unsigned char>& out, std::uint32_t v) {
    for (int s = 24; s >= 0; s -= 8) out.push_back((unsigned char)(v >> s));
}

void put_chunk(std::vector<unsigned char>& out, const char* type, const std::vector<unsigned char>& data) {
    put_u32(out, std::uint32_t(data.size()));
    std::vector<unsigned char> body(type, type + 4);
    body.insert(body.end(), data.begin(), data.end());
    out.insert(out.end(), body.begin(), body.end());
    put_u32(out, crc32(body.data(), body.size()));
}

// `samples` holds raw big-endian sample bytes per row (no filter byte).
std::vector<unsigned char> make_png(std::uint32_t w, std::uint32_t h, int bit_depth, int colour_type,
                                    const std::vector<unsigned char>& samples) {
    std::vector<unsigned char> png = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'};
    std::vector<unsigned char> ihdr;
    put_u32(ihdr, w);
    put_u32(ihdr, h);
    ihdr.push_back((unsigned char)bit_depth);
    ihdr.push_back((unsigned char)colour_type);
    ihdr.push_back(0);  // deflate
    ihdr.push_back(0);  // adaptive filtering
    ihdr.push_back(0);  // no interlace
    put_chunk(png, "IHDR", ihdr);

    // Filtered scanlines: filter type 0 before each row.
    std::vector<unsigned char> raw;
    const std::size_t row_bytes = h ? samples.size() / h : 0;
    for (std::uint32_t y = 0; y < h; ++y) {
        raw.push_back(0);
        raw.insert(raw.end(), samples.begin() + std::ptrdiff_t(y * row_bytes),
                   samples.begin() + std::ptrdiff_t((y + 1) * row_bytes));
    }
    // zlib: header, one final stored block (raw is small), Adler-32.
    std::vector<unsigned char> z = {0x78, 0x01, 0x01};
    const std::uint16_t len = std::uint16_t(raw.size());
    z.push_back((unsigned char)(len & 0xFF));
    z.push_back((unsigned char)(len >> 8));
    z.push_back((unsigned char)(~len & 0xFF));
    z.push_back((unsigned char)((~len >> 8) & 0xFF));
    z.insert(z.end(), raw.begin(), raw.end());
    std::uint32_t a = 1, b = 0;
    for (unsigned char c : raw) {
        a = (a + c) % 65521U;
        b = (b + a) % 65521U;
    }
    put_u32(z, (b << 16) | a);
    put_chunk(png, "IDAT", z);
    put_chunk(png, "IEND", {});
    return png;
}

float srgb_reference(float c) {
    return c <= 0.04045f ? c / 12.92f : std::pow((c + 0.055f) / 1.055f, 2.4f);
}

// A w x h image of distinct, deterministic values.
Image numbered_image(int w, int h) {
    Image img;
    img.width = w;
    img.height = h;
    img.rgba.resize(std::size_t(w) * std::size_t(h) * 4);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            img.set(x, y, glm::vec4(float(x), float(y), float(x + 10 * y), 1.0f + float(x * y)));
    return img;
}

Image random_image(int w, int h, unsigned seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> dist(0.0f, 1.0f);
    Image img;
    img.width = w;
    img.height = h;
    img.rgba.resize(std::size_t(w) * std::size_t(h) * 4);
    for (float& f : img.rgba) f = dist(rng);
    return img;
}

glm::vec4 image_mean(const Texture& tex, int level) {
    glm::dvec4 sum(0.0);
    for (int y = 0; y < tex.height(level); ++y)
        for (int x = 0; x < tex.width(level); ++x) sum += glm::dvec4(tex.texel(level, x, y));
    return glm::vec4(sum / double(tex.width(level) * tex.height(level)));
}

void check_near(const glm::vec4& a, const glm::vec4& b, float tol) {
    INFO("a = (" << a.x << ", " << a.y << ", " << a.z << ", " << a.w << ")  b = (" << b.x << ", "
                 << b.y << ", " << b.z << ", " << b.w << ")");
    CHECK(std::fabs(a.x - b.x) <= tol);
    CHECK(std::fabs(a.y - b.y) <= tol);
    CHECK(std::fabs(a.z - b.z) <= tol);
    CHECK(std::fabs(a.w - b.w) <= tol);
}

bool all_finite(const glm::vec4& c) {
    return std::isfinite(c.x) && std::isfinite(c.y) && std::isfinite(c.z) && std::isfinite(c.w);
}

} // namespace

TEST_SUITE("texture") {

TEST_CASE("mip chain of a checker averages to grey") {
    const Texture tex = Texture::from_image(
        make_checker(256, 8, glm::vec4(0, 0, 0, 1), glm::vec4(1, 1, 1, 1)), Wrap::Repeat, Wrap::Repeat);
    REQUIRE(tex.levels() == 9);
    for (int l = 0; l < tex.levels(); ++l) {
        CHECK(tex.width(l) == (256 >> l));
        CHECK(tex.height(l) == (256 >> l));
    }
    check_near(tex.average(), glm::vec4(0.5f, 0.5f, 0.5f, 1.0f), 1e-6f);
    // Level 5 (8x8) is exactly one texel per cell: still black and white.
    CHECK(tex.texel(5, 0, 0).r == 0.0f);
    CHECK(tex.texel(5, 1, 0).r == 1.0f);
    // Level 6 (4x4) averages 2x2 cells: grey everywhere.
    CHECK(tex.texel(6, 2, 3).r == 0.5f);
}

TEST_CASE("level sizes halve, round down, stop at 1") {
    const Texture t53 = Texture::from_image(random_image(5, 3, 1), Wrap::Repeat, Wrap::Repeat);
    REQUIRE(t53.levels() == 3);
    CHECK(t53.width(0) == 5);  CHECK(t53.height(0) == 3);
    CHECK(t53.width(1) == 2);  CHECK(t53.height(1) == 1);
    CHECK(t53.width(2) == 1);  CHECK(t53.height(2) == 1);

    const Texture t17 = Texture::from_image(random_image(17, 1, 2), Wrap::Repeat, Wrap::Repeat);
    REQUIRE(t17.levels() == 5);  // 17, 8, 4, 2, 1
    CHECK(t17.width(1) == 8);
    CHECK(t17.height(4) == 1);

    const Texture t1 = Texture::from_image(random_image(1, 1, 3), Wrap::Repeat, Wrap::Repeat);
    CHECK(t1.levels() == 1);
    // Out-of-range levels clamp.
    CHECK(t53.width(99) == 1);
    CHECK(t53.width(-3) == 5);
}

TEST_CASE("the odd-size area filter preserves the mean") {
    // Stated tolerance: 2e-6 on values in [0, 1] (float rounding of the weights).
    for (const auto& size : {glm::ivec2(5, 3), glm::ivec2(7, 7), glm::ivec2(13, 6), glm::ivec2(3, 1),
                             glm::ivec2(101, 37)}) {
        const Texture tex = Texture::from_image(random_image(size.x, size.y, 7u + unsigned(size.x)),
                                                Wrap::Repeat, Wrap::Repeat);
        const glm::vec4 mean0 = image_mean(tex, 0);
        for (int l = 1; l < tex.levels(); ++l) check_near(image_mean(tex, l), mean0, 2e-6f);
        check_near(tex.average(), mean0, 2e-6f);
    }
    // A 3-wide row of (0, 3, 6) shrinks to 1 texel: weights (1, 1, 1) / 3.
    Image row;
    row.width = 3;
    row.height = 1;
    row.rgba = {0, 0, 0, 1, 3, 3, 3, 1, 6, 6, 6, 1};
    CHECK(Texture::from_image(row, Wrap::Repeat, Wrap::Repeat).texel(1, 0, 0).r == doctest::Approx(3.0));
    // 5 -> 2: output 0 = (2 a0 + 2 a1 + 1 a2) / 5, output 1 = (1 a2 + 2 a3 + 2 a4) / 5.
    Image five;
    five.width = 5;
    five.height = 1;
    five.rgba.assign(20, 1.0f);
    for (int x = 0; x < 5; ++x) five.rgba[4 * x] = float(x * x);  // 0 1 4 9 16
    const Texture t5 = Texture::from_image(five, Wrap::Repeat, Wrap::Repeat);
    CHECK(t5.texel(1, 0, 0).r == doctest::Approx((0 + 2 + 4) / 5.0));
    CHECK(t5.texel(1, 1, 0).r == doctest::Approx((4 + 18 + 32) / 5.0));
}

TEST_CASE("bilinear: texel centres and midpoints") {
    const Texture tex = Texture::from_image(numbered_image(4, 4), Wrap::Repeat, Wrap::Repeat);
    for (int y = 0; y < 4; ++y)
        for (int x = 0; x < 4; ++x) {
            const glm::vec4 s = tex.sample_bilinear((x + 0.5f) / 4.0f, (y + 0.5f) / 4.0f, 0);
            CHECK(s == tex.texel(0, x, y));
        }
    // Halfway between (1, 1) and (2, 1), and the centre of a 2x2 block.
    CHECK(tex.sample_bilinear(0.5f, 1.5f / 4.0f, 0) == (tex.texel(0, 1, 1) + tex.texel(0, 2, 1)) * 0.5f);
    check_near(tex.sample_bilinear(0.5f, 0.5f, 0),
               (tex.texel(0, 1, 1) + tex.texel(0, 2, 1) + tex.texel(0, 1, 2) + tex.texel(0, 2, 2)) * 0.25f,
               1e-6f);
    // Level argument clamps.
    CHECK(tex.sample_bilinear(0.3f, 0.7f, 42) == tex.average());
}

TEST_CASE("wrap modes at the borders") {
    const Image img = numbered_image(4, 4);
    const Texture rep = Texture::from_image(img, Wrap::Repeat, Wrap::Repeat);
    const Texture clamp = Texture::from_image(img, Wrap::ClampToEdge, Wrap::ClampToEdge);
    const Texture mirror = Texture::from_image(img, Wrap::MirroredRepeat, Wrap::MirroredRepeat);
    const float v = 1.5f / 4.0f;  // row 1 centre
    auto u_of = [](int i) { return (float(i) + 0.5f) / 4.0f; };  // centre of (virtual) texel i
    struct Case { int i, repeat, clamped, mirrored; };
    // Virtual index -> stored column: Repeat wraps, Clamp sticks, Mirrored reflects (period 8).
    for (const Case& c : {Case{-1, 3, 0, 0}, Case{-2, 2, 0, 1}, Case{-4, 0, 0, 3}, Case{4, 0, 3, 3},
                          Case{5, 1, 3, 2}, Case{7, 3, 3, 0}, Case{9, 1, 3, 1}, Case{-9, 3, 0, 0}}) {
        INFO("virtual texel " << c.i);
        CHECK(rep.sample_bilinear(u_of(c.i), v, 0) == rep.texel(0, c.repeat, 1));
        CHECK(clamp.sample_bilinear(u_of(c.i), v, 0) == clamp.texel(0, c.clamped, 1));
        CHECK(mirror.sample_bilinear(u_of(c.i), v, 0) == mirror.texel(0, c.mirrored, 1));
    }
    // On the edge u = 0: Repeat blends the first and last columns, the others do not.
    CHECK(rep.sample_bilinear(0.0f, v, 0) == (rep.texel(0, 3, 1) + rep.texel(0, 0, 1)) * 0.5f);
    CHECK(clamp.sample_bilinear(0.0f, v, 0) == clamp.texel(0, 0, 1));
    CHECK(mirror.sample_bilinear(0.0f, v, 0) == mirror.texel(0, 0, 1));
    // Per-axis modes: s repeats, t clamps.
    const Texture mixed = Texture::from_image(img, Wrap::Repeat, Wrap::ClampToEdge);
    CHECK(mixed.sample_bilinear(u_of(-1), u_of(-1), 0) == mixed.texel(0, 3, 0));
    CHECK(mixed.sample_bilinear(u_of(5), u_of(6), 0) == mixed.texel(0, 1, 3));
}

TEST_CASE("trilinear LOD picks the level of a plane seen at an angle") {
    const Texture tex = Texture::from_image(random_image(64, 64, 11), Wrap::Repeat, Wrap::Repeat);
    REQUIRE(tex.levels() == 7);
    // Head-on, one pixel covers 2 texels; the plane turned 60 degrees about
    // the vertical axis stretches x by 1 / cos(60) = 2: 4 texels per pixel.
    const float cos60 = std::cos(glm::radians(60.0f));
    const float dudx = (2.0f / 64.0f) / cos60, dvdy = 2.0f / 64.0f;
    CHECK(tex.lod(dudx, 0.0f, 0.0f, dvdy) == doctest::Approx(2.0).epsilon(1e-5));
    // With exactly 4 texels per pixel: lambda = 2 exactly, and level 2 exactly.
    const float lambda = tex.lod(4.0f / 64.0f, 0.0f, 0.0f, 2.0f / 64.0f);
    CHECK(lambda == 2.0f);
    const float u = 0.3f, v = 0.55f;
    CHECK(tex.sample(u, v, 4.0f / 64.0f, 0.0f, 0.0f, 2.0f / 64.0f) == tex.sample_bilinear(u, v, 2));
    // The same footprint rotated 90 degrees (y stretched instead), and a
    // diagonal one: |(3, 4)| = 5 texels per pixel.
    CHECK(tex.lod(0.0f, 2.0f / 64.0f, 0.0f, 4.0f / 64.0f) == 2.0f);
    CHECK(tex.lod(3.0f / 64.0f, 4.0f / 64.0f, 0.0f, 1.0f / 64.0f) == doctest::Approx(std::log2(5.0)));
    // Non-square textures use each axis' size.
    const Texture wide = Texture::from_image(random_image(128, 32, 12), Wrap::Repeat, Wrap::Repeat);
    CHECK(wide.lod(1.0f / 128.0f, 0.0f, 0.0f, 8.0f / 32.0f) == 3.0f);
    // Between levels the result blends linearly.
    for (float t : {0.25f, 0.5f, 0.9f}) {
        const glm::vec4 expect =
            tex.sample_bilinear(u, v, 2) * (1.0f - t) + tex.sample_bilinear(u, v, 3) * t;
        check_near(tex.sample_trilinear(u, v, 2.0f + t), expect, 1e-6f);
    }
    // Magnification and the far end.
    CHECK(tex.sample_trilinear(u, v, -3.0f) == tex.sample_bilinear(u, v, 0));
    CHECK(tex.sample_trilinear(u, v, 0.0f) == tex.sample_bilinear(u, v, 0));
    CHECK(tex.sample_trilinear(u, v, 6.0f) == tex.average());
    CHECK(tex.sample_trilinear(u, v, 100.0f) == tex.average());
}

TEST_CASE("NaN and Inf never crash or leave the texture") {
    const float nan = std::numeric_limits<float>::quiet_NaN();
    const float inf = std::numeric_limits<float>::infinity();
    for (Wrap w : {Wrap::Repeat, Wrap::ClampToEdge, Wrap::MirroredRepeat}) {
        const Texture tex = Texture::from_image(random_image(16, 8, 5), w, w);
        CHECK(tex.sample_trilinear(nan, nan, 1.5f) == tex.sample_trilinear(0.0f, 0.0f, 1.5f));
        CHECK(tex.sample_trilinear(0.25f, 0.5f, nan) == tex.sample_bilinear(0.25f, 0.5f, 0));
        CHECK(tex.lod(nan, nan, nan, nan) == 0.0f);
        CHECK(std::isfinite(tex.lod(0.0f, 0.0f, 0.0f, 0.0f)));
        CHECK(std::isfinite(tex.lod(inf, 0.0f, 0.0f, 0.0f)));
        for (float u : {nan, inf, -inf, 1e30f, -1e30f, 3e9f, -2.5e9f, 1e-30f, -1e-30f, 0.9999999f})
            for (float lambda : {nan, -inf, -1.0f, 0.5f, 2.7f, 3.0f, inf}) {
                CHECK(all_finite(tex.sample_trilinear(u, 0.5f, lambda)));
                CHECK(all_finite(tex.sample_trilinear(0.5f, u, lambda)));
                CHECK(all_finite(tex.sample(u, u, u, 0.01f, lambda, 0.02f)));
            }
    }
}

TEST_CASE("default texture and invalid images") {
    const Texture white;
    CHECK(white.levels() == 1);
    CHECK(white.sample(0.3f, 0.4f, 0.1f, 0.0f, 0.0f, 0.1f) == glm::vec4(1.0f));
    CHECK_THROWS_AS(Texture::from_image(Image{}, Wrap::Repeat, Wrap::Repeat), std::invalid_argument);
    Image bad;
    bad.width = 2;
    bad.height = 2;
    bad.rgba.resize(15);
    CHECK_THROWS_AS(Texture::from_image(bad, Wrap::Repeat, Wrap::Repeat), std::invalid_argument);
}

TEST_CASE("decode: sRGB 8-bit RGBA, grey, grey+alpha") {
    TempDir dir("texture");
    // 4x1 RGBA with known bytes.
    const unsigned char rgba[16] = {0, 10, 128, 255, 255, 188, 64, 0, 1, 2, 3, 4, 200, 100, 50, 128};
    const std::string path = dir.file("rgba.png");
    REQUIRE(stbi_write_png(path.c_str(), 4, 1, 4, rgba, 16));
    const Image srgb = decode_image(file_source(path), true);
    const Image linear = decode_image(file_source(path), false);
    REQUIRE(srgb.width == 4);
    REQUIRE(srgb.height == 1);
    // Kept as the file's bytes: 4 channels, marked sRGB or not.
    CHECK(srgb.channels == 4);
    CHECK(srgb.srgb);
    CHECK(!linear.srgb);
    CHECK(srgb.pixels == std::vector<std::uint8_t>(rgba, rgba + 16));
    CHECK(srgb.rgba.empty());
    for (int i = 0; i < 16; ++i) {
        const float c = rgba[i] / 255.0f;
        const bool alpha = i % 4 == 3;
        CHECK(srgb.at(i / 4, 0)[i % 4] == doctest::Approx(alpha ? c : srgb_reference(c)).epsilon(1e-6));
        CHECK(linear.at(i / 4, 0)[i % 4] == doctest::Approx(c).epsilon(1e-7));
    }
    // Known values: sRGB 128 -> 0.21586, 188 -> 0.50289.
    CHECK(srgb.at(0, 0).b == doctest::Approx(0.2158605).epsilon(1e-5));
    CHECK(srgb.at(1, 0).g == doctest::Approx(0.5028865).epsilon(1e-5));
    CHECK(srgb.at(0, 0).r == 0.0f);
    CHECK(srgb.at(1, 0).r == 1.0f);

    // 3x2 grey: replicated to RGB, alpha 1.
    const unsigned char grey[6] = {0, 51, 102, 153, 204, 255};
    const std::string grey_path = dir.file("grey.png");
    REQUIRE(stbi_write_png(grey_path.c_str(), 3, 2, 1, grey, 3));
    const Image g = decode_image(file_source(grey_path), false);
    REQUIRE(g.width == 3);
    REQUIRE(g.height == 2);
    CHECK(g.channels == 1);
    for (int i = 0; i < 6; ++i) {
        const glm::vec4 t = g.at(i % 3, i / 3);
        CHECK(t.r == doctest::Approx(grey[i] / 255.0f));
        CHECK(t.g == t.r);
        CHECK(t.b == t.r);
        CHECK(t.a == 1.0f);
    }
    const Image gs = decode_image(file_source(grey_path), true);
    CHECK(gs.at(1, 0).g == doctest::Approx(srgb_reference(51 / 255.0f)).epsilon(1e-6));

    // Grey + alpha; alpha stays linear.
    const unsigned char ga[4] = {128, 64, 255, 255};
    const std::string ga_path = dir.file("ga.png");
    REQUIRE(stbi_write_png(ga_path.c_str(), 2, 1, 2, ga, 4));
    const Image gai = decode_image(file_source(ga_path), true);
    CHECK(gai.channels == 2);
    CHECK(gai.at(0, 0).b == doctest::Approx(srgb_reference(128 / 255.0f)).epsilon(1e-6));
    CHECK(gai.at(0, 0).a == doctest::Approx(64 / 255.0f));

    // The same bytes embedded (no path) decode identically; row 0 is the top.
    ImageSource embedded;
    embedded.bytes = read_bytes(path);
    embedded.name = "scene.glb#image0";
    CHECK(decode_image(embedded, true).pixels == srgb.pixels);
    const unsigned char two_rows[2] = {0, 255};
    const std::string rows_path = dir.file("rows.png");
    REQUIRE(stbi_write_png(rows_path.c_str(), 1, 2, 1, two_rows, 1));
    const Image rows = decode_image(file_source(rows_path), false);
    CHECK(rows.at(0, 0).r == 0.0f);
    CHECK(rows.at(0, 1).r == 1.0f);
}

TEST_CASE("decode: 16-bit PNG") {
    TempDir dir("texture");
    // 2x2 grey, 16-bit big-endian samples.
    const std::uint16_t values[4] = {0, 1, 32768, 65535};
    std::vector<unsigned char> samples;
    for (std::uint16_t s : values) {
        samples.push_back((unsigned char)(s >> 8));
        samples.push_back((unsigned char)(s & 0xFF));
    }
    const std::string path = dir.file("grey16.png");
    write_bytes(path, make_png(2, 2, 16, 0, samples));
    const Image linear = decode_image(file_source(path), false);
    REQUIRE(linear.width == 2);
    REQUIRE(linear.height == 2);
    for (int i = 0; i < 4; ++i) {
        const glm::vec4 t = linear.at(i % 2, i / 2);
        CHECK(t.r == doctest::Approx(values[i] / 65535.0).epsilon(1e-7));
        CHECK(t.b == t.r);
        CHECK(t.a == 1.0f);
    }
    // 1 / 65535 survives: an 8-bit path would have rounded it to 0.
    CHECK(linear.at(1, 0).r > 0.0f);
    const Image srgb = decode_image(file_source(path), true);
    CHECK(srgb.at(0, 1).g == doctest::Approx(srgb_reference(32768 / 65535.0f)).epsilon(1e-6));

    // 1x1 RGBA 16-bit.
    const std::vector<unsigned char> px = {0x12, 0x34, 0x80, 0x00, 0xFF, 0xFF, 0x40, 0x00};
    const std::string rgba_path = dir.file("rgba16.png");
    write_bytes(rgba_path, make_png(1, 1, 16, 6, px));
    const Image c = decode_image(file_source(rgba_path), false);
    CHECK(c.at(0, 0).r == doctest::Approx(0x1234 / 65535.0));
    CHECK(c.at(0, 0).g == doctest::Approx(0x8000 / 65535.0));
    CHECK(c.at(0, 0).b == 1.0f);
    CHECK(c.at(0, 0).a == doctest::Approx(0x4000 / 65535.0));
}

TEST_CASE("decode: HDR round-trips exactly") {
    TempDir dir("texture");
    // RGBE holds 8 mantissa bits per channel with a shared exponent: values
    // of the form k * 2^e with k < 256 and a common e per texel are exact.
    const float hdr[12] = {1.0f, 0.5f, 0.25f, 128.0f, 64.0f, 2.0f, 0.0f, 0.0f, 0.0f, 3.0f, 5.0f, 7.0f};
    const std::string path = dir.file("env.hdr");
    REQUIRE(stbi_write_hdr(path.c_str(), 2, 2, 3, hdr));
    for (bool srgb : {false, true}) {  // HDR data is linear whatever the flag says
        const Image img = decode_image(file_source(path), srgb);
        REQUIRE(img.width == 2);
        REQUIRE(img.height == 2);
        for (int i = 0; i < 4; ++i) {
            const glm::vec4 t = img.at(i % 2, i / 2);
            CHECK(t.r == hdr[3 * i]);
            CHECK(t.g == hdr[3 * i + 1]);
            CHECK(t.b == hdr[3 * i + 2]);
            CHECK(t.a == 1.0f);
        }
    }
}

TEST_CASE("decode: bad files throw LoadError naming the file") {
    TempDir dir("texture");
    require_load_error(file_source(dir.file("missing.png")), "missing.png");
    require_load_error(file_source(dir.path.string()), dir.path.filename().string());

    const std::string empty = dir.file("empty.png");
    write_bytes(empty, {});
    require_load_error(file_source(empty), "empty.png");

    // A valid 8x8 PNG, cut at many lengths.
    unsigned char pixels[8 * 8 * 3];
    for (int i = 0; i < 8 * 8 * 3; ++i) pixels[i] = (unsigned char)(i * 37);
    const std::string good = dir.file("good.png");
    REQUIRE(stbi_write_png(good.c_str(), 8, 8, 3, pixels, 24));
    const std::vector<unsigned char> png = read_bytes(good);
    REQUIRE(png.size() > 40);
    CHECK_NOTHROW(decode_image(file_source(good), true));
    for (std::size_t cut : {std::size_t(1), std::size_t(7), std::size_t(8), std::size_t(20), std::size_t(33),
                            std::size_t(45), png.size() / 2, png.size() - 20}) {
        const std::string name = "cut_" + std::to_string(cut) + ".png";
        write_bytes(dir.file(name), std::vector<unsigned char>(png.begin(), png.begin() + std::ptrdiff_t(cut)));
        require_load_error(file_source(dir.file(name)), name);
    }

    // Corrupt headers: a broken signature, a broken IHDR length.
    std::vector<unsigned char> sig = png;
    sig[1] = 'X';
    write_bytes(dir.file("bad_sig.png"), sig);
    require_load_error(file_source(dir.file("bad_sig.png")), "bad_sig.png");
    std::vector<unsigned char> ihdr = png;
    ihdr[11] = 14;  // IHDR length must be 13
    write_bytes(dir.file("bad_ihdr.png"), ihdr);
    require_load_error(file_source(dir.file("bad_ihdr.png")), "bad_ihdr.png");

    // Zero size, and an absurd size refused before allocation (with the numbers).
    const std::vector<unsigned char> one_px = {0};
    write_bytes(dir.file("zero.png"), make_png(0, 1, 8, 2, {}));
    require_load_error(file_source(dir.file("zero.png")), "zero.png");
    write_bytes(dir.file("huge.png"), make_png(20000, 20000, 8, 0, one_px));
    require_load_error(file_source(dir.file("huge.png")), "400000000");
    require_load_error(file_source(dir.file("huge.png")), "huge.png");

    // Embedded bytes use the source's name; bytes that are no image at all.
    ImageSource junk;
    junk.bytes = {'h', 'e', 'l', 'l', 'o'};
    junk.name = "model.glb#image2";
    require_load_error(junk, "model.glb#image2");
    ImageSource nothing;
    nothing.name = "nothing";
    require_load_error(nothing, "nothing");
}

namespace {

// pixels (w x h, `format` a TJPF_*) compressed by libjpeg-turbo.
std::vector<unsigned char> tj_compress(const std::vector<unsigned char>& pixels, int w, int h, int format,
                                       int subsamp, int quality, int flags = 0) {
    tjhandle tj = tjInitCompress();
    REQUIRE(tj);
    unsigned char* out = nullptr;
    unsigned long size = 0;
    const int ok = tjCompress2(tj, pixels.data(), w, 0, h, format, &out, &size, subsamp, quality, flags);
    INFO(tjGetErrorStr2(tj));
    REQUIRE(ok == 0);
    std::vector<unsigned char> bytes(out, out + size);
    tjFree(out);
    tjDestroy(tj);
    return bytes;
}

Image decode_bytes(const std::vector<unsigned char>& bytes, const char* name) {
    ImageSource src;
    src.bytes = bytes;
    src.name = name;
    return decode_image(src, true);
}

} // namespace

TEST_CASE("decode: JPEG through libjpeg-turbo (colour, grey, CMYK, progressive)") {
    // A smooth colour gradient, 4:2:0 at quality 95: within 3 of stb_image's
    // decode of the same file (the two round their inverse DCTs, chroma
    // upsampling and colour conversion differently) and within 6 of the source.
    const int w = 67, h = 45;  // not multiples of the 16x16 MCU
    std::vector<unsigned char> rgb(std::size_t(w) * h * 3);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            unsigned char* p = &rgb[(std::size_t(y) * w + x) * 3];
            p[0] = (unsigned char)(x * 255 / (w - 1));
            p[1] = (unsigned char)(y * 255 / (h - 1));
            p[2] = (unsigned char)(128 + (x - y) / 2);
        }
    const std::vector<unsigned char> jpg = tj_compress(rgb, w, h, TJPF_RGB, TJSAMP_420, 95);
    const Image img = decode_bytes(jpg, "gradient.jpg");
    REQUIRE(img.width == w);
    REQUIRE(img.height == h);
    REQUIRE(img.channels == 3);
    CHECK(img.srgb);
    int sw = 0, sh = 0, sc = 0;
    stbi_uc* stb = stbi_load_from_memory(jpg.data(), int(jpg.size()), &sw, &sh, &sc, 3);
    REQUIRE(stb);
    int worst_stb = 0, worst_source = 0;
    for (std::size_t i = 0; i < rgb.size(); ++i) {
        worst_stb = std::max(worst_stb, std::abs(int(img.pixels[i]) - int(stb[i])));
        worst_source = std::max(worst_source, std::abs(int(img.pixels[i]) - int(rgb[i])));
    }
    stbi_image_free(stb);
    MESSAGE("JPEG gradient: largest difference " << worst_stb << " from stb_image, " << worst_source
                                                 << " from the source");
    CHECK(worst_stb <= 3);
    CHECK(worst_source <= 6);

    // Progressive coding reorders the same coefficients: the same image.
    const Image progressive =
        decode_bytes(tj_compress(rgb, w, h, TJPF_RGB, TJSAMP_420, 95, TJFLAG_PROGRESSIVE), "progressive.jpg");
    CHECK(progressive.pixels == img.pixels);

    // Grey: one channel.
    std::vector<unsigned char> grey(std::size_t(w) * h);
    for (std::size_t i = 0; i < grey.size(); ++i) grey[i] = (unsigned char)(i % 251);
    const Image g = decode_bytes(tj_compress(grey, w, h, TJPF_GRAY, TJSAMP_GRAY, 100), "grey.jpg");
    REQUIRE(g.channels == 1);
    REQUIRE(g.pixels.size() == grey.size());

    // CMYK (stored as Adobe YCCK, inverted): each colour is c * k / 255.
    // Flat 16x16 squares keep the lossy coding out of the way.
    const int cw = 32, ch = 32;
    const unsigned char inks[4][4] = {{255, 128, 0, 255}, {200, 255, 50, 128}, {0, 0, 0, 0}, {255, 255, 255, 64}};
    std::vector<unsigned char> cmyk(std::size_t(cw) * ch * 4);
    for (int y = 0; y < ch; ++y)
        for (int x = 0; x < cw; ++x)
            for (int c = 0; c < 4; ++c) cmyk[(std::size_t(y) * cw + x) * 4 + c] = inks[(y / 16) * 2 + x / 16][c];
    const Image k = decode_bytes(tj_compress(cmyk, cw, ch, TJPF_CMYK, TJSAMP_444, 100), "cmyk.jpg");
    REQUIRE(k.channels == 3);
    for (int s = 0; s < 4; ++s) {
        const int x = (s % 2) * 16 + 8, y = (s / 2) * 16 + 8;
        for (int c = 0; c < 3; ++c) {
            const int want = (inks[s][c] * inks[s][3] + 127) / 255;
            CHECK(std::abs(int(k.pixels[(std::size_t(y) * cw + x) * 3 + c]) - want) <= 2);
        }
    }
}

TEST_CASE("decode with room for the mips: the texture takes the decoded buffer, same pixels and texels") {
    std::mt19937 rng(23u);
    struct Case {
        const char* name;
        std::vector<unsigned char> bytes;
    };
    std::vector<Case> cases;
    for (int channels = 1; channels <= 4; ++channels) {
        const int w = 37 + channels * 20, h = 29 + channels;
        std::vector<std::uint8_t> px(std::size_t(w) * std::size_t(h) * std::size_t(channels));
        for (std::uint8_t& b : px) b = std::uint8_t(rng() & 0xFFu);
        cases.push_back({"png", encode_png_pixels(px.data(), w, h, channels)});
    }
    for (int format : {TJPF_GRAY, TJPF_RGB}) {
        const int w = 64, h = 40, C = format == TJPF_GRAY ? 1 : 3;
        std::vector<unsigned char> px(std::size_t(w) * h * C);
        for (std::size_t i = 0; i < px.size(); ++i) px[i] = (unsigned char)((i * 7) ^ (i >> 5));
        cases.push_back({"jpeg", tj_compress(px, w, h, format, format == TJPF_GRAY ? TJSAMP_GRAY : TJSAMP_420, 90)});
    }
    for (const Case& c : cases)
        for (bool srgb : {false, true}) {
            ImageSource src;
            src.bytes = c.bytes;
            src.name = c.name;
            const Image plain = decode_image(src, srgb);
            Image roomy = decode_image(src, srgb, &Texture::unorm8_bytes);
            INFO(c.name, " ", plain.width, "x", plain.height, " channels ", plain.channels, " srgb ", srgb);
            REQUIRE(roomy.pixels == plain.pixels);
            CHECK(roomy.pixels.capacity() >= Texture::unorm8_bytes(roomy.width, roomy.height, roomy.channels));
            const std::uint8_t* buffer = roomy.pixels.data();
            const Texture copied = Texture::from_image(plain);
            const Texture adopted = Texture::from_image(std::move(roomy));
            CHECK(adopted.unorm8_data() == buffer);  // level 0 not copied
            CHECK(copied.unorm8_data() != plain.pixels.data());
            REQUIRE(adopted.memory_bytes() == copied.memory_bytes());
            CHECK(std::memcmp(adopted.unorm8_data(), copied.unorm8_data(), copied.memory_bytes()) == 0);
            // The read slack past the last level is zero in both.
            for (std::size_t i = 0; i < 8; ++i) CHECK(adopted.unorm8_data()[copied.memory_bytes() + i] == 0);
        }
}

TEST_CASE("decode: randomly corrupted PNG and JPEG never crash") {
    TempDir dir("texture");
    unsigned char pixels[16 * 16 * 3];
    for (int i = 0; i < 16 * 16 * 3; ++i) pixels[i] = (unsigned char)((i * 7) ^ (i >> 3));
    const std::string png_path = dir.file("small.png"), jpg_path = dir.file("small.jpg");
    REQUIRE(stbi_write_png(png_path.c_str(), 16, 16, 3, pixels, 48));
    REQUIRE(stbi_write_jpg(jpg_path.c_str(), 16, 16, 3, pixels, 90));

    std::mt19937 rng(20240611u);
    int decoded = 0, rejected = 0;
    for (const std::string& path : {png_path, jpg_path}) {
        const std::vector<unsigned char> original = read_bytes(path);
        REQUIRE(!original.empty());
        for (int round = 0; round < 300; ++round) {
            std::vector<unsigned char> bytes = original;
            // Flip 1-8 random bytes; a third of the time also truncate.
            const int flips = 1 + int(rng() % 8);
            for (int f = 0; f < flips; ++f) bytes[rng() % bytes.size()] ^= (unsigned char)(1 + rng() % 255);
            if (rng() % 3 == 0) bytes.resize(1 + rng() % bytes.size());
            ImageSource src;
            src.bytes = bytes;
            src.name = "fuzz" + std::to_string(round);
            try {
                const Image img = decode_image(src, round % 2 == 0);
                CHECK(img.pixels.size() == img.texel_count() * std::size_t(img.channels));
                ++decoded;
            } catch (const LoadError& e) {
                CHECK(std::string(e.what()).find(src.name) != std::string::npos);
                ++rejected;
            }
        }
    }
    MESSAGE("corrupted images: " << decoded << " decoded, " << rejected << " rejected");
    CHECK(decoded + rejected == 600);
    CHECK(rejected > 0);
}

TEST_CASE("procedural brick textures") {
    const int size = 128;
    const Image albedo = make_tiles_albedo(size);
    const Image normal = make_tiles_normal(size);
    const Image orm = make_tiles_roughness_metal(size);
    for (const Image* img : {&albedo, &normal, &orm}) {
        REQUIRE(img->width == size);
        REQUIRE(img->height == size);
        REQUIRE(img->rgba.size() == std::size_t(size * size * 4));
    }
    // Deterministic.
    CHECK(make_tiles_albedo(size).rgba == albedo.rgba);
    CHECK(make_tiles_normal(size).rgba == normal.rgba);
    // Made together (as the built-in scene does, in bands of rows), the same texels.
    for (int n : {size, 37}) {
        CAPTURE(n);
        TileMaps maps = tile_maps_storage(n);
        for (int y = n; y > 0; y -= 5) fill_tile_map_rows(maps, std::max(0, y - 5), y);
        CHECK(maps.albedo.rgba == (n == size ? albedo : make_tiles_albedo(n)).rgba);
        CHECK(maps.normal.rgba == (n == size ? normal : make_tiles_normal(n)).rgba);
        CHECK(maps.roughness_metal.rgba == (n == size ? orm : make_tiles_roughness_metal(n)).rgba);
        CHECK(make_tile_maps(n).normal.rgba == maps.normal.rgba);
    }

    int grout = 0, metal = 0, tilted = 0;
    for (int y = 0; y < size; ++y)
        for (int x = 0; x < size; ++x) {
            const glm::vec4 a = albedo.at(x, y), n = normal.at(x, y), m = orm.at(x, y);
            // Albedo and ORM in [0, 1], opaque.
            for (int c = 0; c < 4; ++c) {
                CHECK(a[c] >= 0.0f);
                CHECK(a[c] <= 1.0f);
                CHECK(m[c] >= 0.0f);
                CHECK(m[c] <= 1.0f);
            }
            CHECK(a.a == 1.0f);
            // Unit normals pointing out of the surface.
            const glm::vec3 v = glm::vec3(n) * 2.0f - 1.0f;
            CHECK(glm::length(v) == doctest::Approx(1.0).epsilon(1e-5));
            CHECK(v.z > 0.5f);
            if (v.z < 0.95f) ++tilted;
            if (m.g > 0.8f) ++grout;
            if (m.b > 0.99f) ++metal;
        }
    CHECK(grout > size * size / 20);  // the grout is there, and rough
    CHECK(metal > 0);                 // some gold bricks
    CHECK(tilted > size * 2);         // bevels and grooves

    // The top row of bricks starts at v = 0: the grout between rows runs
    // along y = 0, where the bevel below tilts the normal up the image (+green).
    const glm::vec3 below_joint = glm::vec3(normal.at(5, 1)) * 2.0f - 1.0f;
    CHECK(below_joint.y > 0.3f);

    // Seamless under Repeat: the wrap-around difference is like any other.
    double wrap = 0.0, inner = 0.0;
    for (int y = 0; y < size; ++y) {
        wrap += glm::length(albedo.at(0, y) - albedo.at(size - 1, y));
        inner += glm::length(albedo.at(size / 2, y) - albedo.at(size / 2 - 1, y));
    }
    CHECK(wrap < 3.0 * inner + 1.0);

    const Image checker = make_checker(8, 2, glm::vec4(0.0f), glm::vec4(1.0f));
    CHECK(checker.at(0, 0) == glm::vec4(0.0f));
    CHECK(checker.at(4, 0) == glm::vec4(1.0f));
    CHECK(checker.at(4, 4) == glm::vec4(0.0f));
}

} // TEST_SUITE

// Tone mapping tests: the operators' known values and shapes, and the 8-bit
// resolve against hand-computed bytes and against the per-pixel reference;
// the vectorised resolve on every special value and at every sRGB threshold;
// the tile-pass resolve of a frame against the whole-image resolve.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

#include "scene/default_scene.h"
#include "shading/color.h"
#include "shading/output8.h"
#include "renderer/scene_renderer.h"
#include "shading/tonemap.h"

using namespace prast;

namespace {

float aces(float x) { return tonemap(glm::vec3(x), ToneMap::Aces).x; }
glm::vec3 neutral(glm::vec3 c) { return tonemap(c, ToneMap::Neutral); }

void check_near(glm::vec3 a, glm::vec3 b, double eps) {
    for (int i = 0; i < 3; ++i) CHECK(a[i] == doctest::Approx(b[i]).epsilon(eps));
}

// The per-pixel reference: tonemap(), then linear_to_srgb8() (std::pow),
// alpha clamped and rounded.
void reference_pixel(const float* c, float exposure, ToneMap tm, std::uint8_t* out) {
    const glm::vec3 m = tonemap(glm::vec3(c[0], c[1], c[2]) * exposure, tm);
    for (int k = 0; k < 3; ++k) out[k] = linear_to_srgb8(m[k]);
    float a = c[3];
    a = a > 0.0f ? (a < 1.0f ? a : 1.0f) : 0.0f;
    out[3] = std::uint8_t(std::floor(a * 255.0f + 0.5f));
}

float from_bits(std::uint32_t b) {
    float f;
    std::memcpy(&f, &b, sizeof f);
    return f;
}

} // namespace

TEST_SUITE("tonemap") {

TEST_CASE("parse_tonemap") {
    ToneMap tm = ToneMap::None;
    CHECK(parse_tonemap("aces", tm));
    CHECK(tm == ToneMap::Aces);
    CHECK(parse_tonemap("neutral", tm));
    CHECK(tm == ToneMap::Neutral);
    CHECK(parse_tonemap("none", tm));
    CHECK(tm == ToneMap::None);
    CHECK_FALSE(parse_tonemap("reinhard", tm));
    CHECK_FALSE(parse_tonemap("ACES", tm));
    CHECK(tm == ToneMap::None);
    CHECK(std::string(tonemap_name(ToneMap::Neutral)) == "neutral");
}

TEST_CASE("none clamps to [0, 1]") {
    CHECK(tonemap(glm::vec3(-1.0f, 0.5f, 3.0f), ToneMap::None) == glm::vec3(0.0f, 0.5f, 1.0f));
    CHECK(tonemap(glm::vec3(std::numeric_limits<float>::quiet_NaN()), ToneMap::None).x == 0.0f);
}

TEST_CASE("aces: Narkowicz fit, known values and shape") {
    CHECK(aces(0.0f) == 0.0f);  // 0 / 0.14
    // x = 1: 2.54 / 3.16 = 0.8037975; x = 0.5: 0.6425 / 1.0425 = 0.6163070.
    CHECK(aces(1.0f) == doctest::Approx(0.8037975).epsilon(1e-6));
    CHECK(aces(0.5f) == doctest::Approx(0.6163070).epsilon(1e-6));
    // The fit tends to 2.51 / 2.43 > 1 and crosses 1 at
    // x = (0.56 + sqrt(0.56^2 + 4 * 0.08 * 0.14)) / 0.16 = 7.2417; the clamp holds it at 1 beyond.
    CHECK(aces(7.2f) < 1.0f);
    CHECK(aces(7.3f) == 1.0f);
    CHECK(aces(1e6f) == 1.0f);
    CHECK(aces(-1.0f) == 0.0f);
    float prev = 0.0f;
    for (int i = 1; i <= 20000; ++i) {
        float x = float(i) * 0.001f;
        float y = aces(x);
        CAPTURE(x);
        CHECK(y >= prev);
        CHECK(y <= 1.0f);
        prev = y;
    }
    CHECK(aces(2.0f) < 1.0f);
}

TEST_CASE("neutral: Khronos PBR Neutral") {
    // Below the compression start (peak after the offset < 0.76) the operator
    // is the identity minus the toe offset: 0.04 once the smallest channel
    // reaches 0.08 (so neutral(x) = x - 0.04, not x), x - 6.25 x^2 below.
    check_near(neutral(glm::vec3(0.3f, 0.2f, 0.1f)), glm::vec3(0.26f, 0.16f, 0.06f), 1e-6);
    check_near(neutral(glm::vec3(0.5f)), glm::vec3(0.46f), 1e-6);
    // Toe: min = 0.04, offset = 0.04 - 6.25 * 0.0016 = 0.03.
    check_near(neutral(glm::vec3(0.04f, 0.5f, 0.2f)), glm::vec3(0.01f, 0.47f, 0.17f), 1e-5);
    CHECK(neutral(glm::vec3(0.0f)) == glm::vec3(0.0f));
    // Compression, grey 1: offset 0.04, peak 0.96, d = 0.24,
    // new peak = 1 - 0.0576 / (0.96 + 0.24 - 0.76) = 0.8690909; grey stays grey.
    check_near(neutral(glm::vec3(1.0f)), glm::vec3(0.8690909f), 1e-6);
    // (2, 1, 0.5): offset 0.04 -> (1.96, 0.96, 0.46), peak 1.96, new peak
    // 1 - 0.0576 / 1.44 = 0.96, scale 0.96 / 1.96 -> (0.96, 0.4702041, 0.2253061),
    // g = 1 - 1 / (0.15 * 1.0 + 1) = 0.1304348, mix towards 0.96:
    // (0.96, 0.5340905, 0.3211358).
    check_near(neutral(glm::vec3(2.0f, 1.0f, 0.5f)), glm::vec3(0.96f, 0.5340905f, 0.3211358f), 1e-5);
    // Monotone in grey up to float rounding (the peak's rescale
    // c * (new_peak / peak) wobbles by 1 ulp near 1), and below 1.
    float prev = 0.0f;
    for (int i = 1; i <= 20000; ++i) {
        float y = neutral(glm::vec3(float(i) * 0.005f)).x;
        CAPTURE(i);
        CHECK(y >= prev - 2e-7f);
        CHECK(y < 1.0f);
        prev = y;
    }
    // Negative input is treated as 0.
    CHECK(neutral(glm::vec3(-1.0f, 0.5f, 0.5f)).x == 0.0f);
}

TEST_CASE("resolve_to_srgb8 gives the hand-computed bytes") {
    SUBCASE("none, exposure 1; alpha clamped and rounded") {
        // 0.5 -> 188, 0.001 -> 3, 0.0031308 -> 10 (see test_color), NaN -> 0;
        // alpha 0.25 -> floor(63.75 + 0.5) = 64, -0.2 -> 0, 1.7 -> 255.
        const float nan = std::numeric_limits<float>::quiet_NaN();
        const float in[] = {0.5f, 0.0f, 1.0f, 1.0f,       0.001f, 2.0f, -1.0f, 0.25f,
                            0.0031308f, nan, 0.5f, -0.2f, 1.0f, 1.0f, 1.0f, 1.7f};
        const std::uint8_t expected[] = {188, 0, 255, 255, 3, 255, 0, 64,
                                         10, 0, 188, 0, 255, 255, 255, 255};
        std::uint8_t out[16] = {};
        resolve_to_srgb8(in, 2, 2, 1.0f, ToneMap::None, out);
        for (int i = 0; i < 16; ++i) {
            CAPTURE(i);
            CHECK(int(out[i]) == int(expected[i]));
        }
    }
    SUBCASE("aces, exposure 2; alpha not exposed") {
        // (0.25, 0.5, 0.05) * 2 = (0.5, 1, 0.1) -> aces (0.6163070, 0.8037975, 0.1258397)
        // -> sRGB * 255 + 0.5 = (206.37, 232.10, 99.90) -> (206, 232, 99); alpha 0.5 -> 128.
        const float in[] = {0.25f, 0.5f, 0.05f, 0.5f};
        std::uint8_t out[4] = {};
        resolve_to_srgb8(in, 1, 1, 2.0f, ToneMap::Aces, out);
        CHECK(int(out[0]) == 206);
        CHECK(int(out[1]) == 232);
        CHECK(int(out[2]) == 99);
        CHECK(int(out[3]) == 128);
    }
    SUBCASE("neutral, exposure 1") {
        // (1, 1, 1) -> 0.8690909 -> 240.22 -> 240;
        // (2, 1, 0.5) -> (0.96, 0.5340905, 0.3211358) -> (250.96, 193.63, 154.06) -> (250, 193, 154);
        // (0.3, 0.2, 0.1) -> (0.26, 0.16, 0.06) -> (139.95, 111.84, 69.78) -> (139, 111, 69).
        const float in[] = {1.0f, 1.0f, 1.0f, 1.0f, 2.0f, 1.0f, 0.5f, 1.0f, 0.3f, 0.2f, 0.1f, 1.0f};
        const std::uint8_t expected[] = {240, 240, 240, 255, 250, 193, 154, 255, 139, 111, 69, 255};
        std::uint8_t out[12] = {};
        resolve_to_srgb8(in, 3, 1, 1.0f, ToneMap::Neutral, out);
        for (int i = 0; i < 12; ++i) {
            CAPTURE(i);
            CHECK(int(out[i]) == int(expected[i]));
        }
    }
}

TEST_CASE("resolve_to_srgb8 equals the per-pixel reference") {
    // linear_to_srgb8(tonemap(c * exposure)) for HDR values over [0, 8).
    const int w = 64, h = 32;
    std::vector<float> in(std::size_t(w) * h * 4);
    std::uint32_t s = 12345u;
    for (float& x : in) {
        s = s * 1664525u + 1013904223u;  // LCG, same on every platform
        x = float(s >> 8) * (8.0f / 16777216.0f);
    }
    std::vector<std::uint8_t> out(in.size());
    for (ToneMap tm : {ToneMap::None, ToneMap::Aces, ToneMap::Neutral}) {
        const float exposure = 0.7f;
        resolve_to_srgb8(in.data(), w, h, exposure, tm, out.data());
        int mismatches = 0;
        for (std::size_t p = 0; p < std::size_t(w) * h; ++p) {
            const float* c = &in[p * 4];
            glm::vec3 m = tonemap(glm::vec3(c[0], c[1], c[2]) * exposure, tm);
            for (int k = 0; k < 3; ++k) mismatches += out[p * 4 + k] != linear_to_srgb8(m[k]);
            float a = std::min(c[3], 1.0f);
            mismatches += out[p * 4 + 3] != std::uint8_t(std::floor(a * 255.0f + 0.5f));
        }
        CAPTURE(std::string(tonemap_name(tm)));
        CHECK(mismatches == 0);
    }
}

TEST_CASE("resolve_pixels_srgb8 (eight lanes) equals the reference on special values and every threshold") {
    // Values: specials, both sides of every sRGB byte threshold (the floats
    // where the reference's byte changes), and a wide random spread.
    std::vector<float> values = {0.0f, -0.0f, 1.0f, -1.0f, 0.5f, 1e-45f, -1e-45f, 1e-38f, 1e30f, -1e30f, 3.4e38f,
                                 std::numeric_limits<float>::infinity(), -std::numeric_limits<float>::infinity(),
                                 std::numeric_limits<float>::quiet_NaN(), 0.76f, 0.04f, 0.08f, 2.0f, 65504.0f};
    const Srgb8Encoder& enc = Srgb8Encoder::instance();
    for (int b = 1; b < 256; ++b) {
        const std::uint32_t t = enc.threshold_bits(b);
        if (t == 0xFFFFFFFFu || t == 0) continue;
        for (std::uint32_t d : {t - 2, t - 1, t, t + 1, t + 2}) values.push_back(from_bits(d));
    }
    std::uint32_t seed = 777u;
    for (int i = 0; i < 4000; ++i) {
        seed = seed * 1664525u + 1013904223u;
        const float u = float(seed >> 8) * (1.0f / 16777216.0f);
        values.push_back((seed & 1u ? 1.0f : -0.05f) * std::exp2(u * 24.0f - 16.0f));
    }
    // Pixels from consecutive values (so each channel and alpha meet them all);
    // several counts, so the scalar tails run too.
    std::vector<float> rgba;
    for (std::size_t i = 0; i + 3 < values.size() * 4; ++i) rgba.push_back(values[(i * 7 + i / 5) % values.size()]);
    const std::size_t pixels = rgba.size() / 4;
    for (ToneMap tm : {ToneMap::None, ToneMap::Aces, ToneMap::Neutral})
        for (float exposure : {1.0f, 0.7f, 3.3f}) {
            CAPTURE(std::string(tonemap_name(tm)));
            CAPTURE(exposure);
            for (std::size_t count : {pixels, std::size_t(13), std::size_t(8), std::size_t(1)}) {
                std::vector<std::uint8_t> got(count * 4), want(count * 4);
                resolve_pixels_srgb8(rgba.data(), count, exposure, tm, got.data());
                for (std::size_t p = 0; p < count; ++p) reference_pixel(&rgba[p * 4], exposure, tm, &want[p * 4]);
                int mismatches = 0;
                for (std::size_t i = 0; i < got.size(); ++i) mismatches += got[i] != want[i];
                CHECK(mismatches == 0);
            }
        }
}

TEST_CASE("the tile-pass resolve of a frame equals the whole-image resolve byte for byte") {
    DefaultScene d = make_default_scene();
    const int W = 203, H = 117;
    for (int samples : {1, 4})
        for (int threads : {1, 3})
            for (int tile : {16, 64}) {
                for (DebugView view : {DebugView::None, DebugView::Normal, DebugView::Tiles}) {
                    CAPTURE(samples);
                    CAPTURE(threads);
                    CAPTURE(tile);
                    CAPTURE(int(view));
                    Renderer r({threads, tile});
                    SceneRenderer sr(d.scene, r);
                    FrameSettings fs;
                    fs.camera = d.camera;
                    fs.lights = default_light_rig();
                    fs.samples = samples;
                    fs.view = view;
                    Framebuffer fb(W, H);
                    std::vector<std::uint8_t> tiles(std::size_t(W) * H * 4, 7), whole(tiles.size(), 9);
                    ImageOutput out;
                    out.rgba8 = tiles.data();
                    out.exposure = 1.3f;
                    out.tonemap = view == DebugView::Tiles ? ToneMap::Neutral : ToneMap::Aces;
                    out.raw = view == DebugView::Normal;
                    sr.render(fs, fb, &out);
                    if (out.raw) resolve_raw8(fb.color.data(), W, H, whole.data());
                    else resolve_to_srgb8(fb.color.data(), W, H, out.exposure, out.tonemap, whole.data());
                    CHECK(tiles == whole);
                }
            }
}

} // TEST_SUITE

TEST_SUITE("tonemap") {
TEST_CASE("resolve_raw8 writes data views as value * 255, no sRGB") {
    const float px[8] = {0.0f, 0.5f, 1.0f, 0.2f, -1.0f, 2.0f, std::nanf(""), 0.0f};
    std::uint8_t out[8];
    prast::resolve_raw8(px, 2, 1, out);
    CHECK(out[0] == 0);
    CHECK(out[1] == 128);  // floor(127.5 + 0.5)
    CHECK(out[2] == 255);
    CHECK(out[3] == 255);  // alpha
    CHECK(out[4] == 0);    // clamped
    CHECK(out[5] == 255);
    CHECK(out[6] == 0);    // NaN
    CHECK(out[7] == 255);
}
}

TEST_CASE("the eight-lane sRGB encoder equals the scalar encoder over [0, 1]") {
    // Every 251st float of [0, 1], and every float within 64 ulps of each
    // byte threshold and of each 2^16-float bucket edge the lanes' table
    // uses (the floats where its entry or its comparison changes). With
    // ToneMap::None and exposure 1 the resolve is clamp01 then the encoder.
    // (Checked over every float of [0, 1] once by hand: no mismatch.)
    const Srgb8Encoder& enc = Srgb8Encoder::instance();
    constexpr std::uint32_t kOne = 0x3F800000u;
    std::vector<std::uint32_t> bits;
    for (std::uint32_t b = 0; b <= kOne; b += 251) bits.push_back(b);
    auto around = [&](std::uint32_t c) {
        for (std::uint32_t d = c < 64 ? 0 : c - 64; d <= c + 64 && d <= kOne; ++d) bits.push_back(d);
    };
    for (int b = 1; b < 256; ++b)
        if (enc.threshold_bits(b) != 0xFFFFFFFFu) around(enc.threshold_bits(b));
    for (std::uint32_t edge = 0; edge <= kOne; edge += 1u << 16) around(edge);
    std::vector<float> rgba(bits.size() * 4 + 4, 0.5f);  // whole pixels; alpha 0.5
    for (std::size_t i = 0; i < bits.size(); ++i) rgba[(i / 3) * 4 + i % 3] = from_bits(bits[i]);
    const std::size_t pixels = (bits.size() + 2) / 3;
    std::vector<std::uint8_t> out(pixels * 4);
    resolve_pixels_srgb8(rgba.data(), pixels, 1.0f, ToneMap::None, out.data());
    int mismatches = 0;
    for (std::size_t i = 0; i < bits.size(); ++i) {
        const float x = from_bits(bits[i]);
        mismatches += out[(i / 3) * 4 + i % 3] != enc(x);
    }
    CHECK(bits.size() > 4000000);
    CHECK(mismatches == 0);
}

TEST_CASE("Rgba8Buffer: zeroed, cache-line aligned, movable") {
    for (std::size_t pixels : {std::size_t(1), std::size_t(17), std::size_t(1920) * 1080}) {
        Rgba8Buffer b(pixels);
        REQUIRE(b.data() != nullptr);
        CHECK(reinterpret_cast<std::uintptr_t>(b.data()) % 64 == 0);
        std::size_t nonzero = 0;
        for (std::size_t i = 0; i < pixels * 4; ++i) nonzero += b.data()[i] != 0;
        CHECK(nonzero == 0);
        b.data()[pixels * 4 - 1] = 7;
        Rgba8Buffer moved(std::move(b));
        CHECK(b.data() == nullptr);
        CHECK(moved.data()[pixels * 4 - 1] == 7);
        b = std::move(moved);
        CHECK(b.data()[pixels * 4 - 1] == 7);
    }
    CHECK(Rgba8Buffer(0).data() == nullptr);
}

// sRGB transfer function tests: hand-computed values, the exact 8-bit round
// trip, and the fast encoder against the reference formula.
#include <doctest/doctest.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>

#include "shading/color.h"

using namespace prast;

namespace {

float from_bits(std::uint32_t bits) {
    float x;
    std::memcpy(&x, &bits, sizeof x);
    return x;
}

} // namespace

TEST_SUITE("color") {

TEST_CASE("sRGB transfer function: known values") {
    CHECK(srgb_to_linear(0.0f) == 0.0f);
    CHECK(srgb_to_linear(1.0f) == doctest::Approx(1.0).epsilon(1e-6));
    // ((0.5 + 0.055) / 1.055)^2.4 = 0.2140411
    CHECK(srgb_to_linear(0.5f) == doctest::Approx(0.2140411).epsilon(1e-6));
    // Linear segment: 0.04045 / 12.92 = 0.0031308
    CHECK(srgb_to_linear(0.04045f) == doctest::Approx(0.0031308).epsilon(1e-5));
    // 1.055 * 0.5^(1 / 2.4) - 0.055 = 0.7353570
    CHECK(linear_to_srgb(0.5f) == doctest::Approx(0.7353570).epsilon(1e-6));
    CHECK(linear_to_srgb(0.001f) == doctest::Approx(0.01292).epsilon(1e-6));
    CHECK(linear_to_srgb(srgb_to_linear(0.3f)) == doctest::Approx(0.3).epsilon(1e-6));

    // Bytes: 0.7353570 * 255 + 0.5 = 188.016 -> 188; 0.01292 * 255 + 0.5 = 3.79 -> 3;
    // 0.0031308 * 12.92 * 255 + 0.5 = 10.81 -> 10.
    CHECK(linear_to_srgb8(0.5f) == 188);
    CHECK(linear_to_srgb8(0.001f) == 3);
    CHECK(linear_to_srgb8(0.0031308f) == 10);
    CHECK(linear_to_srgb8(0.0f) == 0);
    CHECK(linear_to_srgb8(1.0f) == 255);
    // Clamping, and NaN -> 0.
    CHECK(linear_to_srgb8(-1.0f) == 0);
    CHECK(linear_to_srgb8(7.0f) == 255);
    CHECK(linear_to_srgb8(std::numeric_limits<float>::infinity()) == 255);
    CHECK(linear_to_srgb8(std::numeric_limits<float>::quiet_NaN()) == 0);
}

TEST_CASE("sRGB 8-bit round trip is exact for all 256 values") {
    const float* table = srgb8_to_linear_table();
    REQUIRE(table == srgb8_to_linear_table());  // built once
    CHECK(table[0] == 0.0f);
    CHECK(table[255] == doctest::Approx(1.0).epsilon(1e-6));
    for (int i = 0; i < 256; ++i) {
        CAPTURE(i);
        CHECK(int(linear_to_srgb8(table[i])) == i);
        CHECK(int(linear_to_srgb8_fast(table[i])) == i);
        if (i > 0) CHECK(table[i] > table[i - 1]);
    }
}

TEST_CASE("fast 8-bit encoder gives the reference byte") {
    // Checked once over all 1,065,353,217 floats in [0, 1] (0 mismatches, the
    // reference monotonic); here: every float within 64 ulps of each of the
    // 255 thresholds, every 997th float of [0, 1], and special values.
    const Srgb8Encoder& fast = Srgb8Encoder::instance();
    int mismatches = 0;
    auto check = [&](float x) {
        if (fast(x) != linear_to_srgb8(x)) {
            if (++mismatches <= 10) MESSAGE("mismatch at " << x);
        }
    };
    const std::uint32_t one = 0x3F800000u;
    for (int b = 1; b < 256; ++b) {
        std::uint32_t t = fast.threshold_bits(b);
        REQUIRE(t <= one);
        CHECK(linear_to_srgb8(from_bits(t)) >= b);
        if (t > 0) CHECK(linear_to_srgb8(from_bits(t - 1)) < b);
        for (std::int64_t d = -64; d <= 64; ++d) {
            std::int64_t bits = std::int64_t(t) + d;
            if (bits >= 0 && bits <= one) check(from_bits(std::uint32_t(bits)));
        }
    }
    for (std::uint32_t bits = 0; bits <= one; bits += 997) check(from_bits(bits));
    const float specials[] = {0.0f, -0.0f, 1.0f, -1.0f, 2.0f, 1e-45f, 1e-38f,
                              std::numeric_limits<float>::infinity(),
                              -std::numeric_limits<float>::infinity(),
                              std::numeric_limits<float>::quiet_NaN(),
                              std::nextafter(1.0f, 0.0f), std::nextafter(1.0f, 2.0f)};
    for (float x : specials) check(x);
    CHECK(mismatches == 0);
}

TEST_CASE("luminance uses the Rec. 709 weights") {
    CHECK(luminance(glm::vec3(1.0f)) == doctest::Approx(1.0).epsilon(1e-6));
    CHECK(luminance(glm::vec3(0.0f, 1.0f, 0.0f)) == doctest::Approx(0.7152).epsilon(1e-6));
    CHECK(luminance(glm::vec3(1.0f, 0.0f, 0.0f)) == doctest::Approx(0.2126).epsilon(1e-6));
    CHECK(luminance(glm::vec3(0.0f, 0.0f, 2.0f)) == doctest::Approx(0.1444).epsilon(1e-6));
}

} // TEST_SUITE

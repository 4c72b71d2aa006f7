// sRGB transfer functions and the tables built from them (see color.h).
#include "shading/color.h"

#include <array>
#include <cmath>

#include "scene/det_math.h"

namespace prast {

float srgb_to_linear(float c) {
    if (c <= 0.04045f) return c / 12.92f;
    return det::pow((c + 0.055f) / 1.055f, 2.4f);
}

float linear_to_srgb(float x) {
    if (x <= 0.0031308f) return x * 12.92f;
    return 1.055f * det::pow(x, 1.0f / 2.4f) - 0.055f;
}

std::uint8_t linear_to_srgb8(float x) {
    if (!(x > 0.0f)) x = 0.0f;  // also NaN
    if (x > 1.0f) x = 1.0f;
    return static_cast<std::uint8_t>(std::floor(linear_to_srgb(x) * 255.0f + 0.5f));
}

const float* srgb8_to_linear_table() {
    // A function-local static is initialised once, thread-safely (C++11).
    static const std::array<float, 256> table = [] {
        std::array<float, 256> t{};
        for (int i = 0; i < 256; ++i) t[i] = srgb_to_linear(float(i) / 255.0f);
        return t;
    }();
    return table.data();
}

const Srgb8Encoder& Srgb8Encoder::instance() {
    static const Srgb8Encoder encoder;
    return encoder;
}

Srgb8Encoder::Srgb8Encoder() {
    auto byte_of_bits = [](std::uint32_t bits) {
        float x;
        std::memcpy(&x, &bits, sizeof x);
        return int(linear_to_srgb8(x));
    };
    // Thresholds: bisection over the float bit patterns of [0, 1], which are
    // ordered like the values they encode.
    threshold_bits_[0] = 0;
    for (int b = 1; b < 256; ++b) {
        if (byte_of_bits(kOneBits) < b) {
            threshold_bits_[b] = 0xFFFFFFFFu;
            continue;
        }
        std::uint32_t lo = 0, hi = kOneBits;  // byte(lo) < b <= byte(hi), unless lo already reaches b
        if (byte_of_bits(lo) >= b) {
            threshold_bits_[b] = 0;
            continue;
        }
        while (hi - lo > 1) {
            std::uint32_t mid = lo + (hi - lo) / 2;
            if (byte_of_bits(mid) >= b) hi = mid; else lo = mid;
        }
        threshold_bits_[b] = hi;
    }
    // Coarse table: the byte at the first float of each bucket, by counting thresholds.
    int b = 0;
    for (int i = 0; i < kBuckets; ++i) {
        std::uint32_t start = std::uint32_t(i) << kBucketShift;
        while (b < 255 && threshold_bits_[b + 1] <= start) ++b;
        coarse_[i] = static_cast<std::uint8_t>(b);
    }
}

} // namespace prast

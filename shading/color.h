// Colour encodings: the sRGB transfer function (IEC 61966-2-1) both ways, the
// 8-bit decode table used for sRGB textures, an exact fast 8-bit encoder for
// the final resolve, and Rec. 709 luminance. Everything else in the project
// works on linear values.
#pragma once

#include <cstdint>
#include <cstring>

#include <glm/glm.hpp>

namespace prast {

// sRGB-encoded value in [0, 1] to linear (IEC 61966-2-1, the piecewise curve).
float srgb_to_linear(float c);
// Linear value in [0, 1] to sRGB-encoded; no clamping.
float linear_to_srgb(float x);
// Reference 8-bit encoder: clamp to [0, 1] (NaN -> 0), encode, then
// floor(e * 255 + 0.5). Every other encoder must match it byte for byte.
std::uint8_t linear_to_srgb8(float x);
// Linear values of the 256 sRGB bytes, srgb_to_linear(i / 255); built once, thread-safe.
const float* srgb8_to_linear_table();

// Relative luminance of linear Rec. 709 / sRGB primaries (ITU-R BT.709).
inline float luminance(glm::vec3 c) { return 0.2126f * c.r + 0.7152f * c.g + 0.0722f * c.b; }

// linear_to_srgb8 without std::pow, the same byte for every float. Since the
// encoding is monotonic, byte(x) = the number of thresholds t_1..t_255 <= x,
// where t_b is the smallest float the reference maps to b or more (found by
// bisection on the reference itself, so the tables cannot drift from it).
// A coarse table indexed by the top bits of x gives the byte at the start of
// x's bucket; at most one threshold falls inside a bucket, so one compare
// finishes (a loop, for safety). The tests compare it with the reference.
class Srgb8Encoder {
public:
    static const Srgb8Encoder& instance();

    std::uint8_t operator()(float x) const {
        // Clamp to [0, 1]; NaN fails both compares and becomes 0.
        if (!(x > 0.0f)) x = 0.0f;
        if (x > 1.0f) x = 1.0f;
        std::uint32_t bits;
        std::memcpy(&bits, &x, sizeof bits);
        unsigned b = coarse_[bits >> kBucketShift];
        while (b < 255u && bits >= threshold_bits_[b + 1]) ++b;
        return static_cast<std::uint8_t>(b);
    }

    // Bit pattern of the smallest float in [0, 1] encoding to byte b (b = 1..255);
    // 0xFFFFFFFF if none does. For the tests.
    std::uint32_t threshold_bits(int b) const { return threshold_bits_[b]; }

private:
    Srgb8Encoder();
    // A bucket spans 2^15 floats: 1/256 of an octave, under half a byte step
    // anywhere on the sRGB curve (the step peaks near 0.44 of a byte at x = 1).
    static constexpr int kBucketShift = 15;
    static constexpr std::uint32_t kOneBits = 0x3F800000u;  // 1.0f
    static constexpr int kBuckets = int(kOneBits >> kBucketShift) + 1;

    std::uint8_t coarse_[kBuckets];
    std::uint32_t threshold_bits_[256];
};

inline std::uint8_t linear_to_srgb8_fast(float x) { return Srgb8Encoder::instance()(x); }

} // namespace prast

// The 8-bit resolve, eight pixels at a time; see output8.h. Each lane performs
// the scalar reference's float operations in the same order (tonemap.cpp's
// operators) and encodes with Srgb8Encoder's byte thresholds (from a table of
// its own), so the bytes are the same: the GCC vector extension gives
// lane-wise IEEE arithmetic, and comparisons and selects are written to treat
// NaN as the scalar code's if/else does.
#include "shading/output8.h"

#include <cmath>
#include <cstdlib>
#include <cstring>
#include <vector>

#if defined(__AVX2__)
#include <immintrin.h>
#endif

#include "scene/huge_pages.h"
#include "shading/color.h"

namespace prast {

Rgba8Buffer::Rgba8Buffer(std::size_t pixels) {
    if (!pixels) return;
    if (pixels > (SIZE_MAX - 63) / 4) throw std::bad_alloc();
    const std::size_t bytes = pixels * 4 + 63;
    store_.reset(static_cast<std::uint8_t*>(allocate_huge(bytes)));
    std::memset(store_.get(), 0, bytes);
    const std::uintptr_t at = reinterpret_cast<std::uintptr_t>(store_.get());
    data_ = store_.get() + ((64 - (at & 63)) & 63);
}

void Rgba8Buffer::Free::operator()(std::uint8_t* p) const noexcept { free_huge(p); }

namespace {

inline std::uint8_t alpha8(float a) {
    if (!(a > 0.0f)) a = 0.0f;  // also NaN
    if (!(a < 1.0f)) a = 1.0f;
    return static_cast<std::uint8_t>(std::floor(a * 255.0f + 0.5f));
}

// The reference, one pixel (the tails of rows).
inline void resolve_pixel(const float* in, float exposure, ToneMap tm, std::uint8_t* out) {
    const Srgb8Encoder& encode = Srgb8Encoder::instance();
    const glm::vec3 c = tonemap(glm::vec3(in[0], in[1], in[2]) * exposure, tm);
    out[0] = encode(c.r);
    out[1] = encode(c.g);
    out[2] = encode(c.b);
    out[3] = alpha8(in[3]);
}

#if defined(__AVX2__)

typedef float F8 __attribute__((vector_size(32)));
typedef int I8 __attribute__((vector_size(32)));

inline F8 splat(float x) { return F8{x, x, x, x, x, x, x, x}; }
inline F8 select(I8 mask, F8 a, F8 b) { return mask ? a : b; }

// clamp01 of tonemap.cpp: !(x > 0) -> 0 (NaN too), then x < 1 ? x : 1.
inline F8 clamp01(F8 x) {
    x = select(x > 0.0f, x, splat(0.0f));
    return select(x < 1.0f, x, splat(1.0f));
}

inline F8 aces(F8 x) {
    x = select(x < 0.0f, splat(0.0f), x);  // std::max(x, 0): NaN stays NaN
    const F8 num = x * (2.51f * x + 0.03f);
    const F8 den = x * (2.43f * x + 0.59f) + 0.14f;
    return clamp01(num / den);
}

// Khronos PBR Neutral, as tonemap.cpp's pbr_neutral (glm's max/min/mix).
inline void neutral(F8& r, F8& g, F8& b) {
    constexpr float kF90 = 0.04f;
    constexpr float kStartCompression = 0.8f - 0.04f;
    constexpr float kDesaturation = 0.15f;
    constexpr float d = 1.0f - kStartCompression;
    // glm::max(c, 0): (c < 0) ? 0 : c.
    r = select(r < 0.0f, splat(0.0f), r);
    g = select(g < 0.0f, splat(0.0f), g);
    b = select(b < 0.0f, splat(0.0f), b);
    // std::min(r, std::min(g, b)): (b < a) ? b : a.
    const F8 gb = select(b < g, b, g);
    const F8 x = select(gb < r, gb, r);
    const F8 offset = select(x < 2.0f * kF90, x - 6.25f * x * x, splat(kF90));
    r = r - offset;
    g = g - offset;
    b = b - offset;
    // std::max(r, std::max(g, b)): (a < b) ? b : a.
    const F8 gb_max = select(g < b, b, g);
    const F8 peak = select(r < gb_max, gb_max, r);
    const I8 keep = peak < kStartCompression;
    const F8 new_peak = 1.0f - d * d / (peak + d - kStartCompression);
    const F8 scale = new_peak / peak;
    const F8 mix = 1.0f - 1.0f / (kDesaturation * (peak - new_peak) + 1.0f);
    const F8 keep_mix = 1.0f - mix;
    // c *= new_peak / peak; glm::mix(c, vec3(new_peak), mix) = c * (1 - mix) + new_peak * mix.
    r = select(keep, r, (r * scale) * keep_mix + new_peak * mix);
    g = select(keep, g, (g * scale) * keep_mix + new_peak * mix);
    b = select(keep, b, (b * scale) * keep_mix + new_peak * mix);
    r = clamp01(r);
    g = clamp01(g);
    b = clamp01(b);
}

// Srgb8Encoder on eight lanes with one gather per channel. A bucket of 2^16
// floats spans under 0.7 of a byte step anywhere on the sRGB curve, so it
// holds at most one threshold: its entry is the byte at its first float and
// that threshold's offset into the bucket (2^16: none), and the byte is the
// entry's plus one where the float's low bits reach the offset. The table
// starts at the bucket of the first threshold (entry 0 stands for every
// bucket below: byte 0), 6.6 KB, which stays in the L1 cache beside a tile.
class Srgb8Lanes {
public:
    static const Srgb8Lanes& instance() {
        static const Srgb8Lanes lanes;
        return lanes;
    }
    __m256i operator()(F8 x) const {
        x = select(x > 0.0f, x, splat(0.0f));
        x = select(x > 1.0f, splat(1.0f), x);
        __m256i bits;
        std::memcpy(&bits, &x, sizeof bits);
        const __m256i index = _mm256_max_epi32(
            _mm256_sub_epi32(_mm256_srli_epi32(bits, kBucketShift), _mm256_set1_epi32(first_bucket_ - 1)),
            _mm256_setzero_si256());
        const __m256i entry = _mm256_i32gather_epi32(entry_.data(), index, 4);
        const __m256i low = _mm256_and_si256(bits, _mm256_set1_epi32((1 << kBucketShift) - 1));
        // byte + (low >= offset), as byte - (all ones where !(offset > low)).
        const __m256i below = _mm256_cmpgt_epi32(_mm256_srli_epi32(entry, 8), low);
        return _mm256_sub_epi32(_mm256_and_si256(entry, _mm256_set1_epi32(0xFF)),
                                _mm256_andnot_si256(below, _mm256_set1_epi32(-1)));
    }

private:
    static constexpr int kBucketShift = 16;
    static constexpr std::uint32_t kOneBits = 0x3F800000u;  // 1.0f

    Srgb8Lanes() {
        const Srgb8Encoder& enc = Srgb8Encoder::instance();
        // threshold[b] = the smallest bits encoding to b or more (b >= 1);
        // bytes no float reaches get a value no input reaches.
        std::vector<std::uint32_t> threshold(257, 0xFFFFFFFFu);
        for (int b = 1; b < 256; ++b) threshold[std::size_t(b)] = enc.threshold_bits(b);
        const int last = int(kOneBits >> kBucketShift);
        first_bucket_ = int(threshold[1] >> kBucketShift);
        entry_.assign(std::size_t(last - first_bucket_ + 2), 0);
        entry_[0] = int(1u << (kBucketShift + 8));  // byte 0, no threshold
        int b = 0;
        for (int i = first_bucket_; i <= last; ++i) {
            const std::uint32_t start = std::uint32_t(i) << kBucketShift, end = start + (1u << kBucketShift);
            while (b < 255 && threshold[std::size_t(b) + 1] <= start) ++b;
            const std::uint32_t next = threshold[std::size_t(b) + 1];
            // A second threshold inside the bucket would need a wider table.
            if (next < end && threshold[std::size_t(b) + 2] < end) std::abort();
            const std::uint32_t offset = next < end ? next - start : 1u << kBucketShift;
            entry_[std::size_t(i - first_bucket_ + 1)] = int(std::uint32_t(b) | (offset << 8));
        }
    }

    std::vector<int> entry_;
    int first_bucket_ = 0;
};

inline void load8(const float* in, F8& r, F8& g, F8& b, F8& a) {
    // Pixels 0..7 as RGBA: after the two unpack rounds each channel holds the
    // pixels in the order 0 2 4 6 1 3 5 7 (undone when storing).
    const __m256 p0 = _mm256_loadu_ps(in), p1 = _mm256_loadu_ps(in + 8);
    const __m256 p2 = _mm256_loadu_ps(in + 16), p3 = _mm256_loadu_ps(in + 24);
    const __m256d t0 = _mm256_castps_pd(_mm256_unpacklo_ps(p0, p1)), t1 = _mm256_castps_pd(_mm256_unpackhi_ps(p0, p1));
    const __m256d t2 = _mm256_castps_pd(_mm256_unpacklo_ps(p2, p3)), t3 = _mm256_castps_pd(_mm256_unpackhi_ps(p2, p3));
    const __m256 vr = _mm256_castpd_ps(_mm256_unpacklo_pd(t0, t2)), vg = _mm256_castpd_ps(_mm256_unpackhi_pd(t0, t2));
    const __m256 vb = _mm256_castpd_ps(_mm256_unpacklo_pd(t1, t3)), va = _mm256_castpd_ps(_mm256_unpackhi_pd(t1, t3));
    std::memcpy(&r, &vr, sizeof r);
    std::memcpy(&g, &vg, sizeof g);
    std::memcpy(&b, &vb, sizeof b);
    std::memcpy(&a, &va, sizeof a);
}

inline void store8(__m256i r, __m256i g, __m256i b, __m256i a, std::uint8_t* out) {
    __m256i px = _mm256_or_si256(_mm256_or_si256(r, _mm256_slli_epi32(g, 8)),
                                 _mm256_or_si256(_mm256_slli_epi32(b, 16), _mm256_slli_epi32(a, 24)));
    px = _mm256_permutevar8x32_epi32(px, _mm256_setr_epi32(0, 4, 1, 5, 2, 6, 3, 7));
    _mm256_storeu_si256(reinterpret_cast<__m256i*>(out), px);
}

inline __m256i alpha_lanes(F8 a) {
    a = select(a > 0.0f, a, splat(0.0f));
    a = select(a < 1.0f, a, splat(1.0f));
    const F8 v = a * 255.0f + 0.5f;
    __m256 f;
    std::memcpy(&f, &v, sizeof f);
    return _mm256_cvttps_epi32(_mm256_floor_ps(f));
}

template <ToneMap TM>
void resolve_lanes(const float* in, std::size_t count, float exposure, std::uint8_t* out) {
    const Srgb8Lanes& encode = Srgb8Lanes::instance();
    std::size_t i = 0;
    for (; i + 8 <= count; i += 8, in += 32, out += 32) {
        F8 r, g, b, a;
        load8(in, r, g, b, a);
        r = r * exposure;
        g = g * exposure;
        b = b * exposure;
        if constexpr (TM == ToneMap::Aces) {
            r = aces(r);
            g = aces(g);
            b = aces(b);
        } else if constexpr (TM == ToneMap::Neutral) {
            neutral(r, g, b);
        } else {
            r = clamp01(r);
            g = clamp01(g);
            b = clamp01(b);
        }
        store8(encode(r), encode(g), encode(b), alpha_lanes(a), out);
    }
    for (; i < count; ++i, in += 4, out += 4) resolve_pixel(in, exposure, TM, out);
}

#endif

} // namespace

void resolve_pixels_srgb8(const float* rgba, std::size_t count, float exposure, ToneMap tm, std::uint8_t* out) {
#if defined(__AVX2__)
    switch (tm) {
    case ToneMap::Aces: resolve_lanes<ToneMap::Aces>(rgba, count, exposure, out); return;
    case ToneMap::Neutral: resolve_lanes<ToneMap::Neutral>(rgba, count, exposure, out); return;
    case ToneMap::None: resolve_lanes<ToneMap::None>(rgba, count, exposure, out); return;
    }
#endif
    for (std::size_t i = 0; i < count; ++i) resolve_pixel(rgba + 4 * i, exposure, tm, out + 4 * i);
}

void resolve_pixels_raw8(const float* rgba, std::size_t count, std::uint8_t* out) {
    for (std::size_t i = 0; i < count; ++i) {
        for (int c = 0; c < 3; ++c) {
            float x = rgba[i * 4 + c];
            x = x > 0.0f ? (x < 1.0f ? x : 1.0f) : 0.0f;  // NaN -> 0
            out[i * 4 + c] = std::uint8_t(std::floor(x * 255.0f + 0.5f));
        }
        out[i * 4 + 3] = 255;
    }
}

} // namespace prast

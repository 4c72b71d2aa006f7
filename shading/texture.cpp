// Texture: the box-filtered mip chains (float, and 8-bit with exact rounding)
// and the sampler tables; the samplers themselves are inline in texture.h.
#include "shading/texture.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <mutex>
#include <stdexcept>
#include <string>

#if defined(__SSSE3__)
#include <immintrin.h>
#endif

#include "scene/det_math.h"
#include "scene/huge_pages.h"
#include "raster/thread_pool.h"
#include "shading/isa.h"

namespace prast {

namespace {


// The source texels under output texel i when a row of n texels becomes
// max(1, n / 2): weights are the overlapped areas, normalised to sum to 1.
struct BoxTaps {
    int first = 0;
    int count = 0;
    float weight[3] = {0.0f, 0.0f, 0.0f};
};

BoxTaps box_taps(int n, int i) {
    BoxTaps t;
    if (n == 1) {  // this axis is already 1 texel: copy
        t.first = 0;
        t.count = 1;
        t.weight[0] = 1.0f;
    } else if (n % 2 == 0) {
        t.first = 2 * i;
        t.count = 2;
        t.weight[0] = t.weight[1] = 0.5f;
    } else {
        // n = 2m + 1 shrinks to m texels of width n / m = 2 + 1/m source texels;
        // output i spans [i n / m, (i + 1) n / m), which overlaps texels 2i, 2i+1
        // and 2i+2 by (m - i) / m, 1 and (i + 1) / m.
        const int m = n / 2;
        t.first = 2 * i;
        t.count = 3;
        t.weight[0] = float(m - i) / float(n);
        t.weight[1] = float(m) / float(n);
        t.weight[2] = float(i + 1) / float(n);
    }
    return t;
}

// Separable area filter for output rows [j0, j1): the source rows they need
// filtered horizontally into `tmp`, then columns into dst. Each output texel
// sees the same operations whichever rows a call covers.
void downsample(const glm::vec4* src, int sw, int sh, glm::vec4* dst, int dw, int j0, int j1,
                std::vector<glm::vec4>& tmp) {
    std::vector<BoxTaps> tx(static_cast<std::size_t>(dw));
    for (int i = 0; i < dw; ++i) tx[i] = box_taps(sw, i);
    const int y0 = box_taps(sh, j0).first;
    const BoxTaps last = box_taps(sh, j1 - 1);
    const int y1 = last.first + last.count;
    tmp.resize(std::size_t(dw) * std::size_t(y1 - y0));
    for (int y = y0; y < y1; ++y) {
        const glm::vec4* row = src + std::size_t(y) * std::size_t(sw);
        glm::vec4* out = tmp.data() + std::size_t(y - y0) * std::size_t(dw);
        for (int i = 0; i < dw; ++i) {
            const BoxTaps& t = tx[i];
            glm::vec4 sum(0.0f);
            for (int k = 0; k < t.count; ++k) sum += row[t.first + k] * t.weight[k];
            out[i] = sum;
        }
    }
    for (int j = j0; j < j1; ++j) {
        const BoxTaps t = box_taps(sh, j);
        glm::vec4* out = dst + std::size_t(j) * std::size_t(dw);
        for (int i = 0; i < dw; ++i) out[i] = glm::vec4(0.0f);
        for (int k = 0; k < t.count; ++k) {
            const glm::vec4* row = tmp.data() + std::size_t(t.first + k - y0) * std::size_t(dw);
            for (int i = 0; i < dw; ++i) out[i] += row[i] * t.weight[k];
        }
    }
}

// ---- 8-bit mips.

// The integer form of box_taps(): weights k[i] over the common denominator d
// (2 for even sizes, n for odd ones, 1 for a size of 1).
struct IntTaps {
    int first = 0, count = 0;
    std::int64_t k[3] = {0, 0, 0};
    std::int64_t d = 1;
};

IntTaps int_taps(int n, int i) {
    IntTaps t;
    if (n == 1) {
        t.count = 1;
        t.k[0] = 1;
    } else if (n % 2 == 0) {
        t.first = 2 * i;
        t.count = 2;
        t.k[0] = t.k[1] = 1;
        t.d = 2;
    } else {
        const int m = n / 2;
        t.first = 2 * i;
        t.count = 3;
        t.k[0] = m - i;
        t.k[1] = m;
        t.k[2] = i + 1;
        t.d = n;
    }
    return t;
}

// The exact sRGB transfer function (IEC 61966-2-1) in double: the reference
// both the mip re-encoding and the filter's sRGB codes round from.
double srgb_decode_exact(double c) {
    return c <= 0.04045 ? c / 12.92 : det::pow((c + 0.055) / 1.055, 2.4);
}

// Re-encoding linear values to sRGB bytes, correctly rounded: byte b is the
// number of thresholds T_k = decode((k + 0.5) / 255), k = 0..254, at or below
// the value (ties round up), with decode the exact sRGB transfer function in
// double. A 4097-entry table of the answer at i / 4096 gives the start of a
// search that then steps up at most a couple of times.
//
// The 2x2 case works in integers: each decoded byte (a float, a multiple of
// 2^-35 below 1) is value[b] = decoded * 2^35 exactly, a sum S of four is
// exact, and its mean S * 2^-37 >= T_k exactly when S >= ceil(T_k * 2^37).
// So encode_sum4(S) is encode(S * 2^-37) without a conversion to double.
struct SrgbEncoder {
    double threshold[256];      // [255] = +inf, a sentinel
    std::uint8_t start[4097];
    std::uint64_t value[256];            // srgb8_decode_table() * 2^35
    std::uint64_t threshold_sum4[256];   // ceil(threshold * 2^37); [255] a sentinel

    SrgbEncoder() {
        for (int k = 0; k < 255; ++k) threshold[k] = srgb_decode_exact((double(k) + 0.5) / 255.0);
        threshold[255] = HUGE_VAL;
        int b = 0;
        for (int i = 0; i <= 4096; ++i) {
            while (b < 255 && double(i) / 4096.0 >= threshold[b]) ++b;
            start[i] = std::uint8_t(b);
        }
        const float* srgb = srgb8_decode_table();
        for (int k = 0; k < 256; ++k) {
            value[k] = std::uint64_t(std::ldexp(double(srgb[k]), 35));
            // Not a multiple of 2^-35 (a different table): the integer path would round.
            if (std::ldexp(double(value[k]), -35) != double(srgb[k])) std::abort();
            threshold_sum4[k] = k < 255 ? std::uint64_t(std::ceil(std::ldexp(threshold[k], 37))) : ~std::uint64_t(0);
        }
        // encode_sum4's one step: every bucket [i, i + 1) / 4096 holds at most one threshold.
        for (int k = 1; k < 255; ++k)
            if (int(threshold[k] * 4096.0) == int(threshold[k - 1] * 4096.0)) std::abort();
    }
    // The byte of the mean of four decoded bytes, from the sum of their value[].
    // No 1/4096 of [0, 1] holds two thresholds (the closest are 1 / (255 *
    // 12.92) apart, near 0), so one compare finishes what start[] begins:
    // branch-free, as the data's order would mispredict a loop's exit.
    std::uint8_t encode_sum4(std::uint64_t sum) const {
        const int b = start[sum >> 25];  // int(mean * 4096), the mean at most 1
        return std::uint8_t(b + int(sum >= threshold_sum4[b]));
    }
    std::uint8_t encode(double linear) const {
        const double x = linear < 0.0 ? 0.0 : (linear > 1.0 ? 1.0 : linear);
        int b = start[int(x * 4096.0)];
        while (x >= threshold[b]) ++b;
        return std::uint8_t(b);
    }
};

const SrgbEncoder& srgb_encoder() {
    static const SrgbEncoder e;
    return e;
}

#if defined(__SSSE3__)
// Byte shuffles for 4 output texels of a linear C-channel 2x2 row: from the
// 8C input bytes (the first 16 in one register, the rest in another), byte
// k < 4C of `first` is input byte 2C (k / C) + k % C (the left texel's
// channel), of `second` the one C bytes on (the right texel's).
struct Pick2x2 {
    alignas(16) std::int8_t first_lo[16], first_hi[16], second_lo[16], second_hi[16];
};
constexpr Pick2x2 pick_2x2(int C) {
    Pick2x2 p{};
    for (int k = 0; k < 16; ++k) {
        const int a = k < 4 * C ? 2 * C * (k / C) + k % C : -1, b = a < 0 ? -1 : a + C;
        p.first_lo[k] = std::int8_t(a >= 0 && a < 16 ? a : -1);
        p.first_hi[k] = std::int8_t(a >= 16 ? a - 16 : -1);
        p.second_lo[k] = std::int8_t(b >= 0 && b < 16 ? b : -1);
        p.second_hi[k] = std::int8_t(b >= 16 ? b - 16 : -1);
    }
    return p;
}
template <int C> struct Pick2x2Of {
    static constexpr Pick2x2 pick = pick_2x2(C);
};

// The 8C bytes of 4 texel pairs of a row (lo: the first 16), never read past them.
template <int C> inline void load_2x2_block(const std::uint8_t* p, __m128i& lo, __m128i& hi) {
    lo = C == 1 ? _mm_loadl_epi64(reinterpret_cast<const __m128i*>(p))
                : _mm_loadu_si128(reinterpret_cast<const __m128i*>(p));
    hi = C == 3   ? _mm_loadl_epi64(reinterpret_cast<const __m128i*>(p + 16))
         : C == 4 ? _mm_loadu_si128(reinterpret_cast<const __m128i*>(p + 16))
                  : _mm_setzero_si128();
}

// Output texels [0, 4 * (dw / 4)) of a linear row, as the scalar loop below
// gives them: (a + b + c + d + 2) >> 2 per channel, in 16-bit lanes.
template <int C>
int downsample_2x2_linear_sse(const std::uint8_t* r0, const std::uint8_t* r1, std::uint8_t* out, int dw) {
    const Pick2x2& pk = Pick2x2Of<C>::pick;
    const __m128i fl = _mm_load_si128(reinterpret_cast<const __m128i*>(pk.first_lo));
    const __m128i fh = _mm_load_si128(reinterpret_cast<const __m128i*>(pk.first_hi));
    const __m128i sl = _mm_load_si128(reinterpret_cast<const __m128i*>(pk.second_lo));
    const __m128i sh = _mm_load_si128(reinterpret_cast<const __m128i*>(pk.second_hi));
    const __m128i zero = _mm_setzero_si128(), two = _mm_set1_epi16(2);
    int i = 0;
    for (; i + 4 <= dw; i += 4) {
        __m128i a0, b0, a1, b1;
        load_2x2_block<C>(r0 + std::size_t(i) * 2 * C, a0, b0);
        load_2x2_block<C>(r1 + std::size_t(i) * 2 * C, a1, b1);
        const __m128i f0 = _mm_or_si128(_mm_shuffle_epi8(a0, fl), _mm_shuffle_epi8(b0, fh));
        const __m128i s0 = _mm_or_si128(_mm_shuffle_epi8(a0, sl), _mm_shuffle_epi8(b0, sh));
        const __m128i f1 = _mm_or_si128(_mm_shuffle_epi8(a1, fl), _mm_shuffle_epi8(b1, fh));
        const __m128i s1 = _mm_or_si128(_mm_shuffle_epi8(a1, sl), _mm_shuffle_epi8(b1, sh));
        auto half = [&](auto unpack) {
            const __m128i top = _mm_add_epi16(unpack(f0, zero), unpack(s0, zero));
            const __m128i bottom = _mm_add_epi16(unpack(f1, zero), unpack(s1, zero));
            return _mm_srli_epi16(_mm_add_epi16(_mm_add_epi16(top, bottom), two), 2);
        };
        const __m128i lo = half([](__m128i x, __m128i z) { return _mm_unpacklo_epi8(x, z); });
        const __m128i hi = half([](__m128i x, __m128i z) { return _mm_unpackhi_epi8(x, z); });
        alignas(16) std::uint8_t bytes[16];
        _mm_store_si128(reinterpret_cast<__m128i*>(bytes), _mm_packus_epi16(lo, hi));
        std::memcpy(out + std::size_t(i) * C, bytes, 4 * C);  // the row's own bytes only
    }
    return i;
}
#endif

// One output row of the 2x2 case, the channel layout fixed at compile time:
// C channels, the colour ones sRGB when Srgb (alpha, channel 1 of 2 or 3 of
// 4, never). Sums of four table values are exact in double (each value is a
// multiple of 2^-35 below 1), so their order is free.
template <int C, bool Srgb>
void downsample_2x2_row(const std::uint8_t* r0, const std::uint8_t* r1, std::uint8_t* out, int dw) {
    const SrgbEncoder& enc = srgb_encoder();
    const std::uint64_t* value = enc.value;
    constexpr int kAlpha = C == 2 ? 1 : (C == 4 ? 3 : -1);
    int i = 0;
#if defined(__SSSE3__)
    if constexpr (!Srgb) {
        i = downsample_2x2_linear_sse<C>(r0, r1, out, dw);
        r0 += std::size_t(i) * 2 * C;
        r1 += std::size_t(i) * 2 * C;
        out += std::size_t(i) * C;
    }
#endif
    for (; i < dw; ++i, r0 += 2 * C, r1 += 2 * C, out += C) {
        for (int c = 0; c < C; ++c) {
            if (Srgb && c != kAlpha) {
                out[c] = enc.encode_sum4(value[r0[c]] + value[r0[C + c]] + value[r1[c]] + value[r1[C + c]]);
            } else {
                out[c] = std::uint8_t((r0[c] + r0[C + c] + r1[c] + r1[C + c] + 2) >> 2);
            }
        }
    }
}

// Output rows [j0, j1) of an 8-bit level from the level above, channel by
// channel: linear channels exactly in integers (round half up), sRGB ones as
// the area-weighted mean of the decoded values (in double: the weighted sum of
// up to 9 floats is exact, then one division) re-encoded by SrgbEncoder.
void downsample_unorm8(const std::uint8_t* src, int sw, int sh, std::uint8_t* dst, int dw, int j0, int j1,
                       int channels, const bool* srgb_channel) {
    const float* srgb = srgb8_decode_table();
    const SrgbEncoder& enc = srgb_encoder();
    const std::size_t C = std::size_t(channels);
    std::vector<IntTaps> tx(static_cast<std::size_t>(dw));
    for (int i = 0; i < dw; ++i) tx[i] = int_taps(sw, i);
    for (int j = j0; j < j1; ++j) {
        const IntTaps ty = int_taps(sh, j);
        std::uint8_t* out = dst + std::size_t(j) * std::size_t(dw) * C;
        const std::uint8_t* rows[3];
        for (int b = 0; b < ty.count; ++b) rows[b] = src + std::size_t(ty.first + b) * std::size_t(sw) * C;
        if (ty.count == 2 && sw % 2 == 0) {
            // The common case, 2x2 texels of weight 1/4.
            const bool colour_srgb = srgb_channel[0];
            switch (channels * 2 + int(colour_srgb)) {
            case 2: downsample_2x2_row<1, false>(rows[0], rows[1], out, dw); break;
            case 3: downsample_2x2_row<1, true>(rows[0], rows[1], out, dw); break;
            case 4: downsample_2x2_row<2, false>(rows[0], rows[1], out, dw); break;
            case 5: downsample_2x2_row<2, true>(rows[0], rows[1], out, dw); break;
            case 6: downsample_2x2_row<3, false>(rows[0], rows[1], out, dw); break;
            case 7: downsample_2x2_row<3, true>(rows[0], rows[1], out, dw); break;
            case 8: downsample_2x2_row<4, false>(rows[0], rows[1], out, dw); break;
            default: downsample_2x2_row<4, true>(rows[0], rows[1], out, dw); break;
            }
            continue;
        }
        for (int i = 0; i < dw; ++i) {
            const IntTaps& t = tx[std::size_t(i)];
            const std::int64_t d = t.d * ty.d;
            for (std::size_t c = 0; c < C; ++c) {
                if (srgb_channel[c]) {
                    double sum = 0.0;
                    for (int b = 0; b < ty.count; ++b)
                        for (int a = 0; a < t.count; ++a)
                            sum += double(ty.k[b] * t.k[a]) *
                                   double(srgb[rows[b][std::size_t(t.first + a) * C + c]]);
                    out[std::size_t(i) * C + c] = enc.encode(sum / double(d));
                } else {
                    std::int64_t sum = 0;
                    for (int b = 0; b < ty.count; ++b)
                        for (int a = 0; a < t.count; ++a)
                            sum += ty.k[b] * t.k[a] * rows[b][std::size_t(t.first + a) * C + c];
                    out[std::size_t(i) * C + c] = std::uint8_t((2 * sum + d) / (2 * d));
                }
            }
        }
    }
}

// Runs fn(j0, j1) over [0, rows) in chunks, on the pool when there is one and
// the level is large enough to pay for it.
template <class F>
void for_row_chunks(ThreadPool* pool, int rows, std::size_t row_texels, F fn) {
    const std::size_t texels = std::size_t(rows) * row_texels;
    if (!pool || pool->size() == 1 || texels < 16384) {
        fn(0, rows);
        return;
    }
    const int chunks = std::min(rows, 8 * pool->size());
    pool->run(chunks, [&](int c, int) {
        const int j0 = int(std::int64_t(rows) * c / chunks), j1 = int(std::int64_t(rows) * (c + 1) / chunks);
        if (j0 < j1) fn(j0, j1);
    });
}

// Texture::unorm8_codes() is built where the 8-lane AVX2 fetch reads it:
// an AVX2 build without the 16-lane copy, or with it on a CPU that does not
// run it.
bool wants_codes16(int channels, const bool srgb[4]) {
#if defined(__AVX2__) && !defined(PRAST_SIMD16)
    if (channels < 3 || !(srgb[0] || srgb[1] || srgb[2] || srgb[3])) return false;
#if PRAST_CALLS_AVX512
    return !use_avx512();
#else
    return true;
#endif
#else
    (void)channels;
    (void)srgb;
    return false;
#endif
}

// out = code[c][byte] for the C bytes of texels [t0, t1).
template <int C>
void encode_codes(const std::uint8_t* bytes, std::uint16_t* out, std::size_t t0, std::size_t t1,
                  const std::uint16_t* const code[4]) {
    const std::uint16_t* table[C];
    for (int c = 0; c < C; ++c) table[c] = code[c];
    const std::uint8_t* in = bytes + t0 * C;
    std::uint16_t* o = out + t0 * C;
    for (std::size_t t = t0; t < t1; ++t, in += C, o += C)
        for (int c = 0; c < C; ++c) o[c] = table[c][in[c]];
}

// Uninitialised memory for the 8-bit texels, on huge pages where large
// (filling them then faults a few times, not once per 4 KiB); freed with
// free_huge() (Texture::FreeBytes, CodeCache::Free).
std::uint8_t* allocate_texels(std::size_t bytes) { return static_cast<std::uint8_t*>(allocate_huge(bytes)); }

// The 15-bit codes of the fixed-point filter (texture.h): linear bytes b * 128;
// sRGB bytes the exact decode (in double) * 32640, rounded to nearest. Two
// spare entries, so that a 4-byte read at any entry stays inside (the block
// sampler's gathers).
struct CodeTables {
    alignas(64) std::uint16_t linear[258];
    alignas(64) std::uint16_t srgb[258];
    alignas(64) float srgb_value[256];  // srgb[b] / 32640

    CodeTables() {
        for (int b = 0; b < 256; ++b) {
            linear[b] = std::uint16_t(b * 128);
            const double lin = srgb_decode_exact(double(b) / 255.0);
            srgb[b] = std::uint16_t(std::floor(lin * double(texture_detail::kFixOne) + 0.5));
            srgb_value[b] = float(srgb[b]) / float(texture_detail::kFixOne);
        }
        linear[256] = linear[257] = srgb[256] = srgb[257] = 0;
    }
};

const CodeTables& code_tables() {
    static const CodeTables t;
    return t;
}

} // namespace

namespace texture_detail {
const std::uint16_t* srgb_code_table() { return code_tables().srgb; }
namespace {
std::array<float, 257> make_log2_mantissa() {
    std::array<float, 257> t{};
    for (int i = 0; i <= 256; ++i) t[std::size_t(i)] = float(det::log2(1.0 + double(i) / 256.0));
    return t;
}
} // namespace
const std::array<float, 257> kLog2Mantissa = make_log2_mantissa();
} // namespace texture_detail

// The samplers for each (wrap_s, wrap_t), indexed by the Wrap enumerators.
static_assert(int(Wrap::Repeat) == 0 && int(Wrap::ClampToEdge) == 1 && int(Wrap::MirroredRepeat) == 2);
namespace {
constexpr Wrap kR = Wrap::Repeat, kC = Wrap::ClampToEdge, kM = Wrap::MirroredRepeat;
} // namespace
const Texture::Sampler Texture::kTrilinear[3][3] = {
    {&Texture::trilinear_wrapped<kR, kR>, &Texture::trilinear_wrapped<kR, kC>, &Texture::trilinear_wrapped<kR, kM>},
    {&Texture::trilinear_wrapped<kC, kR>, &Texture::trilinear_wrapped<kC, kC>, &Texture::trilinear_wrapped<kC, kM>},
    {&Texture::trilinear_wrapped<kM, kR>, &Texture::trilinear_wrapped<kM, kC>, &Texture::trilinear_wrapped<kM, kM>}};
const Texture::Sampler Texture::kFiltered[3][3] = {
    {&Texture::filtered_wrapped<kR, kR>, &Texture::filtered_wrapped<kR, kC>, &Texture::filtered_wrapped<kR, kM>},
    {&Texture::filtered_wrapped<kC, kR>, &Texture::filtered_wrapped<kC, kC>, &Texture::filtered_wrapped<kC, kM>},
    {&Texture::filtered_wrapped<kM, kR>, &Texture::filtered_wrapped<kM, kC>, &Texture::filtered_wrapped<kM, kM>}};
const Texture::LevelSampler Texture::kNearest[3][3] = {
    {&Texture::nearest_wrapped<kR, kR>, &Texture::nearest_wrapped<kR, kC>, &Texture::nearest_wrapped<kR, kM>},
    {&Texture::nearest_wrapped<kC, kR>, &Texture::nearest_wrapped<kC, kC>, &Texture::nearest_wrapped<kC, kM>},
    {&Texture::nearest_wrapped<kM, kR>, &Texture::nearest_wrapped<kM, kC>, &Texture::nearest_wrapped<kM, kM>}};
const Texture::LevelSampler Texture::kBilinear[3][3] = {
    {&Texture::bilinear_wrapped<kR, kR>, &Texture::bilinear_wrapped<kR, kC>, &Texture::bilinear_wrapped<kR, kM>},
    {&Texture::bilinear_wrapped<kC, kR>, &Texture::bilinear_wrapped<kC, kC>, &Texture::bilinear_wrapped<kC, kM>},
    {&Texture::bilinear_wrapped<kM, kR>, &Texture::bilinear_wrapped<kM, kC>, &Texture::bilinear_wrapped<kM, kM>}};

void Texture::set_sampler(const SamplerState& s) {
    sampler_ = s;
    default_filters_ = s.mag == Filter::Linear && s.min == MinFilter::LinearMipmapLinear;
    // OpenGL's switch-over point c: 0.5 when magnifying LINEAR beside a
    // NEAREST_MIPMAP_* minification, so that a minified texture is never
    // sharper than a magnified one; 0 otherwise.
    min_mag_c_ = s.mag == Filter::Linear &&
                         (s.min == MinFilter::NearestMipmapNearest || s.min == MinFilter::NearestMipmapLinear)
                     ? 0.5f
                     : 0.0f;
    sample_fn_ = default_filters_ ? kTrilinear[int(s.wrap_s)][int(s.wrap_t)] : kFiltered[int(s.wrap_s)][int(s.wrap_t)];
    sampler_key_ = unsigned(s.wrap_s) | unsigned(s.wrap_t) << 2 | unsigned(s.mag) << 4 | unsigned(s.min) << 5;
}

Texture Texture::with_sampler(const SamplerState& s) const {
    Texture t = *this;
    t.set_sampler(s);
    return t;
}

Texture::Texture() {
    auto st = std::make_shared<Storage>();
    st->texels.assign(1, glm::vec4(1.0f));
    texels_ = st->texels.data();
    storage_ = std::move(st);
    levels_[0] = Level{1, 1, 1.0f, 1.0f, 0};
    level_count_ = 1;
    total_texels_ = 1;
    memory_bytes_ = sizeof(glm::vec4);
}

void Texture::layout(int w, int h) {
    int n = 0;
    std::size_t total = 0;
    for (;;) {
        levels_[n] = Level{w, h, float(w), float(h), total};
        total += std::size_t(w) * std::size_t(h);
        ++n;
        if (w == 1 && h == 1) break;
        w = std::max(1, w / 2);
        h = std::max(1, h / 2);
    }
    level_count_ = n;
    total_texels_ = total;
}

Texture Texture::from_image(Image img, Wrap s, Wrap t, ThreadPool* pool) {
    if (img.empty())
        throw std::invalid_argument("Texture::from_image: empty image (" +
                                    std::to_string(img.width) + "x" + std::to_string(img.height) + ")");
    const std::size_t count0 = img.texel_count();
    if (img.is_8bit()) {
        if (img.channels > 4 || img.pixels.size() != count0 * std::size_t(img.channels))
            throw std::invalid_argument("Texture::from_image: " + std::to_string(img.channels) +
                                        "-channel image holds " + std::to_string(img.pixels.size()) +
                                        " bytes, expected " + std::to_string(count0 * std::size_t(img.channels)));
        // Grey and grey+alpha replicate their first channel to r, g, b.
        static const int kSwizzle[5][4] = {
            {0, 1, 2, 3}, {0, 0, 0, kOne}, {0, 0, 0, 1}, {0, 1, 2, kOne}, {0, 1, 2, 3}};
        // Alpha (channel 1 of 2, 3 of 4) is linear whatever the colour is.
        bool srgb[4] = {img.srgb, img.srgb, img.srgb, img.srgb};
        if (img.channels == 2 || img.channels == 4) srgb[img.channels - 1] = false;
        return from_unorm8(img.pixels.data(), img.channels, srgb, kSwizzle[img.channels], img.width,
                           img.height, s, t, pool, &img.pixels);
    }
    if (img.rgba.size() != count0 * 4)
        throw std::invalid_argument("Texture::from_image: rgba holds " +
                                    std::to_string(img.rgba.size()) + " floats, expected " +
                                    std::to_string(count0 * 4));
    Texture tex;
    tex.set_sampler(SamplerState{s, t});
    tex.layout(img.width, img.height);

    // Level 0 is the image; each further level is the box-filtered one above.
    auto st = std::make_shared<Storage>();
    st->texels.resize(tex.total_texels_);
    std::memcpy(static_cast<void*>(st->texels.data()), img.rgba.data(), count0 * sizeof(glm::vec4));
    img = Image();  // release the source before the chain needs its scratch rows
    for (int l = 1; l < tex.level_count_; ++l) {
        const Level& a = tex.levels_[l - 1];
        const Level& b = tex.levels_[l];
        glm::vec4* base = st->texels.data();
        for_row_chunks(pool, b.height, std::size_t(b.width), [&](int j0, int j1) {
            std::vector<glm::vec4> tmp;
            downsample(base + a.offset, a.width, a.height, base + b.offset, b.width, j0, j1, tmp);
        });
    }
    tex.memory_bytes_ = tex.total_texels_ * sizeof(glm::vec4);
    tex.texels_ = st->texels.data();
    tex.storage_ = std::move(st);
    return tex;
}

struct CodeCache {
    struct Free {  // of allocate_texels()
        void operator()(std::uint8_t* p) const noexcept { free_huge(p); }
    };
    std::unique_ptr<std::uint8_t[], Free> buffer;
    std::atomic<std::uint32_t> ready{0};  // bit l: level l is filled
    std::mutex lock;
    std::uint16_t* codes() { return reinterpret_cast<std::uint16_t*>(buffer.get()); }
};

std::size_t Texture::unorm8_bytes(int w, int h, int channels) {
    Texture tex;
    tex.layout(w, h);
    return tex.total_texels_ * std::size_t(channels) + kReadSlack;
}

Texture Texture::from_unorm8(const std::uint8_t* level0, int channels, const bool srgb[4], const int swizzle[4],
                             int w, int h, Wrap s, Wrap t, ThreadPool* pool, std::vector<std::uint8_t>* adopt) {
    Texture tex;
    tex.set_sampler(SamplerState{s, t});
    tex.channels_ = channels;
    const CodeTables& codes = code_tables();
    for (int c = 0; c < 4; ++c) {
        tex.swizzle_[c] = swizzle[c];
        tex.srgb_[c] = c < channels && srgb[c];
        // Linear: b * 128 / 32640 is b / 255, which unorm8_decode_table() holds.
        tex.code_[c] = tex.srgb_[c] ? codes.srgb : codes.linear;
        tex.table_[c] = tex.srgb_[c] ? codes.srgb_value : unorm8_decode_table();
        tex.srgb_code_[c] = tex.srgb_[c] ? codes.srgb : nullptr;
    }
    for (unsigned mask = 0; mask < 16; ++mask) {
        Unorm8Reads& r = tex.reads_[mask];
        for (int k = 0; k < 4; ++k) {
            if (!((mask >> k) & 1u)) continue;
            const int sw = tex.swizzle_[k];
            r.component[r.outputs] = std::int8_t(k);
            r.channel[r.outputs++] = std::int8_t(sw);
            if (sw != kOne) {
                r.need = std::uint8_t(r.need | 1u << sw);
                r.needs_srgb = r.needs_srgb || tex.srgb_[sw];
            }
        }
        r.identity = r.outputs == channels;
        for (int k = 0; k < r.outputs; ++k) r.identity = r.identity && r.component[k] == k && r.channel[k] == k;
    }
    tex.layout(w, h);
    const std::size_t C = std::size_t(channels);
    // Spare bytes: the block sampler reads 4 or 8 bytes at any texel.
    const std::size_t bytes = tex.total_texels_ * C + kReadSlack;
    auto st = std::make_shared<Storage>();
    std::uint8_t* base = nullptr;
    if (adopt && level0 && adopt->data() == level0 && adopt->capacity() >= bytes) {
        st->adopted = std::move(*adopt);
        st->adopted.resize(bytes);  // no reallocation; the slack zeroed
        base = st->adopted.data();
    } else {
        st->bytes.reset(allocate_texels(bytes));
        base = st->bytes.get();
        if (level0) std::memcpy(base, level0, std::size_t(w) * std::size_t(h) * C);
    }
    std::memset(base + tex.total_texels_ * C, 0, kReadSlack);
    for (int l = 1; l < tex.level_count_; ++l) {
        const Level& a = tex.levels_[l - 1];
        const Level& b = tex.levels_[l];
        for_row_chunks(pool, b.height, std::size_t(b.width), [&](int j0, int j1) {
            downsample_unorm8(base + a.offset * C, a.width, a.height, base + b.offset * C, b.width, j0, j1,
                              channels, tex.srgb_);
        });
    }
    tex.memory_bytes_ = tex.total_texels_ * C;
    if (wants_codes16(channels, tex.srgb_)) {
        // Reserved whole, filled level by level on first use (unorm8_codes()):
        // the pages of levels never read are never touched.
        const std::size_t n = tex.total_texels_ * C;
        st->codes = std::make_unique<CodeCache>();
        st->codes->buffer.reset(allocate_texels((n + kCodeSlack) * sizeof(std::uint16_t)));
        std::memset(st->codes->codes() + n, 0, kCodeSlack * sizeof(std::uint16_t));
        tex.codes_ = st->codes.get();
    }
    tex.bytes_ = base;
    tex.storage_ = std::move(st);
    return tex;
}

void Texture::FreeBytes::operator()(std::uint8_t* p) const noexcept { free_huge(p); }

Texture::Storage::Storage() = default;
Texture::Storage::~Storage() = default;

const std::uint16_t* Texture::filled_codes(std::uint32_t levels) const {
    levels &= level_count_ >= 32 ? ~0u : (1u << level_count_) - 1u;
    if ((codes_->ready.load(std::memory_order_acquire) & levels) != levels) {
        const std::lock_guard<std::mutex> hold(codes_->lock);
        std::uint32_t ready = codes_->ready.load(std::memory_order_relaxed);
        for (std::uint32_t todo = levels & ~ready; todo; todo &= todo - 1) {
            const Level& L = levels_[__builtin_ctz(todo)];
            const std::size_t t0 = L.offset, t1 = L.offset + std::size_t(L.width) * std::size_t(L.height);
            if (channels_ == 3)
                encode_codes<3>(bytes_, codes_->codes(), t0, t1, code_);
            else
                encode_codes<4>(bytes_, codes_->codes(), t0, t1, code_);
        }
        codes_->ready.store(ready | levels, std::memory_order_release);
    }
    return codes_->codes();
}

std::size_t Texture::code_bytes() const {
    if (!codes_) return 0;
    const std::uint32_t ready = codes_->ready.load(std::memory_order_acquire);
    std::size_t texels = 0;
    for (int l = 0; l < level_count_; ++l)
        if ((ready >> l) & 1u) texels += std::size_t(levels_[l].width) * std::size_t(levels_[l].height);
    return texels * std::size_t(channels_) * sizeof(std::uint16_t);
}

Texture Texture::pack_roughness_metal(const Image& rough, const Image& metal, Wrap s, Wrap t, ThreadPool* pool) {
    if (!rough.is_8bit() || !metal.is_8bit() || rough.srgb || metal.srgb)
        throw std::invalid_argument("Texture::pack_roughness_metal: needs two 8-bit linear images");
    if (rough.empty() || rough.width != metal.width || rough.height != metal.height)
        throw std::invalid_argument("Texture::pack_roughness_metal: the images differ in size");
    if (rough.pixels.size() != rough.texel_count() * std::size_t(rough.channels) ||
        metal.pixels.size() != metal.texel_count() * std::size_t(metal.channels))
        throw std::invalid_argument("Texture::pack_roughness_metal: wrong data size");
    static const bool kLinear[4] = {false, false, false, false};
    static const int kSwizzle[4] = {0, 0, 1, kOne};
    const std::size_t n = rough.texel_count();
    std::unique_ptr<std::uint8_t[], FreeBytes> packed(allocate_texels(n * 2));
    const std::size_t rc = std::size_t(rough.channels), mc = std::size_t(metal.channels);
    for (std::size_t i = 0; i < n; ++i) {
        packed[2 * i] = rough.pixels[i * rc];
        packed[2 * i + 1] = metal.pixels[i * mc];
    }
    return from_unorm8(packed.get(), 2, kLinear, kSwizzle, rough.width, rough.height, s, t, pool);
}

glm::vec4 Texture::texel(int level, int x, int y) const {
    const Level& L = levels_[clamp_level(level)];
    x = std::clamp(x, 0, L.width - 1);
    y = std::clamp(y, 0, L.height - 1);
    return texel_at(L.offset + std::size_t(y) * std::size_t(L.width) + std::size_t(x));
}

} // namespace prast

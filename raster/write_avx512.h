// The colour write of a shaded block (shade.h write_color(), blending
// Replace) with AVX-512: the block's pixels put in row order once, then each
// row one masked 64-byte store a sample plane (a half block whose pixels are
// all written: plain stores), with no branch on which pixels the edges left
// (at a triangle's edge a coin toss, which the pair-by-pair AVX2 stores
// mispredicted). An x86-64-v3 build compiles it in write_avx512.cpp alone and
// calls it there where the CPU has AVX-512 (isa.h); an x86-64-v4 build
// inlines it.
#pragma once

#include <cstddef>
#include <cstdint>

#include "raster/fragment.h"

#if defined(__AVX512F__) && defined(__AVX512VL__)
#include <immintrin.h>
#endif

namespace prast::raster_detail {

// Samples s < `samples` of the block at `color` (RGBA floats; `row` pixels
// from one row to the next, `plane` from one sample's plane to the next):
// the lanes masks[s] of `out`. The floats of the other lanes are neither
// read nor written (nor fault), so the block may overhang the plane.
void write_planes_avx512(float* color, std::size_t row, std::size_t plane, const std::uint32_t* masks, int samples,
                         const FragmentOut& out);

#if defined(__AVX512F__) && defined(__AVX512VL__)
// Element 4x + c of row y's store: channel c of pixel x, from the (r, g)
// pairs of lanes 0-7 or 8-15 (elements 2k, 2k + 1 for lane k & 7) or, at 16
// and on, their (b, a) pairs.
struct RowPickAvx512 {
    alignas(64) int index[4][16];
};
constexpr RowPickAvx512 row_pick_avx512() {
    RowPickAvx512 p{};
    for (int y = 0; y < 4; ++y)
        for (int x = 0; x < 4; ++x) {
            const int k = block_lane(x, y) & 7;
            p.index[y][4 * x + 0] = 2 * k;
            p.index[y][4 * x + 1] = 2 * k + 1;
            p.index[y][4 * x + 2] = 16 + 2 * k;
            p.index[y][4 * x + 3] = 16 + 2 * k + 1;
        }
    return p;
}
inline constexpr RowPickAvx512 kRowPickAvx512 = row_pick_avx512();

// The store masks of a half block's two rows from its eight lane bits
// (lanes 8h .. 8h + 7 hold rows 2h and 2h + 1): row 2h's in the low 16 bits,
// row 2h + 1's in the high, each lane's bit repeated for its pixel's four
// floats.
struct RowMasksAvx512 {
    std::uint32_t rows[256];
};
constexpr RowMasksAvx512 row_masks_avx512() {
    RowMasksAvx512 t{};
    for (int bits = 0; bits < 256; ++bits)
        for (int y = 0; y < 2; ++y)
            for (int x = 0; x < 4; ++x)
                if ((bits >> block_lane(x, y)) & 1) t.rows[bits] |= 0xFu << (16 * y + 4 * x);
    return t;
}
inline constexpr RowMasksAvx512 kRowMasksAvx512 = row_masks_avx512();

typedef float Floats16Avx512 __attribute__((vector_size(64)));
typedef float Floats8Avx512 __attribute__((vector_size(32)));
[[gnu::always_inline]] inline Floats8Avx512 load8_avx512(const float* p) {
    return Floats8Avx512(_mm256_load_ps(p));
}

// S: the sample count (1, 2, 4 or 8), or 0 for `samples`.
template <int S>
[[gnu::always_inline]] inline void write_planes_avx512_inline(float* color, std::size_t row, std::size_t plane,
                                                              const std::uint32_t* masks, int samples,
                                                              const FragmentOut& out) {
    if constexpr (S > 0) samples = S;
    std::uint32_t any = 0;
    for (int s = 0; s < samples; ++s) any |= masks[s];
    for (int h = 0; h < 2; ++h) {
        if (!((any >> (8 * h)) & 0xFFu)) continue;
        // This half's (r, g) and (b, a) pairs, then its two rows. Read as
        // 32-byte halves: the program has just stored them so, and a 64-byte
        // load of two stores in flight would wait for both to retire.
        const Floats8Avx512 r = load8_avx512(out.r + 8 * h), g = load8_avx512(out.g + 8 * h);
        const Floats8Avx512 b = load8_avx512(out.b + 8 * h), a = load8_avx512(out.a + 8 * h);
        const __m512 rg = __m512(__builtin_shufflevector(r, g, 0, 8, 1, 9, 2, 10, 3, 11, 4, 12, 5, 13, 6, 14, 7, 15));
        const __m512 ba = __m512(__builtin_shufflevector(b, a, 0, 8, 1, 9, 2, 10, 3, 11, 4, 12, 5, 13, 6, 14, 7, 15));
        const Floats16Avx512 top = Floats16Avx512(
            _mm512_permutex2var_ps(rg, _mm512_load_si512(kRowPickAvx512.index[2 * h]), ba));
        const Floats16Avx512 bottom = Floats16Avx512(
            _mm512_permutex2var_ps(rg, _mm512_load_si512(kRowPickAvx512.index[2 * h + 1]), ba));
        for (int s = 0; s < samples; ++s) {
            const std::uint32_t bits = (masks[s] >> (8 * h)) & 0xFFu;
            if (!bits) continue;
            float* c = color + (std::size_t(s) * plane + std::size_t(2 * h) * row) * 4;
            if (bits == 0xFFu) {
                // Plain 32-byte stores: the rows start 16 bytes into a cache
                // line (malloc's alignment), where a 64-byte store always
                // spans two lines (measured: quad 0.95x). The halves by a
                // shuffle, not the intrinsics, whose undefined pass-through
                // GCC 12 warns of.
                _mm256_storeu_ps(c, __m256(__builtin_shufflevector(top, top, 0, 1, 2, 3, 4, 5, 6, 7)));
                _mm256_storeu_ps(c + 8, __m256(__builtin_shufflevector(top, top, 8, 9, 10, 11, 12, 13, 14, 15)));
                _mm256_storeu_ps(c + row * 4, __m256(__builtin_shufflevector(bottom, bottom, 0, 1, 2, 3, 4, 5, 6, 7)));
                _mm256_storeu_ps(c + row * 4 + 8,
                                 __m256(__builtin_shufflevector(bottom, bottom, 8, 9, 10, 11, 12, 13, 14, 15)));
                continue;
            }
            const std::uint32_t k = kRowMasksAvx512.rows[bits];
            _mm512_mask_storeu_ps(c, __mmask16(k), __m512(top));
            _mm512_mask_storeu_ps(c + row * 4, __mmask16(k >> 16), __m512(bottom));
        }
    }
}
#endif

} // namespace prast::raster_detail

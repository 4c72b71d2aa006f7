// W float or int32 lanes per instruction under AVX2: Simd<8> (ymm) and
// Simd<4> (xmm), and Simd<16> (zmm) where the file is compiled for AVX-512,
// with the same member names, so a lane loop is written once
// and instantiated for whole blocks and for packed sparse ones
// (sample_lanes.h texture fetches, shadow_lanes.h PCF).
#pragma once

#ifdef __AVX2__

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <utility>

#include <immintrin.h>

#include "shading/isa.h"

namespace prast {

// Eight-byte gathers are written as one load per lane: on AMD's Zen 4 a
// vpgatherdq is slower than the eight loads and inserts it stands for, while
// the 4-byte vpgatherdd is not (docs/performance.md, "Eight-byte gathers
// are loads"). The loads read exactly the bytes the gather would: the index
// sign-extended, times Scale, from base.
namespace simd_detail {

template <class T, int Scale>
[[gnu::always_inline]] inline T load_element(const std::uint8_t* base, std::int32_t i) {
    T v;
    std::memcpy(&v, base + std::ptrdiff_t(i) * Scale, sizeof v);
    return v;
}

typedef long long Qword4 __attribute__((vector_size(32)));
typedef long long Qword8 __attribute__((vector_size(64)));

// The vector of the 8-byte elements at base + Scale ix[L].
template <class Vec, int Scale, std::size_t... L>
[[gnu::always_inline]] inline Vec load_qwords(const std::uint8_t* base, const std::int32_t* ix,
                                              std::index_sequence<L...>) {
    return Vec{load_element<long long, Scale>(base, ix[L])...};
}

// An integer in memory for Simd<8>::splat_i().
template <int K> struct Splat {
    static constexpr std::int32_t value = K;
};

} // namespace simd_detail

// W lanes per instruction: 8 (ymm) or 4 (xmm).
template <int W> struct Simd;

template <> struct Simd<8> {
    using F = __m256;
    using I = __m256i;
    static I load_i(const std::int32_t* p) { return _mm256_load_si256(reinterpret_cast<const __m256i*>(p)); }
    static F load_f(const float* p) { return _mm256_load_ps(p); }
    static void store_f(float* p, F v) { _mm256_store_ps(p, v); }
    static I set1_i(int v) { return _mm256_set1_epi32(v); }
    // set1_i(K) for a constant K. GCC 12 builds an integer splat in a general
    // register and broadcasts it, three instructions at every use; a
    // broadcast load of the constant is one, and a loop invariant.
    template <int K> [[gnu::always_inline]] static I splat_i() {
#if defined(__GNUC__) && !defined(__clang__)
        I r;
        asm("vpbroadcastd %1, %0" : "=x"(r) : "m"(simd_detail::Splat<K>::value));
        return r;
#else
        return _mm256_set1_epi32(K);
#endif
    }
    static F set1_f(float v) { return _mm256_set1_ps(v); }
    static F zero_f() { return _mm256_setzero_ps(); }
    static I lane_bits() { return _mm256_setr_epi32(1, 2, 4, 8, 16, 32, 64, 128); }
    // The 4 bytes at base + Scale idx per lane (Scale 3: a 3-byte texel's
    // index), from stored indices or a vector of them.
    template <int Scale> [[gnu::always_inline]] static I gather_i(const std::uint8_t* base, I idx) {
        if constexpr (Scale == 3) idx = _mm256_add_epi32(idx, _mm256_add_epi32(idx, idx));
        return _mm256_i32gather_epi32(reinterpret_cast<const int*>(base), idx, Scale == 3 ? 1 : Scale);
    }
    template <int Scale> [[gnu::always_inline]] static I gather_i(const std::uint8_t* base, const std::int32_t* ix) {
        return gather_i<Scale>(base, load_i(ix));
    }
    static F gather_f(const float* table, I idx) { return _mm256_i32gather_ps(table, idx, 4); }
    // The 8 bytes at base + Scale ix[l] for each lane: their low 4 bytes, and
    // 4 bytes from Shift bits on. The qwords are read in the lane order
    // 0 1 4 5 and 2 3 6 7, so that one in-lane shuffle puts them back.
    template <int Scale, int Shift>
    [[gnu::always_inline]] static void gather_q(const std::uint8_t* base, const std::int32_t* ix, I& low, I& shifted) {
        using simd_detail::Qword4;
        const std::int32_t ia[4] = {ix[0], ix[1], ix[4], ix[5]}, ib[4] = {ix[2], ix[3], ix[6], ix[7]};
        const I a = I(simd_detail::load_qwords<Qword4, Scale>(base, ia, std::make_index_sequence<4>()));
        const I b = I(simd_detail::load_qwords<Qword4, Scale>(base, ib, std::make_index_sequence<4>()));
        low = pick_low(a, b);
        shifted = pick_low(_mm256_srli_epi64(a, Shift), _mm256_srli_epi64(b, Shift));
    }
    static I add_i(I a, I b) { return _mm256_add_epi32(a, b); }
    static I sub_i(I a, I b) { return _mm256_sub_epi32(a, b); }
    static I and_i(I a, I b) { return _mm256_and_si256(a, b); }
    static I or_i(I a, I b) { return _mm256_or_si256(a, b); }
    template <int N> static I slli_i(I a) { return _mm256_slli_epi32(a, N); }
    template <int N> static I srli_i(I a) { return _mm256_srli_epi32(a, N); }
    // Per 32-bit lane: low16(a) low16(b) + high16(a) high16(b), signed.
    static I madd_i(I a, I b) { return _mm256_madd_epi16(a, b); }
    static I cvtt(F a) { return _mm256_cvttps_epi32(a); }
    static I select_i(I mask, I yes, I no) { return _mm256_blendv_epi8(no, yes, mask); }
    static I srlv_i(I a, I n) { return _mm256_srlv_epi32(a, n); }
    static I shuffle_bytes(I a, I idx) { return _mm256_shuffle_epi8(a, idx); }  // within each 16 bytes
    // 4 (l % 4) in bytes 0 and 2 of lane l: where its dword starts in its 16 bytes.
    static I dword_byte_offsets() { return _mm256_setr_epi32(0, 0x40004, 0x80008, 0xC000C, 0, 0x40004, 0x80008, 0xC000C); }
    static I cmpeq_i(I a, I b) { return _mm256_cmpeq_epi32(a, b); }
    static F cvt(I a) { return _mm256_cvtepi32_ps(a); }
    static F add(F a, F b) { return _mm256_add_ps(a, b); }
    static F sub(F a, F b) { return _mm256_sub_ps(a, b); }
    static F mul(F a, F b) { return _mm256_mul_ps(a, b); }
    static F div(F a, F b) { return _mm256_div_ps(a, b); }
    static F select(F mask, F yes, F no) { return _mm256_blendv_ps(no, yes, mask); }
    static F as_f(I a) { return _mm256_castsi256_ps(a); }
    static F and_f(F a, F b) { return _mm256_and_ps(a, b); }
    static F or_f(F a, F b) { return _mm256_or_ps(a, b); }
    static F cmpge(F a, F b) { return _mm256_cmp_ps(a, b, _CMP_GE_OQ); }
    static F cmplt(F a, F b) { return _mm256_cmp_ps(a, b, _CMP_LT_OQ); }
    static bool all(F mask) { return _mm256_movemask_ps(mask) == 0xFF; }
    static bool all_i(I mask) { return _mm256_movemask_epi8(mask) == -1; }

private:
    // The low dwords of a's and b's qwords: a0 a1 b0 b1 | a2 a3 b2 b3.
    static I pick_low(I a, I b) {
        return _mm256_castps_si256(_mm256_shuffle_ps(_mm256_castsi256_ps(a), _mm256_castsi256_ps(b), _MM_SHUFFLE(2, 0, 2, 0)));
    }
};

template <> struct Simd<4> {
    using F = __m128;
    using I = __m128i;
    static I load_i(const std::int32_t* p) { return _mm_load_si128(reinterpret_cast<const __m128i*>(p)); }
    static F load_f(const float* p) { return _mm_load_ps(p); }
    static void store_f(float* p, F v) { _mm_store_ps(p, v); }
    static I set1_i(int v) { return _mm_set1_epi32(v); }
    template <int K> static I splat_i() { return _mm_set1_epi32(K); }
    static F set1_f(float v) { return _mm_set1_ps(v); }
    static F zero_f() { return _mm_setzero_ps(); }
    static I lane_bits() { return _mm_setr_epi32(1, 2, 4, 8); }
    template <int Scale> [[gnu::always_inline]] static I gather_i(const std::uint8_t* base, I idx) {
        if constexpr (Scale == 3) idx = _mm_add_epi32(idx, _mm_add_epi32(idx, idx));
        return _mm_i32gather_epi32(reinterpret_cast<const int*>(base), idx, Scale == 3 ? 1 : Scale);
    }
    template <int Scale> [[gnu::always_inline]] static I gather_i(const std::uint8_t* base, const std::int32_t* ix) {
        return gather_i<Scale>(base, load_i(ix));
    }
    static F gather_f(const float* table, I idx) { return _mm_i32gather_ps(table, idx, 4); }
    // As Simd<8>::gather_q, for 4 lanes.
    template <int Scale, int Shift>
    [[gnu::always_inline]] static void gather_q(const std::uint8_t* base, const std::int32_t* ix, I& low, I& shifted) {
        const __m256i q =
            __m256i(simd_detail::load_qwords<simd_detail::Qword4, Scale>(base, ix, std::make_index_sequence<4>()));
        low = pick_low(q);
        shifted = pick_low(_mm256_srli_epi64(q, Shift));
    }
    static I add_i(I a, I b) { return _mm_add_epi32(a, b); }
    static I sub_i(I a, I b) { return _mm_sub_epi32(a, b); }
    static I and_i(I a, I b) { return _mm_and_si128(a, b); }
    static I or_i(I a, I b) { return _mm_or_si128(a, b); }
    template <int N> static I slli_i(I a) { return _mm_slli_epi32(a, N); }
    template <int N> static I srli_i(I a) { return _mm_srli_epi32(a, N); }
    static I madd_i(I a, I b) { return _mm_madd_epi16(a, b); }
    static I cvtt(F a) { return _mm_cvttps_epi32(a); }
    static I select_i(I mask, I yes, I no) { return _mm_blendv_epi8(no, yes, mask); }
    static I srlv_i(I a, I n) { return _mm_srlv_epi32(a, n); }
    static I shuffle_bytes(I a, I idx) { return _mm_shuffle_epi8(a, idx); }
    static I dword_byte_offsets() { return _mm_setr_epi32(0, 0x40004, 0x80008, 0xC000C); }
    static I cmpeq_i(I a, I b) { return _mm_cmpeq_epi32(a, b); }
    static F cvt(I a) { return _mm_cvtepi32_ps(a); }
    static F add(F a, F b) { return _mm_add_ps(a, b); }
    static F sub(F a, F b) { return _mm_sub_ps(a, b); }
    static F mul(F a, F b) { return _mm_mul_ps(a, b); }
    static F div(F a, F b) { return _mm_div_ps(a, b); }
    static F select(F mask, F yes, F no) { return _mm_blendv_ps(no, yes, mask); }
    static F as_f(I a) { return _mm_castsi128_ps(a); }
    static F and_f(F a, F b) { return _mm_and_ps(a, b); }
    static F or_f(F a, F b) { return _mm_or_ps(a, b); }
    static F cmpge(F a, F b) { return _mm_cmp_ps(a, b, _CMP_GE_OQ); }
    static F cmplt(F a, F b) { return _mm_cmp_ps(a, b, _CMP_LT_OQ); }
    static bool all(F mask) { return _mm_movemask_ps(mask) == 0xF; }
    static bool all_i(I mask) { return _mm_movemask_epi8(mask) == 0xFFFF; }

private:
    // The low dwords of q's four qwords.
    static I pick_low(__m256i q) {
        const __m128 lo = _mm_castsi128_ps(_mm256_castsi256_si128(q));
        const __m128 hi = _mm_castsi128_ps(_mm256_extracti128_si256(q, 1));
        return _mm_castps_si128(_mm_shuffle_ps(lo, hi, _MM_SHUFFLE(2, 0, 2, 0)));
    }
};

#ifdef PRAST_SIMD16
// 16 lanes (zmm): a whole 4x4 block per instruction, in x86-64-v4 builds and
// in the AVX-512 copy of the block loops (shading/isa.h).
// Comparisons give vector masks (all ones or zeros per lane) as the narrower
// widths do, turned into AVX-512 mask registers where an instruction takes one.
// GCC 12's plain forms of many AVX-512 intrinsics pass an undefined register
// to their builtins, which -Wmaybe-uninitialized reports wherever they are
// inlined (GCC bug 105593): the gathers are the masked forms with a zero
// source, the rest the zero-masked forms with every lane set.
template <> struct Simd<16> {
    using F = __m512;
    using I = __m512i;
    static I load_i(const std::int32_t* p) { return _mm512_load_si512(p); }
    static F load_f(const float* p) { return _mm512_load_ps(p); }
    static void store_f(float* p, F v) { _mm512_store_ps(p, v); }
    static I set1_i(int v) { return _mm512_set1_epi32(v); }
    template <int K> static I splat_i() { return _mm512_set1_epi32(K); }
    static F set1_f(float v) { return _mm512_set1_ps(v); }
    static F zero_f() { return _mm512_setzero_ps(); }
    static I lane_bits() {
        return _mm512_setr_epi32(1, 2, 4, 8, 16, 32, 64, 128, 256, 512, 1024, 2048, 4096, 8192, 16384, 32768);
    }
    template <int Scale> [[gnu::always_inline]] static I gather_i(const std::uint8_t* base, I idx) {
        if constexpr (Scale == 3) idx = _mm512_add_epi32(idx, _mm512_add_epi32(idx, idx));
        return _mm512_mask_i32gather_epi32(_mm512_setzero_si512(), 0xFFFF, idx, base, Scale == 3 ? 1 : Scale);
    }
    template <int Scale> [[gnu::always_inline]] static I gather_i(const std::uint8_t* base, const std::int32_t* ix) {
        return gather_i<Scale>(base, load_i(ix));
    }
    static F gather_f(const float* table, I idx) {
        return _mm512_mask_i32gather_ps(_mm512_setzero_ps(), 0xFFFF, idx, table, 4);
    }
    // The 8 bytes at base + Scale ix[l], lanes 0-7 in q[0] and 8-15 in q[1].
    template <int Scale>
    [[gnu::always_inline]] static void gather_qwords(const std::uint8_t* base, const std::int32_t* ix, I* q) {
        using simd_detail::Qword8;
        q[0] = I(simd_detail::load_qwords<Qword8, Scale>(base, ix, std::make_index_sequence<8>()));
        q[1] = I(simd_detail::load_qwords<Qword8, Scale>(base, ix + 8, std::make_index_sequence<8>()));
    }
    // As Simd<8>::gather_q, the qwords in lane order.
    template <int Scale, int Shift>
    [[gnu::always_inline]] static void gather_q(const std::uint8_t* base, const std::int32_t* ix, I& low, I& shifted) {
        I q[2];
        gather_qwords<Scale>(base, ix, q);
        low = join(low_dwords(q[0]), low_dwords(q[1]));
        shifted = join(low_dwords(_mm512_maskz_srli_epi64(0xFF, q[0], Shift)),
                       low_dwords(_mm512_maskz_srli_epi64(0xFF, q[1], Shift)));
    }
    static I add_i(I a, I b) { return _mm512_add_epi32(a, b); }
    static I sub_i(I a, I b) { return _mm512_sub_epi32(a, b); }
    static I and_i(I a, I b) { return _mm512_and_si512(a, b); }
    static I or_i(I a, I b) { return _mm512_or_si512(a, b); }
    template <int N> static I slli_i(I a) { return _mm512_maskz_slli_epi32(0xFFFF, a, N); }
    template <int N> static I srli_i(I a) { return _mm512_maskz_srli_epi32(0xFFFF, a, N); }
    static I madd_i(I a, I b) { return _mm512_madd_epi16(a, b); }
    static I cvtt(F a) { return _mm512_maskz_cvttps_epi32(0xFFFF, a); }
    static I select_i(I mask, I yes, I no) { return _mm512_mask_blend_epi32(_mm512_movepi32_mask(mask), no, yes); }
    static I srlv_i(I a, I n) { return _mm512_maskz_srlv_epi32(0xFFFF, a, n); }
    static I shuffle_bytes(I a, I idx) { return _mm512_maskz_shuffle_epi8(~0ull, a, idx); }  // within each 16 bytes
    static I dword_byte_offsets() {
        return _mm512_setr_epi32(0, 0x40004, 0x80008, 0xC000C, 0, 0x40004, 0x80008, 0xC000C, 0, 0x40004, 0x80008, 0xC000C,
                                 0, 0x40004, 0x80008, 0xC000C);
    }
    static I cmpeq_i(I a, I b) { return _mm512_movm_epi32(_mm512_cmpeq_epi32_mask(a, b)); }
    static F cvt(I a) { return _mm512_maskz_cvtepi32_ps(0xFFFF, a); }
    static F add(F a, F b) { return _mm512_add_ps(a, b); }
    static F sub(F a, F b) { return _mm512_sub_ps(a, b); }
    static F mul(F a, F b) { return _mm512_mul_ps(a, b); }
    static F div(F a, F b) { return _mm512_div_ps(a, b); }
    static F select(F mask, F yes, F no) {
        return _mm512_mask_blend_ps(_mm512_movepi32_mask(_mm512_castps_si512(mask)), no, yes);
    }
    static F as_f(I a) { return _mm512_castsi512_ps(a); }
    static F and_f(F a, F b) { return _mm512_and_ps(a, b); }
    static F or_f(F a, F b) { return _mm512_or_ps(a, b); }
    static F cmpge(F a, F b) { return _mm512_castsi512_ps(_mm512_movm_epi32(_mm512_cmp_ps_mask(a, b, _CMP_GE_OQ))); }
    static F cmplt(F a, F b) { return _mm512_castsi512_ps(_mm512_movm_epi32(_mm512_cmp_ps_mask(a, b, _CMP_LT_OQ))); }
    static bool all(F mask) { return _mm512_movepi32_mask(_mm512_castps_si512(mask)) == 0xFFFF; }
    static bool all_i(I mask) { return _mm512_movepi32_mask(mask) == 0xFFFF; }

private:
    static __m256i low_dwords(I q) { return _mm512_maskz_cvtepi64_epi32(0xFF, q); }
    static I join(__m256i lo, __m256i hi) { return _mm512_maskz_inserti64x4(0xFF, _mm512_castsi256_si512(lo), hi, 1); }
};
#endif

} // namespace prast

#endif // __AVX2__

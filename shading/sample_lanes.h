// Trilinear texture sampling for the 16 lanes of a 4x4 block at once, in two
// steps: prepare_trilinear_lanes() turns the lanes' uv and their quads' lambda
// into texel indices and filter weights (branch-free loops over lanes, which
// the compiler vectorises), and fetch_trilinear_lanes() reads and blends the
// texels. 8-bit textures are read 8 (or 4; 16 where the 16-lane loops run
// their AVX-512 copy, shading/isa.h) lanes per instruction: a gather of
// each tap's packed texel bytes (8-byte reads as a load per lane, simd.h
// says why), the channels unpacked into their
// 15-bit codes (a shift, or a gather from the sRGB code table), then the
// fixed-point lerps of texture.h, each one multiply-add of 16-bit pairs
// (_mm256_madd_epi16); sparse blocks and builds without AVX2 call the scalar
// sampler's own steps (Texture::fix_bilinear, fix_blend) lane by lane.
// Integers agree wherever they are computed. Float textures are read one live
// lane at a time (one 4-channel vector per texel), with exactly the float
// operations of Texture::sample_lod() in the same order. So every lane equals
// the scalar sampler bit for bit (tests/test_sample_lanes.cpp); the stepper
// and the debug views keep using the scalar sampler.
//
// The indices depend only on the level-0 size and the sampler, as does
// lambda (Texture::lod), so textures with the same layout share one
// preparation: a material whose maps have one size prepares once per block.
// The loops run over the first N lanes (4, 8 or 16): the fragment program
// packs the live lanes of one or several sparse blocks first, each lane
// remembering the 2x2 quad (of up to kMaxQuadSlots) whose lambda it uses.
#pragma once

#include <cstdint>
#include <cstring>
#include <type_traits>

#include <glm/glm.hpp>

#ifdef __AVX2__
#include <immintrin.h>
#endif

#include "raster/limits.h"
#include "shading/isa.h"
#include "shading/simd.h"
#include "shading/texture.h"

namespace prast {

// Per-lane sampling result, structure of arrays.
struct TexelLanes {
    static constexpr int N = kBlockLanes;
    alignas(64) float r[N], g[N], b[N], a[N];
};

// Where the lanes of one block sample a texture layout. Level A is the level
// sample_trilinear() reads first (the only one when magnifying, at the last
// level, or at an integer lambda); the lanes in `blend` also read level B and
// return a + (b - a) t with t = lambda - floor(lambda).
struct TrilinearLanes {
    static constexpr int N = kBlockLanes;
    // Texel indices into Texture::texel_data(): (x0, y0), (x1, y0), (x0, y1), (x1, y1).
    // Texel counts stay below 2^31 (kMaxImageTexels = 2^28 for level 0).
    alignas(64) std::int32_t ia[4][N], ib[4][N];
    alignas(64) float txa[N], tya[N], txb[N], tyb[N], t[N];
    std::uint32_t live = 0;     // lanes to fetch
    std::uint32_t blend = 0;    // lanes that blend two levels
    // Lanes whose quad reads the NEAREST texel (non-default filters): their
    // four indices are that texel's and their weights 0, which blends 8-bit
    // (finite) texels to exactly the texel; float texels are read as is.
    std::uint32_t nearest = 0;
    std::uint32_t levels = 0;   // bit k: a live lane reads level k
};

// True when a and b sample at the same texel indices with the same weights
// for any uv and derivatives: same level-0 size (hence the same chain and the
// same lambda) and the same sampler (wrap modes and filters).
inline bool same_sampling_layout(const Texture& a, const Texture& b) {
    return a.width(0) == b.width(0) && a.height(0) == b.height(0) && a.sampler_key() == b.sampler_key();
}

// Quads a packed call may draw its lanes from: a live lane each at most.
constexpr int kMaxQuadSlots = kBlockLanes;

namespace sample_lanes_detail {

constexpr int kMaxN = kBlockLanes;

#if PRAST_CALLS_AVX512
// Sixteen lanes compiled for AVX-512 alone (shading/sample_lanes_avx512.cpp)
// and called only when the CPU has it: the same integers and floats per
// lane as the default code. fetch_unorm8_lanes<16, IsaAvx512> and
// prepare_trilinear_lanes<16, IsaAvx512>. The material lanes switch to
// their own AVX-512 copy as a whole (material_lanes.h), which calls these
// directly; these serve other callers of the 16-lane sampler (the sampler
// tests hold them to the scalar sampler over every wrap mode and filter).
void fetch_unorm8_lanes16_avx512(const Texture& tex, const TrilinearLanes& at, TexelLanes& out, unsigned components);
void prepare_trilinear_lanes16_avx512(const Texture& tex, const float* u, const float* v, const float* lambda,
                                      const std::uint8_t* quad, std::uint32_t live, TrilinearLanes& out);
#endif

#if PRAST_CALLS_VBMI
// The 16-lane 8-bit fetch compiled with AVX512_VBMI too
// (shading/sample_lanes_vbmi.cpp), for textures vbmi_serves(): the same
// integers per lane, each channel's pair of taps picked from the gathered
// qwords and the sRGB codes looked up by byte permutes.
void fetch_unorm8_lanes16_vbmi(const Texture& tex, const TrilinearLanes& at, TexelLanes& out, unsigned components);

// Three or four stored channels, whose sRGB ones decode with the sRGB table.
inline bool vbmi_serves(const Texture& tex) {
    if (tex.channels() < 3) return false;
    for (int c = 0; c < tex.channels(); ++c)
        if (tex.srgb(c) && tex.code_table(c) != texture_detail::srgb_code_table()) return false;
    return true;
}
#endif

// One mip level per lane (its quad's).
struct LevelLanes {
    alignas(64) float fw[kMaxN], fh[kMaxN];
    alignas(64) std::int32_t w[kMaxN], h[kMaxN], offset[kMaxN];

    // Lanes [begin, end) read `level`.
    template <class Isa = IsaDefault>
    void set(const Texture& tex, int level, int begin, int end) {
        const std::int32_t lw = tex.width(level), lh = tex.height(level);
        const std::int32_t loff = std::int32_t(tex.level_offset(level));
        const float lfw = float(lw), lfh = float(lh);
        for (int l = begin; l < end; ++l) {
            fw[l] = lfw; fh[l] = lfh;
            w[l] = lw; h[l] = lh; offset[l] = loff;
        }
    }
};

// wrap_index<W>(i, n) and wrap_index<W>(i + 1, n) for i = floor(r n - 0.5)
// of a reduced coordinate r = reduce<W>(c). For Repeat and ClampToEdge r is
// in [0, 1], so i is in [-1, n - 1] and each index meets one side only.
template <Wrap W>
[[gnu::always_inline]] inline void wrap_pair(int i, int n, int& a, int& b) {
    if constexpr (W == Wrap::Repeat) {
        a = i < 0 ? i + n : i;
        b = i + 1 >= n ? i + 1 - n : i + 1;
    } else if constexpr (W == Wrap::ClampToEdge) {
        a = i < 0 ? 0 : i;
        b = i + 1 >= n ? n - 1 : i + 1;
    } else {
        a = texture_detail::wrap_index<W>(i, n);
        b = texture_detail::wrap_index<W>(i + 1, n);
    }
}

// Texture::bilinear_reduced() up to the texel indices, for the first N lanes.
template <int N, Wrap S, Wrap T, class Isa = IsaDefault>
inline void bilinear_indices(const float* __restrict ur, const float* __restrict vr,
                             const LevelLanes& __restrict L, std::int32_t (*__restrict idx)[kMaxN],
                             float* __restrict tx, float* __restrict ty) {
    for (int l = 0; l < N; ++l) {
        const float x = ur[l] * L.fw[l] - 0.5f, y = vr[l] * L.fh[l] - 0.5f;
        const float fx = std::floor(x), fy = std::floor(y);
        tx[l] = x - fx;
        ty[l] = y - fy;
        const int x0 = int(fx), y0 = int(fy), w = L.w[l], h = L.h[l];
        int xa, xb, ya, yb;
        wrap_pair<S>(x0, w, xa, xb);
        wrap_pair<T>(y0, h, ya, yb);
        const int row_a = L.offset[l] + ya * w;
        const int row_b = L.offset[l] + yb * w;
        idx[0][l] = row_a + xa;
        idx[1][l] = row_a + xb;
        idx[2][l] = row_b + xa;
        idx[3][l] = row_b + xb;
    }
}

// Texture::nearest_reduced() up to the texel index, for the lanes in `lanes`
// (the others keep their bilinear indices and weights).
template <int N, Wrap S, Wrap T, class Isa = IsaDefault>
inline void nearest_indices(const float* __restrict ur, const float* __restrict vr, const LevelLanes& __restrict L,
                            std::uint32_t lanes, std::int32_t (*__restrict idx)[kMaxN], float* __restrict tx,
                            float* __restrict ty) {
    using texture_detail::nearest_index;
    for (int l = 0; l < N; ++l) {
        if (!((lanes >> l) & 1u)) continue;
        const int x = nearest_index<S>(ur[l] * L.fw[l], L.w[l]);
        const int y = nearest_index<T>(vr[l] * L.fh[l], L.h[l]);
        idx[0][l] = idx[1][l] = idx[2][l] = idx[3][l] = L.offset[l] + y * L.w[l] + x;
        tx[l] = ty[l] = 0.0f;
    }
}

template <int N, Wrap S, Wrap T, class Isa>
inline void prepare(const float* __restrict u, const float* __restrict v, const LevelLanes& A,
                    const LevelLanes* B, TrilinearLanes& out) {
    alignas(64) float ur[kMaxN], vr[kMaxN];
    for (int l = 0; l < N; ++l) {
        ur[l] = texture_detail::reduce<S>(u[l]);
        vr[l] = texture_detail::reduce<T>(v[l]);
    }
    bilinear_indices<N, S, T, Isa>(ur, vr, A, out.ia, out.txa, out.tya);
    if (B) bilinear_indices<N, S, T, Isa>(ur, vr, *B, out.ib, out.txb, out.tyb);
    if (out.nearest) {
        nearest_indices<N, S, T, Isa>(ur, vr, A, out.nearest, out.ia, out.txa, out.tya);
        if (B) nearest_indices<N, S, T, Isa>(ur, vr, *B, out.nearest, out.ib, out.txb, out.tyb);
    }
}

template <int N, Wrap S, class Isa>
inline void prepare_s(Wrap t, const float* u, const float* v, const LevelLanes& A, const LevelLanes* B,
                      TrilinearLanes& out) {
    switch (t) {
    case Wrap::Repeat: prepare<N, S, Wrap::Repeat, Isa>(u, v, A, B, out); return;
    case Wrap::ClampToEdge: prepare<N, S, Wrap::ClampToEdge, Isa>(u, v, A, B, out); return;
    case Wrap::MirroredRepeat: prepare<N, S, Wrap::MirroredRepeat, Isa>(u, v, A, B, out); return;
    }
}

// 4-channel float vector (one texel); lane-wise IEEE operations, no contraction.
typedef float Float4 __attribute__((vector_size(16)));

// A float texture's texel as a 4-channel vector.
inline Float4 load_texel(const glm::vec4* texels, std::int32_t i) {
    Float4 r;
    std::memcpy(&r, &texels[i], sizeof r);
    return r;
}

template <class Texels>
[[gnu::always_inline]] inline Float4 bilinear(const Texels& texels, const std::int32_t (*idx)[kMaxN], const float* tx,
                                              const float* ty, int l) {
    const Float4 a = load_texel(texels, idx[0][l]), b = load_texel(texels, idx[1][l]);
    const Float4 c = load_texel(texels, idx[2][l]), d = load_texel(texels, idx[3][l]);
    const Float4 top = a + (b - a) * tx[l];
    const Float4 bottom = c + (d - c) * tx[l];
    return top + (bottom - top) * ty[l];
}

// Lane l of an 8-bit texture: Texture::trilinear_wrapped() / filtered_wrapped()'s
// fixed-point steps on the prepared indices and weights.
template <class Isa = IsaDefault>
[[gnu::always_inline]] inline glm::vec4 fix_lane(const Texture& tex, const TrilinearLanes& at, int l) {
    const bool nearest = (at.nearest >> l) & 1u;
    auto level = [&](const std::int32_t (*idx)[kMaxN], const float* tx, const float* ty) {
        if (nearest) return tex.fix_texel(std::size_t(idx[0][l]));
        return tex.fix_bilinear(std::size_t(idx[0][l]), std::size_t(idx[1][l]), std::size_t(idx[2][l]),
                                std::size_t(idx[3][l]), tx[l], ty[l]);
    };
    Texture::Fix4 a = level(at.ia, at.txa, at.tya);
    if ((at.blend >> l) & 1u) a = Texture::fix_blend(a, level(at.ib, at.txb, at.tyb), at.t[l]);
    return tex.fix_value(a);
}

// The live lanes of an 8-bit texture one at a time; the others get 0.
template <int N, class Isa = IsaDefault>
inline void fetch_fix_one_by_one(const Texture& tex, const TrilinearLanes& at, TexelLanes& out) {
    if (at.live != (1u << N) - 1u)
        for (int l = 0; l < N; ++l) out.r[l] = out.g[l] = out.b[l] = out.a[l] = 0.0f;
    for (std::uint32_t m = at.live; m; m &= m - 1) {
        const int l = __builtin_ctz(m);
        const glm::vec4 c = fix_lane<Isa>(tex, at, l);
        out.r[l] = c.r;
        out.g[l] = c.g;
        out.b[l] = c.b;
        out.a[l] = c.a;
    }
}

// The live lanes one at a time, for K float textures: src[k] is a texel array.
template <int N, int K, class Texels, class Isa = IsaDefault>
inline void fetch_texels_one_by_one(const Texels* const* src, const TrilinearLanes& at, TexelLanes* const* out) {
    if (at.live != (1u << N) - 1u) {
        for (int k = 0; k < K; ++k)
            for (int l = 0; l < N; ++l) out[k]->r[l] = out[k]->g[l] = out[k]->b[l] = out[k]->a[l] = 0.0f;
    }
    for (std::uint32_t m = at.live; m; m &= m - 1) {
        const int l = __builtin_ctz(m);
        Float4 c[K];
        if ((at.nearest >> l) & 1u) {  // the texel itself, as Texture::nearest_reduced() returns it
            for (int k = 0; k < K; ++k) c[k] = load_texel(src[k], at.ia[0][l]);
            if ((at.blend >> l) & 1u) {
                for (int k = 0; k < K; ++k) {
                    const Float4 cb = load_texel(src[k], at.ib[0][l]);
                    c[k] = c[k] + (cb - c[k]) * at.t[l];
                }
            }
        } else {
            for (int k = 0; k < K; ++k) c[k] = bilinear(src[k], at.ia, at.txa, at.tya, l);
            if ((at.blend >> l) & 1u) {
                for (int k = 0; k < K; ++k) {
                    const Float4 cb = bilinear(src[k], at.ib, at.txb, at.tyb, l);
                    c[k] = c[k] + (cb - c[k]) * at.t[l];
                }
            }
        }
        for (int k = 0; k < K; ++k) {
            out[k]->r[l] = c[k][0];
            out[k]->g[l] = c[k][1];
            out[k]->b[l] = c[k][2];
            out[k]->a[l] = c[k][3];
        }
    }
}

template <int N, int K, class Isa = IsaDefault>
inline void fetch_lanes_one_by_one(const Texture* const* tex, const TrilinearLanes& at, TexelLanes* const* out) {
    bool float_only = true;
    for (int k = 0; k < K; ++k) float_only &= !tex[k]->is_unorm8();
    if (float_only) {
        const glm::vec4* texels[K];
        for (int k = 0; k < K; ++k) texels[k] = tex[k]->texel_data();
        fetch_texels_one_by_one<N, K, glm::vec4, Isa>(texels, at, out);
        return;
    }
    for (int k = 0; k < K; ++k) {
        if (tex[k]->is_unorm8()) {
            fetch_fix_one_by_one<N, Isa>(*tex[k], at, *out[k]);
        } else {
            const glm::vec4* texels = tex[k]->texel_data();
            fetch_texels_one_by_one<N, 1, glm::vec4, Isa>(&texels, at, out + k);
        }
    }
}

template <int N, class Isa = IsaDefault>
inline void fetch_lanes_one_by_one(const Texture* const* tex, int count, const TrilinearLanes& at,
                                   TexelLanes* const* out) {
    for (; count >= 3; count -= 3, tex += 3, out += 3) fetch_lanes_one_by_one<N, 3, Isa>(tex, at, out);
    if (count == 2) fetch_lanes_one_by_one<N, 2, Isa>(tex, at, out);
    if (count == 1) fetch_lanes_one_by_one<N, 1, Isa>(tex, at, out);
}

#ifdef __AVX2__

// The packed bytes of texels idx and idx + 1 (C bytes each) for W lanes: one
// 4-byte read per lane holds both when C <= 2, one 8-byte read when C >= 3.
// Texture keeps 8 spare bytes after the chain (Texture::kReadSlack).
template <class V, int C>
inline void gather_texel_pairs(const std::uint8_t* base, const std::int32_t* ix, typename V::I& left,
                               typename V::I& right) {
    if constexpr (C <= 2) {
        left = V::template gather_i<C>(base, ix);
        right = V::srlv_i(left, V::template splat_i<8 * C>());
    } else {
        V::template gather_q<C, 8 * C>(base, ix, left, right);
    }
}

// Stored channel c of the words as 15-bit codes (texture.h): byte * 128, or
// the sRGB code table's entry (a 4-byte gather at 2 bytes an entry; the
// table has spare entries).
template <class V>
inline typename V::I channel_codes(typename V::I words, int c, const std::uint16_t* srgb_codes) {
    const typename V::I byte = V::and_i(V::srlv_i(words, V::set1_i(8 * c)), V::template splat_i<0xFF>());
    if (!srgb_codes) return V::template slli_i<7>(byte);
    return V::and_i(V::template gather_i<2>(reinterpret_cast<const std::uint8_t*>(srgb_codes), byte),
                    V::template splat_i<0xFFFF>());
}

// Both taps' codes of one row for 8 lanes of a 3- or 4-channel texture
// with Texture::unorm8_codes(): pair[c] = (code of x0) | (code of x1) << 16
// of stored channel c, as channel_codes() and code_pair() give them. A
// lane's 2C codes are one 16-byte load at its x0; a byte shuffle puts
// channel c's pair in dword c, and a 4x4 transpose of dwords across the
// four registers (lanes k and k + 4 each) gives each channel its lanes.
template <class Isa, int C>
[[gnu::always_inline]] inline void code_pair_rows(const std::uint16_t* codes, const std::int32_t* ix, __m256i pair[4]) {
    auto at = [&](int l) __attribute__((always_inline)) {
        return _mm_loadu_si128(reinterpret_cast<const __m128i*>(codes + std::size_t(ix[l]) * C));
    };
    // dword c: bytes of words c and C + c; dwords past C zero.
    const __m256i pick = C == 4 ? _mm256_setr_epi8(0, 1, 8, 9, 2, 3, 10, 11, 4, 5, 12, 13, 6, 7, 14, 15,
                                                   0, 1, 8, 9, 2, 3, 10, 11, 4, 5, 12, 13, 6, 7, 14, 15)
                                : _mm256_setr_epi8(0, 1, 6, 7, 2, 3, 8, 9, 4, 5, 10, 11, -1, -1, -1, -1,
                                                   0, 1, 6, 7, 2, 3, 8, 9, 4, 5, 10, 11, -1, -1, -1, -1);
    __m256i v[4];
    for (int k = 0; k < 4; ++k)
        v[k] = _mm256_shuffle_epi8(_mm256_inserti128_si256(_mm256_castsi128_si256(at(k)), at(k + 4), 1), pick);
    const __m256i t0 = _mm256_unpacklo_epi32(v[0], v[1]), t1 = _mm256_unpacklo_epi32(v[2], v[3]);
    const __m256i t2 = _mm256_unpackhi_epi32(v[0], v[1]), t3 = _mm256_unpackhi_epi32(v[2], v[3]);
    pair[0] = _mm256_unpacklo_epi64(t0, t1);
    pair[1] = _mm256_unpackhi_epi64(t0, t1);
    pair[2] = _mm256_unpacklo_epi64(t2, t3);
    pair[3] = _mm256_unpackhi_epi64(t2, t3);
}

// code_pair_rows for linear channels of the 8-bit bytes themselves: a
// lane's 2C bytes are one 8-byte load at its x0, the shuffle puts channel
// c's two bytes in the low bytes of dword c's words, and times 128 they are
// the codes (channel_codes()).
template <class Isa, int C>
[[gnu::always_inline]] inline void byte_pair_rows(const std::uint8_t* base, const std::int32_t* ix, __m256i pair[4]) {
    auto at = [&](int l) __attribute__((always_inline)) {
        return _mm_loadl_epi64(reinterpret_cast<const __m128i*>(base + std::size_t(ix[l]) * C));
    };
    const __m256i pick = C == 4 ? _mm256_setr_epi8(0, -1, 4, -1, 1, -1, 5, -1, 2, -1, 6, -1, 3, -1, 7, -1,
                                                   0, -1, 4, -1, 1, -1, 5, -1, 2, -1, 6, -1, 3, -1, 7, -1)
                                : _mm256_setr_epi8(0, -1, 3, -1, 1, -1, 4, -1, 2, -1, 5, -1, -1, -1, -1, -1,
                                                   0, -1, 3, -1, 1, -1, 4, -1, 2, -1, 5, -1, -1, -1, -1, -1);
    __m256i v[4];
    for (int k = 0; k < 4; ++k)
        v[k] = _mm256_slli_epi32(
            _mm256_shuffle_epi8(_mm256_inserti128_si256(_mm256_castsi128_si256(at(k)), at(k + 4), 1), pick), 7);
    const __m256i t0 = _mm256_unpacklo_epi32(v[0], v[1]), t1 = _mm256_unpacklo_epi32(v[2], v[3]);
    const __m256i t2 = _mm256_unpackhi_epi32(v[0], v[1]), t3 = _mm256_unpackhi_epi32(v[2], v[3]);
    pair[0] = _mm256_unpacklo_epi64(t0, t1);
    pair[1] = _mm256_unpackhi_epi64(t0, t1);
    pair[2] = _mm256_unpacklo_epi64(t2, t3);
    pair[3] = _mm256_unpackhi_epi64(t2, t3);
}

#if defined(__AVX512VBMI__)
// The sRGB code table (texture_detail::srgb_code_table()) as the low and the
// high bytes of its 256 codes: a byte permute looks up 128 entries at once.
struct SrgbCodeBytes {
    alignas(64) std::uint8_t lo[256], hi[256];
};
template <class Isa>
inline const SrgbCodeBytes& srgb_code_bytes() {
    static const SrgbCodeBytes bytes = [] {
        SrgbCodeBytes b;
        const std::uint16_t* t = texture_detail::srgb_code_table();
        for (int i = 0; i < 256; ++i) {
            b.lo[i] = std::uint8_t(t[i] & 0xFFu);
            b.hi[i] = std::uint8_t(t[i] >> 8);
        }
        return b;
    }();
    return bytes;
}

// The sRGB codes of the 64 bytes of q, as their low and high bytes: four
// byte permutes (two a half of the table) and a blend by the bytes' top bit.
template <class Isa>
[[gnu::always_inline]] inline void code_bytes(__m512i q, const SrgbCodeBytes& t, __m512i& lo, __m512i& hi) {
    const __mmask64 upper = _mm512_movepi8_mask(q);
    auto look = [&](const std::uint8_t* tab) __attribute__((always_inline)) {
        const __m512i below = _mm512_permutex2var_epi8(_mm512_load_si512(tab), q, _mm512_load_si512(tab + 64));
        const __m512i above = _mm512_permutex2var_epi8(_mm512_load_si512(tab + 128), q, _mm512_load_si512(tab + 192));
        return _mm512_mask_blend_epi8(upper, below, above);
    };
    lo = look(t.lo);
    hi = look(t.hi);
}

// The sRGB codes of all four bytes of the 16 words: code[c] holds byte c's
// (texel channel c) in lane order: the 64 bytes' code bytes (code_bytes)
// unpacked into words, then into each channel's lanes.
template <class Isa>
[[gnu::always_inline]] inline void srgb_codes_vbmi(__m512i w, const SrgbCodeBytes& t, __m512i* code) {
    __m512i lo, hi;
    code_bytes<Isa>(w, t, lo, hi);
    // Per 128 bits (lanes 4k..4k+3): the codes of lanes 4k, 4k+1, then of 4k+2, 4k+3.
    const __m512i first = _mm512_unpacklo_epi8(lo, hi), second = _mm512_unpackhi_epi8(lo, hi);
    // Channels 0 and 1 of lane 4k + j: dword 4k + 2j of `first` (j < 2), of `second` (16 + 4k + 2(j - 2)).
    const __m512i pick01 = _mm512_setr_epi32(0, 2, 16, 18, 4, 6, 20, 22, 8, 10, 24, 26, 12, 14, 28, 30);
    const __m512i pick23 = _mm512_add_epi32(pick01, _mm512_set1_epi32(1));
    const __m512i c01 = _mm512_permutex2var_epi32(first, pick01, second);
    const __m512i c23 = _mm512_permutex2var_epi32(first, pick23, second);
    const __m512i low16 = _mm512_set1_epi32(0xFFFF);
    code[0] = _mm512_and_si512(c01, low16);
    code[1] = _mm512_maskz_srli_epi32(0xFFFF, c01, 16);
    code[2] = _mm512_and_si512(c23, low16);
    code[3] = _mm512_maskz_srli_epi32(0xFFFF, c23, 16);
}

// Byte indices for a permute of two registers (128 bytes) that puts a
// lane's texel x0 and x1 bytes of one channel in bytes 0 and 2 of its dword:
// pair_bytes() picks from the gathered qwords (lanes 0-7 in the first
// register, 8-15 in the second), pair_codes() from one register's code
// bytes (the low ones first, the high ones second), each code byte followed
// by its high byte.
struct PairPick {
    alignas(64) std::uint8_t index[64];
};
constexpr PairPick pair_bytes(int x0, int x1) {  // dword l: [x0, -, x1, -] of lane l's qword
    PairPick p{};
    for (int l = 0; l < 16; ++l) {
        const int q = (l / 8) * 64 + (l % 8) * 8;
        p.index[4 * l] = std::uint8_t(q + x0);
        p.index[4 * l + 2] = std::uint8_t(q + x1);
    }
    return p;
}
constexpr PairPick pair_codes(int x0, int x1) {  // dword l: [lo(x0), hi(x0), lo(x1), hi(x1)] of lane l % 8
    PairPick p{};
    for (int l = 0; l < 16; ++l) {
        const int q = (l % 8) * 8;
        p.index[4 * l] = std::uint8_t(q + x0);
        p.index[4 * l + 1] = std::uint8_t(64 + q + x0);
        p.index[4 * l + 2] = std::uint8_t(q + x1);
        p.index[4 * l + 3] = std::uint8_t(64 + q + x1);
    }
    return p;
}
template <int C, int c> struct PairIndex {
    static constexpr PairPick bytes = pair_bytes(c, C + c);
    static constexpr PairPick codes = pair_codes(c, C + c);
};

// (code of x0) | (code of x1) << 16 of stored channel c, per lane: lerp8's
// pair, from the qwords q (linear: byte * 128) or their code bytes lo, hi.
template <class Isa, int C, int c>
[[gnu::always_inline]] inline __m512i pair_linear(const __m512i* q) {
    const __m512i idx = _mm512_load_si512(PairIndex<C, c>::bytes.index);
    return _mm512_maskz_slli_epi32(0xFFFF, _mm512_maskz_permutex2var_epi8(0x5555555555555555ull, q[0], idx, q[1]), 7);
}
template <class Isa, int C, int c>
[[gnu::always_inline]] inline __m512i pair_srgb(const __m512i* lo, const __m512i* hi) {
    const __m512i idx = _mm512_load_si512(PairIndex<C, c>::codes.index);
    return _mm512_mask_blend_epi32(0xFF00, _mm512_permutex2var_epi8(lo[0], idx, hi[0]),
                                   _mm512_permutex2var_epi8(lo[1], idx, hi[1]));
}

// bilinear_unorm8's x-lerp pairs without splitting the gathered qwords: each
// channel's (x0, x1) codes of a row come from one or two byte permutes of
// them (or of their sRGB code bytes); the same integers as the split path.
template <class Isa, int C, int c>
[[gnu::always_inline]] inline void pair_rows_vbmi(const __m512i* qa, const __m512i* qc, const __m512i* la,
                                                  const __m512i* ha, const __m512i* lc, const __m512i* hc, bool srgb,
                                                  __m512i& top, __m512i& bottom) {
    if (srgb) {
        top = pair_srgb<Isa, C, c>(la, ha);
        bottom = pair_srgb<Isa, C, c>(lc, hc);
    } else {
        top = pair_linear<Isa, C, c>(qa);
        bottom = pair_linear<Isa, C, c>(qc);
    }
}
#endif

// texture_detail::weight8 / lerp8 / narrow8, per lane. A lerp is one
// multiply-add of the 16-bit pairs (a, b) and (256 - w, w): the codes are at
// most 32640 and the weights 256, inside madd's signed 16-bit inputs.
template <class V> inline typename V::I weight8(typename V::F t) {
    return V::cvtt(V::add(V::mul(t, V::set1_f(256.0f)), V::set1_f(0.5f)));
}
template <class V> inline typename V::I weight_pairs(typename V::I w) {
    return V::or_i(V::sub_i(V::template splat_i<256>(), w), V::template slli_i<16>(w));
}
// a | b << 16: the 16-bit pair a lerp multiplies.
template <class V> inline typename V::I code_pair(typename V::I a, typename V::I b) {
    return V::or_i(a, V::template slli_i<16>(b));
}
template <class V> inline typename V::I lerp8(typename V::I a, typename V::I b, typename V::I pairs) {
    return V::madd_i(code_pair<V>(a, b), pairs);
}
template <class V> inline typename V::I narrow8(typename V::I x) {
    return V::template srli_i<8>(V::add_i(x, V::template splat_i<128>()));
}
// The bilinear filter of a row pair's codes, each row as (x0) | (x1) << 16:
// the x-lerps narrowed, then the y-lerp (Texture::fix_bilinear()).
template <class V>
inline typename V::I bilerp_pairs(typename V::I top, typename V::I bottom, typename V::I wx, typename V::I wy) {
    return lerp8<V>(narrow8<V>(V::madd_i(top, wx)), narrow8<V>(V::madd_i(bottom, wx)), wy);
}

// Bilinear filter of every needed stored channel of one level for lanes
// [l0, l0 + W): Texture::fix_bilinear() per lane. needs_srgb: a channel in
// `need` is sRGB-encoded (srgb_codes[c] set).
template <class V, int C, class Isa>
[[gnu::always_inline]] inline void bilinear_unorm8(const Texture& tex, const std::uint16_t* codes, const std::uint16_t* const* srgb_codes, unsigned need,
                                                   bool needs_srgb, const std::int32_t (*idx)[kMaxN], const float* tx_lanes,
                                                   const float* ty_lanes, int l0, typename V::I* result) {
    using I = typename V::I;
    const std::uint8_t* base = tex.unorm8_data();
    const I ia = V::load_i(idx[0] + l0), ib = V::load_i(idx[1] + l0);
    const I ic = V::load_i(idx[2] + l0), id = V::load_i(idx[3] + l0);
    // Unless a lane's footprint wraps or clamps at a row's end, its right taps
    // follow its left ones in memory: half the gathered elements.
    const I one = V::template splat_i<1>();
    const bool pairs = V::all_i(V::and_i(V::cmpeq_i(ib, V::add_i(ia, one)), V::cmpeq_i(id, V::add_i(ic, one))));
    const I wx = weight_pairs<V>(weight8<V>(V::load_f(tx_lanes + l0)));
    const I wy = weight_pairs<V>(weight8<V>(V::load_f(ty_lanes + l0)));
    if constexpr (std::is_same_v<V, Simd<8>> && (C == 3 || C == 4)) {
        if (pairs && codes) {
            I top[4], bottom[4];
            code_pair_rows<Isa, C>(codes, idx[0] + l0, top);
            code_pair_rows<Isa, C>(codes, idx[2] + l0, bottom);
            for (int c = 0; c < C; ++c)
                if ((need >> c) & 1u) result[c] = bilerp_pairs<V>(top[c], bottom[c], wx, wy);
            return;
        }
        if (pairs && !needs_srgb) {
            I top[4], bottom[4];
            byte_pair_rows<Isa, C>(base, idx[0] + l0, top);
            byte_pair_rows<Isa, C>(base, idx[2] + l0, bottom);
            for (int c = 0; c < C; ++c)
                if ((need >> c) & 1u) result[c] = bilerp_pairs<V>(top[c], bottom[c], wx, wy);
            return;
        }
    }
#if defined(__AVX512VBMI__)
    if constexpr (std::is_same_v<Isa, IsaAvx512Vbmi> && (C == 3 || C == 4)) {
        if (pairs) {
            I qa[2], qc[2];
            // A lane's two taps of a row (x0 and x1) are the qword read at x0.
            V::template gather_qwords<C>(base, idx[0] + l0, qa);
            V::template gather_qwords<C>(base, idx[2] + l0, qc);
            // Without an sRGB channel the code bytes are not made at all
            // (zeroing them for nothing cost stores of eight registers).
            auto rows = [&](auto srgb_tag) __attribute__((always_inline)) {
                constexpr bool kSrgb = decltype(srgb_tag)::value;
                I la[2], ha[2], lc[2], hc[2];
                if constexpr (kSrgb) {
                    const SrgbCodeBytes& table = srgb_code_bytes<Isa>();
                    for (int k = 0; k < 2; ++k) {
                        code_bytes<Isa>(qa[k], table, la[k], ha[k]);
                        code_bytes<Isa>(qc[k], table, lc[k], hc[k]);
                    }
                }
                auto channel = [&](auto cc) __attribute__((always_inline)) {
                    constexpr int c = decltype(cc)::value;
                    if (!((need >> c) & 1u)) return;
                    I top, bottom;  // (the code bytes are read only where kSrgb made them)
                    pair_rows_vbmi<Isa, C, c>(qa, qc, la, ha, lc, hc, kSrgb && srgb_codes[c] != nullptr, top, bottom);
                    result[c] = bilerp_pairs<V>(top, bottom, wx, wy);
                };
                channel(std::integral_constant<int, 0>());
                channel(std::integral_constant<int, 1>());
                channel(std::integral_constant<int, 2>());
                if constexpr (C == 4) channel(std::integral_constant<int, 3>());
            };
            if (needs_srgb) rows(std::true_type());
            else rows(std::false_type());
            return;
        }
    }
#endif
    if constexpr (C <= 2) {
        // One 4-byte read holds both taps of a row: each linear channel's
        // (x0, x1) bytes move into the low bytes of the two words by one
        // byte shuffle, and times 128 they are lerp8's code pair.
        if (pairs && !needs_srgb) {
            const I ra = V::template gather_i<C>(base, idx[0] + l0), rc = V::template gather_i<C>(base, idx[2] + l0);
            for (int c = 0; c < C; ++c) {
                if (!((need >> c) & 1u)) continue;
                // Bytes c and C + c of the lane's dword to bytes 0 and 2; 0x80 zeroes 1 and 3.
                const I pick = V::add_i(V::set1_i(int(0x80008000u) | c | ((C + c) << 16)), V::dword_byte_offsets());
                const I top = V::template slli_i<7>(V::shuffle_bytes(ra, pick));
                const I bottom = V::template slli_i<7>(V::shuffle_bytes(rc, pick));
                result[c] = bilerp_pairs<V>(top, bottom, wx, wy);
            }
            return;
        }
    }
    I wa, wb, wc, wd;
    if (pairs) {
        gather_texel_pairs<V, C>(base, idx[0] + l0, wa, wb);
        gather_texel_pairs<V, C>(base, idx[2] + l0, wc, wd);
    } else {
        // Each tap's C bytes (4 read).
        wa = V::template gather_i<C>(base, idx[0] + l0);
        wb = V::template gather_i<C>(base, idx[1] + l0);
        wc = V::template gather_i<C>(base, idx[2] + l0);
        wd = V::template gather_i<C>(base, idx[3] + l0);
    }
#if defined(__AVX512VBMI__)
    // Every sRGB channel's codes from the permutes (vbmi_serves()).
    constexpr bool kVbmi = std::is_same_v<Isa, IsaAvx512Vbmi>;
    [[maybe_unused]] I pa[4] = {}, pb[4] = {}, pc[4] = {}, pd[4] = {};
    if (kVbmi && needs_srgb) {
        const SrgbCodeBytes& table = srgb_code_bytes<Isa>();
        srgb_codes_vbmi<Isa>(wa, table, pa);
        srgb_codes_vbmi<Isa>(wb, table, pb);
        srgb_codes_vbmi<Isa>(wc, table, pc);
        srgb_codes_vbmi<Isa>(wd, table, pd);
    }
#endif
    for (int c = 0; c < C; ++c) {
        if (!((need >> c) & 1u)) continue;
        const std::uint16_t* codes = srgb_codes[c];
        I a, b, cc, d;
#if defined(__AVX512VBMI__)
        if (kVbmi && codes) {
            a = pa[c]; b = pb[c]; cc = pc[c]; d = pd[c];
        } else
#endif
        {
            a = channel_codes<V>(wa, c, codes); b = channel_codes<V>(wb, c, codes);
            cc = channel_codes<V>(wc, c, codes); d = channel_codes<V>(wd, c, codes);
        }
        result[c] = bilerp_pairs<V>(code_pair<V>(a, b), code_pair<V>(cc, d), wx, wy);
    }
}

// All N lanes of an 8-bit texture, W at a time; non-live lanes get 0. Only
// the output components in `components` (bit k: r, g, b, a) are written, and
// only the stored channels they need are read.
template <int N, int W, int C, class Isa>
inline void fetch_unorm8_lanes(const Texture& tex, const TrilinearLanes& at, TexelLanes& out, unsigned components) {
    using V = Simd<W>;
    using F = typename V::F;
    using I = typename V::I;
    const std::uint16_t* const* srgb_codes = tex.srgb_code_tables();
    const std::uint16_t* codes = W == 8 && C >= 3 ? tex.unorm8_codes(at.levels) : nullptr;
    // What every group of W lanes does alike (Texture::unorm8_reads()): the
    // stored channels needed, and each written output's destination and
    // source channel (-1: the constant 1).
    const Texture::Unorm8Reads& reads = tex.unorm8_reads(components);
    float* const all_dst[4] = {out.r, out.g, out.b, out.a};
    float* dst[4];
    int src[4];
    const int outputs = reads.outputs;
    for (int k = 0; k < outputs; ++k) {
        dst[k] = all_dst[reads.component[k]];
        src[k] = reads.channel[k] == Texture::kOne ? -1 : reads.channel[k];
    }
    const unsigned needed = reads.need;
    const bool needs_srgb = reads.needs_srgb;  // a needed channel is sRGB-encoded
    // The loop over groups, inlined three times: with every stored channel
    // needed (the usual case) `need` is a constant there and its tests fold
    // away, and where each output is its own channel the values stay in
    // registers.
    auto groups = [&](const unsigned need, const bool identity) __attribute__((always_inline)) {
        for (int l0 = 0; l0 < N; l0 += W) {
            const unsigned live = (at.live >> l0) & ((1u << W) - 1u);
            if (!live) {
                for (int k = 0; k < outputs; ++k) V::store_f(dst[k] + l0, V::zero_f());
                continue;
            }
            const I izero = V::set1_i(0);
            I res[4] = {izero, izero, izero, izero};
            bilinear_unorm8<V, C, Isa>(tex, codes, srgb_codes, need, needs_srgb, at.ia, at.txa, at.tya, l0, res);
            const unsigned blend = (at.blend >> l0) & ((1u << W) - 1u);
            if (blend) {
                I resb[4] = {izero, izero, izero, izero};
                bilinear_unorm8<V, C, Isa>(tex, codes, srgb_codes, need, needs_srgb, at.ib, at.txb, at.tyb, l0, resb);
                const I wt = weight_pairs<V>(weight8<V>(V::load_f(at.t + l0)));
                const I mask = V::cmpeq_i(V::and_i(V::set1_i(int(blend)), V::lane_bits()), V::lane_bits());
                for (int c = 0; c < C; ++c)
                    if ((need >> c) & 1u)
                        res[c] = V::select_i(mask, lerp8<V>(narrow8<V>(res[c]), narrow8<V>(resb[c]), wt), res[c]);
            }
            const F live_mask = V::as_f(V::cmpeq_i(V::and_i(V::set1_i(int(live)), V::lane_bits()), V::lane_bits()));
            const F zero = V::zero_f();
            const F full = V::set1_f(texture_detail::kFixFullF);
            F value[4] = {zero, zero, zero, zero};
            for (int c = 0; c < C; ++c)
                if ((need >> c) & 1u) value[c] = V::div(V::cvt(res[c]), full);  // Texture::fix_value()
            if (identity) {
                for (int c = 0; c < C; ++c) V::store_f(all_dst[c] + l0, V::select(live_mask, value[c], zero));
                continue;
            }
            for (int k = 0; k < outputs; ++k) {
                const F v = src[k] < 0 ? V::set1_f(1.0f) : value[src[k]];
                V::store_f(dst[k] + l0, V::select(live_mask, v, zero));
            }
        }
    };
    constexpr unsigned kAll = (1u << C) - 1u;
    if (needed == kAll && reads.identity) groups(kAll, true);
    else if (needed == kAll) groups(kAll, false);
    else groups(needed, false);
}

// Blocks with at most this many live lanes read them one by one.
constexpr int kSparseLanes = 4;


template <int N, class Isa = IsaDefault>
inline void fetch_unorm8_lanes(const Texture& tex, const TrilinearLanes& at, TexelLanes& out, unsigned components) {
#ifdef PRAST_SIMD16
    constexpr int W = N >= 16 ? 16 : (N >= 8 ? 8 : 4);
#else
    constexpr int W = N >= 8 ? 8 : 4;
#endif
    if (__builtin_popcount(at.live) <= kSparseLanes) {
        fetch_fix_one_by_one<N, Isa>(tex, at, out);  // any channel count
        return;
    }
#if PRAST_CALLS_AVX512
    if constexpr (N == 16 && std::is_same_v<Isa, IsaDefault>) {
        if (use_avx512()) {
            fetch_unorm8_lanes16_avx512(tex, at, out, components);
            return;
        }
    }
#endif
#if PRAST_CALLS_VBMI
    if constexpr (N == 16 && std::is_same_v<Isa, IsaAvx512>) {
        if (use_avx512_vbmi() && vbmi_serves(tex)) {
            fetch_unorm8_lanes16_vbmi(tex, at, out, components);
            return;
        }
    }
#endif
    switch (tex.channels()) {
    case 1: fetch_unorm8_lanes<N, W, 1, Isa>(tex, at, out, components); return;
    case 2: fetch_unorm8_lanes<N, W, 2, Isa>(tex, at, out, components); return;
    case 3: fetch_unorm8_lanes<N, W, 3, Isa>(tex, at, out, components); return;
    default: fetch_unorm8_lanes<N, W, 4, Isa>(tex, at, out, components); return;
    }
}

#endif // __AVX2__

} // namespace sample_lanes_detail

// Prepares the first N lanes: u and v hold their coordinates, lambda[q] the
// level of detail of quad q (Texture::lod of its uv derivatives). With quad
// null, N = 16 and the block is unpacked: lane l lies in quad l / 4 of four.
// Otherwise the lanes are packed (the live lanes of one or several sparse
// blocks first) and quad[l] < kMaxQuadSlots names lane l's quad. Only the
// lanes in `live` are fetched later, but every lane gets valid indices
// (reduce() folds any coordinate).
template <int N = kBlockLanes, class Isa = IsaDefault>
inline void prepare_trilinear_lanes(const Texture& tex, const float* u, const float* v, const float* lambda,
                                    const std::uint8_t* quad, std::uint32_t live, TrilinearLanes& out) {
    using namespace sample_lanes_detail;
    static_assert(N % 4 == 0 && N <= kMaxN, "whole vectors of lanes");
#if PRAST_CALLS_AVX512
    if constexpr (N == 16 && std::is_same_v<Isa, IsaDefault>) {
        if (use_avx512()) {
            prepare_trilinear_lanes16_avx512(tex, u, v, lambda, quad, live, out);
            return;
        }
    }
#endif
    const bool unpacked = !quad;
    auto quad_of = [quad](int l) { return quad ? int(quad[l]) : l >> 2; };

    // The level choice of Texture::trilinear_wrapped(), once per quad with a
    // live lane: level A alone, or A and B = A + 1 blended by t.
    std::uint32_t live_quads = 0;
    if (unpacked) {
        for (int q = 0; q < 4; ++q) live_quads |= std::uint32_t(((live >> (4 * q)) & 0xFu) != 0) << q;
    } else {
        for (int l = 0; l < N; ++l)
            if ((live >> l) & 1u) live_quads |= 1u << quad_of(l);
    }
    int la[kMaxQuadSlots] = {};
    float t[kMaxQuadSlots] = {};
    std::uint32_t blend_quads = 0, nearest_quads = 0;
    const int last = tex.levels() - 1;
#ifdef __AVX2__
    if (unpacked && live_quads == 0xFu && tex.default_filters()) {
        // The loop below for the four quads of a block at once: the same
        // comparisons, floor and subtraction per quad.
        const __m128 lam = _mm_loadu_ps(lambda);
        const __m128 minify = _mm_cmpgt_ps(lam, _mm_setzero_ps());  // false for NaN
        const __m128 between = _mm_andnot_ps(_mm_cmpge_ps(lam, _mm_set1_ps(float(last))), minify);
        const __m128 fl = _mm_floor_ps(lam);
        const __m128 tq = _mm_and_ps(between, _mm_sub_ps(lam, fl));
        const __m128i at_last = _mm_and_si128(_mm_castps_si128(minify), _mm_set1_epi32(last));
        const __m128i level = _mm_blendv_epi8(at_last, _mm_cvttps_epi32(fl), _mm_castps_si128(between));
        _mm_storeu_si128(reinterpret_cast<__m128i*>(la), level);
        _mm_storeu_ps(t, tq);
        blend_quads = std::uint32_t(_mm_movemask_ps(_mm_cmpneq_ps(tq, _mm_setzero_ps())));
    } else
#endif
    if (tex.default_filters()) {
        for (std::uint32_t qs = live_quads; qs; qs &= qs - 1) {
            const int q = __builtin_ctz(qs);
            const float lam = lambda[q];
            if (!(lam > 0.0f)) {
                la[q] = 0;  // magnification, or NaN
            } else if (lam >= float(last)) {
                la[q] = last;
            } else {
                const float fl = std::floor(lam);
                la[q] = int(fl);
                t[q] = lam - fl;
                if (t[q] != 0.0f) blend_quads |= 1u << q;
            }
        }
    } else {
        for (std::uint32_t qs = live_quads; qs; qs &= qs - 1) {
            const int q = __builtin_ctz(qs);
            const LevelChoice c = tex.choose_level(lambda[q]);
            la[q] = c.level;
            t[q] = c.t;
            blend_quads |= std::uint32_t(c.blend) << q;
            nearest_quads |= std::uint32_t(c.nearest) << q;
        }
    }
    // Quads without a live lane read a live quad's level (their lanes are
    // dropped): every lane then reads a level in out.levels, the levels whose
    // 16-bit codes the fetch has filled (Texture::unorm8_codes()).
    {
        const int q_live = live_quads ? __builtin_ctz(live_quads) : 0;
        for (int q = 0; q < (unpacked ? 4 : kMaxQuadSlots); ++q)
            if (!((live_quads >> q) & 1u)) la[q] = la[q_live];
    }
    out.live = live;
    out.blend = 0;
    out.nearest = 0;
    out.levels = 0;
    for (std::uint32_t qs = live_quads; qs; qs &= qs - 1) {
        const int q = __builtin_ctz(qs);
        out.levels |= (1u | ((blend_quads >> q) & 1u) << 1) << la[q];
    }
    if (unpacked) {
        for (int q = 0; q < 4; ++q) {
            for (int l = 4 * q; l < 4 * q + 4; ++l) out.t[l] = t[q];
            out.blend |= ((blend_quads >> q) & 1u) * (0xFu << (4 * q));
        }
        if (nearest_quads)
            for (int q = 0; q < 4; ++q) out.nearest |= ((nearest_quads >> q) & 1u) * (0xFu << (4 * q));
    } else {
        for (int l = 0; l < N; ++l) {
            out.t[l] = t[quad_of(l)];
            out.blend |= ((blend_quads >> quad_of(l)) & 1u) << l;
        }
        if (nearest_quads)
            for (int l = 0; l < N; ++l) out.nearest |= ((nearest_quads >> quad_of(l)) & 1u) << l;
    }
    out.blend &= live;

    // Per-lane level sizes; usually all quads read the same levels.
    bool uniform = true;
    const int q0 = live_quads ? __builtin_ctz(live_quads) : 0;
    for (std::uint32_t qs = live_quads & (live_quads - 1); qs; qs &= qs - 1) {
        const int q = __builtin_ctz(qs);
        uniform &= la[q] == la[q0] && ((blend_quads >> q) & 1u) == ((blend_quads >> q0) & 1u);
    }
    LevelLanes A, B;
    if (uniform) {
        A.template set<Isa>(tex, la[q0], 0, N);
    } else if (unpacked) {
        for (int q = 0; q < 4; ++q) A.template set<Isa>(tex, la[q], 4 * q, 4 * q + 4);
    } else {
        for (int l = 0; l < N; ++l) A.template set<Isa>(tex, la[quad_of(l)], l, l + 1);
    }
    const LevelLanes* b = nullptr;
    if (out.blend) {
        // Lanes that do not blend get level A again (never read).
        if (uniform) {
            B.template set<Isa>(tex, la[q0] + 1, 0, N);
        } else if (unpacked) {
            for (int q = 0; q < 4; ++q) B.template set<Isa>(tex, la[q] + ((blend_quads >> q) & 1u), 4 * q, 4 * q + 4);
        } else {
            for (int l = 0; l < N; ++l) B.template set<Isa>(tex, la[quad_of(l)] + ((blend_quads >> quad_of(l)) & 1u), l, l + 1);
        }
        b = &B;
    }
    switch (tex.wrap_s()) {
    case Wrap::Repeat: prepare_s<N, Wrap::Repeat, Isa>(tex.wrap_t(), u, v, A, b, out); return;
    case Wrap::ClampToEdge: prepare_s<N, Wrap::ClampToEdge, Isa>(tex.wrap_t(), u, v, A, b, out); return;
    case Wrap::MirroredRepeat: prepare_s<N, Wrap::MirroredRepeat, Isa>(tex.wrap_t(), u, v, A, b, out); return;
    }
}

// Filters the live lanes of `at` from the `count` textures tex[k] (all of the
// layout the lanes were prepared for) into out[k]; the other lanes of the
// first N are set to 0. 8-bit textures go through the gathers (AVX2 builds);
// float ones are read lane by lane, up to three per pass so that the indices
// and weights are read once and the texel loads of the textures overlap.
// components[k] (bit 0 r, 1 g, 2 b, 3 a; null: all) says which components of
// out[k] the caller reads: the gathers skip the others (left unwritten).
template <int N = kBlockLanes, class Isa = IsaDefault>
inline void fetch_trilinear_lanes(const Texture* const* tex, int count, const TrilinearLanes& at,
                                  TexelLanes* const* out, const std::uint8_t* components = nullptr) {
    using namespace sample_lanes_detail;
#ifdef __AVX2__
    const Texture* rest[3];
    TexelLanes* rest_out[3];
    int n_rest = 0;
    for (int k = 0; k < count; ++k) {
        if (tex[k]->is_unorm8()) {
            fetch_unorm8_lanes<N, Isa>(*tex[k], at, *out[k], components ? components[k] : 0xFu);
            continue;
        }
        rest[n_rest] = tex[k];
        rest_out[n_rest++] = out[k];
        if (n_rest == 3) {
            fetch_lanes_one_by_one<N, 3, Isa>(rest, at, rest_out);
            n_rest = 0;
        }
    }
    fetch_lanes_one_by_one<N, Isa>(rest, n_rest, at, rest_out);
#else
    (void)components;
    fetch_lanes_one_by_one<N, Isa>(tex, count, at, out);
#endif
}

// Texture::lod() of the quads in `quads` (bits of up to kMaxQuadSlots) into
// lambda[q], four quads per SSE instruction where AVX2 is on: the scalar
// function's multiplies and adds in its order, its fmax, its three special
// cases and lod_log2's table read, so the bits are the scalar ones
// (tests/test_sample_lanes.cpp). The other entries of lambda in a group of
// four are written too, from zero derivatives.
template <class Isa = IsaDefault>
inline void quad_lods(const Texture& tex, const float* dudx, const float* dvdx, const float* dudy, const float* dvdy,
                      std::uint32_t quads, float* lambda) {
#ifdef __AVX2__
    const __m128 w = _mm_set1_ps(tex.lod_width()), h = _mm_set1_ps(tex.lod_height());
    const __m128i bit = _mm_setr_epi32(1, 2, 4, 8);
    const float* table = texture_detail::kLog2Mantissa.data();
    for (int g = 0; g < kMaxQuadSlots; g += 4) {
        const unsigned four = (quads >> g) & 0xFu;
        if (!four) continue;
        // Quads outside `quads` may hold stale derivatives: zero them.
        const __m128 keep = _mm_castsi128_ps(_mm_cmpeq_epi32(_mm_and_si128(_mm_set1_epi32(int(four)), bit), bit));
        const __m128 ax = _mm_mul_ps(_mm_and_ps(_mm_loadu_ps(dudx + g), keep), w);
        const __m128 bx = _mm_mul_ps(_mm_and_ps(_mm_loadu_ps(dvdx + g), keep), h);
        const __m128 ay = _mm_mul_ps(_mm_and_ps(_mm_loadu_ps(dudy + g), keep), w);
        const __m128 by = _mm_mul_ps(_mm_and_ps(_mm_loadu_ps(dvdy + g), keep), h);
        const __m128 p = _mm_add_ps(_mm_mul_ps(ax, ax), _mm_mul_ps(bx, bx));
        const __m128 q = _mm_add_ps(_mm_mul_ps(ay, ay), _mm_mul_ps(by, by));
        // fmax(p, q): p where p >= q or q is NaN, else q.
        const __m128 take_p = _mm_or_ps(_mm_cmp_ps(p, q, _CMP_GE_OQ), _mm_cmp_ps(q, q, _CMP_UNORD_Q));
        const __m128 rho2 = _mm_blendv_ps(q, p, take_p);
        // lod_log2(rho2), meaningful where rho2 is a positive normal float.
        const __m128i bits = _mm_castps_si128(rho2);
        const __m128 e = _mm_cvtepi32_ps(_mm_sub_epi32(_mm_srli_epi32(bits, 23), _mm_set1_epi32(127)));
        const __m128i m = _mm_and_si128(bits, _mm_set1_epi32(0x7FFFFF));
        const __m128i i = _mm_srli_epi32(m, 15);  // 0..255
        const __m128 f = _mm_mul_ps(_mm_cvtepi32_ps(_mm_and_si128(m, _mm_set1_epi32(0x7FFF))), _mm_set1_ps(1.0f / 32768.0f));
        const __m128 lo = _mm_i32gather_ps(table, i, 4), hi = _mm_i32gather_ps(table + 1, i, 4);
        const __m128 log2 = _mm_add_ps(e, _mm_add_ps(lo, _mm_mul_ps(_mm_sub_ps(hi, lo), f)));
        __m128 lam = _mm_mul_ps(_mm_set1_ps(0.5f), log2);
        lam = _mm_blendv_ps(lam, _mm_set1_ps(64.0f), _mm_cmp_ps(lam, _mm_set1_ps(64.0f), _CMP_GT_OQ));
        lam = _mm_blendv_ps(lam, _mm_set1_ps(-64.0f), _mm_cmp_ps(lam, _mm_set1_ps(-64.0f), _CMP_LT_OQ));
        // The special cases, NaN last since it overrides the others.
        lam = _mm_blendv_ps(lam, _mm_set1_ps(64.0f), _mm_cmp_ps(rho2, _mm_set1_ps(3.40282347e38f), _CMP_NLE_UQ));
        lam = _mm_blendv_ps(lam, _mm_set1_ps(-64.0f), _mm_cmp_ps(rho2, _mm_set1_ps(1.17549435e-38f), _CMP_NGE_UQ));
        lam = _mm_blendv_ps(lam, _mm_setzero_ps(), _mm_cmp_ps(rho2, rho2, _CMP_UNORD_Q));
        _mm_storeu_ps(lambda + g, lam);
    }
#else
    for (std::uint32_t qs = quads; qs; qs &= qs - 1) {
        const int q = __builtin_ctz(qs);
        lambda[q] = tex.lod(dudx[q], dvdx[q], dudy[q], dvdy[q]);
    }
#endif
}

template <int N = kBlockLanes>
inline void fetch_trilinear_lanes(const Texture& tex, const TrilinearLanes& at, TexelLanes& out) {
    const Texture* t = &tex;
    TexelLanes* o = &out;
    fetch_trilinear_lanes<N>(&t, 1, at, &o);
}

} // namespace prast

// The shadow-map lookup of shadow_map.h for the lanes of a 4x4 block (all 16,
// or the first 4 or 8 when the fragment program packs a sparse block's live
// lanes): the taps in a loop over lanes that calls shadow_tap() (branch-free,
// vectorised); then, 8 (or 4) lanes per instruction with AVX2 gathers, the
// least and greatest distance around each lane's 4x4 PCF footprint (the
// map's summary cells: most lanes are all lit or all in shadow, 1 or 0), and
// the whole footprint only for groups with a lane in a penumbra. Each lane performs shadow_pcf()'s float
// operations in the same order, so the block lighting equals the scalar
// shade_surface() bit for bit (tests/test_shadows.cpp).
#pragma once

#include <cstdint>
#include <type_traits>

#ifdef __AVX2__
#include <immintrin.h>
#endif

#include "raster/limits.h"
#include "shading/shadow_map.h"

namespace prast {

// vis[l] = the visibility of receiver l (positions P, geometric normals G,
// unit, facing the viewer) from the light of `map`; l_dir is the direction
// towards a directional light (point lights compute their own).
template <int N = kBlockLanes>
inline void shadow_visibility_lanes(const ShadowMap& map, const float* __restrict Px, const float* __restrict Py,
                                    const float* __restrict Pz, const float* __restrict Gx,
                                    const float* __restrict Gy, const float* __restrict Gz, const glm::vec3& l_dir,
                                    float* __restrict vis) {
    static_assert(N % 4 == 0 && N <= kBlockLanes, "whole vectors of lanes");
    alignas(64) std::int32_t base[N], cell[N];
    alignas(64) float fx[N], fy[N], thr[N];
    const float lx = l_dir.x, ly = l_dir.y, lz = l_dir.z;
    auto taps = [&](auto cube) {
        for (int l = 0; l < N; ++l) {
            const ShadowTap t = shadow_tap<cube()>(map, Px[l], Py[l], Pz[l], Gx[l], Gy[l], Gz[l], lx, ly, lz);
            base[l] = t.base;
            cell[l] = t.cell;
            fx[l] = t.fx;
            fy[l] = t.fy;
            thr[l] = t.threshold;
        }
    };
    if (map.cube) taps(std::true_type{});
    else taps(std::false_type{});
    const float* texels = map.distance.data();
    const int stride = map.stride;
#ifdef __AVX2__
    const float* cmin = map.cell_min.data();
    const float* cmax = map.cell_max.data();
    if constexpr (N >= 8) {
        const __m256 one = _mm256_set1_ps(1.0f), zero = _mm256_setzero_ps();
        for (int h = 0; h < N; h += 8) {
            const __m256i c = _mm256_load_si256(reinterpret_cast<const __m256i*>(cell + h));
            const __m256 th = _mm256_load_ps(thr + h);
            // Footprints all lit or all in shadow: 1 or 0, what the PCF gives.
            const __m256 lit_all = _mm256_cmp_ps(_mm256_i32gather_ps(cmin, c, 4), th, _CMP_GE_OQ);
            const __m256 dark_all = _mm256_cmp_ps(_mm256_i32gather_ps(cmax, c, 4), th, _CMP_LT_OQ);
            if (_mm256_movemask_ps(_mm256_or_ps(lit_all, dark_all)) == 0xFF) {
                _mm256_store_ps(vis + h, _mm256_and_ps(lit_all, one));
                continue;
            }
            const __m256i b = _mm256_load_si256(reinterpret_cast<const __m256i*>(base + h));
            const __m256 fxv = _mm256_load_ps(fx + h), fyv = _mm256_load_ps(fy + h);
            const __m256 wx[4] = {_mm256_sub_ps(one, fxv), one, one, fxv};
            const __m256 wy[4] = {_mm256_sub_ps(one, fyv), one, one, fyv};
            const __m256 sx = _mm256_add_ps(_mm256_add_ps(_mm256_add_ps(wx[0], wx[1]), wx[2]), wx[3]);
            __m256 lit = zero, total = zero;
            for (int j = 0; j < 4; ++j) {
                __m256 rs = zero;
                for (int i = 0; i < 4; ++i) {
                    const __m256i idx = _mm256_add_epi32(b, _mm256_set1_epi32(j * stride + i));
                    const __m256 d = _mm256_i32gather_ps(texels, idx, 4);
                    rs = _mm256_add_ps(rs, _mm256_and_ps(_mm256_cmp_ps(d, th, _CMP_GE_OQ), wx[i]));
                }
                lit = _mm256_add_ps(lit, _mm256_mul_ps(wy[j], rs));
                total = _mm256_add_ps(total, _mm256_mul_ps(wy[j], sx));
            }
            _mm256_store_ps(vis + h, _mm256_div_ps(lit, total));
        }
    } else {
        const __m128 one = _mm_set1_ps(1.0f), zero = _mm_setzero_ps();
        const __m128i c = _mm_load_si128(reinterpret_cast<const __m128i*>(cell));
        const __m128 th = _mm_load_ps(thr);
        const __m128 lit_all = _mm_cmp_ps(_mm_i32gather_ps(cmin, c, 4), th, _CMP_GE_OQ);
        const __m128 dark_all = _mm_cmp_ps(_mm_i32gather_ps(cmax, c, 4), th, _CMP_LT_OQ);
        if (_mm_movemask_ps(_mm_or_ps(lit_all, dark_all)) == 0xF) {
            _mm_store_ps(vis, _mm_and_ps(lit_all, one));
            return;
        }
        const __m128i b = _mm_load_si128(reinterpret_cast<const __m128i*>(base));
        const __m128 fxv = _mm_load_ps(fx), fyv = _mm_load_ps(fy);
        const __m128 wx[4] = {_mm_sub_ps(one, fxv), one, one, fxv};
        const __m128 wy[4] = {_mm_sub_ps(one, fyv), one, one, fyv};
        const __m128 sx = _mm_add_ps(_mm_add_ps(_mm_add_ps(wx[0], wx[1]), wx[2]), wx[3]);
        __m128 lit = zero, total = zero;
        for (int j = 0; j < 4; ++j) {
            __m128 rs = zero;
            for (int i = 0; i < 4; ++i) {
                const __m128i idx = _mm_add_epi32(b, _mm_set1_epi32(j * stride + i));
                const __m128 d = _mm_i32gather_ps(texels, idx, 4);
                rs = _mm_add_ps(rs, _mm_and_ps(_mm_cmp_ps(d, th, _CMP_GE_OQ), wx[i]));
            }
            lit = _mm_add_ps(lit, _mm_mul_ps(wy[j], rs));
            total = _mm_add_ps(total, _mm_mul_ps(wy[j], sx));
        }
        _mm_store_ps(vis, _mm_div_ps(lit, total));
    }
#else
    for (int l = 0; l < N; ++l) {
        ShadowTap t;
        t.base = base[l];
        t.fx = fx[l];
        t.fy = fy[l];
        t.threshold = thr[l];
        vis[l] = shadow_pcf(map, t);
    }
    (void)texels;
    (void)stride;
    (void)cell;
#endif
}

} // namespace prast

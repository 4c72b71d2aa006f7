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


#include "raster/limits.h"
#include "shading/shadow/shadow_map.h"
#include "shading/isa.h"
#include "shading/simd.h"

namespace prast {

#ifdef __AVX2__
// W = V's width lanes of shadow_pcf(), a gather per tap: first the least and
// greatest distance of each lane's footprint cell, which settle lanes all lit
// (1) or all in shadow (0); the 16 taps only when a lane is in a penumbra.
template <class V, class Isa = IsaDefault>
inline void shadow_pcf_group(const ShadowMap& map, const std::int32_t* base, const std::int32_t* cell,
                             const float* fx, const float* fy, const float* thr, float* vis) {
    using F = typename V::F;
    const F one = V::set1_f(1.0f), zero = V::zero_f();
    const typename V::I c = V::load_i(cell);
    const F th = V::load_f(thr);
    const F lit_all = V::cmpge(V::gather_f(map.cell_min.data(), c), th);
    const F dark_all = V::cmplt(V::gather_f(map.cell_max.data(), c), th);
    if (V::all(V::or_f(lit_all, dark_all))) {
        V::store_f(vis, V::and_f(lit_all, one));
        return;
    }
    const typename V::I b = V::load_i(base);
    const F fxv = V::load_f(fx), fyv = V::load_f(fy);
    const F wx[4] = {V::sub(one, fxv), one, one, fxv};
    const F wy[4] = {V::sub(one, fyv), one, one, fyv};
    const F sx = V::add(V::add(V::add(wx[0], wx[1]), wx[2]), wx[3]);
    F lit = zero, total = zero;
    for (int j = 0; j < 4; ++j) {
        F rs = zero;
        for (int i = 0; i < 4; ++i) {
            const F d = V::gather_f(map.distance.data(), V::add_i(b, V::set1_i(j * map.stride + i)));
            rs = V::add(rs, V::and_f(V::cmpge(d, th), wx[i]));
        }
        lit = V::add(lit, V::mul(wy[j], rs));
        total = V::add(total, V::mul(wy[j], sx));
    }
    V::store_f(vis, V::div(lit, total));
}
#endif

// vis[l] = the visibility of receiver l (positions P, geometric normals G,
// unit, facing the viewer) from the light of `map`; l_dir is the direction
// towards a directional light (point lights compute their own).
template <int N = kBlockLanes, class Isa = IsaDefault>
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
#ifdef __AVX2__
    if constexpr (N >= 8) {
        for (int h = 0; h < N; h += 8) shadow_pcf_group<Simd<8>, Isa>(map, base + h, cell + h, fx + h, fy + h, thr + h, vis + h);
    } else {
        shadow_pcf_group<Simd<4>, Isa>(map, base, cell, fx, fy, thr, vis);
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
    (void)cell;
#endif
}

} // namespace prast

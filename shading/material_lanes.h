// sample_material() for many lanes at once (a 4x4 block's 16 in place, or
// the live lanes of one or several blocks packed into 4, 8 or 16): texture lookups through the block sampler
// (sample_lanes.h), then the factors, clamps and normal mapping as loops over
// lanes with selects instead of branches, which the compiler vectorises. Every
// lane performs exactly the float operations of the scalar sample_material()
// in the same order, so the two agree bit for bit (tests/test_sample_lanes.cpp)
// and the stepper's scalar explanation of a pixel holds. The result feeds the
// block lighting of light_block.h.
#pragma once

#include <cstdint>
#include <cstring>
#include <type_traits>

#include "raster/limits.h"
#include "shading/light_block.h"
#include "shading/sample_lanes.h"
#include "shading/surface.h"

namespace prast {

// The interpolated geometry of the lanes (SurfacePoint in structure-of-arrays
// form). The uv derivatives belong to the 2x2 quads (fragment.h: x from the
// quad's top row, y from its left column). With quad null, the 16 lanes are
// one unpacked block (lane l in quad l / 4 of four); otherwise live lanes are
// packed first, from one sparse block or several (of several triangles), and
// quad[l] names lane l's quad, of up to kMaxQuadSlots.
struct SurfaceLanes {
    const float *Px, *Py, *Pz;      // world position
    const float *Nx, *Ny, *Nz;      // interpolated vertex normal
    const float *Tx, *Ty, *Tz, *Tw; // tangent + handedness
    const float *u, *v;             // UV set 0
    const std::uint8_t* quad = nullptr;
    // Per quad slot; the one past kMaxQuadSlots takes the writes of quads
    // without a live lane, which the packing makes without a branch.
    float dudx[kMaxQuadSlots + 1], dvdx[kMaxQuadSlots + 1], dudy[kMaxQuadSlots + 1], dvdy[kMaxQuadSlots + 1];
    std::uint32_t back_facing = 0;  // lanes of back-facing triangles
    // UV sets 1 .. kMaxUvSets - 1 and their per-quad derivatives, filled only
    // when the material reads them (BoundMaterial::reads_extra_uv_sets).
    const float* u_more[kMaxUvSets - 1] = {};
    const float* v_more[kMaxUvSets - 1] = {};
    float dudx_more[kMaxUvSets - 1][kMaxQuadSlots + 1], dvdx_more[kMaxUvSets - 1][kMaxQuadSlots + 1];
    float dudy_more[kMaxUvSets - 1][kMaxQuadSlots + 1], dvdy_more[kMaxUvSets - 1][kMaxQuadSlots + 1];
    // The vertex colour (linear RGBA); null when the mesh has none.
    const float *Cr = nullptr, *Cg = nullptr, *Cb = nullptr, *Ca = nullptr;

    const float* u_of(int set) const { return set == 0 ? u : u_more[set - 1]; }
    const float* v_of(int set) const { return set == 0 ? v : v_more[set - 1]; }
};

namespace material_lanes_detail {

// safe_normalize(v, fallback) of surface.h, per lane.
template <int N, class Isa = IsaDefault>
[[gnu::always_inline]] inline void safe_normalize_lanes(float* __restrict x, float* __restrict y,
                                                        float* __restrict z, const float* __restrict fx,
                                                        const float* __restrict fy, const float* __restrict fz) {
    for (int l = 0; l < N; ++l) {
        const float len2 = x[l] * x[l] + y[l] * y[l] + z[l] * z[l];
        const bool ok = (len2 > 1e-20f) & (len2 <= 3.402823466e38f);
        const float s = std::sqrt(ok ? len2 : 1.0f);
        x[l] = ok ? x[l] / s : fx[l];
        y[l] = ok ? y[l] / s : fy[l];
        z[l] = ok ? z[l] / s : fz[l];
    }
}

// Copies and fills of lane arrays in whole vectors of the width the loops
// that read them use (64 bytes in the AVX-512 copy, else 32 where AVX2 is
// on): a memcpy of 64 bytes compiled to 16-byte moves, and the vector loads
// that read the copy back stalled on store forwarding.
template <int N, class Isa = IsaDefault>
[[gnu::always_inline]] inline void copy_lanes(float* dst, const float* src) {
#ifdef PRAST_SIMD16
    if constexpr (N % 16 == 0) {
        for (int l = 0; l < N; l += 16) _mm512_storeu_ps(dst + l, _mm512_loadu_ps(src + l));
        return;
    }
#endif
#ifdef __AVX2__
    if constexpr (N % 8 == 0) {
        for (int l = 0; l < N; l += 8) _mm256_storeu_ps(dst + l, _mm256_loadu_ps(src + l));
        return;
    }
#endif
    std::memcpy(dst, src, sizeof(float) * N);
}
template <int N, class Isa = IsaDefault>
[[gnu::always_inline]] inline void fill_lanes(float* dst, float v) {
#ifdef PRAST_SIMD16
    if constexpr (N % 16 == 0) {
        for (int l = 0; l < N; l += 16) _mm512_storeu_ps(dst + l, _mm512_set1_ps(v));
        return;
    }
#endif
#ifdef __AVX2__
    if constexpr (N % 8 == 0) {
        for (int l = 0; l < N; l += 8) _mm256_storeu_ps(dst + l, _mm256_set1_ps(v));
        return;
    }
#endif
    for (int l = 0; l < N; ++l) dst[l] = v;
}

} // namespace material_lanes_detail

// plan_lookups(bm, plan) (declared in surface.h, defined in
// material_lanes.cpp as default code, which the AVX-512 copy calls too):
// every map the lanes read, with the components that are used (bit 0 r ..
// 3 a), keyed by UV set and texture transform (key = set * 8 + 1 + the
// first map with an equal transform, or set * 8 without one; all 0 unless
// a map reads another set or has a transform), grouped by layout and key
// in order of first appearance.

namespace material_lanes_detail {
// The maps the lanes read, in BoundMaterial's order: the base colour alone
// for KHR_materials_unlit.
[[gnu::always_inline]] inline void lane_maps(const BoundMaterial& bm, const Texture** maps) {
    const bool unlit = bm.m->unlit;
    const Texture* const all[BoundMaterial::kMaps] = {bm.base_color, bm.metallic_roughness, bm.roughness, bm.metallic,
                                                      bm.normal,     bm.occlusion,          bm.emissive};
    for (int i = 0; i < BoundMaterial::kMaps; ++i) maps[i] = unlit && i != BoundMaterial::kBaseColor ? nullptr : all[i];
}
} // namespace material_lanes_detail

// Fills the first N lanes of mb for the lanes in `live` (the others get
// values nobody reads) and returns the live lanes an alpha MASK discards.
// `plan`: bm's plan_lookups(), or null (or another binding's) to plan here.
#if PRAST_CALLS_AVX512
// sample_material_lanes<16, IsaAvx512>, compiled for AVX-512 alone
// (shading/sample_lanes_avx512.cpp) and called only when the CPU has it.
std::uint32_t sample_material_lanes16_avx512(const BoundMaterial& bm, const SurfaceLanes& s, std::uint32_t live,
                                             MaterialBlock& mb, const LookupPlan* plan);
#endif

template <int N = kBlockLanes, class Isa = IsaDefault>
inline std::uint32_t sample_material_lanes(const BoundMaterial& bm, const SurfaceLanes& s, std::uint32_t live,
                                           MaterialBlock& mb, const LookupPlan* plan = nullptr) {
    using namespace material_lanes_detail;
    static_assert(N % 4 == 0 && N <= kBlockLanes, "whole vectors of lanes");
#if PRAST_CALLS_AVX512
    if constexpr (N == 16 && std::is_same_v<Isa, IsaDefault>) {
        if (use_avx512()) return sample_material_lanes16_avx512(bm, s, live, mb, plan);
    }
#endif
    const Material& m = *bm.m;

    // Look up every bound texture, the components that are used only, as
    // plan_lookups() says: textures of one layout share their level of
    // detail and texel indices (sample_lanes.h), prepared and read
    // together; a texture bound twice (glTF occlusion in R of the
    // metal-roughness map) is read once.
    enum { kBase, kMetalRough, kRough, kMetal, kNormal, kOcclusion, kEmissive, kMaps };
    static_assert(int(kMaps) == int(BoundMaterial::kMaps) && int(kEmissive) == int(BoundMaterial::kEmissive),
                  "the maps in BoundMaterial's order");
    const bool unlit = m.unlit;  // KHR_materials_unlit: the base colour alone is read
    const Texture* maps[kMaps];
    lane_maps(bm, maps);
    const bool mask_mode = m.alpha_mode == AlphaMode::Mask;
    const bool alpha_read = mask_mode || m.alpha_mode == AlphaMode::Blend;
    TexelLanes texel[kMaps];
    const TexelLanes* tl[kMaps];
    if (maps[kBase] || maps[kMetalRough] || maps[kRough] || maps[kMetal] || maps[kNormal] || maps[kOcclusion] ||
        maps[kEmissive]) {
        LookupPlan local;
        if (!plan || plan->bm != &bm) {
            plan_lookups(bm, local);
            plan = &local;
        }
        for (int i = 0; i < kMaps; ++i) tl[i] = &texel[plan->slot[i]];
        std::uint32_t live_quads = 0;
        if (!s.quad) {
            for (int q = 0; q < 4; ++q) live_quads |= std::uint32_t(((live >> (4 * q)) & 0xFu) != 0) << q;
        } else {
            for (int l = 0; l < N; ++l)
                if ((live >> l) & 1u) live_quads |= 1u << s.quad[l];
        }
        const int groups = plan->groups;
        const auto& group_tex = plan->tex;
        const auto& group_used = plan->used;
        const auto& group_key = plan->key;
        const auto& group_size = plan->size;
        TexelLanes* group_out[kMaps][kMaps];
        for (int g = 0; g < groups; ++g)
            for (int k = 0; k < group_size[g]; ++k) group_out[g][k] = &texel[plan->out[g][k]];
        for (int g = 0; g < groups; ++g) {
            // material_lods(): one lambda per quad with a live lane.
            const Texture& first = *group_tex[g][0];
            const int uv_set = group_key[g] / 8;
            const float* dudx = uv_set ? s.dudx_more[uv_set - 1] : s.dudx;
            const float* dvdx = uv_set ? s.dvdx_more[uv_set - 1] : s.dvdx;
            const float* dudy = uv_set ? s.dudy_more[uv_set - 1] : s.dudy;
            const float* dvdy = uv_set ? s.dvdy_more[uv_set - 1] : s.dvdy;
            const float* u = s.u_of(uv_set);
            const float* v = s.v_of(uv_set);
            float lambda[kMaxQuadSlots];
            alignas(64) float tu[N], tv[N];
            if (group_key[g] % 8) {  // KHR_texture_transform: UVs and derivatives as UvTransform's
                const UvTransform& x = bm.xf[group_key[g] % 8 - 1];
                for (int l = 0; l < N; ++l) {
                    tu[l] = x.m00 * u[l] + x.m01 * v[l] + x.ox;
                    tv[l] = x.m10 * u[l] + x.m11 * v[l] + x.oy;
                }
                float ux[kMaxQuadSlots], vx[kMaxQuadSlots], uy[kMaxQuadSlots], vy[kMaxQuadSlots];
                for (int q = 0; q < kMaxQuadSlots; ++q) {
                    ux[q] = x.m00 * dudx[q] + x.m01 * dvdx[q];
                    vx[q] = x.m10 * dudx[q] + x.m11 * dvdx[q];
                    uy[q] = x.m00 * dudy[q] + x.m01 * dvdy[q];
                    vy[q] = x.m10 * dudy[q] + x.m11 * dvdy[q];
                }
                quad_lods<Isa>(first, ux, vx, uy, vy, live_quads, lambda);
                u = tu;
                v = tv;
            } else {
                quad_lods<Isa>(first, dudx, dvdx, dudy, dvdy, live_quads, lambda);
            }
            TrilinearLanes at;
            prepare_trilinear_lanes<N, Isa>(first, u, v, lambda, s.quad, live, at);
            fetch_trilinear_lanes<N, Isa>(group_tex[g], group_size[g], at, group_out[g], group_used[g]);
        }
    }

    // Base colour and alpha: factor times the (already linear) texture.
    const glm::vec4 bf = m.base_color_factor;
    alignas(64) float alpha[N];
    if (maps[kBase]) {
        const TexelLanes& t = *tl[kBase];
        for (int l = 0; l < N; ++l) {
            mb.ar[l] = bf.r * t.r[l]; mb.ag[l] = bf.g * t.g[l]; mb.ab[l] = bf.b * t.b[l];
        }
        if (alpha_read)  // alpha matters only to MASK and BLEND (and is read only then)
            for (int l = 0; l < N; ++l) alpha[l] = bf.a * t.a[l];
        else
            for (int l = 0; l < N; ++l) alpha[l] = bf.a;
    } else {
        for (int l = 0; l < N; ++l) {
            mb.ar[l] = bf.r; mb.ag[l] = bf.g; mb.ab[l] = bf.b;
            alpha[l] = bf.a;
        }
    }
    if (s.Cr) {  // times the vertex colour
        for (int l = 0; l < N; ++l) {
            mb.ar[l] *= s.Cr[l]; mb.ag[l] *= s.Cg[l]; mb.ab[l] *= s.Cb[l];
        }
        if (alpha_read)
            for (int l = 0; l < N; ++l) alpha[l] *= s.Ca[l];
    }
    mb.ior = m.ior;
    mb.unlit = unlit;

    // Metal and roughness: glTF packs them in G and B; OBJ has separate maps (R).
    alignas(64) float metallic[N], roughness[N];
    for (int l = 0; l < N; ++l) {
        metallic[l] = m.metallic_factor;
        roughness[l] = m.roughness_factor;
    }
    if (maps[kMetalRough]) {
        const TexelLanes& t = *tl[kMetalRough];
        for (int l = 0; l < N; ++l) {
            roughness[l] *= t.g[l];
            metallic[l] *= t.b[l];
        }
    }
    if (maps[kRough])
        for (int l = 0; l < N; ++l) roughness[l] *= tl[kRough]->r[l];
    if (maps[kMetal])
        for (int l = 0; l < N; ++l) metallic[l] *= tl[kMetal]->r[l];
    for (int l = 0; l < N; ++l) {
        // glm::clamp(x, 0, 1) = min(max(x, 0), 1), NaN passing through.
        const float mt = metallic[l] < 0.0f ? 0.0f : metallic[l];
        const float rg = roughness[l] < 0.0f ? 0.0f : roughness[l];
        mb.metallic[l] = 1.0f < mt ? 1.0f : mt;
        mb.roughness[l] = 1.0f < rg ? 1.0f : rg;
    }

    if (maps[kOcclusion]) {
        const float strength = m.occlusion_strength;
        for (int l = 0; l < N; ++l) mb.occlusion[l] = 1.0f + strength * (tl[kOcclusion]->r[l] - 1.0f);
    } else {
        for (int l = 0; l < N; ++l) mb.occlusion[l] = 1.0f;
    }
    const glm::vec3 ef = m.emissive_factor;
    if (maps[kEmissive]) {
        const TexelLanes& t = *tl[kEmissive];
        for (int l = 0; l < N; ++l) {
            mb.er[l] = ef.r * t.r[l]; mb.eg[l] = ef.g * t.g[l]; mb.eb[l] = ef.b * t.b[l];
        }
    } else {
        for (int l = 0; l < N; ++l) {
            mb.er[l] = ef.r; mb.eg[l] = ef.g; mb.eb[l] = ef.b;
        }
    }

    // Geometric frame; a back face of a double-sided material flips all of it.
    alignas(64) float Nx[N], Ny[N], Nz[N], zero[N], one[N], flip[N];
    copy_lanes<N, Isa>(Nx, s.Nx); copy_lanes<N, Isa>(Ny, s.Ny); copy_lanes<N, Isa>(Nz, s.Nz);
    fill_lanes<N, Isa>(zero, 0.0f);
    fill_lanes<N, Isa>(one, 1.0f);
    for (int l = 0; l < N; ++l) {
        flip[l] = ((s.back_facing >> l) & 1u) ? -1.0f : 1.0f;
    }
    safe_normalize_lanes<N, Isa>(Nx, Ny, Nz, zero, zero, one);
    for (int l = 0; l < N; ++l) {
        mb.Nx[l] = Nx[l] * flip[l]; mb.Ny[l] = Ny[l] * flip[l]; mb.Nz[l] = Nz[l] * flip[l];
        mb.Gx[l] = mb.Nx[l]; mb.Gy[l] = mb.Ny[l]; mb.Gz[l] = mb.Nz[l];
    }
    if (maps[kNormal]) {
        // Tangent space, OpenGL convention: red along T (+u), green along
        // B = cross(N, T) * w (up the image). T is re-orthogonalised per pixel.
        alignas(64) float Tx[N], Ty[N], Tz[N], ntx[N], nty[N], ntz[N], nx[N], ny[N], nz[N];
        const TexelLanes& tex = *tl[kNormal];
        const float scale = m.normal_scale;
        for (int l = 0; l < N; ++l) {
            const float d = Nx[l] * s.Tx[l] + Ny[l] * s.Ty[l] + Nz[l] * s.Tz[l];
            Tx[l] = s.Tx[l] - Nx[l] * d;
            Ty[l] = s.Ty[l] - Ny[l] * d;
            Tz[l] = s.Tz[l] - Nz[l] * d;
            ntx[l] = (tex.r[l] * 2.0f - 1.0f) * scale;
            nty[l] = (tex.g[l] * 2.0f - 1.0f) * scale;
            ntz[l] = tex.b[l] * 2.0f - 1.0f;
        }
        safe_normalize_lanes<N, Isa>(Tx, Ty, Tz, zero, zero, zero);
        safe_normalize_lanes<N, Isa>(ntx, nty, ntz, zero, zero, one);
        alignas(64) float mapped[N];  // 1 where the tangent frame exists
        for (int l = 0; l < N; ++l) {
            mapped[l] = Tx[l] * Tx[l] + Ty[l] * Ty[l] + Tz[l] * Tz[l] > 0.0f ? 1.0f : 0.0f;
            const float w = s.Tw[l] < 0.0f ? -1.0f : 1.0f;
            const float Bx = (Ny[l] * Tz[l] - Ty[l] * Nz[l]) * w;
            const float By = (Nz[l] * Tx[l] - Tz[l] * Nx[l]) * w;
            const float Bz = (Nx[l] * Ty[l] - Tx[l] * Ny[l]) * w;
            nx[l] = Tx[l] * ntx[l] + Bx * nty[l] + Nx[l] * ntz[l];
            ny[l] = Ty[l] * ntx[l] + By * nty[l] + Ny[l] * ntz[l];
            nz[l] = Tz[l] * ntx[l] + Bz * nty[l] + Nz[l] * ntz[l];
        }
        safe_normalize_lanes<N, Isa>(nx, ny, nz, Nx, Ny, Nz);
        for (int l = 0; l < N; ++l) {
            const bool use = mapped[l] != 0.0f;
            mb.Nx[l] = use ? nx[l] * flip[l] : mb.Nx[l];
            mb.Ny[l] = use ? ny[l] * flip[l] : mb.Ny[l];
            mb.Nz[l] = use ? nz[l] * flip[l] : mb.Nz[l];
        }
    }

    copy_lanes<N, Isa>(mb.Px, s.Px); copy_lanes<N, Isa>(mb.Py, s.Py); copy_lanes<N, Isa>(mb.Pz, s.Pz);

    copy_lanes<N, Isa>(mb.alpha, alpha);

    // Alpha MASK: discard below the cutoff (NaN alpha too).
    std::uint32_t kill = 0;
    if (mask_mode) {
        const float cutoff = m.alpha_cutoff;
        for (int l = 0; l < N; ++l) kill |= std::uint32_t(!(alpha[l] >= cutoff)) << l;
    }
    return kill & live;
}

} // namespace prast

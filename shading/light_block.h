// The lighting sum of shade_surface() for the lanes of a 4x4 block at once (all
// 16, or the first 4 or 8 when the fragment program packs the live lanes of a
// sparse block), in structure-of-arrays form: each step is a loop over lanes
// with no branch (selects only), which the compiler vectorises. Every lane
// performs exactly the float operations of the scalar evaluate_brdf() /
// shade_surface(), in the same order (the build has no FMA contraction), so
// the two paths give bit-identical results: tests/test_light_block.cpp holds
// them to that, and the stepper can explain a pixel with the scalar code.
// Conductor (complex-index) materials are not handled here: the fragment
// program shades them with the scalar path.
#pragma once

#include <cmath>

#include "raster/limits.h"
#include "shading/brdf.h"
#include "shading/shadow_lanes.h"
#include "shading/surface.h"

namespace prast {

struct MaterialBlock {
    static constexpr int N = kBlockLanes;
    alignas(64) float Px[N], Py[N], Pz[N];        // world position
    alignas(64) float Nx[N], Ny[N], Nz[N];        // shading normal (unit)
    alignas(64) float Gx[N], Gy[N], Gz[N];        // geometric normal (unit; for shadow lookups)
    alignas(64) float ar[N], ag[N], ab[N];        // albedo
    alignas(64) float metallic[N], roughness[N], occlusion[N];
    alignas(64) float er[N], eg[N], eb[N];        // emissive
    alignas(64) float alpha[N];                   // base colour alpha (BLEND's coverage; 1 otherwise)
    float ior = 1.5f;                             // per material, uniform
};

struct RadianceBlock {
    alignas(64) float r[kBlockLanes], g[kBlockLanes], b[kBlockLanes];
};

// One light's contribution f * radiance * n.l, added to out, for the first N
// lanes (the fragment program packs the live lanes of a sparse block first).
template <bool Point, bool Gltf, int N = kBlockLanes>
inline void light_lanes(const MaterialBlock& __restrict m, const ShadingLight& L,
                        const float* __restrict vx, const float* __restrict vy, const float* __restrict vz,
                        const float* __restrict F0r, const float* __restrict F0g, const float* __restrict F0b,
                        const float* __restrict alpha, const float* __restrict kdir,
                        RadianceBlock& __restrict out) {
    static_assert(N % 4 == 0 && N <= kBlockLanes, "whole vectors of lanes");
    const float eps = kBrdfMinCos;
    // Uniforms out of the loop, so that it reads only lane arrays.
    const float Lpx = L.position.x, Lpy = L.position.y, Lpz = L.position.z;
    const float Ldx = L.direction.x, Ldy = L.direction.y, Ldz = L.direction.z;
    const float Lr = L.radiance.x, Lg = L.radiance.y, Lb = L.radiance.z;
    // Shadow: light_visibility() per lane, 1 without a map.
    alignas(64) float vis[N];
    if (L.shadow) shadow_visibility_lanes<N>(*L.shadow, m.Px, m.Py, m.Pz, m.Gx, m.Gy, m.Gz, L.direction, vis);
    else for (int l = 0; l < N; ++l) vis[l] = 1.0f;
    for (int l = 0; l < N; ++l) {
        // Light direction and radiance at P (light_at).
        float lx = Ldx, ly = Ldy, lz = Ldz, Rr = Lr, Rg = Lg, Rb = Lb;
        if constexpr (Point) {
            float dx = Lpx - m.Px[l], dy = Lpy - m.Py[l], dz = Lpz - m.Pz[l];
            float d2 = dx * dx + dy * dy + dz * dz;
            bool ok = d2 > 1e-12f;
            float s = std::sqrt(ok ? d2 : 1.0f);
            float dd = ok ? d2 : 1.0f;
            lx = ok ? dx / s : 0.0f;
            ly = ok ? dy / s : 0.0f;
            lz = ok ? dz / s : 1.0f;
            Rr = ok ? Lr / dd : 0.0f;
            Rg = ok ? Lg / dd : 0.0f;
            Rb = ok ? Lb / dd : 0.0f;
        }
        Rr *= vis[l]; Rg *= vis[l]; Rb *= vis[l];
        // Cosines and h.
        float hx = lx + vx[l], hy = ly + vy[l], hz = lz + vz[l];
        float hl2 = hx * hx + hy * hy + hz * hz;
        bool hok = hl2 > 0.0f;
        float hs = std::sqrt(hok ? hl2 : 1.0f);
        hx = hok ? hx / hs : m.Nx[l];
        hy = hok ? hy / hs : m.Ny[l];
        hz = hok ? hz / hs : m.Nz[l];
        auto clamp01 = [](float x) { x = x < 0.0f ? 0.0f : x; return x > 1.0f ? 1.0f : x; };
        float NoL = clamp01(m.Nx[l] * lx + m.Ny[l] * ly + m.Nz[l] * lz);
        float NoV = clamp01(m.Nx[l] * vx[l] + m.Ny[l] * vy[l] + m.Nz[l] * vz[l]);
        float NoH = clamp01(m.Nx[l] * hx + m.Ny[l] * hy + m.Nz[l] * hz);
        float VoH = clamp01(vx[l] * hx + vy[l] * hy + vz[l] * hz);
        // F (Schlick), D, G or V.
        float fc = brdf_detail::pow5(1.0f - (VoH < 0.0f ? 0.0f : VoH));
        float Fr = F0r[l] + (1.0f - F0r[l]) * fc;
        float Fg = F0g[l] + (1.0f - F0g[l]) * fc;
        float Fb = F0b[l] + (1.0f - F0b[l]) * fc;
        float D = D_GGX(NoH, alpha[l]);
        float Sr, Sg, Sb;
        if constexpr (Gltf) {
            float V = V_SmithGGXCorrelated(NoV, NoL, alpha[l]);
            Sr = Fr * D * V; Sg = Fg * D * V; Sb = Fb * D * V;
        } else {
            float G = G_Smith(NoV, NoL, kdir[l]);
            float DG = D * G;
            float den = 4.0f * (NoV > eps ? NoV : eps) * (NoL > eps ? NoL : eps);
            Sr = DG * Fr / den; Sg = DG * Fg / den; Sb = DG * Fb / den;
        }
        // Diffuse, and the sum f * radiance * n.l.
        float km = 1.0f - m.metallic[l];
        const float inv_pi = Fd_Lambert();
        float fr = (1.0f - Fr) * km * m.ar[l] * inv_pi + Sr;
        float fg = (1.0f - Fg) * km * m.ag[l] * inv_pi + Sg;
        float fb = (1.0f - Fb) * km * m.ab[l] * inv_pi + Sb;
        out.r[l] += fr * Rr * NoL;
        out.g[l] += fg * Rg * NoL;
        out.b[l] += fb * Rb * NoL;
    }
}

// shade_surface() for the first N lanes of m.
template <int N = kBlockLanes>
inline void shade_block_lanes(const MaterialBlock& __restrict m, const ShadingContext& ctx,
                              RadianceBlock& __restrict out) {
    static_assert(N % 4 == 0 && N <= kBlockLanes, "whole vectors of lanes");
    const bool gltf = ctx.model == BrdfModel::Gltf;
    alignas(64) float vx[N], vy[N], vz[N], F0r[N], F0g[N], F0b[N], alpha[N], kdir[N];
    const float f0 = f0_from_ior(m.ior);
    // Uniforms out of the loops, so that they read only lane arrays.
    const float ex = ctx.eye.x, ey = ctx.eye.y, ez = ctx.eye.z;
    const float amb_r = ctx.ambient.x, amb_g = ctx.ambient.y, amb_b = ctx.ambient.z;

    // View direction (safe_normalize with the normal as fallback), F0, alpha, k.
    for (int l = 0; l < N; ++l) {
        float dx = ex - m.Px[l], dy = ey - m.Py[l], dz = ez - m.Pz[l];
        float len2 = dx * dx + dy * dy + dz * dz;
        bool ok = (len2 > 1e-20f) & (len2 <= 3.402823466e38f);
        float s = std::sqrt(ok ? len2 : 1.0f);
        vx[l] = ok ? dx / s : m.Nx[l];
        vy[l] = ok ? dy / s : m.Ny[l];
        vz[l] = ok ? dz / s : m.Nz[l];
        float mt = m.metallic[l];
        F0r[l] = f0 * (1.0f - mt) + m.ar[l] * mt;
        F0g[l] = f0 * (1.0f - mt) + m.ag[l] * mt;
        F0b[l] = f0 * (1.0f - mt) + m.ab[l] * mt;
        float rr = m.roughness[l];
        rr = rr < kMinPerceptualRoughness ? kMinPerceptualRoughness : rr;
        rr = rr > 1.0f ? 1.0f : rr;
        alpha[l] = rr * rr;
        float r1 = rr + 1.0f;
        kdir[l] = r1 * r1 * 0.125f;
        out.r[l] = m.er[l];
        out.g[l] = m.eg[l];
        out.b[l] = m.eb[l];
    }

    for (const ShadingLight& L : ctx.lights) {
        if (L.point) {
            if (gltf) light_lanes<true, true, N>(m, L, vx, vy, vz, F0r, F0g, F0b, alpha, kdir, out);
            else light_lanes<true, false, N>(m, L, vx, vy, vz, F0r, F0g, F0b, alpha, kdir, out);
        } else {
            if (gltf) light_lanes<false, true, N>(m, L, vx, vy, vz, F0r, F0g, F0b, alpha, kdir, out);
            else light_lanes<false, false, N>(m, L, vx, vy, vz, F0r, F0g, F0b, alpha, kdir, out);
        }
    }
    for (int l = 0; l < N; ++l) {
        out.r[l] += amb_r * m.ar[l] * m.occlusion[l];
        out.g[l] += amb_g * m.ag[l] * m.occlusion[l];
        out.b[l] += amb_b * m.ab[l] * m.occlusion[l];
    }
}

} // namespace prast

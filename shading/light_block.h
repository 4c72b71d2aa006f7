// The lighting sum of shade_surface() for the 16 lanes of a 4x4 block at once,
// in structure-of-arrays form: each step is a loop over lanes with no branch
// (selects only), which the compiler vectorises. Every lane performs exactly
// the float operations of the scalar evaluate_brdf()/shade_surface(), in the
// same order (the build has no FMA contraction), so the two paths give
// bit-identical results: tests/test_light_block.cpp holds them to that, and
// the stepper can explain a pixel with the scalar code.
// Conductor (complex-index) materials are not handled here: the fragment
// program shades them with the scalar path.
#pragma once

#include <cmath>

#include "raster/limits.h"
#include "shading/brdf.h"
#include "shading/surface.h"

namespace prast {

struct MaterialBlock {
    static constexpr int N = kBlockLanes;
    alignas(64) float Px[N], Py[N], Pz[N];        // world position
    alignas(64) float Nx[N], Ny[N], Nz[N];        // shading normal (unit)
    alignas(64) float ar[N], ag[N], ab[N];        // albedo
    alignas(64) float metallic[N], roughness[N], occlusion[N];
    alignas(64) float er[N], eg[N], eb[N];        // emissive
    float ior = 1.5f;                             // per material, uniform
};

struct RadianceBlock {
    alignas(64) float r[kBlockLanes], g[kBlockLanes], b[kBlockLanes];
};

// One light's contribution f * radiance * n.l, added to out.
template <bool Point, bool Gltf>
inline void light_lanes(const MaterialBlock& __restrict m, const ShadingLight& L,
                        const float* __restrict vx, const float* __restrict vy, const float* __restrict vz,
                        const float* __restrict F0r, const float* __restrict F0g, const float* __restrict F0b,
                        const float* __restrict alpha, const float* __restrict kdir,
                        RadianceBlock& __restrict out) {
    constexpr int N = kBlockLanes;
    const float eps = kBrdfMinCos;
    // Uniforms out of the loop, so that it reads only lane arrays.
    const float Lpx = L.position.x, Lpy = L.position.y, Lpz = L.position.z;
    const float Ldx = L.direction.x, Ldy = L.direction.y, Ldz = L.direction.z;
    const float Lr = L.radiance.x, Lg = L.radiance.y, Lb = L.radiance.z;
    // Light direction and radiance at P (light_at).
    alignas(64) float Lx[N], Ly[N], Lz[N], Rr_[N], Rg_[N], Rb_[N];
    for (int l = 0; l < N; ++l) {
        if constexpr (Point) {
            float dx = Lpx - m.Px[l], dy = Lpy - m.Py[l], dz = Lpz - m.Pz[l];
            float d2 = dx * dx + dy * dy + dz * dz;
            bool ok = d2 > 1e-12f;
            float s = std::sqrt(ok ? d2 : 1.0f);
            float dd = ok ? d2 : 1.0f;
            Lx[l] = ok ? dx / s : 0.0f;
            Ly[l] = ok ? dy / s : 0.0f;
            Lz[l] = ok ? dz / s : 1.0f;
            Rr_[l] = ok ? Lr / dd : 0.0f;
            Rg_[l] = ok ? Lg / dd : 0.0f;
            Rb_[l] = ok ? Lb / dd : 0.0f;
        } else {
            Lx[l] = Ldx; Ly[l] = Ldy; Lz[l] = Ldz;
            Rr_[l] = Lr; Rg_[l] = Lg; Rb_[l] = Lb;
        }
    }
    for (int l = 0; l < N; ++l) {
        const float lx = Lx[l], ly = Ly[l], lz = Lz[l], Rr = Rr_[l], Rg = Rg_[l], Rb = Rb_[l];
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

inline void shade_block_lanes(const MaterialBlock& m, const ShadingContext& ctx, RadianceBlock& out) {
    constexpr int N = kBlockLanes;
    const bool gltf = ctx.model == BrdfModel::Gltf;
    alignas(64) float vx[N], vy[N], vz[N], F0r[N], F0g[N], F0b[N], alpha[N], kdir[N];
    const float f0 = f0_from_ior(m.ior);

    // View direction (safe_normalize with the normal as fallback), F0, alpha, k.
    for (int l = 0; l < N; ++l) {
        float dx = ctx.eye.x - m.Px[l], dy = ctx.eye.y - m.Py[l], dz = ctx.eye.z - m.Pz[l];
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
            if (gltf) light_lanes<true, true>(m, L, vx, vy, vz, F0r, F0g, F0b, alpha, kdir, out);
            else light_lanes<true, false>(m, L, vx, vy, vz, F0r, F0g, F0b, alpha, kdir, out);
        } else {
            if (gltf) light_lanes<false, true>(m, L, vx, vy, vz, F0r, F0g, F0b, alpha, kdir, out);
            else light_lanes<false, false>(m, L, vx, vy, vz, F0r, F0g, F0b, alpha, kdir, out);
        }
    }
    for (int l = 0; l < N; ++l) {
        out.r[l] += ctx.ambient.x * m.ar[l] * m.occlusion[l];
        out.g[l] += ctx.ambient.y * m.ag[l] * m.occlusion[l];
        out.b[l] += ctx.ambient.z * m.ab[l] * m.occlusion[l];
    }
}

} // namespace prast

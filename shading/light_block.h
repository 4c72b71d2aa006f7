// The lighting sum of shade_surface() for the lanes of a 4x4 block at once (all
// 16, or the first 4 or 8 when the fragment program packs the live lanes of a
// sparse block), in structure-of-arrays form: each step is a loop over lanes
// with no branch (selects only), which the compiler vectorises. Every lane
// performs exactly the float operations of the scalar evaluate_brdf() /
// shade_surface(), in the same order (the build has no FMA contraction), so
// the two paths give bit-identical results: tests/test_light_block.cpp holds
// them to that, and the stepper can explain a pixel with the scalar code.
// With an environment map the split sum of ibl_terms() replaces the ambient
// term (ibl_lanes), and --energy conserve scales the lights' lobes as
// apply_energy_terms() does (energy_lanes). Conductor (complex-index)
// materials and the reference integrator are not handled here: the fragment
// program shades them with the scalar path.
#pragma once

#include <cmath>
#include <type_traits>

#include "raster/limits.h"
#include "shading/brdf.h"
#include "shading/isa.h"
#include "shading/shadow/shadow_lanes.h"
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
    bool unlit = false;                           // KHR_materials_unlit: the albedo is the radiance
};

struct RadianceBlock {
    alignas(64) float r[kBlockLanes], g[kBlockLanes], b[kBlockLanes];
};

// Per-lane view direction, the shading normal facing it (facing_normal()),
// F0, alpha and k, computed once per block.
struct ViewLanes {
    static constexpr int N = kBlockLanes;
    alignas(64) float vx[N], vy[N], vz[N], Nx[N], Ny[N], Nz[N], F0r[N], F0g[N], F0b[N], alpha[N], kdir[N], rough[N];
};

// --energy conserve factors of apply_energy_terms(), per lane and channel.
struct EnergyLanes {
    static constexpr int N = kBlockLanes;
    alignas(64) float comp_r[N], comp_g[N], comp_b[N], kd_r[N], kd_g[N], kd_b[N];
};

namespace light_block_detail {

[[gnu::always_inline]] inline float clamp01(float x) {
    x = x < 0.0f ? 0.0f : x;
    return x > 1.0f ? 1.0f : x;
}

// glm::clamp(x, kMinNoV, 1): the n.v the DFG tables are read at.
[[gnu::always_inline]] inline float clamp_nov(float x) {
    x = x < kMinNoV ? kMinNoV : x;
    return x > 1.0f ? 1.0f : x;
}

// DfgTable::lookup() for the first N lanes at (NoV, rough): taps in a
// vectorised loop, then one 4-channel bilinear per lane.
template <int N, class Isa = IsaDefault>
inline void dfg_lanes(const DfgTable& table, const float* __restrict NoV, const float* __restrict rough,
                      float* __restrict A, float* __restrict B, float* __restrict Kd) {
    alignas(64) std::int32_t idx[4][N];
    alignas(64) float tx[N], ty[N];
    for (int l = 0; l < N; ++l) {
        std::int32_t i4[4];
        dfg_taps(NoV[l], rough[l], i4, tx[l], ty[l]);
        idx[0][l] = i4[0]; idx[1][l] = i4[1]; idx[2][l] = i4[2]; idx[3][l] = i4[3];
    }
    const glm::vec4* texels = table.texels();
    for (int l = 0; l < N; ++l) {
        const std::int32_t i4[4] = {idx[0][l], idx[1][l], idx[2][l], idx[3][l]};
        const Texel4 c = bilinear4(texels, i4, tx[l], ty[l]);
        A[l] = c[0]; B[l] = c[1]; Kd[l] = c[2];
    }
}

} // namespace light_block_detail

// apply_energy_terms() for the first N lanes, from a DFG table.
template <int N = kBlockLanes, class Isa = IsaDefault>
inline void energy_lanes(const MaterialBlock& __restrict m, const ViewLanes& __restrict w, const DfgTable& table,
                         EnergyLanes& __restrict e) {
    using light_block_detail::clamp01;
    alignas(64) float NoV[N], A[N], B[N], Kd[N];
    for (int l = 0; l < N; ++l)
        NoV[l] = light_block_detail::clamp_nov(w.Nx[l] * w.vx[l] + w.Ny[l] * w.vy[l] + w.Nz[l] * w.vz[l]);
    light_block_detail::dfg_lanes<N, Isa>(table, NoV, w.rough, A, B, Kd);
    for (int l = 0; l < N; ++l) {
        const float km = 1.0f - m.metallic[l];
        e.comp_r[l] = energy_compensation(w.F0r[l], A[l], B[l]);
        e.comp_g[l] = energy_compensation(w.F0g[l], A[l], B[l]);
        e.comp_b[l] = energy_compensation(w.F0b[l], A[l], B[l]);
        e.kd_r[l] = (1.0f - (w.F0r[l] * A[l] + B[l]) * e.comp_r[l]) * km;
        e.kd_g[l] = (1.0f - (w.F0g[l] * A[l] + B[l]) * e.comp_g[l]) * km;
        e.kd_b[l] = (1.0f - (w.F0b[l] * A[l] + B[l]) * e.comp_b[l]) * km;
    }
}

// One light's contribution f * radiance * n.l, added to out, for the first N
// lanes (the fragment program packs the live lanes of a sparse block first).
// Shaped: a point light with a spot cone or a range (light_falloff()).
template <bool Point, bool Gltf, bool Energy, bool Shaped, int N = kBlockLanes, class Isa = IsaDefault>
inline void light_lanes(const MaterialBlock& __restrict m, const ShadingLight& L, const ViewLanes& __restrict w,
                        const EnergyLanes& __restrict e, RadianceBlock& __restrict out) {
    const float* __restrict vx = w.vx;
    const float* __restrict vy = w.vy;
    const float* __restrict vz = w.vz;
    const float* __restrict F0r = w.F0r;
    const float* __restrict F0g = w.F0g;
    const float* __restrict F0b = w.F0b;
    const float* __restrict alpha = w.alpha;
    const float* __restrict kdir = w.kdir;
    static_assert(N % 4 == 0 && N <= kBlockLanes, "whole vectors of lanes");
    const float eps = kBrdfMinCos;
    // Uniforms out of the loop, so that it reads only lane arrays.
    const float Lpx = L.position.x, Lpy = L.position.y, Lpz = L.position.z;
    const float Ldx = L.direction.x, Ldy = L.direction.y, Ldz = L.direction.z;
    const float Lr = L.radiance.x, Lg = L.radiance.y, Lb = L.radiance.z;
    const bool range_on = L.range_inv2 > 0.0f, spot_on = L.spot;
    const float range_inv2 = L.range_inv2, cone_scale = L.cone_scale, cone_offset = L.cone_offset;
    (void)range_on; (void)spot_on; (void)range_inv2; (void)cone_scale; (void)cone_offset;
    // Shadow: light_visibility() per lane, 1 without a map.
    alignas(64) float vis[N];
    if (L.shadow) shadow_visibility_lanes<N, Isa>(*L.shadow, m.Px, m.Py, m.Pz, m.Gx, m.Gy, m.Gz, L.direction, vis);
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
            if constexpr (Shaped) {  // light_falloff(): the range window, then the spot cone
                float att = 1.0f;
                if (range_on) {
                    const float q = d2 * range_inv2;
                    const float wnd = 1.0f - q * q;
                    att = wnd < 0.0f ? 0.0f : (wnd > 1.0f ? 1.0f : wnd);
                }
                if (spot_on) {
                    const float cd = lx * Ldx + ly * Ldy + lz * Ldz;
                    float a = cd * cone_scale + cone_offset;
                    a = a < 0.0f ? 0.0f : (a > 1.0f ? 1.0f : a);
                    att = att * (a * a);
                }
                Rr *= att; Rg *= att; Rb *= att;
            }
        }
        Rr *= vis[l]; Rg *= vis[l]; Rb *= vis[l];
        // Cosines and h.
        float hx = lx + vx[l], hy = ly + vy[l], hz = lz + vz[l];
        float hl2 = hx * hx + hy * hy + hz * hz;
        bool hok = hl2 > 0.0f;
        float hs = std::sqrt(hok ? hl2 : 1.0f);
        hx = hok ? hx / hs : w.Nx[l];
        hy = hok ? hy / hs : w.Ny[l];
        hz = hok ? hz / hs : w.Nz[l];
        auto clamp01 = [](float x) { x = x < 0.0f ? 0.0f : x; return x > 1.0f ? 1.0f : x; };
        float NoL = clamp01(w.Nx[l] * lx + w.Ny[l] * ly + w.Nz[l] * lz);
        float NoV = clamp01(w.Nx[l] * vx[l] + w.Ny[l] * vy[l] + w.Nz[l] * vz[l]);
        float NoH = clamp01(w.Nx[l] * hx + w.Ny[l] * hy + w.Nz[l] * hz);
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
        float fr, fg, fb;
        if constexpr (Energy) {
            Sr = Sr * e.comp_r[l]; Sg = Sg * e.comp_g[l]; Sb = Sb * e.comp_b[l];
            fr = e.kd_r[l] * m.ar[l] * inv_pi + Sr;
            fg = e.kd_g[l] * m.ag[l] * inv_pi + Sg;
            fb = e.kd_b[l] * m.ab[l] * inv_pi + Sb;
        } else {
            (void)e;
            fr = (1.0f - Fr) * km * m.ar[l] * inv_pi + Sr;
            fg = (1.0f - Fg) * km * m.ag[l] * inv_pi + Sg;
            fb = (1.0f - Fb) * km * m.ab[l] * inv_pi + Sb;
        }
        out.r[l] += fr * Rr * NoL;
        out.g[l] += fg * Rg * NoL;
        out.b[l] += fb * Rb * NoL;
    }
}

// ibl_terms() for the first N lanes, added to out: the taps of the prefiltered
// map, the DFG table and the SH in vectorised loops, then the texel reads lane
// by lane, then the sums.
template <int N = kBlockLanes, class Isa = IsaDefault>
inline void ibl_lanes(const MaterialBlock& __restrict m, const ViewLanes& __restrict w, const ShadingContext& ctx,
                      RadianceBlock& __restrict out) {
    using light_block_detail::clamp01;
    const Environment& env = *ctx.env;
    const float rc = env.rot_cos(), rs = env.rot_sin();
    alignas(64) float NoV[N], Ry[N], mx[N], mz[N], t[N], u[N], v[N];
    alignas(64) std::int32_t la[N], lb[N];
    // Reflection direction, its map direction and (u, v); the level pair.
    for (int l = 0; l < N; ++l) {
        const float d = w.Nx[l] * w.vx[l] + w.Ny[l] * w.vy[l] + w.Nz[l] * w.vz[l];
        NoV[l] = light_block_detail::clamp_nov(d);
        const float d2 = 2.0f * d;
        const float Mx = w.Nx[l] * d2 - w.vx[l], My = w.Ny[l] * d2 - w.vy[l], Mz = w.Nz[l] * d2 - w.vz[l];
        // Bent towards n with roughness (ibl_terms()).
        const float a = w.rough[l] * w.rough[l];
        const float f = a * a;
        const float rf = 1.0f - f;
        const float Rx = Mx * rf + w.Nx[l] * f, Rz = Mz * rf + w.Nz[l] * f;
        Ry[l] = My * rf + w.Ny[l] * f;
        mx[l] = Rx * rc - Rz * rs;
        mz[l] = Rx * rs + Rz * rc;
        // prefiltered_taps(): the level pair and t.
        constexpr float kTop = float(Environment::kSpecularLevels - 1);
        float x = Environment::roughness_lod(w.rough[l]);
        x = x > 0.0f ? x : 0.0f;
        x = x < kTop ? x : kTop;
        la[l] = std::int32_t(x);
        lb[l] = la[l] + 1 < Environment::kSpecularLevels ? la[l] + 1 : la[l];
        t[l] = x - float(la[l]);
        equirect_uv(mx[l], Ry[l], mz[l], u[l], v[l]);
    }
    // Level sizes per lane (a table read), then the bilinear taps of both levels.
    alignas(64) std::int32_t wa[N], ha[N], oa[N], wb[N], hb[N], ob[N];
    alignas(64) float fwa[N], fha[N], fwb[N], fhb[N];
    for (int l = 0; l < N; ++l) {
        const EquirectLevel& A = env.specular_level(la[l]);
        const EquirectLevel& B = env.specular_level(lb[l]);
        wa[l] = A.w; ha[l] = A.h; oa[l] = A.offset; fwa[l] = A.fw; fha[l] = A.fh;
        wb[l] = B.w; hb[l] = B.h; ob[l] = B.offset; fwb[l] = B.fw; fhb[l] = B.fh;
    }
    alignas(64) std::int32_t ia[4][N], ib[4][N];
    alignas(64) float txa[N], tya[N], txb[N], tyb[N];
    for (int l = 0; l < N; ++l) {
        std::int32_t i4[4], j4[4];
        equirect_taps(u[l], v[l], wa[l], ha[l], oa[l], fwa[l], fha[l], i4, txa[l], tya[l]);
        equirect_taps(u[l], v[l], wb[l], hb[l], ob[l], fwb[l], fhb[l], j4, txb[l], tyb[l]);
        ia[0][l] = i4[0]; ia[1][l] = i4[1]; ia[2][l] = i4[2]; ia[3][l] = i4[3];
        ib[0][l] = j4[0]; ib[1][l] = j4[1]; ib[2][l] = j4[2]; ib[3][l] = j4[3];
    }
    // Diffuse irradiance E(n) / pi from the SH, clamped to >= 0.
    alignas(64) float Er[N], Eg[N], Eb[N];
    const ShIrradiance& sh = env.sh();
    for (int l = 0; l < N; ++l) {
        const float er = sh_irradiance_eval(&sh.c[0][0], w.Nx[l], w.Ny[l], w.Nz[l]);
        const float eg = sh_irradiance_eval(&sh.c[0][1], w.Nx[l], w.Ny[l], w.Nz[l]);
        const float eb = sh_irradiance_eval(&sh.c[0][2], w.Nx[l], w.Ny[l], w.Nz[l]);
        Er[l] = er > 0.0f ? er : 0.0f;
        Eg[l] = eg > 0.0f ? eg : 0.0f;
        Eb[l] = eb > 0.0f ? eb : 0.0f;
    }
    // Texel reads: the prefiltered radiance, and the DFG texel.
    alignas(64) float Pr[N], Pg[N], Pb[N], A[N], B[N], Kd[N];
    const glm::vec4* texels = env.texels();
    for (int l = 0; l < N; ++l) {
        const std::int32_t i4[4] = {ia[0][l], ia[1][l], ia[2][l], ia[3][l]};
        const std::int32_t j4[4] = {ib[0][l], ib[1][l], ib[2][l], ib[3][l]};
        const Texel4 a = bilinear4(texels, i4, txa[l], tya[l]);
        const Texel4 b = bilinear4(texels, j4, txb[l], tyb[l]);
        const Texel4 c = a + (b - a) * t[l];
        Pr[l] = c[0]; Pg[l] = c[1]; Pb[l] = c[2];
    }
    light_block_detail::dfg_lanes<N, Isa>(*ctx.dfg_ibl, NoV, w.rough, A, B, Kd);
    // The lobes' weights: specular albedo and kd (the branch outside the loops).
    alignas(64) float sr[N], sg[N], sb[N], kr[N], kg[N], kb[N];
    if (ctx.energy) {
        for (int l = 0; l < N; ++l) {
            const float km = 1.0f - m.metallic[l];
            const float cr = energy_compensation(w.F0r[l], A[l], B[l]);
            const float cg = energy_compensation(w.F0g[l], A[l], B[l]);
            const float cb = energy_compensation(w.F0b[l], A[l], B[l]);
            sr[l] = (w.F0r[l] * A[l] + B[l]) * cr;
            sg[l] = (w.F0g[l] * A[l] + B[l]) * cg;
            sb[l] = (w.F0b[l] * A[l] + B[l]) * cb;
            kr[l] = (1.0f - sr[l]) * km; kg[l] = (1.0f - sg[l]) * km; kb[l] = (1.0f - sb[l]) * km;
        }
    } else {
        for (int l = 0; l < N; ++l) {
            const float km = 1.0f - m.metallic[l];
            sr[l] = w.F0r[l] * A[l] + B[l];
            sg[l] = w.F0g[l] * A[l] + B[l];
            sb[l] = w.F0b[l] * A[l] + B[l];
            kr[l] = (1.0f - w.F0r[l]) * Kd[l] * km;
            kg[l] = (1.0f - w.F0g[l]) * Kd[l] * km;
            kb[l] = (1.0f - w.F0b[l]) * Kd[l] * km;
        }
    }
    // The two lobes, times occlusion.
    for (int l = 0; l < N; ++l) {
        const float occ = m.occlusion[l];
        const float dr = kr[l] * m.ar[l] * Er[l] * occ, dg = kg[l] * m.ag[l] * Eg[l] * occ;
        const float db = kb[l] * m.ab[l] * Eb[l] * occ;
        const float spr = sr[l] * Pr[l] * occ, spg = sg[l] * Pg[l] * occ, spb = sb[l] * Pb[l] * occ;
        out.r[l] += dr + spr;
        out.g[l] += dg + spg;
        out.b[l] += db + spb;
    }
}

#if PRAST_CALLS_AVX512
// shade_block_lanes<16, IsaAvx512>, compiled for AVX-512 alone
// (shading/sample_lanes_avx512.cpp) and called only when the CPU has it.
void shade_block_lanes16_avx512(const MaterialBlock& m, const ShadingContext& ctx, RadianceBlock& out);
#endif

// shade_surface() for the first N lanes of m.
template <int N = kBlockLanes, class Isa = IsaDefault>
inline void shade_block_lanes(const MaterialBlock& __restrict m, const ShadingContext& ctx,
                              RadianceBlock& __restrict out) {
    static_assert(N % 4 == 0 && N <= kBlockLanes, "whole vectors of lanes");
#if PRAST_CALLS_AVX512
    if constexpr (N == 16 && std::is_same_v<Isa, IsaDefault>) {
        if (use_avx512()) {
            shade_block_lanes16_avx512(m, ctx, out);
            return;
        }
    }
#endif
    if (m.unlit) {  // KHR_materials_unlit (shade_surface()): the base colour term alone
        for (int l = 0; l < N; ++l) {
            out.r[l] = m.ar[l];
            out.g[l] = m.ag[l];
            out.b[l] = m.ab[l];
        }
        return;
    }
    const bool gltf = ctx.model == BrdfModel::Gltf;
    ViewLanes w;
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
        w.vx[l] = ok ? dx / s : m.Nx[l];
        w.vy[l] = ok ? dy / s : m.Ny[l];
        w.vz[l] = ok ? dz / s : m.Nz[l];
        // facing_normal(): bent towards v where it faces away.
        const float d = m.Nx[l] * w.vx[l] + m.Ny[l] * w.vy[l] + m.Nz[l] * w.vz[l];
        const bool bend = d < kMinNoV;
        const float k = kMinNoV - d;
        const float bx = m.Nx[l] + w.vx[l] * k, by = m.Ny[l] + w.vy[l] * k, bz = m.Nz[l] + w.vz[l] * k;
        const float bl = std::sqrt(bend ? bx * bx + by * by + bz * bz : 1.0f);
        w.Nx[l] = bend ? bx / bl : m.Nx[l];
        w.Ny[l] = bend ? by / bl : m.Ny[l];
        w.Nz[l] = bend ? bz / bl : m.Nz[l];
        float mt = m.metallic[l];
        w.F0r[l] = f0 * (1.0f - mt) + m.ar[l] * mt;
        w.F0g[l] = f0 * (1.0f - mt) + m.ag[l] * mt;
        w.F0b[l] = f0 * (1.0f - mt) + m.ab[l] * mt;
        float rr = m.roughness[l];
        rr = rr < kMinPerceptualRoughness ? kMinPerceptualRoughness : rr;
        rr = rr > 1.0f ? 1.0f : rr;
        w.rough[l] = rr;
        w.alpha[l] = rr * rr;
        float r1 = rr + 1.0f;
        w.kdir[l] = r1 * r1 * 0.125f;
        out.r[l] = m.er[l];
        out.g[l] = m.eg[l];
        out.b[l] = m.eb[l];
    }

    EnergyLanes e;
    const bool energy = ctx.energy && ctx.dfg_light && !ctx.lights.empty();
    if (energy) energy_lanes<N, Isa>(m, w, *ctx.dfg_light, e);
    for (const ShadingLight& L : ctx.lights) {
        if (energy) {
            if (L.shaped()) {
                if (gltf) light_lanes<true, true, true, true, N, Isa>(m, L, w, e, out);
                else light_lanes<true, false, true, true, N, Isa>(m, L, w, e, out);
            } else if (L.point) {
                if (gltf) light_lanes<true, true, true, false, N, Isa>(m, L, w, e, out);
                else light_lanes<true, false, true, false, N, Isa>(m, L, w, e, out);
            } else {
                if (gltf) light_lanes<false, true, true, false, N, Isa>(m, L, w, e, out);
                else light_lanes<false, false, true, false, N, Isa>(m, L, w, e, out);
            }
        } else if (L.shaped()) {
            if (gltf) light_lanes<true, true, false, true, N, Isa>(m, L, w, e, out);
            else light_lanes<true, false, false, true, N, Isa>(m, L, w, e, out);
        } else if (L.point) {
            if (gltf) light_lanes<true, true, false, false, N, Isa>(m, L, w, e, out);
            else light_lanes<true, false, false, false, N, Isa>(m, L, w, e, out);
        } else {
            if (gltf) light_lanes<false, true, false, false, N, Isa>(m, L, w, e, out);
            else light_lanes<false, false, false, false, N, Isa>(m, L, w, e, out);
        }
    }
    if (ctx.env) {
        ibl_lanes<N, Isa>(m, w, ctx, out);
        return;
    }
    for (int l = 0; l < N; ++l) {
        out.r[l] += amb_r * m.ar[l] * m.occlusion[l];
        out.g[l] += amb_g * m.ag[l] * m.occlusion[l];
        out.b[l] += amb_b * m.ab[l] * m.occlusion[l];
    }
}

} // namespace prast

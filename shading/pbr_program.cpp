// The PBR fragment stage; see pbr_program.h. One call per 4x4 block. The lit
// image takes the 16-lane path (shade_lanes); debug views and conductor
// materials loop over the lanes with the scalar sample_material() and
// shade_surface() inlined, the functions the stepper explains pixels with.
#include "shading/pbr_program.h"

#include "shading/light_block.h"
#include "shading/material_lanes.h"

#include <algorithm>
#include <cmath>

#if defined(__AVX2__)
#include <immintrin.h>
#endif

namespace prast {

namespace {

glm::vec3 sum_lobes(const MaterialSample& ms, const SurfacePoint& sp, const ShadingContext& ctx,
                    bool specular) {
    BrdfInputs bi = brdf_inputs(ms, sp, ctx);
    glm::vec3 sum(0.0f);
    for (const ShadingLight& L : ctx.lights) {
        glm::vec3 radiance;
        light_at(L, sp.P, bi.l, radiance);
        BrdfTerms t = evaluate_brdf(bi, ctx.model);
        sum += (specular ? t.specular : t.diffuse) * radiance * t.NoL;
    }
    // The split sum's lobe of the environment (not in reference mode: the
    // integral does not split into lobes).
    if (ctx.env && ctx.ibl == IblMode::SplitSum) {
        const IblTerms t = ibl_terms(ms, sp, ctx);
        sum += specular ? t.specular : t.diffuse;
    }
    return sum;
}

BrdfTerms first_light_terms(const MaterialSample& ms, const SurfacePoint& sp, const ShadingContext& ctx) {
    BrdfInputs bi = brdf_inputs(ms, sp, ctx);
    if (ctx.lights.empty()) return BrdfTerms{};
    glm::vec3 radiance;
    light_at(ctx.lights[0], sp.P, bi.l, radiance);
    return evaluate_brdf(bi, ctx.model);
}

} // namespace

// The lit path (material_lanes.h, then light_block.h) for a block's live
// lanes, either in place (N = 16) or packed into the first N = 4 or 8 lanes:
// half the blocks of a typical frame have at most 4 live lanes (small
// triangles, edges), and a lane costs the same whether live or not. Each lane
// does the float operations of sample_material() and shade_surface().
template <int N>
void PbrProgram::shade_lanes(const FragmentBlock<kVaryings>& in, FragmentOut& out) const {
    SurfaceLanes s;
    const float* var[kVaryings];
    std::uint32_t live = in.mask;
    // Packed lane i holds block lane lane[i], of quad quad[i]; the spare
    // packed lanes repeat the first live lane (valid inputs, results dropped).
    std::uint8_t lane[N] = {}, quad[N] = {};
    alignas(64) float packed[kVaryings][N];
    if constexpr (N == kBlockLanes) {
        for (int k = 0; k < kVaryings; ++k) var[k] = in.var[k];
    } else {
        static_assert(N == 4 || N == 8, "packed blocks have 4 or 8 lanes");
        int n = 0;
        for (std::uint32_t m = in.mask; m && n < N; m &= m - 1) lane[n++] = std::uint8_t(__builtin_ctz(m));
        live = (1u << n) - 1u;
        for (int l = n; l < N; ++l) lane[l] = lane[0];
        for (int l = 0; l < N; ++l) quad[l] = std::uint8_t(lane[l] >> 2);
#if defined(__AVX2__)
        // Each varying: both halves permuted, then blended.
        alignas(32) std::int32_t index[8];
        for (int l = 0; l < 8; ++l) index[l] = lane[l < N ? l : 0];
        const __m256i idx = _mm256_load_si256(reinterpret_cast<const __m256i*>(index));
        const __m256 from_high = _mm256_castsi256_ps(_mm256_cmpgt_epi32(idx, _mm256_set1_epi32(7)));
        for (int k = 0; k < kVaryings; ++k) {
            const __m256 lo = _mm256_permutevar8x32_ps(_mm256_load_ps(in.var[k]), idx);
            const __m256 hi = _mm256_permutevar8x32_ps(_mm256_load_ps(in.var[k] + 8), idx);
            const __m256 v = _mm256_blendv_ps(lo, hi, from_high);
            if constexpr (N == 8) _mm256_store_ps(packed[k], v);
            else _mm_store_ps(packed[k], _mm256_castps256_ps128(v));
        }
#else
        for (int k = 0; k < kVaryings; ++k)
            for (int l = 0; l < N; ++l) packed[k][l] = in.var[k][lane[l]];
#endif
        for (int k = 0; k < kVaryings; ++k) var[k] = packed[k];
        s.quad = quad;
    }
    s.Px = var[kVarP]; s.Py = var[kVarP + 1]; s.Pz = var[kVarP + 2];
    s.Nx = var[kVarN]; s.Ny = var[kVarN + 1]; s.Nz = var[kVarN + 2];
    s.Tx = var[kVarT]; s.Ty = var[kVarT + 1]; s.Tz = var[kVarT + 2]; s.Tw = var[kVarT + 3];
    s.u = var[kVarUV]; s.v = var[kVarUV + 1];
    for (int q = 0; q < 4; ++q) {
        const int l = 4 * q;  // the quad's derivatives, as surface_point() takes them
        s.dudx[q] = in.ddx(kVarUV, l); s.dvdx[q] = in.ddx(kVarUV + 1, l);
        s.dudy[q] = in.ddy(kVarUV, l); s.dvdy[q] = in.ddy(kVarUV + 1, l);
    }
    s.front_facing = in.front_facing;

    MaterialBlock mb;
    const std::uint32_t kill = sample_material_lanes<N>(*material, s, live, mb);
    RadianceBlock rb;
    shade_block_lanes<N>(mb, *ctx, rb);

    if constexpr (N == kBlockLanes) {
        out.kill = kill;
        for (int l = 0; l < N; ++l) {
            out.r[l] = rb.r[l]; out.g[l] = rb.g[l]; out.b[l] = rb.b[l]; out.a[l] = 1.0f;
        }
    } else {
        std::fill(out.r, out.r + kBlockLanes, 0.0f);
        std::fill(out.g, out.g + kBlockLanes, 0.0f);
        std::fill(out.b, out.b + kBlockLanes, 0.0f);
        std::fill(out.a, out.a + kBlockLanes, 1.0f);
        std::uint32_t block_kill = 0;
        for (std::uint32_t m = live; m; m &= m - 1) {
            const int i = __builtin_ctz(m), l = lane[i];
            out.r[l] = rb.r[i]; out.g[l] = rb.g[i]; out.b[l] = rb.b[i];
            block_kill |= ((kill >> i) & 1u) << l;
        }
        out.kill = block_kill;
    }
}

void PbrProgram::fragment(const FragmentBlock<kVaryings>& in, FragmentOut& out) const {
    const Material& m = *material->m;
    // The lit path samples the material and lights the lanes together, packed
    // when few are live; debug views, conductor materials and the reference
    // integral of the environment go lane by lane.
    const bool reference = ctx->env && ctx->ibl == IblMode::Reference;
    if ((view == DebugView::None || view == DebugView::Tiles) && m.conductor == Conductor::None && !reference) {
        const int live = __builtin_popcount(in.mask);
        if (live > 8) shade_lanes<16>(in, out);
        else if (live > 4) shade_lanes<8>(in, out);
        else shade_lanes<4>(in, out);
        return;
    }

    const bool alpha_mask = m.alpha_mode == AlphaMode::Mask;
    MaterialLods lods;
    for (int l = 0; l < kBlockLanes; ++l) {
        out.r[l] = 0.0f; out.g[l] = 0.0f; out.b[l] = 0.0f; out.a[l] = 1.0f;
        if (!(in.mask & (1u << l))) continue;
        SurfacePoint sp = surface_point(in, l);
        // The quad's lanes share derivatives, hence levels of detail: compute
        // them at the first live lane of each quad.
        if (!(in.mask & (0xFu << (l & ~3)) & ((1u << l) - 1)))
            lods = material_lods(*material, sp.duv_dx, sp.duv_dy);
        MaterialSample ms = sample_material(*material, sp, lods);
        if (alpha_mask && !(ms.alpha >= m.alpha_cutoff)) {
            out.kill |= 1u << l;
            continue;
        }
        glm::vec3 c;
        switch (view) {
        case DebugView::None:
        case DebugView::Tiles:  // lit image; the tile overlay is drawn afterwards
            c = shade_surface(ms, sp, *ctx);
            break;
        case DebugView::Albedo: c = ms.albedo; break;
        case DebugView::Normal: c = ms.N * 0.5f + 0.5f; break;
        case DebugView::Roughness: c = glm::vec3(ms.roughness); break;
        case DebugView::Metallic: c = glm::vec3(ms.metallic); break;
        case DebugView::Uv: c = glm::vec3(sp.uv - glm::floor(sp.uv), 0.0f); break;
        case DebugView::Depth: {
            float n = near_plane, f = far_plane;
            float z_ndc = in.z[l] * 2.0f - 1.0f;
            float d = 2.0f * n * f / (f + n - z_ndc * (f - n));
            c = glm::vec3(1.0f - glm::clamp((d - n) / (f - n), 0.0f, 1.0f));
            break;
        }
        case DebugView::Overdraw: c = glm::vec3(1.0f); break;  // counted with additive blending
        case DebugView::Ndf: c = glm::vec3(first_light_terms(ms, sp, *ctx).D); break;
        case DebugView::Fresnel: c = first_light_terms(ms, sp, *ctx).F; break;
        case DebugView::Geometry: c = glm::vec3(first_light_terms(ms, sp, *ctx).G); break;
        case DebugView::Diffuse: c = sum_lobes(ms, sp, *ctx, false); break;
        case DebugView::Specular: c = sum_lobes(ms, sp, *ctx, true); break;
        case DebugView::Irradiance: c = ctx->env ? ctx->env->irradiance(ms.N) : glm::vec3(0.0f); break;
        }
        out.r[l] = c.r; out.g[l] = c.g; out.b[l] = c.b;
    }
}

} // namespace prast

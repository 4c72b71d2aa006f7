// The PBR fragment stage; see pbr_program.h. One call per 4x4 block: the loop
// over lanes lives here so that sample_material/shade_surface inline into it.
#include "shading/pbr_program.h"

#include "shading/light_block.h"

#include <cmath>

namespace prast {

namespace {

glm::vec3 sum_lobes(const MaterialSample& ms, const SurfacePoint& sp, const ShadingContext& ctx,
                    bool specular) {
    BrdfInputs bi;
    bi.n = ms.N;
    glm::vec3 v = ctx.eye - sp.P;
    float len = glm::length(v);
    bi.v = len > 0.0f ? v / len : ms.N;
    bi.albedo = ms.albedo;
    bi.metallic = ms.metallic;
    bi.roughness = ms.roughness;
    bi.ior = ms.ior;
    bi.conductor = ms.conductor;
    glm::vec3 sum(0.0f);
    for (const ShadingLight& L : ctx.lights) {
        glm::vec3 radiance;
        light_at(L, sp.P, bi.l, radiance);
        BrdfTerms t = evaluate_brdf(bi, ctx.model);
        sum += (specular ? t.specular : t.diffuse) * radiance * t.NoL;
    }
    return sum;
}

BrdfTerms first_light_terms(const MaterialSample& ms, const SurfacePoint& sp, const ShadingContext& ctx) {
    BrdfInputs bi;
    bi.n = ms.N;
    glm::vec3 v = ctx.eye - sp.P;
    float len = glm::length(v);
    bi.v = len > 0.0f ? v / len : ms.N;
    bi.albedo = ms.albedo;
    bi.metallic = ms.metallic;
    bi.roughness = ms.roughness;
    bi.ior = ms.ior;
    bi.conductor = ms.conductor;
    if (ctx.lights.empty()) return BrdfTerms{};
    glm::vec3 radiance;
    light_at(ctx.lights[0], sp.P, bi.l, radiance);
    return evaluate_brdf(bi, ctx.model);
}

} // namespace

void PbrProgram::fragment(const FragmentBlock<kVaryings>& in, FragmentOut& out) const {
    const Material& m = *material->m;
    const bool alpha_mask = m.alpha_mode == AlphaMode::Mask;
    // The lit path batches the lighting of all lanes (light_block.h); debug
    // views and conductor materials shade lane by lane.
    const bool batched = (view == DebugView::None || view == DebugView::Tiles) && m.conductor == Conductor::None;
    MaterialBlock mb;
    MaterialLods lods;
    for (int l = 0; l < kBlockLanes; ++l) {
        out.r[l] = 0.0f; out.g[l] = 0.0f; out.b[l] = 0.0f; out.a[l] = 1.0f;
        if (batched) {
            // Dead lanes get harmless inputs; their results are never written.
            mb.Px[l] = in.var[kVarP][l]; mb.Py[l] = in.var[kVarP + 1][l]; mb.Pz[l] = in.var[kVarP + 2][l];
            mb.Nx[l] = 0.0f; mb.Ny[l] = 0.0f; mb.Nz[l] = 1.0f;
            mb.ar[l] = mb.ag[l] = mb.ab[l] = 0.0f;
            mb.metallic[l] = 0.0f; mb.roughness[l] = 1.0f; mb.occlusion[l] = 1.0f;
            mb.er[l] = mb.eg[l] = mb.eb[l] = 0.0f;
        }
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
        if (batched) {
            mb.Nx[l] = ms.N.x; mb.Ny[l] = ms.N.y; mb.Nz[l] = ms.N.z;
            mb.ar[l] = ms.albedo.r; mb.ag[l] = ms.albedo.g; mb.ab[l] = ms.albedo.b;
            mb.metallic[l] = ms.metallic; mb.roughness[l] = ms.roughness; mb.occlusion[l] = ms.occlusion;
            mb.er[l] = ms.emissive.r; mb.eg[l] = ms.emissive.g; mb.eb[l] = ms.emissive.b;
            mb.ior = ms.ior;
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
        }
        out.r[l] = c.r; out.g[l] = c.g; out.b[l] = c.b;
    }
    if (batched) {
        RadianceBlock rb;
        shade_block_lanes(mb, *ctx, rb);
        for (int l = 0; l < kBlockLanes; ++l) {
            out.r[l] = rb.r[l]; out.g[l] = rb.g[l]; out.b[l] = rb.b[l];
        }
    }
}

} // namespace prast

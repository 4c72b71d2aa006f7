// Material sampling, normal mapping and the lighting sum; see surface.h.
#include "shading/surface.h"

#include <cmath>

namespace prast {

namespace {

glm::vec3 safe_normalize(const glm::vec3& v, const glm::vec3& fallback) {
    float len2 = glm::dot(v, v);
    if (!(len2 > 1e-20f) || !std::isfinite(len2)) return fallback;
    return v / std::sqrt(len2);
}

glm::vec4 fetch(const Texture* tex, const SurfacePoint& sp) {
    return tex->sample(sp.uv.x, sp.uv.y, sp.duv_dx.x, sp.duv_dx.y, sp.duv_dy.x, sp.duv_dy.y);
}

} // namespace

MaterialSample sample_material(const BoundMaterial& bm, const SurfacePoint& sp) {
    const Material& m = *bm.m;
    MaterialSample s;

    // Base colour and alpha: factor times the (already linear) texture.
    glm::vec4 base = m.base_color_factor;
    if (bm.base_color) base *= fetch(bm.base_color, sp);
    s.albedo = glm::vec3(base);
    s.ior = m.ior;
    s.conductor = m.conductor;
    s.alpha = base.a;

    // Metal and roughness: glTF packs them in G and B; OBJ has separate maps (R).
    s.metallic = m.metallic_factor;
    s.roughness = m.roughness_factor;
    if (bm.metallic_roughness) {
        glm::vec4 mr = fetch(bm.metallic_roughness, sp);
        s.roughness *= mr.g;
        s.metallic *= mr.b;
    }
    if (bm.roughness) s.roughness *= fetch(bm.roughness, sp).r;
    if (bm.metallic) s.metallic *= fetch(bm.metallic, sp).r;
    s.metallic = glm::clamp(s.metallic, 0.0f, 1.0f);
    s.roughness = glm::clamp(s.roughness, 0.0f, 1.0f);

    if (bm.occlusion) s.occlusion = 1.0f + m.occlusion_strength * (fetch(bm.occlusion, sp).r - 1.0f);
    s.emissive = m.emissive_factor;
    if (bm.emissive) s.emissive *= glm::vec3(fetch(bm.emissive, sp));

    // Geometric frame; a back face of a double-sided material flips all of it.
    glm::vec3 N = safe_normalize(sp.N, glm::vec3(0.0f, 0.0f, 1.0f));
    float flip = sp.front_facing ? 1.0f : -1.0f;
    s.N_geom = N * flip;
    s.N = s.N_geom;
    if (bm.normal) {
        // Tangent space, OpenGL convention: red along T (+u), green along
        // B = cross(N, T) * w (up the image). T is re-orthogonalised per pixel.
        glm::vec3 T = glm::vec3(sp.T);
        T = safe_normalize(T - N * glm::dot(N, T), glm::vec3(0.0f));
        if (glm::dot(T, T) > 0.0f) {
            float w = sp.T.w < 0.0f ? -1.0f : 1.0f;
            glm::vec3 B = glm::cross(N, T) * w;
            glm::vec4 tx = fetch(bm.normal, sp);
            glm::vec3 nt = glm::vec3(tx) * 2.0f - 1.0f;
            nt.x *= m.normal_scale;
            nt.y *= m.normal_scale;
            nt = safe_normalize(nt, glm::vec3(0.0f, 0.0f, 1.0f));
            glm::vec3 n = T * nt.x + B * nt.y + N * nt.z;
            s.N = safe_normalize(n, N) * flip;
        }
    }
    return s;
}

glm::vec3 shade_surface(const MaterialSample& ms, const SurfacePoint& sp, const ShadingContext& ctx,
                        std::vector<BrdfTerms>* terms) {
    BrdfInputs in;
    in.n = ms.N;
    in.v = safe_normalize(ctx.eye - sp.P, ms.N);
    in.albedo = ms.albedo;
    in.metallic = ms.metallic;
    in.roughness = ms.roughness;
    in.ior = ms.ior;
    in.conductor = ms.conductor;
    glm::vec3 Lo = ms.emissive;
    if (terms) terms->clear();
    for (const ShadingLight& L : ctx.lights) {
        glm::vec3 radiance;
        light_at(L, sp.P, in.l, radiance);
        BrdfTerms t = evaluate_brdf(in, ctx.model);
        Lo += t.f * radiance * t.NoL;
        if (terms) terms->push_back(t);
    }
    Lo += ctx.ambient * ms.albedo * ms.occlusion;
    return Lo;
}

} // namespace prast

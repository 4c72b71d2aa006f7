// Per-pixel shading, independent of the rasterizer: what a material is at a
// surface point (texture lookups, normal mapping) and the light it reflects
// (conventions.md "Shading"). The fragment program and the stepper both call
// these, so an explained pixel shows the numbers that made it.
#pragma once

#include <cmath>
#include <vector>

#include <glm/glm.hpp>

#include "shading/brdf.h"
#include "scene/scene.h"
#include "shading/shadow_map.h"
#include "shading/texture.h"

namespace prast {

// A material with its textures resolved (null = no map).
struct BoundMaterial {
    const Material* m = nullptr;
    const Texture* base_color = nullptr;
    const Texture* metallic_roughness = nullptr;
    const Texture* roughness = nullptr;
    const Texture* metallic = nullptr;
    const Texture* normal = nullptr;
    const Texture* occlusion = nullptr;
    const Texture* emissive = nullptr;
};

// Interpolated geometry at a pixel, world space.
struct SurfacePoint {
    glm::vec3 P{0.0f};
    glm::vec3 N{0.0f, 0.0f, 1.0f};   // interpolated vertex normal (not yet normalised)
    glm::vec4 T{1.0f, 0.0f, 0.0f, 1.0f};  // tangent xyz + handedness
    glm::vec2 uv{0.0f};
    glm::vec2 duv_dx{0.0f}, duv_dy{0.0f};  // screen-space derivatives of uv (quad)
    bool front_facing = true;
};

// The material evaluated at a point.
struct MaterialSample {
    glm::vec3 albedo{0.8f};
    float alpha = 1.0f;
    float metallic = 0.0f;
    float roughness = 0.5f;   // perceptual, before the BRDF's clamp
    float occlusion = 1.0f;
    glm::vec3 emissive{0.0f};
    float ior = 1.5f;
    Conductor conductor = Conductor::None;
    glm::vec3 N{0.0f, 0.0f, 1.0f};  // shading normal (normal-mapped, unit, facing flipped)
    glm::vec3 N_geom{0.0f, 0.0f, 1.0f}; // unit interpolated normal (facing flipped)
};

struct ShadingLight {
    bool point = false;
    glm::vec3 direction{0.0f, 1.0f, 0.0f};  // directional: towards the light
    glm::vec3 position{0.0f};               // point
    glm::vec3 radiance{1.0f};               // colour * intensity
    const ShadowMap* shadow = nullptr;      // its shadow map this frame (shadow_pass.h), or none
};

struct ShadingContext {
    glm::vec3 eye{0.0f};
    std::vector<ShadingLight> lights;
    glm::vec3 ambient{0.03f};
    BrdfModel model = BrdfModel::Default;
};


// Light direction (towards the light) and incoming radiance at P.
inline void light_at(const ShadingLight& L, const glm::vec3& P, glm::vec3& l, glm::vec3& radiance) {
    if (!L.point) {
        l = L.direction;
        radiance = L.radiance;
        return;
    }
    glm::vec3 d = L.position - P;
    float d2 = glm::dot(d, d);
    if (!(d2 > 1e-12f)) { l = glm::vec3(0.0f, 0.0f, 1.0f); radiance = glm::vec3(0.0f); return; }
    l = d / std::sqrt(d2);
    radiance = L.radiance / d2;
}

// The fraction of the light reaching P (geometric normal Ng) past the shadow
// map's casters: 1 without a map. It multiplies the light's radiance.
inline float light_visibility(const ShadingLight& L, const glm::vec3& P, const glm::vec3& Ng) {
    if (!L.shadow) return 1.0f;
    return shadow_pcf(*L.shadow, shadow_tap(*L.shadow, P.x, P.y, P.z, Ng.x, Ng.y, Ng.z, L.direction.x,
                                             L.direction.y, L.direction.z));
}

// Level of detail of each bound texture, from the uv derivatives of a 2x2
// quad (conventions.md "Textures"). The four lanes of a quad share their
// derivatives, so the fragment program computes this once per quad.
struct MaterialLods {
    float base_color = 0, metallic_roughness = 0, roughness = 0, metallic = 0;
    float normal = 0, occlusion = 0, emissive = 0;
};

inline MaterialLods material_lods(const BoundMaterial& bm, glm::vec2 duv_dx, glm::vec2 duv_dy) {
    MaterialLods l;
    auto lod = [&](const Texture* t) { return t ? t->lod(duv_dx.x, duv_dx.y, duv_dy.x, duv_dy.y) : 0.0f; };
    l.base_color = lod(bm.base_color);
    l.metallic_roughness = lod(bm.metallic_roughness);
    l.roughness = lod(bm.roughness);
    l.metallic = lod(bm.metallic);
    l.normal = lod(bm.normal);
    l.occlusion = lod(bm.occlusion);
    l.emissive = lod(bm.emissive);
    return l;
}


namespace surface_detail {

inline glm::vec3 safe_normalize(const glm::vec3& v, const glm::vec3& fallback) {
    float len2 = glm::dot(v, v);
    if (!(len2 > 1e-20f) || !std::isfinite(len2)) return fallback;
    return v / std::sqrt(len2);
}

inline glm::vec4 fetch(const Texture* tex, const SurfacePoint& sp, float lambda) {
    return tex->sample_trilinear(sp.uv.x, sp.uv.y, lambda);
}

} // namespace surface_detail

inline MaterialSample sample_material(const BoundMaterial& bm, const SurfacePoint& sp, const MaterialLods& lods) {
    const Material& m = *bm.m;
    MaterialSample s;

    // Base colour and alpha: factor times the (already linear) texture.
    glm::vec4 base = m.base_color_factor;
    if (bm.base_color) base *= surface_detail::fetch(bm.base_color, sp, lods.base_color);
    s.albedo = glm::vec3(base);
    s.ior = m.ior;
    s.conductor = m.conductor;
    s.alpha = base.a;

    // Metal and roughness: glTF packs them in G and B; OBJ has separate maps (R).
    s.metallic = m.metallic_factor;
    s.roughness = m.roughness_factor;
    if (bm.metallic_roughness) {
        glm::vec4 mr = surface_detail::fetch(bm.metallic_roughness, sp, lods.metallic_roughness);
        s.roughness *= mr.g;
        s.metallic *= mr.b;
    }
    if (bm.roughness) s.roughness *= surface_detail::fetch(bm.roughness, sp, lods.roughness).r;
    if (bm.metallic) s.metallic *= surface_detail::fetch(bm.metallic, sp, lods.metallic).r;
    s.metallic = glm::clamp(s.metallic, 0.0f, 1.0f);
    s.roughness = glm::clamp(s.roughness, 0.0f, 1.0f);

    if (bm.occlusion) s.occlusion = 1.0f + m.occlusion_strength * (surface_detail::fetch(bm.occlusion, sp, lods.occlusion).r - 1.0f);
    s.emissive = m.emissive_factor;
    if (bm.emissive) s.emissive *= glm::vec3(surface_detail::fetch(bm.emissive, sp, lods.emissive));

    // Geometric frame; a back face of a double-sided material flips all of it.
    glm::vec3 N = surface_detail::safe_normalize(sp.N, glm::vec3(0.0f, 0.0f, 1.0f));
    float flip = sp.front_facing ? 1.0f : -1.0f;
    s.N_geom = N * flip;
    s.N = s.N_geom;
    if (bm.normal) {
        // Tangent space, OpenGL convention: red along T (+u), green along
        // B = cross(N, T) * w (up the image). T is re-orthogonalised per pixel.
        glm::vec3 T = glm::vec3(sp.T);
        T = surface_detail::safe_normalize(T - N * glm::dot(N, T), glm::vec3(0.0f));
        if (glm::dot(T, T) > 0.0f) {
            float w = sp.T.w < 0.0f ? -1.0f : 1.0f;
            glm::vec3 B = glm::cross(N, T) * w;
            glm::vec4 tx = surface_detail::fetch(bm.normal, sp, lods.normal);
            glm::vec3 nt = glm::vec3(tx) * 2.0f - 1.0f;
            nt.x *= m.normal_scale;
            nt.y *= m.normal_scale;
            nt = surface_detail::safe_normalize(nt, glm::vec3(0.0f, 0.0f, 1.0f));
            glm::vec3 n = T * nt.x + B * nt.y + N * nt.z;
            s.N = surface_detail::safe_normalize(n, N) * flip;
        }
    }
    return s;
}

// The BRDF inputs at a point, all but the light direction: shade_surface,
// the debug views and the stepper build them the same way.
inline BrdfInputs brdf_inputs(const MaterialSample& ms, const SurfacePoint& sp, const ShadingContext& ctx) {
    BrdfInputs in;
    in.n = ms.N;
    in.v = surface_detail::safe_normalize(ctx.eye - sp.P, ms.N);
    in.albedo = ms.albedo;
    in.metallic = ms.metallic;
    in.roughness = ms.roughness;
    in.ior = ms.ior;
    in.conductor = ms.conductor;
    return in;
}

inline glm::vec3 shade_surface(const MaterialSample& ms, const SurfacePoint& sp, const ShadingContext& ctx,
                               std::vector<BrdfTerms>* terms = nullptr) {
    BrdfInputs in = brdf_inputs(ms, sp, ctx);
    glm::vec3 Lo = ms.emissive;
    if (terms) terms->clear();
    for (const ShadingLight& L : ctx.lights) {
        glm::vec3 radiance;
        light_at(L, sp.P, in.l, radiance);
        radiance *= light_visibility(L, sp.P, ms.N_geom);
        BrdfTerms t = evaluate_brdf(in, ctx.model);
        Lo += t.f * radiance * t.NoL;
        if (terms) terms->push_back(t);
    }
    Lo += ctx.ambient * ms.albedo * ms.occlusion;
    return Lo;
}


inline MaterialSample sample_material(const BoundMaterial& bm, const SurfacePoint& sp) {
    return sample_material(bm, sp, material_lods(bm, sp.duv_dx, sp.duv_dy));
}

} // namespace prast

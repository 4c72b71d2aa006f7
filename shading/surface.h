// Per-pixel shading, independent of the rasterizer: what a material is at a
// surface point (texture lookups, normal mapping) and the light it reflects
// (conventions.md "Shading"). The fragment program and the stepper both call
// these, so an explained pixel shows the numbers that made it.
#pragma once

#include <vector>

#include <glm/glm.hpp>

#include "shading/brdf.h"
#include "shading/scene.h"
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
};

struct ShadingContext {
    glm::vec3 eye{0.0f};
    std::vector<ShadingLight> lights;
    glm::vec3 ambient{0.03f};
    BrdfModel model = BrdfModel::Default;
};

MaterialSample sample_material(const BoundMaterial& mat, const SurfacePoint& sp);

// Outgoing radiance towards the eye. `terms`, when not null, receives the
// BRDF terms of each light (for the stepper and the debug views).
glm::vec3 shade_surface(const MaterialSample& ms, const SurfacePoint& sp, const ShadingContext& ctx,
                        std::vector<BrdfTerms>* terms = nullptr);

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

} // namespace prast

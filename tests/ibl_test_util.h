// Environments and tables the image-based-lighting tests build: a two-thread
// pool, equirect images made from a function of direction, and (for the
// layered-material suites) a white and a structured sky with their DFG
// tables, each built once per test run.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <functional>

#include <glm/glm.hpp>

#include "raster/thread_pool.h"
#include "scene/image.h"
#include "shading/brdf.h"
#include "shading/ibl/dfg.h"
#include "shading/ibl/environment.h"
#include "shading/ibl/equirect.h"
#include "shading/surface.h"

namespace prast::test {

inline ThreadPool& pool2() {
    static ThreadPool p(2);
    return p;
}

// An equirect image whose texel centres take fn(direction).
inline Image make_env(int w, const std::function<glm::vec3(const glm::dvec3&)>& fn) {
    Image img;
    img.width = w;
    img.height = w / 2;
    img.rgba.assign(std::size_t(img.width) * img.height * 4, 1.0f);
    for (int y = 0; y < img.height; ++y)
        for (int x = 0; x < img.width; ++x)
            img.set(x, y, glm::vec4(fn(equirect_direction((x + 0.5) / img.width, (y + 0.5) / img.height)), 1.0f));
    return img;
}

inline glm::vec3 white(const glm::dvec3&) { return glm::vec3(1.0f); }

// A sky with structure for every lobe: a gradient, a soft sun (peak 20,
// about 6 degrees wide), a warm ground.
inline glm::vec3 sky(const glm::dvec3& d) {
    const glm::dvec3 sun = glm::normalize(glm::dvec3(0.5, 0.5, -0.6));
    const double up = std::max(d.y, 0.0);
    glm::dvec3 c = d.y > 0.0 ? glm::mix(glm::dvec3(0.8, 0.85, 0.9), glm::dvec3(0.15, 0.3, 0.7), std::sqrt(up))
                             : glm::dvec3(0.3, 0.22, 0.15) * (1.0 + 0.5 * d.y);
    const double a = std::acos(std::clamp(glm::dot(d, sun), -1.0, 1.0));
    c += glm::dvec3(20.0, 18.0, 15.0) * std::exp(-a * a / (2.0 * 0.05 * 0.05));
    return glm::vec3(c);
}

// The uniform white environment (64 wide) or sky() (256 wide).
inline const Environment& white_or_sky_env(bool uniform) {
    static const Environment u = Environment::build(make_env(64, white), {1.0f, 0.0f, true}, pool2());
    static const Environment s = Environment::build(make_env(256, sky), {1.0f, 0.0f, true}, pool2());
    return uniform ? u : s;
}

// The DFG table a BRDF model's split sum reads.
inline const DfgTable& dfg_for(BrdfModel m) {
    static const DfgTable ibl = DfgTable::build(DfgModel::SchlickIbl, pool2());
    static const DfgTable correlated = DfgTable::build(DfgModel::HeightCorrelated, pool2());
    return m == BrdfModel::Gltf ? correlated : ibl;
}

// A shading point at the origin with normal n (the coat's too) seen from
// direction v (both unit), lit by env through `model`'s split sum.
struct IblPoint {
    MaterialSample ms;
    SurfacePoint sp;
    ShadingContext ctx;
};
inline IblPoint make_ibl_point(const Environment& env, const glm::vec3& n, const glm::vec3& v, glm::vec3 albedo,
                               float metallic, float roughness, bool energy, BrdfModel model = BrdfModel::Default) {
    IblPoint p;
    p.ms.N = p.ms.N_geom = p.ms.clearcoat_N = n;
    p.ms.albedo = albedo;
    p.ms.metallic = metallic;
    p.ms.roughness = roughness;
    p.ctx.eye = v * 5.0f;
    p.ctx.model = model;
    p.ctx.env = &env;
    p.ctx.dfg_ibl = &dfg_for(model);
    p.ctx.energy = energy;
    return p;
}

} // namespace prast::test

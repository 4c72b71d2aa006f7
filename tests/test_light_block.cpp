// The 16-lane lighting (light_block.h) against the scalar shade_surface():
// they must agree bit for bit, so the stepper's scalar explanation of a pixel
// shows exactly the numbers the image was made of.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <random>

#include "raster/thread_pool.h"
#include "shading/light_block.h"
#include "tests/shading_test_util.h"

using namespace prast;
using prast::test::add_test_lights;
using prast::test::bits;

namespace {

// A small environment with structure everywhere (a gradient, a hot spot),
// turned by 30 degrees so the rotation is exercised, and the DFG tables.
struct IblRig {
    ThreadPool pool{2};
    Environment env;
    DfgTable dfg[3];
    IblRig() {
        Image img;
        img.width = 64;
        img.height = 32;
        img.rgba.resize(64 * 32 * 4);
        for (int y = 0; y < 32; ++y)
            for (int x = 0; x < 64; ++x)
                img.set(x, y, glm::vec4(0.2f + x / 64.0f, 1.0f - y / 32.0f, (x == 20 && y == 8) ? 50.0f : 0.3f, 1.0f));
        env = Environment::build(img, {1.3f, 30.0f, false}, pool);
        for (int m = 0; m < 3; ++m) dfg[m] = DfgTable::build(DfgModel(m), pool);
    }
};
const IblRig& ibl_rig() {
    static const IblRig rig;
    return rig;
}

// shaped: also a spot light whose cone spans the lanes (inside the inner
// cone, between the cones, outside) and a point light with a range some lanes
// lie beyond, both at once (KHR_lights_punctual, light_falloff()).
void check_block(BrdfModel model, std::uint32_t seed, bool with_env = false, bool energy = false,
                 bool away = false, bool shaped = false, bool unlit = false) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> uni(0.0f, 1.0f), sym(-1.0f, 1.0f);
    ShadingContext ctx;
    ctx.eye = {sym(rng) * 3, 2.0f + uni(rng), 5.0f};
    ctx.model = model;
    ctx.ambient = {0.03f, 0.04f, 0.05f};
    add_test_lights(ctx, rng);
    if (shaped) {
        ShadingLight spot, ranged;
        spot.point = spot.spot = true;
        spot.position = {sym(rng) * 0.3f, sym(rng) * 0.3f, 2.0f};
        spot.direction = glm::normalize(glm::vec3(sym(rng) * 0.2f, sym(rng) * 0.2f, 1.0f));
        spot.radiance = {20.0f, 18.0f, 15.0f};
        spot_cone(0.15f + 0.1f * uni(rng), 0.45f + 0.1f * uni(rng), spot.cone_scale, spot.cone_offset);
        spot.range_inv2 = (seed % 2) ? 1.0f / (3.0f * 3.0f) : 0.0f;  // with and without a range
        ranged.point = true;
        ranged.position = {sym(rng), sym(rng), 0.5f};
        ranged.radiance = {5.0f, 6.0f, 7.0f};
        ranged.range_inv2 = 1.0f / (1.2f * 1.2f);
        ctx.lights.push_back(spot);
        ctx.lights.push_back(ranged);
    }
    const bool gltf = model == BrdfModel::Gltf;
    if (with_env) {
        ctx.env = &ibl_rig().env;
        ctx.dfg_ibl = &ibl_rig().dfg[int(gltf ? DfgModel::HeightCorrelated : DfgModel::SchlickIbl)];
    }
    if (energy) {
        ctx.energy = true;
        ctx.dfg_light = &ibl_rig().dfg[int(gltf ? DfgModel::HeightCorrelated : DfgModel::SchlickDirect)];
    }

    MaterialBlock mb;
    mb.ior = 1.3f + uni(rng);
    mb.unlit = unlit;
    for (int l = 0; l < kBlockLanes; ++l) {
        glm::vec3 n = glm::normalize(glm::vec3(sym(rng), sym(rng), sym(rng)) + glm::vec3(0, 0, 0.2f));
        mb.Px[l] = sym(rng); mb.Py[l] = sym(rng); mb.Pz[l] = sym(rng);
        mb.Nx[l] = n.x; mb.Ny[l] = n.y; mb.Nz[l] = n.z;
        mb.ar[l] = uni(rng); mb.ag[l] = uni(rng); mb.ab[l] = uni(rng);
        mb.metallic[l] = (l % 4 == 0) ? 1.0f : uni(rng);
        mb.roughness[l] = (l % 5 == 0) ? 0.0f : uni(rng);  // exercises the clamp to 0.045
        mb.occlusion[l] = uni(rng);
        mb.er[l] = uni(rng) * 0.1f; mb.eg[l] = 0.0f; mb.eb[l] = uni(rng) * 0.1f;
    }
    // A lane sitting on the point light and one at the eye: the guarded paths.
    const glm::vec3 lamp = ctx.lights[1].position;
    mb.Px[3] = lamp.x; mb.Py[3] = lamp.y; mb.Pz[3] = lamp.z;
    mb.Px[7] = ctx.eye.x; mb.Py[7] = ctx.eye.y; mb.Pz[7] = ctx.eye.z;
    if (away) {
        // Every normal turned away from the eye (n.v < 0), as a normal map's
        // far slope or the back of a coincident pair gives.
        mb.Px[7] += 1.0f;  // not at the eye
        for (int l = 0; l < kBlockLanes; ++l) {
            const glm::vec3 v = glm::normalize(ctx.eye - glm::vec3(mb.Px[l], mb.Py[l], mb.Pz[l]));
            glm::vec3 n = glm::normalize(glm::vec3(sym(rng), sym(rng), sym(rng)) * 0.8f - v);
            if (glm::dot(n, v) >= 0.0f) n = -n;
            mb.Nx[l] = n.x; mb.Ny[l] = n.y; mb.Nz[l] = n.z;
        }
    }

    RadianceBlock rb;
    shade_block_lanes(mb, ctx, rb);
    for (int l = 0; l < kBlockLanes; ++l) {
        MaterialSample ms;
        ms.albedo = {mb.ar[l], mb.ag[l], mb.ab[l]};
        ms.metallic = mb.metallic[l];
        ms.roughness = mb.roughness[l];
        ms.occlusion = mb.occlusion[l];
        ms.emissive = {mb.er[l], mb.eg[l], mb.eb[l]};
        ms.ior = mb.ior;
        ms.N = {mb.Nx[l], mb.Ny[l], mb.Nz[l]};
        ms.unlit = unlit;
        SurfacePoint sp;
        sp.P = {mb.Px[l], mb.Py[l], mb.Pz[l]};
        glm::vec3 ref = shade_surface(ms, sp, ctx);
        INFO("lane ", l, " seed ", seed, " env ", with_env, " energy ", energy);
        CHECK(bits(rb.r[l]) == bits(ref.r));
        CHECK(bits(rb.g[l]) == bits(ref.g));
        CHECK(bits(rb.b[l]) == bits(ref.b));
        // Lit by the environment, a surface that faces away still reflects it.
        if (away && with_env) CHECK(ref.r + ref.g + ref.b > 0.0f);
        if (unlit) {  // KHR_materials_unlit: the albedo itself, no light, emissive or environment
            CHECK(bits(ref.r) == bits(mb.ar[l]));
            CHECK(bits(ref.g) == bits(mb.ag[l]));
            CHECK(bits(ref.b) == bits(mb.ab[l]));
        }
    }
}

} // namespace

TEST_SUITE("light_block") {
TEST_CASE("facing_normal: bends only normals with n.v < 1e-4: n's part along v becomes 1e-4, normalised") {
    std::mt19937 rng(3);
    std::uniform_real_distribution<float> sym(-1.0f, 1.0f);
    int bent = 0;
    for (int i = 0; i < 10000; ++i) {
        const glm::vec3 v = glm::normalize(glm::vec3(sym(rng), sym(rng), sym(rng)));
        const glm::vec3 n = glm::normalize(glm::vec3(sym(rng), sym(rng), sym(rng)));
        const glm::vec3 f = facing_normal(n, v);
        const float d = n.x * v.x + n.y * v.y + n.z * v.z;
        if (d >= kMinNoV) {
            CHECK(bits(f.x) == bits(n.x));
            CHECK(bits(f.y) == bits(n.y));
            CHECK(bits(f.z) == bits(n.z));
            continue;
        }
        ++bent;
        const glm::dvec3 nd(n), vd(v);
        const glm::dvec3 want = glm::normalize(nd - vd * glm::dot(nd, vd) + vd * double(kMinNoV));
        CHECK(glm::length(glm::dvec3(f) - want) <= 1e-5);
        CHECK(glm::dot(f, v) >= kMinNoV * 0.999f);
        CHECK(glm::length(f) == doctest::Approx(1.0f).epsilon(1e-6));
        // It moves only within the plane of n and v.
        CHECK(std::fabs(glm::dot(f, glm::cross(n, v))) <= 1e-5f);
    }
    CHECK(bent > 4000);
}
TEST_CASE("normals facing away from the eye: bent, lanes equal scalar bit for bit, never black under an environment") {
    for (BrdfModel model : {BrdfModel::Default, BrdfModel::Gltf})
        for (std::uint32_t seed = 1; seed <= 50; ++seed) {
            check_block(model, seed, false, false, true);
            check_block(model, seed, true, false, true);
            check_block(model, seed, true, true, true);
        }
}
TEST_CASE("16-lane lighting equals the scalar shade_surface bit for bit (default BRDF)") {
    for (std::uint32_t seed = 1; seed <= 200; ++seed) check_block(BrdfModel::Default, seed);
}
TEST_CASE("16-lane lighting equals the scalar shade_surface bit for bit (glTF BRDF)") {
    for (std::uint32_t seed = 1; seed <= 200; ++seed) check_block(BrdfModel::Gltf, seed);
}
TEST_CASE("16-lane image-based lighting equals the scalar split sum bit for bit") {
    for (BrdfModel model : {BrdfModel::Default, BrdfModel::Gltf})
        for (std::uint32_t seed = 1; seed <= 100; ++seed) check_block(model, seed, true, false);
}
TEST_CASE("16-lane --energy conserve equals the scalar path bit for bit, with and without an environment") {
    for (BrdfModel model : {BrdfModel::Default, BrdfModel::Gltf})
        for (std::uint32_t seed = 1; seed <= 100; ++seed) {
            check_block(model, seed, false, true);
            check_block(model, seed, true, true);
        }
}
TEST_CASE("16-lane spot lights and light ranges equal the scalar light_falloff() bit for bit") {
    for (BrdfModel model : {BrdfModel::Default, BrdfModel::Gltf})
        for (std::uint32_t seed = 1; seed <= 100; ++seed) {
            check_block(model, seed, false, false, false, true);
            check_block(model, seed, true, false, false, true);
            check_block(model, seed, false, true, false, true);
            check_block(model, seed, true, true, true, true);
        }
}
TEST_CASE("spot_cone() and light_falloff(): the KHR_lights_punctual reference formulas") {
    ShadingLight L;
    L.point = L.spot = true;
    L.direction = {0.0f, 0.0f, 1.0f};
    const double inner = 0.3, outer = 0.6;
    spot_cone(float(inner), float(outer), L.cone_scale, L.cone_offset);
    CHECK(L.cone_scale == doctest::Approx(1.0 / (std::cos(inner) - std::cos(outer))).epsilon(1e-7));
    for (double theta = 0.0; theta < 1.5; theta += 0.01) {
        const glm::vec3 l(float(std::sin(theta)), 0.0f, float(std::cos(theta)));
        const double a = std::clamp((std::cos(theta) - std::cos(outer)) / (std::cos(inner) - std::cos(outer)), 0.0, 1.0);
        const float f = light_falloff(L, l, 1.0f);
        CHECK(std::fabs(double(f) - a * a) <= 1e-5);
        if (theta < inner - 1e-3) CHECK(f == 1.0f);
        if (theta > outer + 1e-3) CHECK(f == 0.0f);
    }
    // Equal angles: the spec's max(0.001, ...) guard, a hard edge, never a division by 0.
    spot_cone(0.5f, 0.5f, L.cone_scale, L.cone_offset);
    CHECK(std::isfinite(L.cone_scale));
    CHECK(L.cone_scale == doctest::Approx(1000.0));
    // The range window 1 - (d / range)^4, 0 beyond it.
    ShadingLight R;
    R.point = true;
    R.range_inv2 = 1.0f / 4.0f;  // range 2
    for (double d = 0.05; d < 3.0; d += 0.05) {
        const double want = std::max(0.0, 1.0 - std::pow(d / 2.0, 4.0));
        CHECK(std::fabs(double(light_falloff(R, {0.0f, 0.0f, 1.0f}, float(d * d))) - want) <= 1e-5);
        if (d > 2.0 + 1e-6) CHECK(light_falloff(R, {0.0f, 0.0f, 1.0f}, float(d * d)) == 0.0f);
    }
}
TEST_CASE("an unlit material (KHR_materials_unlit): lanes and scalar give the albedo, lights and environment aside") {
    for (std::uint32_t seed = 1; seed <= 20; ++seed) {
        check_block(BrdfModel::Default, seed, false, false, false, true, true);
        check_block(BrdfModel::Gltf, seed, true, true, false, true, true);
    }
}
}

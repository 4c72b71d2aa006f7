// The 16-lane lighting (light_block.h) against the scalar shade_surface():
// they must agree bit for bit, so the stepper's scalar explanation of a pixel
// shows exactly the numbers the image was made of.
#include <doctest/doctest.h>

#include <cstring>
#include <random>

#include "shading/light_block.h"
#include "tests/shading_test_util.h"

using namespace prast;
using prast::test::add_test_lights;
using prast::test::bits;

namespace {

void check_block(BrdfModel model, std::uint32_t seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> uni(0.0f, 1.0f), sym(-1.0f, 1.0f);
    ShadingContext ctx;
    ctx.eye = {sym(rng) * 3, 2.0f + uni(rng), 5.0f};
    ctx.model = model;
    ctx.ambient = {0.03f, 0.04f, 0.05f};
    add_test_lights(ctx, rng);

    MaterialBlock mb;
    mb.ior = 1.3f + uni(rng);
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
        SurfacePoint sp;
        sp.P = {mb.Px[l], mb.Py[l], mb.Pz[l]};
        glm::vec3 ref = shade_surface(ms, sp, ctx);
        INFO("lane ", l, " seed ", seed);
        CHECK(bits(rb.r[l]) == bits(ref.r));
        CHECK(bits(rb.g[l]) == bits(ref.g));
        CHECK(bits(rb.b[l]) == bits(ref.b));
    }
}

} // namespace

TEST_SUITE("light_block") {
TEST_CASE("16-lane lighting equals the scalar shade_surface bit for bit (default BRDF)") {
    for (std::uint32_t seed = 1; seed <= 200; ++seed) check_block(BrdfModel::Default, seed);
}
TEST_CASE("16-lane lighting equals the scalar shade_surface bit for bit (glTF BRDF)") {
    for (std::uint32_t seed = 1; seed <= 200; ++seed) check_block(BrdfModel::Gltf, seed);
}
}

// The layered material lobes of glTF: KHR_materials_specular (the
// dielectric's F0 and F90) and KHR_materials_clearcoat (a second GGX lobe
// over the base). The spec's analytic cases on the BRDF, the white furnace
// (deterministic quadrature, the split sum and the reference integral under
// a uniform sky) within today's bounds at the extensions' extremes, the
// split sum of the new lobes against the reference integral, files without
// the lobe (or with clearcoat 0) keeping their bytes, the stepper's
// breakdown and `verify` on a file with both, and hostile values.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "raster/thread_pool.h"
#include "renderer/scene_renderer.h"
#include "scene/image.h"
#include "scene/load_scene.h"
#include "scene/write_image.h"
#include "shading/brdf.h"
#include "shading/ibl/dfg.h"
#include "shading/ibl/environment.h"
#include "shading/ibl/ibl_sampling.h"
#include "shading/surface.h"
#include "tests/cli_util.h"
#include "tests/gltf_writer.h"
#include "tests/ibl_test_util.h"
#include "tests/scratch.h"
#include "tests/step_check.h"

using namespace prast;
using prast::gltf_test::GltfWriter;
using json = nlohmann::json;
using namespace prast::test;

namespace {

constexpr double kPi = 3.14159265358979323846;

// ---- BRDF quadrature (as tests/test_brdf.cpp): v in the xz plane, f symmetric in y.

// The GGX lobes take test_brdf.cpp's 128 steps in u with half its 64 in
// phi, the smooth diffuse lobe 48 x 24 (this grid has 8x its points):
// against 128 x 64 everywhere these move the albedos by < 1e-3.
constexpr int kNTheta = 128;
constexpr int kNPhi = 32;
constexpr int kNThetaDiffuse = 48;
constexpr int kNPhiDiffuse = 24;

glm::vec3 direction(double cos_theta, double phi) {
    const double s = std::sqrt(std::max(0.0, 1.0 - cos_theta * cos_theta));
    return glm::vec3(float(s * std::cos(phi)), float(s * std::sin(phi)), float(cos_theta));
}

// The directional albedo of the inputs' whole BRDF, coat included, max
// over the channels: the diffuse lobe by the midpoint rule in theta, each
// GGX lobe (the base's, the coat's) over its half vector with the GGX
// inverse CDF as the substitution, as tests/test_brdf.cpp integrates the
// specular lobe (the narrow lobes need it): dl = 4 (v.h) dh, dh = du dphi /
// (2 pi D(h) n.h). Every term is evaluate_brdf()'s, attenuation included.
double albedo_of(BrdfInputs in, BrdfModel model, double cos_v) {
    in.n = glm::vec3(0.0f, 0.0f, 1.0f);
    in.v = direction(cos_v, 0.0);
    glm::dvec3 diffuse(0.0), specular(0.0), coat(0.0);
    const double dtheta = 0.5 * kPi / kNThetaDiffuse, dphi = kPi / kNPhiDiffuse;
    for (int i = 0; i < kNThetaDiffuse; ++i) {
        const double theta = (i + 0.5) * dtheta;
        const double c = std::cos(theta), s = std::sin(theta);
        for (int j = 0; j < kNPhiDiffuse; ++j) {
            in.l = direction(c, (j + 0.5) * dphi);
            const BrdfTerms t = evaluate_brdf(in, model);
            diffuse += glm::dvec3(t.diffuse + t.sheen_f) * (c * s);  // the sheen's broad lobe too
        }
    }
    diffuse *= 2.0 * dtheta * dphi;
    const glm::dvec3 v(in.v);
    auto lobe = [&](float roughness, bool of_coat) {
        glm::dvec3 sum(0.0);
        const double r = std::clamp(roughness, kMinPerceptualRoughness, 1.0f);
        const double alpha = double(float(r) * float(r)), a2 = alpha * alpha;
        for (int i = 0; i < kNTheta; ++i) {
            const double u = (i + 0.5) / kNTheta;
            const double cos2 = (1.0 - u) / (1.0 + (a2 - 1.0) * u);
            const double cos_h = std::sqrt(cos2), sin_h = std::sqrt(std::max(0.0, 1.0 - cos2));
            const double d = cos2 * (a2 - 1.0) + 1.0;
            const double pdf_h = a2 / (kPi * d * d) * cos_h;
            for (int j = 0; j < kNPhi; ++j) {
                const double phi = (j + 0.5) * kPi / kNPhi;
                const glm::dvec3 h(sin_h * std::cos(phi), sin_h * std::sin(phi), cos_h);
                const double VoH = glm::dot(v, h);
                if (VoH <= 0.0) continue;
                const glm::dvec3 l = 2.0 * VoH * h - v;
                if (l.z <= 0.0) continue;
                in.l = glm::vec3(l);
                const BrdfTerms t = evaluate_brdf(in, model);
                const glm::dvec3 f = of_coat ? glm::dvec3(double(t.coat_specular)) : glm::dvec3(t.specular);
                sum += f * (l.z * 4.0 * VoH / pdf_h);
            }
        }
        return sum / (double(kNTheta) * double(kNPhi));
    };
    specular = lobe(in.roughness, false);
    if (in.clearcoat > 0.0f) coat = lobe(in.clearcoat_roughness, true);  // n_c = n here
    const glm::dvec3 e = diffuse + specular + coat;
    return std::max(e.x, std::max(e.y, e.z));
}

// Reference formulas in double, written from the extension texts.
double d_ggx(double NoH, double a) {
    const double a2 = a * a, d = NoH * NoH * (a2 - 1.0) + 1.0;
    return a2 / (kPi * d * d);
}
double v_correlated(double NoV, double NoL, double a) {
    const double a2 = a * a;
    return 0.5 / (NoL * std::sqrt(NoV * NoV * (1.0 - a2) + a2) + NoV * std::sqrt(NoL * NoL * (1.0 - a2) + a2));
}

// ---- Image-based lighting

glm::vec3 view_about(const glm::vec3& n, double cos_v, double phi) {
    const Frame f{glm::dvec3(n)};
    const double s = std::sqrt(std::max(0.0, 1.0 - cos_v * cos_v));
    return glm::vec3(glm::normalize(f.to_world({s * std::cos(phi), s * std::sin(phi), cos_v})));
}

float lum(const glm::vec3& c) { return 0.2126f * c.r + 0.7152f * c.g + 0.0722f * c.b; }

// ---- Files

int add_quad(GltfWriter& g, int material, float z = 0.0f) {
    const int pos = g.floats({-1, -1, z, 1, -1, z, 1, 1, z, -1, 1, z}, "VEC3", 3);
    const json attrs = {{"POSITION", pos}, {"NORMAL", g.floats({0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1}, "VEC3", 3)},
                        {"TEXCOORD_0", g.floats({0, 1, 1, 1, 1, 0, 0, 0}, "VEC2", 2)}};
    const int ind = g.u16({0, 1, 2, 0, 2, 3}, "SCALAR", 1);
    g.doc["meshes"].push_back({{"primitives", json::array({{{"attributes", attrs}, {"indices", ind}, {"material", material}}})}});
    return int(g.doc["meshes"].size()) - 1;
}

// An 8x8 RGBA PNG of a smooth pattern, so maps vary over the surface.
std::vector<unsigned char> pattern_png(int seed) {
    std::vector<std::uint8_t> rgba(8 * 8 * 4);
    for (int y = 0; y < 8; ++y)
        for (int x = 0; x < 8; ++x)
            for (int c = 0; c < 4; ++c)
                rgba[std::size_t((y * 8 + x) * 4 + c)] = std::uint8_t((x * 29 + y * 17 + c * 61 + seed * 37) % 200 + 40);
    return encode_png(8, 8, rgba.data());
}

Scene load(const test::TempDir& dir, const GltfWriter& g, const std::string& name) {
    const std::string path = dir.file(name);
    test::write_text(path, g.text());
    return load_scene(path);
}

bool has_warning(const Scene& s, const std::string& part) {
    for (const std::string& w : s.warnings)
        if (w.find(part) != std::string::npos) return true;
    return false;
}

std::vector<float> draw(const Scene& scene, bool env, int threads = 1) {
    Renderer r({threads, 16});
    SceneRenderer sr(scene, r);
    FrameSettings fs;
    fs.camera.eye = {0.3f, 0.4f, 3.0f};
    fs.camera.target = {0.0f, 0.0f, 0.0f};
    fs.ambient = glm::vec3(0.05f);
    fs.scene_environment = false;
    fs.background = Background::Color;
    fs.background_color = glm::vec3(0.0f);
    ShadingLight sun;
    sun.direction = glm::normalize(glm::vec3(0.3f, 0.5f, 1.0f));
    sun.radiance = glm::vec3(2.0f);
    ShadingLight point;
    point.point = true;
    point.position = {-1.0f, 1.5f, 2.0f};
    point.radiance = glm::vec3(4.0f);
    fs.lights = {sun, point};
    if (env) fs.environment = &white_or_sky_env(false);
    Framebuffer fb(48, 40);
    sr.render(fs, fb);
    return fb.color;
}

// A material's JSON: rough grey dielectric, plus `ext` as its extensions.
json grey(const json& ext = json()) {
    json m = {{"pbrMetallicRoughness", {{"baseColorFactor", {0.6, 0.4, 0.3, 1}}, {"metallicFactor", 0.2},
                                        {"roughnessFactor", 0.6}}}};
    if (!ext.is_null()) m["extensions"] = ext;
    return m;
}

} // namespace

TEST_SUITE("material_lobes") {

TEST_CASE("specular: specularFactor 0 leaves no dielectric reflection; the metal is untouched; the defaults change nothing") {
    for (BrdfModel model : {BrdfModel::Default, BrdfModel::Gltf}) {
        for (float metallic : {0.0f, 1.0f}) {
            BrdfInputs in;
            in.albedo = glm::vec3(0.7f, 0.5f, 0.2f);
            in.metallic = metallic;
            in.roughness = 0.4f;
            in.n = glm::vec3(0, 0, 1);
            in.v = glm::normalize(glm::vec3(0.3f, 0.0f, 1.0f));
            in.l = glm::normalize(glm::vec3(-0.5f, 0.2f, 1.0f));
            const BrdfTerms plain = evaluate_brdf(in, model);
            BrdfInputs off = in;
            off.specular_ext = true;
            off.specular = 0.0f;
            const BrdfTerms t0 = evaluate_brdf(off, model);
            BrdfInputs defaults = in;
            defaults.specular_ext = true;
            const BrdfTerms t1 = evaluate_brdf(defaults, model);
            CAPTURE(metallic);
            // Defaults (factor 1, colour white): the same bits as without the extension.
            CHECK(t1.F == plain.F);
            CHECK(t1.f == plain.f);
            if (metallic == 0.0f) {
                // The dielectric's F0 = 0 and F90 = 0: F = 0, no specular, kd = 1.
                CHECK(t0.F == glm::vec3(0.0f));
                CHECK(t0.specular == glm::vec3(0.0f));
                CHECK(t0.kd == glm::vec3(1.0f));
                CHECK(t0.diffuse == in.albedo * Fd_Lambert());
            } else {
                CHECK(t0.F == plain.F);  // the metal BRDF is not affected
                CHECK(t0.f == plain.f);
            }
        }
    }
}

TEST_CASE("specular: F0 = min(F0(ior) colour, 1) specular at normal incidence, F90 = specular at grazing") {
    BrdfInputs in;
    in.albedo = glm::vec3(0.5f);
    in.metallic = 0.0f;
    in.ior = 1.5f;
    in.specular_ext = true;
    in.specular = 0.5f;
    in.specular_color = glm::vec3(2.0f, 0.5f, 40.0f);  // 0.08, 0.02 and clamped 1
    CHECK(brdf_f0(in).x == doctest::Approx(0.04 * 2.0 * 0.5).epsilon(1e-6));
    CHECK(brdf_f0(in).y == doctest::Approx(0.04 * 0.5 * 0.5).epsilon(1e-6));
    CHECK(brdf_f0(in).z == 0.5f);
    CHECK(brdf_f90(in) == 0.5f);
    // v = l = n: v.h = 1, F = F0.
    const BrdfTerms t = evaluate_brdf(in, BrdfModel::Gltf);
    CHECK(t.F == brdf_f0(in));
    CHECK(t.kd == glm::vec3(1.0f) - brdf_f0(in));
    // v.h = 0 (l = -v mirrored about the tangent plane, at grazing): F = F90.
    in.v = glm::vec3(1, 0, 0);
    in.l = glm::vec3(-1, 0, 0);
    const BrdfTerms g = evaluate_brdf(in, BrdfModel::Gltf);
    CHECK(g.VoH == 0.0f);
    CHECK(g.F == glm::vec3(0.5f));
    // Half metal: F0 and F90 mix towards the albedo and 1.
    in.metallic = 0.5f;
    CHECK(brdf_f90(in) == doctest::Approx(0.75));
    CHECK(brdf_f0(in).x == doctest::Approx(0.5 * 0.04 + 0.25));
}

TEST_CASE("clearcoat: 1 at roughness 0, seen and lit along the normal, adds 0.04 D V and attenuates the base by 0.96") {
    for (BrdfModel model : {BrdfModel::Default, BrdfModel::Gltf}) {
        BrdfInputs in;
        in.albedo = glm::vec3(0.8f, 0.3f, 0.1f);
        in.roughness = 0.5f;
        const BrdfTerms base = evaluate_brdf(in, model);
        in.clearcoat = 1.0f;
        in.clearcoat_roughness = 0.0f;  // clamped to 0.045 like the base's
        const BrdfTerms t = evaluate_brdf(in, model);
        REQUIRE(t.coat);
        const double a = 0.045 * 0.045;
        // At n.v = n.l = 1 both geometry forms give G / (4 n.v n.l) = 1 / 4 = V.
        const double expect = 0.04 * d_ggx(1.0, a) * v_correlated(1.0, 1.0, a);
        CAPTURE(std::string(brdf_model_name(model)));
        CHECK(t.coat_F == 0.04f);
        // 1%: the float D_GGX at its sharpest peak (alpha^2 = 4e-6 against
        // n.h's float steps; test_brdf.cpp notes the same bias); the rough
        // coat below holds to 2e-5.
        CHECK(t.coat_specular == doctest::Approx(expect).epsilon(0.01));
        CHECK(t.coat_attenuation == 0.96f);
        CHECK(t.f == (base.diffuse * 0.96f + base.specular * 0.96f));
        const glm::vec3 lo = brdf_light(t, glm::vec3(1.0f));
        CHECK(lo.x == doctest::Approx(double(base.f.x) * 0.96 + double(t.coat_specular)).epsilon(1e-6));
        BrdfInputs rough = in;
        rough.clearcoat_roughness = 0.5f;
        const double a5 = 0.25;
        CHECK(evaluate_brdf(rough, model).coat_specular ==
              doctest::Approx(0.04 * d_ggx(1.0, a5) * v_correlated(1.0, 1.0, a5)).epsilon(2e-5));
        // clearcoat 0: no coat, the same bits.
        in.clearcoat = 0.0f;
        const BrdfTerms none = evaluate_brdf(in, model);
        CHECK_FALSE(none.coat);
        CHECK(none.f == base.f);
        CHECK(brdf_light(none, glm::vec3(0.3f)) == base.f * glm::vec3(0.3f) * base.NoL);
    }
    // At grazing views the coat's Fresnel rises to 1 and the base beneath goes dark.
    BrdfInputs in;
    in.clearcoat = 1.0f;
    in.v = glm::normalize(glm::vec3(1.0f, 0.0f, 1e-3f));
    in.l = glm::vec3(0, 0, 1);
    const BrdfTerms t = evaluate_brdf(in, BrdfModel::Gltf);
    CHECK(t.coat_F > 0.99f);
    CHECK(t.coat_attenuation < 0.01f);
}

TEST_CASE("sheen: the Charlie distribution is normalised, the albedo table is its integral, colour 0 is no sheen") {
    // The deterministic exp and log against libm's.
    for (double x : {-30.0, -3.7, -0.2, 0.0, 0.4, 5.5, 40.0})
        CHECK(det::exp(x) == doctest::Approx(std::exp(x)).epsilon(1e-13));
    for (double x : {1e-9, 0.013, 0.5, 0.7071, 1.0, 3.3, 1e6})
        CHECK(det::log(x) == doctest::Approx(std::log(x)).epsilon(1e-13).scale(1.0));
    // integral of D(h) (n.h) dh = 1 over the hemisphere (midpoint in cos theta_h).
    for (double r : {0.3, 0.6, 1.0}) {
        const double alpha = r * r;
        double sum = 0.0;
        const int n = 20000;
        for (int i = 0; i < n; ++i) {
            const double c = (i + 0.5) / n;
            sum += D_Charlie(c, alpha) * c;
        }
        CAPTURE(r);
        CHECK(sum * 2.0 * kPi / n == doctest::Approx(1.0).epsilon(1e-3));
    }
    // The table against a finer quadrature of D V (n.l) written here in libm's double.
    auto albedo = [](double NoV, double r) {
        const double alpha = r * r, sv = std::sqrt(1.0 - NoV * NoV);
        const int nt = 120, np = 120;
        double sum = 0.0;
        for (int a = 0; a < nt; ++a) {
            const double NoL = (a + 0.5) / nt, sl = std::sqrt(1.0 - NoL * NoL);
            for (int b = 0; b < np; ++b) {
                const double phi = (b + 0.5) * kPi / np;
                const double hx = sl * std::cos(phi) + sv, hy = sl * std::sin(phi), hz = NoL + NoV;
                const double NoH = hz / std::sqrt(hx * hx + hy * hy + hz * hz);
                const double inv = 1.0 / alpha;
                const double D = (2.0 + inv) * std::pow(1.0 - NoH * NoH, 0.5 * inv) / (2.0 * kPi);
                sum += D * V_Charlie(NoV, NoL, alpha) * NoL;
            }
        }
        return sum / nt * (2.0 * kPi / np);
    };
    double worst = 0.0;
    for (int i : {1, 8, 16, 31})
        for (int j : {5, 10, 15}) {
            const double NoV = double(i) / (kSheenNoV - 1), r = double(j) / (kSheenRough - 1);
            const float e = sheen_albedo(float(NoV), float(r));
            CAPTURE(NoV); CAPTURE(r);
            CHECK(e >= 0.0f);
            CHECK(e <= 1.0f);
            CHECK(e == doctest::Approx(albedo(NoV, r)).epsilon(0.01));
            worst = std::max(worst, std::fabs(double(e) - albedo(NoV, r)));
        }
    MESSAGE("sheen albedo table against a 120 x 120 quadrature: max abs difference " << worst);
    // Colour 0: no sheen, the same bits.
    BrdfInputs in;
    in.l = glm::normalize(glm::vec3(0.4f, 0.1f, 1.0f));
    const BrdfTerms plain = evaluate_brdf(in, BrdfModel::Gltf);
    in.sheen_roughness = 0.5f;
    CHECK(evaluate_brdf(in, BrdfModel::Gltf).f == plain.f);
    // Colour 1: the lobe is colour D V, the base times min(1 - E(n.v), 1 - E(n.l)).
    in.sheen_color = glm::vec3(1.0f, 0.5f, 0.25f);
    const BrdfTerms t = evaluate_brdf(in, BrdfModel::Gltf);
    REQUIRE(t.sheen);
    const double as = 0.25;
    const double D = D_Charlie(double(t.NoH), as), V = V_Charlie(double(t.NoV), double(t.NoL), as);
    CHECK(t.sheen_f.x == doctest::Approx(D * V).epsilon(1e-6));
    CHECK(t.sheen_f.z == doctest::Approx(0.25 * D * V).epsilon(1e-6));
    const float scaling = std::min(1.0f - sheen_albedo(t.NoV, 0.5f), 1.0f - sheen_albedo(t.NoL, 0.5f));
    CHECK(t.sheen_scaling == scaling);
    CHECK(t.diffuse == plain.diffuse * scaling);
}

TEST_CASE("white furnace: coat, specular colour and weight at their extremes stay within today's bounds") {
    // Today's bounds (test_brdf.cpp): a white diffuse + specular material
    // reflects <= 1 + 0.006 for n.v >= 0.7, <= 1.07 (default) / 1.80 (gltf)
    // at grazing views; with --energy conserve <= 1 + 0.008 (0.015 at n.v =
    // 0.1, 0.03 at 0.03). The coat keeps (1 - c F_coat) E_base + c F_coat
    // E_DV <= max(E_base, E_DV), so these hold with every lobe at its extreme.
    struct Case { const char* label; float spec; glm::vec3 colour; float coat, coat_r; float sheen = 0, sheen_r = 0; };
    const Case cases[] = {
        {"sheen 1 rough 0.3", 1.0f, glm::vec3(1.0f), 0.0f, 0.0f, 1.0f, 0.3f},
        {"sheen 1 rough 0.5 under coat 1 rough 0.3", 1.0f, glm::vec3(1.0f), 1.0f, 0.3f, 1.0f, 0.5f},
        {"coat 1 rough 0.1", 1.0f, glm::vec3(1.0f), 1.0f, 0.1f},
        {"coat 1 rough 0.3", 1.0f, glm::vec3(1.0f), 1.0f, 0.3f},
        {"coat 1 rough 1", 1.0f, glm::vec3(1.0f), 1.0f, 1.0f},
        {"coat 0.5 rough 0.5", 1.0f, glm::vec3(1.0f), 0.5f, 0.5f},
        {"specular colour 100 (F0 1)", 1.0f, glm::vec3(100.0f), 0.0f, 0.0f},
        {"specular colour 0 (F0 0, F90 1)", 1.0f, glm::vec3(0.0f), 0.0f, 0.0f},
        {"specular 0", 0.0f, glm::vec3(1.0f), 0.0f, 0.0f},
        {"specular colour 100 under coat 1", 1.0f, glm::vec3(100.0f), 1.0f, 0.3f},
    };
    const double cos_grid[] = {1.0, 0.7, 0.3, 0.1, 0.03};
    for (BrdfModel model : {BrdfModel::Default, BrdfModel::Gltf}) {
        const DfgTable table = DfgTable::build(model == BrdfModel::Gltf ? DfgModel::HeightCorrelated : DfgModel::SchlickDirect, pool2());
        const double grazing_bound = model == BrdfModel::Default ? 1.07 : 1.80;
        double max_near = 0, max_grazing = 0, max_energy = 0;
        for (const Case& c : cases) {
            for (float metallic : {0.0f, 0.5f}) {
                if (c.sheen > 0.0f && metallic > 0.0f) continue;  // the sheen's lobe is slow to evaluate: one base
                for (float r : {0.1f, 0.5f, 1.0f}) {
                    for (double cos_v : cos_grid) {
                        BrdfInputs in;
                        in.albedo = glm::vec3(1.0f);
                        in.metallic = metallic;
                        in.roughness = r;
                        in.specular_ext = true;
                        in.specular = c.spec;
                        in.specular_color = c.colour;
                        in.clearcoat = c.coat;
                        in.clearcoat_roughness = c.coat_r;
                        in.clearcoat_n = glm::vec3(0, 0, 1);
                        in.sheen_color = glm::vec3(c.sheen);
                        in.sheen_roughness = c.sheen_r;
                        CAPTURE(std::string(brdf_model_name(model))); CAPTURE(std::string(c.label)); CAPTURE(metallic);
                        CAPTURE(r); CAPTURE(cos_v);
                        const double e = albedo_of(in, model, cos_v);
                        if (cos_v >= 0.7) {
                            CHECK(e <= 1.006);
                            max_near = std::max(max_near, e);
                        } else {
                            // F0 0 with F90 1 (a white specularColorFactor of 0)
                            // is the model's known grazing overshoot (test_brdf.cpp:
                            // kd = 1 - F(v.h) is not 1 - E_spec) at its largest:
                            // measured 1.084 with the default BRDF, so its own
                            // bound; --energy conserve below holds today's.
                            const bool f0_zero = c.colour == glm::vec3(0.0f) && model == BrdfModel::Default;
                            CHECK(e <= (f0_zero ? 1.09 : grazing_bound));
                            max_grazing = std::max(max_grazing, e);
                        }
                        in.n = glm::vec3(0, 0, 1);
                        in.v = direction(cos_v, 0.0);
                        apply_energy_terms(in, table);
                        const double ee = albedo_of(in, model, cos_v);
                        const double tol = cos_v > 0.1 ? 0.008 : (cos_v == 0.1 ? 0.015 : 0.03);
                        CHECK(ee <= 1.0 + tol);
                        max_energy = std::max(max_energy, ee);
                    }
                }
            }
        }
        MESSAGE(std::string(brdf_model_name(model)) << " with the new lobes at their extremes: max albedo " << max_near
                                       << " for n.v >= 0.7, " << max_grazing << " below; --energy conserve max "
                                       << max_energy);
    }
}

TEST_CASE("white furnace under a uniform sky: split sum and reference with the coat and the specular extension") {
    const Environment& env = white_or_sky_env(true);
    const glm::vec3 n(0.0f, 1.0f, 0.0f);
    for (BrdfModel model : {BrdfModel::Default, BrdfModel::Gltf}) {
        double max_energy = 0, max_plain = 0, worst_ref = 0, min_energy = 9;
        for (float metallic : {0.0f, 1.0f}) {
            for (float coat_r : {0.045f, 0.3f, 1.0f}) {
                for (float r : {0.1f, 0.5f, 1.0f}) {
                    for (double cos_v : {1.0, 0.7, 0.4, 0.15}) {
                        const glm::vec3 v = view_about(n, cos_v, 0.3);
                        CAPTURE(std::string(brdf_model_name(model))); CAPTURE(metallic); CAPTURE(coat_r); CAPTURE(r); CAPTURE(cos_v);
                        for (bool energy : {false, true}) {
                            IblPoint p = make_ibl_point(env, n, v, glm::vec3(1.0f), metallic, r, energy, model);
                            p.ms.clearcoat = 1.0f;
                            p.ms.clearcoat_roughness = coat_r;
                            p.ms.has_specular = true;
                            p.ms.specular_color = glm::vec3(100.0f);  // dielectric F0 = 1: the brightest
                            p.ms.sheen_color = glm::vec3(1.0f);         // and a white sheen between
                            p.ms.sheen_roughness = 0.5f;
                            const glm::vec3 lo = shade_surface(p.ms, p.sp, p.ctx);
                            if (!energy) {
                                max_plain = std::max(max_plain, double(lo.x));
                                CHECK(lo.x <= 1.75f);  // today's plain bound (test_ibl.cpp)
                                continue;
                            }
                            max_energy = std::max(max_energy, double(lo.x));
                            min_energy = std::min(min_energy, double(lo.x));
                            CHECK(lo.x <= 1.0f + 2e-3f);
                            if (cos_v >= 0.15) {
                                const glm::vec3 ref = ibl_reference(p.ms, p.sp, p.ctx, 2048);
                                worst_ref = std::max(worst_ref, double(ref.x) - 1.0);
                                CHECK(ref.x <= 1.0f + 0.02f);
                            }
                        }
                    }
                }
            }
        }
        MESSAGE(std::string(brdf_model_name(model)) << " uniform sky, coat 1 over a white sheen over a white F0 = 1 dielectric or metal: plain max "
                                       << max_plain << "; --energy conserve in [" << min_energy << ", " << max_energy
                                       << "] (split sum), reference max excess " << worst_ref);
    }
}

TEST_CASE("split sum against the reference integral: the coat and the specular colour") {
    // Relative luminance error of the environment's share (no lights), as
    // test_ibl.cpp measures the base lobe, albedo (0.9, 0.6, 0.4), metallic
    // 0, base roughness 0.5, four normals, n.v 0.95 .. 0.15. The reference
    // takes 8192 directions. Bounds: measured plus a margin.
    const Environment& env = white_or_sky_env(false);
    const glm::vec3 normals[] = {{0, 1, 0}, glm::normalize(glm::vec3(0.6f, 0.5f, -0.6f)), {1, 0, 0},
                                 glm::normalize(glm::vec3(-0.3f, -0.2f, 0.9f))};
    struct Case { const char* label; float coat, coat_r; bool spec; double mean, max_near, max_all; float sheen_r = -1.0f; };
    const Case cases[] = {
        {"coat 1 rough 0.1", 1.0f, 0.1f, false, 0.015, 0.03, 0.03},
        {"coat 1 rough 0.4", 1.0f, 0.4f, false, 0.02, 0.02, 0.07},
        {"coat 1 rough 1", 1.0f, 1.0f, false, 0.015, 0.025, 0.05},
        {"specular 0.7 colour (2, 1, 0.4)", 0.0f, 0.0f, true, 0.015, 0.02, 0.025},
        // The sheen's split sum (E times the irradiance) is the coarsest.
        {"sheen (1, 0.8, 0.6) rough 0.3", 0.0f, 0.0f, false, 0.09, 0.12, 0.26, 0.3f},
        {"sheen (1, 0.8, 0.6) rough 0.8", 0.0f, 0.0f, false, 0.09, 0.17, 0.17, 0.8f},
    };
    for (const Case& c : cases) {
        double sum = 0, worst = 0, worst_near = 0;
        int count = 0;
        for (double cos_v : {0.95, 0.7, 0.4, 0.15}) {
            for (const glm::vec3& n : normals) {
                const glm::vec3 v = view_about(n, cos_v, 0.7);
                IblPoint p = make_ibl_point(env, n, v, glm::vec3(0.9f, 0.6f, 0.4f), 0.0f, 0.5f, false, BrdfModel::Default);
                p.ms.clearcoat = c.coat;
                p.ms.clearcoat_roughness = c.coat_r;
                if (c.sheen_r >= 0.0f) {
                    p.ms.sheen_color = glm::vec3(1.0f, 0.8f, 0.6f);
                    p.ms.sheen_roughness = c.sheen_r;
                }
                if (c.spec) {
                    p.ms.has_specular = true;
                    p.ms.specular = 0.7f;
                    p.ms.specular_color = glm::vec3(2.0f, 1.0f, 0.4f);
                }
                const glm::vec3 split = ibl_sum(ibl_terms(p.ms, p.sp, p.ctx));
                const glm::vec3 ref = ibl_reference(p.ms, p.sp, p.ctx, 8192);
                const double err = std::fabs(double(lum(split)) - lum(ref)) / std::max(1e-3, double(lum(ref)));
                sum += err;
                ++count;
                if (cos_v >= 0.4) worst_near = std::max(worst_near, err);
                worst = std::max(worst, err);
            }
        }
        const double mean = sum / count;
        MESSAGE(std::string(c.label) << ": split sum vs reference, relative luminance error mean " << mean << ", max "
                        << worst_near << " for n.v >= 0.4, max " << worst << " overall");
        CAPTURE(std::string(c.label));
        CHECK(mean <= c.mean);
        CHECK(worst_near <= c.max_near);
        CHECK(worst <= c.max_all);
    }
}

TEST_CASE("files: without the extensions, with clearcoatFactor 0 or default specular (no environment) the same bytes") {
    test::TempDir dir("material_lobes");
    auto scene_with = [&](const json& ext, const std::string& name) {
        GltfWriter g;
        add_sphere(g, add_material(g, grey(ext)));
        g.scene_of_meshes();
        return load(dir, g, name);
    };
    const Scene plain = scene_with(json(), "plain.gltf");
    const Scene coat0 = scene_with({{"KHR_materials_clearcoat", {{"clearcoatFactor", 0}, {"clearcoatRoughnessFactor", 0.3}}}},
                                   "coat0.gltf");
    const Scene spec1 = scene_with({{"KHR_materials_specular", json::object()}}, "spec1.gltf");
    const Scene coat = scene_with({{"KHR_materials_clearcoat", {{"clearcoatFactor", 1}}}}, "coat.gltf");
    const Scene sheen0 = scene_with({{"KHR_materials_sheen", {{"sheenRoughnessFactor", 0.5}}}}, "sheen0.gltf");
    const Scene sheen = scene_with({{"KHR_materials_sheen", {{"sheenColorFactor", {1, 0.5, 0.5}}}}}, "sheen.gltf");
    CHECK_FALSE(sheen0.materials[0].has_sheen);
    CHECK(sheen.materials[0].has_sheen);
    CHECK(coat0.warnings.empty());
    CHECK_FALSE(coat0.materials[0].has_clearcoat);
    CHECK(spec1.materials[0].has_specular);
    CHECK(coat.materials[0].has_clearcoat);
    for (bool env : {false, true}) {
        const std::vector<float> a = draw(plain, env);
        CAPTURE(env);
        CHECK(draw(coat0, env) == a);
        if (!env) CHECK(draw(spec1, env) == a);  // the split sum's diffuse weight is rounded differently
        CHECK(draw(coat, env) != a);
        CHECK(draw(sheen0, env) == a);
        CHECK(draw(sheen, env) != a);
    }
}

TEST_CASE("files: the coat darkens the emission by 1 - F_coat(n.v), and textures, UV sets and transforms reach the lobes") {
    test::TempDir dir("material_lobes");
    GltfWriter g;
    const int mat = add_material(g, {{"pbrMetallicRoughness", {{"baseColorFactor", {0, 0, 0, 1}}, {"metallicFactor", 0}}},
                                     {"emissiveFactor", {0.5, 0.25, 1.0}},
                                     {"extensions", {{"KHR_materials_clearcoat", {{"clearcoatFactor", 1}}},
                                                     {"KHR_materials_specular", {{"specularFactor", 0}}}}}});
    add_quad(g, mat);
    g.scene_of_meshes();
    const Scene scene = load(dir, g, "emissive.gltf");
    CHECK(scene.warnings.empty());
    Renderer r({1, 16});
    SceneRenderer sr(scene, r);
    FrameSettings fs;
    fs.camera.eye = {0.0f, 0.0f, 3.0f};
    fs.camera.target = {0.0f, 0.0f, 0.0f};
    fs.camera.orthographic = true;
    fs.camera.ortho_ymag = 1.0f;
    fs.ambient = glm::vec3(0.0f);
    fs.scene_environment = false;
    fs.lights.clear();
    Framebuffer fb(32, 32);
    sr.render(fs, fb);
    // The centre pixel: v within 0.01 of n, F_coat = 0.04 + 0.96 (1 - n.v)^5 ~ 0.04.
    const float* p = &fb.color[(16 * 32 + 16) * 4];
    CHECK(p[0] == doctest::Approx(0.5 * 0.96).epsilon(1e-4));
    CHECK(p[1] == doctest::Approx(0.25 * 0.96).epsilon(1e-4));
    CHECK(p[2] == doctest::Approx(1.0 * 0.96).epsilon(1e-4));

    // Maps: each extension texture read through its sampler, UV set and transform.
    GltfWriter t;
    const int img = t.image_png(pattern_png(1)), img2 = t.image_png(pattern_png(2));
    const int tex = t.texture(img, 9729, 9987), tex2 = t.texture(img2, 9728, 9728);
    const json xf = {{"KHR_texture_transform", {{"scale", {2, 2}}, {"rotation", 0.5}}}};
    const int m2 = add_material(t, grey({{"KHR_materials_specular", {{"specularTexture", {{"index", tex}}},
                                                                     {"specularColorTexture", {{"index", tex2}, {"extensions", xf}}},
                                                                     {"specularColorFactor", {1.5, 1, 0.5}}}},
                                         {"KHR_materials_clearcoat", {{"clearcoatFactor", 0.8},
                                                                      {"clearcoatTexture", {{"index", tex2}}},
                                                                      {"clearcoatRoughnessFactor", 0.5},
                                                                      {"clearcoatRoughnessTexture", {{"index", tex}, {"texCoord", 0}}},
                                                                      {"clearcoatNormalTexture", {{"index", tex}, {"scale", 0.5}}}}},
                                         {"KHR_materials_sheen", {{"sheenColorFactor", {0.9, 0.7, 0.5}}, {"sheenRoughnessFactor", 0.6},
                                                                  {"sheenColorTexture", {{"index", tex2}}},
                                                                  {"sheenRoughnessTexture", {{"index", tex}, {"extensions", xf}}}}}}));
    add_sphere(t, m2);
    t.scene_of_meshes();
    const Scene mapped = load(dir, t, "maps.gltf");
    CHECK(mapped.warnings.empty());
    const Material& m = mapped.materials[0];
    CHECK(m.specular_texture.valid());
    CHECK(m.specular_color_texture.transform.present);
    CHECK(m.clearcoat_normal_texture.valid());
    CHECK(m.clearcoat_normal_scale == 0.5f);
    CHECK(m.specular_color_factor == glm::vec3(1.5f, 1.0f, 0.5f));
    CHECK(m.sheen_roughness_texture.transform.present);
    CHECK(m.sheen_color_texture.valid());
    // Same bytes for 1 and 3 threads, and different from the factors alone.
    const std::vector<float> a = draw(mapped, true, 1);
    CHECK(draw(mapped, true, 3) == a);
    Scene bare = mapped;
    for (TextureRef* ref : {&bare.materials[0].specular_texture, &bare.materials[0].specular_color_texture,
                            &bare.materials[0].clearcoat_texture, &bare.materials[0].clearcoat_roughness_texture,
                            &bare.materials[0].clearcoat_normal_texture, &bare.materials[0].sheen_color_texture,
                            &bare.materials[0].sheen_roughness_texture})
        ref->image = -1;
    CHECK(draw(bare, true, 1) != a);
    for (float x : a) CHECK(std::isfinite(x));
}

TEST_CASE("hostile values: out of range, mistyped and non-finite factors and textures are one warning each, drawn finite") {
    test::TempDir dir("material_lobes");
    GltfWriter g;
    const int a = add_material(g, grey({{"KHR_materials_specular", {{"specularFactor", -1}, {"specularColorFactor", {-1, 2, 3}}}},
                                        {"KHR_materials_clearcoat", {{"clearcoatFactor", 1e39}, {"clearcoatRoughnessFactor", 7}}}}));
    const int b = add_material(g, grey({{"KHR_materials_specular", {{"specularFactor", "x"}, {"specularColorFactor", {1, "y", 1}},
                                                                    {"specularTexture", {{"index", 99}}}}},
                                        {"KHR_materials_clearcoat", {{"clearcoatFactor", 0.5}, {"clearcoatTexture", "z"},
                                                                     {"clearcoatNormalTexture", {{"index", 0}, {"scale", "w"}}},
                                                                     {"clearcoatRoughnessTexture", {{"index", -3}}}}}}));
    const int c = add_material(g, grey({{"KHR_materials_specular", 5}, {"KHR_materials_clearcoat", json::array()},
                                        {"KHR_materials_sheen", {{"sheenColorFactor", {2, -1, 0.5}}, {"sheenRoughnessFactor", -0.5}}}}));
    const int d = add_material(g, grey({{"KHR_materials_sheen", {{"sheenColorFactor", {1, 1}}, {"sheenColorTexture", 3}}}}));
    add_sphere(g, d);
    add_sphere(g, a);
    add_sphere(g, b);
    add_sphere(g, c);
    g.scene_of_meshes();
    const Scene s = load(dir, g, "hostile.gltf");
    for (const std::string& w : s.warnings) MESSAGE(w);
    CHECK(has_warning(s, "specularFactor -1"));
    CHECK(has_warning(s, "negative specularColorFactor"));
    CHECK(has_warning(s, "clearcoatFactor 1e+39 outside [0, 1], clamped to 1"));
    CHECK(has_warning(s, "clearcoatRoughnessFactor 7"));
    CHECK(has_warning(s, "bad specularFactor"));
    CHECK(has_warning(s, "bad specularColorFactor"));
    CHECK(has_warning(s, "specularTexture: texture 99 out of range"));
    CHECK(has_warning(s, "clearcoatTexture: not a textureInfo"));
    CHECK(has_warning(s, "bad scale"));
    CHECK(has_warning(s, "clearcoatRoughnessTexture: texture index not a non-negative integer"));
    // (tinygltf drops an extension that is not an object: material 2 has neither.)
    for (const std::string& w : s.warnings) CHECK(w.find('\n') == std::string::npos);
    const Material& ma = s.materials[0];
    CHECK(ma.specular_factor == 0.0f);
    CHECK(ma.specular_color_factor == glm::vec3(0.0f, 2.0f, 3.0f));
    CHECK(ma.clearcoat_factor == 1.0f);
    CHECK(ma.clearcoat_roughness_factor == 1.0f);
    const Material& mb = s.materials[1];
    CHECK(mb.specular_factor == 1.0f);
    CHECK(mb.specular_color_factor == glm::vec3(1.0f));
    CHECK(mb.clearcoat_normal_scale == 1.0f);
    CHECK_FALSE(s.materials[2].has_specular);
    CHECK_FALSE(s.materials[2].has_clearcoat);
    CHECK(has_warning(s, "sheenColorFactor outside [0, 1], clamped"));
    CHECK(has_warning(s, "sheenRoughnessFactor -0.5 outside [0, 1], clamped to 0"));
    CHECK(has_warning(s, "bad sheenColorFactor (not three finite numbers), [0, 0, 0] used"));
    CHECK(has_warning(s, "sheenColorTexture: not a textureInfo"));
    CHECK(s.materials[2].sheen_color_factor == glm::vec3(1.0f, 0.0f, 0.5f));
    CHECK(s.materials[2].has_sheen);
    CHECK_FALSE(s.materials[3].has_sheen);
    for (float x : draw(s, true)) REQUIRE(std::isfinite(x));
}

TEST_CASE("step: the breakdown shows the coat and specular terms, its srgb8 equals render's PNG, and verify passes") {
    using namespace prast::cli_test;
    CliSandbox box;
    GltfWriter g;
    const int img = g.image_png(pattern_png(3));
    const int tex = g.texture(img, 9729, 9987);
    const int mat = add_material(g, grey({{"KHR_materials_specular", {{"specularFactor", 0.7}, {"specularColorFactor", {1.5, 1, 0.5}},
                                                                      {"specularColorTexture", {{"index", tex}}}}},
                                          {"KHR_materials_clearcoat", {{"clearcoatFactor", 0.9}, {"clearcoatRoughnessFactor", 0.2},
                                                                       {"clearcoatNormalTexture", {{"index", tex}}}}},
                                          {"KHR_materials_sheen", {{"sheenColorFactor", {0.8, 0.6, 1.0}}, {"sheenRoughnessFactor", 0.4},
                                                                   {"sheenColorTexture", {{"index", tex}}}}}}));
    add_sphere(g, mat);
    g.scene_of_meshes();
    const std::string file = box.path("lobes.gltf");
    write_text(file, g.text());
    // step reads files inside the model's folder only.
    fs::copy_file(std::string(PRAST_SOURCE_DIR) + "/assets/env/studio_small.hdr", box.path("studio.hdr"));
    const std::string env = box.path("studio.hdr");
    for (const std::vector<std::string>& extra :
         {std::vector<std::string>{}, std::vector<std::string>{"--env", env, "--energy", "conserve", "--brdf", "gltf"}}) {
        std::vector<std::string> flags = {file, "--eye", "0.3,0.4,3", "--target", "0,0,0", "--size", "40x32",
                                          "--msaa", "1", "--sun", "0.3,0.5,1:2,2,2"};
        flags.insert(flags.end(), extra.begin(), extra.end());
        const StepAgainstRender r = step_pixels_match_render(box, flags, 4, 6);
        const std::string& out = r.step.out;
        INFO(out.substr(0, 4000));
        CHECK(out.find("KHR_materials_specular: specular 0.7") != std::string::npos);
        CHECK(out.find("KHR_materials_clearcoat: clearcoat 0.9") != std::string::npos);
        CHECK(out.find("(its own normal map, scale 1)") != std::string::npos);
        CHECK(out.find(extra.empty() ? "    clear coat: n_c.l " : "    clear coat: prefiltered ") != std::string::npos);
        CHECK(out.find("map specularColorTexture") != std::string::npos);
        CHECK(out.find("KHR_materials_sheen: colour ") != std::string::npos);
        CHECK(out.find(extra.empty() ? "    sheen: D " : "    sheen: irradiance ") != std::string::npos);
        CHECK(r.lit > 10);
    }
}

} // TEST_SUITE

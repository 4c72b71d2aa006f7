// Image-based lighting held to numbers: the equirect mapping of the
// conventions, the DFG table against direct quadrature, white furnaces (split
// sum and reference, plain and --energy conserve), a mirror returning the
// environment, the SH irradiance of a sky step pixel by pixel (exact for order
// 2) and of a small sun (the order-2 bound), the split sum against the
// reflectance integral on a procedural environment and on the venice HDR,
// filtered importance sampling without fireflies, and determinism of every
// precomputed byte for any thread count.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "raster/thread_pool.h"
#include "scene/load_environment.h"
#include "scene/mesh_gen.h"
#include "shading/ibl/dfg.h"
#include "shading/ibl/environment.h"
#include "shading/ibl/ibl_sampling.h"
#include "shading/ibl/prefilter.h"
#include "renderer/scene_renderer.h"
#include "shading/surface.h"
#include "tests/ibl_test_util.h"

using namespace prast;
namespace fs = std::filesystem;
using prast::test::IblPoint;
using prast::test::make_env;
using prast::test::make_ibl_point;
using prast::test::pool2;

namespace {

Image uniform_env(float L, int w = 64) {
    return make_env(w, [L](const glm::dvec3&) { return glm::vec3(L); });
}

// 1 above the horizon, 0 below: with an even height the horizon is a row
// boundary, so the texels hold the step exactly.
Image sky_step_env(int w = 256) {
    return make_env(w, [](const glm::dvec3& d) { return glm::vec3(d.y > 0.0 ? 1.0f : 0.0f); });
}

// A procedural sky: a blue gradient, a bright soft sun (peak 40, about 3
// degrees wide), a warm ground and a coloured band, so that every lobe sees
// structure.
const glm::dvec3 kProceduralSun = glm::normalize(glm::dvec3(0.5, 0.35, -0.6));
Image procedural_env(int w = 512) {
    return make_env(w, [](const glm::dvec3& d) {
        const double up = std::max(d.y, 0.0);
        glm::dvec3 c = d.y > 0.0 ? glm::mix(glm::dvec3(0.8, 0.85, 0.9), glm::dvec3(0.15, 0.3, 0.7), std::sqrt(up))
                                 : glm::dvec3(0.3, 0.22, 0.15) * (1.0 + 0.5 * d.y);
        const double a = std::acos(std::clamp(glm::dot(d, kProceduralSun), -1.0, 1.0));
        c += glm::dvec3(40.0, 36.0, 30.0) * std::exp(-a * a / (2.0 * 0.025 * 0.025));
        c += glm::dvec3(0.6, 0.1, 0.1) * std::exp(-std::pow((d.x - 0.7) / 0.1, 2.0));
        return glm::vec3(c);
    });
}

const Environment& shared_env(const char* which) {
    static const Environment uniform1 = Environment::build(uniform_env(1.0f), {1.0f, 0.0f, true}, pool2());
    static const Environment procedural = Environment::build(procedural_env(), {1.0f, 0.0f, true}, pool2());
    return std::strcmp(which, "uniform") == 0 ? uniform1 : procedural;
}

// The tables by DFG model: the ones the BRDF models read (built once).
const DfgTable& shared_dfg(DfgModel m) {
    return prast::test::dfg_for(m == DfgModel::SchlickIbl ? BrdfModel::Default : BrdfModel::Gltf);
}

// v at angle acos(cos_v) from n, turned by phi about n.
glm::vec3 view_about(const glm::vec3& n, double cos_v, double phi) {
    const Frame f{glm::dvec3(n)};
    const double s = std::sqrt(std::max(0.0, 1.0 - cos_v * cos_v));
    return glm::vec3(glm::normalize(f.to_world({s * std::cos(phi), s * std::sin(phi), cos_v})));
}

float lum(const glm::vec3& c) { return 0.2126f * c.r + 0.7152f * c.g + 0.0722f * c.b; }

std::uint64_t hash_bytes(const void* data, std::size_t n, std::uint64_t h = 1469598103934665603ull) {
    const unsigned char* p = static_cast<const unsigned char*>(data);
    for (std::size_t i = 0; i < n; ++i) h = (h ^ p[i]) * 1099511628211ull;
    return h;
}

std::uint64_t hash_env(const Environment& env) {
    std::size_t n = 0;
    const EquirectLevel& last = env.specular_level(Environment::kSpecularLevels - 1);
    n = std::size_t(last.offset) + std::size_t(last.w) * std::size_t(last.h);
    std::uint64_t h = hash_bytes(env.texels(), n * sizeof(glm::vec4));
    return hash_bytes(&env.sh(), sizeof(ShIrradiance), h);
}

const float kRoughness[] = {0.045f, 0.1f, 0.2f, 0.3f, 0.4f, 0.5f, 0.6f, 0.7f, 0.8f, 0.9f, 1.0f};
const double kCosView[] = {1.0, 0.9, 0.7, 0.5, 0.3, 0.15, 0.05};

} // namespace

TEST_SUITE("ibl") {

TEST_CASE("the equirect mapping follows the conventions") {
    struct Case { glm::vec3 d; float u, v; };
    const Case cases[] = {
        {{0, 0, -1}, 0.5f, 0.5f},   // the centre column looks down -Z
        {{1, 0, 0}, 0.75f, 0.5f},   // u grows towards +X
        {{-1, 0, 0}, 0.25f, 0.5f},
        {{0, 1, 0}, 0.5f, 0.0f},    // row 0 looks straight up
        {{0, -1, 0}, 0.5f, 1.0f},
    };
    for (const Case& c : cases) {
        float u, v;
        equirect_uv(c.d.x, c.d.y, c.d.z, u, v);
        CAPTURE(c.d.x); CAPTURE(c.d.y); CAPTURE(c.d.z);
        CHECK(u == doctest::Approx(c.u).epsilon(1e-6));
        CHECK(v == doctest::Approx(c.v).epsilon(1e-6));
    }
    // The polynomial atan2 against std::atan2 over the whole circle, and the
    // inverse mapping round trip.
    double worst = 0.0, worst_uv = 0.0;
    for (int i = 0; i < 20000; ++i) {
        const double a = (i + 0.5) / 20000 * 2.0 * M_PI - M_PI;
        for (double r : {1e-3, 1.0, 1e3}) {
            const float y = float(r * std::sin(a)), x = float(r * std::cos(a));
            worst = std::max(worst, std::fabs(double(atan2_poly(y, x)) - std::atan2(double(y), double(x))));
        }
        const double u = (i + 0.5) / 20000, v = 0.05 + 0.9 * radical_inverse2(std::uint32_t(i));
        const glm::dvec3 d = equirect_direction(u, v);
        float fu, fv;
        equirect_uv(float(d.x), float(d.y), float(d.z), fu, fv);
        worst_uv = std::max({worst_uv, std::fabs(fu - u), std::fabs(fv - v)});
    }
    MESSAGE("atan2_poly max error " << worst << " rad; uv round trip max error " << worst_uv);
    CHECK(worst < 1e-6);
    CHECK(worst_uv < 1e-6);
}

TEST_CASE("DFG table against direct quadrature of the BRDF") {
    // E_spec with F = 1 (A + B) and with F0 = 0 (B), and Kd, by a midpoint
    // rule over the hemisphere of l (not by the table's own sampling).
    double worst = 0.0;
    for (DfgModel m : {DfgModel::SchlickIbl, DfgModel::HeightCorrelated}) {
        const DfgTable& t = shared_dfg(m);
        for (float r : {0.3f, 0.6f, 1.0f}) {
            for (double cos_v : {0.95, 0.6, 0.25}) {
                const glm::vec3 v(float(std::sqrt(1.0 - cos_v * cos_v)), 0.0f, float(cos_v));
                BrdfInputs in;
                in.n = {0, 0, 1};
                in.v = v;
                in.roughness = r;
                in.ibl_geometry = true;
                in.albedo = glm::vec3(1.0f);
                const BrdfModel model = m == DfgModel::SchlickIbl ? BrdfModel::Default : BrdfModel::Gltf;
                double e1 = 0.0, e0 = 0.0, kd = 0.0;
                const int NT = 512, NP = 256;
                for (int i = 0; i < NT; ++i) {
                    const double th = (i + 0.5) / NT * 0.5 * M_PI;
                    for (int j = 0; j < NP; ++j) {
                        const double ph = (j + 0.5) / NP * 2.0 * M_PI;
                        in.l = glm::vec3(float(std::sin(th) * std::cos(ph)), float(std::sin(th) * std::sin(ph)),
                                         float(std::cos(th)));
                        const double w = std::cos(th) * std::sin(th) * (0.5 * M_PI / NT) * (2.0 * M_PI / NP);
                        in.metallic = 1.0f;  // F0 = 1
                        e1 += double(evaluate_brdf(in, model).specular.x) * w;
                        in.metallic = 0.0f;
                        in.ior = 1.0f;       // F0 = 0
                        const BrdfTerms b = evaluate_brdf(in, model);
                        e0 += double(b.specular.x) * w;
                        kd += double(b.kd.x) / M_PI * w;
                        in.ior = 1.5f;
                    }
                }
                const glm::vec4 ab = t.lookup(float(cos_v), r);
                const double err = std::max({std::fabs(ab.x + ab.y - e1), std::fabs(ab.y - e0), std::fabs(ab.z - kd)});
                CAPTURE(int(m)); CAPTURE(r); CAPTURE(cos_v);
                CHECK(err < 4e-3);
                worst = std::max(worst, err);
            }
        }
    }
    MESSAGE("DFG table vs quadrature: max abs error " << worst);
}

TEST_CASE("white furnace: split sum and reference under a uniform sky of radiance 1") {
    const Environment& env = shared_env("uniform");
    const glm::vec3 n(0.0f, 1.0f, 0.0f);
    for (BrdfModel model : {BrdfModel::Default, BrdfModel::Gltf}) {
        for (float metallic : {0.0f, 1.0f}) {
            double min_plain = 9, max_plain = 0, max_plain_near = 0, worst_energy = 0, worst_ref = 0;
            for (float r : kRoughness) {
                for (double cos_v : kCosView) {
                    const glm::vec3 v = view_about(n, cos_v, 0.3);
                    CAPTURE(std::string(brdf_model_name(model))); CAPTURE(metallic); CAPTURE(r); CAPTURE(cos_v);
                    IblPoint plain = make_ibl_point(env, n, v, glm::vec3(1.0f), metallic, r, false, model);
                    const glm::vec3 lp = shade_surface(plain.ms, plain.sp, plain.ctx);
                    min_plain = std::min(min_plain, double(lp.x));
                    max_plain = std::max(max_plain, double(lp.x));
                    if (cos_v >= 0.7) max_plain_near = std::max(max_plain_near, double(lp.x));
                    IblPoint energy = make_ibl_point(env, n, v, glm::vec3(1.0f), metallic, r, true, model);
                    const glm::vec3 le = shade_surface(energy.ms, energy.sp, energy.ctx);
                    worst_energy = std::max(worst_energy, std::fabs(double(le.x) - 1.0));
                    CHECK(std::fabs(le.x - 1.0f) < 2e-3f);
                    // The reference integral of the energy-conserving BRDF: the
                    // table's compensation holds against the true integral.
                    if (cos_v >= 0.15) {
                        const glm::vec3 ref = ibl_reference(energy.ms, energy.sp, energy.ctx, 2048);
                        worst_ref = std::max(worst_ref, std::fabs(double(ref.x) - 1.0));
                        CHECK(std::fabs(ref.x - 1.0f) < 0.02f);
                    }
                }
            }
            MESSAGE(std::string(brdf_model_name(model)) << " metallic " << metallic << ": plain split sum in [" << min_plain
                                           << ", " << max_plain << "] (max " << max_plain_near
                                           << " for n.v >= 0.7); --energy conserve max |Lo - 1| " << worst_energy
                                           << " (split sum), " << worst_ref << " (reference, n.v >= 0.15)");
            // The plain model, measured: a white metal keeps only its single
            // scattering (down to 0.31 at r = 1 with k = r^2 / 2); a white
            // dielectric stays within 1 near normal incidence and overshoots at
            // grazing views (the conventions' kd, docs/deviations.md).
            if (metallic == 1.0f) {
                CHECK(max_plain <= 1.0 + 2e-4);
                CHECK(min_plain >= 0.30);
                CHECK(min_plain <= 0.32);
            } else {
                CHECK(max_plain_near <= 1.0 + 2e-3);
                CHECK(min_plain >= 0.97);
                CHECK(max_plain <= 1.75);
            }
        }
    }
}

TEST_CASE("white furnace: a rendered sphere under a uniform sky comes out at 1 (energy conserve)") {
    // The lane path end to end: spheres of albedo 1, metallic 0 and 1, rough
    // 0.045 to 1, in front of a uniform environment of radiance 1.
    Scene scene;
    scene.environment = std::make_shared<const Image>(uniform_env(1.0f));
    const float roughness[] = {0.045f, 0.5f, 1.0f};
    for (int row = 0; row < 2; ++row)
        for (int col = 0; col < 3; ++col) {
            Material m;
            m.base_color_factor = glm::vec4(1.0f);
            m.metallic_factor = float(row);
            m.roughness_factor = roughness[col];
            scene.materials.push_back(m);
            scene.meshes.push_back(make_uv_sphere(glm::vec3(float(col) - 1.0f, float(row) - 0.5f, 0.0f), 0.4f, 48, 24,
                                                  int(scene.materials.size() - 1)));
        }
    Renderer r({2, 64});
    SceneRenderer sr(scene, r);
    FrameSettings fs;
    fs.camera.eye = {0.0f, 0.0f, 6.0f};
    fs.camera.target = {0.0f, 0.0f, 0.0f};
    fs.camera.fov_y_deg = 30.0f;
    fs.energy = true;
    fs.background = Background::Black;
    Framebuffer fb(240, 160);
    sr.render(fs, fb);
    double worst = 0.0;
    int covered = 0;
    for (int i = 0; i < fb.width * fb.height; ++i) {
        if (fb.depth[std::size_t(i)] >= 1.0f) continue;
        ++covered;
        for (int c = 0; c < 3; ++c) worst = std::max(worst, std::fabs(double(fb.color[std::size_t(i) * 4 + c]) - 1.0));
    }
    MESSAGE("rendered furnace: " << covered << " pixels, max |Lo - 1| = " << worst);
    CHECK(covered > 3000);
    CHECK(worst < 3e-3);
}

TEST_CASE("a mirror returns the environment") {
    // Metallic 1, roughness 0 (clamped to 0.045: the specular level 0, i.e.
    // the source itself), albedo 1. With --energy conserve the lobe's albedo
    // is exactly 1, so Lo is the environment along the lookup direction to
    // float precision, and that direction is the mirror's bent by
    // alpha^2 = 4e-6 towards n; without, Lo is A + B of r = 0.045 (shadowing
    // near grazing) times it.
    const Environment& env = shared_env("procedural");
    double worst_exact = 0.0, worst_energy = 0.0, worst_plain = 0.0;
    for (int i = 0; i < 400; ++i) {
        const glm::dvec3 nd = equirect_direction((i + 0.5) / 400.0, 0.05 + 0.9 * radical_inverse2(std::uint32_t(i)));
        const glm::vec3 n = glm::vec3(nd);
        for (double cos_v : {1.0, 0.8, 0.5, 0.3}) {
            const glm::vec3 v = view_about(n, cos_v, 1.0 + i);
            IblPoint p = make_ibl_point(env, n, v, glm::vec3(1.0f), 1.0f, 0.0f, true);
            const IblTerms t = ibl_terms(p.ms, p.sp, p.ctx);
            const glm::vec3 mirror = n * (2.0f * glm::dot(n, v)) - v;
            const glm::vec3 expect = env.radiance(mirror);
            const glm::vec3 along = env.radiance(t.R);
            worst_exact = std::max(worst_exact, double(glm::length(shade_surface(p.ms, p.sp, p.ctx) - along)) /
                                                    std::max(1e-3, double(glm::length(along))));
            const glm::vec3 got = shade_surface(p.ms, p.sp, p.ctx);
            const double e = std::fabs(double(lum(got)) - lum(expect)) / std::max(1e-3, double(lum(expect)));
            worst_energy = std::max(worst_energy, e);
            IblPoint q = make_ibl_point(env, n, v, glm::vec3(1.0f), 1.0f, 0.0f, false);
            const glm::vec3 plain = shade_surface(q.ms, q.sp, q.ctx);
            worst_plain = std::max(worst_plain, std::fabs(double(lum(plain)) - lum(expect)) /
                                                    std::max(1e-3, double(lum(expect))));
        }
    }
    MESSAGE("mirror: max relative error against the environment along R " << worst_energy
                                                                          << " (energy conserve), " << worst_plain
                                                                          << " (plain, n.v >= 0.3); against the "
                                                                             "lookup direction "
                                                                          << worst_exact);
    CHECK(worst_exact < 1e-5);
    CHECK(worst_energy < 1e-3);
    CHECK(worst_plain < 0.03);
}

TEST_CASE("the prefiltered map at roughness 0 is the source") {
    Image img = procedural_env(256);
    const Environment env = Environment::build(img, {}, pool2());
    const EquirectLevel& L0 = env.specular_level(0);
    REQUIRE(L0.w == img.width);
    REQUIRE(L0.h == img.height);
    bool same = true;
    for (int y = 0; y < img.height; ++y)
        for (int x = 0; x < img.width; ++x) {
            const glm::vec4 t = env.texels()[std::size_t(L0.offset) + std::size_t(y) * img.width + x];
            const glm::vec4 s = img.at(x, y);
            same &= t.r == s.r && t.g == s.g && t.b == s.b;
        }
    CHECK(same);
    bool lookups = true;
    for (int i = 0; i < 1000; ++i) {
        const glm::vec3 d(equirect_direction(radical_inverse3(std::uint32_t(i)), radical_inverse2(std::uint32_t(i))));
        const glm::vec3 a = env.prefiltered(d, 0.0f), b = env.radiance(d);
        lookups &= a == b;
    }
    CHECK(lookups);
    CHECK(Environment::roughness_lod(kMinPerceptualRoughness) == 0.0f);
}

TEST_CASE("SH irradiance of a sky step is (1 + n.y) / 2, pixel by pixel on a rendered sphere") {
    // Order 2 cannot hold the step itself, but the clamped-cosine kernel has
    // no odd bands above 1 and the step is odd apart from its mean: its
    // irradiance is exactly 1/2 + n.y / 2, so the only error left is the
    // quadrature of the projection.
    Scene scene;
    scene.environment = std::make_shared<const Image>(sky_step_env());
    Material m;
    m.base_color_factor = glm::vec4(1.0f);
    scene.materials.push_back(m);
    scene.meshes.push_back(make_uv_sphere(glm::vec3(0.0f), 1.0f, 64, 32, 0));
    Renderer r({2, 64});
    SceneRenderer sr(scene, r);
    FrameSettings fs;
    fs.camera.eye = {0.0f, 1.5f, 4.0f};
    fs.camera.target = {0.0f, 0.0f, 0.0f};
    fs.camera.fov_y_deg = 40.0f;
    Framebuffer irr(160, 160), nrm(160, 160);
    fs.view = DebugView::Irradiance;
    sr.render(fs, irr);
    fs.view = DebugView::Normal;
    sr.render(fs, nrm);
    double worst = 0.0;
    int covered = 0;
    for (int i = 0; i < 160 * 160; ++i) {
        if (irr.depth[std::size_t(i)] >= 1.0f) continue;
        ++covered;
        const glm::vec3 n = glm::normalize(glm::vec3(nrm.color[std::size_t(i) * 4], nrm.color[std::size_t(i) * 4 + 1],
                                                     nrm.color[std::size_t(i) * 4 + 2]) * 2.0f - 1.0f);
        const double expect = 0.5 + 0.5 * n.y;  // albedo 1 x (1 + n.y) / 2
        for (int c = 0; c < 3; ++c)
            worst = std::max(worst, std::fabs(double(irr.color[std::size_t(i) * 4 + c]) - expect));
    }
    MESSAGE("sky step: " << covered << " pixels, max |E/pi - (1 + n.y)/2| = " << worst);
    CHECK(covered > 8000);
    CHECK(worst < 1e-3);
}

TEST_CASE("SH irradiance of a small sun: the order-2 error bound") {
    // A sun of 0.5 degrees: its exact irradiance is E_sun max(0, n.s); order 2
    // gives E_sun (1/4 + x/2 + 5/32 (3x^2 - 1)) with x = n.s, off by at most
    // 3/32 = 0.094 E_sun (at x = 0) and -0.040 E_sun (at x = -8/15).
    const glm::dvec3 s = glm::normalize(glm::dvec3(0.3, 0.8, -0.5));
    const Image img = make_env(1024, [&](const glm::dvec3& d) {
        return glm::vec3(glm::dot(d, s) > std::cos(0.5 * M_PI / 180.0) ? 1000.0f : 0.0f);
    });
    const Environment env = Environment::build(img, {}, pool2());
    // E_sun / pi: the source's own sum over its texels (what the SH saw).
    double e_sun = 0.0;
    for (int y = 0; y < img.height; ++y) {
        const double omega = 2.0 * M_PI / img.width * (std::cos(M_PI * y / img.height) - std::cos(M_PI * (y + 1) / img.height));
        for (int x = 0; x < img.width; ++x) e_sun += img.at(x, y).r * omega;
    }
    e_sun /= M_PI;
    double worst = 0.0, worst_x = 0.0;
    for (int i = 0; i <= 200; ++i) {
        const double x = -1.0 + 2.0 * i / 200.0;
        const Frame f(s);
        const glm::dvec3 n = f.to_world({std::sqrt(std::max(0.0, 1.0 - x * x)), 0.0, x});
        const double got = env.irradiance(glm::vec3(n)).r, exact = e_sun * std::max(0.0, x);
        const double err = std::fabs(got - exact) / e_sun;
        if (err > worst) { worst = err; worst_x = x; }
    }
    MESSAGE("small sun: max |SH - exact| = " << worst << " E_sun at n.s = " << worst_x << " (theory 0.094 at 0)");
    CHECK(worst < 0.094 + 0.005);
    CHECK(worst > 0.085);  // the known ringing really is there
}

TEST_CASE("split sum against the reference integral") {
    // Relative error of the luminance of Lo (the environment's share: no
    // lights) over roughness 0.1..1, n.v 0.95..0.15 and four normals, with
    // albedo (0.9, 0.6, 0.4). The reference uses 8192 directions; against
    // 65536 it moves by < 0.5% at the worst points (and BRDF sampling alone
    // with 4M directions agrees), so what is measured is the split sum's own
    // error: largest on rough metals seen at grazing angles, whose stretched
    // lobe is far from the prefilter's n = v = R (the worst: a wall facing +X
    // seen from above, r = 0.7, where the true lobe reaches venice's sun on
    // the horizon and the prefiltered one sees the ground: 0.08 for 0.16).
    // Bounds: measured plus a margin.
    struct Env { std::string name; const Environment* env; };
    std::vector<Env> envs = {{"procedural", &shared_env("procedural")}};
    static std::unique_ptr<Environment> venice;
    const fs::path venice_path = fs::path(PRAST_SHARED_ASSETS) / "venice-sunset-1k/venice_sunset_1k.hdr";
    if (fs::exists(venice_path)) {
        if (!venice)
            venice = std::make_unique<Environment>(
                Environment::build(load_environment_hdr(venice_path.string()), {1.0f, 0.0f, true}, pool2()));
        envs.push_back({"venice", venice.get()});
    } else {
        MESSAGE("skipped venice: " << venice_path.string() << " is absent");
    }
    struct Bound { const char* env; float metallic; double mean, max_near, max_all; };
    const Bound bounds[] = {
        {"procedural", 0.0f, 0.010, 0.015, 0.035}, {"procedural", 1.0f, 0.050, 0.20, 0.30},
        {"venice", 0.0f, 0.022, 0.055, 0.070},     {"venice", 1.0f, 0.11, 0.60, 0.70},
    };
    const glm::vec3 normals[] = {{0, 1, 0}, glm::normalize(glm::vec3(0.6f, 0.5f, -0.6f)), {1, 0, 0},
                                 glm::normalize(glm::vec3(-0.3f, -0.2f, 0.9f))};
    for (const Env& e : envs) {
        for (float metallic : {0.0f, 1.0f}) {
            double sum = 0.0, worst = 0.0, worst_near = 0.0;
            int count = 0;
            float worst_r = 0;
            double worst_cos = 0;
            for (float r : {0.1f, 0.3f, 0.5f, 0.7f, 1.0f}) {
                for (double cos_v : {0.95, 0.7, 0.4, 0.15}) {
                    for (const glm::vec3& n : normals) {
                        const glm::vec3 v = view_about(n, cos_v, 0.7);
                        IblPoint p = make_ibl_point(*e.env, n, v, glm::vec3(0.9f, 0.6f, 0.4f), metallic, r, false);
                        const IblTerms t = ibl_terms(p.ms, p.sp, p.ctx);
                        const glm::vec3 split = t.diffuse + t.specular;
                        const glm::vec3 ref = ibl_reference(p.ms, p.sp, p.ctx, 8192);
                        const double err = std::fabs(double(lum(split)) - lum(ref)) / std::max(1e-3, double(lum(ref)));
                        sum += err;
                        ++count;
                        if (cos_v >= 0.4) worst_near = std::max(worst_near, err);
                        if (err > worst) { worst = err; worst_r = r; worst_cos = cos_v; }
                    }
                }
            }
            const double mean = sum / count;
            MESSAGE(e.name << " metallic " << metallic << ": split sum vs reference, relative luminance error mean "
                           << mean << ", max " << worst_near << " for n.v >= 0.4, max " << worst << " overall (r "
                           << worst_r << ", n.v " << worst_cos << ")");
            for (const Bound& b : bounds) {
                if (e.name != b.env || metallic != b.metallic) continue;
                CAPTURE(e.name); CAPTURE(metallic);
                CHECK(mean <= b.mean);
                CHECK(worst_near <= b.max_near);
                CHECK(worst <= b.max_all);
            }
        }
    }
}

TEST_CASE("filtered importance sampling: the prefiltered venice sun makes no fireflies") {
    const fs::path venice_path = fs::path(PRAST_SHARED_ASSETS) / "venice-sunset-1k/venice_sunset_1k.hdr";
    Image img;
    if (fs::exists(venice_path)) {
        img = load_environment_hdr(venice_path.string());
    } else {
        MESSAGE("venice absent: using a procedural map with a 2000x sun instead");
        img = make_env(1024, [](const glm::dvec3& d) {
            return glm::vec3(glm::dot(d, kProceduralSun) > 0.9999 ? 2000.0f : 0.5f);
        });
    }
    const Environment env = Environment::build(img, {}, pool2());
    EquirectLevel mips[32];
    for (int k = 0; k < env.source_levels(); ++k) mips[k] = env.source_level(k);
    // Each level's filter (its roughness and sample count), on a 128x64 grid
    // of directions, against the same filter with 16 times the samples: with
    // FIS both are the same smooth function. Without it (mips limited to
    // level 0), the few samples that hit the sun make fireflies: texels many
    // times brighter than the converged value.
    for (int level = 1; level < Environment::kSpecularLevels; ++level) {
        const std::size_t base = std::size_t(mips[env.source_levels() - 1].offset) + 1;
        std::vector<glm::vec4> texels(env.texels(), env.texels() + base);
        EquirectLevel out[3];
        for (EquirectLevel& o : out) {
            o.w = 128; o.h = 64; o.fw = 128.0f; o.fh = 64.0f;
            o.offset = std::int32_t(texels.size());
            texels.resize(texels.size() + 128 * 64);
        }
        const float r = Environment::level_roughness(level);
        const int n = Environment::kSpecularSamples[level];
        prefilter_ggx(texels.data(), mips, env.source_levels(), r, n, out[0], pool2());
        prefilter_ggx(texels.data(), mips, env.source_levels(), r, n * 16, out[1], pool2());
        prefilter_ggx(texels.data(), mips, 1, r, n, out[2], pool2());
        double over = 0.0, over_nofis = 0.0, mean = 0.0;
        for (int i = 0; i < 128 * 64; ++i) {
            const double ref = lum(glm::vec3(texels[std::size_t(out[1].offset) + i]));
            const double a = lum(glm::vec3(texels[std::size_t(out[0].offset) + i]));
            const double b = lum(glm::vec3(texels[std::size_t(out[2].offset) + i]));
            over = std::max(over, a / std::max(ref, 1e-3));
            over_nofis = std::max(over_nofis, b / std::max(ref, 1e-3));
            mean += std::fabs(a - ref) / std::max(ref, 1e-3);
        }
        mean /= 128 * 64;
        MESSAGE("level " << level << " (r " << r << ", " << n << " samples): brightest texel / converged "
                         << over << " with FIS (mean relative difference " << mean << "), " << over_nofis
                         << " without");
        CHECK(over < 1.4);
        CHECK(mean < 0.06);
        CHECK(over_nofis > 2.0);
    }
}

TEST_CASE("precomputation is byte-identical for 1, 2 and 3 threads") {
    const Image img = procedural_env(300);  // odd-sized mips on the way down
    ThreadPool p1(1), p3(3);
    const EnvironmentSettings s{1.7f, 33.0f, true};
    const Environment a = Environment::build(img, s, p1);
    const Environment b = Environment::build(img, s, pool2());
    const Environment c = Environment::build(img, s, p3);
    CHECK(hash_env(a) == hash_env(b));
    CHECK(hash_env(a) == hash_env(c));
    for (DfgModel m : {DfgModel::SchlickIbl, DfgModel::SchlickDirect, DfgModel::HeightCorrelated}) {
        const DfgTable t1 = DfgTable::build(m, p1), t3 = DfgTable::build(m, p3);
        const std::size_t n = std::size_t(DfgTable::kSizeNoV) * DfgTable::kSizeRough * sizeof(glm::vec4);
        CHECK(hash_bytes(t1.texels(), n) == hash_bytes(t3.texels(), n));
        // Four n.v columns per lane loop: the bits of the scalar loop.
        const DfgTable scalar = DfgTable::build(m, p3, DfgTable::Path::Scalar);
        CHECK(std::memcmp(scalar.texels(), t1.texels(), n) == 0);
    }
}

TEST_CASE("the GGX prefilter's eight-texel lanes give the scalar loop's bits") {
    // Widths with and without a tail of fewer than eight texels, each
    // roughness level's filter, a map with odd-sized mips and one with a
    // 2000x sun (texel values far apart), against PrefilterPath::Scalar.
    const Image maps[2] = {procedural_env(300), make_env(256, [](const glm::dvec3& d) {
                               const float sky = 0.25f + 0.5f * float(d.y * d.y);
                               return glm::vec3(glm::dot(d, kProceduralSun) > 0.999 ? 2000.0f : sky);
                           })};
    for (const Image& img : maps) {
        const Environment env = Environment::build(img, {}, pool2());
        EquirectLevel mips[32];
        for (int k = 0; k < env.source_levels(); ++k) mips[k] = env.source_level(k);
        const std::size_t base = std::size_t(mips[env.source_levels() - 1].offset) + 1;
        for (int level = 1; level < Environment::kSpecularLevels; ++level)
            for (int w : {8, 37, 64, 150}) {
                CAPTURE(level);
                CAPTURE(w);
                std::vector<glm::vec4> texels(env.texels(), env.texels() + base);
                EquirectLevel out[2];
                for (EquirectLevel& o : out) {
                    o.w = w; o.h = std::max(1, w / 2); o.fw = float(o.w); o.fh = float(o.h);
                    o.offset = std::int32_t(texels.size());
                    texels.resize(texels.size() + std::size_t(o.w) * std::size_t(o.h), glm::vec4(-1.0f));
                }
                const float r = Environment::level_roughness(level);
                const int n = Environment::kSpecularSamples[level];
                prefilter_ggx(texels.data(), mips, env.source_levels(), r, n, out[0], pool2(), PrefilterPath::Lanes);
                prefilter_ggx(texels.data(), mips, env.source_levels(), r, n, out[1], pool2(), PrefilterPath::Scalar);
                const std::size_t count = std::size_t(out[0].w) * std::size_t(out[0].h);
                CHECK(std::memcmp(texels.data() + out[0].offset, texels.data() + out[1].offset,
                                  count * sizeof(glm::vec4)) == 0);
                CHECK(texels[std::size_t(out[0].offset)].x >= 0.0f);
            }
    }
}

TEST_CASE("rendering with an environment is byte-identical for any thread count and tile size") {
    Scene scene;
    scene.environment = std::make_shared<const Image>(procedural_env(128));
    for (int i = 0; i < 3; ++i) {
        Material m;
        m.base_color_factor = glm::vec4(0.9f, 0.7f, 0.5f, 1.0f);
        m.metallic_factor = 0.5f * float(i);
        m.roughness_factor = 0.1f + 0.4f * float(i);
        scene.materials.push_back(m);
        scene.meshes.push_back(make_uv_sphere(glm::vec3(float(i) - 1.0f, 0.0f, 0.0f), 0.45f, 32, 16, i));
    }
    auto frame = [&](int threads, int tile, bool energy, int samples) {
        Renderer r({threads, tile});
        SceneRenderer sr(scene, r);
        FrameSettings fs;
        fs.camera.eye = {0.3f, 0.5f, 4.0f};
        fs.energy = energy;
        fs.samples = samples;
        Framebuffer fb(101, 67);
        sr.render(fs, fb);
        return hash_bytes(fb.color.data(), fb.color.size() * sizeof(float));
    };
    for (int samples : {1, 4}) {
        for (bool energy : {false, true}) {
            CAPTURE(samples); CAPTURE(energy);
            const std::uint64_t ref = frame(1, 64, energy, samples);
            CHECK(frame(2, 64, energy, samples) == ref);
            CHECK(frame(3, 16, energy, samples) == ref);
            CHECK(frame(2, 256, energy, samples) == ref);
        }
    }
}

TEST_CASE("with several samples per pixel, the samples no triangle covers resolve to the background") {
    // The frame clears every sample to its pixel's background, so a pixel is
    // (covered samples' colours + uncovered ones x background) / S: the same
    // frame over the sky and over black differs by k / S times the pixel's
    // background, k the uncovered samples. Uncovered pixels equal the
    // background exactly.
    Scene scene;
    scene.environment = std::make_shared<const Image>(procedural_env(128));
    Material m;
    m.metallic_factor = 1.0f;
    m.roughness_factor = 0.2f;
    scene.materials.push_back(m);
    scene.meshes.push_back(make_uv_sphere(glm::vec3(0.0f), 0.6f, 32, 16, 0));
    Renderer r({2, 32});
    SceneRenderer sr(scene, r);
    for (Background mode : {Background::Env, Background::Blur}) {
        for (int samples : {1, 2, 4, 8}) {
            CAPTURE(int(mode)); CAPTURE(samples);
            FrameSettings fs;
            fs.camera.eye = {0.2f, 0.4f, 3.0f};
            fs.samples = samples;
            fs.background = mode;
            Framebuffer sky(96, 64), black(96, 64);
            sr.render(fs, sky);
            fs.background = Background::Black;
            sr.render(fs, black);
            fs.background = mode;
            const BackgroundFill bg = frame_background(fs, sr.environment(fs), 96, 64);
            int empty = 0, edge = 0, inside = 0;
            double worst = 0.0;
            for (int y = 0; y < 64; ++y)
                for (int x = 0; x < 96; ++x) {
                    const float* a = sky.pixel(x, y);
                    const float* b = black.pixel(x, y);
                    const glm::vec3 c = bg.at(x, y);
                    // k / S from the brightest channel, then every channel checked.
                    const int ch = c.b >= c.r && c.b >= c.g ? 2 : c.g >= c.r ? 1 : 0;
                    const int k = int(std::lround(double(a[ch] - b[ch]) / double(c[ch]) * samples));
                    REQUIRE(k >= 0);
                    REQUIRE(k <= samples);
                    if (k == samples) {
                        ++empty;
                        CHECK(b[0] == 0.0f);
                        for (int i = 0; i < 3; ++i) CHECK(a[i] == c[i]);  // the background itself, bit for bit
                    } else {
                        ++(k == 0 ? inside : edge);
                        for (int i = 0; i < 3; ++i)
                            worst = std::max(worst, std::fabs(double(a[i] - b[i]) - double(c[i]) * k / samples));
                    }
                }
            CHECK(empty > 2000);
            CHECK(inside > 500);
            if (samples > 1) CHECK(edge > 40);  // the silhouette, partly covered
            else CHECK(edge == 0);
            CHECK(worst < 1e-6);
        }
    }
}

}

// BRDF tests: hand-computed values of every term, normalisation of D, energy
// (white furnace) by deterministic quadrature, reciprocity, and the conductor
// Fresnel approximation against the exact equations.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>

#include "raster/thread_pool.h"
#include "shading/brdf.h"
#include "shading/ibl/dfg.h"
#include "shading/surface.h"

using namespace prast;

namespace {

constexpr double kPi = 3.14159265358979323846;

const float kRoughnessGrid[] = {0.05f, 0.1f, 0.25f, 0.5f, 0.75f, 1.0f};
const double kCosViewGrid[] = {1.0, 0.9, 0.7, 0.5, 0.3, 0.1, 0.03};

// Quadrature resolution: (theta or u) x phi over half the azimuth, which is
// enough since v lies in the xz plane and f is symmetric in y. Measured
// against 4x finer grids: < 1e-3 away from grazing, < 1e-2 at n.v = 0.03,
// where the horizon cut of the specular lobe converges slowly (and where
// every specular albedo is far below 1).
constexpr int kNTheta = 128;
constexpr int kNPhi = 64;

glm::vec3 direction(double cos_theta, double phi) {
    double sin_theta = std::sqrt(std::max(0.0, 1.0 - cos_theta * cos_theta));
    return glm::vec3(float(sin_theta * std::cos(phi)), float(sin_theta * std::sin(phi)),
                     float(cos_theta));
}

// Integral over the hemisphere of fn(l) cos(theta_l) dl: midpoint rule,
// uniform in theta (so that it is not exact for the cosine by construction).
template <class Fn>
glm::dvec3 integrate_cosine_weighted(Fn fn) {
    glm::dvec3 sum(0.0);
    double dtheta = 0.5 * kPi / kNTheta, dphi = kPi / kNPhi;
    for (int i = 0; i < kNTheta; ++i) {
        double theta = (i + 0.5) * dtheta;
        double c = std::cos(theta), s = std::sin(theta);
        for (int j = 0; j < kNPhi; ++j) {
            glm::vec3 l = direction(c, (j + 0.5) * dphi);
            sum += glm::dvec3(fn(l)) * (c * s);
        }
    }
    return sum * (2.0 * dtheta * dphi);  // x2: the other half of the azimuth
}

struct DirectionalAlbedo {
    glm::dvec3 diffuse{0.0}, specular{0.0};
    glm::dvec3 total() const { return diffuse + specular; }
};

// Directional albedo of each lobe for a view at cos_v: the integral of
// f(l, v) cos(theta_l) dl over the hemisphere. The specular lobe is narrow
// (alpha = 0.0025 at r = 0.05), so it is integrated over h instead, with the
// GGX inverse CDF cos^2(theta_h) = (1 - u) / (1 + (alpha^2 - 1) u) as the
// substitution: dl = 4 (v.h) dh, dh = du dphi / (2 pi D(h) n.h).
DirectionalAlbedo directional_albedo(BrdfInputs in, BrdfModel model, double cos_v,
                                     bool with_diffuse = true) {
    DirectionalAlbedo out;
    in.n = glm::vec3(0.0f, 0.0f, 1.0f);
    in.v = direction(cos_v, 0.0);
    if (with_diffuse) {
        out.diffuse = integrate_cosine_weighted([&](glm::vec3 l) {
            in.l = l;
            return evaluate_brdf(in, model).diffuse;
        });
    }
    double r = std::clamp(in.roughness, kMinPerceptualRoughness, 1.0f);
    double alpha = double(float(r) * float(r));
    double a2 = alpha * alpha;
    glm::dvec3 v(in.v);
    for (int i = 0; i < kNTheta; ++i) {
        double u = (i + 0.5) / kNTheta;
        double cos2 = (1.0 - u) / (1.0 + (a2 - 1.0) * u);
        double cos_h = std::sqrt(cos2), sin_h = std::sqrt(std::max(0.0, 1.0 - cos2));
        double d = cos2 * (a2 - 1.0) + 1.0;
        double pdf_h = a2 / (kPi * d * d) * cos_h;  // D(h) n.h, in double
        for (int j = 0; j < kNPhi; ++j) {
            double phi = (j + 0.5) * kPi / kNPhi;
            glm::dvec3 h(sin_h * std::cos(phi), sin_h * std::sin(phi), cos_h);
            double VoH = glm::dot(v, h);
            if (VoH <= 0.0) continue;
            glm::dvec3 l = 2.0 * VoH * h - v;
            if (l.z <= 0.0) continue;
            in.l = glm::vec3(l);
            out.specular += glm::dvec3(evaluate_brdf(in, model).specular) * (l.z * 4.0 * VoH / pdf_h);
        }
    }
    out.specular /= double(kNTheta) * double(kNPhi);
    return out;
}

double max_channel(glm::dvec3 c) { return std::max(c.x, std::max(c.y, c.z)); }

std::string name(BrdfModel m) { return brdf_model_name(m); }

// A small deterministic generator (xorshift64*), the same on every platform.
struct Rng {
    std::uint64_t s = 0x9E3779B97F4A7C15ull;
    double next() {
        s ^= s >> 12; s ^= s << 25; s ^= s >> 27;
        return double((s * 0x2545F4914F6CDD1Dull) >> 11) * (1.0 / 9007199254740992.0);
    }
};

} // namespace

TEST_SUITE("brdf") {

TEST_CASE("known values of each term") {
    // D_GGX(1, 0.5): a2 = 0.25, d = 1 * (0.25 - 1) + 1 = 0.25, D = 0.25 / (pi * 0.0625) = 4 / pi.
    CHECK(D_GGX(1.0f, 0.5f) == doctest::Approx(1.2732395).epsilon(1e-6));
    // D_GGX(0, 0.5): d = 1, D = a2 / pi = 0.25 / pi.
    CHECK(D_GGX(0.0f, 0.5f) == doctest::Approx(0.0795775).epsilon(1e-6));
    // D_GGX(cos 30, 0.25): a2 = 0.0625, d = 0.75 * (-0.9375) + 1 = 0.296875,
    // D = 0.0625 / (pi * 0.0881348) = 0.2257267.
    CHECK(D_GGX(0.8660254f, 0.25f) == doctest::Approx(0.2257267).epsilon(1e-5));
    // alpha = 0 at n.h = 1 is a delta: the guard returns 0, not NaN.
    CHECK(D_GGX(1.0f, 0.0f) == 0.0f);

    // G1(0.5, k = 0.5) = 0.5 / (0.5 * 0.5 + 0.5) = 2/3.
    CHECK(G1_SchlickGGX(0.5f, 0.5f) == doctest::Approx(2.0 / 3.0).epsilon(1e-6));
    // k_direct(0.5) = 1.5^2 / 8 = 0.28125; k_ibl(0.5) = 0.25 / 2 = 0.125.
    CHECK(k_direct(0.5f) == 0.28125f);
    CHECK(k_ibl(0.5f) == 0.125f);
    // G_Smith(0.5, 1, 0.28125) = 0.5 / (0.5 * 0.71875 + 0.28125) * 1 / (0.71875 + 0.28125)
    //                          = 0.5 / 0.640625 * 1 = 0.7804878.
    CHECK(G_Smith(0.5f, 1.0f, 0.28125f) == doctest::Approx(0.7804878).epsilon(1e-6));

    // V(1, 1, a) = 0.5 / (1 * 1 + 1 * 1) = 0.25 for any alpha.
    CHECK(V_SmithGGXCorrelated(1.0f, 1.0f, 0.3f) == doctest::Approx(0.25).epsilon(1e-6));
    // V(0.5, 0.5, 0.5): a2 = 0.25, sqrt(0.25 * 0.75 + 0.25) = sqrt(0.4375) = 0.6614378,
    // V = 0.5 / (2 * 0.5 * 0.6614378) = 0.7559289.
    CHECK(V_SmithGGXCorrelated(0.5f, 0.5f, 0.5f) == doctest::Approx(0.7559289).epsilon(1e-6));
    CHECK(V_SmithGGXCorrelated(0.0f, 0.0f, 0.5f) == 0.0f);  // guard, not inf

    // F_Schlick(0.04, 0.5) = 0.04 + 0.96 * 0.5^5 = 0.04 + 0.03 = 0.07.
    CHECK(F_Schlick(glm::vec3(0.04f), 0.5f).y == doctest::Approx(0.07).epsilon(1e-6));
    CHECK(F_Schlick(0.04f, 0.5f) == doctest::Approx(0.07).epsilon(1e-6));
    CHECK(F_Schlick(glm::vec3(0.04f), 1.0f).x == doctest::Approx(0.04).epsilon(1e-6));
    CHECK(F_Schlick(glm::vec3(0.04f), -0.3f).x == 1.0f);  // v.h clamped to 0
    // f0_from_ior(1.5) = (0.5 / 2.5)^2 = 0.04; (1.33): (0.33 / 2.33)^2 = 0.0200593.
    CHECK(f0_from_ior(1.5f) == doctest::Approx(0.04).epsilon(1e-6));
    CHECK(f0_from_ior(1.33f) == doctest::Approx(0.0200593).epsilon(1e-5));

    CHECK(Fd_Lambert() == doctest::Approx(0.3183099).epsilon(1e-7));
}

TEST_CASE("evaluate_brdf matches a hand computation") {
    // n = v = +z, l 60 degrees off the normal in xz: l = (sin 60, 0, cos 60).
    // h = normalize(l + v) = (0.8660, 0, 1.5) / sqrt(3) = (0.5, 0, 0.8660):
    // n.l = 0.5, n.v = 1, n.h = v.h = cos 30 = 0.8660254.
    // r = 0.5: alpha = 0.25, D = 0.2257267 (above), k = 0.28125, G = G1(1) G1(0.5) = 0.7804878,
    // (1 - v.h)^5 = 0.1339746^5 = 4.3163e-5.
    BrdfInputs in;
    in.n = glm::vec3(0.0f, 0.0f, 1.0f);
    in.v = in.n;
    in.l = glm::vec3(0.8660254f, 0.0f, 0.5f);
    in.roughness = 0.5f;

    SUBCASE("dielectric, Default") {
        // albedo 0.5, metallic 0: F = 0.04 + 0.96 * 4.3163e-5 = 0.0400414,
        // specular = D G F / (4 * 1 * 0.5) = 0.2257267 * 0.7804878 * 0.0400414 / 2 = 0.00352719,
        // kd = 1 - F = 0.9599586, diffuse = kd * 0.5 / pi = 0.1527822, f = 0.1563093.
        in.albedo = glm::vec3(0.5f);
        in.metallic = 0.0f;
        BrdfTerms t = evaluate_brdf(in, BrdfModel::Default);
        CHECK(t.NoL == doctest::Approx(0.5).epsilon(1e-6));
        CHECK(t.NoV == doctest::Approx(1.0).epsilon(1e-6));
        CHECK(t.NoH == doctest::Approx(0.8660254).epsilon(1e-6));
        CHECK(t.VoH == doctest::Approx(0.8660254).epsilon(1e-6));
        CHECK(t.D == doctest::Approx(0.2257267).epsilon(1e-5));
        CHECK(t.G == doctest::Approx(0.7804878).epsilon(1e-6));
        CHECK(t.F.x == doctest::Approx(0.0400414).epsilon(1e-5));
        CHECK(t.kd.y == doctest::Approx(0.9599586).epsilon(1e-6));
        CHECK(t.specular.z == doctest::Approx(0.00352719).epsilon(1e-5));
        CHECK(t.diffuse.x == doctest::Approx(0.1527822).epsilon(1e-5));
        CHECK(t.f.x == doctest::Approx(0.1563093).epsilon(1e-5));
    }
    SUBCASE("metal, Default and Gltf") {
        // albedo (1, 0.5, 0.25), metallic 1: F0 = albedo, F = F0 + (1 - F0) 4.3163e-5
        // = (1, 0.5000216, 0.2500324); kd = 0 (F.x = 1 and metallic = 1).
        // Default: specular = D G F / 2 = 0.0880885 F.
        // Gltf: V(1, 0.5, 0.25) = 0.5 / (0.5 * 1 + 1 * sqrt(0.25 * 0.9375 + 0.0625))
        //       = 0.5 / (0.5 + 0.5448624) = 0.4785319; specular = F D V = 0.1080174 F.
        in.albedo = glm::vec3(1.0f, 0.5f, 0.25f);
        in.metallic = 1.0f;
        BrdfTerms t = evaluate_brdf(in, BrdfModel::Default);
        CHECK(t.F.y == doctest::Approx(0.5000216).epsilon(1e-6));
        CHECK(t.kd == glm::vec3(0.0f));
        CHECK(t.f.x == doctest::Approx(0.0880885).epsilon(1e-5));
        CHECK(t.f.y == doctest::Approx(0.0440461).epsilon(1e-5));
        CHECK(t.f.z == doctest::Approx(0.0220250).epsilon(1e-5));
        BrdfTerms g = evaluate_brdf(in, BrdfModel::Gltf);
        CHECK(g.D == t.D);
        CHECK(g.G == doctest::Approx(0.4785319).epsilon(1e-6));
        CHECK(g.f.x == doctest::Approx(0.1080174).epsilon(1e-5));
        CHECK(g.f.y == doctest::Approx(0.0540110).epsilon(1e-5));
        CHECK(g.f.z == doctest::Approx(0.0270079).epsilon(1e-5));
    }
    SUBCASE("normal incidence: both models agree") {
        // l = v = n: D = 1 / (pi alpha^2) = 16 / pi = 5.0929582, G = 1, V = 0.25,
        // so D G F / 4 = F D V = 0.04 * 5.0929582 / 4 = 0.0509296.
        in.l = in.n;
        in.albedo = glm::vec3(0.5f);
        in.metallic = 0.0f;
        BrdfTerms t = evaluate_brdf(in, BrdfModel::Default);
        BrdfTerms g = evaluate_brdf(in, BrdfModel::Gltf);
        CHECK(t.D == doctest::Approx(5.0929582).epsilon(1e-6));
        CHECK(t.specular.x == doctest::Approx(0.0509296).epsilon(1e-5));
        CHECK(g.specular.x == doctest::Approx(0.0509296).epsilon(1e-5));
        // diffuse = 0.96 * 0.5 / pi = 0.1527887
        CHECK(t.diffuse.x == doctest::Approx(0.1527887).epsilon(1e-5));
    }
    SUBCASE("roughness is clamped to 0.045") {
        in.roughness = 0.0f;
        BrdfTerms t0 = evaluate_brdf(in, BrdfModel::Default);
        in.roughness = kMinPerceptualRoughness;
        BrdfTerms t1 = evaluate_brdf(in, BrdfModel::Default);
        CHECK(t0.f == t1.f);
        CHECK(std::isfinite(t0.f.x));
    }
}

TEST_CASE("D is normalised: integral of D(h) n.h over the hemisphere is 1") {
    // Substitute 1 - cos(theta_h) = exp(s), s in [-40, 0]: the samples crowd
    // towards the pole as the peak (width ~ alpha^2 in 1 - cos) requires.
    // integral = 2 pi int D(mu) mu dmu, dmu = exp(s) ds. Tolerance 1e-2 (the
    // brief's); measured 2.3e-4 (at r = 0.1, where n.h in float is
    // quantised to ~1% of the peak width).
    double worst = 0.0;
    for (float r : {0.1f, 0.25f, 0.5f, 0.75f, 1.0f}) {
        float alpha = r * r;
        const int n = 20000;
        const double s0 = -40.0, ds = -s0 / n;
        double sum = 0.0;
        for (int i = 0; i < n; ++i) {
            double one_minus_mu = std::exp(s0 + (i + 0.5) * ds);
            double mu = 1.0 - one_minus_mu;
            sum += double(D_GGX(float(mu), alpha)) * mu * one_minus_mu * ds;
        }
        double integral = 2.0 * kPi * sum;
        worst = std::max(worst, std::abs(integral - 1.0));
        CAPTURE(r);
        CHECK(integral == doctest::Approx(1.0).epsilon(1e-2));
    }
    MESSAGE("D normalisation: max |integral - 1| = " << worst);
}

TEST_CASE("white furnace: Lambert alone reflects exactly 1") {
    glm::dvec3 e = integrate_cosine_weighted([](glm::vec3) { return glm::vec3(Fd_Lambert()); });
    CHECK(e.x == doctest::Approx(1.0).epsilon(1e-3));
    MESSAGE("Lambert albedo (quadrature check) = " << e.x);
}

TEST_CASE("white furnace: each lobe reflects at most 1") {
    // Tolerance 0.006: the float D_GGX has an upward rounding bias at the
    // sharp peak of r <= 0.05 (n.h is quantised to 6e-8 while the peak is
    // alpha^2 = 6e-6 wide; measured +0.35% at r = 0.05, +0.44% at r = 0.045,
    // 0.00% with D in double), plus < 1e-3 of quadrature error.
    const double kTol = 0.006;
    struct Material {
        const char* label;
        glm::vec3 albedo;
        float metallic, ior;
        Conductor conductor;
    };
    const Material materials[] = {
        {"metal F0 = (1, 0.7, 0.3)", {1.0f, 0.7f, 0.3f}, 1.0f, 1.5f, Conductor::None},
        {"half metal", {1.0f, 0.7f, 0.3f}, 0.5f, 1.5f, Conductor::None},
        {"dielectric ior 1.5", {1.0f, 1.0f, 1.0f}, 0.0f, 1.5f, Conductor::None},
        {"dielectric ior 3", {1.0f, 1.0f, 1.0f}, 0.0f, 3.0f, Conductor::None},
        {"gold", {1.0f, 1.0f, 1.0f}, 0.0f, 1.5f, Conductor::Gold},
        {"copper", {1.0f, 1.0f, 1.0f}, 0.0f, 1.5f, Conductor::Copper},
        {"aluminium", {1.0f, 1.0f, 1.0f}, 0.0f, 1.5f, Conductor::Aluminium},
        {"silver", {1.0f, 1.0f, 1.0f}, 0.0f, 1.5f, Conductor::Silver},
    };
    for (BrdfModel model : {BrdfModel::Default, BrdfModel::Gltf}) {
        double max_spec = 0.0, max_diffuse = 0.0;
        for (const Material& m : materials) {
            for (float r : kRoughnessGrid) {
                for (double cos_v : kCosViewGrid) {
                    BrdfInputs in;
                    in.albedo = m.albedo;
                    in.metallic = m.metallic;
                    in.ior = m.ior;
                    in.conductor = m.conductor;
                    in.roughness = r;
                    // The diffuse lobe is smooth and does not depend on the model; do it once.
                    bool with_diffuse = model == BrdfModel::Default && m.metallic < 1.0f &&
                                        m.conductor == Conductor::None;
                    DirectionalAlbedo e = directional_albedo(in, model, cos_v, with_diffuse);
                    CAPTURE(name(model));
                    CAPTURE(std::string(m.label));
                    CAPTURE(r);
                    CAPTURE(cos_v);
                    CHECK(max_channel(e.specular) <= 1.0 + kTol);
                    CHECK(max_channel(e.diffuse) <= 1.0 + kTol);
                    max_spec = std::max(max_spec, max_channel(e.specular));
                    max_diffuse = std::max(max_diffuse, max_channel(e.diffuse));
                    // The lobe is really found: a white metal seen head-on
                    // reflects nearly all of it at low roughness.
                    if (m.metallic == 1.0f && cos_v == 1.0 && r <= 0.25f)
                        CHECK(e.specular.x >= 0.98);
                }
            }
        }
        std::string diffuse_note =
            model == BrdfModel::Default ? ", max diffuse albedo " + std::to_string(max_diffuse) : "";
        MESSAGE(name(model) << ": max specular albedo " << max_spec << diffuse_note);
    }
}

TEST_CASE("white furnace: diffuse plus specular, and the known grazing overshoot") {
    // Known flaw of the model as the conventions and the glTF spec define it,
    // recorded here rather than fixed: kd = (1 - F(v.h)) removes, for each l,
    // the Fresnel of that l's half vector, not the energy the specular lobe
    // actually took. With albedo 1 the sum stays within 1 near normal
    // incidence but exceeds it at grazing views. Default's Schlick-GGX G with
    // k = (r + 1)^2 / 8 over-shadows smooth surfaces and keeps the excess
    // small; Gltf's exact height-correlated V keeps the whole grazing mirror
    // reflection (~0.9) on top of ~0.93 of diffuse. A fix (scaling the
    // diffuse by 1 - E_spec(v), Kelemen & Szirmay-Kalos 2001) would change
    // the conventions. Bounds are measured over this grid plus a margin.
    const double kTol = 0.006;  // as above
    for (BrdfModel model : {BrdfModel::Default, BrdfModel::Gltf}) {
        const double grazing_bound = model == BrdfModel::Default ? 1.07 : 1.80;
        double max_near = 0.0, max_grazing = 0.0;
        float worst_r = 0.0f;
        double worst_cos = 0.0;
        for (float metallic : {0.0f, 0.5f}) {
            for (float ior : {1.5f, 3.0f}) {
                for (float r : kRoughnessGrid) {
                    for (double cos_v : kCosViewGrid) {
                        BrdfInputs in;
                        in.albedo = glm::vec3(1.0f, 0.7f, 0.3f);
                        in.metallic = metallic;
                        in.ior = ior;
                        in.roughness = r;
                        double e = max_channel(directional_albedo(in, model, cos_v).total());
                        CAPTURE(name(model));
                        CAPTURE(metallic);
                        CAPTURE(ior);
                        CAPTURE(r);
                        CAPTURE(cos_v);
                        if (cos_v >= 0.7) {
                            CHECK(e <= 1.0 + kTol);
                            max_near = std::max(max_near, e);
                        } else {
                            CHECK(e <= grazing_bound);
                            if (e > max_grazing) {
                                max_grazing = e;
                                worst_r = r;
                                worst_cos = cos_v;
                            }
                        }
                    }
                }
            }
        }
        MESSAGE(name(model) << ": max albedo " << max_near << " for n.v >= 0.7; "
                            << max_grazing << " for n.v < 0.7 (r = " << worst_r
                            << ", n.v = " << worst_cos << ")");
    }
}

TEST_CASE("white furnace with --energy conserve: white reflects 1 at every angle and roughness") {
    // Multiple-scattering compensation (1 + F0 (1 / E_ss - 1)) and the diffuse
    // scaled by 1 - E_spec(v): a white material (albedo 1), metal or not,
    // reflects 1 at every view angle, where the plain model loses energy in
    // rough metals and overshoots at grazing views (the test above). The
    // residue: the table's own sampling error (up to 0.6% against 1M
    // directions, at n.v near 0.1), this file's quadrature near grazing (0.7%
    // at n.v = 0.1, about 1% at 0.03) and the float D bias at r <= 0.05
    // noted above.
    ThreadPool pool(2);
    for (BrdfModel model : {BrdfModel::Default, BrdfModel::Gltf}) {
        const DfgTable table =
            DfgTable::build(model == BrdfModel::Gltf ? DfgModel::HeightCorrelated : DfgModel::SchlickDirect, pool);
        double worst = 0.0, worst_grazing = 0.0, plain_metal_min = 1.0;
        for (float metallic : {0.0f, 0.5f, 1.0f}) {
            for (float r : kRoughnessGrid) {
                for (double cos_v : kCosViewGrid) {
                    BrdfInputs in;
                    in.albedo = glm::vec3(1.0f);
                    in.metallic = metallic;
                    in.roughness = r;
                    in.n = glm::vec3(0.0f, 0.0f, 1.0f);
                    in.v = direction(cos_v, 0.0);
                    if (metallic == 1.0f)
                        plain_metal_min = std::min(plain_metal_min, directional_albedo(in, model, cos_v).total().x);
                    apply_energy_terms(in, table);
                    const double e = max_channel(directional_albedo(in, model, cos_v).total());
                    CAPTURE(name(model)); CAPTURE(metallic); CAPTURE(r); CAPTURE(cos_v);
                    const double tol = cos_v > 0.1 ? 0.008 : (cos_v == 0.1 ? 0.015 : 0.03);
                    CHECK(e <= 1.0 + tol);
                    // A half metal keeps E_spec + (1 - E_spec) / 2 < 1, as in
                    // Filament: its diffuse is (1 - metallic) of the albedo.
                    if (metallic == 0.5f) continue;
                    CHECK(std::fabs(e - 1.0) <= tol);
                    double& w = cos_v > 0.1 ? worst : worst_grazing;
                    w = std::max(w, std::fabs(e - 1.0));
                }
            }
        }
        MESSAGE(name(model) << " --energy conserve: white metal and dielectric, max |albedo - 1| " << worst
                            << " for n.v >= 0.3, "
                            << worst_grazing << " at n.v = 0.1 and 0.03; plain white metal goes down to "
                            << plain_metal_min);
    }
}

TEST_CASE("reciprocity: f(l, v) == f(v, l)") {
    // Random directions in the upper hemisphere (n.l, n.v >= 0.05) and random
    // materials. D, G (V), the 1e-4 clamps and h are symmetric by construction;
    // F uses v.h, equal to l.h up to rounding: hence 1e-5 relative.
    Rng rng;
    double worst = 0.0;
    const Conductor conductors[] = {Conductor::None, Conductor::None, Conductor::Gold,
                                    Conductor::Copper, Conductor::Aluminium, Conductor::Silver};
    auto random_dir = [&rng]() {
        double cos_theta = 0.05 + 0.95 * rng.next();
        return direction(cos_theta, 2.0 * kPi * rng.next());
    };
    for (int i = 0; i < 2000; ++i) {
        BrdfInputs in;
        in.n = glm::vec3(0.0f, 0.0f, 1.0f);
        in.v = random_dir();
        in.l = random_dir();
        in.albedo = glm::vec3(float(rng.next()), float(rng.next()), float(rng.next()));
        in.metallic = float(rng.next());
        in.roughness = float(rng.next());
        in.ior = float(1.0 + 2.0 * rng.next());
        in.conductor = conductors[i % 6];
        for (BrdfModel model : {BrdfModel::Default, BrdfModel::Gltf}) {
            glm::vec3 a = evaluate_brdf(in, model).f;
            BrdfInputs swapped = in;
            std::swap(swapped.l, swapped.v);
            glm::vec3 b = evaluate_brdf(swapped, model).f;
            for (int c = 0; c < 3; ++c) {
                double rel = std::abs(double(a[c]) - double(b[c])) /
                             std::max(1e-30, double(std::max(std::abs(a[c]), std::abs(b[c]))));
                worst = std::max(worst, rel);
                CAPTURE(i);
                CAPTURE(name(model));
                CHECK(rel <= 1e-5);
            }
        }
    }
    MESSAGE("reciprocity: max relative difference " << worst);
}

TEST_CASE("conductor Fresnel: Schlick approximation against the exact equations") {
    struct Metal {
        const char* label;
        Conductor c;
        double bound;  // measured max |Schlick - exact| over cos in [0, 1], plus ~10%
    };
    // Measured (float; the same to 1e-6 in double with complex arithmetic):
    // gold 0.0179 (blue, cos 0.097), copper 0.0396 (blue, cos 0.148),
    // aluminium 0.1296 (red, cos 0.105: exact 0.830, Schlick 0.960; the
    // Schlick form misses aluminium's deep Rp dip near grazing, the error
    // Lazanyi's extra term corrects), silver 0.0066 (green, cos 0.204).
    const Metal metals[] = {
        {"gold", Conductor::Gold, 0.020},
        {"copper", Conductor::Copper, 0.044},
        {"aluminium", Conductor::Aluminium, 0.143},
        {"silver", Conductor::Silver, 0.0075},
    };
    for (const Metal& m : metals) {
        ConductorIOR ior = conductor_ior(m.c);
        CAPTURE(std::string(m.label));
        // Normal incidence: both reduce to ((eta - 1)^2 + k^2) / ((eta + 1)^2 + k^2).
        glm::vec3 s1 = F_ConductorSchlick(ior.eta, ior.k, 1.0f);
        glm::vec3 e1 = F_ConductorExact(ior.eta, ior.k, 1.0f);
        for (int c = 0; c < 3; ++c) {
            double n = ior.eta[c], k = ior.k[c];
            double f0 = ((n - 1) * (n - 1) + k * k) / ((n + 1) * (n + 1) + k * k);
            CHECK(s1[c] == doctest::Approx(f0).epsilon(1e-6));
            CHECK(e1[c] == doctest::Approx(f0).epsilon(1e-6));
        }
        // Grazing: both are 1.
        CHECK(F_ConductorSchlick(ior.eta, ior.k, 0.0f).x == doctest::Approx(1.0).epsilon(1e-6));
        CHECK(F_ConductorExact(ior.eta, ior.k, 0.0f).z == doctest::Approx(1.0).epsilon(1e-6));
        // In between: measure the worst error.
        double worst = 0.0, worst_cos = 0.0;
        for (int i = 0; i <= 1000; ++i) {
            float cos_theta = float(i) / 1000.0f;
            glm::vec3 d = F_ConductorSchlick(ior.eta, ior.k, cos_theta) -
                          F_ConductorExact(ior.eta, ior.k, cos_theta);
            double err = max_channel(glm::abs(glm::dvec3(d)));
            if (err > worst) { worst = err; worst_cos = cos_theta; }
        }
        MESSAGE(std::string(m.label) << ": max |Schlick - exact| = " << worst << " at cos = " << worst_cos);
        CHECK(worst <= m.bound);
        CHECK(worst > 0.0);
    }
}

TEST_CASE("conductor Fresnel: exact equations against complex arithmetic") {
    // Values from rs = (c - ct) / (c + ct), rp = (m^2 c - ct) / (m^2 c + ct),
    // ct = sqrt(m^2 - sin^2), m = eta + i k, F = (|rs|^2 + |rp|^2) / 2, in double.
    // Dielectric eta 1.5 at 60 degrees: 0.0891867 (Rs 0.1766, Rp 0.0018).
    CHECK(F_ConductorExact(1.5f, 0.0f, 0.5f) == doctest::Approx(0.0891867).epsilon(1e-5));
    CHECK(F_ConductorExact(1.5f, 0.0f, 1.0f) == doctest::Approx(0.04).epsilon(1e-5));
    // Gold at 45 degrees: (0.9548909, 0.7900120, 0.4154037); at 80: (0.9570481, 0.8637143, 0.6241072).
    ConductorIOR au = conductor_ior(Conductor::Gold);
    glm::vec3 f45 = F_ConductorExact(au.eta, au.k, 0.70710678f);
    CHECK(f45.x == doctest::Approx(0.9548909).epsilon(1e-5));
    CHECK(f45.y == doctest::Approx(0.7900120).epsilon(1e-5));
    CHECK(f45.z == doctest::Approx(0.4154037).epsilon(1e-5));
    glm::vec3 f80 = F_ConductorExact(au.eta, au.k, 0.17364818f);
    CHECK(f80.x == doctest::Approx(0.9570481).epsilon(1e-5));
    CHECK(f80.y == doctest::Approx(0.8637143).epsilon(1e-5));
    CHECK(f80.z == doctest::Approx(0.6241072).epsilon(1e-5));
    // Conductors in evaluate_brdf: fully metallic, F from the exact equations.
    BrdfInputs in;
    in.n = glm::vec3(0.0f, 0.0f, 1.0f);
    in.v = in.l = in.n;
    in.conductor = Conductor::Gold;
    in.metallic = 0.0f;
    BrdfTerms t = evaluate_brdf(in, BrdfModel::Default);
    CHECK(t.kd == glm::vec3(0.0f));
    CHECK(t.diffuse == glm::vec3(0.0f));
    CHECK(t.F.y == doctest::Approx(0.7915801).epsilon(1e-5));
}

TEST_CASE("parse_brdf_model") {
    BrdfModel m = BrdfModel::Default;
    CHECK(parse_brdf_model("gltf", m));
    CHECK(m == BrdfModel::Gltf);
    CHECK(parse_brdf_model("default", m));
    CHECK(m == BrdfModel::Default);
    CHECK_FALSE(parse_brdf_model("GGX", m));
    CHECK(m == BrdfModel::Default);
}

} // TEST_SUITE

// The reflectance model: Cook-Torrance microfacet specular (GGX D, Smith G or
// the height-correlated V, Schlick or conductor Fresnel) plus Lambert diffuse,
// as docs/conventions.md writes it, and the glTF 2.0 / Filament variant. Small pure
// inline functions named after the papers (Filament style), so a shader can
// inline them, plus evaluate_brdf(), which the shaders and the debug stepper
// both call so that they show the same numbers.
//
// Determinism: plain float arithmetic, no std::pow (powers are multiply
// chains); the project builds with -ffp-contract=off and no fast-math.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <string>

#include <glm/glm.hpp>
#include <glm/gtc/constants.hpp>

#include "scene/det_math.h"
#include "scene/scene.h"

namespace prast {

namespace brdf_detail {
inline float pow5(float x) {
    float x2 = x * x;
    return x2 * x2 * x;
}
} // namespace brdf_detail

// Perceptual roughness range: below 0.045, alpha^2 < 4e-6 and the GGX peak
// 1 / (pi alpha^2) outgrows float precision of n.h (Filament's MIN_PERCEPTUAL_ROUGHNESS).
constexpr float kMinPerceptualRoughness = 0.045f;
// The conventions' e: keeps D G F / (4 n.v n.l) finite at grazing angles.
constexpr float kBrdfMinCos = 1e-4f;

// ---- Normal distribution

// Trowbridge-Reitz / GGX distribution (Walter et al. 2007, eq. 33), alpha = r^2.
inline float D_GGX(float NoH, float alpha) {
    float a2 = alpha * alpha;
    float d = NoH * NoH * (a2 - 1.0f) + 1.0f;
    float denom = glm::pi<float>() * d * d;
    // d = 0 only for alpha = 0 at n.h = 1 (a delta): return 0, not inf/NaN.
    return denom > 0.0f ? a2 / denom : 0.0f;
}

// ---- Geometry (shadowing-masking)

// Schlick's approximation of Smith's G1 for GGX (Schlick 1994; Karis 2013).
inline float G1_SchlickGGX(float NoX, float k) {
    float denom = NoX * (1.0f - k) + k;
    // 0/0 only when n.x = 0 and k = 0; both k below are > 0.
    return denom > 0.0f ? NoX / denom : 0.0f;
}

// Separable Smith G = G1(n.v) G1(n.l) (Smith 1967, with Schlick's G1).
inline float G_Smith(float NoV, float NoL, float k) {
    return G1_SchlickGGX(NoV, k) * G1_SchlickGGX(NoL, k);
}

// k for analytic lights: (r + 1)^2 / 8, Karis 2013 ("reduces hotness" at low r).
inline float k_direct(float r) {
    float r1 = r + 1.0f;
    return r1 * r1 * 0.125f;
}

// k for image-based lighting: alpha / 2 = r^2 / 2 (Karis 2013).
inline float k_ibl(float r) { return r * r * 0.5f; }

// Height-correlated Smith visibility V = G / (4 n.v n.l) for GGX
// (Heitz 2014, eq. 99; the form used by Filament and the glTF 2.0 spec).
inline float V_SmithGGXCorrelated(float NoV, float NoL, float alpha) {
    float a2 = alpha * alpha;
    float ggxv = NoL * std::sqrt(NoV * NoV * (1.0f - a2) + a2);
    float ggxl = NoV * std::sqrt(NoL * NoL * (1.0f - a2) + a2);
    float denom = ggxv + ggxl;
    // 0 only when n.v = n.l = 0, where the caller's n.l factor is 0 anyway.
    return denom > 0.0f ? 0.5f / denom : 0.0f;
}

// ---- Fresnel

// Schlick 1994: F0 + (1 - F0) (1 - v.h)^5.
inline glm::vec3 F_Schlick(glm::vec3 F0, float VoH) {
    float fc = brdf_detail::pow5(1.0f - std::max(VoH, 0.0f));
    return F0 + (glm::vec3(1.0f) - F0) * fc;
}
inline float F_Schlick(float F0, float VoH) {
    float fc = brdf_detail::pow5(1.0f - std::max(VoH, 0.0f));
    return F0 + (1.0f - F0) * fc;
}

// Reflectance at normal incidence of a dielectric from air: ((1 - ior) / (1 + ior))^2.
inline float f0_from_ior(float ior) {
    float r = (1.0f - ior) / (1.0f + ior);
    return r * r;
}

// Schlick-style approximation for a conductor of complex index eta + i k
// (Lazanyi and Szirmay-Kalos 2005, without their correction term):
// ((eta - 1)^2 + 4 eta (1 - cos)^5 + k^2) / ((eta + 1)^2 + k^2), per channel.
// Exact at cos = 1 and cos = 0; a few percent off in between.
inline glm::vec3 F_ConductorSchlick(glm::vec3 eta, glm::vec3 k, float cosTheta) {
    float fc = brdf_detail::pow5(1.0f - glm::clamp(cosTheta, 0.0f, 1.0f));
    glm::vec3 em1 = eta - 1.0f, ep1 = eta + 1.0f, k2 = k * k;
    return (em1 * em1 + 4.0f * eta * fc + k2) / (ep1 * ep1 + k2);
}

// Exact unpolarised Fresnel reflectance of a conductor, eta + i k, seen from
// air: (Rs + Rp) / 2, the Fresnel equations in the real-arithmetic form of
// Lagarde, "Memo on Fresnel equations" (2013), with
// a^2 + b^2 = sqrt((eta^2 - k^2 - sin^2)^2 + 4 eta^2 k^2).
inline float F_ConductorExact(float eta, float k, float cosTheta) {
    float c = glm::clamp(cosTheta, 0.0f, 1.0f);
    float c2 = c * c;
    float s2 = 1.0f - c2;
    float eta2 = eta * eta, k2 = k * k;
    // Compute a^2 + b^2 and a, the real part of the transmitted cosine term.
    float t0 = eta2 - k2 - s2;
    float a2b2 = std::sqrt(t0 * t0 + 4.0f * eta2 * k2);
    float a = std::sqrt(std::max(0.5f * (a2b2 + t0), 0.0f));
    // Perpendicular (s) polarisation.
    float t1 = a2b2 + c2;
    float t2 = 2.0f * a * c;
    float Rs = (t1 - t2) / (t1 + t2);
    // Parallel (p) polarisation, relative to Rs.
    float t3 = c2 * a2b2 + s2 * s2;
    float t4 = t2 * s2;
    float Rp = Rs * (t3 - t4) / (t3 + t4);
    return 0.5f * (Rs + Rp);
}
inline glm::vec3 F_ConductorExact(glm::vec3 eta, glm::vec3 k, float cosTheta) {
    return glm::vec3(F_ConductorExact(eta.x, k.x, cosTheta),
                     F_ConductorExact(eta.y, k.y, cosTheta),
                     F_ConductorExact(eta.z, k.z, cosTheta));
}

// Complex refractive index of a measured metal at R, G, B = 650, 550, 450 nm,
// linearly interpolated from the refractiveindex.info database tables:
// gold, copper, silver from Johnson & Christy, Phys. Rev. B 6, 4370 (1972);
// aluminium from Rakic, Appl. Opt. 34, 4755 (1995).
// Normal-incidence reflectance: gold (0.957, 0.792, 0.408), copper (0.935,
// 0.624, 0.538), aluminium (0.906, 0.915, 0.922), silver (0.990, 0.983, 0.980).
struct ConductorIOR {
    glm::vec3 eta, k;
};
inline ConductorIOR conductor_ior(Conductor c) {
    switch (c) {
    case Conductor::Gold:      return {{0.1556f, 0.4241f, 1.3831f}, {3.6024f, 2.4721f, 1.9155f}};
    case Conductor::Copper:    return {{0.2378f, 1.0066f, 1.2404f}, {3.6264f, 2.5823f, 2.3929f}};
    case Conductor::Aluminium: return {{1.5580f, 1.0152f, 0.6332f}, {7.7124f, 6.6273f, 5.4544f}};
    case Conductor::Silver:    return {{0.0522f, 0.0596f, 0.0400f}, {4.4094f, 3.5974f, 2.6484f}};
    case Conductor::None:      break;
    }
    // Not a metal: the default dielectric, ior 1.5, no absorption (F0 = 0.04).
    return {glm::vec3(1.5f), glm::vec3(0.0f)};
}

// ---- Sheen (KHR_materials_sheen)

// The "Charlie" sheen distribution (Conty Estevez and Kulla 2017), alpha =
// r^2: (2 + 1/alpha) sin(theta_h)^(1/alpha) / (2 pi). The sheen's powers are
// scene/det_math.h's, so that they do not depend on the CPU's libm variant.
inline double D_Charlie(double NoH, double alpha) {
    const double inv = 1.0 / alpha;
    const double sin2 = 1.0 - NoH * NoH;
    return (2.0 + inv) * det::pow(sin2, 0.5 * inv) / (2.0 * glm::pi<double>());
}

// Their visibility, with the fitted Lambda the extension gives.
inline double sheen_lambda(double cos_theta, double alpha) {
    const double t = (1.0 - alpha) * (1.0 - alpha);
    const auto l = [&](double x) {
        const double a = 21.5473 + (25.3245 - 21.5473) * t, b = 3.82987 + (3.32435 - 3.82987) * t;
        const double c = 0.19823 + (0.16801 - 0.19823) * t, d = -1.97760 + (-1.27393 + 1.97760) * t;
        const double e = -4.32054 + (-4.85967 + 4.32054) * t;
        return a / (1.0 + b * det::pow(x, c)) + d * x + e;
    };
    return cos_theta < 0.5 ? det::exp(l(cos_theta))
                           : det::exp(2.0 * l(0.5) - l(1.0 - cos_theta));
}
inline double V_Charlie(double NoV, double NoL, double alpha) {
    const double den = (1.0 + sheen_lambda(NoV, alpha) + sheen_lambda(NoL, alpha)) * (4.0 * NoV * NoL);
    return den > 0.0 ? std::min(1.0 / den, 1.0) : 0.0;
}

// The directional albedo E(n.v, r) of the sheen lobe with colour 1, the
// integral of D V (n.l) over the hemisphere, for the extension's albedo
// scaling: a table of kSheenNoV x kSheenRough texels, n.v = i / (kSheenNoV -
// 1), r = j / (kSheenRough - 1) clamped to [0.045, 1], built once in double
// by a fixed-order midpoint rule (the same bytes everywhere), read bilinearly.
constexpr int kSheenNoV = 32, kSheenRough = 16;
inline const std::array<float, kSheenNoV * kSheenRough>& sheen_albedo_table() {
    static const std::array<float, kSheenNoV * kSheenRough> table = [] {
        std::array<float, kSheenNoV * kSheenRough> t{};
        constexpr int kTheta = 48, kPhi = 48;  // phi over half the circle (the lobe is symmetric)
        const double pi = glm::pi<double>();
        for (int j = 0; j < kSheenRough; ++j) {
            const double r = std::max(double(kMinPerceptualRoughness), double(j) / (kSheenRough - 1));
            const double alpha = r * r;
            for (int i = 0; i < kSheenNoV; ++i) {
                const double NoV = std::max(double(i) / (kSheenNoV - 1), 1e-4);
                const double sv = std::sqrt(1.0 - NoV * NoV);
                const double lv = sheen_lambda(NoV, alpha);
                double sum = 0.0;
                for (int a = 0; a < kTheta; ++a) {
                    // Uniform in cos(theta_l): dl = d(cos) dphi. V_Charlie's
                    // terms, out of the phi loop (V depends on the cosines only).
                    const double NoL = (a + 0.5) / kTheta, sl = std::sqrt(1.0 - NoL * NoL);
                    const double V = std::min(1.0 / ((1.0 + lv + sheen_lambda(NoL, alpha)) * (4.0 * NoV * NoL)), 1.0);
                    double row = 0.0;
                    for (int b = 0; b < kPhi; ++b) {
                        const double phi = (b + 0.5) * pi / kPhi;
                        const double hx = sl * det::cos(phi) + sv, hy = sl * det::sin(phi), hz = NoL + NoV;
                        const double NoH = hz / std::sqrt(hx * hx + hy * hy + hz * hz);
                        row += D_Charlie(NoH, alpha);
                    }
                    sum += row * V * NoL;
                }
                t[std::size_t(j * kSheenNoV + i)] = float(sum * (1.0 / kTheta) * (2.0 * pi / kPhi));
            }
        }
        return t;
    }();
    return table;
}
inline float sheen_albedo(float NoV, float r) {
    const auto& t = sheen_albedo_table();
    float x = NoV * float(kSheenNoV - 1), y = r * float(kSheenRough - 1);
    x = x > 0.0f ? (x < float(kSheenNoV - 1) ? x : float(kSheenNoV - 1)) : 0.0f;  // NaN -> 0
    y = y > 0.0f ? (y < float(kSheenRough - 1) ? y : float(kSheenRough - 1)) : 0.0f;
    const int x0 = std::min(int(x), kSheenNoV - 2), y0 = std::min(int(y), kSheenRough - 2);
    const float fx = x - float(x0), fy = y - float(y0);
    const float* row0 = &t[std::size_t(y0 * kSheenNoV)];
    const float* row1 = row0 + kSheenNoV;
    const float a = row0[x0] + (row0[x0 + 1] - row0[x0]) * fx;
    const float b = row1[x0] + (row1[x0 + 1] - row1[x0]) * fx;
    return a + (b - a) * fy;
}

// ---- Diffuse

// Lambert: a constant 1 / pi, so that albedo 1 reflects all incident energy.
inline float Fd_Lambert() { return glm::one_over_pi<float>(); }

// ---- Combined evaluation

// Default: docs/conventions.md (Cook-Torrance, Smith/Schlick-GGX G with k_direct).
// Gltf: glTF 2.0 spec appendix B / Filament (height-correlated V instead of
// G / (4 n.v n.l)); same D, F and diffuse.
enum class BrdfModel { Default, Gltf };

inline const char* brdf_model_name(BrdfModel m) {
    return m == BrdfModel::Gltf ? "gltf" : "default";
}
inline bool parse_brdf_model(const std::string& s, BrdfModel& out) {
    if (s == "default") { out = BrdfModel::Default; return true; }
    if (s == "gltf") { out = BrdfModel::Gltf; return true; }
    return false;
}

// n, v, l are unit vectors: v towards the camera, l towards the light.
struct BrdfInputs {
    glm::vec3 n{0.0f, 0.0f, 1.0f}, v{0.0f, 0.0f, 1.0f}, l{0.0f, 0.0f, 1.0f};
    glm::vec3 albedo{0.8f};
    float metallic = 0.0f;
    float roughness = 0.5f;  // perceptual; clamped to [0.045, 1] inside
    float ior = 1.5f;
    Conductor conductor = Conductor::None;  // not None: measured metal, albedo and metallic ignored
    // Smith G with k = r^2 / 2, the conventions' k for image-based lighting
    // (the reference integrator); analytic lights use (r + 1)^2 / 8.
    bool ibl_geometry = false;
    // --energy conserve (dfg.h): the specular lobe times energy_comp (multiple
    // scattering), and kd = energy_kd = (1 - E_spec(v))(1 - metallic) instead
    // of (1 - F)(1 - metallic).
    bool energy = false;
    glm::vec3 energy_comp{1.0f}, energy_kd{0.0f};
    // KHR_materials_specular (specular_ext): the dielectric's F0 is
    // min(F0(ior) specular_color, 1) specular and its F90 specular.
    bool specular_ext = false;
    float specular = 1.0f;
    glm::vec3 specular_color{1.0f};
    // KHR_materials_clearcoat: the coat's weight (0: no coat, the base's
    // arithmetic unchanged), perceptual roughness and unit normal.
    float clearcoat = 0.0f;
    float clearcoat_roughness = 0.0f;
    glm::vec3 clearcoat_n{0.0f, 0.0f, 1.0f};
    // KHR_materials_sheen: the sheen colour (0: no sheen, the base's
    // arithmetic unchanged) and its perceptual roughness.
    glm::vec3 sheen_color{0.0f};
    float sheen_roughness = 0.0f;
    bool has_sheen() const { return sheen_color.x > 0.0f || sheen_color.y > 0.0f || sheen_color.z > 0.0f; }
    // KHR_materials_transmission: the share of the dielectric's diffuse
    // transmitted instead (0: none, the base's arithmetic unchanged), the
    // transmission lobe's perceptual roughness (transmission_roughness())
    // and KHR_materials_volume's transmittance (volume_transmittance()).
    float transmission = 0.0f;
    float transmission_roughness = 0.0f;
    glm::vec3 transmittance{1.0f};
    float thickness = 0.0f;  // KHR_materials_volume's (0: thin-walled), for transmission_direction()
    // --energy conserve: the transmission lobe times transmission_comp =
    // (1 - E_spec) / ((1 - F0) A + (1 - F90) B), so that it carries all the
    // reflection leaves, as the diffuse's kd does (apply_energy_terms()).
    glm::vec3 transmission_comp{1.0f};
};

// Where the environment is seen through a transmitting surface (what the
// Sample Viewer reads from the frame behind it, without a screen-space pass):
// straight on, -v, through a thin wall; through a volume, Filament's "solid
// sphere": refracted in (1 / ior), then out through a back face whose normal
// is (n.r) r - n / 2 normalised, refracted by ior (r itself where that
// reflects totally). n and v unit.
inline glm::vec3 transmission_direction(const glm::vec3& n, const glm::vec3& v, float ior, float thickness) {
    if (!(thickness > 0.0f) || !(ior > 0.0f)) return -v;
    const glm::vec3 r = glm::refract(-v, n, 1.0f / ior);
    const float rl2 = glm::dot(r, r);
    if (!(rl2 > 1e-12f)) return -v;
    const glm::vec3 m = r * glm::dot(n, r) - n * 0.5f;
    const float ml2 = glm::dot(m, m);
    if (!(ml2 > 1e-12f)) return r / std::sqrt(rl2);
    const glm::vec3 out = glm::refract(r, m / std::sqrt(ml2), ior);
    const float ol2 = glm::dot(out, out);
    return ol2 > 1e-12f ? out / std::sqrt(ol2) : r / std::sqrt(rl2);
}

// The transmission lobe's perceptual roughness: the Khronos Sample Viewer's
// applyIorToRoughness, r clamp(2 ior - 2, 0, 1) (an ior of 1 does not blur
// what is seen through the surface).
inline float transmission_roughness(float r, float ior) {
    return r * glm::clamp(ior * 2.0f - 2.0f, 0.0f, 1.0f);
}

// KHR_materials_volume's Beer-Lambert attenuation over a path of length
// `thickness`: per channel exp(-sigma d) with sigma = -ln(colour) / distance,
// i.e. colour^(d / distance); 1 for a thin wall (thickness 0) or an infinite
// distance (0). In double with det::pow (no libm variant changes a pixel),
// rounded once.
inline glm::vec3 volume_transmittance(float thickness, float distance, const glm::vec3& color) {
    if (!(thickness > 0.0f) || !(distance > 0.0f)) return glm::vec3(1.0f);
    glm::vec3 t;
    for (int c = 0; c < 3; ++c)
        t[c] = color[c] > 0.0f ? float(det::pow(double(color[c]), double(thickness) / double(distance)))
                               : 0.0f;
    return t;
}

// The clear coat's F0: a dielectric of ior 1.5, as KHR_materials_clearcoat fixes it.
constexpr float kClearcoatF0 = 0.04f;

// F0 of the inputs: the conductor's reflectance at normal incidence, or the
// conventions' mix of the dielectric's and the albedo by metallic.
inline glm::vec3 brdf_f0(const BrdfInputs& in) {
    if (in.conductor != Conductor::None) {
        ConductorIOR ior = conductor_ior(in.conductor);
        return F_ConductorSchlick(ior.eta, ior.k, 1.0f);
    }
    if (in.specular_ext) {
        const glm::vec3 d = glm::min(glm::vec3(f0_from_ior(in.ior)) * in.specular_color, glm::vec3(1.0f)) * in.specular;
        return glm::mix(d, in.albedo, in.metallic);
    }
    return glm::mix(glm::vec3(f0_from_ior(in.ior)), in.albedo, in.metallic);
}

// F90 of the inputs: 1, or KHR_materials_specular's mix(specular, 1, metallic).
inline float brdf_f90(const BrdfInputs& in) {
    if (in.conductor != Conductor::None || !in.specular_ext) return 1.0f;
    return in.specular * (1.0f - in.metallic) + in.metallic;
}

// Every intermediate, for the debug stepper. The cosines are clamped to [0, 1].
struct BrdfTerms {
    float NoL = 0.0f, NoV = 0.0f, NoH = 0.0f, VoH = 0.0f;
    float D = 0.0f;
    float G = 0.0f;  // Gltf: the visibility V = G / (4 n.v n.l)
    glm::vec3 F{0.0f}, kd{0.0f}, diffuse{0.0f}, specular{0.0f};
    glm::vec3 f{0.0f};  // diffuse + specular; the caller multiplies by radiance * n.l
    // The clear coat (coat true): its cosines about n_c, D, G (or V), its
    // Fresnel F_coat = F_Schlick(0.04, n_c.v), the base's attenuation
    // 1 - clearcoat F_coat (already in f) and the lobe clearcoat F_coat D G,
    // which the caller multiplies by radiance * n_c.l (brdf_light()).
    bool coat = false;
    float coat_NoL = 0.0f, coat_NoV = 0.0f, coat_NoH = 0.0f, coat_D = 0.0f, coat_G = 0.0f, coat_F = 0.0f;
    float coat_attenuation = 1.0f, coat_specular = 0.0f;
    // The sheen (sheen true): its D and V, the albedo scaling of the base
    // min(1 - max(colour) E(n.v), 1 - max(colour) E(n.l)) (already in
    // diffuse and specular) and the lobe colour D V, in f (under the coat).
    bool sheen = false;
    float sheen_D = 0.0f, sheen_V = 0.0f, sheen_scaling = 1.0f;
    glm::vec3 sheen_f{0.0f};
    // KHR_materials_transmission (transmission true): the diffuse above is
    // already times 1 - transmission. A light behind the surface (n.l < 0)
    // reaches the eye through the lobe the Sample Viewer uses: l mirrored
    // through the surface's plane to l', h_t = (l' + v) normalised, and
    // tr_f = transmission (1 - metallic) (1 - F(v.h_t)) albedo D G (or V) x
    // transmittance at the transmission roughness, which the caller
    // multiplies by radiance * n.l' (brdf_light()).
    bool transmission = false;
    float tr_NoL = 0.0f, tr_NoH = 0.0f, tr_VoH = 0.0f, tr_D = 0.0f, tr_G = 0.0f;
    glm::vec3 tr_F{0.0f}, tr_f{0.0f};
};

// The inputs' Fresnel at v.h: evaluate_brdf()'s F, for the transmission lobe.
inline glm::vec3 brdf_fresnel(const BrdfInputs& in, float VoH) {
    if (in.conductor != Conductor::None) {
        ConductorIOR ior = conductor_ior(in.conductor);
        return F_ConductorSchlick(ior.eta, ior.k, VoH);
    }
    if (in.specular_ext) {
        const glm::vec3 F0 = brdf_f0(in);
        return F0 + (glm::vec3(brdf_f90(in)) - F0) * brdf_detail::pow5(1.0f - VoH);
    }
    return F_Schlick(glm::mix(glm::vec3(f0_from_ior(in.ior)), in.albedo, in.metallic), VoH);
}

// The scalar part D G / (4 n.v n.l) of a GGX lobe with perceptual roughness
// r (alpha a = r^2) and distribution value D; with the glTF BRDF D V. The
// clear coat's and the transmission's lobes; G gets G (or V).
inline float ggx_lobe(BrdfModel model, bool ibl_geometry, float NoV, float NoL, float D, float r, float a, float& G) {
    if (model == BrdfModel::Gltf) {
        G = V_SmithGGXCorrelated(NoV, NoL, a);
        return D * G;
    }
    G = G_Smith(NoV, NoL, ibl_geometry ? k_ibl(r) : k_direct(r));
    return D * G / (4.0f * std::max(NoV, kBrdfMinCos) * std::max(NoL, kBrdfMinCos));
}

inline BrdfTerms evaluate_brdf(const BrdfInputs& in, BrdfModel model) {
    BrdfTerms t;
    // Compute cosines and h. l = -v has no half vector; any h gives n.l <= 0 there.
    glm::vec3 sum = in.l + in.v;
    float len2 = glm::dot(sum, sum);
    glm::vec3 h = len2 > 0.0f ? sum / std::sqrt(len2) : in.n;
    t.NoL = glm::clamp(glm::dot(in.n, in.l), 0.0f, 1.0f);
    t.NoV = glm::clamp(glm::dot(in.n, in.v), 0.0f, 1.0f);
    t.NoH = glm::clamp(glm::dot(in.n, h), 0.0f, 1.0f);
    t.VoH = glm::clamp(glm::dot(in.v, h), 0.0f, 1.0f);

    float r = glm::clamp(in.roughness, kMinPerceptualRoughness, 1.0f);
    float alpha = r * r;

    // Evaluate Fresnel factor F.
    float metallic = in.metallic;
    if (in.conductor != Conductor::None) {
        // Conductor Fresnel: the Schlick form with a complex index; its
        // error against the exact equations is measured in test_brdf.cpp.
        ConductorIOR ior = conductor_ior(in.conductor);
        t.F = F_ConductorSchlick(ior.eta, ior.k, t.VoH);
        metallic = 1.0f;
    } else if (in.specular_ext) {
        // KHR_materials_specular: F0 + (F90 - F0) (1 - v.h)^5.
        const glm::vec3 F0 = brdf_f0(in);
        const float F90 = brdf_f90(in);
        t.F = F0 + (glm::vec3(F90) - F0) * brdf_detail::pow5(1.0f - t.VoH);
    } else {
        glm::vec3 F0 = glm::mix(glm::vec3(f0_from_ior(in.ior)), in.albedo, in.metallic);
        t.F = F_Schlick(F0, t.VoH);
    }

    // Evaluate D and G (or V) and the specular lobe.
    t.D = D_GGX(t.NoH, alpha);
    if (model == BrdfModel::Gltf) {
        t.G = V_SmithGGXCorrelated(t.NoV, t.NoL, alpha);
        t.specular = t.F * t.D * t.G;
    } else {
        t.G = G_Smith(t.NoV, t.NoL, in.ibl_geometry ? k_ibl(r) : k_direct(r));
        t.specular = t.D * t.G * t.F /
                     (4.0f * std::max(t.NoV, kBrdfMinCos) * std::max(t.NoL, kBrdfMinCos));
    }
    if (in.energy) t.specular = t.specular * in.energy_comp;

    // Evaluate the diffuse lobe: what the specular reflection leaves, if not a metal.
    t.kd = in.energy ? in.energy_kd : (glm::vec3(1.0f) - t.F) * (1.0f - metallic);
    t.diffuse = t.kd * in.albedo * Fd_Lambert();
    if (in.transmission > 0.0f) {
        // KHR_materials_transmission: the transmitted share leaves the diffuse.
        t.transmission = true;
        t.diffuse = t.diffuse * (1.0f - in.transmission);
        const float NoL = glm::dot(in.n, in.l);
        if (NoL < 0.0f) {
            const glm::vec3 lm = in.l - in.n * (2.0f * NoL);
            const glm::vec3 hs = lm + in.v;
            const float hl2 = glm::dot(hs, hs);
            const glm::vec3 ht = hl2 > 0.0f ? hs / std::sqrt(hl2) : in.n;
            t.tr_NoL = glm::clamp(glm::dot(in.n, lm), 0.0f, 1.0f);
            t.tr_NoH = glm::clamp(glm::dot(in.n, ht), 0.0f, 1.0f);
            t.tr_VoH = glm::clamp(glm::dot(in.v, ht), 0.0f, 1.0f);
            const float rt = glm::clamp(in.transmission_roughness, kMinPerceptualRoughness, 1.0f);
            const float at = rt * rt;
            t.tr_F = brdf_fresnel(in, t.tr_VoH);
            t.tr_D = D_GGX(t.tr_NoH, at);
            const float lobe = ggx_lobe(model, in.ibl_geometry, t.NoV, t.tr_NoL, t.tr_D, rt, at, t.tr_G);
            t.tr_f = (glm::vec3(1.0f) - t.tr_F) * in.albedo * in.transmittance *
                     (in.transmission * (1.0f - metallic) * lobe);
            if (in.energy) t.tr_f = t.tr_f * in.transmission_comp;
        }
    }
    t.f = t.diffuse + t.specular;
    if (in.has_sheen()) {
        // KHR_materials_sheen: the Charlie lobe over the base, which keeps
        // what the sheen leaves (the extension's albedo scaling).
        t.sheen = true;
        const float rs = glm::clamp(in.sheen_roughness, kMinPerceptualRoughness, 1.0f);
        const double as = double(rs) * double(rs);
        t.sheen_D = float(D_Charlie(double(t.NoH), as));
        t.sheen_V = float(V_Charlie(double(t.NoV), double(t.NoL), as));
        const float cmax = std::max(in.sheen_color.x, std::max(in.sheen_color.y, in.sheen_color.z));
        t.sheen_scaling = std::min(1.0f - cmax * sheen_albedo(t.NoV, rs), 1.0f - cmax * sheen_albedo(t.NoL, rs));
        t.diffuse = t.diffuse * t.sheen_scaling;
        t.specular = t.specular * t.sheen_scaling;
        t.sheen_f = in.sheen_color * (t.sheen_D * t.sheen_V);
        t.tr_f = t.tr_f * t.sheen_scaling;
        t.f = t.diffuse + t.specular + t.sheen_f;
    }
    if (in.clearcoat > 0.0f) {
        // KHR_materials_clearcoat: a GGX lobe about the coat's normal with the
        // coat's roughness and the extension's fresnel_coat, Schlick's F at
        // n_c.v, which weights the lobe and attenuates the base beneath.
        t.coat = true;
        t.coat_NoL = glm::clamp(glm::dot(in.clearcoat_n, in.l), 0.0f, 1.0f);
        t.coat_NoV = glm::clamp(glm::dot(in.clearcoat_n, in.v), 0.0f, 1.0f);
        t.coat_NoH = glm::clamp(glm::dot(in.clearcoat_n, h), 0.0f, 1.0f);
        const float rc = glm::clamp(in.clearcoat_roughness, kMinPerceptualRoughness, 1.0f);
        const float ac = rc * rc;
        t.coat_F = F_Schlick(kClearcoatF0, t.coat_NoV);
        t.coat_D = D_GGX(t.coat_NoH, ac);
        const float lobe = ggx_lobe(model, in.ibl_geometry, t.coat_NoV, t.coat_NoL, t.coat_D, rc, ac, t.coat_G);
        t.coat_attenuation = 1.0f - in.clearcoat * t.coat_F;
        t.coat_specular = in.clearcoat * t.coat_F * lobe;
        t.diffuse = t.diffuse * t.coat_attenuation;
        t.specular = t.specular * t.coat_attenuation;
        t.tr_f = t.tr_f * t.coat_attenuation;
        t.f = t.diffuse + t.specular;
        if (t.sheen) {  // the sheen lies under the coat too
            t.sheen_f = t.sheen_f * t.coat_attenuation;
            t.f = t.f + t.sheen_f;
        }
    }
    return t;
}

// One light's reflected radiance from its terms: f radiance n.l, plus the
// clear coat's lobe times radiance n_c.l.
inline glm::vec3 brdf_light(const BrdfTerms& t, const glm::vec3& radiance) {
    glm::vec3 c = t.f * radiance * t.NoL;
    if (t.coat) c += glm::vec3(t.coat_specular) * radiance * t.coat_NoL;
    if (t.transmission) c += t.tr_f * radiance * t.tr_NoL;
    return c;
}

} // namespace prast

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
#include <cmath>
#include <string>

#include <glm/glm.hpp>
#include <glm/gtc/constants.hpp>

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
};

// F0 of the inputs: the conductor's reflectance at normal incidence, or the
// conventions' mix of the dielectric's and the albedo by metallic.
inline glm::vec3 brdf_f0(const BrdfInputs& in) {
    if (in.conductor != Conductor::None) {
        ConductorIOR ior = conductor_ior(in.conductor);
        return F_ConductorSchlick(ior.eta, ior.k, 1.0f);
    }
    return glm::mix(glm::vec3(f0_from_ior(in.ior)), in.albedo, in.metallic);
}

// Every intermediate, for the debug stepper. The cosines are clamped to [0, 1].
struct BrdfTerms {
    float NoL = 0.0f, NoV = 0.0f, NoH = 0.0f, VoH = 0.0f;
    float D = 0.0f;
    float G = 0.0f;  // Gltf: the visibility V = G / (4 n.v n.l)
    glm::vec3 F{0.0f}, kd{0.0f}, diffuse{0.0f}, specular{0.0f};
    glm::vec3 f{0.0f};  // diffuse + specular; the caller multiplies by radiance * n.l
};

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
    t.f = t.diffuse + t.specular;
    return t;
}

} // namespace prast

// The reference integral of the reflectance equation; see ibl_reference.h.
#include "shading/ibl/ibl_reference.h"

#include <algorithm>
#include <cmath>

#include "shading/ibl/ibl_sampling.h"

namespace prast {

glm::vec3 integrate_environment(const Environment& env, const BrdfInputs& in_, BrdfModel model, int samples) {
    BrdfInputs in = in_;
    in.ibl_geometry = true;
    if (samples < 1) return glm::vec3(0.0f);
    const glm::dvec3 n(in.n), v(in.v);
    const double r = std::clamp(double(in.roughness), double(kMinPerceptualRoughness), 1.0);
    const double alpha = r * r;
    const Frame frame(n);

    // Shares: a third for the map when it can be sampled; the rest between the
    // specular and the diffuse lobe by how metallic the material is.
    const double metal = in.conductor != Conductor::None ? 1.0 : std::clamp(double(in.metallic), 0.0, 1.0);
    const int n_env = env.has_sampler() ? samples / 3 : 0;
    const int rest = samples - n_env;
    int n_ggx = std::min(rest, int(std::lround(rest * (0.5 + 0.5 * metal))));
    int n_cos = rest - n_ggx;
    // KHR_materials_clearcoat: half of the GGX share samples the coat's lobe
    // (its own normal and roughness); without a coat nothing changes.
    const bool coat = in.clearcoat > 0.0f;
    const glm::dvec3 nc(in.clearcoat_n);
    const double rc = std::clamp(double(in.clearcoat_roughness), double(kMinPerceptualRoughness), 1.0);
    const double alpha_c = rc * rc;
    const Frame frame_c(coat ? nc : n);
    const int n_coat = coat ? n_ggx / 2 : 0;
    n_ggx -= n_coat;
    // KHR_materials_transmission: the transmitted share of the diffuse's
    // samples goes to the transmission lobe, the reflection lobe of the
    // transmission roughness mirrored through the surface's plane (the lobe
    // evaluate_brdf() gives a light behind the surface). What it sees is the
    // environment along the lobe's direction turned as -v is turned to
    // transmission_direction() (no turn for a thin wall), as the split sum
    // looks it up.
    const bool tr = in.transmission > 0.0f;
    const double rt = std::clamp(double(in.transmission_roughness), double(kMinPerceptualRoughness), 1.0);
    const double alpha_t = rt * rt;
    const int n_tr = tr ? std::min(n_cos, int(std::lround(n_cos * std::clamp(double(in.transmission), 0.0, 1.0)))) : 0;
    n_cos -= n_tr;
    // The turn: Rodrigues' rotation taking a = -v to b.
    glm::dvec3 turn_axis(0.0);
    double turn_cos = 1.0, turn_sin = 0.0;
    if (tr && in.thickness > 0.0f) {
        const glm::dvec3 a = -v, b(transmission_direction(in.n, in.v, in.ior, in.thickness));
        const glm::dvec3 c = glm::cross(a, b);
        turn_sin = glm::length(c);
        turn_cos = glm::dot(a, b);
        if (turn_sin > 1e-12) turn_axis = c / turn_sin;
    }
    auto turned = [&](const glm::dvec3& l) {
        if (!(turn_sin > 1e-12)) return l;
        return l * turn_cos + glm::cross(turn_axis, l) * turn_sin + turn_axis * (glm::dot(turn_axis, l) * (1.0 - turn_cos));
    };

    // count samples' density at l of GGX half vectors about `normal` with
    // alpha a: D(n.h) n.h / (4 v.h) each, 0 where the half vector is not
    // on the normal's and v's side.
    auto ggx_density = [&](int count, const glm::dvec3& l, const glm::dvec3& normal, double a) {
        const glm::dvec3 hsum = l + v;
        const double len = glm::length(hsum);
        if (!(len > 0.0)) return 0.0;
        const glm::dvec3 h = hsum / len;
        const double VoH = glm::dot(v, h), NoH = glm::dot(normal, h);
        return VoH > 0.0 && NoH > 0.0 ? count * D_GGX_d(NoH, a) * NoH / (4.0 * VoH) : 0.0;
    };
    // sum_s N_s pdf_s(l) for a direction l.
    auto mixture_pdf = [&](const glm::dvec3& l) {
        double p = 0.0;
        const double NoL = glm::dot(n, l);
        if (n_cos > 0 && NoL > 0.0) p += n_cos * NoL / M_PI;
        if (n_ggx > 0) p += ggx_density(n_ggx, l, n, alpha);
        if (n_env > 0) p += n_env * env.direction_pdf(glm::vec3(l));
        // The transmission's: the GGX density at l mirrored (its samples may land in front too).
        if (n_tr > 0) p += ggx_density(n_tr, l - n * (2.0 * NoL), n, alpha_t);
        if (n_coat > 0) p += ggx_density(n_coat, l, nc, alpha_c);
        return p;
    };

    glm::dvec3 sum(0.0);
    auto add = [&](const glm::dvec3& l) {
        const bool behind = tr && glm::dot(n, l) < 0.0;
        if (!(glm::dot(n, l) > 0.0) && !(coat && glm::dot(nc, l) > 0.0) && !behind) return;
        const double p = mixture_pdf(l);
        if (!(p > 0.0)) return;
        in.l = glm::vec3(l);
        const BrdfTerms t = evaluate_brdf(in, model);
        const glm::vec3 L = env.radiance(in.l);
        sum += glm::dvec3(t.f * L) * (double(t.NoL) / p);
        if (t.coat) sum += glm::dvec3(L) * (double(t.coat_specular) * double(t.coat_NoL) / p);
        if (behind && t.tr_NoL > 0.0f) {
            const glm::vec3 Lt = env.radiance(glm::vec3(turned(l)));
            sum += glm::dvec3(t.tr_f * Lt) * (double(t.tr_NoL) / p);
        }
    };
    for (int j = 0; j < n_ggx; ++j) {
        const glm::dvec3 h = frame.to_world(sample_ggx_half(hammersley(std::uint32_t(j), std::uint32_t(n_ggx)), alpha));
        // A half vector facing away from v reflects v below the surface, where
        // mixture_pdf() counts no density for it: with transmission, which
        // evaluates directions there, it is a lost sample.
        if (tr && !(glm::dot(v, h) > 0.0)) continue;
        add(2.0 * glm::dot(v, h) * h - v);
    }
    for (int j = 0; j < n_coat; ++j) {
        const glm::dvec3 h =
            frame_c.to_world(sample_ggx_half(hammersley(std::uint32_t(j), std::uint32_t(n_coat)), alpha_c));
        if (tr && !(glm::dot(v, h) > 0.0)) continue;  // as above
        add(2.0 * glm::dot(v, h) * h - v);
    }
    for (int j = 0; j < n_tr; ++j) {
        const glm::dvec3 h = frame.to_world(sample_ggx_half(hammersley(std::uint32_t(j), std::uint32_t(n_tr)), alpha_t));
        if (!(glm::dot(v, h) > 0.0)) continue;  // as above
        const glm::dvec3 lm = 2.0 * glm::dot(v, h) * h - v;
        add(lm - n * (2.0 * glm::dot(n, lm)));  // mirrored through the surface's plane
    }
    for (int j = 0; j < n_cos; ++j)
        add(frame.to_world(sample_cosine(hammersley(std::uint32_t(j), std::uint32_t(n_cos)))));
    for (int j = 0; j < n_env; ++j) {
        double pdf;
        add(glm::dvec3(env.sample_direction(hammersley(std::uint32_t(j), std::uint32_t(n_env)), pdf)));
    }
    return glm::vec3(sum);
}

} // namespace prast

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
    const int n_cos = rest - n_ggx;
    // KHR_materials_clearcoat: half of the GGX share samples the coat's lobe
    // (its own normal and roughness); without a coat nothing changes.
    const bool coat = in.clearcoat > 0.0f;
    const glm::dvec3 nc(in.clearcoat_n);
    const double rc = std::clamp(double(in.clearcoat_roughness), double(kMinPerceptualRoughness), 1.0);
    const double alpha_c = rc * rc;
    const Frame frame_c(coat ? nc : n);
    const int n_coat = coat ? n_ggx / 2 : 0;
    n_ggx -= n_coat;

    // sum_s N_s pdf_s(l) for a direction l.
    auto mixture_pdf = [&](const glm::dvec3& l) {
        double p = 0.0;
        const double NoL = glm::dot(n, l);
        if (n_cos > 0 && NoL > 0.0) p += n_cos * NoL / M_PI;
        if (n_ggx > 0) {
            const glm::dvec3 hsum = l + v;
            const double len = glm::length(hsum);
            if (len > 0.0) {
                const glm::dvec3 h = hsum / len;
                const double VoH = glm::dot(v, h), NoH = glm::dot(n, h);
                if (VoH > 0.0 && NoH > 0.0) p += n_ggx * D_GGX_d(NoH, alpha) * NoH / (4.0 * VoH);
            }
        }
        if (n_env > 0) p += n_env * env.direction_pdf(glm::vec3(l));
        if (n_coat > 0) {
            const glm::dvec3 hsum = l + v;
            const double len = glm::length(hsum);
            if (len > 0.0) {
                const glm::dvec3 h = hsum / len;
                const double VoH = glm::dot(v, h), NoH = glm::dot(nc, h);
                if (VoH > 0.0 && NoH > 0.0) p += n_coat * D_GGX_d(NoH, alpha_c) * NoH / (4.0 * VoH);
            }
        }
        return p;
    };

    glm::dvec3 sum(0.0);
    auto add = [&](const glm::dvec3& l) {
        if (!(glm::dot(n, l) > 0.0) && !(coat && glm::dot(nc, l) > 0.0)) return;
        const double p = mixture_pdf(l);
        if (!(p > 0.0)) return;
        in.l = glm::vec3(l);
        const BrdfTerms t = evaluate_brdf(in, model);
        const glm::vec3 L = env.radiance(in.l);
        sum += glm::dvec3(t.f * L) * (double(t.NoL) / p);
        if (t.coat) sum += glm::dvec3(L) * (double(t.coat_specular) * double(t.coat_NoL) / p);
    };
    for (int j = 0; j < n_ggx; ++j) {
        const glm::dvec3 h = frame.to_world(sample_ggx_half(hammersley(std::uint32_t(j), std::uint32_t(n_ggx)), alpha));
        add(2.0 * glm::dot(v, h) * h - v);
    }
    for (int j = 0; j < n_coat; ++j) {
        const glm::dvec3 h =
            frame_c.to_world(sample_ggx_half(hammersley(std::uint32_t(j), std::uint32_t(n_coat)), alpha_c));
        add(2.0 * glm::dot(v, h) * h - v);
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

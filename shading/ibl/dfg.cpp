// Building the DFG tables; see dfg.h.
#include "shading/ibl/dfg.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "shading/brdf.h"
#include "shading/ibl/ibl_sampling.h"

namespace prast {

namespace {

// A and B along one roughness row: GGX importance sampling of h (pdf
// D (n.h)), l the mirror of v about h, so f_spec (n.l) / pdf_l =
// (f_spec / (D F)) (n.l) 4 (v.h) / (n.h). The half vectors depend on the
// row only, so they are drawn once and reused for every n.v.
void integrate_specular_row(DfgModel model, double r, glm::dvec2* out) {
    constexpr int S = DfgTable::kSizeNoV, N = DfgTable::kSamples;
    const double alpha = r * r, a2 = alpha * alpha;
    const double eps = kBrdfMinCos;
    const double k = model == DfgModel::SchlickIbl ? r * r * 0.5 : (r + 1.0) * (r + 1.0) * 0.125;
    std::vector<glm::dvec3> hs(N);
    for (int i = 0; i < N; ++i) hs[std::size_t(i)] = sample_ggx_half(hammersley(std::uint32_t(i), N), alpha);
    for (int c = 0; c < S; ++c) {
        const double NoV = (double(c) / (S - 1)) * (double(c) / (S - 1));
        const glm::dvec3 v(std::sqrt(std::max(0.0, 1.0 - NoV * NoV)), 0.0, NoV);
        glm::dvec2 sum(0.0);
        for (const glm::dvec3& h : hs) {
            const double VoH = glm::dot(v, h);
            const double NoL = std::min(2.0 * VoH * h.z - NoV, 1.0), NoH = h.z;
            if (!(NoL > 0.0) || !(VoH > 0.0) || !(NoH > 0.0)) continue;
            double w;
            if (model == DfgModel::HeightCorrelated) {
                const double gv = NoL * std::sqrt(NoV * NoV * (1.0 - a2) + a2);
                const double gl = NoV * std::sqrt(NoL * NoL * (1.0 - a2) + a2);
                const double V = gv + gl > 0.0 ? 0.5 / (gv + gl) : 0.0;
                w = V * NoL * 4.0 * VoH / NoH;
            } else {
                const double G = NoV / (NoV * (1.0 - k) + k) * (NoL / (NoL * (1.0 - k) + k));
                w = G * NoL * VoH / (std::max(NoV, eps) * std::max(NoL, eps) * NoH);
            }
            const double fc = pow5d(1.0 - VoH);
            sum.x += (1.0 - fc) * w;
            sum.y += fc * w;
        }
        out[c] = sum / double(N);
    }
}

// Kd at one n.v: cosine-weighted l (pdf (n.l) / pi), so the integral is the
// mean of 1 - Fc(v.h). `ls` holds the kSamples directions, the same for
// every n.v.
double integrate_diffuse_fresnel(double NoV, const std::vector<glm::dvec3>& ls) {
    const glm::dvec3 v(std::sqrt(std::max(0.0, 1.0 - NoV * NoV)), 0.0, NoV);
    double sum = 0.0;
    for (const glm::dvec3& l : ls) {
        const glm::dvec3 h = glm::normalize(l + v);
        sum += 1.0 - pow5d(1.0 - std::clamp(glm::dot(v, h), 0.0, 1.0));
    }
    return sum / double(DfgTable::kSamples);
}

} // namespace

DfgTable DfgTable::build(DfgModel model, ThreadPool& pool) {
    constexpr int S = kSizeNoV, R = kSizeRough;
    DfgTable t;
    t.model_ = model;
    t.texels_.assign(std::size_t(S) * R, glm::vec4(0.0f));
    std::vector<glm::dvec3> ls(kSamples);
    for (int i = 0; i < kSamples; ++i) ls[std::size_t(i)] = sample_cosine(hammersley(std::uint32_t(i), kSamples));
    std::vector<double> kd(S);
    pool.run(S, [&](int i, int) {
        const double c = double(i) / (S - 1);
        kd[std::size_t(i)] = integrate_diffuse_fresnel(c * c, ls);
    });
    pool.run(R, [&](int j, int) {
        const double r = std::clamp(double(j) / (R - 1), double(kMinPerceptualRoughness), 1.0);
        glm::dvec2 ab[S];
        integrate_specular_row(model, r, ab);
        for (int i = 0; i < S; ++i)
            t.texels_[std::size_t(j) * S + std::size_t(i)] =
                glm::vec4(float(ab[i].x), float(ab[i].y), float(kd[std::size_t(i)]), 0.0f);
    });
    return t;
}

} // namespace prast

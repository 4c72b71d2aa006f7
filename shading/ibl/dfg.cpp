// Building the DFG tables; see dfg.h.
#include "shading/ibl/dfg.h"

#include <algorithm>
#include <cmath>
#include <vector>

#ifdef __AVX2__
#include <immintrin.h>
#endif

#include "shading/brdf.h"
#include "shading/ibl/ibl_sampling.h"

namespace prast {

namespace {

// A and B along one roughness row: GGX importance sampling of h (pdf
// D (n.h)), l the mirror of v about h, so f_spec (n.l) / pdf_l =
// (f_spec / (D F)) (n.l) 4 (v.h) / (n.h). The half vectors depend on the
// row only, so they are drawn once and reused for every n.v.
#ifdef __AVX2__
// Columns c .. c + 3 of a row in four double lanes: the scalar loop's
// operations in its order, lane by lane (IEEE adds, multiplies, divisions
// and square roots, so the same bits); a sample a lane skips leaves its sums
// as they are. Terms of n.v alone are worked out once.
void integrate_specular_four(DfgModel model, int c, double a2, double k, double eps, const std::vector<glm::dvec3>& hs,
                             glm::dvec2* out) {
    constexpr int S = DfgTable::kSizeNoV;
    alignas(32) double nov[4], vx[4];
    for (int l = 0; l < 4; ++l) {
        nov[l] = (double(c + l) / (S - 1)) * (double(c + l) / (S - 1));
        vx[l] = std::sqrt(std::max(0.0, 1.0 - nov[l] * nov[l]));
    }
    const __m256d NoV = _mm256_load_pd(nov), v_x = _mm256_load_pd(vx), v_y = _mm256_setzero_pd();
    const __m256d zero = _mm256_setzero_pd(), one = _mm256_set1_pd(1.0), two = _mm256_set1_pd(2.0);
    const __m256d one_minus_a2 = _mm256_set1_pd(1.0 - a2), A2 = _mm256_set1_pd(a2);
    const __m256d one_minus_k = _mm256_set1_pd(1.0 - k), K = _mm256_set1_pd(k), Eps = _mm256_set1_pd(eps);
    const bool height_correlated = model == DfgModel::HeightCorrelated;
    // sqrt(NoV NoV (1 - a2) + a2), NoV / (NoV (1 - k) + k) and max(NoV, eps).
    const __m256d root_v =
        _mm256_sqrt_pd(_mm256_add_pd(_mm256_mul_pd(_mm256_mul_pd(NoV, NoV), one_minus_a2), A2));
    const __m256d g_v = _mm256_div_pd(NoV, _mm256_add_pd(_mm256_mul_pd(NoV, one_minus_k), K));
    const __m256d NoV_eps = _mm256_blendv_pd(NoV, Eps, _mm256_cmp_pd(NoV, Eps, _CMP_LT_OQ));
    __m256d sum_a = zero, sum_b = zero;
    for (const glm::dvec3& h : hs) {
        if (!(h.z > 0.0)) continue;
        const __m256d hx = _mm256_set1_pd(h.x), hy = _mm256_set1_pd(h.y), NoH = _mm256_set1_pd(h.z);
        // glm::dot: (v.x h.x + v.y h.y) + v.z h.z, v.z = n.v.
        const __m256d VoH = _mm256_add_pd(_mm256_add_pd(_mm256_mul_pd(v_x, hx), _mm256_mul_pd(v_y, hy)),
                                          _mm256_mul_pd(NoV, NoH));
        __m256d NoL = _mm256_sub_pd(_mm256_mul_pd(_mm256_mul_pd(two, VoH), NoH), NoV);
        NoL = _mm256_blendv_pd(NoL, one, _mm256_cmp_pd(one, NoL, _CMP_LT_OQ));  // std::min(NoL, 1.0)
        const __m256d live = _mm256_and_pd(_mm256_cmp_pd(NoL, zero, _CMP_GT_OQ), _mm256_cmp_pd(VoH, zero, _CMP_GT_OQ));
        if (_mm256_movemask_pd(live) == 0) continue;
        __m256d w;
        if (height_correlated) {
            const __m256d gv = _mm256_mul_pd(NoL, root_v);
            const __m256d gl = _mm256_mul_pd(
                NoV, _mm256_sqrt_pd(_mm256_add_pd(_mm256_mul_pd(_mm256_mul_pd(NoL, NoL), one_minus_a2), A2)));
            const __m256d g = _mm256_add_pd(gv, gl);
            const __m256d V = _mm256_and_pd(_mm256_div_pd(_mm256_set1_pd(0.5), g), _mm256_cmp_pd(g, zero, _CMP_GT_OQ));
            w = _mm256_div_pd(_mm256_mul_pd(_mm256_mul_pd(_mm256_mul_pd(V, NoL), _mm256_set1_pd(4.0)), VoH), NoH);
        } else {
            const __m256d G =
                _mm256_mul_pd(g_v, _mm256_div_pd(NoL, _mm256_add_pd(_mm256_mul_pd(NoL, one_minus_k), K)));
            const __m256d NoL_eps = _mm256_blendv_pd(NoL, Eps, _mm256_cmp_pd(NoL, Eps, _CMP_LT_OQ));
            w = _mm256_div_pd(_mm256_mul_pd(_mm256_mul_pd(G, NoL), VoH),
                              _mm256_mul_pd(_mm256_mul_pd(NoV_eps, NoL_eps), NoH));
        }
        const __m256d x = _mm256_sub_pd(one, VoH), x2 = _mm256_mul_pd(x, x);
        const __m256d fc = _mm256_mul_pd(_mm256_mul_pd(x2, x2), x);  // pow5d
        sum_a = _mm256_blendv_pd(sum_a, _mm256_add_pd(sum_a, _mm256_mul_pd(_mm256_sub_pd(one, fc), w)), live);
        sum_b = _mm256_blendv_pd(sum_b, _mm256_add_pd(sum_b, _mm256_mul_pd(fc, w)), live);
    }
    alignas(32) double a[4], b[4];
    _mm256_store_pd(a, sum_a);
    _mm256_store_pd(b, sum_b);
    for (int l = 0; l < 4; ++l) out[l] = glm::dvec2(a[l], b[l]) / double(DfgTable::kSamples);
}
#endif

void integrate_specular_row(DfgModel model, double r, glm::dvec2* out, DfgTable::Path path) {
    constexpr int S = DfgTable::kSizeNoV, N = DfgTable::kSamples;
    const double alpha = r * r, a2 = alpha * alpha;
    const double eps = kBrdfMinCos;
    const double k = model == DfgModel::SchlickIbl ? r * r * 0.5 : (r + 1.0) * (r + 1.0) * 0.125;
    std::vector<glm::dvec3> hs(N);
    for (int i = 0; i < N; ++i) hs[std::size_t(i)] = sample_ggx_half(hammersley(std::uint32_t(i), N), alpha);
    int c = 0;
#ifdef __AVX2__
    if (path == DfgTable::Path::Lanes)
        for (; c + 4 <= S; c += 4) integrate_specular_four(model, c, a2, k, eps, hs, out + c);
#else
    (void)path;
#endif
    for (; c < S; ++c) {
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

DfgTable DfgTable::build(DfgModel model, ThreadPool& pool, Path path) {
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
        integrate_specular_row(model, r, ab, path);
        for (int i = 0; i < S; ++i)
            t.texels_[std::size_t(j) * S + std::size_t(i)] =
                glm::vec4(float(ab[i].x), float(ab[i].y), float(kd[std::size_t(i)]), 0.0f);
    });
    return t;
}

} // namespace prast

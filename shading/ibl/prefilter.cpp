// Resampling and GGX prefiltering of equirect levels; see prefilter.h.
#include "shading/ibl/prefilter.h"

#include <algorithm>
#include <cmath>
#include <vector>

#ifdef __AVX2__
#include <immintrin.h>
#endif

#include "scene/det_math.h"
#include "shading/ibl/ibl_sampling.h"

namespace prast {

namespace {

struct Tap {
    int index;
    double weight;
};

// For each of n_out cells of [0, 1), the source cells of n_in it overlaps and
// their weights: the overlap's length, or with `solid_angle` (rows, theta =
// pi * coordinate) its solid angle cos(theta_lo) - cos(theta_hi). Normalised.
std::vector<std::vector<Tap>> overlap_taps(int n_in, int n_out, bool solid_angle) {
    std::vector<std::vector<Tap>> taps(static_cast<std::size_t>(n_out));
    for (int o = 0; o < n_out; ++o) {
        const double a = double(o) * n_in / n_out, b = double(o + 1) * n_in / n_out;
        double total = 0.0;
        for (int j = int(std::floor(a)); j < n_in && double(j) < b; ++j) {
            const double lo = std::max(a, double(j)), hi = std::min(b, double(j + 1));
            if (!(hi > lo)) continue;
            const double w = solid_angle ? det::cos(M_PI * lo / n_in) - det::cos(M_PI * hi / n_in) : hi - lo;
            taps[std::size_t(o)].push_back({j, w});
            total += w;
        }
        for (Tap& t : taps[std::size_t(o)]) t.weight = total > 0.0 ? t.weight / total : 0.0;
    }
    return taps;
}

// One GGX sample of a prefiltered row, worked out once per row (see
// prefilter_ggx): where texel 0 reads it, and the rows, weights and level
// blend that every texel of the row shares.
struct GgxTap {
    double u0;
    const glm::vec4* rows[4];  // level a: rows ya, yb; level b: rows ya, yb
    float fw[2], ty[2], t, weight;
    std::int32_t w[2];
};

// Texel x of a row: the sum of its taps, u = u0 + shift, shift = x / width.
glm::vec4 prefilter_texel(const std::vector<GgxTap>& taps, double shift) {
    glm::vec3 sum(0.0f);
    for (const GgxTap& t : taps) {
        double u = t.u0 + shift;
        u -= std::floor(u);
        glm::vec3 c[2];
        for (int k = 0; k < 2; ++k) {
            const float fx = float(u) * t.fw[k] - 0.5f;
            const float fl = std::floor(fx);
            const float tx = fx - fl;
            const int x0 = int(fl), w = t.w[k];
            const int xa = x0 < 0 ? x0 + w : (x0 >= w ? x0 - w : x0);
            const int xb = x0 + 1 >= w ? x0 + 1 - w : x0 + 1;
            const glm::vec3 a0(t.rows[2 * k][xa]), b0(t.rows[2 * k][xb]);
            const glm::vec3 a1(t.rows[2 * k + 1][xa]), b1(t.rows[2 * k + 1][xb]);
            const glm::vec3 top_row = a0 + (b0 - a0) * tx, bottom_row = a1 + (b1 - a1) * tx;
            c[k] = top_row + (bottom_row - top_row) * t.ty[k];
        }
        sum += (c[0] + (c[1] - c[0]) * t.t) * t.weight;
    }
    return glm::vec4(sum, 0.0f);
}

#ifdef __AVX2__
// Texels x .. x + 7 of a row: prefilter_texel's operations in its order,
// lane by lane, so the same bits (IEEE adds, multiplies, floors and
// conversions). The texel coordinates of the eight run in one register;
// the bilinear blends run on two texels' (r, g, b, unused) at a time, their
// texels read whole. (Gathering each channel instead is slower on Zen 3.)
void prefilter_eight(const std::vector<GgxTap>& taps, const double* shift, glm::vec4* out) {
    const __m256d shift_lo = _mm256_loadu_pd(shift), shift_hi = _mm256_loadu_pd(shift + 4);
    const __m256i one = _mm256_set1_epi32(1);
    __m256 sum[4];
    for (int l = 0; l < 4; ++l) sum[l] = _mm256_setzero_ps();
    alignas(32) std::int32_t ia[2][8], ib[2][8];
    __m256 txv[2];
    for (const GgxTap& t : taps) {
        const __m256d u0 = _mm256_set1_pd(t.u0);
        __m256d u_lo = _mm256_add_pd(u0, shift_lo), u_hi = _mm256_add_pd(u0, shift_hi);
        u_lo = _mm256_sub_pd(u_lo, _mm256_floor_pd(u_lo));
        u_hi = _mm256_sub_pd(u_hi, _mm256_floor_pd(u_hi));
        const __m256 u = _mm256_set_m128(_mm256_cvtpd_ps(u_hi), _mm256_cvtpd_ps(u_lo));
        for (int k = 0; k < 2; ++k) {
            const __m256 fx = _mm256_sub_ps(_mm256_mul_ps(u, _mm256_set1_ps(t.fw[k])), _mm256_set1_ps(0.5f));
            const __m256 fl = _mm256_floor_ps(fx);
            txv[k] = _mm256_sub_ps(fx, fl);
            const __m256i x0 = _mm256_cvttps_epi32(fl), w = _mm256_set1_epi32(t.w[k]);
            const __m256i last = _mm256_sub_epi32(w, one);
            const __m256i xa = _mm256_sub_epi32(
                _mm256_add_epi32(x0, _mm256_and_si256(_mm256_cmpgt_epi32(_mm256_setzero_si256(), x0), w)),
                _mm256_and_si256(_mm256_cmpgt_epi32(x0, last), w));
            const __m256i x1 = _mm256_add_epi32(x0, one);
            const __m256i xb = _mm256_sub_epi32(x1, _mm256_and_si256(_mm256_cmpgt_epi32(x1, last), w));
            _mm256_store_si256(reinterpret_cast<__m256i*>(ia[k]), _mm256_slli_epi32(xa, 2));
            _mm256_store_si256(reinterpret_cast<__m256i*>(ib[k]), _mm256_slli_epi32(xb, 2));
        }
        const __m256 ty0 = _mm256_set1_ps(t.ty[0]), ty1 = _mm256_set1_ps(t.ty[1]);
        const __m256 blend = _mm256_set1_ps(t.t), weight = _mm256_set1_ps(t.weight);
        const float* r[4] = {reinterpret_cast<const float*>(t.rows[0]), reinterpret_cast<const float*>(t.rows[1]),
                             reinterpret_cast<const float*>(t.rows[2]), reinterpret_cast<const float*>(t.rows[3])};
        for (int p = 0; p < 4; ++p) {
            const int l = 2 * p;  // lanes l (low half) and l + 1
            const __m256i spread = _mm256_setr_epi32(l, l, l, l, l + 1, l + 1, l + 1, l + 1);
            __m256 c[2];
            for (int k = 0; k < 2; ++k) {
                const __m256 tx = _mm256_permutevar8x32_ps(txv[k], spread);
                const __m256 a0 = _mm256_loadu2_m128(r[2 * k] + ia[k][l + 1], r[2 * k] + ia[k][l]);
                const __m256 b0 = _mm256_loadu2_m128(r[2 * k] + ib[k][l + 1], r[2 * k] + ib[k][l]);
                const __m256 a1 = _mm256_loadu2_m128(r[2 * k + 1] + ia[k][l + 1], r[2 * k + 1] + ia[k][l]);
                const __m256 b1 = _mm256_loadu2_m128(r[2 * k + 1] + ib[k][l + 1], r[2 * k + 1] + ib[k][l]);
                const __m256 top = _mm256_add_ps(a0, _mm256_mul_ps(_mm256_sub_ps(b0, a0), tx));
                const __m256 bottom = _mm256_add_ps(a1, _mm256_mul_ps(_mm256_sub_ps(b1, a1), tx));
                c[k] = _mm256_add_ps(top, _mm256_mul_ps(_mm256_sub_ps(bottom, top), k == 0 ? ty0 : ty1));
            }
            const __m256 c01 = _mm256_add_ps(c[0], _mm256_mul_ps(_mm256_sub_ps(c[1], c[0]), blend));
            sum[p] = _mm256_add_ps(sum[p], _mm256_mul_ps(c01, weight));
        }
    }
    for (int p = 0; p < 4; ++p) {
        alignas(32) float v[8];
        _mm256_store_ps(v, sum[p]);
        out[2 * p] = glm::vec4(v[0], v[1], v[2], 0.0f);
        out[2 * p + 1] = glm::vec4(v[4], v[5], v[6], 0.0f);
    }
}
#endif

} // namespace

void resample_equirect(glm::vec4* texels, const EquirectLevel& in, const EquirectLevel& out, ThreadPool& pool) {
    if (in.w == 2 * out.w && in.h == 2 * out.h) {
        // Halving both ways (every mip of a power-of-two map): each output
        // texel averages a 2x2 block, its two rows weighted by their solid
        // angles; the same result as the general path below, faster.
        pool.run(out.h, [&](int y, int) {
            const double c0 = det::cos(M_PI * (2 * y) / in.h), c1 = det::cos(M_PI * (2 * y + 1) / in.h);
            const double c2 = det::cos(M_PI * (2 * y + 2) / in.h);
            const double w0 = (c0 - c1) / (c0 - c2), w1 = (c1 - c2) / (c0 - c2);
            const glm::vec4* a = texels + in.offset + std::size_t(2 * y) * std::size_t(in.w);
            const glm::vec4* b = a + in.w;
            glm::vec4* row = texels + out.offset + std::size_t(y) * std::size_t(out.w);
            for (int x = 0; x < out.w; ++x) {
                const glm::dvec3 top = (glm::dvec3(a[2 * x]) + glm::dvec3(a[2 * x + 1])) * 0.5;
                const glm::dvec3 bottom = (glm::dvec3(b[2 * x]) + glm::dvec3(b[2 * x + 1])) * 0.5;
                row[x] = glm::vec4(glm::vec3(top * w0 + bottom * w1), 0.0f);
            }
        });
        return;
    }
    const std::vector<std::vector<Tap>> tx = overlap_taps(in.w, out.w, false);
    const std::vector<std::vector<Tap>> ty = overlap_taps(in.h, out.h, true);
    // Along rows first (in.h rows of out.w texels), then down the columns.
    std::vector<glm::dvec3> across(std::size_t(in.h) * std::size_t(out.w));
    pool.run(in.h, [&](int y, int) {
        const glm::vec4* row = texels + in.offset + std::size_t(y) * std::size_t(in.w);
        for (int x = 0; x < out.w; ++x) {
            glm::dvec3 sum(0.0);
            for (const Tap& t : tx[std::size_t(x)]) sum += glm::dvec3(row[t.index]) * t.weight;
            across[std::size_t(y) * std::size_t(out.w) + std::size_t(x)] = sum;
        }
    });
    pool.run(out.h, [&](int y, int) {
        glm::vec4* row = texels + out.offset + std::size_t(y) * std::size_t(out.w);
        for (int x = 0; x < out.w; ++x) {
            glm::dvec3 sum(0.0);
            for (const Tap& t : ty[std::size_t(y)])
                sum += across[std::size_t(t.index) * std::size_t(out.w) + std::size_t(x)] * t.weight;
            row[x] = glm::vec4(glm::vec3(sum), 0.0f);
        }
    });
}

void prefilter_ggx(glm::vec4* texels, const EquirectLevel* mips, int mip_count, float roughness, int samples,
                   const EquirectLevel& out, ThreadPool& pool, PrefilterPath path) {
    // Everything that depends on the sample only: with n = v, l = reflect(-n, h)
    // has n.l = 2 (n.h)^2 - 1 and pdf_l = D / 4.
    struct Sample {
        glm::dvec3 l;  // about +Z
        double NoL;
        double lod;    // before the texel's own solid angle
    };
    const double alpha = double(roughness) * double(roughness);
    const EquirectLevel& base = mips[0];
    // Solid angle of a level-0 texel at the equator: (2 pi / W) (pi / H).
    const double omega_equator = 2.0 * M_PI * M_PI / (double(base.w) * double(base.h));
    std::vector<Sample> list;
    double weight = 0.0;
    for (int i = 0; i < samples; ++i) {
        const glm::dvec3 h = sample_ggx_half(hammersley(std::uint32_t(i), std::uint32_t(samples)), alpha);
        const double NoH = h.z, NoL = 2.0 * NoH * NoH - 1.0;
        if (!(NoL > 0.0)) continue;
        const double pdf = D_GGX_d(NoH, alpha) * 0.25;
        const double omega_s = 1.0 / (double(samples) * pdf);
        // lod = log4(4 omega_s / omega_p): the +1 (log4 4) lets neighbouring samples' footprints overlap.
        list.push_back({{2.0 * NoH * h.x, 2.0 * NoH * h.y, NoL}, NoL, 0.5 * det::log2(omega_s / omega_equator) + 1.0});
        weight += NoL;
    }
    // A texel's solid angle shrinks with sin(theta); below half a row from the
    // pole, use the pole row's.
    const double min_sin = det::sin(0.5 * M_PI / double(base.h));
    const double top = double(mip_count - 1);

    // Turning a direction about +Y only shifts its u: the samples of texel x
    // of a row are those of texel 0 shifted by x / width, with the same v and
    // level. So each row works out its samples' rows, levels and weights once
    // (in double, with the exact atan2 and acos), and each texel only moves
    // along u: two bilinear reads per sample.
    std::vector<double> shift(std::size_t(out.w));
    for (int x = 0; x < out.w; ++x) shift[std::size_t(x)] = double(x) / out.w;
    pool.run(out.h, [&](int y, int) {
        const Frame frame(equirect_direction(0.5 / out.w, (y + 0.5) / out.h));
        std::vector<GgxTap> taps;
        taps.reserve(list.size());
        for (const Sample& s : list) {
            const glm::dvec3 l = glm::normalize(frame.to_world(s.l));
            GgxTap t;
            t.u0 = 0.5 + det::atan2(l.x, -l.z) / (2.0 * M_PI);
            const double v = det::acos(std::clamp(l.y, -1.0, 1.0)) / M_PI;
            const double sin_theta = std::max(std::sqrt(l.x * l.x + l.z * l.z), min_sin);
            const double lod = std::clamp(s.lod - 0.5 * det::log2(sin_theta), 0.0, top);
            const int la = int(lod), lb = std::min(la + 1, mip_count - 1);
            t.t = float(lod - la);
            t.weight = float(s.NoL / weight);
            for (int k = 0; k < 2; ++k) {
                const EquirectLevel& L = mips[k == 0 ? la : lb];
                const double fy = v * L.h - 0.5;
                const int y0 = int(std::floor(fy));
                t.ty[k] = float(fy - std::floor(fy));
                t.rows[2 * k] = texels + L.offset + std::size_t(std::clamp(y0, 0, L.h - 1)) * std::size_t(L.w);
                t.rows[2 * k + 1] = texels + L.offset + std::size_t(std::clamp(y0 + 1, 0, L.h - 1)) * std::size_t(L.w);
                t.fw[k] = L.fw;
                t.w[k] = L.w;
            }
            taps.push_back(t);
        }
        glm::vec4* row = texels + out.offset + std::size_t(y) * std::size_t(out.w);
        int x = 0;
#ifdef __AVX2__
        if (path == PrefilterPath::Lanes)
            for (; x + 8 <= out.w; x += 8) prefilter_eight(taps, &shift[std::size_t(x)], row + x);
#else
        (void)path;
#endif
        for (; x < out.w; ++x) row[x] = prefilter_texel(taps, shift[std::size_t(x)]);
    });
}

} // namespace prast

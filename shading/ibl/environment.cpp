// Building an Environment; see environment.h.
#include "shading/ibl/environment.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>

#include "scene/det_math.h"
#include "shading/ibl/prefilter.h"

namespace prast {

namespace {

using Clock = std::chrono::steady_clock;

double ms_since(Clock::time_point t0) {
    return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

EquirectLevel make_level(int w, int h, std::size_t offset) {
    EquirectLevel L;
    L.w = w;
    L.h = h;
    L.offset = std::int32_t(offset);
    L.fw = float(w);
    L.fh = float(h);
    return L;
}

// Radiance beyond this is clamped on load: differences of two texels stay
// finite, so filtering never makes inf or NaN.
constexpr float kMaxRadiance = 1e30f;

float luminance(const glm::vec4& c) { return 0.2126f * c.r + 0.7152f * c.g + 0.0722f * c.b; }

} // namespace

Environment Environment::build(const Image& img, const EnvironmentSettings& s, ThreadPool& pool) {
    if (img.empty() || (!img.is_8bit() && img.rgba.size() != img.texel_count() * 4) ||
        (img.is_8bit() && img.pixels.size() != img.texel_count() * std::size_t(img.channels)))
        throw std::invalid_argument("environment: empty image");
    Environment env;
    const double turn = double(s.rotate_deg) * M_PI / 180.0;
    env.rot_cos_ = s.rotate_deg == 0.0f ? 1.0f : float(det::cos(turn));
    env.rot_sin_ = s.rotate_deg == 0.0f ? 0.0f : float(det::sin(turn));

    // Level sizes: the source (at most kMaxWidth wide), its mips down to 1x1,
    // then the prefiltered levels 1...
    auto t0 = Clock::now();
    int w0 = img.width, h0 = img.height;
    const bool shrink = w0 > kMaxWidth;
    if (shrink) {
        h0 = std::max(1, int(std::lround(double(h0) * kMaxWidth / w0)));
        w0 = kMaxWidth;
    }
    std::size_t total = 0;
    for (int w = w0, h = h0;; w = std::max(1, w / 2), h = std::max(1, h / 2)) {
        env.source_[env.source_count_++] = make_level(w, h, total);
        total += std::size_t(w) * std::size_t(h);
        if (w == 1 && h == 1) break;
    }
    env.specular_[0] = env.source_[0];
    for (int i = 1; i < kSpecularLevels; ++i) {
        const int w = std::max(kMinLevelWidth, std::min(w0 >> i, kLevel1Width >> (i - 1)));
        env.specular_[i] = make_level(w, std::max(1, w / 2), total);
        total += std::size_t(w) * std::size_t(std::max(1, w / 2));
    }
    env.texels_.assign(total, glm::vec4(0.0f));

    // Level 0: the image times the intensity (clamped, NaN to 0), resampled
    // when too wide.
    auto scaled = [&](int x, int y) {
        const glm::vec4 p = img.at(x, y);
        glm::vec4 c(0.0f);
        for (int ch = 0; ch < 3; ++ch) {
            const float v = p[ch] * s.intensity;
            c[ch] = v >= 0.0f ? std::min(v, kMaxRadiance) : 0.0f;
        }
        return c;
    };
    if (!shrink) {
        pool.run(h0, [&](int y, int) {
            for (int x = 0; x < w0; ++x)
                env.texels_[std::size_t(y) * std::size_t(w0) + std::size_t(x)] = scaled(x, y);
        });
    } else {
        std::vector<glm::vec4> full(std::size_t(img.width) * std::size_t(img.height));
        pool.run(img.height, [&](int y, int) {
            for (int x = 0; x < img.width; ++x)
                full[std::size_t(y) * std::size_t(img.width) + std::size_t(x)] = scaled(x, y);
        });
        const EquirectLevel in = make_level(img.width, img.height, 0);
        std::vector<glm::vec4> tmp = std::move(full);
        tmp.resize(tmp.size() + std::size_t(w0) * std::size_t(h0));
        const EquirectLevel out = make_level(w0, h0, std::size_t(img.width) * std::size_t(img.height));
        resample_equirect(tmp.data(), in, out, pool);
        std::copy(tmp.begin() + out.offset, tmp.end(), env.texels_.begin());
    }
    for (int k = 1; k < env.source_count_; ++k)
        resample_equirect(env.texels_.data(), env.source_[k - 1], env.source_[k], pool);
    env.timings_.mips = ms_since(t0);

    // Diffuse: SH from the first mip at most 512 texels wide (order 2 needs no more).
    t0 = Clock::now();
    int sh_level = 0;
    while (env.source_[sh_level].w > 512 && sh_level + 1 < env.source_count_) ++sh_level;
    env.sh_ = project_sh_irradiance(env.texels_.data(), env.source_[sh_level], env.rot_cos_, env.rot_sin_, pool);
    env.timings_.sh = ms_since(t0);

    // Specular: GGX-prefiltered levels.
    t0 = Clock::now();
    for (int i = 1; i < kSpecularLevels; ++i)
        prefilter_ggx(env.texels_.data(), env.source_, env.source_count_, level_roughness(i), kSpecularSamples[i],
                      env.specular_[i], pool);
    env.timings_.prefilter = ms_since(t0);

    // Sampler: texel probability proportional to luminance times solid angle.
    if (s.importance_sampling) {
        t0 = Clock::now();
        const int W = w0, H = h0;
        env.col_cdf_.assign(std::size_t(H) * std::size_t(W + 1), 0.0f);
        std::vector<double> row_weight(std::size_t(H), 0.0);
        pool.run(H, [&](int y, int) {
            const double omega = 2.0 * M_PI / W * (det::cos(M_PI * y / H) - det::cos(M_PI * (y + 1) / H));
            float* cdf = &env.col_cdf_[std::size_t(y) * std::size_t(W + 1)];
            double sum = 0.0;
            std::vector<double> run(std::size_t(W) + 1, 0.0);
            for (int x = 0; x < W; ++x) {
                sum += double(luminance(env.texels_[std::size_t(y) * std::size_t(W) + std::size_t(x)]));
                run[std::size_t(x) + 1] = sum;
            }
            for (int x = 0; x <= W; ++x)
                cdf[x] = sum > 0.0 ? float(run[std::size_t(x)] / sum) : float(x) / float(W);
            cdf[W] = 1.0f;
            row_weight[std::size_t(y)] = sum * omega;
        });
        double total_weight = 0.0;
        for (double w : row_weight) total_weight += w;
        if (total_weight > 0.0 && std::isfinite(total_weight)) {
            env.row_cdf_.assign(std::size_t(H) + 1, 0.0);
            double run = 0.0;
            for (int y = 0; y < H; ++y) {
                run += row_weight[std::size_t(y)];
                env.row_cdf_[std::size_t(y) + 1] = run / total_weight;
            }
            env.row_cdf_[std::size_t(H)] = 1.0;
        } else {
            env.col_cdf_.clear();
        }
        env.timings_.sampler = ms_since(t0);
    }
    return env;
}

glm::vec3 Environment::sample_direction(glm::dvec2 u, double& pdf) const {
    const int W = source_[0].w, H = source_[0].h;
    // Row, then column, by inverting the CDFs; the remainder of each search
    // places the direction inside the texel, uniformly in solid angle.
    auto row_it = std::upper_bound(row_cdf_.begin(), row_cdf_.end(), u.x);
    int y = std::clamp(int(row_it - row_cdf_.begin()) - 1, 0, H - 1);
    const double py = row_cdf_[std::size_t(y) + 1] - row_cdf_[std::size_t(y)];
    const double fy = py > 0.0 ? std::clamp((u.x - row_cdf_[std::size_t(y)]) / py, 0.0, 1.0) : 0.5;
    const float* cdf = &col_cdf_[std::size_t(y) * std::size_t(W + 1)];
    const float* col_it = std::upper_bound(cdf, cdf + W + 1, float(u.y));
    int x = std::clamp(int(col_it - cdf) - 1, 0, W - 1);
    const double px = double(cdf[x + 1]) - double(cdf[x]);
    const double fx = px > 0.0 ? std::clamp((u.y - double(cdf[x])) / px, 0.0, 1.0) : 0.5;
    const double c0 = det::cos(M_PI * y / H), c1 = det::cos(M_PI * (y + 1) / H);
    const double omega = 2.0 * M_PI / W * (c0 - c1);
    pdf = omega > 0.0 ? py * px / omega : 0.0;
    const double cos_theta = c0 + (c1 - c0) * fy;
    const double sin_theta = std::sqrt(std::max(0.0, 1.0 - cos_theta * cos_theta));
    const double phi = ((x + fx) / W - 0.5) * 2.0 * M_PI;
    const double mx = sin_theta * det::sin(phi), mz = -sin_theta * det::cos(phi);
    // Map -> world: R_y(angle).
    return glm::vec3(float(mx * rot_cos_ + mz * rot_sin_), float(cos_theta), float(-mx * rot_sin_ + mz * rot_cos_));
}

double Environment::direction_pdf(const glm::vec3& dir) const {
    const int W = source_[0].w, H = source_[0].h;
    float mx, mz, u, v;
    to_map(dir.x, dir.z, mx, mz);
    equirect_uv(mx, dir.y, mz, u, v);
    if (!(u >= 0.0f && u <= 1.0f && v >= 0.0f && v <= 1.0f)) return 0.0;
    const int x = std::min(int(u * float(W)), W - 1), y = std::min(int(v * float(H)), H - 1);
    const double py = row_cdf_[std::size_t(y) + 1] - row_cdf_[std::size_t(y)];
    const float* cdf = &col_cdf_[std::size_t(y) * std::size_t(W + 1)];
    const double px = double(cdf[x + 1]) - double(cdf[x]);
    const double omega = 2.0 * M_PI / W * (det::cos(M_PI * y / H) - det::cos(M_PI * (y + 1) / H));
    return omega > 0.0 ? py * px / omega : 0.0;
}

} // namespace prast

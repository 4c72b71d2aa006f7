// An environment map made ready for image-based lighting (docs/conventions.md
// "Environment maps", "Shading"): from an equirect radiance image, times
// --env-intensity and turned about +Y by --env-rotate, it precomputes
//   - the source's mip chain (area- and solid-angle-weighted), which the
//     background, the reference integrator and the prefilter read;
//   - the split sum's specular half: kSpecularLevels equirect levels, level 0
//     the source itself (roughness 0.045, a mirror at any map resolution we
//     take), level i the source GGX-prefiltered for roughness
//     0.045 + 0.955 i / 7 with filtered importance sampling (prefilter.h);
//   - the diffuse irradiance as order-2 spherical harmonics (sh_irradiance.h);
//   - on request, a luminance distribution over the source's texels for the
//     reference integrator's importance sampling.
// Texels stay in map space (the prefiltered level 0 is the source, bit for
// bit); lookups turn world directions into map directions (to_map), and the
// SH coefficients are projected in world space.
//
// Precomputation runs on the renderer's thread pool, one task per output row,
// with fixed-order sums: the same bytes for any thread count. It is fast
// enough not to need a cache (docs/ibl.md gives the times).
#pragma once

#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "raster/thread_pool.h"
#include "scene/image.h"
#include "shading/brdf.h"
#include "shading/ibl/equirect.h"
#include "shading/ibl/sh_irradiance.h"

namespace prast {

struct EnvironmentSettings {
    float intensity = 1.0f;    // radiance multiplier (--env-intensity)
    float rotate_deg = 0.0f;   // the map turned about +Y, right-handed (--env-rotate)
    bool importance_sampling = false;  // build the sampler (--ibl reference)
};

// Milliseconds per precomputation stage (render --stats, docs/ibl.md).
struct EnvironmentTimings {
    double mips = 0, sh = 0, prefilter = 0, sampler = 0;
};

class Environment {
public:
    static constexpr int kSpecularLevels = 8;
    // A wider source is resampled to this width first (a 4096-wide map already
    // has texels of 0.09 degrees, finer than the sharpest lobe we draw).
    static constexpr int kMaxWidth = 4096;
    // Prefiltered level i >= 1 is min(source >> i, 256 >> (i - 1)) wide, at
    // least 32 (texels of 1.4 degrees for r = 0.18, whose lobe is about 4
    // degrees wide, as Filament's 256-per-face cube maps have at that level).
    static constexpr int kLevel1Width = 256, kMinLevelWidth = 32;
    // GGX samples per texel for levels 1.. (level 0 is the source).
    static constexpr int kSpecularSamples[kSpecularLevels] = {0, 64, 128, 192, 256, 384, 512, 512};

    // Throws std::invalid_argument when the image is empty. (8-bit images are
    // read as their linear values.)
    static Environment build(const Image& equirect, const EnvironmentSettings& settings, ThreadPool& pool);

    // Perceptual roughness of specular level i, and the (fractional) level of
    // roughness r, which the caller has clamped to [0.045, 1].
    static float level_roughness(int level) {
        return kMinPerceptualRoughness + (1.0f - kMinPerceptualRoughness) * float(level) / float(kSpecularLevels - 1);
    }
    [[gnu::always_inline]] static float roughness_lod(float r) {
        constexpr float kScale = float(kSpecularLevels - 1) / (1.0f - kMinPerceptualRoughness);
        return (r - kMinPerceptualRoughness) * kScale;
    }

    // World direction -> map direction: the inverse of the map's turn about +Y.
    [[gnu::always_inline]] void to_map(float x, float z, float& mx, float& mz) const {
        mx = x * rot_cos_ - z * rot_sin_;
        mz = x * rot_sin_ + z * rot_cos_;
    }
    float rot_cos() const { return rot_cos_; }
    float rot_sin() const { return rot_sin_; }

    const glm::vec4* texels() const { return texels_.data(); }
    const EquirectLevel& source_level(int i) const { return source_[i]; }
    int source_levels() const { return source_count_; }
    const EquirectLevel& specular_level(int i) const { return specular_[i]; }
    int width() const { return source_[0].w; }
    int height() const { return source_[0].h; }

    // Radiance along a world direction: bilinear on the source (the background,
    // the mirror and the reference integrator all see this function).
    glm::vec3 radiance(const glm::vec3& dir) const;
    // The prefiltered radiance at a fractional specular level (trilinear).
    glm::vec3 prefiltered(const glm::vec3& dir, float lod) const;
    // E(n) / pi from the SH, clamped to >= 0.
    glm::vec3 irradiance(const glm::vec3& n) const { return sh_irradiance(sh_, n); }
    const ShIrradiance& sh() const { return sh_; }

    // Importance sampling of the source by luminance times texel solid angle
    // (only when built with importance_sampling and the map is not black).
    bool has_sampler() const { return !row_cdf_.empty(); }
    // A world direction for u in [0, 1)^2, and its pdf per steradian.
    glm::vec3 sample_direction(glm::dvec2 u, double& pdf) const;
    double direction_pdf(const glm::vec3& dir) const;

    const EnvironmentTimings& timings() const { return timings_; }

private:
    std::vector<glm::vec4> texels_;  // source mips, then prefiltered levels 1..
    EquirectLevel source_[32];
    int source_count_ = 0;
    EquirectLevel specular_[kSpecularLevels];
    ShIrradiance sh_;
    float rot_cos_ = 1.0f, rot_sin_ = 0.0f;
    // Sampler: row_cdf_ has h + 1 entries; col_cdf_ h rows of w + 1.
    std::vector<double> row_cdf_;
    std::vector<float> col_cdf_;
    EnvironmentTimings timings_;
};

// The prefiltered lookup of Environment::prefiltered() from its parts, for the
// lane code: the same operations in the same order. (mx, my, mz) is a map
// direction.
[[gnu::always_inline]] inline void prefiltered_taps(const Environment& env, float mx, float my, float mz, float lod,
                                                    std::int32_t* ia, std::int32_t* ib, float& txa, float& tya,
                                                    float& txb, float& tyb, float& t) {
    constexpr float kTop = float(Environment::kSpecularLevels - 1);
    lod = lod > 0.0f ? lod : 0.0f;  // NaN -> 0
    lod = lod < kTop ? lod : kTop;
    const int l0 = int(lod);
    const int l1 = l0 + 1 < Environment::kSpecularLevels ? l0 + 1 : l0;
    t = lod - float(l0);
    float u, v;
    equirect_uv(mx, my, mz, u, v);
    const EquirectLevel& A = env.specular_level(l0);
    const EquirectLevel& B = env.specular_level(l1);
    equirect_taps(u, v, A.w, A.h, A.offset, A.fw, A.fh, ia, txa, tya);
    equirect_taps(u, v, B.w, B.h, B.offset, B.fw, B.fh, ib, txb, tyb);
}

inline glm::vec3 Environment::prefiltered(const glm::vec3& dir, float lod) const {
    float mx, mz;
    to_map(dir.x, dir.z, mx, mz);
    std::int32_t ia[4], ib[4];
    float txa, tya, txb, tyb, t;
    prefiltered_taps(*this, mx, dir.y, mz, lod, ia, ib, txa, tya, txb, tyb, t);
    const Texel4 a = bilinear4(texels_.data(), ia, txa, tya);
    const Texel4 b = bilinear4(texels_.data(), ib, txb, tyb);
    const Texel4 c = a + (b - a) * t;
    return {c[0], c[1], c[2]};
}

inline glm::vec3 Environment::radiance(const glm::vec3& dir) const {
    float mx, mz, u, v;
    to_map(dir.x, dir.z, mx, mz);
    equirect_uv(mx, dir.y, mz, u, v);
    return bilinear_rgb(texels_.data(), source_[0], u, v);
}

} // namespace prast

// Textures: the box-filtered mip chain of a decoded image (scene/image.h) and
// the bilinear / trilinear samplers the shaders call per pixel.
//
// Conventions (conventions.md, "Textures"): texel centres at (i + 0.5) / width,
// v = 0 is the TOP row of the image (the project's internal UVs; no flipping
// here), lambda = log2(max(|d(uv * size)/dx|, |d(uv * size)/dy|)) with level-0
// sizes, as the OpenGL specification writes it (no anisotropy). Filtering and
// mip generation happen in linear space: sRGB images are decoded on load.
//
// A Texture is immutable after construction and is shared read-only between
// render threads: no caches, no allocation and no virtual calls when sampling.
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "scene/image.h"
#include "scene/scene.h"

namespace prast {

class Texture {
public:
    static constexpr int kMaxLevels = 32;

    // A 1x1 opaque white texture, so that a default Texture samples safely.
    Texture();

    // Builds the full mip chain (level k+1 = level k halved, rounded down, at
    // least 1) with an area-weighted box filter: even sizes average 2 texels
    // per axis; an odd size n = 2m + 1 gives m texels that each cover n / m
    // source texels, i.e. 3 taps weighted (m - i, m, i + 1) / n for output i.
    // Every source texel gives away exactly its area, so the mean of each level
    // equals the mean of level 0 (up to float rounding).
    // Throws std::invalid_argument for an empty image or a wrong rgba size.
    static Texture from_image(Image img, Wrap s = Wrap::Repeat, Wrap t = Wrap::Repeat);

    int levels() const { return level_count_; }
    int width(int level) const { return levels_[clamp_level(level)].width; }
    int height(int level) const { return levels_[clamp_level(level)].height; }
    Wrap wrap_s() const { return wrap_s_; }
    Wrap wrap_t() const { return wrap_t_; }

    // One stored texel; the level and coordinates are clamped to the valid range.
    glm::vec4 texel(int level, int x, int y) const;
    // The mean colour of the image: the last (1x1) level.
    glm::vec4 average() const { return texel(level_count_ - 1, 0, 0); }
    // The texels of every level, level 0 first, each row-major; level k starts
    // at level_offset(k). For the 4x4-block sampler (sample_lanes.h).
    const glm::vec4* texel_data() const { return texels_.data(); }
    std::size_t level_offset(int level) const { return levels_[clamp_level(level)].offset; }

    // lambda = log2(rho), rho = max(sqrt((dudx w)^2 + (dvdx h)^2),
    // sqrt((dudy w)^2 + (dvdy h)^2)) with the level-0 size w x h. The result is
    // finite: clamped to [-64, 64] (zero derivatives give -64), NaN gives 0.
    float lod(float dudx, float dvdx, float dudy, float dvdy) const;

    // Bilinear filter of one level (clamped to the valid range).
    glm::vec4 sample_bilinear(float u, float v, int level) const;
    // lambda <= 0 (or NaN): bilinear on level 0 (magnification). Otherwise a
    // linear blend of the bilinear results of levels floor(lambda) and
    // floor(lambda) + 1, clamped to the last level.
    glm::vec4 sample_trilinear(float u, float v, float lambda) const;
    // sample_trilinear(u, v, lod(...)).
    glm::vec4 sample(float u, float v, float dudx, float dvdx, float dudy, float dvdy) const {
        return sample_trilinear(u, v, lod(dudx, dvdx, dudy, dvdy));
    }

private:
    struct Level {
        int width = 0, height = 0;
        float fwidth = 0.0f, fheight = 0.0f;
        std::size_t offset = 0;  // first texel in texels_
    };

    int clamp_level(int level) const {
        return level < 0 ? 0 : (level >= level_count_ ? level_count_ - 1 : level);
    }
    // The samplers with the wrap modes fixed at compile time; the public ones
    // dispatch to them through a table, once per call.
    template <Wrap S, Wrap T> glm::vec4 bilinear_reduced(float u, float v, int level) const;
    template <Wrap S, Wrap T> glm::vec4 bilinear_wrapped(float u, float v, int level) const;
    template <Wrap S, Wrap T> glm::vec4 trilinear_wrapped(float u, float v, float lambda) const;
    using Sampler = glm::vec4 (Texture::*)(float, float, float) const;
    using LevelSampler = glm::vec4 (Texture::*)(float, float, int) const;
    static const Sampler kTrilinear[3][3];
    static const LevelSampler kBilinear[3][3];

    std::vector<glm::vec4> texels_;  // all levels, level 0 first, row-major
    Level levels_[kMaxLevels];
    int level_count_ = 0;
    Wrap wrap_s_ = Wrap::Repeat, wrap_t_ = Wrap::Repeat;
};

// ---- Inline sampling (the per-pixel hot path).

namespace texture_detail {

// Folds a texture coordinate into one period of its wrap mode, so that the
// texel index computed from it stays in [-1, 2 * size] and converts to int
// safely: Repeat -> [0, 1], MirroredRepeat -> [0, 2], ClampToEdge -> [0, 1]
// (clamping u to [0, 1] gives the same texels as clamping the index).
// NaN and +-Inf become 0. Branch-free after inlining, so that the block
// sampler's lane loops (sample_lanes.h) vectorise with the same operations.
template <Wrap W>
inline float reduce(float c) {
    c = std::fabs(c) <= 3.402823466e38f ? c : 0.0f;  // NaN or Inf
    if constexpr (W == Wrap::Repeat) return c - std::floor(c);
    if constexpr (W == Wrap::MirroredRepeat) return c - 2.0f * std::floor(c * 0.5f);
    c = c < 0.0f ? 0.0f : c;
    return c > 1.0f ? 1.0f : c;
}

// Maps a texel index in [-1, 2n] (guaranteed by reduce()) into [0, n).
template <Wrap W>
inline int wrap_index(int i, int n) {
    if constexpr (W == Wrap::Repeat) {
        i = i < 0 ? i + n : i;
        return i >= n ? i - n : i;
    }
    if constexpr (W == Wrap::MirroredRepeat) {
        i = i < 0 ? -1 - i : i;          // mirror image of -1 is 0
        i = i >= 2 * n ? i - 2 * n : i;  // period 2n
        return i >= n ? 2 * n - 1 - i : i;
    }
    i = i < 0 ? 0 : i;
    return i >= n ? n - 1 : i;
}

} // namespace texture_detail

template <Wrap S, Wrap T>
inline glm::vec4 Texture::bilinear_reduced(float u, float v, int level) const {
    const Level& L = levels_[level];
    // Texel centres at (i + 0.5) / size.
    const float x = u * L.fwidth - 0.5f, y = v * L.fheight - 0.5f;
    const float fx = std::floor(x), fy = std::floor(y);
    const float tx = x - fx, ty = y - fy;
    const int x0 = int(fx), y0 = int(fy);
    const int xa = texture_detail::wrap_index<S>(x0, L.width);
    const int xb = texture_detail::wrap_index<S>(x0 + 1, L.width);
    const int ya = texture_detail::wrap_index<T>(y0, L.height);
    const int yb = texture_detail::wrap_index<T>(y0 + 1, L.height);
    const glm::vec4* base = texels_.data() + L.offset;
    const glm::vec4* row_a = base + std::size_t(ya) * std::size_t(L.width);
    const glm::vec4* row_b = base + std::size_t(yb) * std::size_t(L.width);
    // a + (b - a) t: exact at t = 0 and wherever a == b (a constant texture
    // samples to exactly its value).
    const glm::vec4 top = row_a[xa] + (row_a[xb] - row_a[xa]) * tx;
    const glm::vec4 bottom = row_b[xa] + (row_b[xb] - row_b[xa]) * tx;
    return top + (bottom - top) * ty;
}

template <Wrap S, Wrap T>
inline glm::vec4 Texture::bilinear_wrapped(float u, float v, int level) const {
    return bilinear_reduced<S, T>(texture_detail::reduce<S>(u), texture_detail::reduce<T>(v),
                                  clamp_level(level));
}

template <Wrap S, Wrap T>
inline glm::vec4 Texture::trilinear_wrapped(float u, float v, float lambda) const {
    const float ur = texture_detail::reduce<S>(u), vr = texture_detail::reduce<T>(v);
    if (!(lambda > 0.0f)) return bilinear_reduced<S, T>(ur, vr, 0);  // magnification, or NaN
    const int last = level_count_ - 1;
    if (lambda >= float(last)) return bilinear_reduced<S, T>(ur, vr, last);
    const float fl = std::floor(lambda);  // in [0, last): the int conversion is safe
    const int l0 = int(fl);
    const float t = lambda - fl;
    const glm::vec4 a = bilinear_reduced<S, T>(ur, vr, l0);
    if (t == 0.0f) return a;
    return a + (bilinear_reduced<S, T>(ur, vr, l0 + 1) - a) * t;
}

inline glm::vec4 Texture::sample_bilinear(float u, float v, int level) const {
    return (this->*kBilinear[int(wrap_s_)][int(wrap_t_)])(u, v, level);
}

inline glm::vec4 Texture::sample_trilinear(float u, float v, float lambda) const {
    return (this->*kTrilinear[int(wrap_s_)][int(wrap_t_)])(u, v, lambda);
}

inline float Texture::lod(float dudx, float dvdx, float dudy, float dvdy) const {
    const float w = levels_[0].fwidth, h = levels_[0].fheight;
    const float ax = dudx * w, bx = dvdx * h, ay = dudy * w, by = dvdy * h;
    // log2(rho) = 0.5 log2(rho^2): saves both square roots.
    const float rho2 = std::fmax(ax * ax + bx * bx, ay * ay + by * by);
    const float lambda = 0.5f * std::log2(rho2);
    if (lambda != lambda) return 0.0f;  // NaN derivatives
    return lambda < -64.0f ? -64.0f : (lambda > 64.0f ? 64.0f : lambda);
}

} // namespace prast

// Textures: the box-filtered mip chain of a decoded image (scene/image.h) and
// the bilinear / trilinear samplers the shaders call per pixel.
//
// Conventions (docs/conventions.md, "Textures"): texel centres at (i + 0.5) / width,
// v = 0 is the TOP row of the image (the project's internal UVs; no flipping
// here), lambda = log2(max(|d(uv * size)/dx|, |d(uv * size)/dy|)) with level-0
// sizes, as the OpenGL specification writes it (no anisotropy). Filtering and
// mip generation happen in linear space.
//
// Storage follows the image: 8-bit images keep 1 to 4 bytes per texel (a
// 2048x2048 RGBA map with its mips is 21.3 MB, not the 89 MB of float RGBA),
// decoded to float per texel when sampled through 256-entry tables (sRGB for
// the colour channels of colour maps), so level 0 samples exactly the floats a
// float texture of the decoded image would. Their mips are stored in 8 bits
// too, as GPUs store generated mips: each texel is the correctly rounded byte
// of the exact area-weighted box filter of the level above, in linear space
// (sRGB channels are decoded, filtered, and re-encoded). Float images (HDR,
// 16-bit, procedural) keep float RGBA texels and float mips.
//
// A Texture is the decoded storage (shared, immutable) seen through one
// sampler: its wrap modes and its glTF/OpenGL filters. with_sampler() gives
// another view of the same texels, so one decoded image serves every texture
// that names it, each with its own sampler. The storage's layout is private to
// this class and sample_lanes.h (texel indices through level_offset()).
//
// Filters follow OpenGL (the rules glTF samplers name): magnification when
// lambda <= c, with c = 0.5 for magFilter LINEAR with minFilter
// NEAREST_MIPMAP_NEAREST or NEAREST_MIPMAP_LINEAR and c = 0 otherwise;
// NEAREST takes texel (floor(u w), floor(v h)) wrapped; the MIPMAP_NEAREST
// modes read level d = ceil(lambda + 1/2) - 1 clamped to the chain; the
// MIPMAP_LINEAR modes blend levels floor(lambda) and floor(lambda) + 1 by the
// fraction. The default (LINEAR, LINEAR_MIPMAP_LINEAR) is sample_trilinear().
//
// A Texture is immutable after construction and is shared read-only between
// render threads: no caches, no allocation and no virtual calls when sampling.
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <memory>
#include <vector>

#include <glm/glm.hpp>

#include "scene/image.h"
#include "scene/scene.h"

namespace prast {

class ThreadPool;

// A texture's sampler: wrap modes and filters (defaults: trilinear, repeat).
struct SamplerState {
    Wrap wrap_s = Wrap::Repeat, wrap_t = Wrap::Repeat;
    Filter mag = Filter::Linear;
    MinFilter min = MinFilter::LinearMipmapLinear;
    bool operator==(const SamplerState& o) const {
        return wrap_s == o.wrap_s && wrap_t == o.wrap_t && mag == o.mag && min == o.min;
    }
    bool operator!=(const SamplerState& o) const { return !(*this == o); }
};

inline SamplerState sampler_of(const TextureRef& r) {
    return SamplerState{r.wrap_s, r.wrap_t, r.mag_filter, r.min_filter};
}

// Where a lookup reads: level `level` (and level + 1 blended by t when
// `blend`), with the NEAREST texel or the bilinear footprint in each.
struct LevelChoice {
    int level = 0;
    float t = 0.0f;
    bool blend = false;
    bool nearest = false;
};

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
    // equals the mean of level 0 (up to rounding). Float images filter in
    // float; 8-bit ones as the file comment says. The rows of each level are
    // built in parallel on `pool` when given (same bytes on any thread count).
    // Throws std::invalid_argument for an empty image or a wrong data size.
    static Texture from_image(Image img, Wrap s = Wrap::Repeat, Wrap t = Wrap::Repeat,
                              ThreadPool* pool = nullptr);

    // Separate roughness and metalness maps (OBJ map_Pr, map_Pm: 8-bit linear,
    // same size; channel R of each is used) packed into one 2-byte texture
    // that samples as (rough, rough, metal, 1), i.e. as a glTF
    // metallic-roughness map (G rough, B metal), with bit for bit the values
    // the two maps give apart. Throws std::invalid_argument when they cannot
    // be packed (float storage, sRGB, different sizes).
    static Texture pack_roughness_metal(const Image& rough, const Image& metal, Wrap s = Wrap::Repeat,
                                        Wrap t = Wrap::Repeat, ThreadPool* pool = nullptr);

    // The same storage (shared, not copied) seen through another sampler.
    Texture with_sampler(const SamplerState& s) const;
    // True when a and b hold the same decoded storage.
    bool shares_storage(const Texture& o) const { return storage_ == o.storage_; }

    int levels() const { return level_count_; }
    int width(int level) const { return levels_[clamp_level(level)].width; }
    int height(int level) const { return levels_[clamp_level(level)].height; }
    Wrap wrap_s() const { return sampler_.wrap_s; }
    Wrap wrap_t() const { return sampler_.wrap_t; }
    const SamplerState& sampler() const { return sampler_; }
    // LINEAR / LINEAR_MIPMAP_LINEAR: sample_lod() is sample_trilinear().
    bool default_filters() const { return default_filters_; }
    // Wrap modes and filters in one number: equal keys sample alike.
    unsigned sampler_key() const { return sampler_key_; }

    // One stored texel as linear RGBA; the level and coordinates are clamped to
    // the valid range.
    glm::vec4 texel(int level, int x, int y) const;
    // The mean colour of the image: the last (1x1) level.
    glm::vec4 average() const { return texel(level_count_ - 1, 0, 0); }
    // The texel at index i of the whole chain (level_offset(k) + y * width + x),
    // as linear RGBA: what the samplers filter.
    glm::vec4 texel_at(std::size_t i) const;

    // Storage. Float: texel_data() holds float RGBA. 8-bit: unorm8_data() holds
    // channels() bytes per texel (and kReadSlack more bytes, so that 8 bytes can
    // be read at any texel); stored channel c becomes a float through table(c), and
    // output component k (r, g, b, a) is stored channel swizzle(k), or 1 when
    // swizzle(k) == kOne.
    static constexpr int kOne = 4;
    static constexpr std::size_t kReadSlack = 8;
    bool is_unorm8() const { return channels_ > 0; }
    int channels() const { return channels_; }
    int swizzle(int k) const { return swizzle_[k]; }
    const float* table(int c) const { return table_[c]; }
    // The texels of every level, level 0 first, each row-major; level k starts
    // at texel level_offset(k). For the 4x4-block sampler (sample_lanes.h).
    const glm::vec4* texel_data() const { return texels_; }
    const std::uint8_t* unorm8_data() const { return bytes_; }
    std::size_t level_offset(int level) const { return levels_[clamp_level(level)].offset; }
    // Bytes held by the texels of all levels.
    std::size_t memory_bytes() const { return memory_bytes_; }

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
    // The texel NEAREST to (u, v) on one level (clamped to the valid range).
    glm::vec4 sample_nearest(float u, float v, int level) const;
    // The levels and filter the sampler's filters choose at lambda (file
    // comment); NaN lambda magnifies.
    LevelChoice choose_level(float lambda) const;
    // The lookup the sampler's filters define at lambda: sample_trilinear()
    // for the default filters.
    glm::vec4 sample_lod(float u, float v, float lambda) const { return (this->*sample_fn_)(u, v, lambda); }
    // sample_lod(u, v, lod(...)).
    glm::vec4 sample(float u, float v, float dudx, float dvdx, float dudy, float dvdy) const {
        return sample_lod(u, v, lod(dudx, dvdx, dudy, dvdy));
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
    template <Wrap S, Wrap T> glm::vec4 nearest_reduced(float u, float v, int level) const;
    template <Wrap S, Wrap T> glm::vec4 nearest_wrapped(float u, float v, int level) const;
    template <Wrap S, Wrap T> glm::vec4 filtered_wrapped(float u, float v, float lambda) const;
    using Sampler = glm::vec4 (Texture::*)(float, float, float) const;
    using LevelSampler = glm::vec4 (Texture::*)(float, float, int) const;
    static const Sampler kTrilinear[3][3];
    static const Sampler kFiltered[3][3];
    static const LevelSampler kBilinear[3][3];
    static const LevelSampler kNearest[3][3];
    void set_sampler(const SamplerState& s);

    // Lays out the chain for a w x h level 0.
    void layout(int w, int h);
    static Texture from_unorm8(const std::uint8_t* level0, int channels, const float* const tables[4],
                               const int swizzle[4], int w, int h, Wrap s, Wrap t, ThreadPool* pool);

    struct FreeBytes {
        void operator()(std::uint8_t* p) const { std::free(p); }
    };
    // The texels, shared by every view of one decoded image.
    struct Storage {
        std::vector<glm::vec4> texels;  // float storage: all levels, level 0 first, row-major
        std::unique_ptr<std::uint8_t[], FreeBytes> bytes;  // 8-bit storage, same order
    };
    std::shared_ptr<const Storage> storage_;
    const glm::vec4* texels_ = nullptr;   // storage_->texels
    const std::uint8_t* bytes_ = nullptr; // storage_->bytes
    int channels_ = 0;               // 0: float storage
    int swizzle_[4] = {0, 1, 2, 3};
    const float* table_[4] = {nullptr, nullptr, nullptr, nullptr};
    std::size_t total_texels_ = 0;
    std::size_t memory_bytes_ = 0;
    Level levels_[kMaxLevels];
    int level_count_ = 0;
    SamplerState sampler_;
    Sampler sample_fn_ = &Texture::trilinear_wrapped<Wrap::Repeat, Wrap::Repeat>;
    float min_mag_c_ = 0.0f;         // magnification when lambda <= c
    bool default_filters_ = true;
    unsigned sampler_key_ = 0;
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

// The NEAREST texel of a reduced coordinate x = reduce<W>(c) * n, i.e.
// floor(c n) wrapped, into [0, n). Repeat and ClampToEdge reach n only when
// the true index is n - 1 (a tiny negative c folds to 1; c n rounding up to
// n); MirroredRepeat reaches 2n only from a tiny negative c (texel 0).
template <Wrap W>
inline int nearest_index(float x, int n) {
    const int i = int(std::floor(x));
    if constexpr (W == Wrap::MirroredRepeat) {
        const int j = i >= 2 * n ? i - 2 * n : i;
        return j >= n ? 2 * n - 1 - j : j;
    }
    return i >= n ? n - 1 : i;
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
    const std::size_t row_a = L.offset + std::size_t(ya) * std::size_t(L.width);
    const std::size_t row_b = L.offset + std::size_t(yb) * std::size_t(L.width);
    const glm::vec4 a = texel_at(row_a + std::size_t(xa)), b = texel_at(row_a + std::size_t(xb));
    const glm::vec4 c = texel_at(row_b + std::size_t(xa)), d = texel_at(row_b + std::size_t(xb));
    // a + (b - a) t: exact at t = 0 and wherever a == b (a constant texture
    // samples to exactly its value).
    const glm::vec4 top = a + (b - a) * tx;
    const glm::vec4 bottom = c + (d - c) * tx;
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

template <Wrap S, Wrap T>
inline glm::vec4 Texture::nearest_reduced(float u, float v, int level) const {
    const Level& L = levels_[level];
    const int x = texture_detail::nearest_index<S>(u * L.fwidth, L.width);
    const int y = texture_detail::nearest_index<T>(v * L.fheight, L.height);
    return texel_at(L.offset + std::size_t(y) * std::size_t(L.width) + std::size_t(x));
}

template <Wrap S, Wrap T>
inline glm::vec4 Texture::nearest_wrapped(float u, float v, int level) const {
    return nearest_reduced<S, T>(texture_detail::reduce<S>(u), texture_detail::reduce<T>(v), clamp_level(level));
}

inline LevelChoice Texture::choose_level(float lambda) const {
    LevelChoice c;
    if (!(lambda > min_mag_c_)) {  // magnification, or NaN
        c.nearest = sampler_.mag == Filter::Nearest;
        return c;
    }
    const int last = level_count_ - 1;
    switch (sampler_.min) {
    case MinFilter::Nearest: c.nearest = true; return c;
    case MinFilter::Linear: return c;
    case MinFilter::NearestMipmapNearest:
    case MinFilter::LinearMipmapNearest: {
        // ceil(lambda + 1/2) - 1 == ceil(lambda - 1/2), and lambda - 0.5f is
        // exact for lambda >= 0.25 (both are multiples of lambda's ulp).
        const float d = std::ceil(lambda - 0.5f);
        c.level = d <= 0.0f ? 0 : (d >= float(last) ? last : int(d));
        c.nearest = sampler_.min == MinFilter::NearestMipmapNearest;
        return c;
    }
    case MinFilter::NearestMipmapLinear:
    case MinFilter::LinearMipmapLinear:
        c.nearest = sampler_.min == MinFilter::NearestMipmapLinear;
        if (lambda >= float(last)) {
            c.level = last;
            return c;
        }
        const float fl = std::floor(lambda);
        c.level = int(fl);
        c.t = lambda - fl;
        c.blend = c.t != 0.0f;
        return c;
    }
    return c;
}

template <Wrap S, Wrap T>
inline glm::vec4 Texture::filtered_wrapped(float u, float v, float lambda) const {
    const float ur = texture_detail::reduce<S>(u), vr = texture_detail::reduce<T>(v);
    const LevelChoice c = choose_level(lambda);
    const glm::vec4 a = c.nearest ? nearest_reduced<S, T>(ur, vr, c.level) : bilinear_reduced<S, T>(ur, vr, c.level);
    if (!c.blend) return a;
    const glm::vec4 b =
        c.nearest ? nearest_reduced<S, T>(ur, vr, c.level + 1) : bilinear_reduced<S, T>(ur, vr, c.level + 1);
    return a + (b - a) * c.t;
}

inline glm::vec4 Texture::texel_at(std::size_t i) const {
    if (channels_ == 0) return texels_[i];
    const std::uint8_t* p = bytes_ + i * std::size_t(channels_);
    float c[5] = {0.0f, 0.0f, 0.0f, 0.0f, 1.0f};
    for (int k = 0; k < channels_; ++k) c[k] = table_[k][p[k]];
    return {c[swizzle_[0]], c[swizzle_[1]], c[swizzle_[2]], c[swizzle_[3]]};
}

inline glm::vec4 Texture::sample_bilinear(float u, float v, int level) const {
    return (this->*kBilinear[int(sampler_.wrap_s)][int(sampler_.wrap_t)])(u, v, level);
}

inline glm::vec4 Texture::sample_nearest(float u, float v, int level) const {
    return (this->*kNearest[int(sampler_.wrap_s)][int(sampler_.wrap_t)])(u, v, level);
}

inline glm::vec4 Texture::sample_trilinear(float u, float v, float lambda) const {
    return (this->*kTrilinear[int(sampler_.wrap_s)][int(sampler_.wrap_t)])(u, v, lambda);
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

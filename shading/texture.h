// Textures: the box-filtered mip chain of a decoded image (scene/image.h) and
// the bilinear / trilinear samplers the shaders call per pixel.
//
// Conventions (docs/conventions.md, "Textures"): texel centres at (i + 0.5) / width,
// v = 0 is the TOP row of the image (the project's internal UVs; no flipping
// here), lambda = log2(max(|d(uv * size)/dx|, |d(uv * size)/dy|)) with level-0
// sizes, as the OpenGL specification writes it (no anisotropy), the log2 from
// a table (texture_detail::lod_log2). Filtering and mip generation happen in
// linear space.
//
// Storage follows the image: 8-bit images keep 1 to 4 bytes per texel (a
// 2048x2048 RGBA map with its mips is 21.3 MB, not the 89 MB of float RGBA).
// Their mips are stored in 8 bits too, as GPUs store generated mips: each
// texel is the correctly rounded byte of the exact area-weighted box filter of
// the level above, in linear space (sRGB channels are decoded, filtered, and
// re-encoded). Float images (HDR, 16-bit, procedural) keep float RGBA texels
// and float mips, and filter in float.
//
// 8-bit textures filter in fixed point (docs/conventions.md, "Precision of
// the weights"), as llvmpipe's 8-bit path and Direct3D 11 hardware do: each
// stored byte becomes a 15-bit linear code (byte * 128 for linear channels,
// the correctly rounded sRGB decode * 32640 for colour ones: linear 1.0 is
// 32640 = 255 * 128), the bilinear and level weights are rounded to 8 bits
// (w = int(t * 256 + 0.5), 0..256), and each lerp is a * (256 - w) + b * w
// in integers, narrowed back to 15 bits ((x + 128) >> 8) before the next
// one. The last integer (at most 32640 * 256) becomes a float by one
// division by 32640 * 256. Integers leave nothing to round differently, so
// the scalar sampler, the 4x4-block one and the stepper agree by
// construction; a linear byte b that is read alone gives exactly b / 255.
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

#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>
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

struct CodeCache;  // Texture::unorm8_codes(), texture.cpp

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
    // An 8-bit image whose pixel buffer has the capacity unorm8_bytes() asks
    // for (decode_image's `capacity`) becomes the texture's storage in place:
    // its level 0 is not copied.
    static Texture from_image(Image img, Wrap s = Wrap::Repeat, Wrap t = Wrap::Repeat,
                              ThreadPool* pool = nullptr);
    // The bytes the 8-bit storage of a w x h image of `channels` takes: every
    // level and the read slack.
    static std::size_t unorm8_bytes(int w, int h, int channels);

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
    // be read at any texel); stored channel c's byte becomes the 15-bit code
    // code_table(c)[byte] (file comment), whose value table(c)[byte] is
    // code / 32640; output component k (r, g, b, a) is stored channel
    // swizzle(k), or 1 when swizzle(k) == kOne.
    static constexpr int kOne = 4;
    static constexpr std::size_t kReadSlack = 8;
    bool is_unorm8() const { return channels_ > 0; }
    int channels() const { return channels_; }
    int swizzle(int k) const { return swizzle_[k]; }
    const float* table(int c) const { return table_[c]; }
    const std::uint16_t* code_table(int c) const { return code_[c]; }
    // Stored channel c holds sRGB-encoded bytes.
    bool srgb(int c) const { return srgb_[c]; }
    // code_table(c) of the sRGB channels, null for the linear ones.
    const std::uint16_t* const* srgb_code_tables() const { return srgb_code_; }
    // What an 8-bit lookup of the output components in a mask (bit k: r, g,
    // b, a) reads, worked out once at construction for the block sampler:
    // the stored channels needed (bit c), whether one of them is sRGB, and
    // for each written output in order its component and its stored channel
    // (kOne: the constant 1).
    // identity: the outputs are components 0 .. channels() - 1, each from
    // its own stored channel.
    struct Unorm8Reads {
        std::uint8_t need = 0, outputs = 0;
        bool needs_srgb = false, identity = false;
        std::int8_t component[4] = {}, channel[4] = {};
    };
    const Unorm8Reads& unorm8_reads(unsigned components) const { return reads_[components & 15u]; }

    // The 8-bit filter's steps (file comment), shared by the scalar sampler
    // and the block sampler's lanes: per stored channel, an integer in
    // [0, 32640 * 256].
    struct Fix4 {
        std::int32_t c[4] = {0, 0, 0, 0};
    };
    // Texel i alone (NEAREST): code * 256.
    Fix4 fix_texel(std::size_t i) const;
    // Bilinear over texels i00, i10 (right), i01 (below), i11 with weights tx, ty.
    Fix4 fix_bilinear(std::size_t i00, std::size_t i10, std::size_t i01, std::size_t i11, float tx,
                      float ty) const;
    // Level blend a + (b - a) t, both narrowed to codes first.
    static Fix4 fix_blend(const Fix4& a, const Fix4& b, float t);
    // As linear RGBA: each channel / (32640 * 256), through swizzle().
    glm::vec4 fix_value(const Fix4& f) const;
    // The texels of every level, level 0 first, each row-major; level k starts
    // at texel level_offset(k). For the 4x4-block sampler (sample_lanes.h).
    const glm::vec4* texel_data() const { return texels_; }
    const std::uint8_t* unorm8_data() const { return bytes_; }
    // The codes of unorm8_data(), code_table(c)[byte] for every stored byte
    // (channels() per texel, and kCodeSlack more), of at least the levels
    // whose bits are set in `levels` (built on first use, once, under a lock:
    // a frame often reads only a few levels of a large map), or null. Held
    // only by 3- and 4-channel textures with an sRGB channel where the block
    // sampler runs its 8-lane AVX2 loop, which then reads a lane's two taps of
    // a row as one 16-byte load instead of a gather per tap and channel from
    // the code table (sample_lanes.h).
    static constexpr std::size_t kCodeSlack = 8;
    const std::uint16_t* unorm8_codes(std::uint32_t levels) const { return codes_ ? filled_codes(levels) : nullptr; }
    std::size_t level_offset(int level) const { return levels_[clamp_level(level)].offset; }
    // Bytes held by the texels of all levels.
    std::size_t memory_bytes() const { return memory_bytes_; }
    // Bytes of the levels of unorm8_codes() built so far (0 without them).
    std::size_t code_bytes() const;

    // lambda = log2(rho), rho = max(sqrt((dudx w)^2 + (dvdx h)^2),
    // sqrt((dudy w)^2 + (dvdy h)^2)) with the level-0 size w x h. The result is
    // finite: clamped to [-64, 64] (zero derivatives give -64), NaN gives 0.
    float lod(float dudx, float dvdx, float dudy, float dvdy) const;
    // The level-0 size as lod() scales the derivatives by it.
    float lod_width() const { return levels_[0].fwidth; }
    float lod_height() const { return levels_[0].fheight; }

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

    // unorm8_codes() with codes_ set: fills the levels not filled yet.
    const std::uint16_t* filled_codes(std::uint32_t levels) const;
    int clamp_level(int level) const {
        return level < 0 ? 0 : (level >= level_count_ ? level_count_ - 1 : level);
    }
    // The samplers with the wrap modes fixed at compile time; the public ones
    // dispatch to them through a table, once per call.
    template <Wrap S, Wrap T>
    void footprint(float u, float v, int level, std::size_t idx[4], float& tx, float& ty) const;
    template <Wrap S, Wrap T> Fix4 fix_bilinear_reduced(float u, float v, int level) const;
    template <Wrap S, Wrap T> std::size_t nearest_texel(float u, float v, int level) const;
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
    // srgb[c]: stored channel c holds sRGB-encoded colour.
    // With `adopt` (whose data is level0) of capacity enough, its buffer
    // becomes the storage.
    static Texture from_unorm8(const std::uint8_t* level0, int channels, const bool srgb[4], const int swizzle[4],
                               int w, int h, Wrap s, Wrap t, ThreadPool* pool,
                               std::vector<std::uint8_t>* adopt = nullptr);

    struct FreeBytes {  // for the 8-bit storage's buffers (allocated on huge pages where large)
        void operator()(std::uint8_t* p) const noexcept;
    };
    // The texels, shared by every view of one decoded image.
    struct Storage {
        std::vector<glm::vec4> texels;  // float storage: all levels, level 0 first, row-major
        std::unique_ptr<std::uint8_t[], FreeBytes> bytes;  // 8-bit storage, same order
        std::vector<std::uint8_t> adopted;                  // or the decoded image's own buffer
        std::unique_ptr<CodeCache> codes;  // unorm8_codes(), or null
        Storage();
        ~Storage();
    };
    std::shared_ptr<const Storage> storage_;
    const glm::vec4* texels_ = nullptr;   // storage_->texels
    const std::uint8_t* bytes_ = nullptr; // storage_->bytes
    CodeCache* codes_ = nullptr;          // storage_->codes
    int channels_ = 0;               // 0: float storage
    int swizzle_[4] = {0, 1, 2, 3};
    const float* table_[4] = {nullptr, nullptr, nullptr, nullptr};
    const std::uint16_t* code_[4] = {nullptr, nullptr, nullptr, nullptr};
    bool srgb_[4] = {false, false, false, false};
    const std::uint16_t* srgb_code_[4] = {nullptr, nullptr, nullptr, nullptr};
    Unorm8Reads reads_[16];
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

// The fixed-point filter of 8-bit textures (file comment).
constexpr std::int32_t kFixOne = 255 * 128;         // the code of linear 1.0
constexpr std::int32_t kFixFull = kFixOne * 256;    // a filtered value before narrowing
constexpr float kFixFullF = float(kFixFull);        // exact

// The code table of every sRGB channel (Texture::code_table()), 258 entries.
const std::uint16_t* srgb_code_table();

// A weight in [0, 1] rounded to 8 bits: 0..256 (t * 256 is exact).
inline std::int32_t weight8(float t) { return std::int32_t(t * 256.0f + 0.5f); }
// a (256 - w) + b w, for codes a, b <= kFixOne: at most kFixFull.
inline std::int32_t lerp8(std::int32_t a, std::int32_t b, std::int32_t w) { return a * (256 - w) + b * w; }
// A lerp's result back to a code, rounding half up.
inline std::int32_t narrow8(std::int32_t x) { return (x + 128) >> 8; }

// log2(x) for the level of detail, the same bits everywhere and cheap
// enough per quad: the exponent, plus log2(1 + m) for the mantissa m read
// linearly between the 257 entries of a table of log2(1 + i / 256) made with
// det::log2 (error below 3e-6 before the sum's rounding, far under the 1/256
// the level fraction keeps).
// x must be a positive normal float.
extern const std::array<float, 257> kLog2Mantissa;
inline float lod_log2(float x) {
    std::uint32_t bits;
    std::memcpy(&bits, &x, sizeof bits);
    const int e = int(bits >> 23) - 127;
    const std::uint32_t m = bits & 0x7FFFFFu;
    const int i = int(m >> 15);
    const float f = float(m & 0x7FFFu) * (1.0f / 32768.0f);  // exact
    const float lo = kLog2Mantissa[std::size_t(i)], hi = kLog2Mantissa[std::size_t(i) + 1];
    return float(e) + (lo + (hi - lo) * f);
}

} // namespace texture_detail

template <Wrap S, Wrap T>
inline void Texture::footprint(float u, float v, int level, std::size_t idx[4], float& tx, float& ty) const {
    const Level& L = levels_[level];
    // Texel centres at (i + 0.5) / size.
    const float x = u * L.fwidth - 0.5f, y = v * L.fheight - 0.5f;
    const float fx = std::floor(x), fy = std::floor(y);
    tx = x - fx;
    ty = y - fy;
    const int x0 = int(fx), y0 = int(fy);
    const int xa = texture_detail::wrap_index<S>(x0, L.width);
    const int xb = texture_detail::wrap_index<S>(x0 + 1, L.width);
    const int ya = texture_detail::wrap_index<T>(y0, L.height);
    const int yb = texture_detail::wrap_index<T>(y0 + 1, L.height);
    const std::size_t row_a = L.offset + std::size_t(ya) * std::size_t(L.width);
    const std::size_t row_b = L.offset + std::size_t(yb) * std::size_t(L.width);
    idx[0] = row_a + std::size_t(xa);
    idx[1] = row_a + std::size_t(xb);
    idx[2] = row_b + std::size_t(xa);
    idx[3] = row_b + std::size_t(xb);
}

template <Wrap S, Wrap T>
inline Texture::Fix4 Texture::fix_bilinear_reduced(float u, float v, int level) const {
    std::size_t i[4];
    float tx, ty;
    footprint<S, T>(u, v, level, i, tx, ty);
    return fix_bilinear(i[0], i[1], i[2], i[3], tx, ty);
}

template <Wrap S, Wrap T>
inline glm::vec4 Texture::bilinear_reduced(float u, float v, int level) const {
    if (channels_) return fix_value(fix_bilinear_reduced<S, T>(u, v, level));
    std::size_t i[4];
    float tx, ty;
    footprint<S, T>(u, v, level, i, tx, ty);
    const glm::vec4 a = texels_[i[0]], b = texels_[i[1]], c = texels_[i[2]], d = texels_[i[3]];
    // a + (b - a) t: exact at t = 0 and wherever a == b (a constant texture
    // samples to exactly its value).
    const glm::vec4 top = a + (b - a) * tx;
    const glm::vec4 bottom = c + (d - c) * tx;
    return top + (bottom - top) * ty;
}

inline Texture::Fix4 Texture::fix_texel(std::size_t i) const {
    const std::uint8_t* p = bytes_ + i * std::size_t(channels_);
    Fix4 r;
    for (int c = 0; c < channels_; ++c) r.c[c] = std::int32_t(code_[c][p[c]]) * 256;
    return r;
}

inline Texture::Fix4 Texture::fix_bilinear(std::size_t i00, std::size_t i10, std::size_t i01, std::size_t i11,
                                           float tx, float ty) const {
    using namespace texture_detail;
    const std::size_t C = std::size_t(channels_);
    const std::uint8_t *a = bytes_ + i00 * C, *b = bytes_ + i10 * C, *c = bytes_ + i01 * C, *d = bytes_ + i11 * C;
    const std::int32_t wx = weight8(tx), wy = weight8(ty);
    Fix4 r;
    for (std::size_t k = 0; k < C; ++k) {
        const std::uint16_t* code = code_[k];
        const std::int32_t top = narrow8(lerp8(code[a[k]], code[b[k]], wx));
        const std::int32_t bottom = narrow8(lerp8(code[c[k]], code[d[k]], wx));
        r.c[k] = lerp8(top, bottom, wy);
    }
    return r;
}

inline Texture::Fix4 Texture::fix_blend(const Fix4& a, const Fix4& b, float t) {
    using namespace texture_detail;
    const std::int32_t w = weight8(t);
    Fix4 r;
    for (int k = 0; k < 4; ++k) r.c[k] = lerp8(narrow8(a.c[k]), narrow8(b.c[k]), w);
    return r;
}

inline glm::vec4 Texture::fix_value(const Fix4& f) const {
    float v[5];
    for (int k = 0; k < 4; ++k) v[k] = float(f.c[k]) / texture_detail::kFixFullF;
    v[kOne] = 1.0f;
    return {v[swizzle_[0]], v[swizzle_[1]], v[swizzle_[2]], v[swizzle_[3]]};
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
    if (channels_) {
        const Fix4 a = fix_bilinear_reduced<S, T>(ur, vr, l0);
        if (t == 0.0f) return fix_value(a);
        return fix_value(fix_blend(a, fix_bilinear_reduced<S, T>(ur, vr, l0 + 1), t));
    }
    const glm::vec4 a = bilinear_reduced<S, T>(ur, vr, l0);
    if (t == 0.0f) return a;
    return a + (bilinear_reduced<S, T>(ur, vr, l0 + 1) - a) * t;
}

template <Wrap S, Wrap T>
inline std::size_t Texture::nearest_texel(float u, float v, int level) const {
    const Level& L = levels_[level];
    const int x = texture_detail::nearest_index<S>(u * L.fwidth, L.width);
    const int y = texture_detail::nearest_index<T>(v * L.fheight, L.height);
    return L.offset + std::size_t(y) * std::size_t(L.width) + std::size_t(x);
}

template <Wrap S, Wrap T>
inline glm::vec4 Texture::nearest_reduced(float u, float v, int level) const {
    return texel_at(nearest_texel<S, T>(u, v, level));
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
    if (channels_) {
        auto one = [&](int level) {
            return c.nearest ? fix_texel(nearest_texel<S, T>(ur, vr, level)) : fix_bilinear_reduced<S, T>(ur, vr, level);
        };
        const Fix4 a = one(c.level);
        return fix_value(c.blend ? fix_blend(a, one(c.level + 1), c.t) : a);
    }
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
    if (rho2 != rho2) return 0.0f;                 // NaN derivatives
    if (!(rho2 >= 1.17549435e-38f)) return -64.0f;  // zero or subnormal: below 2^-63
    if (!(rho2 <= 3.40282347e38f)) return 64.0f;   // infinite
    const float lambda = 0.5f * texture_detail::lod_log2(rho2);
    return lambda < -64.0f ? -64.0f : (lambda > 64.0f ? 64.0f : lambda);
}

} // namespace prast

// Image decoding (stb_image -> linear float RGBA), mip chain construction, and
// the procedural brick textures of the built-in default scene. The samplers are
// inline in texture.h.
#include "shading/texture.h"

#include <algorithm>
#include <array>
#include <cerrno>
#include <climits>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <memory>
#include <stdexcept>
#include <string>

#include <stb_image.h>

namespace prast {

namespace {

// ---- Decoding

// The sRGB electro-optical transfer function (IEC 61966-2-1), exact form.
float srgb_to_linear(float c) {
    return c <= 0.04045f ? c / 12.92f : std::pow((c + 0.055f) / 1.055f, 2.4f);
}

const std::array<float, 256>& srgb_table() {
    static const std::array<float, 256> table = [] {
        std::array<float, 256> t{};
        for (int i = 0; i < 256; ++i) t[i] = srgb_to_linear(float(i) / 255.0f);
        return t;
    }();
    return table;
}

std::string stbi_reason() {
    const char* r = stbi_failure_reason();
    return r ? r : "unknown error";
}

// The container format by its signature, for messages: when its header is
// bad, stb_image tries every other format and reports only the last failure
// ("unknown image type").
const char* sniff_format(const unsigned char* p, std::size_t n) {
    auto starts = [&](const char* sig, std::size_t len) { return n >= len && std::memcmp(p, sig, len) == 0; };
    if (starts("\x89PNG\r\n\x1a\n", 8)) return "PNG";
    if (starts("\xff\xd8\xff", 3)) return "JPEG";
    if (starts("#?RADIANCE", 10) || starts("#?RGBE", 6)) return "HDR";
    if (starts("GIF8", 4)) return "GIF";
    if (starts("8BPS", 4)) return "PSD";
    if (starts("BM", 2)) return "BMP";
    return nullptr;
}

// Reads a whole file; stb_image's memory API then decodes it. Reading it
// ourselves lets us tell a directory, an empty file and an unreadable one apart.
std::vector<unsigned char> read_file(const std::string& path, const std::string& name) {
    std::error_code ec;
    if (std::filesystem::is_directory(path, ec))
        throw LoadError(name + ": is a directory, not an image file");
    std::FILE* f = std::fopen(path.c_str(), "rb");
    if (!f) throw LoadError(name + ": cannot open: " + std::strerror(errno));
    std::unique_ptr<std::FILE, int (*)(std::FILE*)> closer(f, std::fclose);
    std::vector<unsigned char> bytes;
    unsigned char chunk[1 << 16];
    for (;;) {
        const std::size_t n = std::fread(chunk, 1, sizeof chunk, f);
        bytes.insert(bytes.end(), chunk, chunk + n);
        // stb_image's memory API takes an int length.
        if (bytes.size() > std::size_t(INT_MAX))
            throw LoadError(name + ": file too large (over 2 GiB)");
        if (n < sizeof chunk) break;
    }
    if (std::ferror(f)) throw LoadError(name + ": read error: " + std::strerror(errno));
    if (bytes.empty()) throw LoadError(name + ": empty file");
    return bytes;
}

// Expands `comp` channels per texel to RGBA, decoding colour channels with
// `colour` and alpha with `alpha`.
template <class T, class ColourFn, class AlphaFn>
void expand_to_rgba(const T* src, int comp, std::size_t count, float* dst, ColourFn colour,
                    AlphaFn alpha) {
    for (std::size_t i = 0; i < count; ++i, src += comp, dst += 4) {
        if (comp <= 2) {
            const float g = colour(src[0]);
            dst[0] = dst[1] = dst[2] = g;
            dst[3] = comp == 2 ? alpha(src[1]) : 1.0f;
        } else {
            dst[0] = colour(src[0]);
            dst[1] = colour(src[1]);
            dst[2] = colour(src[2]);
            dst[3] = comp == 4 ? alpha(src[3]) : 1.0f;
        }
    }
}

// ---- Mip generation

// The source texels under output texel i when a row of n texels becomes
// max(1, n / 2): weights are the overlapped areas, normalised to sum to 1.
struct BoxTaps {
    int first = 0;
    int count = 0;
    float weight[3] = {0.0f, 0.0f, 0.0f};
};

BoxTaps box_taps(int n, int i) {
    BoxTaps t;
    if (n == 1) {  // this axis is already 1 texel: copy
        t.first = 0;
        t.count = 1;
        t.weight[0] = 1.0f;
    } else if (n % 2 == 0) {
        t.first = 2 * i;
        t.count = 2;
        t.weight[0] = t.weight[1] = 0.5f;
    } else {
        // n = 2m + 1 shrinks to m texels of width n / m = 2 + 1/m source texels;
        // output i spans [i n / m, (i + 1) n / m), which overlaps texels 2i, 2i+1
        // and 2i+2 by (m - i) / m, 1 and (i + 1) / m.
        const int m = n / 2;
        t.first = 2 * i;
        t.count = 3;
        t.weight[0] = float(m - i) / float(n);
        t.weight[1] = float(m) / float(n);
        t.weight[2] = float(i + 1) / float(n);
    }
    return t;
}

// Separable area filter: rows first into `tmp`, then columns into dst.
void downsample(const glm::vec4* src, int sw, int sh, glm::vec4* dst, int dw, int dh,
                std::vector<glm::vec4>& tmp) {
    std::vector<BoxTaps> tx(static_cast<std::size_t>(dw)), ty(static_cast<std::size_t>(dh));
    for (int i = 0; i < dw; ++i) tx[i] = box_taps(sw, i);
    for (int j = 0; j < dh; ++j) ty[j] = box_taps(sh, j);

    tmp.assign(std::size_t(dw) * std::size_t(sh), glm::vec4(0.0f));
    for (int y = 0; y < sh; ++y) {
        const glm::vec4* row = src + std::size_t(y) * std::size_t(sw);
        glm::vec4* out = tmp.data() + std::size_t(y) * std::size_t(dw);
        for (int i = 0; i < dw; ++i) {
            const BoxTaps& t = tx[i];
            glm::vec4 sum(0.0f);
            for (int k = 0; k < t.count; ++k) sum += row[t.first + k] * t.weight[k];
            out[i] = sum;
        }
    }
    for (int j = 0; j < dh; ++j) {
        const BoxTaps& t = ty[j];
        glm::vec4* out = dst + std::size_t(j) * std::size_t(dw);
        for (int i = 0; i < dw; ++i) out[i] = glm::vec4(0.0f);
        for (int k = 0; k < t.count; ++k) {
            const glm::vec4* row = tmp.data() + std::size_t(t.first + k) * std::size_t(dw);
            for (int i = 0; i < dw; ++i) out[i] += row[i] * t.weight[k];
        }
    }
}

} // namespace

Image decode_image(const ImageSource& src, bool srgb) {
    const std::string name = !src.name.empty()   ? src.name
                             : !src.path.empty() ? src.path
                                                 : std::string("<embedded image>");
    // Get the encoded bytes: embedded ones win over the path.
    std::vector<unsigned char> file_bytes;
    const std::vector<unsigned char>* bytes = &src.bytes;
    if (src.bytes.empty()) {
        if (src.path.empty()) throw LoadError(name + ": no image data (no path, no bytes)");
        file_bytes = read_file(src.path, name);
        bytes = &file_bytes;
    }
    if (bytes->size() > std::size_t(INT_MAX)) throw LoadError(name + ": image data too large");
    const stbi_uc* data = bytes->data();
    const int len = int(bytes->size());

    // Check the header before decoding anything: refuse absurd sizes up front.
    int w = 0, h = 0, comp = 0;
    if (!stbi_info_from_memory(data, len, &w, &h, &comp)) {
        const char* format = sniff_format(data, bytes->size());
        const std::string reason = stbi_reason();
        if (!format) throw LoadError(name + ": not an image file stb_image can read (" + reason + ")");
        throw LoadError(name + ": cannot decode " + format + " image: " +
                        (reason == "unknown image type" ? "corrupt or truncated header" : reason));
    }
    if (w <= 0 || h <= 0)
        throw LoadError(name + ": image has zero size (" + std::to_string(w) + "x" +
                        std::to_string(h) + ")");
    const std::int64_t texels = std::int64_t(w) * std::int64_t(h);
    if (texels > kMaxImageTexels)
        throw LoadError(name + ": image too large: " + std::to_string(w) + "x" +
                        std::to_string(h) + " = " + std::to_string(texels) +
                        " texels, more than the limit of " + std::to_string(kMaxImageTexels) +
                        " (2^28)");

    // Decode with the file's own channel count.
    struct StbiFree {
        void operator()(void* p) const { stbi_image_free(p); }
    };
    Image img;
    int dw = 0, dh = 0, dcomp = 0;
    auto check = [&](const void* pixels) {
        if (!pixels) throw LoadError(name + ": cannot decode image: " + stbi_reason());
        if (dw != w || dh != h || dcomp < 1 || dcomp > 4)
            throw LoadError(name + ": inconsistent image header");
        img.width = w;
        img.height = h;
        img.rgba.resize(std::size_t(texels) * 4);
    };
    const std::size_t count = std::size_t(texels);
    const auto unit = [](float c) { return c; };
    if (stbi_is_hdr_from_memory(data, len)) {
        // Radiance HDR: linear floats, kept as is whatever `srgb` says.
        std::unique_ptr<float, StbiFree> px(stbi_loadf_from_memory(data, len, &dw, &dh, &dcomp, 0));
        check(px.get());
        expand_to_rgba(px.get(), dcomp, count, img.rgba.data(), unit, unit);
    } else if (stbi_is_16_bit_from_memory(data, len)) {
        std::unique_ptr<stbi_us, StbiFree> px(stbi_load_16_from_memory(data, len, &dw, &dh, &dcomp, 0));
        check(px.get());
        const auto linear = [](stbi_us c) { return float(c) / 65535.0f; };
        const auto decode = [](stbi_us c) { return srgb_to_linear(float(c) / 65535.0f); };
        if (srgb) expand_to_rgba(px.get(), dcomp, count, img.rgba.data(), decode, linear);
        else expand_to_rgba(px.get(), dcomp, count, img.rgba.data(), linear, linear);
    } else {
        std::unique_ptr<stbi_uc, StbiFree> px(stbi_load_from_memory(data, len, &dw, &dh, &dcomp, 0));
        check(px.get());
        const std::array<float, 256>& table = srgb_table();
        const auto linear = [](stbi_uc c) { return float(c) / 255.0f; };
        const auto decode = [&table](stbi_uc c) { return table[c]; };
        if (srgb) expand_to_rgba(px.get(), dcomp, count, img.rgba.data(), decode, linear);
        else expand_to_rgba(px.get(), dcomp, count, img.rgba.data(), linear, linear);
    }
    return img;
}

// ---- Texture

// The samplers for each (wrap_s, wrap_t), indexed by the Wrap enumerators.
static_assert(int(Wrap::Repeat) == 0 && int(Wrap::ClampToEdge) == 1 && int(Wrap::MirroredRepeat) == 2);
namespace {
constexpr Wrap kR = Wrap::Repeat, kC = Wrap::ClampToEdge, kM = Wrap::MirroredRepeat;
} // namespace
const Texture::Sampler Texture::kTrilinear[3][3] = {
    {&Texture::trilinear_wrapped<kR, kR>, &Texture::trilinear_wrapped<kR, kC>, &Texture::trilinear_wrapped<kR, kM>},
    {&Texture::trilinear_wrapped<kC, kR>, &Texture::trilinear_wrapped<kC, kC>, &Texture::trilinear_wrapped<kC, kM>},
    {&Texture::trilinear_wrapped<kM, kR>, &Texture::trilinear_wrapped<kM, kC>, &Texture::trilinear_wrapped<kM, kM>}};
const Texture::LevelSampler Texture::kBilinear[3][3] = {
    {&Texture::bilinear_wrapped<kR, kR>, &Texture::bilinear_wrapped<kR, kC>, &Texture::bilinear_wrapped<kR, kM>},
    {&Texture::bilinear_wrapped<kC, kR>, &Texture::bilinear_wrapped<kC, kC>, &Texture::bilinear_wrapped<kC, kM>},
    {&Texture::bilinear_wrapped<kM, kR>, &Texture::bilinear_wrapped<kM, kC>, &Texture::bilinear_wrapped<kM, kM>}};

Texture::Texture() {
    texels_.assign(1, glm::vec4(1.0f));
    levels_[0] = Level{1, 1, 1.0f, 1.0f, 0};
    level_count_ = 1;
}

Texture Texture::from_image(Image img, Wrap s, Wrap t) {
    if (img.empty())
        throw std::invalid_argument("Texture::from_image: empty image (" +
                                    std::to_string(img.width) + "x" + std::to_string(img.height) + ")");
    const std::size_t count0 = std::size_t(img.width) * std::size_t(img.height);
    if (img.rgba.size() != count0 * 4)
        throw std::invalid_argument("Texture::from_image: rgba holds " +
                                    std::to_string(img.rgba.size()) + " floats, expected " +
                                    std::to_string(count0 * 4));
    Texture tex;
    tex.wrap_s_ = s;
    tex.wrap_t_ = t;

    // Lay out the chain: halve, round down, at least 1.
    int w = img.width, h = img.height, n = 0;
    std::size_t total = 0;
    for (;;) {
        tex.levels_[n] = Level{w, h, float(w), float(h), total};
        total += std::size_t(w) * std::size_t(h);
        ++n;
        if (w == 1 && h == 1) break;
        w = std::max(1, w / 2);
        h = std::max(1, h / 2);
    }
    tex.level_count_ = n;

    // Level 0 is the image; each further level is the box-filtered one above.
    tex.texels_.assign(total, glm::vec4(0.0f));
    for (std::size_t i = 0; i < count0; ++i)
        tex.texels_[i] = glm::vec4(img.rgba[4 * i], img.rgba[4 * i + 1], img.rgba[4 * i + 2],
                                   img.rgba[4 * i + 3]);
    img = Image();  // release the source before the chain needs its scratch row
    std::vector<glm::vec4> tmp;
    for (int l = 1; l < n; ++l) {
        const Level& a = tex.levels_[l - 1];
        const Level& b = tex.levels_[l];
        downsample(tex.texels_.data() + a.offset, a.width, a.height, tex.texels_.data() + b.offset,
                   b.width, b.height, tmp);
    }
    return tex;
}

glm::vec4 Texture::texel(int level, int x, int y) const {
    const Level& L = levels_[clamp_level(level)];
    x = std::clamp(x, 0, L.width - 1);
    y = std::clamp(y, 0, L.height - 1);
    return texels_[L.offset + std::size_t(y) * std::size_t(L.width) + std::size_t(x)];
}

// ---- Procedural images

namespace {

void check_size(const char* what, int size) {
    if (size < 1 || size > 16384)
        throw std::invalid_argument(std::string(what) + ": size " + std::to_string(size) +
                                    " out of range [1, 16384]");
}

// An integer hash with good avalanche (xorshift-multiply rounds, after Chris
// Wellons' "lowbias32" constants).
std::uint32_t hash_u32(std::uint32_t x) {
    x ^= x >> 16;
    x *= 0x7feb352dU;
    x ^= x >> 15;
    x *= 0x846ca68bU;
    x ^= x >> 16;
    return x;
}

std::uint32_t hash3(int x, int y, std::uint32_t seed) {
    return hash_u32(std::uint32_t(x) * 0x9E3779B1U ^ hash_u32(std::uint32_t(y) + seed * 0x85EBCA77U));
}

float unit_float(std::uint32_t h) { return float(h >> 8) * (1.0f / 16777216.0f); }  // [0, 1)

// Smooth value noise in [0, 1) with `period` lattice cells across [0, 1), so
// it tiles seamlessly.
float value_noise(glm::vec2 uv, int period, std::uint32_t seed) {
    const float x = uv.x * float(period), y = uv.y * float(period);
    const float fx = std::floor(x), fy = std::floor(y);
    const int ix = int(fx), iy = int(fy);
    auto lattice = [&](int i, int j) {
        return unit_float(hash3(((i % period) + period) % period, ((j % period) + period) % period, seed));
    };
    auto smooth = [](float t) { return t * t * (3.0f - 2.0f * t); };
    const float sx = smooth(x - fx), sy = smooth(y - fy);
    const float top = lattice(ix, iy) + (lattice(ix + 1, iy) - lattice(ix, iy)) * sx;
    const float bottom = lattice(ix, iy + 1) + (lattice(ix + 1, iy + 1) - lattice(ix, iy + 1)) * sx;
    return top + (bottom - top) * sy;
}

// Brick layout, in brick heights H = 1/8 of the texture: 4 bricks (2H wide)
// across, 8 rows, odd rows shifted by half a brick (running bond). Both counts
// divide the texture, so the pattern tiles under Repeat.
constexpr int kBrickCols = 4, kBrickRows = 8;
constexpr float kGroutHalf = 0.06f;  // half the grout joint, in H
constexpr float kBevel = 0.10f;      // width of the rounded brick edge, in H

enum class Zone { Grout, Bevel, Face };

struct BrickPoint {
    std::uint32_t id = 0;  // hash of the (wrapped) brick coordinates
    Zone zone = Zone::Face;
    float t = 0.0f;        // position across the zone, 0 at its inner (grout-side) edge
    glm::vec2 inward{0.0f};  // uv direction in which the distance to the brick edge grows
};

BrickPoint brick_at(glm::vec2 uv) {
    const float ry = uv.y * float(kBrickRows);
    const float row = std::floor(ry), fy = ry - row;
    const int irow = int(row);
    const float rx = uv.x * float(kBrickCols) + ((irow & 1) ? 0.5f : 0.0f);
    const float col = std::floor(rx), fx = rx - col;
    const int icol = int(col);

    BrickPoint p;
    p.id = hash3(((icol % kBrickCols) + kBrickCols) % kBrickCols,
                 ((irow % kBrickRows) + kBrickRows) % kBrickRows, 17U);
    // Distances to the nearest vertical and horizontal brick edges, in H.
    const float dx = std::min(fx, 1.0f - fx) * 2.0f;
    const float dy = std::min(fy, 1.0f - fy);
    float d;
    if (dx < dy) {
        d = dx;
        p.inward = glm::vec2(fx < 0.5f ? 1.0f : -1.0f, 0.0f);
    } else {
        d = dy;
        p.inward = glm::vec2(0.0f, fy < 0.5f ? 1.0f : -1.0f);
    }
    if (d < kGroutHalf) {
        p.zone = Zone::Grout;
        p.t = d / kGroutHalf;
    } else if (d < kGroutHalf + kBevel) {
        p.zone = Zone::Bevel;
        p.t = (d - kGroutHalf) / kBevel;
    } else {
        p.zone = Zone::Face;
        p.t = 1.0f;
    }
    return p;
}

struct BrickLook {
    glm::vec3 albedo;
    float roughness;
    float metallic;
    glm::vec2 tilt;  // height gradient of the brick face (a slightly uneven lay)
};

BrickLook brick_look(std::uint32_t id) {
    // Glazed ceramic colours, linear.
    static const glm::vec3 palette[5] = {
        {0.42f, 0.11f, 0.05f},  // terracotta
        {0.60f, 0.46f, 0.28f},  // sand
        {0.09f, 0.13f, 0.21f},  // slate blue
        {0.19f, 0.29f, 0.17f},  // sage
        {0.74f, 0.69f, 0.57f},  // cream
    };
    BrickLook look;
    const float pick = unit_float(hash_u32(id ^ 0x1234567U));
    if (pick < 0.1f) {  // a few gold bricks show off the metallic path
        look.albedo = glm::vec3(1.0f, 0.766f, 0.336f);
        look.metallic = 1.0f;
        look.roughness = 0.25f;
    } else {
        const int k = int(hash_u32(id ^ 0xABCDEFU) % 5U);
        look.albedo = palette[k] * (0.85f + 0.3f * unit_float(hash_u32(id ^ 0x55AA55U)));
        look.metallic = 0.0f;
        look.roughness = 0.25f + 0.2f * unit_float(hash_u32(id ^ 0x777U));
    }
    look.tilt = glm::vec2(unit_float(hash_u32(id ^ 0x9E37U)) - 0.5f,
                          unit_float(hash_u32(id ^ 0x79B9U)) - 0.5f) * 0.06f;
    return look;
}

// Renders f(uv) -> vec4 with 2x2 sub-samples per texel averaged: smoother
// grout edges at small sizes; the mip chain does the rest.
template <class F>
Image render_procedural(int size, F f) {
    Image img;
    img.width = img.height = size;
    img.rgba.assign(std::size_t(size) * std::size_t(size) * 4, 0.0f);
    const float inv = 1.0f / float(size);
    for (int y = 0; y < size; ++y)
        for (int x = 0; x < size; ++x) {
            glm::vec4 sum(0.0f);
            for (int sy = 0; sy < 2; ++sy)
                for (int sx = 0; sx < 2; ++sx)
                    sum += f(glm::vec2((float(x) + 0.25f + 0.5f * float(sx)) * inv,
                                       (float(y) + 0.25f + 0.5f * float(sy)) * inv));
            img.set(x, y, sum * 0.25f);
        }
    return img;
}

constexpr float kGroutAlbedo = 0.28f;

} // namespace

Image make_checker(int size, int cells, glm::vec4 a, glm::vec4 b) {
    check_size("make_checker", size);
    if (cells < 1 || cells > size)
        throw std::invalid_argument("make_checker: cells " + std::to_string(cells) +
                                    " out of range [1, size]");
    Image img;
    img.width = img.height = size;
    img.rgba.assign(std::size_t(size) * std::size_t(size) * 4, 0.0f);
    for (int y = 0; y < size; ++y)
        for (int x = 0; x < size; ++x) {
            const int cx = int(std::int64_t(x) * cells / size), cy = int(std::int64_t(y) * cells / size);
            img.set(x, y, ((cx + cy) & 1) ? b : a);
        }
    return img;
}

Image make_tiles_albedo(int size) {
    check_size("make_tiles_albedo", size);
    return render_procedural(size, [](glm::vec2 uv) {
        const BrickPoint p = brick_at(uv);
        if (p.zone == Zone::Grout) {
            const float grit = value_noise(uv, 128, 3U);
            return glm::vec4(glm::vec3(kGroutAlbedo * (0.8f + 0.4f * grit)), 1.0f);
        }
        const BrickLook look = brick_look(p.id);
        const float mottle = value_noise(uv, 32, 5U);
        // Edges slightly darker where the glaze runs thin.
        const float edge = p.zone == Zone::Bevel ? 0.85f + 0.15f * p.t : 1.0f;
        return glm::vec4(glm::min(look.albedo * ((0.92f + 0.16f * mottle) * edge), glm::vec3(1.0f)), 1.0f);
    });
}

Image make_tiles_normal(int size) {
    check_size("make_tiles_normal", size);
    Image img = render_procedural(size, [](glm::vec2 uv) {
        const BrickPoint p = brick_at(uv);
        // Height gradient (dh/du, dh/dv), as a slope per unit distance.
        glm::vec2 grad(0.0f);
        switch (p.zone) {
        case Zone::Grout:  // concave groove: flat in the middle, rising to the brick
            grad = p.inward * (0.3f * p.t);
            break;
        case Zone::Bevel:  // rounded edge: steepest next to the grout, flat at the face
            grad = p.inward * (1.1f * (1.0f - p.t)) + brick_look(p.id).tilt;
            break;
        case Zone::Face:
            grad = brick_look(p.id).tilt;
            break;
        }
        // Tangent space: x along T = +u, y along B = -v (up the image), so
        // n = (-dh/du, +dh/dv, 1), normalised.
        return glm::vec4(glm::normalize(glm::vec3(-grad.x, grad.y, 1.0f)), 0.0f);
    });
    // Renormalise the averaged sub-samples and encode 0.5 n + 0.5.
    for (int y = 0; y < size; ++y)
        for (int x = 0; x < size; ++x) {
            const glm::vec3 n = glm::normalize(glm::vec3(img.at(x, y)));
            img.set(x, y, glm::vec4(n * 0.5f + 0.5f, 1.0f));
        }
    return img;
}

Image make_tiles_roughness_metal(int size) {
    check_size("make_tiles_roughness_metal", size);
    return render_procedural(size, [](glm::vec2 uv) {
        const BrickPoint p = brick_at(uv);
        if (p.zone == Zone::Grout) {
            const float grit = value_noise(uv, 128, 3U);
            return glm::vec4(0.55f + 0.15f * p.t, 0.85f + 0.1f * grit, 0.0f, 1.0f);
        }
        const BrickLook look = brick_look(p.id);
        const float ao = p.zone == Zone::Bevel ? 0.85f + 0.15f * p.t : 1.0f;
        const float wear = value_noise(uv, 32, 9U);
        return glm::vec4(ao, look.roughness * (0.9f + 0.2f * wear), look.metallic, 1.0f);
    });
}

} // namespace prast

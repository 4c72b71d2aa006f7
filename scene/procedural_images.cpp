// The procedural images of the built-in scene: a checker and the brick-tile
// albedo, normal and occlusion/roughness/metal maps; see procedural_images.h.
#include "scene/procedural_images.h"

#include <cmath>
#include <stdexcept>
#include <string>

namespace prast {

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

// Brick layout, in brick heights H = 1/8 of the texture: 4 bricks (2H wide)
// across, 8 rows, odd rows shifted by half a brick (running bond). Both counts
// divide the texture, so the pattern tiles under Repeat.
constexpr int kBrickCols = 4, kBrickRows = 8;
constexpr float kGroutHalf = 0.06f;  // half the grout joint, in H
constexpr float kBevel = 0.10f;      // width of the rounded brick edge, in H

enum class Zone { Grout, Bevel, Face };

struct BrickPoint {
    int cell = 0;  // the wrapped brick coordinates, col + row * kBrickCols (look_of)
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
    const int wcol = ((icol % kBrickCols) + kBrickCols) % kBrickCols;
    const int wrow = ((irow % kBrickRows) + kBrickRows) % kBrickRows;
    p.cell = wcol + wrow * kBrickCols;
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

// brick_look of every brick, computed once: the images ask for it at every
// sub-sample.
const BrickLook& look_of(const BrickPoint& p) {
    static const struct Looks {
        BrickLook look[kBrickCols * kBrickRows];
        Looks() {
            for (int r = 0; r < kBrickRows; ++r)
                for (int c = 0; c < kBrickCols; ++c) look[c + r * kBrickCols] = brick_look(hash3(c, r, 17U));
        }
    } looks;
    return looks.look[p.cell];
}

// value_noise's interpolation of lattice values at(i, j), i and j wrapped to
// [0, period).
template <class At> float lattice_noise(glm::vec2 uv, int period, At at) {
    const float x = uv.x * float(period), y = uv.y * float(period);
    const float fx = std::floor(x), fy = std::floor(y);
    const int ix = int(fx), iy = int(fy);
    auto wrap = [period](int i) { return ((i % period) + period) % period; };
    auto smooth = [](float t) { return t * t * (3.0f - 2.0f * t); };
    const float sx = smooth(x - fx), sy = smooth(y - fy);
    const int x0 = wrap(ix), x1 = wrap(ix + 1), y0 = wrap(iy), y1 = wrap(iy + 1);
    const float top = at(x0, y0) + (at(x1, y0) - at(x0, y0)) * sx;
    const float bottom = at(x0, y1) + (at(x1, y1) - at(x0, y1)) * sx;
    return top + (bottom - top) * sy;
}

float lattice_value_of(int x, int y, std::uint32_t seed, NoiseLattice lattice);

// value_noise(uv, Period, Seed) with the lattice's values held in a table.
template <int Period, std::uint32_t Seed> float table_noise(glm::vec2 uv) {
    static const struct Table {
        float v[Period * Period];
        Table() {
            for (int j = 0; j < Period; ++j)
                for (int i = 0; i < Period; ++i) v[i + j * Period] = lattice_value_of(i, j, Seed, NoiseLattice::Mixed);
        }
    } table;
    return lattice_noise(uv, Period, [](int i, int j) { return table.v[i + j * Period]; });
}

// Sub-sample (sx, sy) of texel (x, y), sx and sy in {0, 1}; inv = 1 / size.
glm::vec2 subsample_uv(int x, int y, int sx, int sy, float inv) {
    return glm::vec2((float(x) + 0.25f + 0.5f * float(sx)) * inv, (float(y) + 0.25f + 0.5f * float(sy)) * inv);
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
                for (int sx = 0; sx < 2; ++sx) sum += f(subsample_uv(x, y, sx, sy, inv));
            img.set(x, y, sum * 0.25f);
        }
    return img;
}

constexpr float kGroutAlbedo = 0.28f;

} // namespace

namespace {
float lattice_value_of(int x, int y, std::uint32_t seed, NoiseLattice lattice) {
    if (lattice == NoiseLattice::Linear)
        return unit_float(hash_u32(std::uint32_t(x) * 73856093U ^ std::uint32_t(y) * 19349663U ^ seed));
    return unit_float(hash3(x, y, seed));
}
} // namespace

float lattice_value(int x, int y, std::uint32_t seed, NoiseLattice lattice) {
    return lattice_value_of(x, y, seed, lattice);
}

float value_noise(glm::vec2 uv, int period, std::uint32_t seed, NoiseLattice lattice) {
    return lattice_noise(uv, period, [&](int i, int j) { return lattice_value_of(i, j, seed, lattice); });
}

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

namespace {

// The three maps' values at one sub-sample, given its brick.
glm::vec4 albedo_at(glm::vec2 uv, const BrickPoint& p) {
    if (p.zone == Zone::Grout) {
        const float grit = table_noise<128, 3U>(uv);
        return glm::vec4(glm::vec3(kGroutAlbedo * (0.8f + 0.4f * grit)), 1.0f);
    }
    const BrickLook& look = look_of(p);
    const float mottle = table_noise<32, 5U>(uv);
    // Edges slightly darker where the glaze runs thin.
    const float edge = p.zone == Zone::Bevel ? 0.85f + 0.15f * p.t : 1.0f;
    return glm::vec4(glm::min(look.albedo * ((0.92f + 0.16f * mottle) * edge), glm::vec3(1.0f)), 1.0f);
}

// The unit normal, before the sub-samples' mean is renormalised and encoded.
glm::vec4 normal_at(glm::vec2, const BrickPoint& p) {
    // Height gradient (dh/du, dh/dv), as a slope per unit distance.
    glm::vec2 grad(0.0f);
    switch (p.zone) {
    case Zone::Grout:  // concave groove: flat in the middle, rising to the brick
        grad = p.inward * (0.3f * p.t);
        break;
    case Zone::Bevel:  // rounded edge: steepest next to the grout, flat at the face
        grad = p.inward * (1.1f * (1.0f - p.t)) + look_of(p).tilt;
        break;
    case Zone::Face:
        grad = look_of(p).tilt;
        break;
    }
    // Tangent space: x along T = +u, y along B = -v (up the image), so
    // n = (-dh/du, +dh/dv, 1), normalised.
    return glm::vec4(glm::normalize(glm::vec3(-grad.x, grad.y, 1.0f)), 0.0f);
}

// Renormalises a mean of normal_at and encodes it as 0.5 n + 0.5.
glm::vec4 encode_normal(glm::vec4 mean) {
    const glm::vec3 n = glm::normalize(glm::vec3(mean));
    return glm::vec4(n * 0.5f + 0.5f, 1.0f);
}

glm::vec4 roughness_metal_at(glm::vec2 uv, const BrickPoint& p) {
    if (p.zone == Zone::Grout) {
        const float grit = table_noise<128, 3U>(uv);
        return glm::vec4(0.55f + 0.15f * p.t, 0.85f + 0.1f * grit, 0.0f, 1.0f);
    }
    const BrickLook& look = look_of(p);
    const float ao = p.zone == Zone::Bevel ? 0.85f + 0.15f * p.t : 1.0f;
    const float wear = table_noise<32, 9U>(uv);
    return glm::vec4(ao, look.roughness * (0.9f + 0.2f * wear), look.metallic, 1.0f);
}

} // namespace

Image make_tiles_albedo(int size) {
    check_size("make_tiles_albedo", size);
    return render_procedural(size, [](glm::vec2 uv) { return albedo_at(uv, brick_at(uv)); });
}

Image make_tiles_normal(int size) {
    check_size("make_tiles_normal", size);
    Image img = render_procedural(size, [](glm::vec2 uv) { return normal_at(uv, brick_at(uv)); });
    for (int y = 0; y < size; ++y)
        for (int x = 0; x < size; ++x) img.set(x, y, encode_normal(img.at(x, y)));
    return img;
}

Image make_tiles_roughness_metal(int size) {
    check_size("make_tiles_roughness_metal", size);
    return render_procedural(size, [](glm::vec2 uv) { return roughness_metal_at(uv, brick_at(uv)); });
}

TileMaps tile_maps_storage(int size) {
    check_size("tile_maps_storage", size);
    TileMaps m;
    for (Image* img : {&m.albedo, &m.normal, &m.roughness_metal}) {
        img->width = img->height = size;
        img->rgba.assign(std::size_t(size) * std::size_t(size) * 4, 0.0f);
    }
    return m;
}

void fill_tile_map_rows(TileMaps& maps, int y0, int y1) {
    const int size = maps.albedo.width;
    const float inv = 1.0f / float(size);
    for (int y = y0; y < y1; ++y)
        for (int x = 0; x < size; ++x) {
            // render_procedural's sub-samples and sums, in its order, for each map.
            glm::vec4 albedo(0.0f), normal(0.0f), rm(0.0f);
            for (int sy = 0; sy < 2; ++sy)
                for (int sx = 0; sx < 2; ++sx) {
                    const glm::vec2 uv = subsample_uv(x, y, sx, sy, inv);
                    const BrickPoint p = brick_at(uv);
                    albedo += albedo_at(uv, p);
                    normal += normal_at(uv, p);
                    rm += roughness_metal_at(uv, p);
                }
            maps.albedo.set(x, y, albedo * 0.25f);
            maps.normal.set(x, y, encode_normal(normal * 0.25f));
            maps.roughness_metal.set(x, y, rm * 0.25f);
        }
}

TileMaps make_tile_maps(int size) {
    TileMaps m = tile_maps_storage(size);
    fill_tile_map_rows(m, 0, size);
    return m;
}

} // namespace prast

// A light's shadow map and how a surface point reads it (docs/shadows-and-transparency.md). The map stores, per texel, the distance from the light to
// the nearest caster: along the light's direction from the map's near plane
// (directional lights, one orthographic map) or from the light's position
// (point lights, a cube of six 90-degree perspective faces). shadow_pass.h
// draws them; this file is the lookup, shared by the scalar shade_surface()
// and the block lighting (shadow_lanes.h), which perform the same float
// operations in the same order so both paths stay bit-identical.
//
// Lookup, per receiver point P with geometric normal N and direction l to
// the light, theta the angle between N and l, t the world size of a texel at
// P (constant for a directional map, proportional to the distance for a cube):
//   normal offset:   P' = P + N * t * kShadowNormalOffset * sin(theta)
//   slope bias:      bias = t * (kShadowConstantBias + kShadowSlopeBias * tan(theta))
//   PCF:             3x3 bilinear taps one texel apart, i.e. the 4x4 texels
//                    around P' with weights (1 - f, 1, 1, f) per axis, each
//                    lit when its distance >= distance(P') - bias.
// The visibility is the lit weight over the total: exactly 1 when every tap
// is lit, exactly 0 when none is.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include <glm/glm.hpp>

namespace prast {

// render --shadows / --shadow-size.
struct ShadowSettings {
    bool enabled = false;
    int size = 2048;  // texels a side of a directional map; cube faces get size / 2
};
constexpr int kMinShadowSize = 64;
constexpr int kMaxShadowSize = 8192;  // a 8192^2 map is 268 MB of distances

// Texels of padding (distance +inf, lit) around each face: the PCF footprint
// reaches two texels beyond the receiver's texel and never leaves the storage.
constexpr int kShadowPad = 2;
// Bias, in texels of the map at the receiver (see above). The PCF footprint
// reaches 2 texels from P' along each axis, 2 sqrt(2) diagonally, over which a
// plane at angle theta changes distance by up to 2 sqrt(2) t tan(theta): the
// slope factor 3 covers it, the constant 1 covers rasterisation and rounding.
constexpr float kShadowConstantBias = 1.0f;
constexpr float kShadowSlopeBias = 3.0f;
// tan(theta) is clamped to 5 (theta = 78.7 degrees), where n.l is already
// below 0.2: past it the bias would grow without bound and detach shadows.
constexpr float kShadowMinCos = 0.19611613f;  // 1 / sqrt(26)
constexpr float kShadowNormalOffset = 1.0f;

// The six faces of a point light's cube: the direction each looks along and
// its image's right and up axes (right = cross(forward, up), as lookAt has it).
struct ShadowCubeFace {
    glm::vec3 forward, right, up;
};
inline const ShadowCubeFace& shadow_cube_face(int face) {
    static const ShadowCubeFace kFaces[6] = {
        {{1, 0, 0}, {0, 0, 1}, {0, 1, 0}},   {{-1, 0, 0}, {0, 0, -1}, {0, 1, 0}},
        {{0, 1, 0}, {-1, 0, 0}, {0, 0, -1}}, {{0, -1, 0}, {-1, 0, 0}, {0, 0, 1}},
        {{0, 0, 1}, {-1, 0, 0}, {0, 1, 0}},  {{0, 0, -1}, {1, 0, 0}, {0, 1, 0}},
    };
    return kFaces[face];
}

struct ShadowMap {
    bool cube = false;
    int size = 0;      // texels per side of the map (of each cube face)
    int stride = 0;    // size + 2 kShadowPad: floats per stored row
    // Distances, face after face, row 0 at the top (the rasterizer's rows),
    // padded; +inf where no caster was drawn.
    std::vector<float> distance;
    // Summaries for the block lookup (shadow_lanes.h): cell (ci, cj) of a
    // face holds the least and greatest distance of texels [2 ci, 2 ci + 5] x
    // [2 cj, 2 cj + 5] (clipped to the face), which hold the PCF footprint of
    // every tap whose base texel is in [2 ci, 2 ci + 1] x [2 cj, 2 cj + 1]. A
    // tap is all lit when its threshold <= cell_min, all in shadow when
    // cell_max < threshold: 1 and 0 exactly, what the PCF gives, so lanes are
    // read in full only in penumbrae.
    int cells = 0;  // per side of a face: (stride + 1) / 2
    std::vector<float> cell_min, cell_max;

    // Directional: texel coordinates (u, v) = (dot(Q, axis_u) + offset_u,
    // dot(Q, axis_v) + offset_v) and distance distance0 - dot(Q, toward_light)
    // for Q = P' - origin. The offsets are whole numbers: the texel grid stays
    // fixed in the world from frame to frame (texel snapping).
    glm::vec3 origin{0.0f};
    glm::vec3 axis_u{0.0f}, axis_v{0.0f};  // world axes scaled to texels
    float offset_u = 0.0f, offset_v = 0.0f;
    glm::vec3 toward_light{0.0f, 1.0f, 0.0f};
    float distance0 = 0.0f;
    float texel = 0.0f;        // world size of one texel

    // Cube: each face spans tangents [-extent, extent] (extent a little over
    // 1, so the PCF footprint of a point near a face's edge stays on it).
    glm::vec3 position{0.0f};
    float extent = 1.0f;
    float texel_angle = 0.0f;  // 2 extent / size: a texel's size per unit distance

    float at(int face, int i, int j) const {  // texel (i, j) of a face, i, j in [-pad, size + pad)
        return distance[std::size_t(face) * std::size_t(stride) * std::size_t(stride) +
                        std::size_t(j + kShadowPad) * std::size_t(stride) + std::size_t(i + kShadowPad)];
    }
};

// Where one receiver reads the map: the top-left texel of its 4x4 footprint
// (an index into distance), the bilinear fractions and the distance a texel
// must reach to be lit.
struct ShadowTap {
    std::int32_t base = 0;
    std::int32_t cell = 0;  // its summary cell
    float fx = 0.0f, fy = 0.0f;
    float threshold = 0.0f;
    // For explanations (the stepper): the receiver's texel coordinates, face,
    // distance and bias.
    float u = 0.0f, v = 0.0f, receiver = 0.0f, bias = 0.0f;
    int face = 0;
    bool inside = false;
};

// The tap of receiver P (normal N, unit, facing the viewer) in a cube map
// (Cube) or a directional map (the light towards l). Branch-free on the
// values (selects), so a loop over lanes calling it vectorises.
template <bool Cube>
[[gnu::always_inline]] inline ShadowTap shadow_tap(const ShadowMap& map, float Px, float Py, float Pz, float Nx,
                                                   float Ny, float Nz, float lx, float ly, float lz) {
    ShadowTap t;
    // Direction to the light; for a point light, the receiver's distance sets
    // the texel size.
    float r = 0.0f;
    if constexpr (Cube) {
        const float dx = map.position.x - Px, dy = map.position.y - Py, dz = map.position.z - Pz;
        const float d2 = dx * dx + dy * dy + dz * dz;
        const bool ok = d2 > 1e-12f;
        r = std::sqrt(ok ? d2 : 1.0f);
        lx = ok ? dx / r : 0.0f;
        ly = ok ? dy / r : 0.0f;
        lz = ok ? dz / r : 1.0f;
    }
    const float texel = Cube ? map.texel_angle * r : map.texel;
    // Slope: theta between the geometric normal and l, tan clamped.
    float c = Nx * lx + Ny * ly + Nz * lz;
    c = c > kShadowMinCos ? c : kShadowMinCos;
    c = c < 1.0f ? c : 1.0f;
    const float s = std::sqrt(1.0f - c * c);
    const float offset = texel * kShadowNormalOffset * s;
    t.bias = texel * (kShadowConstantBias + kShadowSlopeBias * (s / c));
    // The offset point, its texel coordinates and distance.
    const float qx = Px + Nx * offset, qy = Py + Ny * offset, qz = Pz + Nz * offset;
    const float n = float(map.size);
    float u, v, dist;
    int face = 0;
    if constexpr (!Cube) {
        const float ox = qx - map.origin.x, oy = qy - map.origin.y, oz = qz - map.origin.z;
        u = ox * map.axis_u.x + oy * map.axis_u.y + oz * map.axis_u.z + map.offset_u;
        v = ox * map.axis_v.x + oy * map.axis_v.y + oz * map.axis_v.z + map.offset_v;
        dist = map.distance0 - (ox * map.toward_light.x + oy * map.toward_light.y + oz * map.toward_light.z);
    } else {
        // The face of the major axis (x before y before z on ties), its
        // tangents a (right) and b (up): shadow_cube_face() written out.
        const float ox = qx - map.position.x, oy = qy - map.position.y, oz = qz - map.position.z;
        const float ax = std::fabs(ox), ay = std::fabs(oy), az = std::fabs(oz);
        // (Written with few selects: the vectoriser gives up on deep ones.)
        const bool xm = (ax >= ay) & (ax >= az);
        const bool ym = !xm & (ay >= az);
        const float major = xm ? ax : (ym ? ay : az);
        const float along = xm ? ox : (ym ? oy : oz);
        const float sgn = along >= 0.0f ? 1.0f : -1.0f;
        face = 2 * (int(!xm) + int(!xm & !ym)) + int(along < 0.0f);
        const float ra = xm ? sgn * oz : (ym ? -ox : -sgn * ox);
        const float ub = ym ? -sgn * oz : oy;
        const float a = ra / major, b = ub / major;
        u = (a / map.extent + 1.0f) * 0.5f * n;
        v = (1.0f - b / map.extent) * 0.5f * n;
        dist = std::sqrt(ox * ox + oy * oy + oz * oz);
    }
    // Outside the map (or not a number): lit, read from texel (0, 0).
    t.inside = (u >= 0.0f) & (u <= n) & (v >= 0.0f) & (v <= n);
    t.u = u;
    t.v = v;
    t.receiver = dist;
    t.face = face;
    t.threshold = t.inside ? dist - t.bias : -std::numeric_limits<float>::infinity();
    const float su = t.inside ? u - 0.5f : 0.0f, sv = t.inside ? v - 0.5f : 0.0f;
    const float iu = std::floor(su), iv = std::floor(sv);
    t.fx = su - iu;
    t.fy = sv - iv;
    // Footprint texels iu - 1 .. iu + 2, all inside the padding.
    const std::int32_t bi = std::int32_t(iu) - 1 + kShadowPad, bj = std::int32_t(iv) - 1 + kShadowPad;
    t.base = std::int32_t(face) * map.stride * map.stride + bj * map.stride + bi;
    t.cell = std::int32_t(face) * map.cells * map.cells + (bj >> 1) * map.cells + (bi >> 1);
    return t;
}

inline ShadowTap shadow_tap(const ShadowMap& map, float Px, float Py, float Pz, float Nx, float Ny, float Nz,
                           float lx, float ly, float lz) {
    return map.cube ? shadow_tap<true>(map, Px, Py, Pz, Nx, Ny, Nz, lx, ly, lz)
                    : shadow_tap<false>(map, Px, Py, Pz, Nx, Ny, Nz, lx, ly, lz);
}

// The PCF of one tap: 4x4 texels, weights (1 - fx, 1, 1, fx) x (1 - fy, 1, 1, fy),
// rows summed left to right, then top to bottom; the lit weight over the total.
inline float shadow_pcf(const ShadowMap& map, const ShadowTap& t) {
    const float wx[4] = {1.0f - t.fx, 1.0f, 1.0f, t.fx};
    const float wy[4] = {1.0f - t.fy, 1.0f, 1.0f, t.fy};
    const float* d = map.distance.data() + t.base;
    const float sx = ((wx[0] + wx[1]) + wx[2]) + wx[3];
    float lit = 0.0f, total = 0.0f;
    for (int j = 0; j < 4; ++j) {
        const float* row = d + j * map.stride;
        float rs = 0.0f;
        for (int i = 0; i < 4; ++i) rs = rs + (row[i] >= t.threshold ? wx[i] : 0.0f);
        lit = lit + wy[j] * rs;
        total = total + wy[j] * sx;
    }
    return lit / total;
}

// What the stepper shows for one light: the tap, the nearest texel's stored
// distance and the visibility (1 lit, 0 in shadow).
struct ShadowProbe {
    ShadowTap tap;
    float map_distance = std::numeric_limits<float>::infinity();
    float visibility = 1.0f;
};

inline ShadowProbe shadow_probe(const ShadowMap& map, const glm::vec3& P, const glm::vec3& N, const glm::vec3& l) {
    ShadowProbe p;
    p.tap = shadow_tap(map, P.x, P.y, P.z, N.x, N.y, N.z, l.x, l.y, l.z);
    p.visibility = shadow_pcf(map, p.tap);
    if (p.tap.inside) {
        const int i = std::min(map.size - 1, int(p.tap.u)), j = std::min(map.size - 1, int(p.tap.v));
        p.map_distance = map.at(p.tap.face, i, j);
    }
    return p;
}

} // namespace prast

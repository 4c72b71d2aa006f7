// The equirectangular (latitude-longitude) mapping of docs/conventions.md
// "Environment maps": a world direction d = (x, y, z) maps to
// u = 0.5 + atan2(x, -z) / (2 pi), v = acos(y) / pi (row 0 looks up +Y, the
// centre column looks down -Z, u grows towards +X), and bilinear filtering of
// one level of such a map (u wraps, v clamps).
//
// Everything here is branch-free float code shared by the scalar shading path
// and the lane loops of light_block.h, so the two give the same bits: atan2 is
// a polynomial (Cephes' atanf, relative error about 1e-7, i.e. 1e-6 texel of a
// 4k map) instead of std::atan2, which a lane loop could not vectorise, and
// acos(y) is written atan2(sqrt(x^2 + z^2), y), exact for unit d and well
// conditioned near the poles.
#pragma once

#include <cmath>
#include <cstdint>
#include <cstring>

#include <glm/glm.hpp>

#include "scene/det_math.h"

namespace prast {

namespace equirect_detail {

// atan(a) for a in [0, 1]: above tan(pi/8), atan(a) = pi/4 + atan((a - 1) / (a + 1)),
// then Cephes' odd polynomial on [-tan(pi/8), tan(pi/8)].
[[gnu::always_inline]] inline float atan01(float a) {
    const bool big = a > 0.41421356f;
    const float x = big ? (a - 1.0f) / (a + 1.0f) : a;
    const float z = x * x;
    const float p = (((8.05374449538e-2f * z - 1.38776856032e-1f) * z + 1.99777106478e-1f) * z -
                     3.33329491539e-1f) * z * x + x;
    return big ? p + 0.785398163f : p;
}

} // namespace equirect_detail

// atan2(y, x) in (-pi, pi], branch-free; 0 for x = y = 0.
[[gnu::always_inline]] inline float atan2_poly(float y, float x) {
    const float ax = std::fabs(x), ay = std::fabs(y);
    const bool steep = ay > ax;
    const float hi = steep ? ay : ax, lo = steep ? ax : ay;
    const float a = lo / (hi > 0.0f ? hi : 1.0f);
    float r = equirect_detail::atan01(a);
    r = steep ? 1.57079633f - r : r;
    r = x < 0.0f ? 3.14159265f - r : r;
    return y < 0.0f ? -r : r;
}

// u, v of direction (x, y, z) (need not be unit). NaN directions give NaN;
// equirect_taps() folds them to 0.
[[gnu::always_inline]] inline void equirect_uv(float x, float y, float z, float& u, float& v) {
    constexpr float kInv2Pi = 0.159154943f, kInvPi = 0.318309886f;
    u = 0.5f + atan2_poly(x, -z) * kInv2Pi;
    v = atan2_poly(std::sqrt(x * x + z * z), y) * kInvPi;
}

// The unit direction at (u, v): the inverse of equirect_uv (precomputation only).
inline glm::dvec3 equirect_direction(double u, double v) {
    const double phi = (u - 0.5) * 2.0 * M_PI, theta = v * M_PI;
    const double s = det::sin(theta);
    return {s * det::sin(phi), det::cos(theta), -s * det::cos(phi)};
}

// One level of an equirectangular map inside a texel array: w x h texels,
// row-major from `offset`.
struct EquirectLevel {
    std::int32_t w = 0, h = 0, offset = 0;
    float fw = 0.0f, fh = 0.0f;
};

// A texel: linear RGB radiance and one unused channel, so one texel is one
// 16-byte vector load.
typedef float Texel4 __attribute__((vector_size(16)));

// The four texels and weights of a bilinear lookup at (u, v) of a level of
// w x h texels starting at `offset`: texel centres at (i + 0.5) / size, u
// wrapping around, v clamped to the first and last row. A u or v outside
// [0, 1] (only NaN reaches here) reads at 0.
[[gnu::always_inline]] inline void equirect_taps(float u, float v, std::int32_t w, std::int32_t h,
                                                 std::int32_t offset, float fw, float fh, std::int32_t* idx,
                                                 float& tx, float& ty) {
    u = u >= 0.0f && u <= 1.0f ? u : 0.0f;
    v = v >= 0.0f && v <= 1.0f ? v : 0.0f;
    const float x = u * fw - 0.5f, y = v * fh - 0.5f;
    const float fx = std::floor(x), fy = std::floor(y);
    tx = x - fx;
    ty = y - fy;
    const std::int32_t x0 = std::int32_t(fx), y0 = std::int32_t(fy);  // in [-1, w - 1], [-1, h - 1]
    const std::int32_t xa = x0 < 0 ? x0 + w : x0, xb = x0 + 1 >= w ? x0 + 1 - w : x0 + 1;
    const std::int32_t ya = y0 < 0 ? 0 : y0, yb = y0 + 1 >= h ? h - 1 : y0 + 1;
    idx[0] = offset + ya * w + xa;
    idx[1] = offset + ya * w + xb;
    idx[2] = offset + yb * w + xa;
    idx[3] = offset + yb * w + xb;
}

inline Texel4 load_texel4(const glm::vec4* texels, std::int32_t i) {
    Texel4 t;
    std::memcpy(&t, &texels[i], sizeof t);
    return t;
}

// a + (b - a) t per channel, blended across x then y: exact where the texels
// are equal (a constant map filters to exactly its value).
inline Texel4 bilinear4(const glm::vec4* texels, const std::int32_t* idx, float tx, float ty) {
    const Texel4 a = load_texel4(texels, idx[0]), b = load_texel4(texels, idx[1]);
    const Texel4 c = load_texel4(texels, idx[2]), d = load_texel4(texels, idx[3]);
    const Texel4 top = a + (b - a) * tx;
    const Texel4 bottom = c + (d - c) * tx;
    return top + (bottom - top) * ty;
}

inline glm::vec3 bilinear_rgb(const glm::vec4* texels, const EquirectLevel& L, float u, float v) {
    std::int32_t idx[4];
    float tx, ty;
    equirect_taps(u, v, L.w, L.h, L.offset, L.fw, L.fh, idx, tx, ty);
    const Texel4 c = bilinear4(texels, idx, tx, ty);
    return {c[0], c[1], c[2]};
}

} // namespace prast

// Diffuse irradiance from spherical harmonics to order 2 (9 coefficients per
// channel; Ramamoorthi & Hanrahan 2001): the map's radiance is projected on the
// real SH basis, and the clamped-cosine convolution scales band l by
// A_0 = pi, A_1 = 2 pi / 3, A_2 = pi / 4. What is stored is E(n) / pi, the
// "irradiance as a radiance", already folded into the coefficients of nine
// polynomials in the world direction (1, y, z, x, xy, yz, 3z^2 - 1, xz,
// x^2 - y^2), so a lane evaluates it with multiplies and adds only.
//
// Accuracy: the cosine kernel's odd bands above 1 vanish, so order 2 misses
// only the even bands l >= 4, where A_l is at most 2.4% of A_0 and falls as
// l^-2.5: a sky that steps from 1 to 0 at the horizon (odd apart from its mean)
// gives exactly (1 + n.y) / 2, while a small bright source is smeared (its
// lobe's tail can go negative, which eval clamps to 0). test_ibl.cpp holds
// both to numbers.
#pragma once

#include <glm/glm.hpp>

#include "raster/thread_pool.h"
#include "shading/ibl/equirect.h"

namespace prast {

struct ShIrradiance {
    // c[i][channel]: E(n) / pi = sum_i c[i] * P_i(n).
    float c[9][3] = {};
};

// Projects one level of an equirect map (map-space texels) onto the SH basis
// of world space, with the map turned about +Y by the angle whose cosine and
// sine are given (world = R_y(angle) map). One task per row, each row's sums
// in double, the rows added in order: the same bytes for any thread count.
ShIrradiance project_sh_irradiance(const glm::vec4* texels, const EquirectLevel& level, float rot_cos,
                                   float rot_sin, ThreadPool& pool);

// E(n) / pi for one channel, n a unit world direction; shared by the scalar and
// the lane code (same operations, same order). Not clamped.
[[gnu::always_inline]] inline float sh_irradiance_eval(const float* c, float x, float y, float z) {
    return c[0] + c[3] * y + c[6] * z + c[9] * x + c[12] * (x * y) + c[15] * (y * z) +
           c[18] * (3.0f * z * z - 1.0f) + c[21] * (x * z) + c[24] * (x * x - y * y);
}

// E(n) / pi, clamped to >= 0.
inline glm::vec3 sh_irradiance(const ShIrradiance& sh, const glm::vec3& n) {
    glm::vec3 e;
    for (int ch = 0; ch < 3; ++ch) {
        const float v = sh_irradiance_eval(&sh.c[0][ch], n.x, n.y, n.z);
        e[ch] = v > 0.0f ? v : 0.0f;
    }
    return e;
}

} // namespace prast

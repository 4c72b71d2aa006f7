// Spherical-harmonic projection of an equirect map; see sh_irradiance.h.
#include "shading/ibl/sh_irradiance.h"

#include <cmath>
#include <vector>

#include "scene/det_math.h"

namespace prast {

ShIrradiance project_sh_irradiance(const glm::vec4* texels, const EquirectLevel& level, float rot_cos,
                                   float rot_sin, ThreadPool& pool) {
    const int W = level.w, H = level.h;
    std::vector<double> rows(std::size_t(H) * 27, 0.0);
    pool.run(H, [&](int y, int) {
        double* acc = &rows[std::size_t(y) * 27];
        // Texel solid angle: (2 pi / W) (cos theta_top - cos theta_bottom), exact for the row.
        const double t0 = M_PI * y / H, t1 = M_PI * (y + 1) / H;
        const double d_omega = 2.0 * M_PI / W * (det::cos(t0) - det::cos(t1));
        for (int x = 0; x < W; ++x) {
            const glm::dvec3 m = equirect_direction((x + 0.5) / W, (y + 0.5) / H);
            // World direction of the texel: R_y(angle) applied to the map direction.
            const double dx = m.x * rot_cos + m.z * rot_sin, dy = m.y, dz = -m.x * rot_sin + m.z * rot_cos;
            const double basis[9] = {1.0, dy, dz, dx, dx * dy, dy * dz, 3.0 * dz * dz - 1.0, dx * dz,
                                     dx * dx - dy * dy};
            const glm::vec4& L = texels[std::size_t(level.offset) + std::size_t(y) * W + std::size_t(x)];
            for (int i = 0; i < 9; ++i)
                for (int ch = 0; ch < 3; ++ch) acc[i * 3 + ch] += double(L[ch]) * basis[i] * d_omega;
        }
    });
    // L_lm = K_lm * (integral of L * P_i); E / pi = sum (A_l / pi) K_lm^2 (integral) P_i(n).
    const double K0 = 0.5 * std::sqrt(1.0 / M_PI), K1 = std::sqrt(3.0 / (4.0 * M_PI));
    const double K2 = 0.5 * std::sqrt(15.0 / M_PI), K6 = 0.25 * std::sqrt(5.0 / M_PI);
    const double K8 = 0.25 * std::sqrt(15.0 / M_PI);
    const double A0 = 1.0, A1 = 2.0 / 3.0, A2 = 0.25;  // A_l / pi
    const double scale[9] = {A0 * K0 * K0, A1 * K1 * K1, A1 * K1 * K1, A1 * K1 * K1, A2 * K2 * K2,
                             A2 * K2 * K2, A2 * K6 * K6, A2 * K2 * K2, A2 * K8 * K8};
    ShIrradiance sh;
    for (int i = 0; i < 9; ++i)
        for (int ch = 0; ch < 3; ++ch) {
            double sum = 0.0;
            for (int y = 0; y < H; ++y) sum += rows[std::size_t(y) * 27 + std::size_t(i) * 3 + std::size_t(ch)];
            sh.c[i][ch] = float(sum * scale[i]);
        }
    return sh;
}

} // namespace prast

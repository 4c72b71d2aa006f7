// The background pass; see background.h.
#include "shading/background.h"

#include <algorithm>
#include <cmath>

namespace prast {

void draw_background(Framebuffer& fb, const Camera& cam, const Environment* env, Background mode,
                     const glm::vec3& color, ThreadPool& pool) {
    if (mode == Background::Black) return;  // the clear colour already
    if (mode != Background::Color && !env) return;
    // The camera's basis, as glm::lookAt builds it, and the half extents of
    // the image plane at distance 1.
    const glm::vec3 f = glm::normalize(cam.target - cam.eye);
    const glm::vec3 s = glm::normalize(glm::cross(f, cam.up));
    const glm::vec3 u_ = glm::cross(s, f);
    const float half_h = std::tan(glm::radians(cam.fov_y_deg) * 0.5f);
    const float half_w = half_h * float(fb.width) / float(fb.height);
    const float lod = Environment::roughness_lod(kBlurBackgroundRoughness);
    EquirectLevel level;
    if (env) level = env->source_level(0);
    pool.run(fb.height, [&](int y, int) {
        const float ndc_y = 1.0f - (float(y) + 0.5f) / float(fb.height) * 2.0f;
        const float* depth = &fb.depth[std::size_t(y) * std::size_t(fb.width)];
        if (mode == Background::Color) {
            for (int x = 0; x < fb.width; ++x) {
                if (depth[x] < 1.0f) continue;
                float* p = fb.pixel(x, y);
                p[0] = color.r; p[1] = color.g; p[2] = color.b;
            }
            return;
        }
        // Sixteen pixels at a time: directions and map coordinates in a loop
        // the compiler vectorises, then the texel reads pixel by pixel.
        constexpr int L = 16;
        alignas(64) float u[L], v[L];
        for (int x0 = 0; x0 < fb.width; x0 += L) {
            for (int l = 0; l < L; ++l) {
                const float ndc_x = (float(x0 + l) + 0.5f) / float(fb.width) * 2.0f - 1.0f;
                const float dx = f.x + s.x * (ndc_x * half_w) + u_.x * (ndc_y * half_h);
                const float dy = f.y + s.y * (ndc_x * half_w) + u_.y * (ndc_y * half_h);
                const float dz = f.z + s.z * (ndc_x * half_w) + u_.z * (ndc_y * half_h);
                float mx, mz;
                env->to_map(dx, dz, mx, mz);
                equirect_uv(mx, dy, mz, u[l], v[l]);
            }
            const int n = std::min(L, fb.width - x0);
            for (int l = 0; l < n; ++l) {
                if (depth[x0 + l] < 1.0f) continue;
                glm::vec3 c;
                if (mode == Background::Env) {
                    c = bilinear_rgb(env->texels(), level, u[l], v[l]);
                } else {
                    const float ndc_x = (float(x0 + l) + 0.5f) / float(fb.width) * 2.0f - 1.0f;
                    c = env->prefiltered(f + s * (ndc_x * half_w) + u_ * (ndc_y * half_h), lod);
                }
                float* p = fb.pixel(x0 + l, y);
                p[0] = c.r; p[1] = c.g; p[2] = c.b;
            }
        }
    });
}

} // namespace prast

// The background pass; see background.h.
#include "shading/background.h"

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
    const glm::vec3 u = glm::cross(s, f);
    const float half_h = std::tan(glm::radians(cam.fov_y_deg) * 0.5f);
    const float half_w = half_h * float(fb.width) / float(fb.height);
    const float lod = Environment::roughness_lod(kBlurBackgroundRoughness);
    pool.run(fb.height, [&](int y, int) {
        const float ndc_y = 1.0f - (float(y) + 0.5f) / float(fb.height) * 2.0f;
        for (int x = 0; x < fb.width; ++x) {
            if (fb.depth[std::size_t(y) * std::size_t(fb.width) + std::size_t(x)] < 1.0f) continue;
            glm::vec3 c = color;
            if (mode != Background::Color) {
                const float ndc_x = (float(x) + 0.5f) / float(fb.width) * 2.0f - 1.0f;
                const glm::vec3 dir = f + s * (ndc_x * half_w) + u * (ndc_y * half_h);
                c = mode == Background::Env ? env->radiance(dir) : env->prefiltered(dir, lod);
            }
            float* p = fb.pixel(x, y);
            p[0] = c.r; p[1] = c.g; p[2] = c.b;
        }
    });
}

} // namespace prast

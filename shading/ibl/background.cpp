// The background a frame clears to; see background.h.
#include "shading/ibl/background.h"

#include <algorithm>
#include <cmath>

#include "scene/det_math.h"

namespace prast {

BackgroundFill::BackgroundFill(const Camera& cam, int width, int height, const Environment* env, Background mode,
                               const glm::vec3& color)
    : mode_(mode), color_(color), env_(env), width_(width), height_(height) {
    if (mode_ != Background::Color && !env_) mode_ = Background::Black;
    f_ = glm::normalize(cam.target - cam.eye);
    s_ = glm::normalize(glm::cross(f_, cam.up));
    u_ = glm::cross(s_, f_);
    half_h_ = det::tan(glm::radians(cam.fov_y_deg) * 0.5f);
    half_w_ = half_h_ * float(width) / float(height);
    lod_ = Environment::roughness_lod(kBlurBackgroundRoughness);
    if (env_) level_ = env_->source_level(0);
}

glm::vec3 BackgroundFill::at(int x, int y) const {
    float rgba[4];
    fill(x, y, 1, 1, rgba, 4);
    return {rgba[0], rgba[1], rgba[2]};
}

void BackgroundFill::fill(int x0, int y0, int w, int h, float* rgba, std::size_t row) const {
    for (int j = 0; j < h; ++j) {
        float* out = rgba + std::size_t(j) * row;
        if (mode_ == Background::Black || mode_ == Background::Color) {
            const glm::vec3 c = mode_ == Background::Color ? color_ : glm::vec3(0.0f);
            for (int i = 0; i < w; ++i) {
                out[4 * i] = c.r; out[4 * i + 1] = c.g; out[4 * i + 2] = c.b; out[4 * i + 3] = 1.0f;
            }
            continue;
        }
        const float ndc_y = 1.0f - (float(y0 + j) + 0.5f) / float(height_) * 2.0f;
        // Sixteen pixels at a time: directions and map coordinates in a loop
        // the compiler vectorises, then the texel reads pixel by pixel.
        constexpr int L = 16;
        alignas(64) float u[L], v[L];
        for (int i0 = 0; i0 < w; i0 += L) {
            for (int l = 0; l < L; ++l) {
                const float ndc_x = (float(x0 + i0 + l) + 0.5f) / float(width_) * 2.0f - 1.0f;
                const float dx = f_.x + s_.x * (ndc_x * half_w_) + u_.x * (ndc_y * half_h_);
                const float dy = f_.y + s_.y * (ndc_x * half_w_) + u_.y * (ndc_y * half_h_);
                const float dz = f_.z + s_.z * (ndc_x * half_w_) + u_.z * (ndc_y * half_h_);
                float mx, mz;
                env_->to_map(dx, dz, mx, mz);
                equirect_uv(mx, dy, mz, u[l], v[l]);
            }
            const int n = std::min(L, w - i0);
            for (int l = 0; l < n; ++l) {
                glm::vec3 c;
                if (mode_ == Background::Env) {
                    c = bilinear_rgb(env_->texels(), level_, u[l], v[l]);
                } else {
                    const float ndc_x = (float(x0 + i0 + l) + 0.5f) / float(width_) * 2.0f - 1.0f;
                    c = env_->prefiltered(f_ + s_ * (ndc_x * half_w_) + u_ * (ndc_y * half_h_), lod_);
                }
                float* p = out + 4 * (i0 + l);
                p[0] = c.r; p[1] = c.g; p[2] = c.b; p[3] = 1.0f;
            }
        }
    }
}

void BackgroundFill::attach(FrameOptions& frame) const {
    if (black()) return;
    frame.clear_fill = [](const void* user, int x0, int y0, int w, int h, float* rgba, std::size_t row) {
        static_cast<const BackgroundFill*>(user)->fill(x0, y0, w, h, rgba, row);
    };
    frame.clear_user = this;
}

} // namespace prast

// Camera matrices and framing; see camera.h.
#include "scene/camera.h"

#include <algorithm>
#include <cmath>

#include <glm/gtc/matrix_transform.hpp>

namespace prast {

glm::mat4 Camera::view() const { return glm::lookAt(eye, target, up); }

glm::mat4 Camera::projection(float aspect) const {
    if (orthographic) {
        const float x = ortho_ymag * aspect;
        return glm::ortho(-x, x, -ortho_ymag, ortho_ymag, near_plane, far_plane);
    }
    if (infinite_far) return glm::infinitePerspective(glm::radians(fov_y_deg), aspect, near_plane);
    return glm::perspective(glm::radians(fov_y_deg), aspect, near_plane, far_plane);
}

void fit_clip_planes(Camera& cam, const Bounds& b) {
    float r = std::max(b.radius(), 1e-4f);
    float d = glm::length(cam.eye - b.center());
    // Far encloses the sphere; near stays a sane fraction of it so depth keeps
    // its precision when the eye is inside the bounds.
    cam.far_plane = d + r * 1.05f;
    cam.near_plane = std::max(d - r * 1.05f, cam.far_plane * 1e-4f);
}

Camera frame_bounds(const Bounds& b, float fov_y_deg, float aspect) {
    Camera cam;
    cam.fov_y_deg = fov_y_deg;
    float r = std::max(b.radius(), 1e-4f);
    // The tighter of the vertical and horizontal half-angles must hold the sphere.
    float half_v = glm::radians(fov_y_deg) * 0.5f;
    float half_h = std::atan(std::tan(half_v) * aspect);
    float half = std::min(half_v, half_h);
    float dist = r / std::sin(half) * 1.02f;
    glm::vec3 dir = glm::normalize(glm::vec3(0.0f, 0.35f, 1.0f));
    cam.target = b.center();
    cam.eye = cam.target + dir * dist;
    fit_clip_planes(cam, b);
    return cam;
}

} // namespace prast

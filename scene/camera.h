// A perspective camera (docs/conventions.md: right-handed, +Y up, looking down -Z in
// view space, OpenGL clip space) and its default framing on a scene's bounds.
#pragma once

#include <glm/glm.hpp>

#include "scene/scene.h"

namespace prast {

struct Camera {
    glm::vec3 eye{0.0f, 0.0f, 3.0f};
    glm::vec3 target{0.0f};
    glm::vec3 up{0.0f, 1.0f, 0.0f};
    float fov_y_deg = 45.0f;
    float near_plane = 0.1f;
    float far_plane = 100.0f;
    // A file's camera may be orthographic (half height ortho_ymag, the width
    // from the aspect) or perspective without a far plane.
    bool orthographic = false;
    float ortho_ymag = 1.0f;
    bool infinite_far = false;

    glm::mat4 view() const;
    glm::mat4 projection(float aspect) const;
    glm::mat4 view_projection(float aspect) const { return projection(aspect) * view(); }
};

// Looks at the bounds' centre from the +Z side, slightly above, far enough for
// the bounding sphere to fit the vertical field of view.
Camera frame_bounds(const Bounds& b, float fov_y_deg, float aspect);

// Near/far planes that enclose the bounding sphere as seen from the eye.
void fit_clip_planes(Camera& cam, const Bounds& b);

} // namespace prast

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

// The default view of a file's scene: from the same direction as
// frame_bounds, placed so that the projection of every vertex fills the
// tighter axis of the frame less a margin (kFrameFill of it), centred on the
// frame. With orbit_deg > 0 the distance also keeps every vertex inside the
// frame when the eye turns that far around the target (render's turntable).
// Falls back to frame_bounds when the vertices span no area in view.
constexpr double kFrameFill = 0.9;
Camera frame_scene(const Scene& scene, float fov_y_deg, float aspect, double orbit_deg = 0.0);

// Near/far planes that enclose the bounding sphere as seen from the eye.
void fit_clip_planes(Camera& cam, const Bounds& b);

} // namespace prast

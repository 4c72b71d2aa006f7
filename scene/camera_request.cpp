#include "scene/camera_request.h"

#include <cmath>
#include <cstdio>

#include "scene/det_math.h"

namespace prast {

namespace {

bool fits(const glm::dvec3& v) {
    return std::fabs(v.x) <= kMaxCameraCoordinate && std::fabs(v.y) <= kMaxCameraCoordinate &&
           std::fabs(v.z) <= kMaxCameraCoordinate;
}

std::string vec_text(const glm::dvec3& v) {
    char buf[96];
    std::snprintf(buf, sizeof buf, "%g,%g,%g", v.x, v.y, v.z);
    return buf;
}

CameraFault fault(CameraFault::Kind kind, std::string message) { return {kind, std::move(message)}; }

// Every coordinate within kMaxCameraCoordinate, eye and target apart, up not
// along the view. Blames the flag that is wrong, or the scene's bounds when
// the framing came from them.
CameraFault check_camera(const Camera& cam, const CameraRequest& req, const Bounds& bounds, bool framed) {
    using K = CameraFault::Kind;
    const std::string scene = req.scene.empty() ? "the built-in scene" : req.scene;
    const glm::dvec3 lo(bounds.lo), hi(bounds.hi);
    const bool bounds_fit = bounds.empty() || (fits(lo) && fits(hi) && fits(hi - lo));
    const std::string bounds_text = bounds.empty() ? "empty" : "from " + vec_text(lo) + " to " + vec_text(hi);
    if (framed && (!req.eye || !req.target) && !bounds_fit)
        return fault(K::Scene, scene + ": cannot frame the scene: its bounds (" + bounds_text +
                                   ") reach beyond +-1e18, where single precision breaks down; give --eye and "
                                   "--target (and --near, --far)");
    if (framed && (!req.near_plane || !req.far_plane) && !bounds_fit)
        return fault(K::Scene, scene + ": cannot fit clip planes to the scene: its bounds (" + bounds_text +
                                   ") reach beyond +-1e18; give --near and --far");
    const glm::dvec3 eye(cam.eye), target(cam.target);
    if (!fits(eye) || !fits(target)) {
        // Framing put the eye too far: the field of view was too narrow for the scene.
        if (req.fov_deg < 45.0f)
            return fault(K::Flag, "--fov " + std::to_string(req.fov_deg) + ": framing the scene (bounds " +
                                      bounds_text + ") this narrowly puts the eye at " + vec_text(eye) +
                                      ", beyond +-1e18; give a wider --fov or --eye");
        return fault(K::Scene, scene + ": cannot frame the scene: its bounds (" + bounds_text +
                                   ") put the eye at " + vec_text(eye) + ", beyond +-1e18; give --eye and --target");
    }
    const glm::dvec3 view = target - eye;
    if (!(glm::length(view) > 0.0)) {
        if (req.eye && req.target) return fault(K::Flag, "--eye/--target: the eye and the target are the same point");
        if (req.eye)
            return fault(K::Flag, "--eye " + vec_text(eye) +
                                      ": the framed target (the scene's centre) is there too; give --target");
        if (req.target)
            return fault(K::Flag, "--target " + vec_text(target) + ": the framed eye is there too; give --eye");
        return fault(K::Scene, scene + ": cannot frame the scene: its bounds (" + bounds_text +
                                   ") are too small for their distance from the origin in single precision");
    }
    if (!(glm::length(glm::cross(glm::normalize(view), glm::dvec3(cam.up))) > 1e-4)) {
        if (req.up) return fault(K::Flag, "--up: parallel to the viewing direction (eye to target); give another --up");
        return fault(K::Flag, "--eye/--target: the view is vertical, along the default up 0,1,0; give --up");
    }
    return {};
}

// v rotated by `radians` around the unit axis k (Rodrigues), in double so the
// eye of frame i does not depend on which frames were rendered before it.
glm::vec3 rotate_around(const glm::vec3& v, const glm::vec3& k, double radians) {
    const glm::dvec3 dv(v), dk(k);
    const double c = det::cos(radians), s = det::sin(radians);
    return glm::vec3(dv * c + glm::cross(dk, dv) * s + dk * glm::dot(dk, dv) * (1.0 - c));
}

} // namespace

CameraFault request_camera(const CameraRequest& req, const Bounds& bounds, float aspect, const Scene* framed,
                           const Camera& own, Camera& out) {
    Camera camera = framed ? frame_scene(*framed, req.fov_deg, aspect, req.orbit_deg) : own;
    camera.fov_y_deg = req.fov_deg;
    if (req.eye) camera.eye = *req.eye;
    if (req.target) camera.target = *req.target;
    // Normalised in double: a float normalize of a huge --up overflows.
    if (req.up) camera.up = glm::vec3(glm::normalize(glm::dvec3(*req.up)));
    if (CameraFault f = check_camera(camera, req, bounds, framed != nullptr)) return f;
    out = camera;
    return {};
}

CameraFault orbit_camera(const CameraRequest& req, const Camera& base, const Bounds& bounds, double angle,
                         Camera& out) {
    Camera cam = base;
    cam.eye = base.target + rotate_around(base.eye - base.target, glm::normalize(base.up), angle);
    fit_clip_planes(cam, bounds);
    if (req.near_plane) cam.near_plane = *req.near_plane;
    if (req.far_plane) cam.far_plane = *req.far_plane;
    if (!(cam.near_plane < cam.far_plane))
        return fault(CameraFault::Flag, "--near/--far: near " + std::to_string(cam.near_plane) +
                                            " is not less than far " + std::to_string(cam.far_plane) +
                                            " (give both --near and --far)");
    out = cam;
    return {};
}

} // namespace prast

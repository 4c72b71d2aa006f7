// The camera a command line asks for (render, step, llvmpipe-render): the
// built-in scene's own camera or a framing of the scene's bounds, with the
// flags --eye, --target, --up, --fov, --near and --far overriding single
// fields, then checked so that the view matrix stays finite in single
// precision. Every tool that takes render's flags goes through here, so the
// same command line gives the same floats everywhere.
#pragma once

#include <optional>
#include <string>

#include <glm/glm.hpp>

#include "scene/camera.h"
#include "scene/scene.h"

namespace prast {

// Camera coordinates beyond this leave single precision no room: the view
// matrix squares distances (1e19 squared overflows a float).
constexpr double kMaxCameraCoordinate = 1e18;

struct CameraRequest {
    std::string scene;                       // the scene's path, for messages; "" for the built-in scene
    std::optional<glm::vec3> eye, target, up;
    float fov_deg = 45.0f;
    std::optional<float> near_plane, far_plane;
    double orbit_deg = 0.0;                  // a turntable's sweep, which the framing must hold over
};

// Why a camera cannot render: a flag is at fault (render's exit 2) or the
// scene's bounds are (exit 1).
struct CameraFault {
    enum Kind { None, Flag, Scene } kind = None;
    std::string message;                     // one line, without a program prefix
    explicit operator bool() const { return kind != None; }
};

// The turntable's base camera: `own` (the built-in scene's camera) when
// `framed` is null, else the framing of that scene (frame_scene, at the
// request's field of view and orbit); then the flags. `bounds` are the
// scene's. A fault names what is wrong.
CameraFault request_camera(const CameraRequest& request, const Bounds& bounds, float aspect, const Scene* framed,
                           const Camera& own, Camera& out);

// Frame `angle` (radians) of the turntable around the base camera's target
// and up, with clip planes fitted to the bounds unless --near/--far are given.
CameraFault orbit_camera(const CameraRequest& request, const Camera& base, const Bounds& bounds, double angle,
                         Camera& out);

} // namespace prast

// One frame set-up for every tool that takes render's command line (render,
// step, bench, llvmpipe-render): a FrameRequest (what the flags say) becomes
// a ready frame, in this order: the scene loaded or the built-in one built,
// the camera the flags ask for, the lights (the default rig only when no
// light and no environment lights the scene), the memory plan checked
// against the budget before anything big is allocated, the environment map
// loaded, the FrameSettings, the Renderer and SceneRenderer (textures
// decoded) and the environment prefiltered. The same request gives the same
// floats in every tool, so that step explains the pixels render writes.
//
// Nothing is printed here: warnings and notes are collected for the caller,
// and a failure is an exit code and one line, without a program prefix.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "raster/pipeline.h"
#include "scene/camera.h"
#include "scene/camera_request.h"
#include "scene/image.h"
#include "scene/scene.h"
#include "renderer/scene_renderer.h"

namespace prast {

// Exit codes of a failed set-up: a bad file (or a job too big for memory),
// or a flag at fault.
constexpr int kFrameExitBadFile = 1;
constexpr int kFrameExitUsage = 2;

// What a frame is to be: the options of render's command line that shape it.
struct FrameRequest {
    std::string scene;                       // empty: the built-in scene
    bool allow_outside_paths = false;        // the model may name files outside its folder
    int width = 1280, height = 720;
    std::optional<glm::vec3> eye, target, up;
    float fov_deg = 45.0f;
    std::optional<float> near_plane, far_plane;
    std::vector<ShadingLight> lights;        // from the flags, in order
    glm::vec3 ambient{0.03f};
    bool ambient_given = false;              // notes that an environment replaces it
    bool file_lights = true;                 // the file's KHR_lights_punctual lights (--file-lights)
    bool no_default_lights = false;
    BrdfModel brdf = BrdfModel::Default;
    std::string env;                         // an .hdr file; empty: the scene's own, if any
    float env_intensity = 1.0f, env_rotate_deg = 0.0f;
    bool env_importance_sampling = false;    // build the environment's sampler (reference integrals)
    IblMode ibl = IblMode::SplitSum;
    int ibl_samples = 256;
    Background background = Background::Env;
    glm::vec3 background_color{0.0f};
    bool energy = false;
    DebugView view = DebugView::None;
    int samples = 1;                         // per pixel
    ShadowSettings shadows;
    float exposure = 1.0f;
    ToneMap tonemap = ToneMap::Aces;         // the tone map the image is written with
    int threads = 0;                         // 0: all hardware threads
    int tile_size = kDefaultTileSize;
    std::uint64_t bytes_per_pixel = 24;      // framebuffer and output image, for the memory plan
    bool recording = false;                  // step: the plan counts the recording of the frame
    bool cap_warnings = true;                // at most a few warnings of each kind (scene/messages.h)
    // Animation (scene/animation.h): frame i is at time + i / fps (fps 0:
    // every frame at `time`), of the animation named (empty: every one);
    // `camera` names a camera of the file (empty: framed, or the flags').
    double time = 0.0;
    std::string animation;
    std::string camera;
    // KHR_materials_variants: a variant's name or index (empty: the default
    // materials); each primitive mapping it draws that variant's material.
    std::string variant;
    double fps = 0.0;
    double orbit_deg = 0.0;                  // a turntable's sweep: the default framing holds over it
    // A scene loaded (or built) already, drawn instead of loading `scene`,
    // which then only names it in messages; `decoded` keeps its textures'
    // decoded images between frames (the Python module's prast.load).
    std::shared_ptr<const Scene> loaded;
    std::shared_ptr<DecodedImages> decoded;

    CameraRequest camera_request() const {
        return {scene, eye, target, up, fov_deg, near_plane, far_plane, orbit_deg};
    }
};

// Where the set-up is, for a progress display and "out of memory while ...".
enum class FrameStage { Load, PlanMemory, StartThreads, DecodeTextures, PrefilterEnvironment };

// Why a set-up failed: an exit code (kFrameExitBadFile, kFrameExitUsage)
// and one line.
struct FrameError {
    int code = 0;
    std::string message;
    explicit operator bool() const { return code != 0; }
};

// A frame ready to draw. Holds the scene the renderer points into: neither
// copied nor moved.
struct FrameSetup {
    FrameSetup() = default;
    FrameSetup(const FrameSetup&) = delete;
    FrameSetup& operator=(const FrameSetup&) = delete;

    FrameRequest request;
    Scene scene;
    Bounds bounds;
    Camera base_camera;                      // the turntable's base: framed, then the flags
    int animation = -1;                      // scene/animation.h: kAllAnimations or an index
    int file_camera = -1;                    // index into scene.cameras; -1: framed
    double time = 0.0;                       // the time the scene is posed at
    Bounds first_bounds;                     // the bounds at frame 0, which framed the camera
    bool used_default_rig = false;
    std::shared_ptr<const Image> environment_image;  // --env's, or the scene's own
    FrameSettings settings;                  // camera: the base until orbit() sets a frame's
    std::unique_ptr<Renderer> renderer;
    std::unique_ptr<SceneRenderer> scene_renderer;
    std::unique_ptr<Environment> environment;  // prefiltered, when there is one
    // Warnings ("warning: ...") and notes, in the order they arose.
    std::vector<std::string> notes;
    double load_ms = 0.0, textures_ms = 0.0, environment_ms = 0.0;

    // The turntable's camera at `radians` around the base camera's target
    // and up, into settings.camera; a fault is the flags' (--near/--far).
    CameraFault orbit(double radians);
    // Frame `index` of a sequence or turntable: the scene posed at its time
    // (request.time + index / request.fps), then the camera as orbit()
    // sets it, or the file's camera at that time; clip planes fitted to the
    // bounds of frame 0 and of this frame together.
    CameraFault set_frame(int index, double radians);
    double frame_time(int index) const {
        return request.fps > 0.0 ? request.time + double(index) / request.fps : request.time;
    }

    int width() const { return request.width; }
    int height() const { return request.height; }
    int samples() const { return request.samples; }
    float exposure() const { return request.exposure; }
    ToneMap tonemap() const { return request.tonemap; }
    float aspect() const { return float(request.width) / float(request.height); }
    // The context the frame shades with, and what its samples clear to, for
    // a frame of the requested size (SceneRenderer::shading_context).
    ShadingContext shading_context() const { return scene_renderer->shading_context(settings, aspect()); }
    BackgroundFill background(int width, int height) const {
        return frame_background(settings, scene_renderer->environment(settings), width, height);
    }
};

// Called as each stage begins.
using FrameStageHook = std::function<void(FrameStage)>;

// The scene, camera, lights, memory plan, environment map and FrameSettings:
// everything but the renderer. `out` is filled in place (it holds the
// scene). Until start_renderer, settings.environment is unset (a renderer
// of the caller's prefilters the scene's own map on first use).
FrameError prepare_scene(const FrameRequest& request, FrameSetup& out, const FrameStageHook& on_stage = {});

// The Renderer and SceneRenderer and the prefiltered environment, after
// prepare_scene. The camera is left to orbit(): each frame of a turntable
// has its own.
FrameError start_renderer(FrameSetup& frame, const FrameStageHook& on_stage = {});

// Both: a frame ready to render.
FrameError setup_frame(const FrameRequest& request, FrameSetup& out, const FrameStageHook& on_stage = {});

} // namespace prast

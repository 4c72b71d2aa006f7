// The frame `step` records: the scene, camera and lights that `render` would
// use for the same command line (frame 0 of apps/render.cpp, step for step),
// so that every pixel step explains is the pixel render writes. The tests
// (tests/test_step.cpp) compare the two executables' outputs pixel by pixel.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "raster/pipeline.h"
#include "scene/scene.h"
#include "renderer/scene_renderer.h"
#include "shading/tonemap.h"

namespace prast::stepper {

// The frame to record: what render's options (apps/render_options.h) say
// about the scene, camera, lights and view transform; apps/step.cpp fills it.
struct FrameRequest {
    std::string scene;                       // empty: the built-in scene
    int width = 1280, height = 720;
    std::optional<glm::vec3> eye, target, up;
    float fov_deg = 45.0f;
    std::optional<float> near_plane, far_plane;
    std::vector<ShadingLight> lights;        // from the flags, in order
    glm::vec3 ambient{0.03f};
    bool no_default_lights = false;
    BrdfModel brdf = BrdfModel::Default;
    std::string env;                         // --env FILE.hdr; empty: the scene's own, if any
    float env_intensity = 1.0f, env_rotate_deg = 0.0f;
    Background background = Background::Env;
    glm::vec3 background_color{0.0f};
    bool energy = false;                     // --energy conserve
    float exposure = 1.0f;
    ToneMap tonemap = ToneMap::Aces;         // render's effective tone map
    int threads = 0;
    int tile_size = kDefaultTileSize;
    int samples = 1;                         // per pixel (render's --msaa)
    ShadowSettings shadows;                  // render's --shadows, --shadow-size
    std::uint64_t bytes_per_pixel = 24;      // render's framebuffer and image per pixel
};

// A scene ready to draw: loaded, framed, lit, its textures bound.
struct StepScene {
    FrameRequest options;
    Scene scene;
    FrameSettings settings;          // camera (frame 0), lights, ambient, BRDF
    std::unique_ptr<Renderer> renderer;
    std::unique_ptr<SceneRenderer> scene_renderer;
    std::unique_ptr<Environment> environment;  // prefiltered as render does, when there is one
    std::vector<std::string> notes;  // warnings and the default-rig note, for stderr
    int width() const { return options.width; }
    int height() const { return options.height; }
    int samples() const { return options.samples; }
    float exposure() const { return options.exposure; }
    ToneMap tonemap() const { return options.tonemap; }
};

// What went wrong while setting up: a message and render's exit code
// (1: bad file, 2: bad usage).
struct SetupError {
    int code = 0;
    std::string message;
};

// Loads and frames as render does; returns false with `err` set on failure.
bool setup_scene(const FrameRequest& request, StepScene& out, SetupError& err);

} // namespace prast::stepper

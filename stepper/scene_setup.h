// The frame `step` records: the scene, camera and lights that `render` would
// use for the same command line (frame 0 of apps/render.cpp, step for step),
// so that every pixel step explains is the pixel render writes. The tests
// (tests/test_step.cpp) compare the two executables' outputs pixel by pixel.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "apps/render_options.h"
#include "raster/pipeline.h"
#include "scene/scene.h"
#include "shading/scene_renderer.h"

namespace prast::stepper {

// A scene ready to draw: loaded, framed, lit, its textures bound.
struct StepScene {
    RenderOptions options;
    Scene scene;
    FrameSettings settings;          // camera (frame 0), lights, ambient, BRDF
    std::unique_ptr<Renderer> renderer;
    std::unique_ptr<SceneRenderer> scene_renderer;
    std::vector<std::string> notes;  // warnings and the default-rig note, for stderr
    int width() const { return options.width; }
    int height() const { return options.height; }
    float exposure() const { return options.exposure; }
    ToneMap tonemap() const { return options.effective_tonemap(); }
};

// What went wrong while setting up: a message and render's exit code
// (1: bad file, 2: bad usage).
struct SetupError {
    int code = 0;
    std::string message;
};

// Loads and frames as render does; returns false with `err` set on failure.
bool setup_scene(const RenderOptions& options, StepScene& out, SetupError& err);

} // namespace prast::stepper

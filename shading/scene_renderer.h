// Draws a loaded Scene: decodes and binds its textures once (in parallel, on
// the renderer's threads), then renders frames of it with the PBR program into
// a linear HDR framebuffer. The render CLI, bench and stepper all go through it.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "raster/pipeline.h"
#include "scene/camera.h"
#include "shading/debug_view.h"
#include "shading/pbr_program.h"
#include "scene/scene.h"
#include "shading/surface.h"
#include "shading/texture.h"

namespace prast {

struct FrameSettings {
    Camera camera;
    std::vector<ShadingLight> lights;
    glm::vec3 ambient{0.03f};
    BrdfModel model = BrdfModel::Default;
    DebugView view = DebugView::None;
};

// Scene lights (KHR_lights_punctual) in shading form.
std::vector<ShadingLight> shading_lights(const Scene& scene);

// The documented default rig for scenes without lights: a key sun from the
// upper left front and a weaker, cooler fill from the right.
std::vector<ShadingLight> default_light_rig();

class SceneRenderer {
public:
    // Decodes every texture the materials use. A texture that cannot be
    // decoded is dropped with a warning (the factor alone is used).
    SceneRenderer(const Scene& scene, Renderer& renderer);

    // Renders one frame into fb (resized by the caller): clears to black,
    // draws every mesh, and applies the overdraw/tiles debug overlays.
    void render(const FrameSettings& settings, Framebuffer& fb);

    const std::vector<std::string>& warnings() const { return warnings_; }
    const std::vector<BoundMaterial>& materials() const { return bound_; }
    const Scene& scene() const { return scene_; }
    Renderer& renderer() { return renderer_; }

private:
    const Scene& scene_;
    Renderer& renderer_;
    std::vector<std::unique_ptr<Texture>> textures_;  // [image * 2 + srgb]
    std::vector<std::unique_ptr<Texture>> packed_;    // OBJ roughness + metal pairs
    std::vector<BoundMaterial> bound_;
    std::vector<std::string> warnings_;
};

// Debug-view post passes, exposed for tests.
void apply_overdraw_heat(Framebuffer& fb);
void apply_tile_overlay(Framebuffer& fb, const std::vector<std::uint32_t>& entries, int tile_size);

} // namespace prast

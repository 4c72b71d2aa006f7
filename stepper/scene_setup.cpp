// The scene, camera and lights of render's frame 0; see scene_setup.h. Each
// step below is the one apps/render.cpp takes, in the same order, so the
// floats are the same.
#include "stepper/scene_setup.h"

#include "scene/camera.h"
#include "scene/camera_request.h"
#include "scene/default_scene.h"
#include "scene/image.h"
#include "scene/load_environment.h"
#include "scene/load_scene.h"
#include "renderer/memory_plan.h"

namespace prast::stepper {

bool setup_scene(const FrameRequest& opt, StepScene& out, SetupError& err) {
    out.options = opt;
    Camera camera;
    if (opt.scene.empty()) {
        DefaultScene d = make_default_scene();
        out.scene = std::move(d.scene);
        camera = d.camera;
    } else {
        try {
            out.scene = load_scene(opt.scene);
        } catch (const LoadError& e) {
            err = {1, e.what()};
            return false;
        }
    }
    for (const std::string& w : out.scene.warnings) out.notes.push_back("warning: " + w);

    // Camera: the default scene's own, or framed on the bounds; flags override.
    const Bounds bounds = out.scene.bounds();
    const float aspect = float(opt.width) / float(opt.height);
    const CameraRequest camera_request{opt.scene, opt.eye, opt.target, opt.up, opt.fov_deg, opt.near_plane,
                                       opt.far_plane};
    if (CameraFault f = request_camera(camera_request, bounds, aspect, !opt.scene.empty(), camera, camera)) {
        err = {f.kind == CameraFault::Flag ? 2 : 1, f.message};
        return false;
    }

    // Lights (the memory plan counts their shadow maps); the default rig
    // only when no light and no environment lights the scene.
    FrameSettings& s = out.settings;
    bool used_default_rig = false;
    s.lights = frame_lights(out.scene, opt.lights, opt.no_default_lights,
                            out.scene.environment || !opt.env.empty(), used_default_rig);
    if (used_default_rig)
        out.notes.push_back("no lights in the scene or flags: using the default key+fill rig "
                            "(--no-default-lights to disable)");

    // render's memory plan, plus the recording: refused before anything big
    // is allocated.
    MemoryPlan plan = plan_memory(out.scene, opt.width, opt.height, opt.bytes_per_pixel);
    plan_environment(plan, out.scene, opt.env);
    plan_shadows(plan, s.lights, opt.shadows);
    plan_recording(plan, out.scene, opt.width, opt.height, opt.samples);
    const std::uint64_t budget = memory_budget();
    if (plan.total() > budget) {
        err = {1, (opt.scene.empty() ? std::string("the built-in scene") : opt.scene) + ": recording the frame needs " +
                      plan.describe() + ", more than the " + std::to_string(budget) +
                      " bytes allowed (half the physical memory)"};
        return false;
    }

    // The environment: --env, or the scene's own (the built-in sky).
    std::shared_ptr<const Image> env_image = out.scene.environment;
    if (!opt.env.empty()) {
        try {
            env_image = std::make_shared<const Image>(load_environment_hdr(opt.env));
        } catch (const LoadError& e) {
            err = {1, e.what()};
            return false;
        }
    }

    s.ambient = opt.ambient;
    s.model = opt.brdf;
    s.view = DebugView::None;
    s.energy = opt.energy;
    s.background = opt.background;
    s.background_color = opt.background_color;
    s.samples = opt.samples;
    s.shadows = opt.shadows;

    // Frame 0 of render's turntable loop.
    if (CameraFault f = orbit_camera(camera_request, camera, bounds, 0.0, s.camera)) {
        err = {2, f.message};
        return false;
    }

    RendererOptions ro;
    ro.threads = opt.threads;
    ro.tile_size = opt.tile_size;
    out.renderer = std::make_unique<Renderer>(ro);
    out.scene_renderer = std::make_unique<SceneRenderer>(out.scene, *out.renderer);
    if (env_image) {
        EnvironmentSettings es;
        es.intensity = opt.env_intensity;
        es.rotate_deg = opt.env_rotate_deg;
        out.environment = std::make_unique<Environment>(Environment::build(*env_image, es, out.renderer->pool()));
    }
    s.environment = out.environment.get();
    s.scene_environment = false;
    for (const std::string& w : out.scene_renderer->warnings()) out.notes.push_back("warning: " + w);
    return true;
}

} // namespace prast::stepper

// The scene, camera and lights of render's frame 0; see scene_setup.h. Each
// step below is the one apps/render.cpp takes, in the same order, so the
// floats are the same.
#include "stepper/scene_setup.h"

#include <cmath>

#include "scene/camera.h"
#include "scene/default_scene.h"
#include "scene/image.h"
#include "scene/load_environment.h"
#include "scene/load_scene.h"

namespace prast::stepper {

namespace {

// render's turntable rotation (Rodrigues, in double): frame 0 turns by 0
// radians, which still rounds eye - target through float and back.
glm::vec3 rotate_around(const glm::vec3& v, const glm::vec3& k, double radians) {
    const glm::dvec3 dv(v), dk(k);
    const double c = std::cos(radians), s = std::sin(radians);
    return glm::vec3(dv * c + glm::cross(dk, dv) * s + dk * glm::dot(dk, dv) * (1.0 - c));
}

} // namespace

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
    if (!opt.scene.empty()) camera = frame_bounds(bounds, opt.fov_deg, aspect);
    camera.fov_y_deg = opt.fov_deg;
    if (opt.eye) camera.eye = *opt.eye;
    if (opt.target) camera.target = *opt.target;
    if (opt.up) camera.up = glm::normalize(*opt.up);
    const glm::vec3 view_dir = camera.target - camera.eye;
    if (!(glm::length(view_dir) > 0.0f)) {
        err = {2, "--eye/--target: the eye and the target are the same point"};
        return false;
    }
    if (!(glm::length(glm::cross(glm::normalize(view_dir), camera.up)) > 1e-4f)) {
        err = {2, "--up: parallel to the viewing direction (eye to target); give another --up"};
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

    // Lights: the scene's and the flags'; the default rig only when neither
    // has any and no environment lights the scene.
    FrameSettings& s = out.settings;
    s.lights = shading_lights(out.scene);
    s.lights.insert(s.lights.end(), opt.lights.begin(), opt.lights.end());
    if (s.lights.empty() && !opt.no_default_lights && !env_image) {
        s.lights = default_light_rig();
        out.notes.push_back("no lights in the scene or flags: using the default key+fill rig "
                            "(--no-default-lights to disable)");
    }
    s.ambient = opt.ambient;
    s.model = opt.brdf;
    s.view = DebugView::None;
    s.energy = opt.energy;
    s.background = opt.background;
    s.background_color = opt.background_color;
    s.samples = opt.samples;

    // Frame 0 of render's turntable loop.
    Camera cam = camera;
    cam.eye = camera.target + rotate_around(camera.eye - camera.target, glm::normalize(camera.up), 0.0);
    fit_clip_planes(cam, bounds);
    if (opt.near_plane) cam.near_plane = *opt.near_plane;
    if (opt.far_plane) cam.far_plane = *opt.far_plane;
    if (!(cam.near_plane < cam.far_plane)) {
        err = {2, "--near/--far: near " + std::to_string(cam.near_plane) + " is not less than far " +
                      std::to_string(cam.far_plane) + " (give both --near and --far)"};
        return false;
    }
    s.camera = cam;

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

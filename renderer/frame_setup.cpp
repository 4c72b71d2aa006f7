// The frame set-up; see frame_setup.h. The order of the steps is the order of
// the messages a tool prints, and each float is computed once, here.
#include "renderer/frame_setup.h"

#include <algorithm>
#include <chrono>

#include "scene/animation.h"
#include "scene/default_scene.h"
#include "scene/load_environment.h"
#include "scene/load_scene.h"
#include "scene/tangents.h"
#include "scene/messages.h"
#include "renderer/memory_plan.h"

namespace prast {

namespace {

using Clock = std::chrono::steady_clock;

double ms_since(Clock::time_point t0) {
    return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

void stage(const FrameStageHook& hook, FrameStage s) {
    if (hook) hook(s);
}

void add_warnings(FrameSetup& f, const std::vector<std::string>& warnings) {
    for (const std::string& w : f.request.cap_warnings ? cap_warnings(warnings) : warnings)
        f.notes.push_back("warning: " + w);
}

// "FLAG 'VALUE': SCENE has no WHAT of that name or index (...)", listing
// what there is.
std::string not_found(const std::string& flag, const std::string& value, const std::string& scene,
                      const char* what, const std::vector<std::string>& names) {
    std::string have;
    for (std::size_t i = 0; i < names.size() && i < 8; ++i)
        have += (i ? ", " : "") + std::to_string(i) + " '" + cut(names[i]) + "'";
    if (names.size() > 8) have += ", ...";
    return flag + " '" + cut(value) + "': " + scene + " has no " + what + " of that name or index (" +
           (names.empty() ? std::string("it has none") : "it has " + have) + ")";
}

// KHR_materials_variants: every primitive with a mapping for variant v
// takes its material. Computed tangents follow the new material's normal map
// when it reads another UV set (tangent_uvs), as the loader would have made them.
void select_variant(Scene& scene, int v) {
    for (Mesh& m : scene.meshes) {
        if (std::size_t(v) >= m.variant_materials.size() || m.variant_materials[std::size_t(v)] < 0) continue;
        const std::vector<glm::vec2>* before = &scene_detail::tangent_uvs(m, scene);
        m.material = m.variant_materials[std::size_t(v)];
        const std::vector<glm::vec2>& after = scene_detail::tangent_uvs(m, scene);
        if (&after != before && !after.empty() && !m.normals.empty()) compute_tangents(m, after);
    }
}

} // namespace

CameraFault FrameSetup::orbit(double radians) {
    if (file_camera < 0) return orbit_camera(request.camera_request(), base_camera, bounds, radians, settings.camera);
    Camera cam = scene_camera(scene, file_camera, time, aspect(), animation);
    if (request.near_plane) cam.near_plane = *request.near_plane;
    if (request.far_plane) {
        cam.far_plane = *request.far_plane;
        cam.infinite_far = false;
    } else if (cam.infinite_far && !bounds.empty()) {
        // The projection has no far plane; what fits to the view (shadow
        // maps) reads this one, which encloses the scene.
        cam.far_plane = std::max(cam.near_plane * 2.0f,
                                 glm::length(cam.eye - bounds.center()) + std::max(bounds.radius(), 1e-4f) * 1.05f);
    }
    if (!(cam.near_plane < cam.far_plane) && !cam.infinite_far)
        return {CameraFault::Flag, "--near/--far: near " + std::to_string(cam.near_plane) +
                                       " is not less than the camera's far " + std::to_string(cam.far_plane)};
    settings.camera = cam;
    return {};
}

CameraFault FrameSetup::set_frame(int index, double radians) {
    const double t = frame_time(index);
    if (scene.source && !scene.animation_names.empty() && t != time) {
        pose_scene(scene, t, animation);
        time = t;
        // The file's lights move with their nodes.
        settings.lights = frame_lights(scene, request.lights, request.file_lights, request.no_default_lights,
                                       scene.environment || !request.env.empty(), used_default_rig);
        bounds = first_bounds;
        const Bounds now = scene.bounds();
        if (!now.empty()) {
            bounds.add(now.lo);
            bounds.add(now.hi);
        }
    }
    return orbit(radians);
}

FrameError prepare_scene(const FrameRequest& req, FrameSetup& out, const FrameStageHook& on_stage) {
    out.request = req;

    // The scene, or the built-in one with its own camera.
    stage(on_stage, FrameStage::Load);
    const auto t_load = Clock::now();
    Camera camera;
    if (req.loaded) {
        out.scene = *req.loaded;
    } else if (req.scene.empty()) {
        DefaultScene d = make_default_scene(req.threads);
        out.scene = std::move(d.scene);
        camera = d.camera;
    } else {
        LoadOptions load_options;
        load_options.allow_outside_paths = req.allow_outside_paths;
        try {
            out.scene = load_scene(req.scene, load_options);
        } catch (const LoadError& e) {
            return {kFrameExitBadFile, e.what()};
        }
    }
    out.load_ms = ms_since(t_load);
    add_warnings(out, out.scene.warnings);

    // The animation and the file camera the flags name, then the pose of
    // frame 0 (the loader gives the rest pose).
    const bool builtin = req.scene.empty() && !req.loaded;
    const std::string scene_name = builtin ? std::string("the built-in scene") : req.scene;
    out.animation = kAllAnimations;
    if (!req.animation.empty()) {
        out.animation = find_named(out.scene.animation_names, req.animation);
        if (out.animation < 0)
            return {kFrameExitUsage,
                    not_found("--animation", req.animation, scene_name, "animation", out.scene.animation_names)};
    }
    if (!req.camera.empty()) {
        std::vector<std::string> names;
        for (const SceneCamera& c : out.scene.cameras) names.push_back(c.name);
        out.file_camera = find_named(names, req.camera);
        if (out.file_camera < 0) return {kFrameExitUsage, not_found("--camera", req.camera, scene_name, "camera", names)};
    }
    if (!req.variant.empty()) {
        const int v = find_named(out.scene.variants, req.variant);
        if (v < 0) return {kFrameExitUsage, not_found("--variant", req.variant, scene_name, "variant", out.scene.variants)};
        select_variant(out.scene, v);  // before posing, whose tangents follow the material
    }
    out.time = req.time;
    if (out.scene.source && !out.scene.animation_names.empty()) pose_scene(out.scene, req.time, out.animation);

    // The camera: the built-in scene's own, or framed on its vertices; the
    // flags override single fields.
    out.bounds = out.scene.bounds();
    out.first_bounds = out.bounds;
    if (out.file_camera >= 0) {
        out.base_camera = scene_camera(out.scene, out.file_camera, out.time, out.aspect(), out.animation);
    } else if (CameraFault f = request_camera(req.camera_request(), out.bounds, out.aspect(),
                                              builtin ? nullptr : &out.scene,
                                              camera, out.base_camera)) {
        return {f.kind == CameraFault::Flag ? kFrameExitUsage : kFrameExitBadFile, f.message};
    }
    out.settings.camera = out.base_camera;

    // The lights: the scene's and the flags'; the default rig only when
    // neither has any and no environment (--env, or the scene's own sky)
    // lights the scene.
    out.settings.lights = frame_lights(out.scene, req.lights, req.file_lights, req.no_default_lights,
                                       out.scene.environment || !req.env.empty(), out.used_default_rig);

    // The whole job must fit in memory before anything big is allocated.
    stage(on_stage, FrameStage::PlanMemory);
    MemoryPlan plan = plan_memory(out.scene, req.width, req.height, req.bytes_per_pixel);
    plan_environment(plan, out.scene, req.env);
    plan_shadows(plan, out.settings.lights, req.shadows);
    if (req.recording) plan_recording(plan, out.scene, req.width, req.height, req.samples);
    const std::uint64_t budget = memory_budget();
    if (plan.total() > budget)
        return {kFrameExitBadFile, scene_name +
                                       (req.recording ? ": recording the frame needs " : ": the render needs ") +
                                       plan.describe() + ", more than the " + std::to_string(budget) +
                                       " bytes allowed (half the physical memory)"};

    // The environment: the --env file, or the scene's own (the built-in sky).
    out.environment_image = out.scene.environment;
    if (!req.env.empty()) {
        try {
            out.environment_image = std::make_shared<const Image>(load_environment_hdr(req.env));
        } catch (const LoadError& e) {
            return {kFrameExitBadFile, e.what()};
        }
    }

    FrameSettings& s = out.settings;
    s.ambient = req.ambient;
    s.model = req.brdf;
    s.view = req.view;
    s.ibl = req.ibl;
    s.ibl_samples = req.ibl_samples;
    s.energy = req.energy;
    s.background = req.background;
    s.background_color = req.background_color;
    s.samples = req.samples;
    s.shadows = req.shadows;

    if (out.used_default_rig)
        out.notes.push_back("no lights in the scene or flags: using the default key+fill rig "
                            "(--no-default-lights to disable)");
    if (out.environment_image && req.ambient_given)
        out.notes.push_back("warning: --ambient is not used: the environment map replaces the ambient term");
    return {};
}

FrameError start_renderer(FrameSetup& out, const FrameStageHook& on_stage) {
    const FrameRequest& req = out.request;
    FrameSettings& s = out.settings;
    stage(on_stage, FrameStage::StartThreads);
    const auto t_tex = Clock::now();
    RendererOptions ro;
    ro.threads = req.threads;
    ro.tile_size = req.tile_size;
    out.renderer = std::make_unique<Renderer>(ro);
    if (!out.renderer->pool().started_fewer().empty())
        out.notes.push_back("warning: " + out.renderer->pool().started_fewer() + "; rendering with " +
                            std::to_string(out.renderer->threads()));
    stage(on_stage, FrameStage::DecodeTextures);
    out.scene_renderer = std::make_unique<SceneRenderer>(out.scene, *out.renderer, req.decoded.get());
    out.textures_ms = ms_since(t_tex);
    add_warnings(out, out.scene_renderer->warnings());

    // Prefiltered once for all frames, on the renderer's threads.
    const auto t_env = Clock::now();
    if (out.environment_image) {
        stage(on_stage, FrameStage::PrefilterEnvironment);
        EnvironmentSettings es;
        es.intensity = req.env_intensity;
        es.rotate_deg = req.env_rotate_deg;
        es.importance_sampling = req.env_importance_sampling;
        out.environment =
            std::make_unique<Environment>(Environment::build(*out.environment_image, es, out.renderer->pool()));
    }
    s.environment = out.environment.get();
    s.scene_environment = false;
    out.environment_ms = ms_since(t_env);
    return {};
}

FrameError setup_frame(const FrameRequest& request, FrameSetup& out, const FrameStageHook& on_stage) {
    if (FrameError e = prepare_scene(request, out, on_stage)) return e;
    return start_renderer(out, on_stage);
}

} // namespace prast

// render: the command-line renderer (issue 4). Parses the options
// (render_options.h), loads the scene or builds the default one, frames the
// camera, and renders one image or a turntable with the library's
// SceneRenderer; everything else lives in shading/ and raster/. Errors are one
// line on stderr, "render: ...": exit code 2 for usage, 1 for bad files and
// failed writes. Output is written atomically (temporary file, then rename).
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <filesystem>
#include <mutex>
#include <new>
#include <string>
#include <thread>
#include <vector>

#include <unistd.h>

#include <glm/glm.hpp>

#include "apps/render_options.h"
#include "raster/pipeline.h"
#include "scene/camera.h"
#include "scene/default_scene.h"
#include "scene/write_image.h"
#include "scene/load_scene.h"
#include "shading/scene_renderer.h"
#include "shading/tonemap.h"

namespace fs = std::filesystem;
using namespace prast;

namespace {

using Clock = std::chrono::steady_clock;

double ms_since(Clock::time_point t0) {
    return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

// Exit codes (issue 4).
constexpr int kExitBadFile = 1;
constexpr int kExitUsage = 2;

// A progress bar on stderr, drawn by its own thread every 200 ms once the job
// has run for a second, and only when stderr is a terminal. Other stderr lines
// go through note() so they never land in the middle of the bar.
class Progress {
public:
    explicit Progress(int total_steps) : total_(std::max(1, total_steps)) {
        if (isatty(STDERR_FILENO)) thread_ = std::thread([this] { loop(); });
    }
    ~Progress() { finish(); }

    void begin(int step, const std::string& label) {
        std::lock_guard<std::mutex> lock(mutex_);
        step_ = step;
        label_ = label;
    }
    void note(const std::string& line) {
        std::lock_guard<std::mutex> lock(mutex_);
        clear_line();
        std::fprintf(stderr, "%s\n", line.c_str());
    }
    void finish() {
        if (!thread_.joinable()) return;
        {
            std::lock_guard<std::mutex> lock(mutex_);
            stop_ = true;
        }
        wake_.notify_all();
        thread_.join();
        clear_line();
    }

private:
    void loop() {
        std::unique_lock<std::mutex> lock(mutex_);
        while (!wake_.wait_for(lock, std::chrono::milliseconds(200), [this] { return stop_; })) {
            const double seconds = ms_since(start_) / 1000.0;
            if (seconds < 1.0) continue;
            constexpr int kWidth = 30;
            const int filled = std::min(kWidth, step_ * kWidth / total_);
            std::string bar(std::size_t(filled), '#');
            bar.append(std::size_t(kWidth - filled), '.');
            std::fprintf(stderr, "\rrender: [%s] %d/%d %s  %.1f s\033[K", bar.c_str(), step_, total_,
                         label_.c_str(), seconds);
            std::fflush(stderr);
            shown_ = true;
        }
    }
    void clear_line() {
        if (shown_) std::fputs("\r\033[K", stderr);
        shown_ = false;
    }

    const Clock::time_point start_ = Clock::now();
    const int total_;
    std::thread thread_;
    std::mutex mutex_;
    std::condition_variable wake_;
    int step_ = 0;
    std::string label_ = "starting";
    bool stop_ = false, shown_ = false;
};

// "" when `path` can be written: its directory exists and a file can be
// created in it (probed with a real temporary file, which also catches
// read-only file systems and what access() gets wrong for root).
std::string check_output_path(const std::string& path) {
    std::error_code ec;
    if (fs::is_directory(path, ec)) return path + ": is a directory, not an output file";
    fs::path dir = fs::path(path).parent_path();
    if (dir.empty()) dir = ".";
    const fs::file_status st = fs::status(dir, ec);
    if (!fs::exists(st)) return path + ": cannot write: directory '" + dir.string() + "' does not exist";
    if (!fs::is_directory(st)) return path + ": cannot write: '" + dir.string() + "' is not a directory";
    std::string probe = (dir / ".render-probe-XXXXXX").string();
    int fd = mkstemp(probe.data());
    if (fd < 0)
        return path + ": cannot write in directory '" + dir.string() + "' (" + std::strerror(errno) + ")";
    close(fd);
    unlink(probe.c_str());
    return "";
}

// v rotated by `radians` around the unit axis k (Rodrigues), in double so the
// eye of frame i does not depend on which frames were rendered before it.
glm::vec3 rotate_around(const glm::vec3& v, const glm::vec3& k, double radians) {
    const glm::dvec3 dv(v), dk(k);
    const double c = std::cos(radians), s = std::sin(radians);
    return glm::vec3(dv * c + glm::cross(dk, dv) * s + dk * glm::dot(dk, dv) * (1.0 - c));
}

// The nearest triangle along pixel (x, y)'s ray, for --pixel: a brute-force
// ray cast (Moller-Trumbore) over the scene, with the rasterizer's culling.
struct PixelHit {
    int mesh = -1;
    std::size_t triangle = 0;
};

PixelHit cast_pixel_ray(const Scene& scene, const Camera& cam, int width, int height, glm::ivec2 px) {
    const glm::mat4 inv = glm::inverse(cam.view_projection(float(width) / float(height)));
    const float x_ndc = (float(px.x) + 0.5f) / float(width) * 2.0f - 1.0f;
    const float y_ndc = 1.0f - (float(px.y) + 0.5f) / float(height) * 2.0f;
    glm::vec4 a = inv * glm::vec4(x_ndc, y_ndc, -1.0f, 1.0f), b = inv * glm::vec4(x_ndc, y_ndc, 1.0f, 1.0f);
    const glm::vec3 origin = glm::vec3(a) / a.w, dir = glm::vec3(b) / b.w - origin;
    PixelHit hit;
    float best = 1.0f;  // ray parameter: 0 at the near plane, 1 at the far plane
    for (std::size_t m = 0; m < scene.meshes.size(); ++m) {
        const Mesh& mesh = scene.meshes[m];
        const bool two_sided = mesh.material >= 0 && std::size_t(mesh.material) < scene.materials.size() &&
                               scene.materials[std::size_t(mesh.material)].double_sided;
        for (std::size_t t = 0; t + 2 < mesh.indices.size(); t += 3) {
            const glm::vec3& p0 = mesh.positions[mesh.indices[t]];
            const glm::vec3 e1 = mesh.positions[mesh.indices[t + 1]] - p0;
            const glm::vec3 e2 = mesh.positions[mesh.indices[t + 2]] - p0;
            // Front faces wind counter-clockwise as seen: their normal faces the ray.
            if (!two_sided && glm::dot(glm::cross(e1, e2), dir) >= 0.0f) continue;
            const glm::vec3 p = glm::cross(dir, e2);
            const float det = glm::dot(e1, p);
            if (det == 0.0f) continue;
            const glm::vec3 s = origin - p0;
            const float u = glm::dot(s, p) / det;
            if (u < 0.0f || u > 1.0f) continue;
            const glm::vec3 q = glm::cross(s, e1);
            const float v = glm::dot(dir, q) / det;
            if (v < 0.0f || u + v > 1.0f) continue;
            const float tr = glm::dot(e2, q) / det;
            if (tr >= 0.0f && tr < best) {
                best = tr;
                hit.mesh = int(m);
                hit.triangle = t / 3;
            }
        }
    }
    return hit;
}

void print_pixel(const Scene& scene, const Camera& cam, const Framebuffer& fb, const std::vector<std::uint8_t>& rgba8,
                 glm::ivec2 px, int frame) {
    const float* c = fb.pixel(px.x, px.y);
    const float depth = fb.depth[std::size_t(px.y) * std::size_t(fb.width) + std::size_t(px.x)];
    std::printf("pixel %d,%d frame %d: depth %.6f linear %.6g %.6g %.6g", px.x, px.y, frame, double(depth),
                double(c[0]), double(c[1]), double(c[2]));
    if (!rgba8.empty()) {
        const std::uint8_t* s = &rgba8[(std::size_t(px.y) * std::size_t(fb.width) + std::size_t(px.x)) * 4];
        std::printf(" srgb8 %d %d %d", s[0], s[1], s[2]);
    }
    if (depth >= 1.0f) {
        std::printf(" (background)\n");
        return;
    }
    const PixelHit hit = cast_pixel_ray(scene, cam, fb.width, fb.height, px);
    if (hit.mesh < 0) {
        std::printf(" (ray cast found no triangle)\n");
        return;
    }
    const Mesh& mesh = scene.meshes[std::size_t(hit.mesh)];
    std::printf(" mesh %d '%s' triangle %zu material '%s'\n", hit.mesh, mesh.name.c_str(), hit.triangle,
                scene.materials[std::size_t(std::max(0, mesh.material))].name.c_str());
}

int run(int argc, char** argv) {
    RenderOptions opt;
    const std::string usage_err = parse_render_args(argc, argv, opt);
    if (!usage_err.empty()) {
        std::fprintf(stderr, "render: %s\n", usage_err.c_str());
        return kExitUsage;
    }
    if (opt.help) {
        std::fputs(render_usage(), stdout);
        return 0;
    }
    if (opt.version) {
        std::printf("render (prast) %s\n", kRenderVersion);
        return 0;
    }

    // Fail on an unwritable output before spending time on the render.
    const render_cli::FramePattern pattern(opt.output);
    for (int frame : {opt.first_frame, opt.last_frame}) {
        const std::string err = check_output_path(pattern.format(frame));
        if (!err.empty()) {
            std::fprintf(stderr, "render: %s\n", err.c_str());
            return kExitBadFile;
        }
    }

    const int frames_to_render = opt.last_frame - opt.first_frame + 1;
    Progress progress(2 + frames_to_render * opt.repeat);
    auto fail = [&](int code, const std::string& message) {
        progress.finish();
        std::fprintf(stderr, "render: %s\n", message.c_str());
        return code;
    };

    // Load the scene, or build the default one with its own camera.
    progress.begin(0, opt.scene.empty() ? "building the default scene" : "loading " + opt.scene);
    auto t_load = Clock::now();
    Scene scene;
    Camera camera;
    if (opt.scene.empty()) {
        DefaultScene d = make_default_scene();
        scene = std::move(d.scene);
        camera = d.camera;
    } else {
        try {
            scene = load_scene(opt.scene);
        } catch (const LoadError& e) {
            return fail(kExitBadFile, e.what());
        }
    }
    const double load_ms = ms_since(t_load);
    for (const std::string& w : scene.warnings) progress.note("render: warning: " + w);

    // Camera: the default scene's own, or framed on the bounds; flags override
    // single fields, and the framing fills in the rest.
    const Bounds bounds = scene.bounds();
    const float aspect = float(opt.width) / float(opt.height);
    if (!opt.scene.empty()) camera = frame_bounds(bounds, opt.fov_deg, aspect);
    camera.fov_y_deg = opt.fov_deg;
    if (opt.eye) camera.eye = *opt.eye;
    if (opt.target) camera.target = *opt.target;
    if (opt.up) camera.up = glm::normalize(*opt.up);
    const glm::vec3 view_dir = camera.target - camera.eye;
    if (!(glm::length(view_dir) > 0.0f))
        return fail(kExitUsage, "--eye/--target: the eye and the target are the same point");
    if (!(glm::length(glm::cross(glm::normalize(view_dir), camera.up)) > 1e-4f))
        return fail(kExitUsage, "--up: parallel to the viewing direction (eye to target); give another --up");

    // Lights: the scene's and the flags'; the default rig only when neither has any.
    FrameSettings settings;
    settings.lights = shading_lights(scene);
    settings.lights.insert(settings.lights.end(), opt.lights.begin(), opt.lights.end());
    if (settings.lights.empty() && !opt.no_default_lights) {
        settings.lights = default_light_rig();
        progress.note("render: no lights in the scene or flags: using the default key+fill rig "
                      "(--no-default-lights to disable)");
    }
    settings.ambient = opt.ambient;
    settings.model = opt.brdf;
    settings.view = opt.view;
    settings.samples = opt.msaa;
    settings.shadows = opt.shadows;

    progress.begin(1, "decoding textures");
    auto t_tex = Clock::now();
    RendererOptions ro;
    ro.threads = opt.threads;
    ro.tile_size = opt.tile_size;
    Renderer renderer(ro);
    SceneRenderer scene_renderer(scene, renderer);
    const double textures_ms = ms_since(t_tex);
    for (const std::string& w : scene_renderer.warnings()) progress.note("render: warning: " + w);

    if (opt.stats)
        std::printf("scene                  %zu triangles, %zu meshes, %zu materials, %zu images\n"
                    "time load              %.3f ms\ntime textures          %.3f ms\nthreads                %d, "
                    "tile %d\n",
                    scene.triangle_count(), scene.meshes.size(), scene.materials.size(), scene.images.size(),
                    load_ms, textures_ms, renderer.threads(), renderer.tile_size());

    Framebuffer fb(opt.width, opt.height);
    std::vector<std::uint8_t> rgba8(opt.hdr_output() ? 0 : std::size_t(opt.width) * opt.height * 4);
    // The PNG's bytes come out of the frame's tile pass (resolve.h).
    ImageOutput out8;
    out8.rgba8 = rgba8.data();
    out8.exposure = opt.exposure;
    out8.tonemap = opt.effective_tonemap();
    out8.raw = debug_view_is_data(opt.view);
    std::vector<double> frame_ms;
    const glm::vec3 orbit_axis = glm::normalize(camera.up);
    int step = 2;
    for (int frame = opt.first_frame; frame <= opt.last_frame; ++frame) {
        // Frame i of a turntable sits at angle i * DEG / N around the target.
        Camera cam = camera;
        const double angle = glm::radians(double(frame) * opt.orbit_deg / double(opt.frames));
        cam.eye = camera.target + rotate_around(camera.eye - camera.target, orbit_axis, angle);
        fit_clip_planes(cam, bounds);
        if (opt.near_plane) cam.near_plane = *opt.near_plane;
        if (opt.far_plane) cam.far_plane = *opt.far_plane;
        if (!(cam.near_plane < cam.far_plane))
            return fail(kExitUsage, "--near/--far: near " + std::to_string(cam.near_plane) +
                                        " is not less than far " + std::to_string(cam.far_plane) +
                                        " (give both --near and --far)");
        settings.camera = cam;

        double render_ms = 0.0;
        for (int r = 0; r < opt.repeat; ++r) {
            progress.begin(step++, "frame " + std::to_string(frame));
            auto t0 = Clock::now();
            scene_renderer.render(settings, fb, opt.hdr_output() ? nullptr : &out8);
            render_ms = ms_since(t0);
            frame_ms.push_back(render_ms);
        }

        auto t_write = Clock::now();
        const std::string path = pattern.format(frame);
        progress.begin(step, "writing " + path);
        try {
            if (opt.hdr_output()) write_hdr_atomic(path, fb.width, fb.height, fb.color.data());
            else write_png_atomic(path, fb.width, fb.height, rgba8.data());
        } catch (const WriteError& e) {
            return fail(kExitBadFile, e.what());
        }
        if (opt.stats) {
            std::printf("frame                  %d\n%stime frame+resolve     %.3f ms\ntime write             %.3f ms\n",
                        frame, renderer.stats().to_string().c_str(), render_ms, ms_since(t_write));
        }
        if (opt.pixel) print_pixel(scene, cam, fb, rgba8, *opt.pixel, frame);
        std::fflush(stdout);
    }
    progress.finish();

    if (opt.repeat_given) {
        std::sort(frame_ms.begin(), frame_ms.end());
        const std::size_t n = frame_ms.size();
        const double median = n % 2 ? frame_ms[n / 2] : 0.5 * (frame_ms[n / 2 - 1] + frame_ms[n / 2]);
        std::printf("frame_ms min=%.3f median=%.3f max=%.3f\n", frame_ms.front(), median, frame_ms.back());
    }
    return 0;
}

} // namespace

int main(int argc, char** argv) {
    // Never crash: whatever escapes is one line and exit code 1.
    try {
        return run(argc, argv);
    } catch (const std::bad_alloc&) {
        std::fprintf(stderr, "render: out of memory (try a smaller --size or a smaller scene)\n");
    } catch (const std::exception& e) {
        std::fprintf(stderr, "render: %s\n", e.what());
    }
    return kExitBadFile;
}

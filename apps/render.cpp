// render: the command-line renderer. Parses the options (render_options.h),
// sets up the frame (renderer/frame_setup.h: scene, camera, lights, memory
// plan, environment) and renders one image or a turntable with the library's
// SceneRenderer; everything else lives in renderer/, shading/ and raster/. Errors are one
// line on stderr, "render: ...": exit code 2 for usage, 1 for bad files and
// failed writes. Output is written atomically (temporary file, then rename);
// SIGINT/SIGTERM remove the temporary file and end the process by the signal
// (exit status 130/143). Every stderr line passes through printable(), so
// nothing a model holds reaches the terminal as a control character.
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <filesystem>
#include <mutex>
#include <new>
#include <optional>
#include <set>
#include <string>
#include <system_error>
#include <thread>
#include <vector>

#include <malloc.h>
#include <unistd.h>

#include <glm/glm.hpp>

#include "apps/frame_request.h"
#include "apps/render_options.h"
#include "raster/pipeline.h"
#include "renderer/frame_setup.h"
#include "renderer/scene_renderer.h"
#include "scene/animation.h"
#include "scene/camera.h"
#include "scene/load_scene.h"
#include "scene/messages.h"
#include "scene/write_image.h"
#include "shading/isa.h"
#include "shading/ibl/environment.h"
#include "shading/output8.h"
#include "shading/surface.h"
#include "shading/tonemap.h"

namespace fs = std::filesystem;
using namespace prast;

namespace {

using Clock = std::chrono::steady_clock;

double ms_since(Clock::time_point t0) {
    return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

// Exit codes.
constexpr int kExitBadFile = 1;
constexpr int kExitUsage = 2;

// What the render is doing, for "out of memory while ..." (main thread only).
std::string g_stage = "starting";

// SIGINT, SIGTERM, SIGHUP: remove the temporary output file, then die by the
// same signal (SA_RESETHAND restored the default action), so the shell sees
// 130/143 and a script's loop stops as it should.
extern "C" void on_fatal_signal(int sig) {
    remove_temporary_output();
    raise(sig);
}

void install_signal_cleanup() {
    struct sigaction sa;
    std::memset(&sa, 0, sizeof sa);
    sa.sa_handler = on_fatal_signal;
    sa.sa_flags = SA_RESETHAND;
    sigemptyset(&sa.sa_mask);
    for (int sig : {SIGINT, SIGTERM, SIGHUP}) {
        // A signal ignored at start stays ignored (a background job's SIGINT).
        struct sigaction old;
        if (sigaction(sig, nullptr, &old) == 0 && old.sa_handler == SIG_IGN) continue;
        sigaction(sig, &sa, nullptr);
    }
}

// A progress bar on stderr, drawn by its own thread every 200 ms once the job
// has run for a second, and only when stderr is a terminal. Other stderr lines
// go through note() so they never land in the middle of the bar.
class Progress {
public:
    explicit Progress(int total_steps) : total_(std::max(1, total_steps)) {
        // No bar rather than no render when a thread cannot be started.
        if (isatty(STDERR_FILENO)) {
            try {
                thread_ = std::thread([this] { loop(); });
            } catch (const std::system_error&) {
            }
        }
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
        std::fprintf(stderr, "%s\n", printable(line).c_str());
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
                         printable(label_).c_str(), seconds);
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

// "" when every frame of [first, last] can be written: each distinct
// directory is probed once, before the first frame is rendered.
std::string check_output_paths(const cli::FramePattern& pattern, int first, int last) {
    std::set<std::string> dirs;
    std::error_code ec;
    for (int frame = first; frame <= last; ++frame) {
        const std::string path = pattern.format(frame);
        if (fs::is_directory(path, ec)) return path + ": is a directory, not an output file";
        if (!dirs.insert(fs::path(path).parent_path().string()).second) continue;
        const std::string err = check_output_path(path);
        if (!err.empty()) return err;
        if (!pattern.has_number) break;
    }
    return "";
}


// The fragment that wrote pixel (x, y), for --pixel: a stage observer
// (raster/observer.h) on every draw of the frame keeps, sample by sample, the
// last fragment whose depth test passed there and whose colour was written
// (the visibility pass's winner, or a fragment shaded in order that its
// shader kept), which is how step's pixel history finds its winner. Draws
// and triangles are numbered as step numbers them: draws in submission
// order, a triangle within its draw's mesh and over the frame.
struct PixelHit {
    int draw = -1;
    int mesh = -1;
    std::size_t triangle = 0;        // within the mesh
    std::uint32_t frame_triangle = 0;
    bool front_facing = true;
    int samples = 0;                 // of the pixel's samples it holds
    float u = 0.0f, v = 0.0f;        // barycentrics of vertices 1 and 2 where the pixel's ray meets its plane
    glm::vec3 origin{0.0f}, dir{0.0f};
};

class PixelWinner {
public:
    PixelWinner(int x, int y, int samples, FrameOptions::Visibility visibility)
        : bx_(x & ~(kBlockSize - 1)), by_(y & ~(kBlockSize - 1)), samples_(samples), visibility_(visibility) {
        for (int l = 0; l < kBlockLanes; ++l)
            if (lane_x(l) == x - bx_ && lane_y(l) == y - by_) lane_ = l;
    }

    struct Tap {
        static constexpr bool enabled = true;
        PixelWinner* w;
        int draw;
        void vertex(std::uint32_t, const float*, const float*, int) {}
        void triangle(std::uint32_t, TriangleFate, bool, const TriangleSetup*) {}
        void binned(std::uint32_t, int) {}
        void fragments(std::uint32_t, int, int, std::uint32_t, std::uint32_t, const float*) {}
        void samples(std::uint32_t prim, int bx, int by, const SampleCoverage& sc) { w->samples(draw, prim, bx, by, sc); }
        template <int NV>
        void shaded(const FragmentBlock<NV>& in, const FragmentOut&, std::uint32_t live) { w->shaded(draw, in, live); }
    };
    Tap tap(const SceneDraw& d) {
        draws_.push_back(d);
        visible_.push_back(shades_after_visibility(d.state, visibility_));
        return Tap{this, int(draws_.size()) - 1};
    }

    // The fragment holding the most samples (the first of them in
    // submission order on a tie); draw -1 when none holds one.
    PixelHit winner() const {
        PixelHit best;
        std::uint64_t best_seq = 0;
        for (int s = 0; s < samples_; ++s) {
            const Owner& o = owner_[s];
            if (o.draw < 0) continue;
            int n = 0;
            for (int t = 0; t < samples_; ++t) n += owner_[t].seq == o.seq && owner_[t].draw >= 0;
            if (n > best.samples || (n == best.samples && o.seq < best_seq)) {
                const SceneDraw& d = draws_[std::size_t(o.draw)];
                best.draw = o.draw;
                best.mesh = d.mesh;
                best.triangle = o.prim;
                best.frame_triangle = d.first_triangle + o.prim;
                best.front_facing = o.front;
                best.samples = n;
                best_seq = o.seq;
            }
        }
        return best;
    }

private:
    struct Owner {
        int draw = -1;
        std::uint32_t prim = 0;
        bool front = true;
        std::uint64_t seq = 0;  // the fragment's place in the tile's sequence
    };

    // The pixel's tile is run by one thread at a time, in submission order,
    // so these calls for its block arrive in order.
    void samples(int draw, std::uint32_t prim, int bx, int by, const SampleCoverage& sc) {
        if (bx != bx_ || by != by_) return;
        std::uint32_t pass = 0;
        for (int s = 0; s < sc.count; ++s) pass |= ((sc.pass[s] >> lane_) & 1u) << s;
        pending_samples_ = 0;
        if (!pass) return;
        const Owner o{draw, prim, true, ++seq_};
        if (visible_[std::size_t(draw)]) {
            // Depth written: the sample's winner so far, shaded later.
            for (int s = 0; s < samples_; ++s)
                if ((pass >> s) & 1u) owner_[s] = o;
        } else {
            pending_ = o;  // written only if the shader keeps it
            pending_samples_ = pass;
        }
    }

    template <int NV>
    void shaded(int draw, const FragmentBlock<NV>& in, std::uint32_t live) {
        if (in.x != bx_ || in.y != by_ || !((in.mask >> lane_) & 1u)) return;
        if (visible_[std::size_t(draw)]) {
            for (int s = 0; s < samples_; ++s)
                if (owner_[s].draw == draw && owner_[s].prim == in.prim_id) owner_[s].front = in.front_facing;
            return;
        }
        if (!pending_samples_ || pending_.draw != draw || pending_.prim != in.prim_id) return;
        if ((live >> lane_) & 1u) {
            pending_.front = in.front_facing;
            for (int s = 0; s < samples_; ++s)
                if ((pending_samples_ >> s) & 1u) owner_[s] = pending_;
        }
        pending_samples_ = 0;
    }

    int bx_, by_, lane_ = 0, samples_;
    FrameOptions::Visibility visibility_;
    std::vector<SceneDraw> draws_;
    std::vector<bool> visible_;
    Owner owner_[kMaxSamples];
    Owner pending_;
    std::uint32_t pending_samples_ = 0;
    std::uint64_t seq_ = 0;
};

// The ray through pixel centre (x, y): origin on the near plane, direction to the far plane.
void pixel_ray(const Camera& cam, int width, int height, glm::vec2 px, glm::vec3& origin, glm::vec3& dir) {
    const glm::mat4 inv = glm::inverse(cam.view_projection(float(width) / float(height)));
    const float x_ndc = (px.x + 0.5f) / float(width) * 2.0f - 1.0f;
    const float y_ndc = 1.0f - (px.y + 0.5f) / float(height) * 2.0f;
    glm::vec4 a = inv * glm::vec4(x_ndc, y_ndc, -1.0f, 1.0f), b = inv * glm::vec4(x_ndc, y_ndc, 1.0f, 1.0f);
    origin = glm::vec3(a) / a.w;
    dir = glm::vec3(b) / b.w - origin;
}

// Where the pixel's ray meets the winning triangle's plane (Moller-Trumbore):
// the barycentrics the environment's terms are evaluated at.
void ray_on_triangle(const Mesh& mesh, const Camera& cam, int width, int height, glm::ivec2 px, PixelHit& hit) {
    pixel_ray(cam, width, height, glm::vec2(px), hit.origin, hit.dir);
    const glm::vec3& p0 = mesh.positions[mesh.indices[hit.triangle * 3]];
    const glm::vec3 e1 = mesh.positions[mesh.indices[hit.triangle * 3 + 1]] - p0;
    const glm::vec3 e2 = mesh.positions[mesh.indices[hit.triangle * 3 + 2]] - p0;
    const glm::vec3 p = glm::cross(hit.dir, e2);
    const float det = glm::dot(e1, p);
    if (det == 0.0f) return;
    const glm::vec3 s = hit.origin - p0;
    hit.u = glm::dot(s, p) / det;
    hit.v = glm::dot(hit.dir, glm::cross(s, e1)) / det;
}

// The surface point a ray hit, interpolated from the triangle's vertices as
// the rasterizer would (barycentrics of the hit); the uv derivatives from the
// rays through the next pixel to the right and below, met on the triangle's plane.
SurfacePoint surface_at_hit(const Mesh& mesh, const PixelHit& hit, const Camera& cam, int width, int height,
                            glm::ivec2 px) {
    const std::uint32_t i0 = mesh.indices[hit.triangle * 3], i1 = mesh.indices[hit.triangle * 3 + 1],
                        i2 = mesh.indices[hit.triangle * 3 + 2];
    auto lerp3 = [&](const auto& attr, float u, float v, auto fallback) {
        using T = decltype(fallback);
        if (attr.size() <= std::max({i0, i1, i2})) return fallback;
        return T(attr[i0] * (1.0f - u - v) + attr[i1] * u + attr[i2] * v);
    };
    const glm::vec3 p0 = mesh.positions[i0], e1 = mesh.positions[i1] - p0, e2 = mesh.positions[i2] - p0;
    // Barycentrics where another pixel's ray meets the triangle's plane.
    auto plane_uv = [&](glm::vec2 at) {
        glm::vec3 o, d;
        pixel_ray(cam, width, height, at, o, d);
        const glm::vec3 p = glm::cross(d, e2);
        const float det = glm::dot(e1, p);
        if (det == 0.0f) return glm::vec2(hit.u, hit.v);
        const glm::vec3 s = o - p0, q = glm::cross(s, e1);
        return glm::vec2(glm::dot(s, p) / det, glm::dot(d, q) / det);
    };
    SurfacePoint sp;
    sp.P = lerp3(mesh.positions, hit.u, hit.v, glm::vec3(0.0f));
    sp.N = lerp3(mesh.normals, hit.u, hit.v, glm::vec3(0.0f, 0.0f, 1.0f));
    sp.T = lerp3(mesh.tangents, hit.u, hit.v, glm::vec4(1.0f, 0.0f, 0.0f, 1.0f));
    sp.uv = lerp3(mesh.uvs, hit.u, hit.v, glm::vec2(0.0f));
    const glm::vec2 bx = plane_uv(glm::vec2(px) + glm::vec2(1.0f, 0.0f)), by = plane_uv(glm::vec2(px) + glm::vec2(0.0f, 1.0f));
    sp.duv_dx = lerp3(mesh.uvs, bx.x, bx.y, glm::vec2(0.0f)) - sp.uv;
    sp.duv_dy = lerp3(mesh.uvs, by.x, by.y, glm::vec2(0.0f)) - sp.uv;
    sp.front_facing = hit.front_facing;
    return sp;
}

// The split sum's terms at the hit and the reference integral (--pixel with
// an environment): what the stepper shows, and the number it approximates.
void print_pixel_ibl(SceneRenderer& sr, const FrameSettings& settings, const Mesh& mesh, const PixelHit& hit,
                     int width, int height, glm::ivec2 px, int samples) {
    static const Material kFallback;
    static const BoundMaterial kFallbackBound = [] {
        BoundMaterial b;
        b.m = &kFallback;
        return b;
    }();
    const BoundMaterial& bm = mesh.material >= 0 && std::size_t(mesh.material) < sr.materials().size()
                                  ? sr.materials()[std::size_t(mesh.material)] : kFallbackBound;
    const SurfacePoint sp = surface_at_hit(mesh, hit, settings.camera, width, height, px);
    const MaterialSample ms = sample_material(bm, sp);
    ShadingContext ctx = sr.shading_context(settings);
    ctx.lights.clear();  // the environment's share alone
    const IblTerms t = ibl_terms(ms, sp, ctx);
    const glm::vec3 split = ibl_sum(t);  // with the sheen's and the clear coat's lobes where the material has them
    const glm::vec3 ref = ibl_reference(ms, sp, ctx, samples);
    std::printf("  ibl split-sum %.6g %.6g %.6g = diffuse %.6g %.6g %.6g + specular %.6g %.6g %.6g",
                double(split.r), double(split.g), double(split.b), double(t.diffuse.r), double(t.diffuse.g),
                double(t.diffuse.b), double(t.specular.r), double(t.specular.g), double(t.specular.b));
    if (t.sheen)
        std::printf(" + sheen %.6g %.6g %.6g", double(t.sheen_specular.r), double(t.sheen_specular.g),
                    double(t.sheen_specular.b));
    if (t.coat)
        std::printf(" + clear coat %.6g %.6g %.6g", double(t.coat_specular.r), double(t.coat_specular.g),
                    double(t.coat_specular.b));
    std::printf("\n");
    std::printf("  ibl terms: irradiance %.6g %.6g %.6g prefiltered %.6g %.6g %.6g level %.4f "
                "dfg scale %.6g bias %.6g diffuse %.6g n.v %.4f occlusion %.4g\n",
                double(t.irradiance.r), double(t.irradiance.g), double(t.irradiance.b), double(t.prefiltered.r),
                double(t.prefiltered.g), double(t.prefiltered.b), double(t.level), double(t.dfg_scale),
                double(t.dfg_bias), double(t.dfg_diffuse), double(t.NoV), double(t.occlusion));
    std::printf("  ibl reference (%d samples) %.6g %.6g %.6g\n", samples, double(ref.r), double(ref.g),
                double(ref.b));
}

void print_pixel(const Scene& scene, const Camera& cam, const Framebuffer& fb, const std::uint8_t* rgba8,
                 glm::ivec2 px, int frame, SceneRenderer& sr, const FrameSettings& settings, int ibl_samples,
                 const PixelWinner& winner) {
    const float* c = fb.pixel(px.x, px.y);
    const float depth = fb.depth[std::size_t(px.y) * std::size_t(fb.width) + std::size_t(px.x)];
    std::printf("pixel %d,%d frame %d: depth %.6f linear %.6g %.6g %.6g", px.x, px.y, frame, double(depth),
                double(c[0]), double(c[1]), double(c[2]));
    if (rgba8) {
        const std::uint8_t* s = &rgba8[(std::size_t(px.y) * std::size_t(fb.width) + std::size_t(px.x)) * 4];
        std::printf(" srgb8 %d %d %d", s[0], s[1], s[2]);
    }
    PixelHit hit = winner.winner();
    if (hit.draw < 0) {
        // Lines and points are not followed past their vertices (observer.h).
        std::printf(depth >= 1.0f ? " (background)\n" : " (no triangle wrote it: a line or point did; step explains it)\n");
        return;
    }
    const Mesh& mesh = scene.meshes[std::size_t(hit.mesh)];
    // The name step prints (stepper/explain.h triangle_name()).
    std::printf(" draw %d (mesh '%s') triangle %zu (frame triangle %u) material '%s', %s face", hit.draw,
                printable(mesh.name).c_str(), hit.triangle, hit.frame_triangle,
                printable(sr.material_of(mesh).m->name).c_str(), hit.front_facing ? "front" : "back");
    if (settings.samples > 1) std::printf(", %d of %d samples", hit.samples, settings.samples);
    std::printf("\n");
    ray_on_triangle(mesh, cam, fb.width, fb.height, px, hit);
    if (sr.environment(settings)) print_pixel_ibl(sr, settings, mesh, hit, fb.width, fb.height, px, ibl_samples);
}

// render --list: what the model holds, one item a line, names escaped.
int list_model(const RenderOptions& opt) {
    Scene scene;
    LoadOptions load_options;
    load_options.allow_outside_paths = opt.allow_outside_paths;
    try {
        scene = load_scene(opt.scene, load_options);
    } catch (const LoadError& e) {
        std::fprintf(stderr, "render: %s\n", printable(e.what()).c_str());
        return kExitBadFile;
    }
    for (const std::string& w : cap_warnings(scene.warnings))
        std::fprintf(stderr, "render: warning: %s\n", printable(w).c_str());
    const SceneSource* src = scene.source.get();
    auto name = [](const std::string& s) { return "'" + printable(cut(s)) + "'"; };
    std::printf("model %s\n", printable(opt.scene).c_str());
    std::printf("meshes %zu (%zu triangles)\n", scene.meshes.size(), scene.triangle_count());
    for (std::size_t i = 0; i < scene.meshes.size(); ++i) {
        const Mesh& m = scene.meshes[i];
        const char* kind = m.topology == Mesh::Topology::Lines ? "lines" : m.topology == Mesh::Topology::Points ? "points" : "triangles";
        const std::size_t per = m.topology == Mesh::Topology::Lines ? 2 : m.topology == Mesh::Topology::Points ? 1 : 3;
        std::string extra;
        if (src && m.source_node >= 0 && std::size_t(m.source_node) < src->nodes.size()) {
            const SourceNode& node = src->nodes[std::size_t(m.source_node)];
            extra += ", node " + std::to_string(m.source_node);
            if (node.skin >= 0) extra += ", skin " + std::to_string(node.skin);
            if (node.mesh >= 0 && src->meshes[std::size_t(node.mesh)].target_count > 0)
                extra += ", " + std::to_string(src->meshes[std::size_t(node.mesh)].target_count) + " morph targets";
        }
        std::printf("  mesh %zu %s: %zu %s, %zu vertices, material %d%s\n", i, name(m.name).c_str(),
                    m.indices.size() / per, kind, m.positions.size(), m.material, extra.c_str());
    }
    std::printf("materials %zu\n", scene.materials.size());
    for (std::size_t i = 0; i < scene.materials.size(); ++i)
        std::printf("  material %zu %s\n", i, name(scene.materials[i].name).c_str());
    std::printf("cameras %zu\n", scene.cameras.size());
    for (std::size_t i = 0; i < scene.cameras.size(); ++i) {
        const SceneCamera& c = scene.cameras[i];
        if (c.orthographic)
            std::printf("  camera %zu %s: orthographic, xmag %g ymag %g, znear %g zfar %g, node %d\n", i,
                        name(c.name).c_str(), c.xmag, c.ymag, c.znear, c.zfar, c.node);
        else if (c.zfar > 0.0)
            std::printf("  camera %zu %s: perspective, yfov %g degrees, znear %g zfar %g, node %d\n", i,
                        name(c.name).c_str(), glm::degrees(c.yfov), c.znear, c.zfar, c.node);
        else
            std::printf("  camera %zu %s: perspective, yfov %g degrees, znear %g zfar infinite, node %d\n", i,
                        name(c.name).c_str(), glm::degrees(c.yfov), c.znear, c.node);
    }
    std::printf("animations %zu\n", scene.animation_names.size());
    for (std::size_t i = 0; src && i < src->animations.size(); ++i) {
        const Animation& a = src->animations[i];
        std::size_t paths[4] = {0, 0, 0, 0};
        for (const AnimationChannel& c : a.channels) ++paths[int(c.path)];
        std::printf("  animation %zu %s: %g s (keys %g to %g s), %zu channels: %zu translation, %zu rotation, "
                    "%zu scale, %zu weights\n",
                    i, name(a.name).c_str(), a.end, a.start, a.end, a.channels.size(), paths[0], paths[1], paths[2],
                    paths[3]);
    }
    std::printf("skins %zu\n", src ? src->skins.size() : std::size_t(0));
    for (std::size_t i = 0; src && i < src->skins.size(); ++i)
        std::printf("  skin %zu: %zu joints\n", i, src->skins[i].joints.size());
    // KHR_materials_variants: a primitive remapped by a variant has a mapping for it.
    std::printf("variants %zu\n", scene.variants.size());
    for (std::size_t v = 0; v < scene.variants.size(); ++v) {
        std::size_t remapped = 0;
        for (const Mesh& m : scene.meshes) remapped += v < m.variant_materials.size() && m.variant_materials[v] >= 0;
        std::printf("  variant %zu %s: remaps %zu of %zu primitives\n", v, name(scene.variants[v]).c_str(), remapped,
                    scene.meshes.size());
    }
    auto joined = [](const std::vector<std::string>& v) {
        std::string out;
        for (const std::string& s : v) out += (out.empty() ? "" : ", ") + printable(cut(s));
        return out.empty() ? std::string("none") : out;
    };
    std::printf("extensions used: %s\n", joined(scene.extensions_used).c_str());
    std::printf("extensions required: %s\n", joined(scene.extensions_required).c_str());
    return 0;
}

int run(int argc, char** argv) {
    install_signal_cleanup();
    RenderOptions opt;
    const std::string usage_err = parse_render_args(argc, argv, opt);
    if (!usage_err.empty()) {
        std::fprintf(stderr, "render: %s\n", printable(usage_err).c_str());
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

    if (opt.list) return list_model(opt);
    // Fail on an unwritable output before spending time on the render: every
    // frame's directory, so a turntable cannot fail half-way.
    const cli::FramePattern pattern(opt.output);
    const std::string out_err = check_output_paths(pattern, opt.first_frame, opt.last_frame);
    if (!out_err.empty()) {
        std::fprintf(stderr, "render: %s\n", printable(out_err).c_str());
        return kExitBadFile;
    }

    const int frames_to_render = opt.last_frame - opt.first_frame + 1;
    Progress progress(2 + frames_to_render * opt.repeat);
    auto fail = [&](int code, const std::string& message) {
        progress.finish();
        std::fprintf(stderr, "render: %s\n", printable(message).c_str());
        return code;
    };

    // The frame: scene, camera, lights, memory plan, environment, renderer.
    const FrameRequest request = render_frame_request(opt);
    FrameSetup frame;
    auto on_stage = [&](FrameStage stage) {
        switch (stage) {
        case FrameStage::Load:
            progress.begin(0, opt.scene.empty() ? "building the default scene" : "loading " + opt.scene);
            if (!opt.scene.empty()) g_stage = "loading " + opt.scene;
            break;
        case FrameStage::PlanMemory: g_stage = "planning memory"; break;
        case FrameStage::StartThreads:
            progress.begin(1, "decoding textures");
            g_stage = "starting threads";
            break;
        case FrameStage::DecodeTextures: g_stage = "decoding textures"; break;
        case FrameStage::PrefilterEnvironment: progress.begin(1, "prefiltering the environment"); break;
        }
    };
    FrameError setup_err;
    try {
        setup_err = setup_frame(request, frame, on_stage);
    } catch (...) {
        for (const std::string& n : frame.notes) progress.note("render: " + n);  // before main's one line
        throw;
    }
    for (const std::string& n : frame.notes) progress.note("render: " + n);
    if (setup_err) return fail(setup_err.code, setup_err.message);
    const Scene& scene = frame.scene;
    Renderer& renderer = *frame.renderer;
    SceneRenderer& scene_renderer = *frame.scene_renderer;
    const Environment* environment = frame.environment.get();
    FrameSettings& settings = frame.settings;

    if (opt.stats) {
        std::printf("scene                  %zu triangles, %zu meshes, %zu materials, %zu images\n"
                    "time load              %.3f ms\ntime textures          %.3f ms\nthreads                %d, "
                    "tile %d\nlanes                  %s\n",
                    scene.triangle_count(), scene.meshes.size(), scene.materials.size(), scene.images.size(),
                    frame.load_ms, frame.textures_ms, renderer.threads(), renderer.tile_size(), lane_isa());
        if (environment) {
            const EnvironmentTimings& et = environment->timings();
            std::printf("environment            %dx%d\ntime environment       %.3f ms (mips %.3f, sh %.3f, "
                        "prefilter %.3f, sampler %.3f)\n",
                        environment->width(), environment->height(), frame.environment_ms, et.mips, et.sh, et.prefilter,
                        et.sampler);
        }
    }

    // Allocated only if a frame keeps its pixels (--pixel, .hdr, the overlay views).
    Framebuffer fb = Framebuffer::deferred(opt.width, opt.height);
    // The PNG's bytes come out of the frame's tile pass (resolve.h), which
    // streams whole cache lines (stream_fill.h) when the rows start on one.
    Rgba8Buffer rgba8_store(opt.hdr_output() ? 0 : std::size_t(opt.width) * std::size_t(opt.height));
    std::uint8_t* rgba8 = rgba8_store.data();
    const ImageOutput out8 = render_image_output(opt, rgba8);
    std::vector<double> frame_ms;
    std::optional<PixelWinner> winner;  // --pixel: the fragment that wrote it
    int step = 2;
    for (int index = opt.first_frame; index <= opt.last_frame; ++index) {
        // Frame i of a turntable sits at angle i * DEG / N around the target;
        // frame i of a sequence (--fps) at time --time + i / F, still unless --orbit.
        const double angle = opt.fps > 0.0 && !opt.orbit_given
                                 ? 0.0
                                 : glm::radians(double(index) * opt.orbit_deg / double(opt.frames));
        if (CameraFault f = frame.set_frame(index, angle)) return fail(kExitUsage, f.message);

        double render_ms = 0.0;
        for (int r = 0; r < opt.repeat; ++r) {
            progress.begin(step++, "frame " + std::to_string(index));
            g_stage = "rendering frame " + std::to_string(index);
            auto t0 = Clock::now();
            if (opt.pixel) {
                // The same frame, watched at the pixel for the fragment that wrote it.
                winner.emplace(opt.pixel->x, opt.pixel->y, settings.samples, settings.visibility);
                scene_renderer.render(settings, fb, opt.hdr_output() ? nullptr : &out8,
                                      [&](const SceneDraw& d) { return winner->tap(d); });
            } else {
                scene_renderer.render(settings, fb, opt.hdr_output() ? nullptr : &out8);
            }
            render_ms = ms_since(t0);
            frame_ms.push_back(render_ms);
        }

        auto t_write = Clock::now();
        const std::string path = pattern.format(index);
        progress.begin(step, "writing " + path);
        g_stage = "writing " + path;
        try {
            if (opt.hdr_output()) write_hdr_atomic(path, fb.width, fb.height, fb.color.data());
            else write_png_atomic(path, fb.width, fb.height, rgba8);
        } catch (const WriteError& e) {
            return fail(kExitBadFile, e.what());
        }
        if (opt.stats) {
            std::printf("frame                  %d\n%stime frame+resolve     %.3f ms\ntime write             %.3f ms\n",
                        index, renderer.stats().to_string().c_str(), render_ms, ms_since(t_write));
        }
        if (opt.pixel)
            print_pixel(scene, settings.camera, fb, rgba8, *opt.pixel, index, scene_renderer, settings,
                        opt.samples_given ? opt.ibl_samples : 4096, *winner);
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
#ifdef M_MMAP_THRESHOLD
    // One render, then exit: a decoder's large scratch buffers (inflated PNG
    // rows, decoded pixels), once freed, serve the next image from the heap
    // instead of being unmapped and faulted in (and zeroed) afresh.
    mallopt(M_MMAP_THRESHOLD, 256 << 20);
    mallopt(M_TRIM_THRESHOLD, 512 << 20);
#endif
    // Never crash: whatever escapes is one line and exit code 1.
    try {
        return run(argc, argv);
    } catch (const std::bad_alloc&) {
        std::fprintf(stderr, "render: out of memory while %s (try a smaller --size or a smaller scene)\n",
                     printable(g_stage).c_str());
    } catch (const std::system_error& e) {
        std::fprintf(stderr, "render: %s failed: %s\n", printable(g_stage).c_str(), printable(e.code().message()).c_str());
    } catch (const std::exception& e) {
        std::fprintf(stderr, "render: %s failed: %s\n", printable(g_stage).c_str(), printable(e.what()).c_str());
    }
    return kExitBadFile;
}

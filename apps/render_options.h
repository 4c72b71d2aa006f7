// The command line of `render`: the options struct, its defaults, and the
// parser that turns argv into it or into a one-line error naming the flag and
// the bad value. The flags themselves are defined once, in
// apps/cli/render_flags.cpp (library prast_cli), which also writes --help and
// docs/flags.md. No rendering happens here.
#pragma once

#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <optional>
#include <string>
#include <vector>

#include <unistd.h>

#include <glm/glm.hpp>

#include "apps/cli/values.h"
#include "raster/limits.h"
#include "scene/camera_request.h"
#include "shading/ibl/background.h"
#include "shading/brdf.h"
#include "shading/debug_view.h"
#include "renderer/memory_plan.h"
#include "shading/surface.h"
#include "shading/tonemap.h"

namespace prast {

// The project version, from CMake's project(VERSION ...).
#ifndef PRAST_VERSION
#define PRAST_VERSION "unknown"
#endif
constexpr const char* kRenderVersion = PRAST_VERSION;

// Memory a frame costs per pixel: the framebuffer (RGBA float colour 16 +
// float depth 4) and the 8-bit copy that is encoded.
constexpr std::uint64_t kFramebufferBytesPerPixel = 20;
constexpr std::uint64_t kImageBytesPerPixel = 4;
constexpr std::uint64_t kBytesPerPixel = kFramebufferBytesPerPixel + kImageBytesPerPixel;

// Caps on counts that no sensible job exceeds; they keep a typo (an extra
// zero) from starting a job that runs for days.
constexpr int kMaxThreads = 1024;
// Below this field of view the framing distance explodes (r / sin(fov / 2)).
constexpr double kMinFovDeg = 0.001;
constexpr long kMaxFrames = 1000000;
constexpr long kMaxRepeat = 100000;
constexpr long kMaxIblSamples = 1 << 20;
constexpr double kMaxEnvIntensity = 1e6;
constexpr double kMaxAnimationTime = 1e9;  // seconds; beyond, float key times mean nothing

// Samples per pixel unless --msaa says otherwise: docs/pipeline.md "Anti-aliasing"
// gives the measurements behind it.
constexpr int kDefaultMsaa = 4;

struct RenderOptions {
    std::string scene;                 // empty: the built-in default scene
    std::string output = "render.png"; // .png or .hdr; may hold one %d-style pattern
    int width = 1280, height = 720;
    std::optional<glm::vec3> eye, target, up;  // unset: from the scene's framing
    float fov_deg = 45.0f;
    std::optional<float> near_plane, far_plane;  // unset: fit_clip_planes
    std::vector<ShadingLight> lights;  // --sun and --point, in command-line order
    glm::vec3 ambient{0.03f};
    bool ambient_given = false;
    bool file_lights = true;                 // --file-lights off: the flags' lights replace the file's
    bool no_default_lights = false;
    // Image-based lighting (the built-in scene has a sky of its own).
    std::string env;                   // --env FILE.hdr
    float env_intensity = 1.0f;
    float env_rotate_deg = 0.0f;
    Background background = Background::Env;  // black when there is no environment
    glm::vec3 background_color{0.0f};
    IblMode ibl = IblMode::SplitSum;
    int ibl_samples = 256;             // --samples, for --ibl reference and --pixel
    bool samples_given = false;
    bool energy = false;               // --energy conserve
    BrdfModel brdf = BrdfModel::Default;
    ShadowSettings shadows{false, 2048};  // --shadows on|off, --shadow-size N
    float exposure = 1.0f;
    // Default aces (highlights roll off instead of clipping, so `render
    // model.glb` looks right at once); none when a --view shows raw data.
    ToneMap tonemap = ToneMap::Aces;
    bool tonemap_given = false;
    DebugView view = DebugView::None;
    int threads = 0;                   // 0: all hardware threads
    int tile_size = kDefaultTileSize;
    int msaa = kDefaultMsaa;           // samples per pixel (docs/pipeline.md "Anti-aliasing")
    int frames = 1;
    double orbit_deg = 360.0;          // total turntable angle over `frames`
    bool orbit_given = false;
    int first_frame = 0, last_frame = 0;  // inclusive, 0-based
    // Animation (scene/animation.h): the time of frame 0, which animation
    // (a name or an index; empty: every one), and with --fps a sequence
    // through time instead of a turntable.
    double time = 0.0;
    std::string animation;
    double fps = 0.0;                  // 0: --frames is a turntable
    std::string camera;                // --camera: a camera of the file (name or index); empty: framed
    std::string variant;               // --variant: a KHR_materials_variants variant (name or index); empty: none
    bool list = false;                 // --list: print the model's contents instead of rendering
    bool frame_range_given = false;
    int repeat = 1;
    bool repeat_given = false;         // print the frame_ms line
    bool stats = false;
    std::optional<glm::ivec2> pixel;
    bool allow_outside_paths = false;  // the model may name files outside its folder
    bool help = false, version = false;

    bool hdr_output() const;
    // What the flags say about the camera (scene/camera_request.h).
    CameraRequest camera_request() const { return {scene, eye, target, up, fov_deg, near_plane, far_plane}; }
    ToneMap effective_tonemap() const {
        return tonemap_given || view == DebugView::None ? tonemap : ToneMap::None;
    }
};

// The --help text, made from the flag definitions: fits an 80x24 terminal.
const char* render_usage();

namespace cli {

// The output name's frame-number pattern: one %d, %4d or %04d (any width up
// to 9), with %% for a literal percent. Formatted here rather than by printf
// so a stray %s in a file name cannot read arbitrary memory.
struct FramePattern {
    bool has_number = false;
    std::string error;  // non-empty: the name is not a valid pattern

    explicit FramePattern(const std::string& name) : name_(name) {
        for (std::size_t i = 0; i < name.size(); ++i) {
            if (name[i] != '%') continue;
            if (i + 1 < name.size() && name[i + 1] == '%') { ++i; continue; }
            std::size_t j = i + 1;
            bool zero = j < name.size() && name[j] == '0';
            if (zero) ++j;
            int width = 0;
            while (j < name.size() && name[j] >= '0' && name[j] <= '9' && width < 10)
                width = width * 10 + (name[j++] - '0');
            if (j >= name.size() || name[j] != 'd' || width > 9) {
                error = "'%" + name.substr(i + 1, j - i) + "' is not a frame-number pattern (use %04d)";
                return;
            }
            if (has_number) { error = "more than one frame-number pattern"; return; }
            has_number = true;
            zero_ = zero;
            width_ = width;
            begin_ = i;
            end_ = j + 1;
            i = j;
        }
    }

    std::string format(int frame) const {
        std::string number = std::to_string(frame);
        if (int(number.size()) < width_) number.insert(0, std::size_t(width_) - number.size(), zero_ ? '0' : ' ');
        std::string out;
        for (std::size_t i = 0; i < name_.size(); ++i) {
            if (has_number && i == begin_) { out += number; i = end_ - 1; continue; }
            if (name_[i] == '%' && i + 1 < name_.size() && name_[i + 1] == '%') ++i;
            out += name_[i];
        }
        return out;
    }

private:
    std::string name_;
    bool zero_ = false;
    int width_ = 0;
    std::size_t begin_ = 0, end_ = 0;
};

} // namespace cli

inline bool RenderOptions::hdr_output() const { return cli::ends_with(cli::lower(output), ".hdr"); }

// "" when a w x h image fits; otherwise the reason, with the bytes it needs.
inline std::string check_image_size(long w, long h, std::uint64_t budget_bytes) {
    const std::string size = std::to_string(w) + "x" + std::to_string(h);
    if (w < 1 || h < 1) return "--size " + size + ": width and height must be at least 1";
    const std::uint64_t bytes = std::uint64_t(w) * std::uint64_t(h) * kBytesPerPixel;
    const std::string need = "needs " + std::to_string(bytes) + " bytes (" +
                             std::to_string(kBytesPerPixel) + " per pixel)";
    if (w > kMaxViewportSize || h > kMaxViewportSize)
        return "--size " + size + ": too large: " + need + "; the limit is " +
               std::to_string(kMaxViewportSize) + " pixels per side";
    if (bytes > budget_bytes)
        return "--size " + size + ": too large: " + need + ", more than the " +
               std::to_string(budget_bytes) + " bytes allowed (half the physical memory)";
    return "";
}

// Parses argv[1..argc) into `out`. Returns "" on success, else one line
// (without the "render: " prefix) naming the flag and the bad value: a usage
// error, exit code 2. --help and --version stop the parse with out.help /
// out.version set. An unknown flag is answered with the nearest defined one.
std::string parse_render_args(int argc, const char* const* argv, RenderOptions& out,
                              std::uint64_t memory_budget = prast::memory_budget());

} // namespace prast

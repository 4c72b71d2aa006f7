// The command line of `render` (issue 4): the options struct, its defaults,
// and a parser that turns argv into it or into a one-line error naming the
// flag and the bad value. Header-only so the tests can check the parsing
// without running the executable. No rendering happens here.
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

// Samples per pixel unless --msaa says otherwise: README "Anti-aliasing"
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
    int msaa = kDefaultMsaa;           // samples per pixel (README "Anti-aliasing")
    int frames = 1;
    double orbit_deg = 360.0;          // total turntable angle over `frames`
    bool orbit_given = false;
    int first_frame = 0, last_frame = 0;  // inclusive, 0-based
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

// The --help text: fits an 80x24 terminal.
inline const char* render_usage() {
    return
"usage: render [SCENE] [options]    SCENE: .obj, .gltf or .glb; none: built-in\n"
"  -o, --output FILE    PNG (default render.png) or .hdr (linear radiance)\n"
"  --size WxH           image size in pixels (default 1280x720)\n"
"  --eye X,Y,Z --target X,Y,Z --up X,Y,Z   camera (default: framed on the scene)\n"
"  --fov DEG --near N --far F   field of view (default 45), clip planes (fitted)\n"
"  --sun X,Y,Z:R,G,B    directional light, X,Y,Z towards the light (repeatable)\n"
"  --point X,Y,Z:R,G,B  point light, radiance R,G,B / distance^2 (repeatable)\n"
"  --ambient R,G,B      ambient light (default 0.03,0.03,0.03)\n"
"  --no-default-lights  no key+fill rig when the scene and flags have no light\n"
"  --env FILE.hdr --env-intensity E --env-rotate DEG   image-based lighting\n"
"  --background env|blur|black|R,G,B  --ibl split-sum|reference --samples N\n"
"  --brdf default|gltf --energy off|conserve --msaa N (1, 2, 4, 8; default 4)\n"
"  --exposure E --tonemap none|aces|neutral   default 1, aces (none with --view)\n"
"  --view NAME          albedo normal roughness metallic uv depth overdraw tiles\n"
"                       ndf fresnel geometry diffuse specular irradiance\n"
"  --shadows on|off --shadow-size N   shadow maps (default off, 2048 texels)\n"
"  --threads N          default: all cores      --tile N  16..256 (default 64)\n"
"  --frames N --orbit DEG  turntable: N images orbiting the target around --up,\n"
"    DEG in total (default 360); FILE needs %04d; --frame-range A-B: frames A..B\n"
"  --repeat N           render N times; print frame_ms min=.. median=.. max=..\n"
"  --stats              per-stage counters and times  --pixel X,Y  probe a pixel\n"
"  --allow-outside-paths  let the model name files outside its own folder\n"
"  --help, --version    exit codes: 0 ok, 1 bad file or write, 2 bad usage\n";
}

namespace render_cli {

inline std::string lower(std::string s) {
    for (char& c : s)
        if (c >= 'A' && c <= 'Z') c = char(c - 'A' + 'a');
    return s;
}

inline bool ends_with(const std::string& s, const std::string& tail) {
    return s.size() >= tail.size() && s.compare(s.size() - tail.size(), tail.size(), tail) == 0;
}

inline std::vector<std::string> split(const std::string& s, char sep) {
    std::vector<std::string> parts;
    std::size_t begin = 0;
    for (;;) {
        std::size_t end = s.find(sep, begin);
        parts.push_back(s.substr(begin, end == std::string::npos ? std::string::npos : end - begin));
        if (end == std::string::npos) return parts;
        begin = end + 1;
    }
}

// A whole string as a finite number; strtod alone would accept "1.5abc",
// "nan" and "inf".
inline bool parse_finite(const std::string& s, double& out) {
    if (s.empty() || s.find_first_of(" \t\n") != std::string::npos) return false;
    errno = 0;
    char* end = nullptr;
    double v = std::strtod(s.c_str(), &end);
    if (end != s.c_str() + s.size() || errno == ERANGE || !std::isfinite(v)) return false;
    // Values beyond float range would become inf once stored.
    if (std::fabs(v) > 3.0e38) return false;
    out = v;
    return true;
}

inline bool parse_integer(const std::string& s, long& out) {
    if (s.empty() || s.find_first_of(" \t\n") != std::string::npos) return false;
    errno = 0;
    char* end = nullptr;
    long v = std::strtol(s.c_str(), &end, 10);
    if (end != s.c_str() + s.size() || errno == ERANGE) return false;
    out = v;
    return true;
}

inline bool parse_vec3(const std::string& s, glm::vec3& out) {
    std::vector<std::string> parts = split(s, ',');
    if (parts.size() != 3) return false;
    for (int i = 0; i < 3; ++i) {
        double v;
        if (!parse_finite(parts[std::size_t(i)], v)) return false;
        out[i] = float(v);
    }
    return true;
}

inline bool non_negative(const glm::vec3& v) { return v.x >= 0.0f && v.y >= 0.0f && v.z >= 0.0f; }

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

} // namespace render_cli

inline bool RenderOptions::hdr_output() const { return render_cli::ends_with(render_cli::lower(output), ".hdr"); }

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
// out.version set.
inline std::string parse_render_args(int argc, const char* const* argv, RenderOptions& out,
                                     std::uint64_t memory_budget = prast::memory_budget()) {
    using namespace render_cli;
    bool frames_given = false, only_positional = false;
    std::string range_text;
    std::string needs_env;  // the first flag given that needs an environment, with its value
    for (int i = 1; i < argc; ++i) {
        std::string arg = argv[i];
        if (only_positional || arg.empty() || arg[0] != '-' || arg == "-") {
            if (!out.scene.empty()) return "unexpected argument '" + arg + "' (one SCENE at most)";
            if (arg.empty()) return "empty SCENE argument";
            out.scene = arg;
            continue;
        }
        if (arg == "--") { only_positional = true; continue; }
        // --flag=value is accepted as well as --flag value.
        std::string flag = arg, inline_value;
        bool has_inline = false;
        std::size_t eq = arg.find('=');
        if (arg.compare(0, 2, "--") == 0 && eq != std::string::npos) {
            flag = arg.substr(0, eq);
            inline_value = arg.substr(eq + 1);
            has_inline = true;
        }
        auto value = [&](const char* what, std::string& v) -> std::string {
            if (has_inline) { v = inline_value; return ""; }
            if (i + 1 >= argc) return flag + ": missing value (" + what + ")";
            v = argv[++i];
            return "";
        };
        auto bad = [&](const std::string& v, const std::string& why) {
            return flag + " '" + v + "': " + why;
        };
        auto no_value = [&]() -> std::string {
            return has_inline ? flag + ": takes no value" : "";
        };
        std::string v, err;

        if (flag == "--help" || flag == "-h") {
            if (!(err = no_value()).empty()) return err;
            out.help = true;
            return "";
        } else if (flag == "--version") {
            if (!(err = no_value()).empty()) return err;
            out.version = true;
            return "";
        } else if (flag == "-o" || flag == "--output") {
            if (!(err = value("FILE", v)).empty()) return err;
            if (v.empty()) return flag + ": empty file name";
            std::string l = lower(v);
            if (!ends_with(l, ".png") && !ends_with(l, ".hdr"))
                return bad(v, "unknown output format (expected a .png or .hdr file name)");
            FramePattern pattern(v);
            if (!pattern.error.empty()) return bad(v, pattern.error);
            out.output = v;
        } else if (flag == "--size") {
            if (!(err = value("WxH", v)).empty()) return err;
            std::size_t x = lower(v).find('x');
            long w, h;
            if (x == std::string::npos || !parse_integer(v.substr(0, x), w) ||
                !parse_integer(v.substr(x + 1), h))
                return bad(v, "expected WxH, e.g. 1280x720");
            std::string size_err = check_image_size(w, h, memory_budget);
            if (!size_err.empty()) return size_err;
            out.width = int(w);
            out.height = int(h);
        } else if (flag == "--eye" || flag == "--target" || flag == "--up") {
            if (!(err = value("X,Y,Z", v)).empty()) return err;
            glm::vec3 p;
            if (!parse_vec3(v, p)) return bad(v, "expected three finite numbers X,Y,Z");
            if (flag == "--up" && glm::dot(p, p) == 0.0f) return bad(v, "the up vector must not be zero");
            if (flag != "--up" && !(std::fabs(p.x) <= kMaxCameraCoordinate && std::fabs(p.y) <= kMaxCameraCoordinate &&
                                    std::fabs(p.z) <= kMaxCameraCoordinate))
                return bad(v, "coordinates beyond +-1e18 cannot be rendered in single precision");
            (flag == "--eye" ? out.eye : flag == "--target" ? out.target : out.up) = p;
        } else if (flag == "--fov") {
            if (!(err = value("DEG", v)).empty()) return err;
            double d;
            if (!parse_finite(v, d)) return bad(v, "not a finite number");
            if (!(d >= kMinFovDeg && d < 180.0))
                return bad(v, "must be at least 0.001 and less than 180 degrees");
            out.fov_deg = float(d);
        } else if (flag == "--near" || flag == "--far") {
            if (!(err = value("distance", v)).empty()) return err;
            double d;
            if (!parse_finite(v, d)) return bad(v, "not a finite number");
            if (!(d > 0.0)) return bad(v, "must be a positive distance");
            (flag == "--near" ? out.near_plane : out.far_plane) = float(d);
        } else if (flag == "--sun" || flag == "--point") {
            if (!(err = value("X,Y,Z:R,G,B", v)).empty()) return err;
            std::vector<std::string> halves = split(v, ':');
            glm::vec3 xyz, rgb;
            if (halves.size() != 2 || !parse_vec3(halves[0], xyz) || !parse_vec3(halves[1], rgb))
                return bad(v, "expected X,Y,Z:R,G,B with finite numbers");
            if (!non_negative(rgb)) return bad(v, "the radiance R,G,B must not be negative");
            ShadingLight light;
            light.radiance = rgb;
            if (flag == "--sun") {
                float len = glm::length(xyz);
                if (!(len > 0.0f) || !std::isfinite(len)) return bad(v, "the direction must not be zero");
                light.direction = xyz / len;
            } else {
                light.point = true;
                light.position = xyz;
            }
            out.lights.push_back(light);
        } else if (flag == "--ambient") {
            if (!(err = value("R,G,B", v)).empty()) return err;
            glm::vec3 rgb;
            if (!parse_vec3(v, rgb)) return bad(v, "expected three finite numbers R,G,B");
            if (!non_negative(rgb)) return bad(v, "must not be negative");
            out.ambient = rgb;
            out.ambient_given = true;
        } else if (flag == "--no-default-lights") {
            if (!(err = no_value()).empty()) return err;
            out.no_default_lights = true;
        } else if (flag == "--env") {
            if (!(err = value("FILE.hdr", v)).empty()) return err;
            if (v.empty()) return flag + ": empty file name";
            if (!ends_with(lower(v), ".hdr")) return bad(v, "expected an equirectangular Radiance .hdr file");
            out.env = v;
        } else if (flag == "--env-intensity") {
            if (!(err = value("E", v)).empty()) return err;
            double d;
            if (!parse_finite(v, d)) return bad(v, "not a finite number");
            if (d < 0.0 || d > kMaxEnvIntensity) return bad(v, "must be between 0 and 1e6");
            out.env_intensity = float(d);
            if (needs_env.empty()) needs_env = flag + " '" + v + "'";
        } else if (flag == "--env-rotate") {
            if (!(err = value("DEG", v)).empty()) return err;
            double d;
            if (!parse_finite(v, d) || std::fabs(d) > 1e6) return bad(v, "not a finite number of degrees");
            out.env_rotate_deg = float(std::fmod(d, 360.0));
            if (needs_env.empty()) needs_env = flag + " '" + v + "'";
        } else if (flag == "--background") {
            if (!(err = value("env|blur|black|R,G,B", v)).empty()) return err;
            glm::vec3 rgb;
            if ((v == "env" || v == "blur") && needs_env.empty()) needs_env = flag + " " + v;
            if (v == "env") out.background = Background::Env;
            else if (v == "blur") out.background = Background::Blur;
            else if (v == "black") out.background = Background::Black;
            else if (parse_vec3(v, rgb) && non_negative(rgb)) {
                out.background = Background::Color;
                out.background_color = rgb;
            } else {
                return bad(v, "expected env, blur, black or R,G,B (finite, not negative)");
            }
        } else if (flag == "--ibl") {
            if (!(err = value("split-sum|reference", v)).empty()) return err;
            if (v == "split-sum") out.ibl = IblMode::SplitSum;
            else if (v == "reference") out.ibl = IblMode::Reference;
            else return bad(v, "expected split-sum or reference");
            if (needs_env.empty()) needs_env = flag + " " + v;
        } else if (flag == "--samples") {
            if (!(err = value("N", v)).empty()) return err;
            long n;
            if (!parse_integer(v, n)) return bad(v, "not an integer");
            if (n < 1 || n > kMaxIblSamples) return bad(v, "must be between 1 and " + std::to_string(kMaxIblSamples));
            out.ibl_samples = int(n);
            out.samples_given = true;
        } else if (flag == "--energy") {
            if (!(err = value("off|conserve", v)).empty()) return err;
            if (v == "off") out.energy = false;
            else if (v == "conserve") out.energy = true;
            else return bad(v, "expected off or conserve");
        } else if (flag == "--brdf") {
            if (!(err = value("default|gltf", v)).empty()) return err;
            if (!parse_brdf_model(v, out.brdf)) return bad(v, "expected default or gltf");
        } else if (flag == "--shadows") {
            if (!(err = value("on|off", v)).empty()) return err;
            if (v != "on" && v != "off") return bad(v, "expected on or off");
            out.shadows.enabled = v == "on";
        } else if (flag == "--shadow-size") {
            if (!(err = value("N", v)).empty()) return err;
            long n;
            if (!parse_integer(v, n)) return bad(v, "not an integer");
            if (n < kMinShadowSize || n > kMaxShadowSize)
                return bad(v, "must be between " + std::to_string(kMinShadowSize) + " and " +
                                  std::to_string(kMaxShadowSize) + " texels");
            out.shadows.size = int(n);
        } else if (flag == "--exposure") {
            if (!(err = value("E", v)).empty()) return err;
            double d;
            if (!parse_finite(v, d)) return bad(v, "not a finite number");
            if (!(d > 0.0)) return bad(v, "must be positive");
            out.exposure = float(d);
        } else if (flag == "--tonemap") {
            if (!(err = value("none|aces|neutral", v)).empty()) return err;
            if (!parse_tonemap(v, out.tonemap)) return bad(v, "expected none, aces or neutral");
            out.tonemap_given = true;
        } else if (flag == "--view") {
            if (!(err = value("NAME", v)).empty()) return err;
            if (!parse_debug_view(v, out.view))
                return bad(v, std::string("unknown view; expected one of ") + debug_view_names());
        } else if (flag == "--msaa") {
            if (!(err = value("N", v)).empty()) return err;
            long n;
            if (!parse_integer(v, n) || (n != 1 && n != 2 && n != 4 && n != 8)) return bad(v, "must be 1, 2, 4 or 8");
            out.msaa = int(n);
        } else if (flag == "--threads" || flag == "--tile" || flag == "--frames" || flag == "--repeat") {
            if (!(err = value("N", v)).empty()) return err;
            long n;
            if (!parse_integer(v, n)) return bad(v, "not an integer");
            if (flag == "--threads") {
                if (n < 1 || n > kMaxThreads)
                    return bad(v, "must be between 1 and " + std::to_string(kMaxThreads));
                out.threads = int(n);
            } else if (flag == "--tile") {
                if (n < kMinTileSize || n > kMaxTileSize || (n & (n - 1)) != 0)
                    return bad(v, "must be a power of two from 16 to 256");
                out.tile_size = int(n);
            } else if (flag == "--frames") {
                if (n < 1 || n > kMaxFrames) return bad(v, "must be between 1 and " + std::to_string(kMaxFrames));
                out.frames = int(n);
                frames_given = true;
            } else {
                if (n < 1 || n > kMaxRepeat) return bad(v, "must be between 1 and " + std::to_string(kMaxRepeat));
                out.repeat = int(n);
                out.repeat_given = true;
            }
        } else if (flag == "--orbit") {
            if (!(err = value("DEG", v)).empty()) return err;
            double d;
            // Negative turns the other way round the up axis.
            if (!parse_finite(v, d) || std::fabs(d) > 1e6) return bad(v, "not a finite number of degrees");
            out.orbit_deg = d;
            out.orbit_given = true;
        } else if (flag == "--frame-range") {
            if (!(err = value("A-B", v)).empty()) return err;
            std::vector<std::string> ab = split(v, '-');
            long a, b;
            if (ab.size() != 2 || !parse_integer(ab[0], a) || !parse_integer(ab[1], b) || a < 0 || b < 0)
                return bad(v, "expected A-B with 0 <= A <= B, e.g. 0-9");
            if (a > b) return bad(v, "the first frame is after the last");
            if (b >= kMaxFrames) return bad(v, "frame number too large");
            out.first_frame = int(a);
            out.last_frame = int(b);
            out.frame_range_given = true;
            range_text = v;
        } else if (flag == "--allow-outside-paths") {
            if (!(err = no_value()).empty()) return err;
            out.allow_outside_paths = true;
        } else if (flag == "--stats") {
            if (!(err = no_value()).empty()) return err;
            out.stats = true;
        } else if (flag == "--pixel") {
            if (!(err = value("X,Y", v)).empty()) return err;
            std::vector<std::string> xy = split(v, ',');
            long x, y;
            if (xy.size() != 2 || !parse_integer(xy[0], x) || !parse_integer(xy[1], y) || x < 0 || y < 0)
                return bad(v, "expected X,Y with non-negative integers");
            if (x > kMaxViewportSize || y > kMaxViewportSize) return bad(v, "outside the image");
            out.pixel = glm::ivec2(int(x), int(y));
        } else {
            return "unknown option '" + arg + "' (render --help lists them)";
        }
    }

    // Checks that need every flag.
    if (out.pixel && (out.pixel->x >= out.width || out.pixel->y >= out.height))
        return "--pixel '" + std::to_string(out.pixel->x) + "," + std::to_string(out.pixel->y) +
               "': outside the " + std::to_string(out.width) + "x" + std::to_string(out.height) + " image";
    if (out.near_plane && out.far_plane && !(*out.near_plane < *out.far_plane))
        return "--near/--far: near (" + std::to_string(*out.near_plane) + ") must be less than far (" +
               std::to_string(*out.far_plane) + ")";
    // Environment flags need an environment: --env, or the built-in scene's sky.
    if (!needs_env.empty() && out.env.empty() && !out.scene.empty())
        return needs_env + ": needs --env FILE.hdr (the scene has no environment)";
    if (out.samples_given && out.ibl != IblMode::Reference && !out.pixel)
        return "--samples: only used with --ibl reference (or --pixel)";
    if (out.orbit_given && !frames_given) return "--orbit: needs --frames N (the number of turntable images)";
    render_cli::FramePattern pattern(out.output);
    if (out.frames > 1 && !pattern.has_number)
        return "-o '" + out.output + "': a turntable of " + std::to_string(out.frames) +
               " frames needs a frame number in the file name, e.g. frame%04d.png";
    if (out.frame_range_given) {
        if (out.last_frame >= out.frames)
            return "--frame-range '" + range_text + "': the turntable has frames 0-" +
                   std::to_string(out.frames - 1) + " (--frames " + std::to_string(out.frames) + ")";
    } else {
        out.first_frame = 0;
        out.last_frame = out.frames - 1;
    }
    return "";
}

} // namespace prast

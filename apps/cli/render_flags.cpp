// render's flags, one definition each: the parse, the --help rows and the
// flags page; see render_flags.h. The messages name the flag as typed and
// the bad value.
#include "apps/cli/render_flags.h"

#include <algorithm>
#include <cmath>

#include "apps/cli/values.h"

namespace prast {

namespace cli {

namespace {

// The view names of debug_view_names() as --help lines at most `width` wide.
std::string wrapped_view_names(std::size_t width) {
    std::string names = debug_view_names(), out, line;
    for (const std::string& word : split(names, ',')) {
        std::string w = word;
        while (!w.empty() && w[0] == ' ') w.erase(0, 1);
        if (w.empty()) continue;
        if (!line.empty() && line.size() + 1 + w.size() > width) {
            out += (out.empty() ? "" : "\n") + line;
            line.clear();
        }
        line += (line.empty() ? "" : " ") + w;
    }
    return out + (out.empty() ? "" : "\n") + line;
}

} // namespace

const std::vector<std::string>& render_only_flags() {
    static const std::vector<std::string> flags = {"-o",       "--output", "--frames", "--orbit",
                                                   "--frame-range", "--repeat", "--view", "--stats",
                                                   "--allow-outside-paths", "--fps", "--list"};
    return flags;
}

void add_render_flags(FlagSet& set, RenderParse& st, bool render_only) {
    RenderOptions& o = st.out;
    auto wanted = [&](const char* name) {
        if (render_only) return true;
        const auto& r = render_only_flags();
        return std::find(r.begin(), r.end(), name) == r.end();
    };
    auto needs_env = [&st](const std::string& given) {
        if (st.needs_env.empty()) st.needs_env = given;
    };
    auto finite = [](const std::string& flag, const std::string& v) {
        double d;
        if (!parse_finite(v, d)) bad_value(flag, v, "not a finite number");
        return d;
    };
    auto integer = [](const std::string& flag, const std::string& v) {
        long n;
        if (!parse_integer(v, n)) bad_value(flag, v, "not an integer");
        return n;
    };

    Flag& help = set.toggle({"-h", "--help"}, "this text", [&o] { o.help = true; });
    help.stops = true;
    help.help = "Prints the flags and exits (exit code 0).";
    Flag& version = set.toggle({"--version"}, "the version", [&o] { o.version = true; });
    version.stops = true;
    version.help = "Prints the version and exits.";

    if (wanted("--output")) {
        Flag& f = set.value({"-o", "--output"}, "FILE", "PNG (default render.png) or .hdr (linear radiance)",
                            "render.png", {"out.jpg", "out%s.png", ""}, [&o](const std::string& flag, const std::string& v) {
                                if (v.empty()) fail(flag + ": empty file name");
                                const std::string l = lower(v);
                                if (!ends_with(l, ".png") && !ends_with(l, ".hdr"))
                                    bad_value(flag, v, "unknown output format (expected a .png or .hdr file name)");
                                cli::FramePattern pattern(v);
                                if (!pattern.error.empty()) bad_value(flag, v, pattern.error);
                                o.output = v;
                            });
        f.help = "The image to write: `.png` (8-bit sRGB) or `.hdr` (linear radiance, Radiance RGBE). A turntable "
                 "(`--frames`) needs one frame-number pattern in the name: `%d`, `%4d` or `%04d` (`%%` is a "
                 "literal percent).";
        f.hints = {"out", "file", "png", "image", "output-file"};
    }
    {
        Flag& f = set.value({"--size"}, "WxH", "image size in pixels (default 1280x720)", "1280x720",
                            {"96", "0x0", "100000x100000", "axb"},
                            [&st](const std::string& flag, const std::string& v) {
                                long w = 0, h = 0;
                                if (!parse_size(v, w, h)) bad_value(flag, v, "expected WxH, e.g. 1280x720");
                                const std::string err = check_image_size(w, h, st.memory_budget);
                                if (!err.empty()) fail(err);
                                st.out.width = int(w);
                                st.out.height = int(h);
                            });
        f.help = "Image width and height in pixels, at most 16384 per side and within half the physical memory "
                 "(24 bytes a pixel).";
        f.hints = {"resolution", "res", "dimensions", "dims", "width", "height", "wxh"};
    }
    auto point = [](std::optional<glm::vec3>& dst, bool up) {
        return [&dst, up](const std::string& flag, const std::string& v) {
            glm::vec3 p;
            if (!parse_vec3(v, p)) bad_value(flag, v, "expected three finite numbers X,Y,Z");
            if (up && glm::dot(p, p) == 0.0f) bad_value(flag, v, "the up vector must not be zero");
            if (!up && !(std::fabs(p.x) <= kMaxCameraCoordinate && std::fabs(p.y) <= kMaxCameraCoordinate &&
                         std::fabs(p.z) <= kMaxCameraCoordinate))
                bad_value(flag, v, "coordinates beyond +-1e18 cannot be rendered in single precision");
            dst = p;
        };
    };
    {
        Flag& f = set.value({"--eye"}, "X,Y,Z", "camera position", "framed on the scene", {"1,2,x", "0,0,2e18"},
                            point(o.eye, false));
        f.help = "Camera position. Unset: the model framed so that its vertices fill 90% of the tighter axis of "
                 "the image, seen from +Z a little above (the built-in scene has a camera of its own).";
        f.hints = {"camera", "position", "from", "cam", "camera-position", "look-from"};
        Flag& t = set.value({"--target"}, "X,Y,Z", "the point looked at", "the framed centre", {"1,2", "-1e19,0,0"},
                            point(o.target, false));
        t.help = "The point the camera looks at. Unset: the framing's, which centres the model's projection in "
                 "the image.";
        t.hints = {"look-at", "lookat", "at", "center", "centre", "focus"};
        Flag& u = set.value({"--up"}, "X,Y,Z", "the camera's up direction", "0,1,0", {"0,0,0"}, point(o.up, true));
        u.help = "The camera's up direction (not zero, not along the view); the turntable orbits around it.";
        u.hints = {"up-vector", "vup"};
    }
    {
        Flag& f = set.value({"--fov"}, "DEG", "vertical field of view in degrees", "45", {"nan", "180", "0.0001"},
                            [&o, finite](const std::string& flag, const std::string& v) {
                                const double d = finite(flag, v);
                                if (!(d >= kMinFovDeg && d < 180.0))
                                    bad_value(flag, v, "must be at least 0.001 and less than 180 degrees");
                                o.fov_deg = float(d);
                            });
        f.help = "Vertical field of view in degrees, at least 0.001 and less than 180.";
        f.hints = {"field-of-view", "angle", "fovy", "zoom"};
        auto clip = [&o, finite](bool near) {
            return [&o, finite, near](const std::string& flag, const std::string& v) {
                const double d = finite(flag, v);
                if (!(d > 0.0)) bad_value(flag, v, "must be a positive distance");
                (near ? o.near_plane : o.far_plane) = float(d);
            };
        };
        Flag& n = set.value({"--near"}, "N", "near clip plane", "fitted to the scene", {"-1", "x"}, clip(true));
        n.help = "Near clip plane distance (positive, less than `--far`). Unset: fitted to the scene's bounds.";
        n.hints = {"znear", "near-plane", "clip-near"};
        Flag& fa = set.value({"--far"}, "F", "far clip plane", "fitted to the scene", {"0", "inf"}, clip(false));
        fa.help = "Far clip plane distance. Unset: fitted to the scene's bounds.";
        fa.hints = {"zfar", "far-plane", "clip-far"};
    }
    auto light = [&o](bool is_point) {
        return [&o, is_point](const std::string& flag, const std::string& v) {
            std::vector<std::string> halves = split(v, ':');
            glm::vec3 xyz, rgb;
            if (halves.size() != 2 || !parse_vec3(halves[0], xyz) || !parse_vec3(halves[1], rgb))
                bad_value(flag, v, "expected X,Y,Z:R,G,B with finite numbers");
            if (!non_negative(rgb)) bad_value(flag, v, "the radiance R,G,B must not be negative");
            ShadingLight l;
            l.radiance = rgb;
            if (!is_point) {
                const float len = glm::length(xyz);
                if (!(len > 0.0f) || !std::isfinite(len)) bad_value(flag, v, "the direction must not be zero");
                l.direction = xyz / len;
            } else {
                l.point = true;
                l.position = xyz;
            }
            o.lights.push_back(l);
        };
    };
    {
        Flag& s = set.value({"--sun"}, "X,Y,Z:R,G,B", "directional light, X,Y,Z towards the light (repeatable)", "",
                            {"0,1,0", "0,0,0:1,1,1", "0,1,0:-1,1,1"}, light(false));
        s.help = "A directional light: X,Y,Z points towards the light, R,G,B is its radiance (not negative). "
                 "Repeatable; lights keep command-line order.";
        s.hints = {"light", "directional", "dir-light", "sunlight"};
        Flag& p = set.value({"--point"}, "X,Y,Z:R,G,B", "point light, radiance R,G,B / distance^2 (repeatable)", "",
                            {"nan,0,0:1,1,1"}, light(true));
        p.help = "A point light at X,Y,Z: radiance R,G,B divided by the squared distance. Repeatable.";
        p.hints = {"point-light", "lamp", "bulb"};
        Flag& a = set.value({"--ambient"}, "R,G,B", "ambient light (default 0.03,0.03,0.03)", "0.03,0.03,0.03",
                            {"1,2", "-1,0,0", "nan,0,0"}, [&o](const std::string& flag, const std::string& v) {
                                glm::vec3 rgb;
                                if (!parse_vec3(v, rgb)) bad_value(flag, v, "expected three finite numbers R,G,B");
                                if (!non_negative(rgb)) bad_value(flag, v, "must not be negative");
                                o.ambient = rgb;
                                o.ambient_given = true;
                            });
        a.help = "Constant ambient light (not negative); not used when an environment lights the scene.";
        a.hints = {"ambient-light", "fill"};
        Flag& n = set.toggle({"--no-default-lights"}, "no key+fill rig when the scene and flags have no light",
                             [&o] { o.no_default_lights = true; });
        n.help = "Without lights in the scene or the flags, render adds a key and a fill light; this leaves the "
                 "scene unlit instead.";
        n.hints = {"no-lights", "nolights", "no-rig", "unlit"};
        Flag& f = set.value({"--file-lights"}, "on|off", "the model's own lights (default on)", "on", {"no"},
                            [&o](const std::string& flag, const std::string& v) {
                                if (v != "on" && v != "off") bad_value(flag, v, "expected on or off");
                                o.file_lights = v == "on";
                            });
        f.help = "The lights the model file defines (glTF KHR_lights_punctual), in the file's units (lux, "
                 "candela): on by default, with --sun and --point added to them; off leaves them out, so the "
                 "flags' lights (or, with none, the key and fill rig) replace them.";
        f.hints = {"model-lights", "scene-lights", "gltf-lights"};
    }
    {
        Flag& e = set.value({"--env"}, "FILE.hdr", "image-based lighting from an equirectangular .hdr", "",
                            {"sky.png", ""}, [&o](const std::string& flag, const std::string& v) {
                                if (v.empty()) fail(flag + ": empty file name");
                                if (!ends_with(lower(v), ".hdr"))
                                    bad_value(flag, v, "expected an equirectangular Radiance .hdr file");
                                o.env = v;
                            });
        e.help = "Image-based lighting from an equirectangular Radiance `.hdr` (diffuse irradiance and prefiltered "
                 "specular). The built-in scene has a sky of its own.";
        e.hints = {"hdri", "environment", "envmap", "env-map", "skybox", "sky", "ibl-file"};
        Flag& i = set.value({"--env-intensity"}, "E", "environment scale", "1", {"-1", "nan", "2e6"},
                            [&o, finite, needs_env](const std::string& flag, const std::string& v) {
                                const double d = finite(flag, v);
                                if (d < 0.0 || d > kMaxEnvIntensity) bad_value(flag, v, "must be between 0 and 1e6");
                                o.env_intensity = float(d);
                                needs_env(flag + " '" + v + "'");
                            });
        i.help = "Scales the environment's radiance, 0 to 1e6. Needs an environment.";
        i.hints = {"env-strength", "env-scale", "ibl-intensity"};
        Flag& r = set.value({"--env-rotate"}, "DEG", "environment rotation about +y", "0", {"inf", "x"},
                            [&o, needs_env](const std::string& flag, const std::string& v) {
                                double d;
                                if (!parse_finite(v, d) || std::fabs(d) > 1e6)
                                    bad_value(flag, v, "not a finite number of degrees");
                                o.env_rotate_deg = float(std::fmod(d, 360.0));
                                needs_env(flag + " '" + v + "'");
                            });
        r.help = "Turns the environment about the up axis (+y) by DEG degrees. Needs an environment.";
        r.hints = {"env-rotation", "rotate-env", "env-angle"};
        Flag& b = set.value({"--background"}, "env|blur|black|R,G,B", "what the background shows", "env",
                            {"grey", "1,nan,0", "-1,0,0"}, [&o, needs_env](const std::string& flag, const std::string& v) {
                                glm::vec3 rgb;
                                if (v == "env" || v == "blur") needs_env(flag + " " + v);
                                if (v == "env") o.background = Background::Env;
                                else if (v == "blur") o.background = Background::Blur;
                                else if (v == "black") o.background = Background::Black;
                                else if (parse_vec3(v, rgb) && non_negative(rgb)) {
                                    o.background = Background::Color;
                                    o.background_color = rgb;
                                } else {
                                    bad_value(flag, v, "expected env, blur, black or R,G,B (finite, not negative)");
                                }
                            });
        b.help = "The background: the environment (`env`), the environment blurred (`blur`), `black`, or a linear "
                 "colour R,G,B. Black without an environment.";
        b.hints = {"bg", "backdrop", "clear-color", "clear-colour", "sky-color"};
        Flag& ibl = set.value({"--ibl"}, "split-sum|reference", "environment integration", "split-sum", {"exact"},
                              [&o, needs_env](const std::string& flag, const std::string& v) {
                                  if (v == "split-sum") o.ibl = IblMode::SplitSum;
                                  else if (v == "reference") o.ibl = IblMode::Reference;
                                  else bad_value(flag, v, "expected split-sum or reference");
                                  needs_env(flag + " " + v);
                              });
        ibl.help = "How the environment is integrated: the split-sum approximation, or a Monte Carlo `reference` "
                   "(slow; `--samples` per pixel). Needs an environment.";
        ibl.hints = {"ibl-mode", "integration"};
        Flag& s = set.value({"--samples"}, "N", "Monte Carlo samples for --ibl reference and --pixel", "256",
                            {"0", "x"}, [&o, integer](const std::string& flag, const std::string& v) {
                                const long n = integer(flag, v);
                                if (n < 1 || n > kMaxIblSamples)
                                    bad_value(flag, v, "must be between 1 and " + std::to_string(kMaxIblSamples));
                                o.ibl_samples = int(n);
                                o.samples_given = true;
                            });
        s.help = "Monte Carlo samples per pixel for `--ibl reference` and the `--pixel` probe's reference, 1 to "
                 "1048576.";
        s.hints = {"spp", "ibl-samples", "mc-samples"};
    }
    {
        Flag& br = set.value({"--brdf"}, "default|gltf", "the specular model", "default", {"phong"},
                             [&o](const std::string& flag, const std::string& v) {
                                 if (!parse_brdf_model(v, o.brdf)) bad_value(flag, v, "expected default or gltf");
                             });
        br.help = "`default`: the project's BRDF; `gltf`: the glTF 2.0 specification's reference BRDF.";
        br.hints = {"brdf-model", "shading-model", "model"};
        Flag& en = set.value({"--energy"}, "off|conserve", "multiple-scattering energy compensation", "off", {"yes"},
                             [&o](const std::string& flag, const std::string& v) {
                                 if (v == "off") o.energy = false;
                                 else if (v == "conserve") o.energy = true;
                                 else bad_value(flag, v, "expected off or conserve");
                             });
        en.help = "`conserve` adds back the energy single-scattering microfacets lose on rough metals.";
        en.hints = {"energy-compensation", "multiscatter", "multi-scatter"};
        Flag& m = set.value({"--msaa"}, "N", "samples per pixel: 1, 2, 4 or 8", std::to_string(kDefaultMsaa),
                            {"3", "16", "x"}, [&o](const std::string& flag, const std::string& v) {
                                long n;
                                if (!parse_integer(v, n) || (n != 1 && n != 2 && n != 4 && n != 8))
                                    bad_value(flag, v, "must be 1, 2, 4 or 8");
                                o.msaa = int(n);
                            });
        m.help = "Multisample anti-aliasing: 1, 2, 4 or 8 samples per pixel.";
        m.hints = {"aa", "antialias", "anti-alias", "antialiasing", "multisample", "ssaa"};
        Flag& ex = set.value({"--exposure"}, "E", "linear exposure before the tone map", "1", {"-1", "1e999"},
                             [&o, finite](const std::string& flag, const std::string& v) {
                                 const double d = finite(flag, v);
                                 if (!(d > 0.0)) bad_value(flag, v, "must be positive");
                                 o.exposure = float(d);
                             });
        ex.help = "Multiplies the linear colour before the tone map (positive).";
        ex.hints = {"ev", "brightness", "gain"};
        Flag& t = set.value({"--tonemap"}, "none|aces|neutral", "the tone map", "aces (none with --view)",
                            {"reinhard"}, [&o](const std::string& flag, const std::string& v) {
                                if (!parse_tonemap(v, o.tonemap)) bad_value(flag, v, "expected none, aces or neutral");
                                o.tonemap_given = true;
                            });
        t.help = "The tone map from linear radiance to the display: `aces` (highlights roll off), `neutral`, or "
                 "`none` (clips). Default `aces`, `none` with a `--view`.";
        t.hints = {"tone-map", "tonemapper", "tone", "tonemapping"};
    }
    if (wanted("--view")) {
        Flag& f = set.value({"--view"}, "NAME", "a debug view instead of the lit colour", "", {"bogus"},
                            [&o](const std::string& flag, const std::string& v) {
                                if (!parse_debug_view(v, o.view))
                                    bad_value(flag, v, std::string("unknown view; expected one of ") + debug_view_names());
                            });
        f.help = std::string("Shows one channel of the shading pipeline instead of the lit colour: ") +
                 debug_view_names() + ".";
        f.hints = {"debug", "debug-view", "channel", "aov", "pass"};
    }
    {
        Flag& s = set.value({"--shadows"}, "on|off", "shadow maps", "off", {"yes"},
                            [&o](const std::string& flag, const std::string& v) {
                                if (v != "on" && v != "off") bad_value(flag, v, "expected on or off");
                                o.shadows.enabled = v == "on";
                            });
        s.help = "Shadow maps: a depth map for each directional light, a cube of six for each point and spot light.";
        s.hints = {"shadow", "shadowmap", "shadow-maps"};
        Flag& z = set.value({"--shadow-size"}, "N", "shadow map texels per side", "2048", {"10", "x"},
                            [&o, integer](const std::string& flag, const std::string& v) {
                                const long n = integer(flag, v);
                                if (n < kMinShadowSize || n > kMaxShadowSize)
                                    bad_value(flag, v, "must be between " + std::to_string(kMinShadowSize) + " and " +
                                                           std::to_string(kMaxShadowSize) + " texels");
                                o.shadows.size = int(n);
                            });
        z.help = "Shadow map resolution, 64 to 8192 texels per side.";
        z.hints = {"shadow-resolution", "shadowmap-size", "shadow-res"};
    }
    {
        Flag& t = set.value({"--threads"}, "N", "worker threads", "all cores", {"0", "-2", "abc"},
                            [&o, integer](const std::string& flag, const std::string& v) {
                                const long n = integer(flag, v);
                                if (n < 1 || n > kMaxThreads)
                                    bad_value(flag, v, "must be between 1 and " + std::to_string(kMaxThreads));
                                o.threads = int(n);
                            });
        t.help = "Worker threads, 1 to 1024. The image does not depend on it.";
        t.hints = {"jobs", "cores", "j", "workers", "parallel", "nthreads"};
        Flag& ti = set.value({"--tile"}, "N", "tile size in pixels", std::to_string(kDefaultTileSize),
                             {"48", "512", "x"}, [&o, integer](const std::string& flag, const std::string& v) {
                                 const long n = integer(flag, v);
                                 if (n < kMinTileSize || n > kMaxTileSize || (n & (n - 1)) != 0)
                                     bad_value(flag, v, "must be a power of two from 16 to 256");
                                 o.tile_size = int(n);
                             });
        ti.help = "Tile size in pixels, a power of two from 16 to 256. The image does not depend on it.";
        ti.hints = {"tile-size", "tiles", "bin-size"};
    }
    {
        Flag& t = set.value({"--time"}, "SEC", "animation time in seconds", "0", {"nan", "x", "1e10"},
                            [&o](const std::string& flag, const std::string& v) {
                                double d;
                                if (!parse_finite(v, d) || std::fabs(d) > kMaxAnimationTime)
                                    bad_value(flag, v, "not a finite number of seconds (at most 1e9)");
                                o.time = d;
                            });
        t.help = "The time, in seconds, at which the model's animations are sampled (frame 0 of a sequence). "
                 "Before an animation's first key it holds its first value, after the last its last. Skins and "
                 "morph targets are applied at any time.";
        t.hints = {"t", "seconds", "at", "keyframe", "anim-time"};
        Flag& a = set.value({"--animation"}, "NAME|INDEX", "which animation plays", "all", {""},
                            [&o](const std::string& flag, const std::string& v) {
                                if (v.empty()) bad_value(flag, v, "expected an animation's name or index");
                                o.animation = v;
                            });
        a.help = "The animation to play, by name or index (`render --list` shows them). Default: every animation "
                 "at once, a later one winning where two move the same node.";
        a.hints = {"anim", "clip", "take", "action"};
        Flag& c = set.value({"--camera"}, "NAME|INDEX", "a camera of the file", "framed on the scene", {""},
                            [&o](const std::string& flag, const std::string& v) {
                                if (v.empty()) bad_value(flag, v, "expected a camera's name or index");
                                o.camera = v;
                            });
        c.help = "Looks through a camera of the model, by name or index (`render --list` shows them), with its "
                 "node's transform and animation; perspective or orthographic. The image's aspect (`--size`) is "
                 "used, not the file's aspectRatio. `--near`/`--far` override its planes.";
        c.hints = {"cam", "view-camera", "file-camera", "viewpoint"};
        Flag& va = set.value({"--variant"}, "NAME", "a material variant of the file", "the default materials", {""},
                             [&o](const std::string& flag, const std::string& v) {
                                 if (v.empty()) bad_value(flag, v, "expected a variant's name or index");
                                 o.variant = v;
                             });
        va.help = "Draws the model's KHR_materials_variants variant NAME (or its index; `render --list` shows "
                  "them): each primitive with a mapping for it takes that material, the others keep their own. "
                  "A name the model does not have is an error listing the variants it has.";
        va.hints = {"material-variant", "variants", "materials", "look", "colorway"};
    }
    if (wanted("--fps")) {
        Flag& f = set.value({"--fps"}, "F", "frames a second of a sequence", "", {"0", "-1", "nan", "2e6"},
                            [&o](const std::string& flag, const std::string& v) {
                                double d;
                                if (!parse_finite(v, d) || !(d > 0.0) || d > 1e6)
                                    bad_value(flag, v, "must be a positive number of frames a second (at most 1e6)");
                                o.fps = d;
                            });
        f.help = "With `--frames N`: renders a sequence through the animation instead of a turntable, frame i at "
                 "`--time` + i / F seconds. Needs `--frames`.";
        f.hints = {"framerate", "frame-rate", "rate", "sequence"};
        Flag& l = set.toggle({"--list"}, "print the model's contents", [&o] { o.list = true; });
        l.help = "Prints the model's meshes, materials, cameras, animations (name, duration, channels), skins, "
                 "material variants (with how many primitives each remaps) and the extensions it uses and "
                 "requires, then exits without rendering.";
        l.hints = {"info", "inspect", "contents", "describe", "ls"};
    }
    if (wanted("--frames")) {
        Flag& f = set.value({"--frames"}, "N", "turntable images", "1", {"0", "x"},
                            [&st, integer](const std::string& flag, const std::string& v) {
                                const long n = integer(flag, v);
                                if (n < 1 || n > kMaxFrames)
                                    bad_value(flag, v, "must be between 1 and " + std::to_string(kMaxFrames));
                                st.out.frames = int(n);
                                st.frames_given = true;
                            });
        f.help = "A turntable of N images orbiting the target around `--up`, or with `--fps` a sequence through "
                 "the animation; the file name needs a frame number (`-o frame%04d.png`).";
        f.hints = {"turntable", "animation", "count", "nframes"};
        Flag& ob = set.value({"--orbit"}, "DEG", "turntable angle in total", "360", {"nan"},
                             [&o](const std::string& flag, const std::string& v) {
                                 double d;
                                 // Negative turns the other way round the up axis.
                                 if (!parse_finite(v, d) || std::fabs(d) > 1e6)
                                     bad_value(flag, v, "not a finite number of degrees");
                                 o.orbit_deg = d;
                                 o.orbit_given = true;
                             });
        ob.help = "The turntable's total angle in degrees (negative turns the other way). Needs `--frames`.";
        ob.hints = {"orbit-angle", "rotate", "spin", "turn"};
        Flag& r = set.value({"--frame-range"}, "A-B", "render only frames A..B", "all", {"x", "3-1"},
                            [&st](const std::string& flag, const std::string& v) {
                                std::vector<std::string> ab = split(v, '-');
                                long a, b;
                                if (ab.size() != 2 || !parse_integer(ab[0], a) || !parse_integer(ab[1], b) || a < 0 ||
                                    b < 0)
                                    bad_value(flag, v, "expected A-B with 0 <= A <= B, e.g. 0-9");
                                if (a > b) bad_value(flag, v, "the first frame is after the last");
                                if (b >= kMaxFrames) bad_value(flag, v, "frame number too large");
                                st.out.first_frame = int(a);
                                st.out.last_frame = int(b);
                                st.out.frame_range_given = true;
                                st.range_text = v;
                            });
        r.help = "Renders only frames A to B (0-based, inclusive) of the turntable, e.g. to split it between "
                 "machines; the images are the same as in a whole run.";
        r.hints = {"range", "frame", "first-frame", "last-frame"};
    }
    if (wanted("--repeat")) {
        Flag& f = set.value({"--repeat"}, "N", "render N times and print frame_ms", "1", {"0", "x"},
                            [&o, integer](const std::string& flag, const std::string& v) {
                                const long n = integer(flag, v);
                                if (n < 1 || n > kMaxRepeat)
                                    bad_value(flag, v, "must be between 1 and " + std::to_string(kMaxRepeat));
                                o.repeat = int(n);
                                o.repeat_given = true;
                            });
        f.help = "Renders the frame N times and prints `frame_ms min=.. median=.. max=..` (timing).";
        f.hints = {"bench", "benchmark", "iterations", "times", "loop"};
    }
    if (wanted("--stats")) {
        Flag& f = set.toggle({"--stats"}, "per-stage counters and times", [&o] { o.stats = true; });
        f.help = "Prints per-stage counters (triangles, fragments, ...) and times.";
        f.hints = {"verbose", "timing", "timings", "stat", "profile"};
    }
    {
        Flag& f = set.value({"--pixel"}, "X,Y", "probe a pixel", "", {"x", "-1,0"},
                            [&o](const std::string& flag, const std::string& v) {
                                std::vector<std::string> xy = split(v, ',');
                                long x, y;
                                if (xy.size() != 2 || !parse_integer(xy[0], x) || !parse_integer(xy[1], y) || x < 0 ||
                                    y < 0)
                                    bad_value(flag, v, "expected X,Y with non-negative integers");
                                if (x > kMaxViewportSize || y > kMaxViewportSize) bad_value(flag, v, "outside the image");
                                o.pixel = glm::ivec2(int(x), int(y));
                            });
        f.help = "Prints what shaded pixel X,Y (0,0 top left): depth, material, every BRDF and lighting term.";
        f.hints = {"probe", "inspect", "debug-pixel", "px"};
    }
    if (wanted("--allow-outside-paths")) {
        Flag& f = set.toggle({"--allow-outside-paths"}, "let the model name files outside its own folder",
                             [&o] { o.allow_outside_paths = true; });
        f.help = "Lets the model's textures and buffers lie outside its own folder (refused by default: a model "
                 "from a stranger must not read other files).";
        f.hints = {"allow-paths", "outside", "unsafe-paths"};
    }
}

std::string finish_render_options(RenderParse& st, const std::vector<std::string>& positionals) {
    RenderOptions& out = st.out;
    for (const std::string& p : positionals) {
        if (!out.scene.empty()) return "unexpected argument '" + p + "' (one SCENE at most)";
        if (p.empty()) return "empty SCENE argument";
        out.scene = p;
    }
    if (out.pixel && (out.pixel->x >= out.width || out.pixel->y >= out.height))
        return "--pixel '" + std::to_string(out.pixel->x) + "," + std::to_string(out.pixel->y) +
               "': outside the " + std::to_string(out.width) + "x" + std::to_string(out.height) + " image";
    if (out.near_plane && out.far_plane && !(*out.near_plane < *out.far_plane))
        return "--near/--far: near (" + std::to_string(*out.near_plane) + ") must be less than far (" +
               std::to_string(*out.far_plane) + ")";
    // Environment flags need an environment: --env, or the built-in scene's sky.
    if (!st.needs_env.empty() && out.env.empty() && !out.scene.empty())
        return st.needs_env + ": needs --env FILE.hdr (the scene has no environment)";
    if (out.samples_given && out.ibl != IblMode::Reference && !out.pixel)
        return "--samples: only used with --ibl reference (or --pixel)";
    if (out.orbit_given && !st.frames_given) return "--orbit: needs --frames N (the number of turntable images)";
    if (out.fps > 0.0 && !st.frames_given) return "--fps: needs --frames N (the number of images of the sequence)";
    if (out.list && out.scene.empty()) return "--list: needs a MODEL (a .gltf, .glb or .obj file)";
    if (!out.camera.empty()) {
        for (const auto& [given, name] : {std::pair<bool, const char*>{out.eye.has_value(), "--eye"},
                                          {out.target.has_value(), "--target"},
                                          {out.up.has_value(), "--up"},
                                          {out.fov_deg != 45.0f, "--fov"}})
            if (given) return std::string("--camera: the file's camera places the view; it cannot be combined with ") + name;
        if (out.scene.empty()) return "--camera: the built-in scene has no cameras; give a MODEL";
        if (out.frames > 1 && out.fps == 0.0)
            return "--camera: a file's camera does not orbit; give --fps F for a sequence through time";
    }
    cli::FramePattern pattern(out.output);
    if (out.frames > 1 && !pattern.has_number)
        return "-o '" + out.output + "': a turntable of " + std::to_string(out.frames) +
               " frames needs a frame number in the file name, e.g. frame%04d.png";
    if (out.frame_range_given) {
        if (out.last_frame >= out.frames)
            return "--frame-range '" + st.range_text + "': the turntable has frames 0-" +
                   std::to_string(out.frames - 1) + " (--frames " + std::to_string(out.frames) + ")";
    } else {
        out.first_frame = 0;
        out.last_frame = out.frames - 1;
    }
    return "";
}

std::vector<HelpRow> render_help_rows(bool render_only) {
    std::vector<HelpRow> rows;
    if (render_only) rows.push_back({{"--output"}, ""});
    rows.push_back({{"--size"}, ""});
    rows.push_back({{"--eye", "--target", "--up"}, "camera (default: framed on the scene)"});
    rows.push_back({{"--fov", "--near", "--far"}, "field of view (default 45), clip planes (fitted)"});
    rows.push_back({{"--sun", "--point"}, "lights (repeatable)"});
    rows.push_back({{"--ambient", "--no-default-lights"}, "(default 0.03); no key+fill rig"});
    rows.push_back({{"--file-lights"}, "on|off: the model's own lights (default on)"});
    rows.push_back({{"--time", "--animation", "--camera"}, render_only ? "time 0, all animations" : "time, animation, camera"});
    rows.push_back({{"--env", "--env-intensity", "--env-rotate"}, "image-based lighting"});
    rows.push_back({{"--background", "--ibl", "--samples"}, ""});
    rows.push_back({{"--brdf", "--energy", "--msaa"}, "(1, 2, 4, 8; default 4)"});
    rows.push_back({{"--exposure", "--tonemap"}, "default 1, aces (none with --view)"});
    if (render_only) rows.push_back({{"--view"}, wrapped_view_names(79 - 23)});
    rows.push_back({{"--shadows", "--shadow-size"}, "shadow maps (default off, 2048 texels)"});
    rows.push_back({{"--threads", "--tile"}, "default: all cores; tile 16..256 (default 64)"});
    if (render_only) {
        rows.push_back({{"--frames", "--orbit", "--fps"},
                        "turntable around --up, DEG (default 360);\n"
                        "--fps: frames in time; FILE needs %04d"});
        rows.push_back({{"--frame-range", "--repeat"}, "frames A..B only; N times, print frame_ms"});
        rows.push_back({{"--stats", "--pixel"}, "per-stage counters and times; probe a pixel"});
        rows.push_back({{"--allow-outside-paths", "--list", "--variant"}, "outside paths; list it; variant"});
    } else {
        rows.push_back({{"--pixel"}, "explain one pixel and exit"});
        rows.push_back({{"--variant"}, ""});
    }
    rows.push_back({{"--help", "--version"}, render_only ? "exit codes: 0 ok, 1 bad file or write, 2 bad usage"
                                                         : "exit codes: 0 ok, 1 bad file or a failed command, "
                                                           "2 bad usage"});
    return rows;
}

namespace {

const char* const kRenderHead = "usage: render [SCENE] [options]    SCENE: .obj, .gltf or .glb; none: built-in\n";

struct RenderDefinitions {
    RenderOptions options;
    RenderParse st{options, ~std::uint64_t(0)};
    FlagSet set{"render"};
    RenderDefinitions() {
        add_render_flags(set, st);
        set.positional("SCENE", "a `.obj` (with its `.mtl`), `.gltf` or `.glb` file; none: the built-in scene");
    }
};

} // namespace

std::vector<Flag> render_flag_list() {
    RenderDefinitions d;
    return d.set.flags();
}

std::string render_markdown() {
    RenderDefinitions d;
    return d.set.markdown("render [SCENE] [options]",
                          "Renders a model (or the built-in scene) to a PNG or HDR image. Exit codes: 0 ok, 1 a bad "
                          "file or a failed write, 2 bad usage.");
}

} // namespace cli

std::string parse_render_args(int argc, const char* const* argv, RenderOptions& out, std::uint64_t memory_budget) {
    cli::RenderParse st{out, memory_budget};
    cli::FlagSet set("render");
    set.unknown_hint = " (render --help lists them)";
    cli::add_render_flags(set, st);
    std::vector<std::string> positionals;
    const std::string err = set.parse(argc, argv, positionals);
    if (!err.empty() || out.help || out.version) return err;
    return cli::finish_render_options(st, positionals);
}

const char* render_usage() {
    static const std::string text = [] {
        cli::RenderDefinitions d;
        return d.set.usage(cli::kRenderHead, cli::render_help_rows(), "");
    }();
    return text.c_str();
}

} // namespace prast

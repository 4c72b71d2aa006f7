// step: the stepper (issue 10). Takes render's scene, camera, light and
// view-transform flags, records one frame with the prast_stepper library and
// explains it: commands on standard input (a prompt only on a terminal),
// --out DIR (every stage as a PNG and an index.html), or --serve (a local web
// page). Errors are one line on stderr, "step: ...": exit code 2 for usage,
// 1 for bad files (and for a session in which a command failed).
#include <cstdio>
#include <cstring>
#include <exception>
#include <iostream>
#include <new>
#include <string>
#include <vector>

#include <unistd.h>

#include "apps/render_options.h"
#include "stepper/html_export.h"
#include "stepper/http_server.h"
#include "stepper/recording.h"
#include "stepper/scene_setup.h"
#include "stepper/session.h"
#include "stepper/stages.h"

using namespace prast;
using namespace prast::stepper;

namespace {

constexpr int kExitBadFile = 1;
constexpr int kExitUsage = 2;

const char* step_usage() {
    return
"usage: step [SCENE] [options]      SCENE: .obj, .gltf or .glb; none: built-in\n"
"  records one frame, as `render` with the same flags would draw it, and explains it:\n"
"  commands on standard input (type help), or\n"
"  --out DIR            every stage as a PNG and DIR/index.html\n"
"  --serve [--port N]   a web page on http://127.0.0.1:N/ (default 8137; 0: any free port)\n"
"  --pixel X,Y          explain one pixel and exit\n"
"  scene, camera, light and view flags as render's (render --help):\n"
"  --size WxH --eye X,Y,Z --target X,Y,Z --up X,Y,Z --fov DEG --near N --far F\n"
"  --sun X,Y,Z:R,G,B --point X,Y,Z:R,G,B --ambient R,G,B --no-default-lights\n"
"  --env FILE.hdr --env-intensity E --env-rotate DEG --ibl split-sum\n"
"  --background env|blur|black|R,G,B --brdf default|gltf --energy off|conserve\n"
"  --exposure E --tonemap none|aces|neutral --msaa N --threads N --tile N\n"
"  --shadows on|off --shadow-size N\n"
"  --help, --version    exit codes: 0 ok, 1 bad file or a failed command, 2 bad usage\n";
}

// Flags of render that make no sense for one recorded frame.
const char* const kNotForStep[] = {"-o", "--output", "--frames", "--orbit", "--frame-range",
                                   "--repeat", "--view", "--stats"};

// The loader's refusals end with a hint at render's --allow-outside-paths,
// which step does not take.
std::string without_outside_hint(std::string s) {
    const std::string hint = " (--allow-outside-paths reads it)";
    for (std::size_t at; (at = s.find(hint)) != std::string::npos;) s.erase(at, hint.size());
    return s;
}

struct StepOptions {
    std::string out_dir;
    bool serve = false;
    long port = 8137;
};

// Takes step's own flags out of argv; the rest goes to render's parser.
std::string parse_step_args(int argc, char** argv, StepOptions& so, std::vector<const char*>& rest) {
    rest.push_back(argv[0]);
    bool port_given = false;
    for (int i = 1; i < argc; ++i) {
        std::string arg = argv[i];
        std::string flag = arg, value;
        bool inline_value = false;
        const std::size_t eq = arg.find('=');
        if (arg.compare(0, 2, "--") == 0 && eq != std::string::npos) {
            flag = arg.substr(0, eq);
            value = arg.substr(eq + 1);
            inline_value = true;
        }
        if (flag == "--allow-outside-paths")
            return flag + ": not a step option (step reads only files inside the model's folder: it may show "
                          "them in a web page)";
        for (const char* f : kNotForStep)
            if (flag == f)
                return flag + ": not a step option (step records one frame; see step --help)";
        if (flag == "--out" || flag == "--port") {
            if (!inline_value) {
                if (i + 1 >= argc) return flag + ": missing value";
                value = argv[++i];
            }
            if (flag == "--out") {
                if (value.empty()) return "--out: empty directory name";
                so.out_dir = value;
            } else {
                if (!parse_int(value, 0, 65535, so.port)) return "--port '" + value + "': expected 0..65535";
                port_given = true;
            }
            continue;
        }
        if (flag == "--serve") {
            if (inline_value) return "--serve: takes no value";
            so.serve = true;
            continue;
        }
        rest.push_back(argv[i]);
    }
    if (port_given && !so.serve) return "--port: only with --serve";
    if (so.serve && !so.out_dir.empty()) return "--serve and --out: choose one";
    return "";
}

int run(int argc, char** argv) {
    StepOptions so;
    std::vector<const char*> rest;
    std::string err = parse_step_args(argc, argv, so, rest);
    RenderOptions opt;
    if (err.empty()) err = parse_render_args(int(rest.size()), rest.data(), opt);
    if (!err.empty()) {
        std::fprintf(stderr, "step: %s\n", err.c_str());
        return kExitUsage;
    }
    if (opt.help) {
        std::fputs(step_usage(), stdout);
        return 0;
    }
    if (opt.version) {
        std::printf("step (prast) %s\n", kRenderVersion);
        return 0;
    }
    if (opt.ibl == IblMode::Reference) {
        std::fprintf(stderr, "step: --ibl reference: step explains the split sum (render --pixel prints the reference)\n");
        return kExitUsage;
    }
    if (opt.pixel && (so.serve || !so.out_dir.empty())) {
        std::fprintf(stderr, "step: --pixel: not with --out or --serve\n");
        return kExitUsage;
    }

    FrameRequest req;
    req.scene = opt.scene;
    req.width = opt.width;
    req.height = opt.height;
    req.eye = opt.eye;
    req.target = opt.target;
    req.up = opt.up;
    req.fov_deg = opt.fov_deg;
    req.near_plane = opt.near_plane;
    req.far_plane = opt.far_plane;
    req.lights = opt.lights;
    req.ambient = opt.ambient;
    req.no_default_lights = opt.no_default_lights;
    req.brdf = opt.brdf;
    req.env = opt.env;
    req.env_intensity = opt.env_intensity;
    req.env_rotate_deg = opt.env_rotate_deg;
    req.background = opt.background;
    req.background_color = opt.background_color;
    req.energy = opt.energy;
    req.exposure = opt.exposure;
    req.tonemap = opt.effective_tonemap();
    req.threads = opt.threads;
    req.tile_size = opt.tile_size;
    req.samples = opt.msaa;
    req.shadows = opt.shadows;
    req.bytes_per_pixel = kBytesPerPixel;

    StepScene scene;
    SetupError setup_err;
    if (!setup_scene(req, scene, setup_err)) {
        std::fprintf(stderr, "step: %s\n", without_outside_hint(setup_err.message).c_str());
        return setup_err.code;
    }
    for (const std::string& n : scene.notes) std::fprintf(stderr, "step: %s\n", without_outside_hint(n).c_str());

    Recording rec;
    record_frame(scene, rec);
    Session session(scene, rec);

    if (opt.pixel) {
        const Reply r = session.run("pixel " + std::to_string(opt.pixel->x) + " " + std::to_string(opt.pixel->y));
        std::fputs(r.text.c_str(), stdout);
        return r.ok ? 0 : kExitBadFile;
    }

    if (!so.out_dir.empty()) {
        const std::string e = export_html(scene, rec, so.out_dir);
        if (!e.empty()) {
            std::fprintf(stderr, "step: %s\n", e.c_str());
            return kExitBadFile;
        }
        std::printf("step: wrote %s/index.html and %zu stage images\n", so.out_dir.c_str(),
                    stage_list().size());
        return 0;
    }

    if (so.serve) return serve(session, int(so.port));

    // Commands on standard input; a prompt only for a person at a terminal.
    const bool tty = isatty(STDIN_FILENO);
    if (tty)
        std::printf("step: %dx%d, %u triangles recorded; type help for the commands\n", rec.width, rec.height,
                    rec.triangle_count());
    bool failed = false;
    std::string line;
    for (;;) {
        if (tty) {
            std::fputs("step> ", stdout);
            std::fflush(stdout);
        }
        if (!std::getline(std::cin, line)) break;
        const Reply r = session.run(line);
        std::fputs(r.text.c_str(), stdout);
        std::fflush(stdout);
        failed |= !r.ok;
        if (r.quit) break;
    }
    if (tty) std::fputs("\n", stdout);
    return failed ? kExitBadFile : 0;
}

} // namespace

int main(int argc, char** argv) {
    // Never crash: whatever escapes is one line and exit code 1.
    try {
        return run(argc, argv);
    } catch (const std::bad_alloc&) {
        std::fprintf(stderr, "step: out of memory (try a smaller --size or a smaller scene)\n");
    } catch (const std::exception& e) {
        std::fprintf(stderr, "step: %s\n", e.what());
    }
    return kExitBadFile;
}

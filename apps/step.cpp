// step: the stepper. Takes render's scene, camera, light and
// view-transform flags, records one frame with the prast_stepper library and
// explains it: commands on standard input (on a terminal a prompt with line
// editing and history, through libedit),
// --out DIR (every stage as a PNG and an index.html), or --serve (a local web
// page). Errors are one line on stderr, "step: ...": exit code 2 for usage,
// 1 for bad files (and for a session in which a command failed).
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <iostream>
#include <new>
#include <string>
#include <vector>

#include <unistd.h>

#include <editline/readline.h>

#include "apps/cli/step_flags.h"
#include "apps/frame_request.h"
#include "apps/render_options.h"
#include "stepper/html_export.h"
#include "stepper/http_server.h"
#include "stepper/recording.h"
#include "stepper/session.h"
#include "stepper/stages.h"

using namespace prast;
using namespace prast::stepper;
using prast::cli::parse_step_args;
using prast::cli::step_usage;
using prast::cli::StepOptions;

namespace {

constexpr int kExitBadFile = 1;
constexpr int kExitUsage = 2;

// The loader's refusals end with a hint at render's --allow-outside-paths,
// which step does not take.
std::string without_outside_hint(std::string s) {
    const std::string hint = " (--allow-outside-paths reads it)";
    for (std::size_t at; (at = s.find(hint)) != std::string::npos;) s.erase(at, hint.size());
    return s;
}

int run(int argc, char** argv) {
    StepOptions so;
    RenderOptions opt;
    const std::string err = parse_step_args(argc, argv, so, opt);
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

    // render's frame 0 (renderer/frame_setup.h), so every explained pixel is render's.
    FrameSetup scene;
    FrameError setup_err = prepare_scene(step_frame_request(opt), scene);
    if (!setup_err) {
        if (CameraFault f = scene.orbit(0.0)) setup_err = {kExitUsage, f.message};
    }
    if (!setup_err) setup_err = start_renderer(scene);
    if (setup_err) {
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
            // libedit: the arrow keys edit the line and walk the history.
            char* got = readline("step> ");
            if (!got) break;
            line = got;
            std::free(got);
            if (line.find_first_not_of(" \t") != std::string::npos) add_history(line.c_str());
        } else if (!std::getline(std::cin, line)) {
            break;
        }
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

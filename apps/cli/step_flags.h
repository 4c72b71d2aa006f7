// step's command line: its own flags (--out, --serve, --port) and render's
// scene, camera, light and view flags, in one FlagSet.
#pragma once

#include "apps/cli/flags.h"

#include <string>

#include "apps/render_options.h"

namespace prast::cli {

struct StepOptions {
    std::string out_dir;  // --out DIR: every stage as a PNG and DIR/index.html
    bool serve = false;   // --serve: a local web page
    long port = 8137;
};

// Parses argv[1..argc) into `so` and `opt`: "" or the error line (without
// "step: "); exit code 2. --help and --version set opt.help / opt.version.
std::string parse_step_args(int argc, const char* const* argv, StepOptions& so, RenderOptions& opt);

// The --help text.
const char* step_usage();

// step's section of docs/flags.md.
std::string step_markdown();
// The definitions (see all_tool_flags in flags_page.h).
std::vector<Flag> step_flag_list();

} // namespace prast::cli

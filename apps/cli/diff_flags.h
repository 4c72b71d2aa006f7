// prast-diff's command line.
#pragma once

#include "apps/cli/flags.h"

#include <string>
#include <vector>

#include "scene/image_diff.h"

namespace prast::cli {

struct DiffOptions {
    std::vector<std::string> files;  // A.png B.png
    DiffTolerance tol;
    std::string heatmap;             // --heatmap OUT.png
    bool help = false, version = false;
};

// Parses argv[1..argc): "" or the error line (without "prast-diff: "); exit code 2.
std::string parse_diff_args(int argc, const char* const* argv, DiffOptions& out);

const char* diff_usage();

// prast-diff's section of docs/flags.md.
std::string diff_markdown();
// The definitions (see all_tool_flags in flags_page.h).
std::vector<Flag> diff_flag_list();

} // namespace prast::cli

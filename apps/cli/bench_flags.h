// bench's command line (tools/bench/bench.cpp): the modes (workloads,
// a scene, --alternate, --write-workloads, --side-by-side, --psnr) and their
// flags, in one FlagSet like the apps'.
#pragma once

#include "apps/cli/flags.h"

#include <string>
#include <vector>

#include "raster/limits.h"
#include "shading/debug_view.h"
#include "shading/shadow/shadow_map.h"

namespace prast::cli {

struct BenchOptions {
    std::string scene_path;            // SCENE: the scene mode
    std::string write_dir;             // --write-workloads DIR
    std::string psnr_a, psnr_b;        // --psnr A B
    std::vector<std::string> exes;     // --side-by-side RENDER_A RENDER_B
    std::string dir;                   // --workloads DIR (the caller sets the default)
    std::string assets;                // --assets DIR (the caller sets the default)
    int width = 1920, height = 1080, repeat = 15, runs = 5;
    std::vector<int> msaa{1};
    std::vector<int> threads{2}, tiles{kDefaultTileSize};
    std::vector<std::string> names;    // --workload; empty: all
    DebugView view = DebugView::None;
    bool flat = false, json = false, alternate = false;
    bool threads_given = false, tiles_given = false, blend_given = false;
    std::vector<bool> shadows{false};  // each configuration is measured once per entry
    int shadow_size = ShadowSettings{}.size;
    float blend_alpha = -1.0f;         // >= 0: every material BLEND with this alpha
    bool help = false, version = false;
};

// The workloads' names, in the order bench measures them.
const std::vector<std::string>& bench_workload_names();

// Parses argv[1..argc): "" or the error line (without "bench: "); exit code 2.
std::string parse_bench_args(int argc, const char* const* argv, BenchOptions& out);

const char* bench_usage();

// bench's section of docs/flags.md.
std::string bench_markdown();
// The definitions (see all_tool_flags in flags_page.h).
std::vector<Flag> bench_flag_list();

} // namespace prast::cli

// bench's flags; see bench_flags.h.
#include "apps/cli/bench_flags.h"

#include <algorithm>

#include "apps/cli/flags.h"
#include "apps/cli/values.h"

namespace prast::cli {

namespace {

constexpr long kMaxBenchThreads = 1024;
constexpr long kMaxBenchRepeat = 100000;
constexpr long kMaxRuns = 1000;

const char* const kBenchHead =
    "usage: bench [--workload quad,grid,bottle,tea,bunny,builtin] [--threads 1,2] [--msaa 1,4] [--repeat N] [--json]\n"
    "             [--alternate]  (frames of each thread count in turn, speed-up per round)\n"
    "       bench SCENE [--size WxH] [--threads 1,2] [--tiles 64] [--repeat N] [--view NAME] [--flat]\n"
    "             [--shadows on|off|both] [--shadow-size N] [--blend ALPHA]\n"
    "       bench --write-workloads DIR\n"
    "       bench --side-by-side RENDER_A RENDER_B [--workload ...] [--threads 1,2] [--msaa 1,4] [--runs N] [--repeat N]\n"
    "             [--json]  (each thread count and sample count in turn)\n"
    "       bench --psnr A.png B.png\n"
    "options:\n";

std::string joined(const std::vector<std::string>& v, const char* sep) {
    std::string s;
    for (const std::string& x : v) s += (s.empty() ? "" : sep) + x;
    return s;
}

void non_empty(const std::string& flag, const std::vector<std::string>& values, const char* what) {
    for (const std::string& v : values)
        if (v.empty()) fail(flag + ": empty " + what);
}

void add_bench_flags(FlagSet& set, BenchOptions& o) {
    Flag& help = set.toggle({"-h", "--help"}, "this text", [&o] { o.help = true; });
    help.stops = true;
    help.help = "Prints the flags and exits (exit code 0).";
    Flag& version = set.toggle({"--version"}, "the version", [&o] { o.version = true; });
    version.stops = true;
    version.help = "Prints the version and exits.";

    Flag& w = set.value({"--workload"}, "LIST", "the workloads to measure (default all)", "all", {"nosuch", ""},
                        [&o](const std::string& flag, const std::string& v) {
                            const std::vector<std::string>& known = bench_workload_names();
                            std::vector<std::string> names = split(v, ',');
                            for (const std::string& n : names)
                                if (std::find(known.begin(), known.end(), n) == known.end())
                                    bad_value(flag, v, "unknown workload '" + n + "' (" + joined(known, ", ") + ")");
                            o.names = names;
                        });
    w.help = "Comma list of workloads to measure: " + joined(bench_workload_names(), ", ") +
             " (1920x1080, one sun, ambient 0.05, ACES; see tools/bench/bench.cpp).";
    w.hints = {"workloads-list", "scenes", "only", "filter"};
    Flag& t = set.value({"--threads"}, "LIST", "thread counts, each measured", "2 (scene mode 1,2)", {"x", "1,-1"},
                        [&o](const std::string& flag, const std::string& v) {
                            if (!parse_int_list(v, o.threads, [](long n) { return n >= 0 && n <= kMaxBenchThreads; }))
                                bad_value(flag, v, "expected a comma list of thread counts from 0 to 1024 "
                                                   "(0: all cores)");
                            o.threads_given = true;
                        });
    t.help = "Comma list of thread counts, each measured in turn (0: all cores). Side by side: the last one.";
    t.hints = {"jobs", "cores", "j", "thread"};
    Flag& m = set.value({"--msaa"}, "LIST", "samples per pixel, each measured", "1", {"3", "1,x"},
                        [&o](const std::string& flag, const std::string& v) {
                            if (!parse_int_list(v, o.msaa, [](long n) { return n == 1 || n == 2 || n == 4 || n == 8; }))
                                bad_value(flag, v, "expected a comma list of 1, 2, 4 or 8");
                        });
    m.help = "Comma list of samples per pixel (1, 2, 4, 8). Side by side: given to executables that take "
             "`--msaa`; builds from before it draw 1 sample.";
    m.hints = {"aa", "samples", "antialias"};
    Flag& r = set.value({"--repeat"}, "N", "frames per measurement (after one warm-up)", "15", {"0", "x"},
                        [&o](const std::string& flag, const std::string& v) {
                            long n;
                            if (!parse_integer_in(v, 1, kMaxBenchRepeat, n))
                                bad_value(flag, v, "must be between 1 and " + std::to_string(kMaxBenchRepeat));
                            o.repeat = int(n);
                        });
    r.help = "Frames measured per configuration, after one warm-up frame; min, median and max are printed.";
    r.hints = {"frames", "iterations", "count", "times"};
    Flag& j = set.toggle({"--json"}, "one JSON object per measurement", [&o] { o.json = true; });
    j.help = "Prints a JSON array, one object per workload and configuration (scripts read it).";
    Flag& a = set.toggle({"--alternate"}, "frames of each thread count in turn", [&o] { o.alternate = true; });
    a.help = "One process, a renderer per thread count, their frames taken in turn; prints the median of the "
             "rounds' speed-ups and whether the images are the same.";
    a.hints = {"interleave", "speedup", "round-robin"};

    Flag& s = set.value({"--size"}, "WxH", "image size", "1920x1080", {"0x10", "96"},
                        [&o](const std::string& flag, const std::string& v) {
                            long w = 0, h = 0;
                            if (!parse_size(v, w, h) || w < 1 || h < 1 || w > kMaxViewportSize || h > kMaxViewportSize)
                                bad_value(flag, v, "expected WxH, each from 1 to " + std::to_string(kMaxViewportSize));
                            o.width = int(w);
                            o.height = int(h);
                        });
    s.help = "Image size in pixels, of the workloads and of the scene mode (the figures in docs/performance.md are "
             "at 1920x1080; smaller sizes test the tool quickly).";
    s.hints = {"resolution", "res", "dimensions", "width", "height"};
    Flag& ti = set.value({"--tiles"}, "LIST", "scene mode: tile sizes, each measured", "64", {"48", "x"},
                         [&o](const std::string& flag, const std::string& v) {
                             if (!parse_int_list(v, o.tiles, [](long n) {
                                     return n >= kMinTileSize && n <= kMaxTileSize && (n & (n - 1)) == 0;
                                 }))
                                 bad_value(flag, v, "expected a comma list of powers of two from 16 to 256");
                             o.tiles_given = true;
                         });
    ti.help = "Comma list of tile sizes (powers of two, 16 to 256), each measured; selects the scene mode.";
    ti.hints = {"tile", "tile-size"};
    Flag& vw = set.value({"--view"}, "NAME", "scene mode: a debug view", "", {"bogus"},
                         [&o](const std::string& flag, const std::string& v) {
                             if (!parse_debug_view(v, o.view))
                                 bad_value(flag, v, std::string("unknown view; expected one of ") + debug_view_names());
                         });
    vw.help = std::string("Measures a debug view (") + debug_view_names() + "); selects the scene mode.";
    Flag& fl = set.toggle({"--flat"}, "scene mode: flat Lambert program", [&o] { o.flat = true; });
    fl.help = "Draws with a flat Lambert program (no textures, one fixed light): the cost of the core. Selects the "
              "scene mode.";
    fl.hints = {"lambert", "simple", "core"};
    Flag& sh = set.value({"--shadows"}, "on|off|both", "shadow maps", "off", {"yes"},
                         [&o](const std::string& flag, const std::string& v) {
                             if (v == "on") o.shadows = {true};
                             else if (v == "off") o.shadows = {false};
                             else if (v == "both") o.shadows = {false, true};
                             else bad_value(flag, v, "expected on, off or both");
                         });
    sh.help = "Shadow maps on, off, or both side by side per configuration (workloads and scene mode).";
    sh.hints = {"shadow"};
    Flag& ss = set.value({"--shadow-size"}, "N", "shadow map texels per side", "2048", {"10", "x"},
                         [&o](const std::string& flag, const std::string& v) {
                             long n;
                             if (!parse_integer_in(v, kMinShadowSize, kMaxShadowSize, n))
                                 bad_value(flag, v, "must be between " + std::to_string(kMinShadowSize) + " and " +
                                                        std::to_string(kMaxShadowSize) + " texels");
                             o.shadow_size = int(n);
                         });
    ss.help = "Shadow map resolution, 64 to 8192 texels per side.";
    Flag& bl = set.value({"--blend"}, "ALPHA", "scene mode: every material BLEND with this alpha", "", {"2", "x"},
                         [&o](const std::string& flag, const std::string& v) {
                             double d;
                             if (!parse_finite(v, d) || d < 0.0 || d > 1.0)
                                 bad_value(flag, v, "expected an alpha from 0 to 1");
                             o.blend_alpha = float(d);
                             o.blend_given = true;
                         });
    bl.help = "Makes every material alpha BLEND with this alpha (0 to 1), the worst case of transparency; selects "
              "the scene mode.";
    bl.hints = {"alpha", "transparency", "transparent"};

    Flag& wd = set.value({"--workloads"}, "DIR", "where the synthetic workloads live", "/tmp/prast-bench-workloads",
                         {""}, [&o](const std::string& flag, const std::string& v) {
                             non_empty(flag, {v}, "directory name");
                             o.dir = v;
                         });
    wd.help = "Where the synthetic workloads are (written there first when missing).";
    Flag& as = set.value({"--assets"}, "DIR", "the shared assets (tea, bunny)",
                         "$PRAST_SHARED_ASSETS or ../shared/assets", {""},
                         [&o](const std::string& flag, const std::string& v) {
                             non_empty(flag, {v}, "directory name");
                             o.assets = v;
                         });
    as.help = "The shared assets folder that holds the tea set and the bunny.";
    Flag& ww = set.value({"--write-workloads"}, "DIR", "write the synthetic workloads and commands.txt", "", {""},
                         [&o](const std::string& flag, const std::string& v) {
                             non_empty(flag, {v}, "directory name");
                             o.write_dir = v;
                         });
    ww.help = "Writes the synthetic workloads as files, plus `DIR/commands.txt` with a render command line per "
              "workload, and exits.";
    ww.hints = {"write", "generate", "export"};
    Flag sbs;
    sbs.names = {"--side-by-side"};
    sbs.value = "RENDER_A RENDER_B";
    sbs.arity = 2;
    sbs.brief = "two render executables, alternately";
    sbs.help = "Runs two render executables alternately on the workloads (`--runs` rounds): whole process, start to "
               "PNG written, and the `--repeat` frame median.";
    sbs.bad = {"", ""};
    sbs.hints = {"compare", "versus", "vs", "ab"};
    sbs.apply = [&o](const std::string& flag, const std::vector<std::string>& v) {
        non_empty(flag, v, "executable name");
        o.exes = v;
    };
    set.add(std::move(sbs));
    Flag& ru = set.value({"--runs"}, "N", "side by side: rounds", "5", {"0", "x"},
                         [&o](const std::string& flag, const std::string& v) {
                             long n;
                             if (!parse_integer_in(v, 1, kMaxRuns, n))
                                 bad_value(flag, v, "must be between 1 and " + std::to_string(kMaxRuns));
                             o.runs = int(n);
                         });
    ru.help = "Side by side: alternating rounds per workload.";
    ru.hints = {"rounds"};
    Flag psnr;
    psnr.names = {"--psnr"};
    psnr.value = "A.png B.png";
    psnr.arity = 2;
    psnr.brief = "the PSNR of two 8-bit images";
    psnr.help = "Prints the PSNR of two 8-bit images (RGB), the largest channel difference and the differing "
                "pixels, and exits.";
    psnr.bad = {"", ""};
    psnr.hints = {"compare-images", "diff"};
    psnr.apply = [&o](const std::string& flag, const std::vector<std::string>& v) {
        non_empty(flag, v, "file name");
        o.psnr_a = v[0];
        o.psnr_b = v[1];
    };
    set.add(std::move(psnr));
    set.positional("SCENE", "scene mode: any scene render reads (the built-in one when `--tiles`, `--view`, "
                            "`--flat` or `--blend` is given without one)");
}

std::vector<HelpRow> bench_rows() {
    return {{{"--workload"}, ""},
            {{"--threads", "--msaa"}, "thread counts, samples per pixel"},
            {{"--repeat"}, "frames per measurement (default 15)"},
            {{"--json", "--alternate"}, "JSON output; thread counts in turn"},
            {{"--size"}, "image size (default 1920x1080)"},
            {{"--tiles", "--view", "--flat"}, "scene mode"},
            {{"--shadows", "--shadow-size", "--blend"}, "shadow maps; every material BLEND"},
            {{"--workloads"}, "where the synthetic workloads live; default /tmp/prast-bench-workloads"},
            {{"--assets"}, "the shared assets; default ../shared/assets"},
            {{"--write-workloads"}, ""},
            {{"--side-by-side", "--runs"}, "two render executables, N rounds"},
            {{"--psnr"}, ""},
            {{"--help", "--version"}, ""}};
}

} // namespace

const std::vector<std::string>& bench_workload_names() {
    static const std::vector<std::string> names = {"quad", "grid", "bottle", "tea", "bunny", "builtin"};
    return names;
}

std::string parse_bench_args(int argc, const char* const* argv, BenchOptions& out) {
    FlagSet set("bench");
    set.unknown_hint = " (bench --help lists them)";
    add_bench_flags(set, out);
    std::vector<std::string> positionals;
    const std::string err = set.parse(argc, argv, positionals);
    if (!err.empty() || out.help || out.version) return err;
    for (const std::string& p : positionals) {
        if (!out.scene_path.empty()) return "unexpected argument '" + p + "' (one SCENE at most)";
        if (p.empty()) return "empty SCENE argument";
        out.scene_path = p;
    }
    return "";
}

const char* bench_usage() {
    static const std::string text = [] {
        BenchOptions o;
        FlagSet set("bench");
        add_bench_flags(set, o);
        return set.usage(kBenchHead, bench_rows(), "", 27);
    }();
    return text.c_str();
}

std::vector<Flag> bench_flag_list() {
    BenchOptions o;
    FlagSet set("bench");
    add_bench_flags(set, o);
    return set.flags();
}

std::string bench_markdown() {
    BenchOptions o;
    FlagSet set("bench");
    add_bench_flags(set, o);
    return set.markdown("bench [--workload LIST] [--threads LIST] [--msaa LIST] [--repeat N] [--json] [--alternate]\n"
                        "bench SCENE [--size WxH] [--tiles LIST] [--view NAME] [--flat] [--blend ALPHA] ...\n"
                        "bench --write-workloads DIR\n"
                        "bench --side-by-side RENDER_A RENDER_B [--workload LIST] [--threads LIST] [--msaa LIST] [--runs N] [--repeat N] [--json]\n"
                        "bench --psnr A.png B.png",
                        "Frame times of the full pipeline on the speed workloads (a developer tool, "
                        "tools/bench/). Timing lives here, never in the tests. Exit codes: 0 ok, 1 a failed "
                        "measurement or a bad file, 2 bad usage.");
}

} // namespace prast::cli

// The `bench` executable as a user runs it: writing the synthetic workloads,
// measuring them (text and --json), frames of 1 and 2 threads in turn, two
// `render` executables side by side, the PSNR of two images, and the errors
// for bad arguments. Timings are only checked for being ordered and positive
// (speed is never asserted in a test); what the figures describe is checked
// exactly: triangle counts, coverage, texture memory, identical images.
#include <doctest/doctest.h>

#include <cmath>
#include <cstdlib>
#include <string>
#include <vector>

#include "apps/cli/bench_flags.h"
#include "tests/cli_util.h"

using namespace prast::cli_test;

namespace {

// The JSON objects of `bench --json`, one per line.
std::vector<std::string> json_objects(const std::string& out) {
    std::vector<std::string> objects;
    for (const std::string& line : lines_of(out))
        if (line.find("{\"workload\"") != std::string::npos) objects.push_back(line);
    return objects;
}

// The number after "key": in a JSON object (NaN when absent).
double number(const std::string& object, const std::string& key) {
    const std::string k = "\"" + key + "\":";
    const std::size_t at = object.find(k);
    if (at == std::string::npos) return std::nan("");
    return std::strtod(object.c_str() + at + k.size(), nullptr);
}

// min <= median <= max, all positive, for a {"min":..,"median":..,"max":..} entry.
void check_summary(const std::string& object, const std::string& key) {
    const std::size_t at = object.find("\"" + key + "\":{");
    REQUIRE(at != std::string::npos);
    const std::string s = object.substr(at, object.find('}', at) - at);
    const double lo = number(s, "min"), mid = number(s, "median"), hi = number(s, "max");
    CHECK(lo > 0.0);
    CHECK(lo <= mid);
    CHECK(mid <= hi);
}

} // namespace

TEST_SUITE("bench") {
TEST_CASE("bench: writes its workloads and measures them, in text, JSON, alternation and side by side") {
    CliSandbox box;
    const std::string dir = box.path("workloads");
    CliRun w = box.run_exe(PRAST_BENCH_EXE, {"--write-workloads", dir});
    REQUIRE(w.code == 0);
    for (const char* f : {"quad/quad.obj", "quad/albedo.png", "grid/grid.gltf", "bottle/bottle.gltf",
                          "bottle/albedo.png", "commands.txt"})
        CHECK(fs::exists(fs::path(dir) / f));
    // commands.txt: a render command line per workload, which runs as written.
    std::string grid_command;
    for (const std::string& line : lines_of(read_text(fs::path(dir) / "commands.txt")))
        if (line.rfind("grid: render ", 0) == 0) grid_command = line.substr(std::string("grid: render ").size());
    REQUIRE(!grid_command.empty());
    // One line per workload --workload accepts, in its order.
    std::vector<std::string> listed;
    for (const std::string& line : lines_of(read_text(fs::path(dir) / "commands.txt")))
        listed.push_back(line.substr(0, line.find(':')));
    CHECK(listed == prast::cli::bench_workload_names());
    CHECK(grid_command.find("'--size' '1920x1080'") != std::string::npos);
    CliRun g = box.run_exe("sh", {"-c", shell_quote(PRAST_RENDER_EXE) + " " + grid_command + " --msaa 1 -o grid.png"});
    CHECK(g.code == 0);
    const Rgb8 grid_png = load_rgb8(box.path("grid.png"));
    CHECK(grid_png.width == 1920);
    CHECK(grid_png.height == 1080);

    // The runs below are at 480x270 (--size): the tool's output, not the
    // frame times, is under test, and a 1080p frame is slow under ASan.
    // --json: one object per workload with the figures docs/performance.md's table uses.
    CliRun j = box.run_exe(PRAST_BENCH_EXE, {"--workloads", dir, "--workload", "grid,bottle", "--threads", "1",
                                             "--repeat", "2", "--json", "--size", "480x270"});
    REQUIRE(j.code == 0);
    const std::vector<std::string> objects = json_objects(j.out);
    REQUIRE(objects.size() == 2);
    CHECK(j.out.front() == '[');
    const std::string& grid = objects[0];
    const std::string& bottle = objects[1];
    CHECK(grid.find("\"workload\":\"grid\"") != std::string::npos);
    CHECK(number(grid, "width") == 480);
    CHECK(number(grid, "height") == 270);
    CHECK(number(grid, "triangles") == 259200);  // a 480x270 grid of quads
    CHECK(number(grid, "coverage") == 1.0);
    CHECK(number(grid, "texture_bytes") == 0);
    CHECK(bottle.find("\"workload\":\"bottle\"") != std::string::npos);
    CHECK(number(bottle, "triangles") == 6912);
    CHECK(number(bottle, "coverage") > 0.10);  // 12% of the frame
    CHECK(number(bottle, "coverage") < 0.14);
    // Three 2048x2048 maps, each at most its 8-bit RGBA size plus a third for mips (22 MB).
    CHECK(number(bottle, "texture_bytes") > 0);
    CHECK(number(bottle, "texture_bytes") <= 3.0 * 2048 * 2048 * 4 * 4 / 3);
    for (const std::string& o : objects) {
        for (const char* k : {"frame_ms", "raster_shade_ms"}) check_summary(o, k);
        CHECK(number(o, "png_bytes") > 0);
    }

    // Frames of 1 and 2 threads in turn: the speed-up is reported and the
    // two images are the same (the line would say IMAGE DIFFERS).
    CliRun a = box.run_exe(PRAST_BENCH_EXE, {"--workloads", dir, "--workload", "grid", "--threads", "1,2",
                                             "--alternate", "--repeat", "1", "--size", "480x270"});
    REQUIRE(a.code == 0);
    CHECK(a.out.find("1 -> 2 threads: ") != std::string::npos);
    CHECK(a.out.find("median=") != std::string::npos);
    CHECK(a.out.find("IMAGE DIFFERS") == std::string::npos);

    // Two executables side by side (here the same one twice).
    CliRun s = box.run_exe(PRAST_BENCH_EXE, {"--side-by-side", PRAST_RENDER_EXE, PRAST_RENDER_EXE, "--workloads", dir,
                                             "--workload", "grid", "--runs", "1", "--repeat", "1", "--size", "480x270"});
    REQUIRE(s.code == 0);
    CHECK(s.out.find("side by side, 1 alternating runs each") != std::string::npos);
    CHECK(s.out.find("grid     whole process A ") != std::string::npos);
    CHECK(s.out.find("frame median A ") != std::string::npos);

    // Side by side in JSON, every thread count and sample count: one object each.
    CliRun sj = box.run_exe(PRAST_BENCH_EXE, {"--side-by-side", PRAST_RENDER_EXE, PRAST_RENDER_EXE, "--workloads", dir,
                                              "--workload", "grid", "--threads", "1,2", "--msaa", "1,4", "--runs", "2",
                                              "--repeat", "1", "--json", "--size", "480x270"});
    REQUIRE(sj.code == 0);
    CHECK(sj.out.front() == '[');
    CHECK(sj.out.find("side by side") == std::string::npos);  // JSON only
    const std::vector<std::string> pairs = json_objects(sj.out);
    REQUIRE(pairs.size() == 4);
    const double want[4][2] = {{1, 1}, {1, 4}, {2, 1}, {2, 4}};
    for (std::size_t i = 0; i < pairs.size(); ++i) {
        INFO(pairs[i]);
        CHECK(number(pairs[i], "threads") == want[i][0]);
        CHECK(number(pairs[i], "msaa") == want[i][1]);
        CHECK(number(pairs[i], "msaa_b") == want[i][1]);  // this render takes --msaa
        CHECK(number(pairs[i], "runs") == 2);
        check_summary(pairs[i], "rounds");
        for (const char* k : {"whole_ms", "frame_ms"}) {
            const std::size_t at = pairs[i].find(std::string("\"") + k + "\":{");
            REQUIRE(at != std::string::npos);
            const std::string o = pairs[i].substr(at, pairs[i].find('}', at) - at);
            CHECK(number(o, "a") > 0.0);
            CHECK(number(o, "b") > 0.0);
        }
    }
}

TEST_CASE("bench: PSNR of two images, and bad arguments are one line and a non-zero exit") {
    CliSandbox box;
    REQUIRE(box.run_exe(PRAST_RENDER_EXE, {"--size", "64x48", "--msaa", "1", "-o", "a.png"}).code == 0);
    REQUIRE(box.run_exe(PRAST_RENDER_EXE, {"--size", "64x48", "--msaa", "1", "--exposure", "2", "-o", "b.png"}).code == 0);
    REQUIRE(box.run_exe(PRAST_RENDER_EXE, {"--size", "32x48", "--msaa", "1", "-o", "c.png"}).code == 0);

    CliRun same = box.run_exe(PRAST_BENCH_EXE, {"--psnr", "a.png", "a.png"});
    CHECK(same.code == 0);
    CHECK(same.out == "psnr inf dB (identical)\n");
    CliRun differ = box.run_exe(PRAST_BENCH_EXE, {"--psnr", "a.png", "b.png"});
    CHECK(differ.code == 0);
    CHECK(differ.out.rfind("psnr ", 0) == 0);
    CHECK(differ.out.find("dB, max channel difference ") != std::string::npos);

    struct Bad { std::vector<std::string> args; int code; const char* says; };
    const Bad bad[] = {
        {{"--psnr", "a.png", "c.png"}, 1, "differ in size"},
        {{"--psnr", "a.png", "missing.png"}, 1, "missing.png"},
        {{"--workload", "nosuch"}, 2, "bench: --workload 'nosuch': unknown workload 'nosuch'"},
        {{"--msaa", "3"}, 2, "bench: --msaa '3': expected a comma list of 1, 2, 4 or 8"},
        {{"--size", "0x10", "--flat"}, 2, "bench: --size '0x10'"},
        {{"--repeat", "x"}, 2, "bench: --repeat 'x'"},
        {{"--psnr", "a.png"}, 2, "bench: --psnr: missing value"},
        {{"--bogus"}, 2, "bench: unknown option '--bogus'"},
        {{"--thread", "1"}, 2, "(did you mean --threads?)"},
    };
    for (const Bad& b : bad) {
        CAPTURE(b.args[0]);
        CAPTURE(b.args[1 < b.args.size() ? 1 : 0]);
        CliRun r = box.run_exe(PRAST_BENCH_EXE, b.args);
        CHECK(r.code == b.code);
        CHECK(r.err.find(b.says) != std::string::npos);
        CHECK(lines_of(r.err).size() == 1);
        CHECK(r.out.empty());
    }
    // Nothing was written but the three images.
    CHECK(box.work_files() == std::vector<std::string>{"a.png", "b.png", "c.png"});
}
} // TEST_SUITE

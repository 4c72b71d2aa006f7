// The flag definitions of render, step, prast-diff and bench
// (apps/cli/*_flags.cpp) against what the programs and the docs say: the
// flags page is the one the definitions make, every flag is on it and in its
// tool's --help, every value-taking flag refuses its bad values with one line
// and exit code 2, and unknown flags get the nearest defined one.
#include <doctest/doctest.h>

#include <random>
#include <string>
#include <vector>

#include "apps/cli/flags.h"
#include "apps/cli/flags_page.h"
#include "apps/cli/step_flags.h"
#include "apps/render_options.h"
#include "tests/cli_util.h"

using namespace prast;
using namespace prast::cli_test;

namespace {

std::string exe_of(const std::string& tool) {
    if (tool == "render") return PRAST_RENDER_EXE;
    if (tool == "step") return PRAST_STEP_EXE;
    if (tool == "prast-diff") return PRAST_DIFF_EXE;
    return PRAST_BENCH_EXE;
}

} // namespace

TEST_SUITE("flags") {

TEST_CASE("flags: docs/flags.md is the page the definitions make (build/apps/cli/flags-doc > docs/flags.md)") {
    const std::string page = read_text(std::string(PRAST_SOURCE_DIR) + "/docs/flags.md");
    REQUIRE_MESSAGE(!page.empty(), "docs/flags.md is missing");
    const std::string made = cli::flags_page();
    if (page != made) {
        // The first line that differs, to say what changed.
        const std::vector<std::string> a = lines_of(page), b = lines_of(made);
        std::size_t i = 0;
        while (i < a.size() && i < b.size() && a[i] == b[i]) ++i;
        FAIL("docs/flags.md differs from the definitions at line " << i + 1 << ":\n  page: "
                                                                    << (i < a.size() ? a[i] : "(end)")
                                                                    << "\n  made: " << (i < b.size() ? b[i] : "(end)"));
    }
}

TEST_CASE("flags: every flag of every tool is on the page and in the tool's --help") {
    const std::string page = cli::flags_page();
    CliSandbox box;
    const std::vector<cli::ToolFlags> tools = cli::all_tool_flags();
    REQUIRE(tools.size() == 4);
    for (const cli::ToolFlags& t : tools) {
        CAPTURE(t.tool);
        const std::size_t section = page.find("\n## " + t.tool + "\n");
        REQUIRE(section != std::string::npos);
        const std::size_t end = page.find("\n## ", section + 1);
        const std::string mine = page.substr(section, end == std::string::npos ? std::string::npos : end - section);
        const CliRun help = box.run_exe(exe_of(t.tool), {"--help"});
        CHECK(help.code == 0);
        CHECK(help.err.empty());
        CHECK(t.flags.size() >= 5);
        for (const cli::Flag& f : t.flags) {
            CAPTURE(f.name());
            CHECK(mine.find("`" + f.name()) != std::string::npos);
            for (const std::string& n : f.names) CHECK(help.out.find(n) != std::string::npos);
            CHECK(!f.brief.empty());
            // Every value-taking flag says what it refuses (the next test runs them).
            if (!f.value.empty()) CHECK(!f.bad.empty());
        }
    }
}

TEST_CASE("flags: a bad value for every value-taking flag is one line naming flag and value, exit code 2") {
    CliSandbox box;
    int runs = 0;
    for (const cli::ToolFlags& t : cli::all_tool_flags())
        for (const cli::Flag& f : t.flags) {
            if (f.value.empty()) continue;
            // One value per run; a flag with two values gets its bad pair.
            std::vector<std::vector<std::string>> cases;
            if (f.arity == 1)
                for (const std::string& b : f.bad) cases.push_back({b});
            else
                cases.push_back(f.bad);
            for (const std::vector<std::string>& values : cases) {
                std::vector<std::string> args = {f.name()};
                args.insert(args.end(), values.begin(), values.end());
                CAPTURE(t.tool);
                CAPTURE(f.name());
                CAPTURE(values.front());
                const CliRun r = box.run_exe(exe_of(t.tool), args);
                ++runs;
                CHECK(r.code == 2);
                CHECK(lines_of(r.err).size() == 1);
                CHECK(r.err.rfind(t.tool + ": " + f.name(), 0) == 0);
                if (!values.front().empty()) CHECK(r.err.find(values.front()) != std::string::npos);
                CHECK(r.out.empty());
            }
        }
    CHECK(runs > 100);
    CHECK(box.work_files().empty());
}

TEST_CASE("flags: an unknown flag gets the nearest defined one") {
    CliSandbox box;
    struct Case {
        std::string tool;
        std::vector<std::string> args;
        std::string err;
    };
    const std::vector<Case> cases = {
        {"render", {"--resolution", "640x480"}, "render: unknown option '--resolution' (did you mean --size?)\n"},
        {"render", {"--thread", "2"}, "render: unknown option '--thread' (did you mean --threads?)\n"},
        {"render", {"--tonemapper=aces"}, "render: unknown option '--tonemapper=aces' (did you mean --tonemap?)\n"},
        {"render", {"--shadow-sise", "64"}, "render: unknown option '--shadow-sise' (did you mean --shadow-size?)\n"},
        {"render", {"--hdri", "sky.hdr"}, "render: unknown option '--hdri' (did you mean --env?)\n"},
        {"render", {"-size", "64x64"}, "render: unknown option '-size' (did you mean --size?)\n"},
        {"render", {"--zzzz"}, "render: unknown option '--zzzz' (render --help lists them)\n"},
        {"step", {"--serv"}, "step: unknown option '--serv' (did you mean --serve?)\n"},
        {"step", {"--frames", "2"}, "step: --frames: not a step option (step records one frame; see step --help)\n"},
        {"prast-diff",
         {"a.png", "b.png", "--tolerence", "3"},
         "prast-diff: unknown option '--tolerence' (did you mean --tolerance?) (see prast-diff --help)\n"},
        {"bench", {"--workload=grid", "--json", "--alternat"},
         "bench: unknown option '--alternat' (did you mean --alternate?)\n"},
    };
    for (const Case& c : cases) {
        CAPTURE(c.args.front());
        const CliRun r = box.run_exe(exe_of(c.tool), c.args);
        CHECK(r.code == 2);
        CHECK(r.err == c.err);
        CHECK(r.out.empty());
    }
}

TEST_CASE("flags: suggestions and the edit distance") {
    CHECK(cli::edit_distance("kitten", "sitting") == 3);
    CHECK(cli::edit_distance("threads", "thraeds") == 1);  // a swap is one edit
    CHECK(cli::edit_distance("", "abc") == 3);
    cli::FlagSet set("t");
    set.value({"--size"}, "WxH", "size", "", {"x"}, [](const std::string&, const std::string&) {})
        .hints = {"resolution", "width"};
    set.value({"--frames"}, "N", "frames", "", {"x"}, [](const std::string&, const std::string&) {});
    set.value({"--frame-range"}, "A-B", "range", "", {"x"}, [](const std::string&, const std::string&) {});
    set.toggle({"--stats"}, "stats", [] {});
    CHECK(set.suggest("--resolution") == "--size");
    CHECK(set.suggest("--image-width") == "--size");  // a hint inside the name
    CHECK(set.suggest("--frame") == "--frames");      // one edit
    CHECK(set.suggest("--frame-ra") == "--frame-range");
    CHECK(set.suggest("--stast") == "--stats");
    CHECK(set.suggest("--colour") == "");
    CHECK(set.suggest("-x") == "");
}

TEST_CASE("flags: the parser's structure: --flag=value, --, repeated flags, stopping flags") {
    auto parse = [](std::vector<std::string> words, RenderOptions& o) {
        words.insert(words.begin(), "render");
        std::vector<const char*> argv;
        for (const std::string& w : words) argv.push_back(w.c_str());
        return parse_render_args(int(argv.size()), argv.data(), o, std::uint64_t(8) << 30);
    };
    RenderOptions a;
    CHECK(parse({"--size=96x64", "--size", "32x16", "-oout.png"}, a) == "");
    CHECK(a.width == 32);  // the last one wins
    CHECK(a.output == "out.png");
    RenderOptions b;
    CHECK(parse({"--", "-weird.obj"}, b) == "");
    CHECK(b.scene == "-weird.obj");
    RenderOptions c;
    CHECK(parse({"--output="}, c) == "--output: empty file name");
    CHECK(parse({"--stats="}, c) == "--stats: takes no value");
    CHECK(parse({"-5"}, c) == "unknown option '-5' (render --help lists them)");
    CHECK(parse({"--env-rotate", "-90", "--eye", "-1,2,3"}, c) == "");
    CHECK(*c.eye == glm::vec3(-1, 2, 3));
    RenderOptions d;
    CHECK(parse({"--fov", "30", "--help", "--bogus"}, d) == "");
    CHECK(d.help);
    RenderOptions e;
    CHECK(parse({"--fov", "abc", "--help"}, e) == "--fov 'abc': not a finite number");
    RenderOptions f;
    CHECK(parse({"--point", "0,1,0:1,1,1", "--sun", "0,1,0:2,2,2", "--point", "1,0,0:3,3,3"}, f) == "");
    REQUIRE(f.lights.size() == 3);
    CHECK(f.lights[0].point);
    CHECK(!f.lights[1].point);
    CHECK(f.lights[2].radiance == glm::vec3(3.0f));
}

TEST_CASE("flags: random command lines of render's and step's words never throw and fail in one line") {
    // Words from the definitions themselves (every spelling, --name=, their
    // bad values) and a few that look like flags or values.
    std::vector<std::string> words = {"--", "-", "", "-5", "--=", "-o=", "scene.obj", "1", "0,1,0", "0,1,0:1,1,1",
                                      "96x64", "a%04d.png", "on", "--bogus", "-xyz", "--size=", "1-2"};
    for (const cli::ToolFlags& t : cli::all_tool_flags())
        for (const cli::Flag& f : t.flags) {
            for (const std::string& n : f.names) words.insert(words.end(), {n, n + "=", n + "=1"});
            words.insert(words.end(), f.bad.begin(), f.bad.end());
        }
    std::mt19937 rng(20);
    std::uniform_int_distribution<std::size_t> pick(0, words.size() - 1), count(0, 8);
    int ok = 0, refused = 0;
    for (int i = 0; i < 3000; ++i) {
        std::vector<std::string> line = {"render"};
        for (std::size_t k = count(rng); k > 0; --k) line.push_back(words[pick(rng)]);
        std::vector<const char*> argv;
        for (const std::string& w : line) argv.push_back(w.c_str());
        RenderOptions o;
        cli::StepOptions so;
        RenderOptions so_opt;
        std::string err, step_err;
        REQUIRE_NOTHROW(err = parse_render_args(int(argv.size()), argv.data(), o, std::uint64_t(8) << 30));
        REQUIRE_NOTHROW(step_err = cli::parse_step_args(int(argv.size()), argv.data(), so, so_opt));
        CHECK(err.find('\n') == std::string::npos);
        CHECK(step_err.find('\n') == std::string::npos);
        if (err.empty() && !o.help && !o.version) {
            ++ok;
            CHECK(o.width >= 1);
            CHECK(o.height >= 1);
            CHECK(o.first_frame <= o.last_frame);
            CHECK(o.last_frame < o.frames);
        } else if (!err.empty()) {
            ++refused;
        }
    }
    CHECK(ok > 50);  // the words make good command lines too
    CHECK(refused > 500);
}

} // TEST_SUITE

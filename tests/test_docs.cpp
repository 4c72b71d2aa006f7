// Docs that cannot go stale: the pages in docs/ and README.md are checked
// against the programs and the tree they describe.
//   - docs/step.md: every block that starts with `$ echo '...' | build/step`
//     is run through the built `step`, and its lines must appear in what step
//     prints, in order (`...` skips lines, a line ending in ` ...` matches by
//     prefix); the page's longer numbers must be numbers step printed; its
//     stage pictures (docs/step/) must be what `step --out` writes;
//   - docs/testing.md lists every CTest test (the suites of tests/test_*.cpp
//     and the add_test() names of the CMake files), and nothing else;
//   - every relative link and #anchor in README.md and docs/*.md resolves;
//   - README.md is at most 300 lines, opens with the two set-up commands (the
//     second exactly the one .ci/run runs), and its five `render` examples run
//     and reproduce the pictures in docs/ that they are named after;
//   - docs/performance.md's table is the one its own data gives.
#include <doctest/doctest.h>

#include <algorithm>
#include <cctype>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <regex>
#include <set>
#include <string>
#include <vector>

#include "tests/cli_util.h"

using namespace prast::cli_test;

namespace {

const std::string kSource = PRAST_SOURCE_DIR;
const std::string kStep = PRAST_STEP_EXE;
const std::string kRender = PRAST_RENDER_EXE;

std::string source_text(const std::string& rel) { return read_text(fs::path(kSource) / rel); }

bool starts_with(const std::string& s, const std::string& p) { return s.compare(0, p.size(), p) == 0; }

std::string trim(const std::string& s) {
    const std::size_t a = s.find_first_not_of(" \t\r");
    if (a == std::string::npos) return "";
    const std::size_t b = s.find_last_not_of(" \t\r");
    return s.substr(a, b - a + 1);
}

std::vector<std::string> split_words(const std::string& s) {
    std::vector<std::string> out;
    std::string w;
    for (char c : s + " ") {
        if (c == ' ' || c == '\t') {
            if (!w.empty()) out.push_back(w);
            w.clear();
        } else {
            w += c;
        }
    }
    return out;
}

// A Markdown page split into fenced code blocks and the prose around them.
struct Block {
    int line = 0;  // 1-based line of the opening fence
    std::string info;
    std::vector<std::string> lines;
};
struct Page {
    std::vector<Block> blocks;
    std::vector<std::pair<int, std::string>> prose;  // (line, text) outside fences
};

Page parse_page(const std::string& text) {
    Page p;
    const std::vector<std::string> lines = lines_of(text);
    bool in_fence = false;
    for (std::size_t i = 0; i < lines.size(); ++i) {
        const std::string t = trim(lines[i]);
        if (starts_with(t, "```")) {
            if (!in_fence) p.blocks.push_back({int(i) + 1, t.substr(3), {}});
            in_fence = !in_fence;
            continue;
        }
        if (in_fence) p.blocks.back().lines.push_back(lines[i]);
        else p.prose.push_back({int(i) + 1, lines[i]});
    }
    return p;
}

// The line without its inline code spans.
std::string without_code(const std::string& line) {
    std::string out;
    bool code = false;
    for (char c : line) {
        if (c == '`') code = !code;
        else if (!code) out += c;
    }
    return out;
}

// GitHub's heading anchors: lower case, spaces to '-', punctuation dropped,
// repeated headings numbered -1, -2, ...
std::set<std::string> anchors_of(const Page& page) {
    std::set<std::string> out;
    std::map<std::string, int> seen;
    for (const auto& [n, line] : page.prose) {
        (void)n;
        if (!starts_with(line, "#")) continue;
        const std::size_t a = line.find_first_not_of('#');
        if (a == std::string::npos || line[a] != ' ') continue;
        std::string slug;
        for (char c : trim(line.substr(a))) {
            const unsigned char u = static_cast<unsigned char>(c);
            if (std::isalnum(u)) slug += char(std::tolower(u));
            else if (c == ' ') slug += '-';
            else if (c == '-' || c == '_') slug += c;
        }
        const int k = seen[slug]++;
        out.insert(k == 0 ? slug : slug + "-" + std::to_string(k));
    }
    return out;
}

std::vector<fs::path> doc_pages() {
    std::vector<fs::path> pages = {fs::path(kSource) / "README.md"};
    for (const auto& e : fs::directory_iterator(fs::path(kSource) / "docs"))
        if (e.path().extension() == ".md") pages.push_back(e.path());
    std::sort(pages.begin(), pages.end());
    return pages;
}

// Runs `exe args` in the sandbox with `input` on standard input.
CliRun run_with_input(CliSandbox& box, const std::string& exe, const std::vector<std::string>& args,
                      const std::string& input) {
    const fs::path dir = box.work().parent_path();
    write_text(dir / "stdin.txt", input);
    std::string cmd = "cd " + shell_quote(box.work().string()) + " && " + shell_quote(exe);
    for (const std::string& a : args) cmd += " " + shell_quote(a);
    cmd += " <" + shell_quote((dir / "stdin.txt").string()) + " >" + shell_quote((dir / "stdout.txt").string()) +
           " 2>" + shell_quote((dir / "stderr.txt").string());
    const int status = std::system(cmd.c_str());
    CliRun r;
    if (status != -1 && WIFEXITED(status)) r.code = WEXITSTATUS(status);
    else if (status != -1 && WIFSIGNALED(status)) r.code = 128 + WTERMSIG(status);
    r.out = read_text(dir / "stdout.txt");
    r.err = read_text(dir / "stderr.txt");
    return r;
}

// Whether `want` (a page's lines: `...` skips, a trailing ` ...` matches a
// prefix) appears in `got` in order. On failure, `why` says which line.
bool quoted_in(const std::vector<std::string>& want, const std::vector<std::string>& got, std::string& why) {
    std::size_t pos = 0;
    bool gap = false;
    for (const std::string& w : want) {
        if (trim(w) == "...") {
            gap = true;
            continue;
        }
        const bool prefix = w.size() > 4 && w.compare(w.size() - 4, 4, " ...") == 0;
        const std::string key = prefix ? w.substr(0, w.size() - 4) : w;
        auto matches = [&](const std::string& g) { return prefix ? starts_with(g, key) : g == key; };
        std::size_t j = pos;
        if (gap) {
            while (j < got.size() && !matches(got[j])) ++j;
        } else if (j < got.size() && !matches(got[j])) {
            j = got.size();
        }
        if (j >= got.size()) {
            why = "the page quotes\n  " + w + "\nbut step printed " +
                  (pos < got.size() ? "(at that point)\n  " + got[pos] : std::string("nothing more"));
            return false;
        }
        pos = j + 1;
        gap = false;
    }
    return true;
}

// The digit runs of a text ("1280x720" gives 1280 and 720).
std::set<std::string> numbers_in(const std::string& text) {
    std::set<std::string> out;
    std::string cur;
    for (char c : text + " ") {
        if (std::isdigit(static_cast<unsigned char>(c))) {
            cur += c;
        } else {
            if (!cur.empty()) out.insert(cur);
            cur.clear();
        }
    }
    return out;
}

} // namespace

TEST_SUITE("docs") {

TEST_CASE("docs/step.md: every quoted step session is what step prints today") {
    const std::string rel = "docs/step.md";
    const Page page = parse_page(source_text(rel));
    const std::regex command(R"(^\$ echo '([^']*)' \| build/step(.*)$)");
    int checked = 0;
    std::string printed;  // everything step printed, for the prose's numbers
    for (const Block& b : page.blocks) {
        if (b.lines.empty() || !starts_with(b.lines[0], "$ ")) continue;
        INFO(rel << ":" << b.line << ": " << b.lines[0]);
        std::smatch m;
        // A session the test cannot run would go stale unseen.
        REQUIRE_MESSAGE(std::regex_match(b.lines[0], m, command),
                        "a command block must read `$ echo 'COMMANDS' | build/step [FLAGS]`");
        CliSandbox box;
        const CliRun r = run_with_input(box, kStep, split_words(m[2].str()), m[1].str() + "\n");
        CHECK(r.code == 0);
        CHECK(r.err == "");
        const std::vector<std::string> want(b.lines.begin() + 1, b.lines.end());
        std::string why;
        CHECK_MESSAGE(quoted_in(want, lines_of(r.out), why), why);
        printed += r.out;
        ++checked;
    }
    // The tutorial's sessions: frame, tri, the clipped tri, tile, two pixels, upto.
    CHECK(checked >= 7);

    // Numbers of four or more digits in the prose (outside code) are quotes
    // of step's output too: each must be a number step printed above.
    const std::set<std::string> got = numbers_in(printed);
    for (const auto& [n, line] : page.prose) {
        std::string plain;
        for (char c : without_code(line))
            if (c != ',') plain += c;  // 98,432 is 98432
        for (const std::string& num : numbers_in(plain)) {
            if (num.size() < 4) continue;
            INFO(rel << ":" << n << ": " << line);
            CHECK_MESSAGE(got.count(num) == 1, "the page says " << num << ", which step did not print");
        }
    }
}

TEST_CASE("docs/step/: the tutorial's stage pictures are what step --out writes today") {
    // The page names the command; page*.png are browser screenshots, not stages.
    const std::string page = source_text("docs/step.md");
    REQUIRE(page.find("`build/step --size 640x360 --out steps`") != std::string::npos);
    CliSandbox box;
    const CliRun r = box.run_exe(kStep, {"--size", "640x360", "--out", "steps"});
    REQUIRE(r.code == 0);
    int compared = 0;
    for (const auto& e : fs::directory_iterator(fs::path(kSource) / "docs" / "step")) {
        const std::string name = e.path().filename().string();
        if (e.path().extension() != ".png") continue;
        if (name.rfind("page", 0) == 0) {
            CHECK_MESSAGE(page.find("(step/" + name + ")") != std::string::npos, name << " not shown on docs/step.md");
            continue;
        }
        INFO("docs/step/" << name);
        CHECK_MESSAGE(page.find("(step/" + name + ")") != std::string::npos, "not shown on docs/step.md");
        const Rgb8 want = load_rgb8(e.path().string());
        const Rgb8 got = load_rgb8(box.path("steps/" + name));
        REQUIRE(!got.empty());
        CHECK(got.width == want.width);
        CHECK(got.height == want.height);
        CHECK_MESSAGE(got.rgb == want.rgb, "regenerate it with build/step --size 640x360 --out steps");
        ++compared;
    }
    CHECK(compared >= 6);
}

TEST_CASE("docs/testing.md lists every CTest test, and nothing else") {
    std::set<std::string> tests;
    const std::regex suite("TEST_SUITE\\(\"([^\"]+)\"\\)");
    for (const auto& e : fs::directory_iterator(fs::path(kSource) / "tests")) {
        const std::string name = e.path().filename().string();
        if (!starts_with(name, "test_") || e.path().extension() != ".cpp") continue;
        const std::string text = read_text(e.path());
        for (auto it = std::sregex_iterator(text.begin(), text.end(), suite); it != std::sregex_iterator(); ++it)
            tests.insert((*it)[1].str());
    }
    const std::regex add_test(R"(add_test\(NAME ([^\s)]+))");
    for (const char* cmake : {"CMakeLists.txt", "tests/browser/CMakeLists.txt"}) {
        const std::string text = source_text(cmake);
        REQUIRE(!text.empty());
        for (auto it = std::sregex_iterator(text.begin(), text.end(), add_test); it != std::sregex_iterator(); ++it) {
            const std::string name = (*it)[1].str();
            if (name.find('$') == std::string::npos) tests.insert(name);  // ${_suite}: the suites above
        }
    }
    // The ones every build has, so that a broken scan cannot pass.
    for (const char* t : {"raster", "cli", "step", "docs", "layers", "examples", "outside_suites", "serve"})
        CHECK_MESSAGE(tests.count(t) == 1, t << " not found in the sources");

    std::set<std::string> listed;
    for (const std::string& line : lines_of(source_text("docs/testing.md"))) {
        if (!starts_with(line, "| `")) continue;
        const std::size_t end = line.find('`', 3);
        REQUIRE(end != std::string::npos);
        listed.insert(line.substr(3, end - 3));
    }
    for (const std::string& t : tests) CHECK_MESSAGE(listed.count(t) == 1, "docs/testing.md does not list " << t);
    for (const std::string& t : listed) CHECK_MESSAGE(tests.count(t) == 1, "docs/testing.md lists " << t << ", no such test");
}

TEST_CASE("every relative link in README.md and docs/*.md reaches a file, and its #anchor a heading") {
    const std::regex link(R"(\]\(([^)\s]+)\))");
    std::map<fs::path, std::set<std::string>> anchors;
    auto anchors_for = [&](const fs::path& p) -> const std::set<std::string>& {
        auto it = anchors.find(p);
        if (it == anchors.end()) it = anchors.emplace(p, anchors_of(parse_page(read_text(p)))).first;
        return it->second;
    };
    int links = 0;
    const std::vector<fs::path> pages = doc_pages();
    CHECK(pages.size() >= 12);
    for (const fs::path& page : pages) {
        const Page parsed = parse_page(read_text(page));
        for (const auto& [n, line] : parsed.prose) {
            const std::string text = without_code(line);
            for (auto it = std::sregex_iterator(text.begin(), text.end(), link); it != std::sregex_iterator(); ++it) {
                const std::string target = (*it)[1].str();
                if (target.find("://") != std::string::npos || starts_with(target, "mailto:")) continue;
                ++links;
                INFO(fs::relative(page, kSource).string() << ":" << n << ": " << target);
                const std::size_t hash = target.find('#');
                const std::string file = target.substr(0, hash);
                const fs::path resolved = file.empty() ? page : (page.parent_path() / file).lexically_normal();
                CHECK_MESSAGE(fs::exists(resolved), "no such file");
                if (hash != std::string::npos && resolved.extension() == ".md" && fs::exists(resolved)) {
                    const std::string anchor = target.substr(hash + 1);
                    CHECK_MESSAGE(anchors_for(resolved).count(anchor) == 1, "no heading with the anchor #" << anchor);
                }
            }
        }
    }
    CHECK(links >= 100);
}

TEST_CASE("README.md: at most 300 lines, opening with the two set-up commands of .ci/run") {
    const std::string readme = source_text("README.md");
    const std::vector<std::string> lines = lines_of(readme);
    CHECK(lines.size() <= 300);
    const Page page = parse_page(readme);
    REQUIRE(!page.blocks.empty());
    const Block& first = page.blocks.front();
    // Only the title and one sentence come before the commands.
    CHECK(first.line <= 5);
    std::vector<std::string> commands;
    for (const std::string& l : first.lines)
        if (!trim(l).empty() && !starts_with(trim(l), "#")) commands.push_back(trim(l));
    REQUIRE(commands.size() == 2);
    CHECK(starts_with(commands[0], "scripts/install-deps.sh && "));
    CHECK(commands[0].find("./build/render -o default.png") != std::string::npos);
    // The second is the test command CI runs, character for character.
    const std::vector<std::string> ci = lines_of(source_text(".ci/run"));
    CHECK(std::find(ci.begin(), ci.end(), commands[1]) != ci.end());
    CHECK(commands[1].find("ctest --test-dir build") != std::string::npos);
}

TEST_CASE("docs/default.png is what the README's first command draws (render with no arguments)") {
    CliSandbox box;
    const CliRun r = box.run_exe(kRender, {"-o", "default.png"});
    REQUIRE(r.code == 0);
    const Rgb8 got = load_rgb8(box.path("default.png"));
    const Rgb8 want = load_rgb8(kSource + "/docs/default.png");
    REQUIRE(!got.empty());
    CHECK(got.width == want.width);
    CHECK(got.height == want.height);
    CHECK_MESSAGE(got.rgb == want.rgb, "regenerate it with ./build/render -o docs/default.png");
}

TEST_CASE("README.md: the five render examples run and draw the pictures they are named after") {
    const Page page = parse_page(source_text("README.md"));
    std::vector<std::string> examples;
    for (const Block& b : page.blocks)
        for (const std::string& l : b.lines)
            if (starts_with(l, "build/render ")) examples.push_back(l);
    REQUIRE(examples.size() == 5);
    int compared = 0;
    for (const std::string& example : examples) {
        INFO("README.md: " << example);
        std::vector<std::string> args = split_words(example.substr(13));
        std::string out;
        int frames = 1;
        for (std::size_t i = 0; i < args.size(); ++i) {
            if (starts_with(args[i], "assets/") || starts_with(args[i], "docs/")) args[i] = kSource + "/" + args[i];
            if (args[i] == "-o" && i + 1 < args.size()) out = args[i + 1];
            if (args[i] == "--frames" && i + 1 < args.size()) frames = std::atoi(args[i + 1].c_str());
        }
        REQUIRE(!out.empty());
        CliSandbox box;
        const CliRun r = box.run_exe(kRender, args);
        REQUIRE(r.code == 0);
        if (out.find("%04d") != std::string::npos) {
            char name[64];
            for (int f = 0; f < frames; ++f) {
                std::snprintf(name, sizeof name, out.c_str(), f);
                CHECK_MESSAGE(fs::exists(box.path(name)), name << " not written");
            }
            continue;
        }
        const Rgb8 got = load_rgb8(box.path(out));
        REQUIRE(!got.empty());
        const fs::path picture = fs::path(kSource) / "docs" / out;
        if (!fs::exists(picture)) continue;
        const Rgb8 want = load_rgb8(picture.string());
        CHECK(got.width == want.width);
        CHECK(got.height == want.height);
        CHECK_MESSAGE(got.rgb == want.rgb, "the picture docs/" << out << " is not what the command draws");
        ++compared;
    }
    CHECK(compared >= 4);
}

TEST_CASE("docs/performance.md: the table is the one its data gives") {
    if (std::system("command -v python3 >/dev/null 2>&1") != 0) {
        MESSAGE("skipped: python3 not found");
        return;
    }
    const std::string cmd = "python3 " + shell_quote(kSource + "/scripts/perf_table.py") + " table --check --page " +
                            shell_quote(kSource + "/docs/performance.md");
    CHECK(std::system(cmd.c_str()) == 0);
}

} // TEST_SUITE

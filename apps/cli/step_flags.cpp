// step's flags; see step_flags.h.
#include "apps/cli/step_flags.h"

#include <algorithm>

#include "apps/cli/render_flags.h"
#include "apps/cli/values.h"

namespace prast::cli {

namespace {

const char* const kStepHead =
    "usage: step [SCENE] [options]      SCENE: .obj, .gltf or .glb; none: built-in\n"
    "  records one frame, as `render` with the same flags would draw it, and explains it:\n"
    "  commands on standard input (type help), or\n";

void add_step_flags(FlagSet& set, StepOptions& so, bool& port_given) {
    Flag& out = set.value({"--out"}, "DIR", "every stage as a PNG and DIR/index.html", "", {""},
                          [&so](const std::string& flag, const std::string& v) {
                              if (v.empty()) fail(flag + ": empty directory name");
                              so.out_dir = v;
                          });
    out.help = "Writes every stage of the frame as a PNG and `DIR/index.html`, a page that explains them, then exits.";
    out.hints = {"output", "dir", "html", "export", "out-dir"};
    Flag& serve = set.toggle({"--serve"}, "a web page on 127.0.0.1", [&so] { so.serve = true; });
    serve.help = "Serves the stepper as a web page on `http://127.0.0.1:PORT/` (local connections only).";
    serve.hints = {"server", "http", "web", "browser"};
    Flag& port = set.value({"--port"}, "N", "the --serve port", "8137", {"65536", "x"},
                           [&so, &port_given](const std::string& flag, const std::string& v) {
                               if (!parse_integer_in(v, 0, 65535, so.port)) bad_value(flag, v, "expected 0..65535");
                               port_given = true;
                           });
    port.help = "The port of `--serve`, 0 to 65535; 0 takes any free port (printed).";
    port.hints = {"listen", "http-port"};
}

std::string refuse_render_only(const std::string& flag) {
    if (flag == "--allow-outside-paths")
        return flag + ": not a step option (step reads only files inside the model's folder: it may show "
                      "them in a web page)";
    const auto& r = render_only_flags();
    if (std::find(r.begin(), r.end(), flag) != r.end())
        return flag + ": not a step option (step records one frame; see step --help)";
    return "";
}

std::vector<HelpRow> step_rows() {
    std::vector<HelpRow> rows = {{{"--out"}, ""},
                                 {{"--serve", "--port"}, "a web page on http://127.0.0.1:N/ (default 8137; 0: any)"}};
    const std::vector<HelpRow> render_rows = render_help_rows(false);
    // render's --pixel row first (step's third way out), then the rest.
    for (const HelpRow& r : render_rows)
        if (r.flags == std::vector<std::string>{"--pixel"}) rows.push_back(r);
    rows.push_back({{}, "scene, camera, light and view flags as render's (render --help):"});
    for (const HelpRow& r : render_rows) {
        if (r.flags == std::vector<std::string>{"--pixel"} || r.flags.front() == "--help") continue;
        rows.push_back({r.flags, ""});  // render --help has the words
    }
    rows.push_back(render_rows.back());
    return rows;
}

struct StepDefinitions {
    StepOptions so;
    RenderOptions options;
    RenderParse st{options, ~std::uint64_t(0)};
    bool port_given = false;
    FlagSet set{"step"};
    StepDefinitions() {
        add_step_flags(set, so, port_given);
        add_render_flags(set, st, false);
        set.positional("SCENE", "as render's; none: the built-in scene");
    }
};

} // namespace

std::string parse_step_args(int argc, const char* const* argv, StepOptions& so, RenderOptions& opt) {
    bool port_given = false;
    RenderParse st{opt, memory_budget()};
    FlagSet set("step");
    set.unknown_hint = " (step --help lists them)";
    set.refuse = refuse_render_only;
    add_step_flags(set, so, port_given);
    add_render_flags(set, st, false);
    std::vector<std::string> positionals;
    std::string err = set.parse(argc, argv, positionals);
    if (!err.empty() || opt.help || opt.version) return err;
    if (port_given && !so.serve) return "--port: only with --serve";
    if (so.serve && !so.out_dir.empty()) return "--serve and --out: choose one";
    return finish_render_options(st, positionals);
}

const char* step_usage() {
    static const std::string text = [] {
        StepDefinitions d;
        return d.set.usage(kStepHead, step_rows(), "");
    }();
    return text.c_str();
}

std::vector<Flag> step_flag_list() {
    StepDefinitions d;
    return d.set.flags();
}

std::string step_markdown() {
    StepDefinitions d;
    return d.set.markdown("step [SCENE] [options]",
                          "Records one frame, as `render` with the same flags would draw it, and explains it: "
                          "commands on standard input, `--out DIR`, `--serve` or `--pixel X,Y`. The scene, camera, "
                          "light and view flags are render's (see there); render's `-o`, `--frames`, `--orbit`, "
                          "`--fps`, `--frame-range`, `--repeat`, `--view`, `--stats`, `--list` and "
                          "`--allow-outside-paths` are refused. "
                          "Exit codes: 0 ok, 1 a bad file or a failed command, 2 bad usage.",
                          [](const Flag& f) {
                              for (const char* own : {"--out", "--serve", "--port", "--pixel", "--help", "--version"})
                                  if (f.name() == own) return true;
                              return false;
                          },
                          "render");
}

} // namespace prast::cli

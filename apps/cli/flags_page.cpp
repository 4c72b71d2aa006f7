// docs/flags.md from the definitions; see flags_page.h.
#include "apps/cli/flags_page.h"

#include "apps/cli/bench_flags.h"
#include "apps/cli/diff_flags.h"
#include "apps/cli/render_flags.h"
#include "apps/cli/step_flags.h"

namespace prast::cli {

std::string flags_page() {
    return "<!-- Generated from apps/cli/*_flags.cpp by flags-doc: do not edit. After changing a flag:\n"
           "     cmake --build build --target flags-doc && build/apps/cli/flags-doc > docs/flags.md\n"
           "     (the test `flags` fails while this page differs from the definitions). -->\n"
           "# Flags\n\n"
           "Every flag of the four programs. Values may follow the flag (`--size 640x480`) or be joined to it "
           "with `=` (`--size=640x480`); `-o` also takes `-oFILE`. A later value replaces an earlier one, "
           "except for `--sun` and `--point`, which add lights. After `--` every argument is a file. A bad value "
           "is one line on stderr naming the flag and the value, and exit code 2; an unknown flag gets the "
           "nearest defined one (\"did you mean --size?\").\n\n" +
           render_markdown() + "\n" + step_markdown() + "\n" + diff_markdown() + "\n" + bench_markdown();
}

std::vector<ToolFlags> all_tool_flags() {
    std::vector<ToolFlags> out = {{"render", render_flag_list()},
                                  {"step", step_flag_list()},
                                  {"prast-diff", diff_flag_list()},
                                  {"bench", bench_flag_list()}};
    for (ToolFlags& t : out)
        for (Flag& f : t.flags) f.apply = nullptr;
    return out;
}

} // namespace prast::cli

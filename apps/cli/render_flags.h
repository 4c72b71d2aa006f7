// render's flags as a FlagSet, for render itself (parse_render_args in
// apps/render_options.h) and for step, which takes most of them.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "apps/cli/flags.h"
#include "apps/render_options.h"

namespace prast::cli {

// What the checks after the last flag need besides the options.
struct RenderParse {
    RenderParse(RenderOptions& options, std::uint64_t budget) : out(options), memory_budget(budget) {}
    RenderOptions& out;
    std::uint64_t memory_budget;
    bool frames_given = false;
    std::string range_text;  // --frame-range as given
    std::string needs_env;   // the first flag given that needs an environment, with its value
};

// render's flags that make no sense for step's one recorded frame.
const std::vector<std::string>& render_only_flags();

// Adds render's flags writing into st.out; without the render-only ones when
// `render_only` is false.
void add_render_flags(FlagSet& set, RenderParse& st, bool render_only = true);
// The checks that need every flag (--pixel inside --size, --near < --far,
// environment flags need an environment, ...): "" or the error line.
std::string finish_render_options(RenderParse& st, const std::vector<std::string>& positionals);

// render's --help rows; step's --help shows the same flags with its own.
std::vector<HelpRow> render_help_rows(bool render_only = true);

// render's section of docs/flags.md.
std::string render_markdown();
// The definitions (see all_tool_flags in flags_page.h).
std::vector<Flag> render_flag_list();

} // namespace prast::cli

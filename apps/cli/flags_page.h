// docs/flags.md, made from the flag definitions of the four tools.
#pragma once

#include <string>
#include <vector>

#include "apps/cli/flags.h"

namespace prast::cli {

std::string flags_page();

// The four tools' definitions, for the tests: every flag documented, listed
// by --help and refusing its bad values. Handlers are dropped (they wrote
// into options that are gone).
struct ToolFlags {
    std::string tool;  // the executable's name
    std::vector<Flag> flags;
};
std::vector<ToolFlags> all_tool_flags();

} // namespace prast::cli

// flags-doc: prints docs/flags.md, the flags page made from the definitions
// (cmake --build build --target flags-doc && build/apps/cli/flags-doc > docs/flags.md).
#include <cstdio>

#include "apps/cli/flags_page.h"

int main() {
    std::fputs(prast::cli::flags_page().c_str(), stdout);
    return 0;
}

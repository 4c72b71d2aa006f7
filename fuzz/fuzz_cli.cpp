// libFuzzer harness: render's command-line parser (apps/render_options.h,
// the flags of apps/cli/render_flags.cpp through CLI11), arguments split at
// NUL bytes; a successful parse must leave options render can use as they
// are (fuzz/targets.h: run_cli), else it traps.
#include "fuzz/targets.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    if (!prast::fuzz::run_cli(data, size)) __builtin_trap();
    return 0;
}

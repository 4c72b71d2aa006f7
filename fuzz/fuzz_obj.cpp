// libFuzzer harness: the OBJ+MTL loader (fuzz/targets.h: run_obj).
#include "fuzz/targets.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    static const std::string dir = prast::fuzz::make_model_dir("obj");
    prast::fuzz::run_obj(dir, data, size);
    return 0;
}

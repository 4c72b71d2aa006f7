// libFuzzer harness: the glTF 2.0 loader, .gltf and .glb (fuzz/targets.h: run_gltf).
#include "fuzz/targets.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    static const std::string dir = prast::fuzz::make_model_dir("gltf");
    prast::fuzz::run_gltf(dir, data, size);
    return 0;
}

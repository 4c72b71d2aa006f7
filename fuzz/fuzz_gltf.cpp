// libFuzzer harness: the glTF 2.0 loader, text (.gltf) or binary (.glb: the
// input starts with "glTF"). Next to the model: b.bin (256 bytes of floats
// and indices that the seeds' buffers name) and t.png. Only LoadError may
// leave the loader; anything else is a finding.
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include "fuzz/fuzz_util.h"
#include "scene/load_scene.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    static const std::string dir = [] {
        const std::string d = prast::fuzz::scratch_dir("gltf");
        std::size_t n = 0;
        const unsigned char* png = prast::fuzz::tiny_png(n);
        prast::fuzz::write_file(d + "/t.png", png, n);
        // A triangle: 3 float positions (36 bytes), then 3 uint16 indices.
        std::vector<unsigned char> bin(256, 0);
        const float pos[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
        const std::uint16_t idx[3] = {0, 1, 2};
        std::memcpy(bin.data(), pos, sizeof pos);
        std::memcpy(bin.data() + 36, idx, sizeof idx);
        prast::fuzz::write_file(d + "/b.bin", bin.data(), bin.size());
        return d;
    }();
    const bool glb = size >= 4 && std::memcmp(data, "glTF", 4) == 0;
    const std::string path = dir + (glb ? "/model.glb" : "/model.gltf");
    prast::fuzz::write_file(path, data, size);
    try {
        const prast::Scene scene = prast::load_gltf(path);
        (void)scene.bounds();
    } catch (const prast::LoadError&) {
    }
    return 0;
}

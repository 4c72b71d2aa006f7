// libFuzzer harness: the OBJ+MTL loader. The input is an OBJ text, then,
// after a line "#--mtl--", the text of m.mtl (the seeds' OBJs say mtllib
// m.mtl). Next to them: t.png and a sub/ folder, so map_* paths resolve to
// something. Only LoadError may leave the loader; anything else, a crash, a
// sanitizer report, a hang (-timeout) or an allocation over -rss_limit_mb is
// a finding.
#include <cstddef>
#include <cstdint>
#include <string>

#include <sys/stat.h>

#include "fuzz/fuzz_util.h"
#include "scene/load_scene.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    static const std::string dir = [] {
        const std::string d = prast::fuzz::scratch_dir("obj");
        std::size_t n = 0;
        const unsigned char* png = prast::fuzz::tiny_png(n);
        prast::fuzz::write_file(d + "/t.png", png, n);
        mkdir((d + "/sub").c_str(), 0700);
        prast::fuzz::write_file(d + "/sub/t.png", png, n);
        return d;
    }();
    const std::string text(reinterpret_cast<const char*>(data), size);
    const std::string sep = "#--mtl--\n";
    const std::size_t cut = text.find(sep);
    prast::fuzz::write_file(dir + "/model.obj", text.substr(0, cut));
    prast::fuzz::write_file(dir + "/m.mtl", cut == std::string::npos ? std::string() : text.substr(cut + sep.size()));
    try {
        const prast::Scene scene = prast::load_obj(dir + "/model.obj");
        (void)scene.bounds();
    } catch (const prast::LoadError&) {
    }
    return 0;
}

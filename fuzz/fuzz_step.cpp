// libFuzzer harness: the stepper's command interpreter (stepper/session.h),
// which both `step`'s standard input and `step --serve`'s JSON API call for
// every request. One recording of the built-in scene at 48x32 is made once;
// each input is up to 16 command lines run against it. Commands that would
// write a file get no file name (their default names land in the scratch
// folder the harness works in), and `cost` (a timing loop) is skipped.
#include <cstddef>
#include <cstdint>
#include <string>

#include <unistd.h>

#include "fuzz/targets.h"
#include "stepper/recording.h"
#include "renderer/frame_setup.h"
#include "stepper/session.h"

namespace {

using namespace prast::stepper;

prast::FrameSetup g_scene;
Recording g_rec;
Session* g_session = nullptr;

} // namespace

// The recording is made before fuzzing starts, outside the per-input timeout
// (the built-in scene's procedural textures take seconds in this build).
extern "C" int LLVMFuzzerInitialize(int*, char***) {
    if (chdir(prast::fuzz::make_model_dir("step").c_str()) != 0) __builtin_trap();
    prast::FrameRequest req;
    req.width = 48;
    req.height = 32;
    req.threads = 1;
    req.recording = true;
    if (prast::setup_frame(req, g_scene) || g_scene.orbit(0.0)) __builtin_trap();
    record_frame(g_scene, g_rec);
    g_session = new Session(g_scene, g_rec);
    return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    Session* session = g_session;
    const std::string text(reinterpret_cast<const char*>(data), size);
    std::size_t begin = 0;
    for (int n = 0; n < 16 && begin <= text.size(); ++n) {
        std::size_t end = text.find('\n', begin);
        if (end == std::string::npos) end = text.size();
        const std::string line = text.substr(begin, end - begin);
        begin = end + 1;
        const std::vector<std::string> w = split_words(line);
        if (!w.empty() && w[0] == "cost") continue;
        if (w.size() >= 3 && (w[0] == "stage" || w[0] == "upto")) continue;
        const Reply r = session->run(line);
        if (!r.ok && r.text.rfind("error: ", 0) != 0) __builtin_trap();  // errors are one "error: ..." line
    }
    return 0;
}

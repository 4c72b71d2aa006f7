// libFuzzer harness: image decoding (scene/image.cpp: stb_image behind our
// checks and, for Radiance, the run-length guard), one build per format:
// PRAST_FUZZ_PNG, PRAST_FUZZ_JPEG or PRAST_FUZZ_HDR. An input that does not
// start with its format's signature gets it in front, so the fuzzer stays on
// that decoder's path. Decoding and the header-only image_dimensions() may
// only throw LoadError.
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include <stb_image.h>

#include "scene/image.h"

namespace {

#if defined(PRAST_FUZZ_PNG)
const char kSignature[] = "\x89PNG\r\n\x1a\n";
#elif defined(PRAST_FUZZ_JPEG)
const char kSignature[] = "\xff\xd8\xff";
#elif defined(PRAST_FUZZ_HDR)
const char kSignature[] = "#?RADIANCE\n";
#else
#error "define PRAST_FUZZ_PNG, PRAST_FUZZ_JPEG or PRAST_FUZZ_HDR"
#endif

// The decoder accepts images up to 2^28 texels (4 GiB as float RGBA), which
// is beyond the fuzzer's memory limit by design: bigger headers are skipped.
constexpr long long kMaxFuzzTexels = 1 << 22;

} // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const std::size_t sig = sizeof kSignature - 1;
    prast::ImageSource src;
    src.name = "fuzz";
    if (size >= sig && std::memcmp(data, kSignature, sig) == 0) {
        src.bytes.assign(data, data + size);
    } else {
        src.bytes.assign(kSignature, kSignature + sig);
        src.bytes.insert(src.bytes.end(), data, data + size);
    }
    int w = 0, h = 0;
    if (prast::image_dimensions(src, w, h) && static_cast<long long>(w) * h > kMaxFuzzTexels) return 0;
    try {
        const prast::Image img = prast::decode_image(src, size % 2 == 1);
        if (img.width != w || img.height != h) __builtin_trap();  // header and decode must agree
    } catch (const prast::LoadError&) {
    }
    return 0;
}

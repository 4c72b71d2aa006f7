// libFuzzer harness: image decoding (scene/image.cpp: our PNG decoder and
// libpng, libjpeg-turbo, stb_image behind the HDR guard, libwebp), one build per
// format: PRAST_FUZZ_PNG, PRAST_FUZZ_JPEG, PRAST_FUZZ_HDR or PRAST_FUZZ_WEBP
// (fuzz/targets.h: run_image).
#include "fuzz/targets.h"

#if defined(PRAST_FUZZ_PNG)
constexpr prast::fuzz::Target kTarget = prast::fuzz::Target::Png;
#elif defined(PRAST_FUZZ_JPEG)
constexpr prast::fuzz::Target kTarget = prast::fuzz::Target::Jpeg;
#elif defined(PRAST_FUZZ_HDR)
constexpr prast::fuzz::Target kTarget = prast::fuzz::Target::Hdr;
#elif defined(PRAST_FUZZ_WEBP)
constexpr prast::fuzz::Target kTarget = prast::fuzz::Target::Webp;
#else
#error "define PRAST_FUZZ_PNG, PRAST_FUZZ_JPEG, PRAST_FUZZ_HDR or PRAST_FUZZ_WEBP"
#endif

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    if (!prast::fuzz::run_image(kTarget, data, size)) __builtin_trap();  // header and decode disagree
    return 0;
}

// Run-time choice of the AVX512_VBMI copy of the 8-bit fetch (shading/isa.h),
// and the name of the lane code; compiled for the build's own ISA.
#include "shading/isa.h"

#include <cstdlib>
#include <cstring>

namespace prast {

#if defined(PRAST_AVX512_DISPATCH)
bool use_avx512_vbmi() {
    static const bool use = [] {
        const char* env = std::getenv("PRAST_VBMI");
        if (env && std::strcmp(env, "0") == 0) return false;
        __builtin_cpu_init();
        return use_avx512() && __builtin_cpu_supports("avx512vbmi");
    }();
    return use;
}
#endif

const char* lane_isa() {
#if defined(PRAST_SIMD16)
    return "avx512";
#elif PRAST_CALLS_AVX512
    return use_avx512_vbmi() ? "avx512-vbmi" : use_avx512() ? "avx512" : "avx2";
#elif defined(__AVX2__)
    return "avx2";
#elif defined(__ARM_NEON)
    return "neon";
#else
    return "portable";
#endif
}

} // namespace prast

// Run-time choice of the AVX-512 copy of the block loops (shading/isa.h),
// compiled for the build's own ISA so that it runs on any CPU.
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

#if PRAST_CALLS_AVX512
namespace isa_detail {
std::atomic<int> g_avx512{0};

// Threads that race here compute the same answer.
int read_avx512() {
    const char* env = std::getenv("PRAST_AVX512");
    // libgcc's check includes the OS saving the AVX-512 registers (XCR0).
    __builtin_cpu_init();
    const bool use = !(env && std::strcmp(env, "0") == 0) && __builtin_cpu_supports("avx512f") &&
                     __builtin_cpu_supports("avx512bw") && __builtin_cpu_supports("avx512dq") &&
                     __builtin_cpu_supports("avx512vl");
    const int state = use ? 2 : 1;
    g_avx512.store(state, std::memory_order_relaxed);
    return state;
}
} // namespace isa_detail
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

// Run-time choice of the AVX-512 copies of the block loops (raster/isa.h),
// compiled for the build's own ISA so that it runs on any CPU.
#include "raster/isa.h"

#if PRAST_CALLS_AVX512
#include <cstdlib>
#include <cstring>

namespace prast {
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
} // namespace prast
#endif

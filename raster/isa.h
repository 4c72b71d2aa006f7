// Whether this process runs the AVX-512 copies of its block loops. An
// x86-64-v3 build carries some loops twice, the second copy compiled for
// AVX-512 in a file of its own (raster/write_avx512.cpp, the colour write;
// shading/sample_lanes_avx512.cpp, the texture, material and lighting
// lanes), and calls it where the CPU has AVX-512; an x86-64-v4 build has
// only that one, inline.
#pragma once

// This file is compiled with AVX-512 (F, BW, DQ): 16-lane vectors exist.
#if defined(__AVX2__) && defined(__AVX512F__) && defined(__AVX512BW__) && defined(__AVX512DQ__)
#define PRAST_SIMD16 1
#endif

// This file calls the AVX-512 copy where the CPU has it.
#if defined(PRAST_AVX512_DISPATCH) && !defined(PRAST_SIMD16)
#define PRAST_CALLS_AVX512 1
#else
#define PRAST_CALLS_AVX512 0
#endif

#if PRAST_CALLS_AVX512
#include <atomic>

namespace prast {
namespace isa_detail {
extern std::atomic<int> g_avx512;  // 0: not read yet, 1: no, 2: yes
int read_avx512();                 // reads it, stores it, returns it
} // namespace isa_detail
// The CPU runs AVX-512 (F, BW, DQ, VL) and PRAST_AVX512 is not 0 in the
// environment; read once. Inline: the block loops ask several times a block.
[[gnu::always_inline]] inline bool use_avx512() {
    int state = isa_detail::g_avx512.load(std::memory_order_relaxed);
    if (__builtin_expect(state == 0, 0)) state = isa_detail::read_avx512();
    return state == 2;
}
} // namespace prast
#endif

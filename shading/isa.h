// The instruction sets the lane code is compiled for. An x86-64-v3 build
// carries a second copy of the 16-lane texture, material and lighting loops
// compiled for AVX-512 (shading/sample_lanes_avx512.cpp), called where the
// CPU has it; an x86-64-v4 build has only that one, inline.
#pragma once

// This file is compiled with AVX-512 (F, BW, DQ): Simd<16> exists.
#if defined(__AVX2__) && defined(__AVX512F__) && defined(__AVX512BW__) && defined(__AVX512DQ__)
#define PRAST_SIMD16 1
#endif

// This file calls the AVX-512 copy where the CPU has it.
#if defined(PRAST_AVX512_DISPATCH) && !defined(PRAST_SIMD16)
#define PRAST_CALLS_AVX512 1
#else
#define PRAST_CALLS_AVX512 0
#endif

// This file is the AVX-512 copy, which calls the 8-bit fetch's VBMI copy
// (shading/sample_lanes_vbmi.cpp: sRGB decode by byte permutes, not
// gathers) where the CPU has AVX512_VBMI.
#if defined(PRAST_AVX512_DISPATCH) && defined(PRAST_SIMD16) && !defined(__AVX512VBMI__)
#define PRAST_CALLS_VBMI 1
#else
#define PRAST_CALLS_VBMI 0
#endif

#if PRAST_CALLS_AVX512
#include <atomic>
#endif

namespace prast {

// Tags for the instruction set a lane loop is instantiated for: the copy
// compiled for AVX-512 must not share a name with the default one (the
// linker would keep either, and run it on any CPU).
struct IsaDefault {};
struct IsaAvx512 {};
struct IsaAvx512Vbmi {};  // the 8-bit fetch alone, also with AVX512_VBMI

#if PRAST_CALLS_AVX512
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
#endif

#if defined(PRAST_AVX512_DISPATCH)
// use_avx512(), the CPU has AVX512_VBMI too, and PRAST_VBMI is not 0 in the
// environment; read once.
bool use_avx512_vbmi();
#endif

// The lane code the 4x4 blocks run in this process: "avx512-vbmi" (the
// AVX-512 copy with the 8-bit fetch's VBMI copy), "avx512", "avx2", "neon"
// or "portable" (render --stats prints it).
const char* lane_isa();

} // namespace prast

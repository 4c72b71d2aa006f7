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

namespace prast {

// Tags for the instruction set a lane loop is instantiated for: the copy
// compiled for AVX-512 must not share a name with the default one (the
// linker would keep either, and run it on any CPU).
struct IsaDefault {};
struct IsaAvx512 {};

#if PRAST_CALLS_AVX512
// The CPU runs AVX-512 (F, BW, DQ, VL) and PRAST_AVX512 is not 0 in the
// environment; read once.
bool use_avx512();
#endif

// The lane code the 4x4 blocks run in this process: "avx512", "avx2",
// "neon" or "portable" (render --stats prints it).
const char* lane_isa();

} // namespace prast

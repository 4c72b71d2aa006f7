// The instruction sets the lane code is compiled for. An x86-64-v3 build
// carries a second copy of the 16-lane texture, material and lighting loops
// compiled for AVX-512 (shading/sample_lanes_avx512.cpp), called where the
// CPU has it; an x86-64-v4 build has only that one, inline.
#pragma once

#include "raster/isa.h"  // PRAST_SIMD16 (Simd<16> exists), PRAST_CALLS_AVX512, use_avx512()

// This file is the AVX-512 copy, which calls the 8-bit fetch's VBMI copy
// (shading/sample_lanes_vbmi.cpp: sRGB decode by byte permutes, not
// gathers) where the CPU has AVX512_VBMI.
#if defined(PRAST_AVX512_DISPATCH) && defined(PRAST_SIMD16) && !defined(__AVX512VBMI__)
#define PRAST_CALLS_VBMI 1
#else
#define PRAST_CALLS_VBMI 0
#endif

namespace prast {

// Tags for the instruction set a lane loop is instantiated for: the copy
// compiled for AVX-512 must not share a name with the default one (the
// linker would keep either, and run it on any CPU).
struct IsaDefault {};
struct IsaAvx512 {};
struct IsaAvx512Vbmi {};  // the 8-bit fetch alone, also with AVX512_VBMI

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

// The 16-lane 8-bit texture fetch compiled with AVX512_VBMI as well, for
// x86-64-v3 builds on CPUs that have it: the AVX-512 copy
// (sample_lanes_avx512.cpp) calls it for textures of 3 or 4 bytes a texel
// (vbmi_serves()), whose sRGB codes it looks up with byte permutes instead
// of a gather per channel and tap, and whose tap pairs it picks out of the
// gathered qwords (sample_lanes.h, srgb_codes_vbmi, pair_rows_vbmi).
// Everything this file instantiates is tagged IsaAvx512Vbmi, which no other
// file instantiates (the `isa` test lists this object's symbols too).

#include "shading/sample_lanes.h"

#if !defined(PRAST_SIMD16) || !defined(__AVX512VBMI__)
#error "sample_lanes_vbmi.cpp needs AVX-512 F, BW, DQ and VBMI (see shading/CMakeLists.txt)"
#endif

namespace prast::sample_lanes_detail {

void fetch_unorm8_lanes16_vbmi(const Texture& tex, const TrilinearLanes& at, TexelLanes& out, unsigned components) {
    if (tex.channels() == 3) fetch_unorm8_lanes<16, 16, 3, IsaAvx512Vbmi>(tex, at, out, components);
    else fetch_unorm8_lanes<16, 16, 4, IsaAvx512Vbmi>(tex, at, out, components);
}

} // namespace prast::sample_lanes_detail

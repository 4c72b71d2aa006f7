// The 16-lane loops of a 4x4 block (the texture fetch and its texel indices,
// the material lanes, the lighting) for x86-64-v3 builds on CPUs with
// AVX-512, which sample_lanes.h, material_lanes.h and light_block.h call
// where use_avx512() says so. This file alone is compiled with
// -mavx512f/bw/dq/vl: everything it instantiates is a template on Simd<16>
// or tagged IsaAvx512 (shading/isa.h), which no other file instantiates, so
// no inline function compiled here can stand in for another file's copy on
// a CPU without AVX-512 (the `isa` test lists this object's symbols). The
// file is always optimised (shading/CMakeLists.txt), so that the small inline
// helpers it calls are inlined rather than emitted as shared copies; the
// larger ones (fix_lane, with its lambda) carry the tag too.

#include "shading/light_block.h"
#include "shading/material_lanes.h"
#include "shading/sample_lanes.h"

#if !defined(PRAST_SIMD16)
#error "sample_lanes_avx512.cpp needs AVX-512 F, BW and DQ (see shading/CMakeLists.txt)"
#endif

namespace prast::sample_lanes_detail {

void fetch_unorm8_lanes16_avx512(const Texture& tex, const TrilinearLanes& at, TexelLanes& out, unsigned components) {
    fetch_unorm8_lanes<16, IsaAvx512>(tex, at, out, components);
}

void prepare_trilinear_lanes16_avx512(const Texture& tex, const float* u, const float* v, const float* lambda,
                                      const std::uint8_t* quad, std::uint32_t live, TrilinearLanes& out) {
    prepare_trilinear_lanes<16, IsaAvx512>(tex, u, v, lambda, quad, live, out);
}

} // namespace prast::sample_lanes_detail

namespace prast {

std::uint32_t sample_material_lanes16_avx512(const BoundMaterial& bm, const SurfaceLanes& s, std::uint32_t live,
                                             MaterialBlock& mb, const LookupPlan* plan) {
    return sample_material_lanes<16, IsaAvx512>(bm, s, live, mb, plan);
}

void shade_block_lanes16_avx512(const MaterialBlock& m, const ShadingContext& ctx, RadianceBlock& out) {
    shade_block_lanes<16, IsaAvx512>(m, ctx, out);
}

} // namespace prast

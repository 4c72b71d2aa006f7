// What a fragment shader sees and returns. The rasterizer hands a shader one 4x4
// pixel block at a time: four 2x2 quads, 16 lanes in structure-of-arrays form,
// so a shader's per-lane loop vectorises. Lane order is quad-major:
//   lane = 4 * quad + pixel,  quad = qx + 2 qy,  pixel = px + 2 py,
// which keeps each quad's four lanes adjacent for screen-space derivatives.
// Lanes outside the triangle (helper lanes) still carry extrapolated varyings,
// so derivatives are valid for every quad that has at least one live lane.
// Multisampling: a live lane whose pixel centre is outside the triangle is
// interpolated at the centroid of its covered samples instead (so textures do
// not bleed from beyond the edge); derivatives still come from the centre
// values, so they, and the pixels whose centres are inside, are unchanged.
#pragma once

#include <cstdint>

#include "raster/limits.h"

namespace prast {

constexpr int lane_x(int lane) { return ((lane >> 2) & 1) * 2 + (lane & 1); }
constexpr int lane_y(int lane) { return ((lane >> 3) & 1) * 2 + ((lane >> 1) & 1); }
// The lane of the block's pixel (x, y), 0 <= x, y < 4: the inverse of the two above.
constexpr int block_lane(int x, int y) { return (x & 1) | ((y & 1) << 1) | ((x >> 1) << 2) | ((y >> 1) << 3); }

template <int NV>
struct FragmentBlock {
    static constexpr int kVaryings = NV;
    alignas(64) float var[NV > 0 ? NV : 1][kBlockLanes]; // perspective-correct varyings
    alignas(64) float z[kBlockLanes];                    // window depth, linear in screen space
    int x = 0, y = 0;          // pixel of lane 0 (top-left of the block)
    std::uint32_t mask = 0;    // live lanes: covered and passed the depth test
    std::uint32_t prim_id = 0; // index of the submitted triangle in the draw
    bool front_facing = true;
    // Lanes interpolated at a centroid (multisampling); when non-zero,
    // centre_var holds every lane's values at its pixel centre.
    std::uint32_t centroid_mask = 0;
    alignas(64) float centre_var[NV > 0 ? NV : 1][kBlockLanes];

    bool quad_live(int quad) const { return (mask >> (quad * 4)) & 0xFu; }
    // Coarse derivatives, one per quad (the OpenGL spec allows it): x from the
    // top row of the quad, y from its left column, at the pixel centres.
    // (centre_var is only read when centroid_mask says it was written, which
    // GCC cannot see through the rasterizer's calls.)
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#endif
    float ddx(int k, int lane) const {
        const int q = lane & ~3;
        if (centroid_mask) return centre_var[k][q + 1] - centre_var[k][q];
        return var[k][q + 1] - var[k][q];
    }
    float ddy(int k, int lane) const {
        const int q = lane & ~3;
        if (centroid_mask) return centre_var[k][q + 2] - centre_var[k][q];
        return var[k][q + 2] - var[k][q];
    }
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic pop
#endif
};

// Batches. A program may also define
//   void fragment_batch(const FragmentBlock<kVaryings>* const* in, FragmentOut* const* out, int count) const;
// and the rasterizer then hands it up to kMaxBatchBlocks sparse blocks of one
// draw at once (of one triangle or several), with at most kBlockLanes live
// lanes together, so that a program packing live lanes into vectors fills
// them where small triangles leave most of each block dead. Each in[i] is the
// block fragment() would be handed and out[i] must be what fragment() writes
// for it. A block with more than kBatchBlockLanes live lanes is shaded alone
// unless it fills up a batch. Batched draws are those whose Observer is
// disabled and that never discard (DrawState::may_discard false).
constexpr int kMaxBatchBlocks = 8;
constexpr int kBatchBlockLanes = 8;

struct FragmentOut {
    alignas(64) float r[kBlockLanes];
    alignas(64) float g[kBlockLanes];
    alignas(64) float b[kBlockLanes];
    alignas(64) float a[kBlockLanes];
    std::uint32_t kill = 0;  // lanes the shader discards (alpha mask)
};

} // namespace prast

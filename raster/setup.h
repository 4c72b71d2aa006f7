// Triangle setup: snap window positions to 1/256 pixel, build exact integer edge
// functions with the top-left fill rule, a pixel bounding box, and float planes
// for barycentrics (from which depth and perspective-correct varyings follow).
// Runs once per (post-clip) triangle.
#pragma once

#include <cstdint>

#include "raster/limits.h"

namespace prast {

// Vertex reference: index into the draw's post-vertex-shader array, or (high
// bit set) into the clip pool of the binning job that made the vertex.
constexpr std::uint32_t kClippedVertexBit = 0x80000000u;

struct TriangleSetup {
    // Edge i is the edge opposite vertex i; E_i(p) = A_i * px + B_i * py + C_i
    // in 1/256-pixel units at pixel centres. E_i >= 0 on every edge means
    // covered; C_i already holds the top-left rule's -1 for non-top-left edges.
    std::int64_t C[3];
    std::int32_t A[3], B[3];
    std::int32_t minx, miny, maxx, maxy;  // covered pixels lie in this box (inclusive, clamped to the viewport)
    // Barycentric weight of vertex i = bary[i][0] + bary[i][1] * dx + bary[i][2] * dy,
    // dx, dy = pixel offsets from the anchor pixel (minx, miny). Screen-space (not
    // perspective-corrected); anchoring at the box keeps the values independent of tiles.
    float bary[3][3];
    float z[3];       // window depth of each vertex
    float inv_w[3];   // 1 / clip w of each vertex
    std::uint32_t vtx[3];
    std::uint32_t prim_id;
    bool front_facing;
};

enum class SetupResult { Ok, CulledBack, Degenerate };

// clip[i] points at the clip-space xyzw of vertex i (w > 0, within the guard band).
SetupResult setup_triangle(const float* const clip[3], const std::uint32_t ref[3],
                           int width, int height, bool cull_back, TriangleSetup& out);

// Which side of an edge an S x S pixel block lies on, judged at pixel centres:
// the block's top-left pixel is (x, y).
enum EdgeClass { kEdgeOut = 0, kEdgePartial = 1, kEdgeIn = 2 };

inline std::int64_t edge_at_pixel(const TriangleSetup& t, int e, int x, int y) {
    return std::int64_t(t.A[e]) * (std::int64_t(x) * kSubPixelScale + kHalfPixel) +
           std::int64_t(t.B[e]) * (std::int64_t(y) * kSubPixelScale + kHalfPixel) + t.C[e];
}

inline EdgeClass classify_block(const TriangleSetup& t, int e, int x, int y, int size) {
    std::int64_t e0 = edge_at_pixel(t, e, x, y);
    std::int64_t span = std::int64_t(size - 1) * kSubPixelScale;
    std::int64_t a = t.A[e], b = t.B[e];
    std::int64_t hi = e0 + (a > 0 ? a : 0) * span + (b > 0 ? b : 0) * span;
    std::int64_t lo = e0 + (a < 0 ? a : 0) * span + (b < 0 ? b : 0) * span;
    if (hi < 0) return kEdgeOut;
    if (lo >= 0) return kEdgeIn;
    return kEdgePartial;
}

} // namespace prast

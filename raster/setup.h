// Triangle setup: snap window positions to 1/256 pixel, build exact integer edge
// functions with the top-left fill rule, a pixel bounding box, and float planes
// for barycentrics (from which depth and perspective-correct varyings follow).
// Runs once per (post-clip) triangle.
#pragma once

#include <cstdint>

#include "raster/limits.h"
#include "raster/samples.h"

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
    // dx, dy = pixel offsets from the anchor pixel (ax, ay): the first pixel
    // centre inside the vertices' extent (clamped to the viewport), which is
    // (minx, miny) with one sample. Screen-space (not perspective-corrected);
    // anchoring at the triangle keeps the values independent of tiles, and
    // anchoring at centres keeps them independent of the sample count.
    float bary[3][3];
    std::int32_t ax, ay;
    float z[3];       // window depth of each vertex
    float inv_w[3];   // 1 / clip w of each vertex
    std::uint32_t vtx[3];
    std::uint32_t prim_id;
    float area;       // in pixels (for the tile pass's overdraw estimate only)
    bool front_facing;
};

enum class SetupResult { Ok, CulledBack, Degenerate };

// A vertex projected to window space (y down) and snapped to 1/256 pixel, in
// double precision so that vertices far out in the guard band snap exactly:
// what setup needs of it. The vertex pass projects every vertex once; only
// vertices made by clipping are projected during setup.
struct WindowVertex {
    std::int32_t x = 0, y = 0;  // 1/256 pixel: |x|, |y| <= 2^29 when ok
    float z = 0.0f;             // window depth
    float inv_w = 0.0f;         // 1 / clip w
    bool ok = false;            // w > 0 and within twice the guard band; setup refuses others
};
WindowVertex window_vertex(const float* clip, int width, int height);

// The same setup from projected vertices (window_vertex()).
SetupResult setup_triangle(const WindowVertex* const v[3], const std::uint32_t ref[3], int width, int height,
                           bool cull_back, TriangleSetup& t, const SampleExtent& samples);

// clip[i] points at the clip-space xyzw of vertex i (w > 0, within the guard band).
// `samples` widens the pixel box to the pixels any sample of which may be
// covered (the default, one sample at the centre, gives the centre box).
SetupResult setup_triangle(const float* const clip[3], const std::uint32_t ref[3],
                           int width, int height, bool cull_back, TriangleSetup& out,
                           const SampleExtent& samples = {});

// Which side of an edge an S x S pixel block lies on, judged at pixel centres:
// the block's top-left pixel is (x, y).
enum EdgeClass { kEdgeOut = 0, kEdgePartial = 1, kEdgeIn = 2 };

inline std::int64_t edge_at_pixel(const TriangleSetup& t, int e, int x, int y) {
    return std::int64_t(t.A[e]) * (std::int64_t(x) * kSubPixelScale + kHalfPixel) +
           std::int64_t(t.B[e]) * (std::int64_t(y) * kSubPixelScale + kHalfPixel) + t.C[e];
}

// The largest and smallest values of edge e over the samples of an S x S
// block, relative to its value at the top-left pixel centre: the block's
// sample box is [lo_x, (S - 1) * 256 + hi_x] x [lo_y, (S - 1) * 256 + hi_y].
// With one sample these are the centre extremes; with several the box is a
// superset of the samples, so "out" and "in" stay exact claims.
struct EdgeSpan {
    std::int64_t hi, lo;
};

inline EdgeSpan edge_span(const TriangleSetup& t, int e, int size, const SampleExtent& s) {
    const std::int64_t span = std::int64_t(size - 1) * kSubPixelScale;
    const std::int64_t a = t.A[e], b = t.B[e];
    const std::int64_t x_hi = span + s.hi_x, x_lo = s.lo_x, y_hi = span + s.hi_y, y_lo = s.lo_y;
    EdgeSpan r;
    r.hi = (a > 0 ? a * x_hi : a * x_lo) + (b > 0 ? b * y_hi : b * y_lo);
    r.lo = (a < 0 ? a * x_hi : a * x_lo) + (b < 0 ? b * y_hi : b * y_lo);
    return r;
}

inline EdgeClass classify_edge(std::int64_t e0, const EdgeSpan& span) {
    if (e0 + span.hi < 0) return kEdgeOut;
    if (e0 + span.lo >= 0) return kEdgeIn;
    return kEdgePartial;
}

inline EdgeClass classify_block(const TriangleSetup& t, int e, int x, int y, int size,
                                const SampleExtent& samples = {}) {
    return classify_edge(edge_at_pixel(t, e, x, y), edge_span(t, e, size, samples));
}

} // namespace prast

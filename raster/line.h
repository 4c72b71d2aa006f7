// Lines and points: 1-pixel-wide segments and 1-pixel points (what glTF asks
// of LINES and POINTS), exact in the same 1/256-pixel fixed point as the
// triangles, with fill rules that give every pixel to at most one primitive
// the way the top-left rule does for triangles:
//
//  - A segment P0 -> P1 covers pixel (x, y) when it meets the pixel's open
//    diamond |px - cx| + |py - cy| < 1/2 around the centre (cx, cy) and P1
//    is not inside it: the line *exits* the diamond (the diamond-exit rule of
//    OpenGL, D3D and Vulkan). A segment that ends in a diamond leaves that
//    pixel to the next segment of a strip, which starts there and exits, so a
//    shared endpoint's pixel is drawn once. Ties (an endpoint or the whole
//    line exactly on a diamond's boundary) are broken by moving the segment
//    by an infinitesimal (+e, +e^2), e > 0, in window space (y down), as
//    OpenGL does with its own perturbation: a line lying on a pixel edge
//    covers the pixels right of or below it, as a triangle edge on a centre
//    gives it to the triangle right of or below it. The test is exact
//    (integers, the perturbation carried symbolically).
//  - A zero-length segment (after snapping) covers nothing: it starts inside
//    the one diamond it meets and never exits it.
//  - A point covers the pixel that contains its snapped position: pixel
//    (floor(x), floor(y)); a point on a pixel edge belongs to the pixel right
//    of or below it (the top and left edges are the pixel's own, as for
//    triangles).
//  - Multisampling: a covered pixel covers all of its samples (aliased lines,
//    as Vulkan's Bresenham lines and points do), each sample depth-tested
//    with the pixel's depth.
//  - Depth and varyings: at the projection of the pixel centre onto the
//    segment (parameter t in [0, 1]), depth linear in window space and
//    varyings perspective-correct; a point has its vertex's. Fragment
//    derivatives are zero (every lane of a quad carries the same values), so
//    textures sample their finest level.
//
// Clipping: near and far planes always, x and y only beyond the guard band
// (as triangles); a point outside the near or far plane is dropped.
#pragma once

#include <cstdint>

#include "raster/clip.h"
#include "raster/setup.h"

namespace prast {

struct LineSetup {
    std::int32_t x0 = 0, y0 = 0, x1 = 0, y1 = 0;  // 1/256 pixel, window space; a point: P1 = P0
    float z0 = 0.0f, z1 = 0.0f;                   // window depth at P0, P1
    float inv_w0 = 0.0f, inv_w1 = 0.0f;           // 1 / clip w at P0, P1
    std::uint32_t vtx[2] = {0, 0};                // vertex refs (setup.h's kClippedVertexBit)
    std::uint32_t prim_id = 0;                    // index of the line or point in the draw
    std::int32_t minx = 0, miny = 0, maxx = 0, maxy = 0;  // covered pixels lie here (clamped to the viewport)
    bool point = false;
    bool x_major = true;                          // |dx| >= |dy|
};

// Sets up segment v[0] -> v[1] or (point) v[0]: false when nothing can be
// covered (a vertex refused by window_vertex(), zero length, no pixel of the
// viewport within reach).
bool setup_line(const WindowVertex& a, const WindowVertex& b, const std::uint32_t ref[2], int width, int height,
                LineSetup& out);
bool setup_point(const WindowVertex& a, std::uint32_t ref, int width, int height, LineSetup& out);

// Whether the primitive covers pixel (x, y): the rules above, exactly.
bool line_covers(const LineSetup& l, int x, int y);

// The parameter along the segment of pixel (x, y)'s centre (its projection,
// clamped to [0, 1]); 0 for a point.
float line_parameter(const LineSetup& l, int x, int y);

// Calls fn(x, y) for every pixel of [x0, x1] x [y0, y1] (inclusive, within
// the viewport) that the primitive covers, column by column (x-major) or row
// by row, visiting only the few candidates next to the segment.
template <class Fn>
void for_each_line_pixel(const LineSetup& l, int x0, int y0, int x1, int y1, Fn&& fn);

namespace raster_detail {
// The candidates of the minor axis (pixels lo..hi, inclusive) for pixels
// major_lo..major_hi of the major axis (x for an x-major segment): every
// pixel there whose square the segment meets, and one more on each side.
// false when the segment does not reach those pixels.
bool line_minor_range(const LineSetup& l, std::int64_t major_lo, std::int64_t major_hi, int& lo, int& hi);
} // namespace raster_detail

template <class Fn>
void for_each_line_pixel(const LineSetup& l, int x0, int y0, int x1, int y1, Fn&& fn) {
    x0 = x0 > l.minx ? x0 : l.minx;
    y0 = y0 > l.miny ? y0 : l.miny;
    x1 = x1 < l.maxx ? x1 : l.maxx;
    y1 = y1 < l.maxy ? y1 : l.maxy;
    if (x0 > x1 || y0 > y1) return;
    if (l.point) {
        fn(l.minx, l.miny);  // the box is the point's pixel
        return;
    }
    const int m0 = l.x_major ? x0 : y0, m1 = l.x_major ? x1 : y1;
    const int n0 = l.x_major ? y0 : x0, n1 = l.x_major ? y1 : x1;
    for (int m = m0; m <= m1; ++m) {
        int lo, hi;
        if (!raster_detail::line_minor_range(l, m, m, lo, hi)) continue;
        lo = lo > n0 ? lo : n0;
        hi = hi < n1 ? hi : n1;
        for (int n = lo; n <= hi; ++n) {
            const int x = l.x_major ? m : n, y = l.x_major ? n : m;
            if (line_covers(l, x, y)) fn(x, y);
        }
    }
}

} // namespace prast

// Line and point setup and the exact diamond-exit test; see line.h.
#include "raster/line.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>

namespace prast {

namespace {

__extension__ typedef __int128 Int128;

// a + b e + c e^2 < 0 for every small enough e > 0: the sign of the first
// non-zero term.
template <class T>
bool negative(T a, std::int64_t b, std::int64_t c) {
    if (a != 0) return a < 0;
    if (b != 0) return b < 0;
    return c < 0;
}

std::int64_t floor_pixel(std::int64_t v) { return v >> kSubPixelBits; }  // arithmetic: floors negatives

bool clamp_box(std::int64_t minx, std::int64_t miny, std::int64_t maxx, std::int64_t maxy, int width, int height,
               LineSetup& l) {
    minx = std::max<std::int64_t>(minx, 0);
    miny = std::max<std::int64_t>(miny, 0);
    maxx = std::min<std::int64_t>(maxx, width - 1);
    maxy = std::min<std::int64_t>(maxy, height - 1);
    if (minx > maxx || miny > maxy) return false;
    l.minx = std::int32_t(minx);
    l.miny = std::int32_t(miny);
    l.maxx = std::int32_t(maxx);
    l.maxy = std::int32_t(maxy);
    return true;
}

} // namespace

bool setup_line(const WindowVertex& a, const WindowVertex& b, const std::uint32_t ref[2], int width, int height,
                LineSetup& l) {
    if (!a.ok || !b.ok) return false;
    const std::int64_t dx = std::int64_t(b.x) - a.x, dy = std::int64_t(b.y) - a.y;
    if (dx == 0 && dy == 0) return false;  // covers nothing (line.h)
    l.x0 = a.x; l.y0 = a.y; l.x1 = b.x; l.y1 = b.y;
    l.z0 = a.z; l.z1 = b.z;
    l.inv_w0 = a.inv_w; l.inv_w1 = b.inv_w;
    l.vtx[0] = ref[0];
    l.vtx[1] = ref[1];
    l.point = false;
    l.x_major = std::llabs(dx) >= std::llabs(dy);
    // A covered pixel's square meets the segment: one pixel of margin covers
    // the squares whose edge the segment only touches.
    return clamp_box(floor_pixel(std::min(a.x, b.x)) - 1, floor_pixel(std::min(a.y, b.y)) - 1,
                     floor_pixel(std::max(a.x, b.x)) + 1, floor_pixel(std::max(a.y, b.y)) + 1, width, height, l);
}

bool setup_point(const WindowVertex& a, std::uint32_t ref, int width, int height, LineSetup& l) {
    if (!a.ok) return false;
    l.x0 = l.x1 = a.x;
    l.y0 = l.y1 = a.y;
    l.z0 = l.z1 = a.z;
    l.inv_w0 = l.inv_w1 = a.inv_w;
    l.vtx[0] = l.vtx[1] = ref;
    l.point = true;
    l.x_major = true;
    const std::int64_t px = floor_pixel(a.x), py = floor_pixel(a.y);
    if (px < 0 || py < 0 || px >= width || py >= height) return false;
    return clamp_box(px, py, px, py, width, height, l);
}

bool line_covers(const LineSetup& l, int x, int y) {
    const std::int64_t cx = std::int64_t(x) * kSubPixelScale + kHalfPixel;
    const std::int64_t cy = std::int64_t(y) * kSubPixelScale + kHalfPixel;
    if (l.point) return floor_pixel(l.x0) == x && floor_pixel(l.y0) == y;

    // Moving the segment by (+e, +e^2) is moving the diamond by (-e, -e^2):
    // q (relative to the centre) is inside when |qx + e| + |qy + e^2| < 1/2.
    // P1 inside: the line does not exit.
    const std::int64_t u = std::int64_t(l.x1) - cx, v = std::int64_t(l.y1) - cy;
    if (negative(std::llabs(u) + std::llabs(v) - kHalfPixel, u >= 0 ? 1 : -1, v >= 0 ? 1 : -1)) return false;

    // Does P0 + t d, t in [0, 1], meet the diamond? The diamond is four open
    // half-planes sx (qx + e) + sy (qy + e^2) < 1/2; each is a + b t + sx e +
    // sy e^2 < 0, an upper bound on t (b > 0), a lower one (b < 0) or a
    // constant (b = 0). Feasible when every constraint holds at the end of
    // [0, 1] it keeps, and every lower bound lies below every upper bound.
    const std::int64_t ax = std::int64_t(l.x0) - cx, ay = std::int64_t(l.y0) - cy;
    const std::int64_t dx = std::int64_t(l.x1) - l.x0, dy = std::int64_t(l.y1) - l.y0;
    struct Bound {
        std::int64_t a, b;
        int sx, sy;
    };
    Bound lower[4], upper[4];
    int nl = 0, nu = 0;
    for (int sx = -1; sx <= 1; sx += 2)
        for (int sy = -1; sy <= 1; sy += 2) {
            const Bound c{sx * ax + sy * ay - kHalfPixel, sx * dx + sy * dy, sx, sy};
            if (c.b == 0) {
                if (!negative(c.a, c.sx, c.sy)) return false;
            } else if (c.b > 0) {
                if (!negative(c.a, c.sx, c.sy)) return false;  // at t = 0
                upper[nu++] = c;
            } else {
                if (!negative(c.a + c.b, c.sx, c.sy)) return false;  // at t = 1
                lower[nl++] = c;
            }
        }
    // L_i = -(a_i + d_i) / b_i < U_j = -(a_j + d_j) / b_j with b_i < 0 < b_j:
    // (a_i + d_i) b_j - (a_j + d_j) b_i < 0.
    for (int i = 0; i < nl; ++i)
        for (int j = 0; j < nu; ++j) {
            const Bound& L = lower[i];
            const Bound& U = upper[j];
            const Int128 r = Int128(L.a) * U.b - Int128(U.a) * L.b;
            if (!negative(r, std::int64_t(L.sx) * U.b - std::int64_t(U.sx) * L.b,
                          std::int64_t(L.sy) * U.b - std::int64_t(U.sy) * L.b))
                return false;
        }
    return true;
}

float line_parameter(const LineSetup& l, int x, int y) {
    if (l.point) return 0.0f;
    const double cx = double(std::int64_t(x) * kSubPixelScale + kHalfPixel);
    const double cy = double(std::int64_t(y) * kSubPixelScale + kHalfPixel);
    const double dx = double(l.x1) - double(l.x0), dy = double(l.y1) - double(l.y0);
    const double t = ((cx - double(l.x0)) * dx + (cy - double(l.y0)) * dy) / (dx * dx + dy * dy);
    return float(std::min(std::max(t, 0.0), 1.0));
}

namespace raster_detail {

bool line_minor_range(const LineSetup& l, std::int64_t major_lo, std::int64_t major_hi, int& lo, int& hi) {
    double a0 = l.x_major ? l.x0 : l.y0, b0 = l.x_major ? l.y0 : l.x0;
    double a1 = l.x_major ? l.x1 : l.y1, b1 = l.x_major ? l.y1 : l.x1;
    if (a0 > a1) {
        std::swap(a0, a1);
        std::swap(b0, b1);
    }
    // The segment over the pixels' span of the major axis (one unit wider,
    // for segments that end on its edge).
    const double A = std::max(double(major_lo * kSubPixelScale - 1), a0);
    const double B = std::min(double((major_hi + 1) * kSubPixelScale + 1), a1);
    if (A > B) return false;
    const double slope = (b1 - b0) / (a1 - a0);  // a1 > a0: the major axis is the longer, and non-zero
    const double bA = b0 + (A - a0) * slope, bB = b0 + (B - a0) * slope;
    lo = int(std::floor(std::min(bA, bB) / double(kSubPixelScale))) - 1;
    hi = int(std::floor(std::max(bA, bB) / double(kSubPixelScale))) + 1;
    return true;
}

} // namespace raster_detail

} // namespace prast

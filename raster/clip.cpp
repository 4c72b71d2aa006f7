// Sutherland-Hodgman clipping in homogeneous coordinates; see clip.h.
#include "raster/clip.h"

#include <cstring>

namespace prast {

GuardBand GuardBand::for_viewport(int width, int height) {
    // x_win = (x_ndc + 1) W / 2 <= G  <=>  x_ndc <= 2G / W - 1 (the tighter side).
    GuardBand gb;
    gb.x = float(2.0 * kGuardBandPixels / double(width) - 1.0);
    gb.y = float(2.0 * kGuardBandPixels / double(height) - 1.0);
    return gb;
}

std::uint32_t outcode(const float* c, const GuardBand& gb) {
    float x = c[0], y = c[1], z = c[2], w = c[3];
    std::uint32_t code = 0;
    if (x < -w) code |= kOutLeft;
    if (x > w) code |= kOutRight;
    if (y < -w) code |= kOutBottom;
    if (y > w) code |= kOutTop;
    // w <= 0 (a vertex at or behind the eye plane) always goes through the
    // clipper: a degenerate w = 0 vertex can sit on the near plane (0 >= -0),
    // and only the clipped path checks w > 0 before the perspective divide.
    if (z < -w || !(w > 0.0f)) code |= kOutNear;
    if (z > w) code |= kOutFar;
    if (x < -gb.x * w) code |= kOutGuardLeft;
    if (x > gb.x * w) code |= kOutGuardRight;
    if (y < -gb.y * w) code |= kOutGuardBottom;
    if (y > gb.y * w) code |= kOutGuardTop;
    return code;
}

namespace {

// Signed distance to a plane, >= 0 inside. Double precision: with vertices
// at 1e20 the float difference of two distances would lose the cut point.
double plane_distance(std::uint32_t plane, const float* c, const GuardBand& gb) {
    double x = c[0], y = c[1], z = c[2], w = c[3];
    switch (plane) {
    case kOutNear: return z + w;
    case kOutFar: return w - z;
    case kOutGuardLeft: return x + double(gb.x) * w;
    case kOutGuardRight: return double(gb.x) * w - x;
    case kOutGuardBottom: return y + double(gb.y) * w;
    default: return double(gb.y) * w - y;  // kOutGuardTop
    }
}

void lerp_vertex(const float* in, const float* out_side, double t, int stride, float* dst) {
    for (int k = 0; k < stride; ++k)
        dst[k] = float(double(in[k]) + t * (double(out_side[k]) - double(in[k])));
}

// Puts a new vertex exactly on the plane it was cut at. When both ends of an
// edge are far away (1e20 and beyond) the relative error of t, times the edge
// length, exceeds the guard band itself; snapping the plane's own coordinate
// keeps the vertex on the plane (and the others only move along the plane).
void snap_to_plane(std::uint32_t plane, const GuardBand& gb, float* v) {
    switch (plane) {
    case kOutNear: v[2] = -v[3]; break;
    case kOutFar: v[2] = v[3]; break;
    case kOutGuardLeft: v[0] = -gb.x * v[3]; break;
    case kOutGuardRight: v[0] = gb.x * v[3]; break;
    case kOutGuardBottom: v[1] = -gb.y * v[3]; break;
    default: v[1] = gb.y * v[3]; break;  // kOutGuardTop
    }
}

} // namespace

int clip_triangle(const float* const v[3], int stride, std::uint32_t planes,
                  const GuardBand& gb, float* out) {
    // Two ping-pong polygons; each step can add at most one vertex.
    float buf[2][kMaxClippedVertices * (4 + kMaxVaryings)];
    int n = 3;
    for (int i = 0; i < 3; ++i) std::memcpy(&buf[0][i * stride], v[i], sizeof(float) * stride);
    int cur = 0;
    static const std::uint32_t kOrder[kClipPlanes] = {kOutNear, kOutFar, kOutGuardLeft,
                                                      kOutGuardRight, kOutGuardBottom, kOutGuardTop};
    for (std::uint32_t plane : kOrder) {
        if (!(planes & plane)) continue;
        const float* src = buf[cur];
        float* dst = buf[cur ^ 1];
        int m = 0;
        for (int i = 0; i < n; ++i) {
            const float* a = &src[i * stride];
            const float* b = &src[((i + 1) % n) * stride];
            double da = plane_distance(plane, a, gb), db = plane_distance(plane, b, gb);
            bool a_in = da >= 0.0, b_in = db >= 0.0;
            if (a_in) {
                std::memcpy(&dst[m * stride], a, sizeof(float) * stride);
                ++m;
            }
            if (a_in != b_in) {
                // Cut from the inside end: t measured from the inside vertex.
                if (a_in) lerp_vertex(a, b, da / (da - db), stride, &dst[m * stride]);
                else lerp_vertex(b, a, db / (db - da), stride, &dst[m * stride]);
                snap_to_plane(plane, gb, &dst[m * stride]);
                ++m;
            }
        }
        n = m;
        cur ^= 1;
        if (n < 3) return 0;
    }
    std::memcpy(out, buf[cur], sizeof(float) * stride * n);
    return n;
}

bool clip_line(const float* a, const float* b, int stride, std::uint32_t planes, const GuardBand& gb,
               float* out) {
    static const std::uint32_t kOrder[kClipPlanes] = {kOutNear, kOutFar, kOutGuardLeft,
                                                      kOutGuardRight, kOutGuardBottom, kOutGuardTop};
    double t0 = 0.0, t1 = 1.0;
    std::uint32_t cut0 = 0, cut1 = 0;
    for (std::uint32_t plane : kOrder) {
        if (!(planes & plane)) continue;
        const double da = plane_distance(plane, a, gb), db = plane_distance(plane, b, gb);
        if (da < 0.0 && db < 0.0) return false;
        if (!(da < 0.0) && !(db < 0.0)) continue;
        const double t = da / (da - db);  // where a -> b meets the plane
        if (!(t >= 0.0 && t <= 1.0)) return false;  // NaN from a broken vertex
        if (da < 0.0 && t > t0) {
            t0 = t;
            cut0 = plane;
        } else if (db < 0.0 && t < t1) {
            t1 = t;
            cut1 = plane;
        }
    }
    if (t0 > t1) return false;
    float* o0 = out;
    float* o1 = out + stride;
    if (cut0) {
        lerp_vertex(a, b, t0, stride, o0);
        snap_to_plane(cut0, gb, o0);
    } else {
        std::memcpy(o0, a, sizeof(float) * std::size_t(stride));
    }
    if (cut1) {
        lerp_vertex(a, b, t1, stride, o1);
        snap_to_plane(cut1, gb, o1);
    } else {
        std::memcpy(o1, b, sizeof(float) * std::size_t(stride));
    }
    return true;
}

} // namespace prast

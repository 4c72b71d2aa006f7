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
    if (z < -w) code |= kOutNear;
    if (z > w) code |= kOutFar;
    if (x < -gb.x * w) code |= kOutGuardLeft;
    if (x > gb.x * w) code |= kOutGuardRight;
    if (y < -gb.y * w) code |= kOutGuardBottom;
    if (y > gb.y * w) code |= kOutGuardTop;
    return code;
}

namespace {

// Signed distance to a plane, >= 0 inside.
float plane_distance(std::uint32_t plane, const float* c, const GuardBand& gb) {
    switch (plane) {
    case kOutNear: return c[2] + c[3];
    case kOutFar: return c[3] - c[2];
    case kOutGuardLeft: return c[0] + gb.x * c[3];
    case kOutGuardRight: return gb.x * c[3] - c[0];
    case kOutGuardBottom: return c[1] + gb.y * c[3];
    default: return gb.y * c[3] - c[1];  // kOutGuardTop
    }
}

void lerp_vertex(const float* in, const float* out_side, float t, int stride, float* dst) {
    for (int k = 0; k < stride; ++k) dst[k] = in[k] + t * (out_side[k] - in[k]);
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
            float da = plane_distance(plane, a, gb), db = plane_distance(plane, b, gb);
            bool a_in = da >= 0.0f, b_in = db >= 0.0f;
            if (a_in) {
                std::memcpy(&dst[m * stride], a, sizeof(float) * stride);
                ++m;
            }
            if (a_in != b_in) {
                // Cut from the inside end: t measured from the inside vertex.
                if (a_in) lerp_vertex(a, b, da / (da - db), stride, &dst[m * stride]);
                else lerp_vertex(b, a, db / (db - da), stride, &dst[m * stride]);
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

} // namespace prast

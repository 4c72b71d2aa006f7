// Triangle setup in fixed point; see setup.h.
#include "raster/setup.h"

#include <algorithm>
#include <cmath>

namespace prast {

WindowVertex window_vertex(const float* clip, int width, int height) {
    // Callers clip to w > 0 and the guard band; a vertex outside them anyway
    // (a contract broken by hand) is refused rather than overflowing llrint.
    const double limit = 2.0 * kGuardBandPixels;
    WindowVertex v;
    const double w = clip[3];
    const double x_win = (double(clip[0]) / w + 1.0) * 0.5 * width;
    const double y_win = (1.0 - double(clip[1]) / w) * 0.5 * height;
    if (!(w > 0.0) || !(std::fabs(x_win) <= limit) || !(std::fabs(y_win) <= limit)) return v;
    v.x = std::int32_t(std::llrint(x_win * double(kSubPixelScale)));
    v.y = std::int32_t(std::llrint(y_win * double(kSubPixelScale)));
    v.z = float((double(clip[2]) / w + 1.0) * 0.5);
    v.inv_w = float(1.0 / w);
    v.ok = true;
    return v;
}

SetupResult setup_triangle(const float* const clip[3], const std::uint32_t ref[3],
                           int width, int height, bool cull_back, TriangleSetup& t,
                           const SampleExtent& samples) {
    WindowVertex wv[3];
    for (int i = 0; i < 3; ++i) {
        wv[i] = window_vertex(clip[i], width, height);
        if (!wv[i].ok) return SetupResult::Degenerate;
    }
    const WindowVertex* const v[3] = {&wv[0], &wv[1], &wv[2]};
    return setup_triangle(v, ref, width, height, cull_back, t, samples);
}

SetupResult setup_triangle(const WindowVertex* const v[3], const std::uint32_t ref[3], int width, int height,
                           bool cull_back, TriangleSetup& t, const SampleExtent& samples) {
    std::int64_t fx[3], fy[3];
    float z[3], inv_w[3];
    for (int i = 0; i < 3; ++i) {
        if (!v[i]->ok) return SetupResult::Degenerate;
        fx[i] = v[i]->x;
        fy[i] = v[i]->y;
        z[i] = v[i]->z;
        inv_w[i] = v[i]->inv_w;
    }

    // Twice the signed area, exact. Front faces wind counter-clockwise in NDC
    // (y up), which is a negative area in window space (y down).
    std::int64_t area2 = (fx[1] - fx[0]) * (fy[2] - fy[0]) - (fx[2] - fx[0]) * (fy[1] - fy[0]);
    if (area2 == 0) return SetupResult::Degenerate;
    bool front = area2 < 0;
    if (!front && cull_back) return SetupResult::CulledBack;

    // Order the vertices so that the area is positive: then every edge function
    // is >= 0 inside, whichever face we look at.
    int order[3] = {0, 1, 2};
    if (front) {
        std::swap(order[1], order[2]);
        area2 = -area2;
    }
    std::int64_t X[3], Y[3];
    for (int i = 0; i < 3; ++i) {
        X[i] = fx[order[i]];
        Y[i] = fy[order[i]];
        t.z[i] = z[order[i]];
        t.inv_w[i] = inv_w[order[i]];
        t.vtx[i] = ref[order[i]];
    }
    t.front_facing = front;

    // Pixel box: pixel i is a candidate when one of its samples i*256+128+s
    // lies within the vertices' extent. Arithmetic shifts floor negatives
    // correctly. The anchor is the first centre within the extent.
    std::int64_t lo_x = std::min({X[0], X[1], X[2]}), hi_x = std::max({X[0], X[1], X[2]});
    std::int64_t lo_y = std::min({Y[0], Y[1], Y[2]}), hi_y = std::max({Y[0], Y[1], Y[2]});
    auto ceil_pixel = [](std::int64_t v) { return (v - kHalfPixel + kSubPixelScale - 1) >> kSubPixelBits; };
    auto floor_pixel = [](std::int64_t v) { return (v - kHalfPixel) >> kSubPixelBits; };
    std::int64_t minx = ceil_pixel(lo_x - samples.hi_x), maxx = floor_pixel(hi_x - samples.lo_x);
    std::int64_t miny = ceil_pixel(lo_y - samples.hi_y), maxy = floor_pixel(hi_y - samples.lo_y);
    minx = std::max<std::int64_t>(minx, 0);
    miny = std::max<std::int64_t>(miny, 0);
    maxx = std::min<std::int64_t>(maxx, width - 1);
    maxy = std::min<std::int64_t>(maxy, height - 1);
    if (minx > maxx || miny > maxy) return SetupResult::Degenerate;
    t.minx = int(minx); t.miny = int(miny); t.maxx = int(maxx); t.maxy = int(maxy);
    const std::int64_t ax = std::max<std::int64_t>(ceil_pixel(lo_x), 0);
    const std::int64_t ay = std::max<std::int64_t>(ceil_pixel(lo_y), 0);
    t.ax = int(ax); t.ay = int(ay);

    // Edge functions. Edge i runs from vertex i+1 to vertex i+2:
    //   E(p) = (bx - ax)(py - ay) - (by - ay)(px - ax) = A px + B py + C.
    // Top-left rule (y down, positive area): a top edge is horizontal with
    // bx > ax; a left edge goes up (by < ay). Others exclude centres exactly on
    // them, which for integers is E - 1 >= 0.
    double anchor_x = double(ax * kSubPixelScale + kHalfPixel);
    double anchor_y = double(ay * kSubPixelScale + kHalfPixel);
    double inv_area2 = 1.0 / double(area2);
    t.area = float(double(area2) * (0.5 / double(kSubPixelScale * kSubPixelScale)));
    for (int e = 0; e < 3; ++e) {
        int a = (e + 1) % 3, b = (e + 2) % 3;
        std::int64_t A = Y[a] - Y[b];
        std::int64_t B = X[b] - X[a];
        std::int64_t C = -(A * X[a] + B * Y[a]);
        bool top = A == 0 && B > 0;
        bool left = A > 0;
        t.A[e] = std::int32_t(A);
        t.B[e] = std::int32_t(B);
        t.C[e] = (top || left) ? C : C - 1;
        // Barycentric plane of the opposite vertex, from the unbiased function.
        double at_anchor = double(A) * anchor_x + double(B) * anchor_y + double(C);
        t.bary[e][0] = float(at_anchor * inv_area2);
        t.bary[e][1] = float(double(A * kSubPixelScale) * inv_area2);
        t.bary[e][2] = float(double(B * kSubPixelScale) * inv_area2);
    }
    return SetupResult::Ok;
}

} // namespace prast

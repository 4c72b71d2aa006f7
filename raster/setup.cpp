// Triangle setup in fixed point; see setup.h.
#include "raster/setup.h"

#include <algorithm>
#include <cmath>
#include <cstring>

#if defined(__AVX2__)
#include <immintrin.h>
#endif

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

namespace {

// The vertices in the order that makes the area positive, and that area.
struct Ordered {
    std::int64_t X[3], Y[3];
    std::int64_t area2;
};

// Refuses, culls, or orders the vertices (filling t's per-vertex fields).
inline SetupResult order_vertices(const WindowVertex* const v[3], const std::uint32_t ref[3], bool cull_back,
                                  TriangleSetup& t, Ordered& o) {
    if (!v[0]->ok || !v[1]->ok || !v[2]->ok) return SetupResult::Degenerate;
    // Twice the signed area, exact. Front faces wind counter-clockwise in NDC
    // (y up), which is a negative area in window space (y down).
    const std::int64_t x0 = v[0]->x, y0 = v[0]->y;
    std::int64_t area2 = (std::int64_t(v[1]->x) - x0) * (std::int64_t(v[2]->y) - y0) -
                         (std::int64_t(v[2]->x) - x0) * (std::int64_t(v[1]->y) - y0);
    if (area2 == 0) return SetupResult::Degenerate;
    const bool front = area2 < 0;
    if (!front && cull_back) return SetupResult::CulledBack;
    // Order the vertices so that the area is positive: then every edge
    // function is >= 0 inside, whichever face we look at.
    const int k1 = front ? 2 : 1, k2 = front ? 1 : 2;
    const WindowVertex* const w[3] = {v[0], v[k1], v[k2]};
    o.area2 = front ? -area2 : area2;
    for (int i = 0; i < 3; ++i) {
        o.X[i] = w[i]->x;
        o.Y[i] = w[i]->y;
        t.z[i] = w[i]->z;
        t.inv_w[i] = w[i]->inv_w;
    }
    t.vtx[0] = ref[0];
    t.vtx[1] = ref[k1];
    t.vtx[2] = ref[k2];
    t.front_facing = front;
    return SetupResult::Ok;
}

// Pixel box: pixel i is a candidate when one of its samples i*256+128+s lies
// within the vertices' extent. Arithmetic shifts floor negatives correctly.
// The anchor is the first centre within the extent.
inline bool pixel_box(const Ordered& o, int width, int height, const SampleExtent& samples, TriangleSetup& t) {
    const std::int64_t* X = o.X;
    const std::int64_t* Y = o.Y;
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
    if (minx > maxx || miny > maxy) return false;
    t.minx = int(minx); t.miny = int(miny); t.maxx = int(maxx); t.maxy = int(maxy);
    t.ax = int(std::max<std::int64_t>(ceil_pixel(lo_x), 0));
    t.ay = int(std::max<std::int64_t>(ceil_pixel(lo_y), 0));
    return true;
}

// Edge functions. Edge i runs from vertex i+1 to vertex i+2:
//   E(p) = (bx - ax)(py - ay) - (by - ay)(px - ax) = A px + B py + C.
// Top-left rule (y down, positive area): a top edge is horizontal with
// bx > ax; a left edge goes up (by < ay). Others exclude centres exactly on
// them, which for integers is E - 1 >= 0. The barycentric plane of the
// opposite vertex comes from the unbiased function.
inline void edges_scalar(const Ordered& o, TriangleSetup& t) {
    const std::int64_t* X = o.X;
    const std::int64_t* Y = o.Y;
    const double anchor_x = double(std::int64_t(t.ax) * kSubPixelScale + kHalfPixel);
    const double anchor_y = double(std::int64_t(t.ay) * kSubPixelScale + kHalfPixel);
    const double inv_area2 = 1.0 / double(o.area2);
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
        double at_anchor = double(A) * anchor_x + double(B) * anchor_y + double(C);
        t.bary[e][0] = float(at_anchor * inv_area2);
        t.bary[e][1] = float(double(A * kSubPixelScale) * inv_area2);
        t.bary[e][2] = float(double(B * kSubPixelScale) * inv_area2);
    }
}

#if defined(__AVX2__)
// edges_scalar()'s integer and double operations, the three edges in lanes
// 0-2 (lane 3 computes an edge of zeros, unused). Every value is the scalar
// one: X, Y, A, B fit in 32 bits (|X|, |Y| <= 2^29, setup.h), the products
// are exact in 64, each double operation is the same rounded one in the same
// order, and C's conversion to double is its high half times 2^32 plus its
// low half, two exact values summed with one rounding, as cvtsi2sd rounds.
inline void edges_avx2(const Ordered& o, TriangleSetup& t) {
    const __m128i x = _mm_setr_epi32(int(o.X[0]), int(o.X[1]), int(o.X[2]), 0);
    const __m128i y = _mm_setr_epi32(int(o.Y[0]), int(o.Y[1]), int(o.Y[2]), 0);
    constexpr int kNext = _MM_SHUFFLE(3, 0, 2, 1), kAfter = _MM_SHUFFLE(3, 1, 0, 2);  // lane e: vertex e+1, e+2
    const __m128i xa = _mm_shuffle_epi32(x, kNext), xb = _mm_shuffle_epi32(x, kAfter);
    const __m128i ya = _mm_shuffle_epi32(y, kNext), yb = _mm_shuffle_epi32(y, kAfter);
    const __m128i A = _mm_sub_epi32(ya, yb), B = _mm_sub_epi32(xb, xa);
    const __m256i C = _mm256_sub_epi64(
        _mm256_setzero_si256(),
        _mm256_add_epi64(_mm256_mul_epi32(_mm256_cvtepi32_epi64(A), _mm256_cvtepi32_epi64(xa)),
                         _mm256_mul_epi32(_mm256_cvtepi32_epi64(B), _mm256_cvtepi32_epi64(ya))));
    const __m128i zero = _mm_setzero_si128();
    const __m128i top_left =
        _mm_or_si128(_mm_and_si128(_mm_cmpeq_epi32(A, zero), _mm_cmpgt_epi32(B, zero)), _mm_cmpgt_epi32(A, zero));
    // Not top-left: -1 (all ones) added.
    const __m256i biased = _mm256_add_epi64(C, _mm256_cvtepi32_epi64(_mm_xor_si128(top_left, _mm_set1_epi32(-1))));

    const __m256i halves = _mm256_permutevar8x32_epi32(C, _mm256_setr_epi32(1, 3, 5, 7, 0, 2, 4, 6));
    const __m256d c_hi = _mm256_cvtepi32_pd(_mm256_castsi256_si128(halves));
    const __m256d c_lo = _mm256_add_pd(
        _mm256_cvtepi32_pd(_mm_xor_si128(_mm256_extracti128_si256(halves, 1), _mm_set1_epi32(INT32_MIN))),
        _mm256_set1_pd(2147483648.0));
    const __m256d Cd = _mm256_add_pd(_mm256_mul_pd(c_hi, _mm256_set1_pd(4294967296.0)), c_lo);
    const __m256d Ad = _mm256_cvtepi32_pd(A), Bd = _mm256_cvtepi32_pd(B);

    const __m256d anchor_x = _mm256_set1_pd(double(std::int64_t(t.ax) * kSubPixelScale + kHalfPixel));
    const __m256d anchor_y = _mm256_set1_pd(double(std::int64_t(t.ay) * kSubPixelScale + kHalfPixel));
    const __m256d inv_area2 = _mm256_set1_pd(1.0 / double(o.area2));
    const __m256d scale = _mm256_set1_pd(double(kSubPixelScale));
    const __m256d at_anchor = _mm256_add_pd(_mm256_add_pd(_mm256_mul_pd(Ad, anchor_x), _mm256_mul_pd(Bd, anchor_y)), Cd);
    __m128 p0 = _mm256_cvtpd_ps(_mm256_mul_pd(at_anchor, inv_area2));
    __m128 p1 = _mm256_cvtpd_ps(_mm256_mul_pd(_mm256_mul_pd(Ad, scale), inv_area2));
    __m128 p2 = _mm256_cvtpd_ps(_mm256_mul_pd(_mm256_mul_pd(Bd, scale), inv_area2));
    __m128 p3 = _mm_setzero_ps();
    _MM_TRANSPOSE4_PS(p0, p1, p2, p3);  // p<e> = edge e's plane
    float planes[3 * 3 + 1];
    _mm_storeu_ps(planes + 0, p0);
    _mm_storeu_ps(planes + 3, p1);
    _mm_storeu_ps(planes + 6, p2);
    std::memcpy(t.bary, planes, sizeof t.bary);

    std::int32_t ab[8];
    _mm_storeu_si128(reinterpret_cast<__m128i*>(ab), A);
    _mm_storeu_si128(reinterpret_cast<__m128i*>(ab + 4), B);
    std::memcpy(t.A, ab, sizeof t.A);
    std::memcpy(t.B, ab + 4, sizeof t.B);
    std::int64_t c[4];
    _mm256_storeu_si256(reinterpret_cast<__m256i*>(c), biased);
    std::memcpy(t.C, c, sizeof t.C);
}
#endif

template <bool kScalar>
inline SetupResult setup_ordered(const WindowVertex* const v[3], const std::uint32_t ref[3], int width, int height,
                                 bool cull_back, TriangleSetup& t, const SampleExtent& samples) {
    Ordered o;
    const SetupResult r = order_vertices(v, ref, cull_back, t, o);
    if (r != SetupResult::Ok) return r;
    if (!pixel_box(o, width, height, samples, t)) return SetupResult::Degenerate;
    t.area = float(double(o.area2) * (0.5 / double(kSubPixelScale * kSubPixelScale)));
#if defined(__AVX2__)
    if constexpr (!kScalar) {
        edges_avx2(o, t);
        return SetupResult::Ok;
    }
#endif
    edges_scalar(o, t);
    return SetupResult::Ok;
}

} // namespace

SetupResult setup_triangle(const WindowVertex* const v[3], const std::uint32_t ref[3], int width, int height,
                           bool cull_back, TriangleSetup& t, const SampleExtent& samples) {
    return setup_ordered<false>(v, ref, width, height, cull_back, t, samples);
}

SetupResult setup_triangle_scalar(const WindowVertex* const v[3], const std::uint32_t ref[3], int width, int height,
                                  bool cull_back, TriangleSetup& t, const SampleExtent& samples) {
    return setup_ordered<true>(v, ref, width, height, cull_back, t, samples);
}

} // namespace prast

// Triangle setup in fixed point; see setup.h.
#include "raster/setup.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
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


#if defined(__AVX2__)
namespace {

// int64 lanes to double, rounded once as cvtsi2sd rounds: the high half
// times 2^32 (exact) plus the low half as unsigned (exact), one rounding.
inline __m256d int64_to_double(__m256i v) {
    const __m256i halves = _mm256_permutevar8x32_epi32(v, _mm256_setr_epi32(1, 3, 5, 7, 0, 2, 4, 6));
    const __m256d hi = _mm256_cvtepi32_pd(_mm256_castsi256_si128(halves));
    const __m256d lo = _mm256_add_pd(
        _mm256_cvtepi32_pd(_mm_xor_si128(_mm256_extracti128_si256(halves, 1), _mm_set1_epi32(INT32_MIN))),
        _mm256_set1_pd(2147483648.0));
    return _mm256_add_pd(_mm256_mul_pd(hi, _mm256_set1_pd(4294967296.0)), lo);
}

inline __m256i mul64(__m128i a, __m128i b) {
    return _mm256_mul_epi32(_mm256_cvtepi32_epi64(a), _mm256_cvtepi32_epi64(b));
}

// The low 32 bits of each 64-bit lane (a mask's lanes as 32-bit ones).
inline __m128i low_halves(__m256i v) {
    return _mm256_castsi256_si128(_mm256_permutevar8x32_epi32(v, _mm256_setr_epi32(0, 2, 4, 6, 0, 2, 4, 6)));
}

// Rows of four 32-bit fields across four triangles to four triangles' rows.
inline void transpose4(__m128i& r0, __m128i& r1, __m128i& r2, __m128i& r3) {
    __m128 a = _mm_castsi128_ps(r0), b = _mm_castsi128_ps(r1), c = _mm_castsi128_ps(r2), d = _mm_castsi128_ps(r3);
    _MM_TRANSPOSE4_PS(a, b, c, d);
    r0 = _mm_castps_si128(a); r1 = _mm_castps_si128(b); r2 = _mm_castps_si128(c); r3 = _mm_castps_si128(d);
}

// The byte layout the stores below write (TriangleSetup's declaration order).
static_assert(offsetof(TriangleSetup, C) == 0 && offsetof(TriangleSetup, A) == 24 &&
                  offsetof(TriangleSetup, B) == 36 && offsetof(TriangleSetup, minx) == 48 &&
                  offsetof(TriangleSetup, maxy) == 60 && offsetof(TriangleSetup, bary) == 64 &&
                  offsetof(TriangleSetup, ax) == 100 && offsetof(TriangleSetup, ay) == 104 &&
                  offsetof(TriangleSetup, z) == 108 && offsetof(TriangleSetup, inv_w) == 120 &&
                  offsetof(TriangleSetup, vtx) == 132 && offsetof(TriangleSetup, prim_id) == 144 &&
                  offsetof(TriangleSetup, area) == 148,
              "setup_triangles4 writes TriangleSetup by its byte layout");

inline void store16(TriangleSetup& t, std::size_t offset, __m128i v) {
    std::memcpy(reinterpret_cast<unsigned char*>(&t) + offset, &v, sizeof v);
}

} // namespace
#endif

void setup_triangles4(const WindowVertex* const* v, const std::uint32_t* ref, int n, int width, int height,
                      bool cull_back, const SampleExtent& samples, TriangleSetup* out, SetupResult* result) {
#if defined(__AVX2__)
    // Lanes past n compute triangle 0 again (their results are not reported).
    const int k1 = n > 1 ? 3 : 0, k2 = n > 2 ? 6 : 0, k3 = n > 3 ? 9 : 0;
    auto lanes_x = [&](int i) { return _mm_setr_epi32(v[i]->x, v[k1 + i]->x, v[k2 + i]->x, v[k3 + i]->x); };
    auto lanes_y = [&](int i) { return _mm_setr_epi32(v[i]->y, v[k1 + i]->y, v[k2 + i]->y, v[k3 + i]->y); };
    auto lanes_z = [&](int i) { return _mm_setr_ps(v[i]->z, v[k1 + i]->z, v[k2 + i]->z, v[k3 + i]->z); };
    auto lanes_w = [&](int i) { return _mm_setr_ps(v[i]->inv_w, v[k1 + i]->inv_w, v[k2 + i]->inv_w, v[k3 + i]->inv_w); };
    auto lanes_ref = [&](int i) {
        return _mm_setr_epi32(int(ref[i]), int(ref[k1 + i]), int(ref[k2 + i]), int(ref[k3 + i]));
    };
    const __m128i x0 = lanes_x(0), x1 = lanes_x(1), x2 = lanes_x(2);
    const __m128i y0 = lanes_y(0), y1 = lanes_y(1), y2 = lanes_y(2);

    // order_vertices(): twice the signed area (differences fit in 32 bits,
    // products in 64), front faces negative, the vertices 1 and 2 swapped
    // for them.
    const __m256i area = _mm256_sub_epi64(mul64(_mm_sub_epi32(x1, x0), _mm_sub_epi32(y2, y0)),
                                          mul64(_mm_sub_epi32(x2, x0), _mm_sub_epi32(y1, y0)));
    const __m256i zero64 = _mm256_setzero_si256();
    const __m256i front64 = _mm256_cmpgt_epi64(zero64, area);
    const __m256i area2 = _mm256_blendv_epi8(area, _mm256_sub_epi64(zero64, area), front64);
    const __m128i front = low_halves(front64);
    const __m128i X[3] = {x0, _mm_blendv_epi8(x1, x2, front), _mm_blendv_epi8(x2, x1, front)};
    const __m128i Y[3] = {y0, _mm_blendv_epi8(y1, y2, front), _mm_blendv_epi8(y2, y1, front)};

    // pixel_box(), in 32 bits (|X|, |Y| <= 2^29; the sample extent is within a pixel).
    const __m128i lo_x = _mm_min_epi32(X[0], _mm_min_epi32(X[1], X[2]));
    const __m128i hi_x = _mm_max_epi32(X[0], _mm_max_epi32(X[1], X[2]));
    const __m128i lo_y = _mm_min_epi32(Y[0], _mm_min_epi32(Y[1], Y[2]));
    const __m128i hi_y = _mm_max_epi32(Y[0], _mm_max_epi32(Y[1], Y[2]));
    auto ceil_pixel = [](__m128i p, std::int64_t less) {
        return _mm_srai_epi32(_mm_add_epi32(p, _mm_set1_epi32(std::int32_t(kSubPixelScale - 1 - kHalfPixel - less))),
                              kSubPixelBits);
    };
    auto floor_pixel = [](__m128i p, std::int64_t less) {
        return _mm_srai_epi32(_mm_sub_epi32(p, _mm_set1_epi32(std::int32_t(kHalfPixel + less))), kSubPixelBits);
    };
    const __m128i zero = _mm_setzero_si128();
    const __m128i minx = _mm_max_epi32(ceil_pixel(lo_x, samples.hi_x), zero);
    const __m128i miny = _mm_max_epi32(ceil_pixel(lo_y, samples.hi_y), zero);
    const __m128i maxx = _mm_min_epi32(floor_pixel(hi_x, samples.lo_x), _mm_set1_epi32(width - 1));
    const __m128i maxy = _mm_min_epi32(floor_pixel(hi_y, samples.lo_y), _mm_set1_epi32(height - 1));
    const __m128i empty = _mm_or_si128(_mm_cmpgt_epi32(minx, maxx), _mm_cmpgt_epi32(miny, maxy));
    const __m128i ax = _mm_max_epi32(ceil_pixel(lo_x, 0), zero), ay = _mm_max_epi32(ceil_pixel(lo_y, 0), zero);

    // edges_scalar(): lane k of each vector is triangle k.
    const __m256d area_d = int64_to_double(area2);
    const __m256d inv_area2 = _mm256_div_pd(_mm256_set1_pd(1.0), area_d);
    const __m128i pixel = _mm_set1_epi32(std::int32_t(kSubPixelScale)), half = _mm_set1_epi32(std::int32_t(kHalfPixel));
    const __m256d anchor_x = _mm256_cvtepi32_pd(_mm_add_epi32(_mm_mullo_epi32(ax, pixel), half));
    const __m256d anchor_y = _mm256_cvtepi32_pd(_mm_add_epi32(_mm_mullo_epi32(ay, pixel), half));
    const __m256d scale = _mm256_set1_pd(double(kSubPixelScale));
    __m128i A[3], B[3], plane[3][3];
    __m256i C[4];
    for (int e = 0; e < 3; ++e) {
        const int a = (e + 1) % 3, b = (e + 2) % 3;
        A[e] = _mm_sub_epi32(Y[a], Y[b]);
        B[e] = _mm_sub_epi32(X[b], X[a]);
        const __m256i c = _mm256_sub_epi64(zero64, _mm256_add_epi64(mul64(A[e], X[a]), mul64(B[e], Y[a])));
        const __m128i top_left = _mm_or_si128(_mm_and_si128(_mm_cmpeq_epi32(A[e], zero), _mm_cmpgt_epi32(B[e], zero)),
                                              _mm_cmpgt_epi32(A[e], zero));
        C[e] = _mm256_add_epi64(c, _mm256_cvtepi32_epi64(_mm_xor_si128(top_left, _mm_set1_epi32(-1))));
        const __m256d Ad = _mm256_cvtepi32_pd(A[e]), Bd = _mm256_cvtepi32_pd(B[e]);
        const __m256d at_anchor =
            _mm256_add_pd(_mm256_add_pd(_mm256_mul_pd(Ad, anchor_x), _mm256_mul_pd(Bd, anchor_y)), int64_to_double(c));
        plane[e][0] = _mm_castps_si128(_mm256_cvtpd_ps(_mm256_mul_pd(at_anchor, inv_area2)));
        plane[e][1] = _mm_castps_si128(_mm256_cvtpd_ps(_mm256_mul_pd(_mm256_mul_pd(Ad, scale), inv_area2)));
        plane[e][2] = _mm_castps_si128(_mm256_cvtpd_ps(_mm256_mul_pd(_mm256_mul_pd(Bd, scale), inv_area2)));
    }
    C[3] = zero64;
    alignas(16) float area_f[4];
    _mm_store_ps(area_f, _mm256_cvtpd_ps(_mm256_mul_pd(area_d, _mm256_set1_pd(0.5 / double(kSubPixelScale * kSubPixelScale)))));

    // The results, in order_vertices()' and pixel_box()' order of refusals.
    const int zero_area = _mm256_movemask_pd(_mm256_castsi256_pd(_mm256_cmpeq_epi64(area, zero64)));
    const int is_front = _mm_movemask_ps(_mm_castsi128_ps(front));
    const int is_empty = _mm_movemask_ps(_mm_castsi128_ps(empty));

    // Each triangle's bytes 0-107: C (a 4x4 transpose of 64-bit lanes), then
    // A, B, the box, the planes and ax, ay as five rows of four 32-bit fields
    // and one.
    __m256i t0 = _mm256_unpacklo_epi64(C[0], C[1]), t1 = _mm256_unpackhi_epi64(C[0], C[1]);
    __m256i t2 = _mm256_unpacklo_epi64(C[2], C[3]), t3 = _mm256_unpackhi_epi64(C[2], C[3]);
    const __m256i c_rows[4] = {_mm256_permute2x128_si256(t0, t2, 0x20), _mm256_permute2x128_si256(t1, t3, 0x20),
                               _mm256_permute2x128_si256(t0, t2, 0x31), _mm256_permute2x128_si256(t1, t3, 0x31)};
    __m128i g[5][4] = {{A[0], A[1], A[2], B[0]},
                       {B[1], B[2], minx, miny},
                       {maxx, maxy, plane[0][0], plane[0][1]},
                       {plane[0][2], plane[1][0], plane[1][1], plane[1][2]},
                       {plane[2][0], plane[2][1], plane[2][2], ax}};
    for (auto& r : g) transpose4(r[0], r[1], r[2], r[3]);
    // Bytes 104-147: ay and the ordered vertices' depths, 1 / w and
    // references, and 8 bytes (prim_id, area) the caller and the loop below
    // replace, as three rows more.
    const __m128 frontf = _mm_castsi128_ps(front);
    const __m128 z0 = lanes_z(0), z1 = lanes_z(1), z2 = lanes_z(2);
    const __m128 w0 = lanes_w(0), w1 = lanes_w(1), w2 = lanes_w(2);
    const __m128i r0 = lanes_ref(0), r1 = lanes_ref(1), r2 = lanes_ref(2);
    __m128i h[3][4] = {
        {ay, _mm_castps_si128(z0), _mm_castps_si128(_mm_blendv_ps(z1, z2, frontf)),
         _mm_castps_si128(_mm_blendv_ps(z2, z1, frontf))},
        {_mm_castps_si128(w0), _mm_castps_si128(_mm_blendv_ps(w1, w2, frontf)),
         _mm_castps_si128(_mm_blendv_ps(w2, w1, frontf)), r0},
        {_mm_blendv_epi8(r1, r2, front), _mm_blendv_epi8(r2, r1, front), zero, zero}};
    for (auto& r : h) transpose4(r[0], r[1], r[2], r[3]);

    const WindowVertex* const* w[4] = {v, v + k1, v + k2, v + k3};
    for (int k = 0; k < n; ++k) {
        const bool ok = w[k][0]->ok && w[k][1]->ok && w[k][2]->ok;
        const bool is_f = (is_front >> k) & 1;
        if (!ok || ((zero_area >> k) & 1)) {
            result[k] = SetupResult::Degenerate;
            continue;
        }
        if (!is_f && cull_back) {
            result[k] = SetupResult::CulledBack;
            continue;
        }
        if ((is_empty >> k) & 1) {
            result[k] = SetupResult::Degenerate;
            continue;
        }
        result[k] = SetupResult::Ok;
        TriangleSetup& t = out[k];
        std::memcpy(&t, &c_rows[k], sizeof c_rows[k]);  // C, and 8 bytes the next store replaces
        for (int r = 0; r < 5; ++r) store16(t, 24 + 16 * std::size_t(r), g[r][k]);
        for (int r = 0; r < 3; ++r) store16(t, 104 + 16 * std::size_t(r), h[r][k]);
        t.area = area_f[k];
        t.front_facing = is_f;
    }
#else
    for (int k = 0; k < n; ++k)
        result[k] = setup_triangle(v + 3 * k, ref + 3 * k, width, height, cull_back, out[k], samples);
#endif
}

} // namespace prast

// Rasterization of one triangle inside one tile: reject or accept 16x16
// blocks, then 4x4 blocks, then samples (exact integer edge tests at every
// sample position), then each covered sample's depth and the LESS test. This
// file owns coverage and depth; shade.h runs the fragment program on what
// survives, and frame.h walks a tile's bins in submission order. One thread
// owns a tile at a time, so its colour, depth and winners need no locking.
#pragma once

#include <algorithm>
#include <cstdint>
#include <cstring>

#if defined(__AVX2__)
#include <immintrin.h>
#endif

#include "raster/fragment.h"
#include "raster/observer.h"
#include "raster/samples.h"
#include "raster/setup.h"
#include "raster/stats.h"

namespace prast {

// A sample whose colour is final in the target (cleared, or written by a draw
// shaded in order) rather than owed by a winner of the visibility pass.
constexpr std::uint32_t kNoWinner = 0xFFFFFFFFu;

// Where the samples of one tile live. With one sample, colour and depth are
// the framebuffer itself (row = its width, origin 0, 0); with several, the
// tile-local planes of frame.h (row = tile size, origin = the tile's corner,
// sample s at s * plane). Winners are always tile-local.
struct TileTarget {
    float* color = nullptr;          // RGBA per sample; null for a depth target
    float* depth = nullptr;
    std::size_t row = 0, plane = 0;  // in pixels
    int ox = 0, oy = 0;
    bool local = false;              // tile-local planes: every 4x4 block of the tile lies inside them
    std::uint32_t* winner = nullptr;
    std::size_t wrow = 0, wplane = 0;
    int wox = 0, woy = 0;

    std::size_t offset(int x, int y) const { return std::size_t(y - oy) * row + std::size_t(x - ox); }
    std::size_t winner_offset(int x, int y) const { return std::size_t(y - woy) * wrow + std::size_t(x - wox); }
};

// What a tile's triangles share: the viewport, the samples and the target.
struct TileContext {
    int width = 0, height = 0;         // viewport
    const SamplePattern* samples = nullptr;
    SampleExtent extent;
    TileTarget target;
    int x0 = 0, y0 = 0, x1 = 0, y1 = 0;  // the tile's pixels, inclusive
    FrameStats* stats = nullptr;
    std::uint64_t* dirty = nullptr;    // a bit per 4x4 block of the tile holding winners
    int blocks_x = 0;                  // 4x4 blocks per tile row

    int sample_count() const { return samples->count; }
    void mark_dirty(int bx, int by) {
        const int b = ((by - y0) / kBlockSize) * blocks_x + (bx - x0) / kBlockSize;
        dirty[b >> 6] |= std::uint64_t(1) << (b & 63);
    }
};

namespace raster_detail {

inline int popcount16(std::uint32_t m) { return __builtin_popcount(m & 0xFFFFu); }

// Lanes of the 4x4 block at (bx, by) that are inside the viewport.
inline std::uint32_t scissor_mask(int bx, int by, int width, int height) {
    if (bx + kBlockSize <= width && by + kBlockSize <= height) return 0xFFFFu;
    std::uint32_t m = 0;
    for (int l = 0; l < kBlockLanes; ++l)
        if (bx + lane_x(l) < width && by + lane_y(l) < height) m |= 1u << l;
    return m;
}

// Per-triangle data prepared once per tile: lane offsets of the edge
// functions, each edge's extremes over a 16x16 and a 4x4 block relative to its
// top-left pixel centre (edge_span of setup.h, over the samples), and each
// sample's offset of each edge function from the pixel centre.
struct TriangleInTile {
    std::int64_t lane_offset[3][kBlockLanes];
    EdgeSpan coarse[3], fine[3];
    std::int64_t sample_offset[3][kMaxSamples];
};

// Eight floats with lane-wise IEEE arithmetic (the GCC/Clang vector
// extension), for the block loops that the auto-vectoriser gets wrong: given
// the interpolation loop, it vectorises across varyings and transposes; the
// std::min/max clamps it leaves scalar. Only ever a local variable: as a
// parameter or return value by value its ABI would depend on AVX (-Wpsabi).
typedef float Lanes8 __attribute__((vector_size(32)));
inline void load_lanes(Lanes8& v, const float* p) { std::memcpy(&v, p, sizeof v); }
inline void store_lanes(float* p, const Lanes8& v) { std::memcpy(p, &v, sizeof v); }

// A x + B y at the lanes' pixel offsets (fragment.h's lane order), by exact
// integer sums: quad (qx, qy) adds 2 qx A + 2 qy B to quad 0.
inline void lane_offsets(std::int64_t a, std::int64_t b, std::int64_t* out) {
    typedef std::int64_t Int64x4 __attribute__((vector_size(32)));
    const std::int64_t a1 = a * kSubPixelScale, b1 = b * kSubPixelScale;
    const Int64x4 quad0 = {0, a1, b1, a1 + b1};
    const Int64x4 quad1 = quad0 + 2 * a1, quad2 = quad0 + 2 * b1, quad3 = quad1 + 2 * b1;
    std::memcpy(out + 0, &quad0, sizeof quad0);
    std::memcpy(out + 4, &quad1, sizeof quad1);
    std::memcpy(out + 8, &quad2, sizeof quad2);
    std::memcpy(out + 12, &quad3, sizeof quad3);
}

// What the sample tests need: lane and sample offsets.
template <bool MS>
inline void prepare_lanes(const TriangleSetup& t, const TileContext& c, TriangleInTile& p) {
    for (int e = 0; e < 3; ++e) {
        lane_offsets(t.A[e], t.B[e], p.lane_offset[e]);
        if constexpr (MS) {
            const SamplePattern& sp = *c.samples;
            for (int s = 0; s < sp.count; ++s)
                p.sample_offset[e][s] = std::int64_t(t.A[e]) * sp.fixed_x(s) + std::int64_t(t.B[e]) * sp.fixed_y(s);
        } else {
            p.sample_offset[e][0] = 0;
        }
    }
}

// What the block classification needs besides: the edges' spans.
template <bool MS>
inline void prepare_spans(const TriangleSetup& t, const TileContext& c, TriangleInTile& p) {
    for (int e = 0; e < 3; ++e) {
        if constexpr (MS) {
            p.coarse[e] = edge_span(t, e, kCoarseBlockSize, c.extent);
            p.fine[e] = edge_span(t, e, kBlockSize, c.extent);
        } else {
            // edge_span with the single sample at the centre.
            const std::int64_t a = t.A[e], b = t.B[e];
            const std::int64_t a_hi = a > 0 ? a : 0, a_lo = a < 0 ? a : 0, b_hi = b > 0 ? b : 0, b_lo = b < 0 ? b : 0;
            constexpr std::int64_t coarse = std::int64_t(kCoarseBlockSize - 1) * kSubPixelScale;
            constexpr std::int64_t fine = std::int64_t(kBlockSize - 1) * kSubPixelScale;
            p.coarse[e] = {(a_hi + b_hi) * coarse, (a_lo + b_lo) * coarse};
            p.fine[e] = {(a_hi + b_hi) * fine, (a_lo + b_lo) * fine};
        }
    }
}

// Lane masks from comparisons. The compiler unrolls these loops and tests
// lane by lane, so with AVX2 they are written with the sign-mask instructions.
// Bit l: a[l] < b[l] (false for NaN).
inline std::uint32_t less_mask(const float* a, const float* b) {
#if defined(__AVX2__)
    std::uint32_t m = 0;
    for (int h = 0; h < kBlockLanes; h += 8)
        m |= std::uint32_t(_mm256_movemask_ps(_mm256_cmp_ps(_mm256_loadu_ps(a + h), _mm256_loadu_ps(b + h),
                                                            _CMP_LT_OQ))) << h;
    return m;
#else
    std::uint32_t m = 0;
    for (int l = 0; l < kBlockLanes; ++l) m |= std::uint32_t(a[l] < b[l]) << l;
    return m;
#endif
}

// Bit l: e0 + offset[l] >= 0 (no overflow: edge values stay below 2^60).
inline std::uint32_t nonnegative_mask(std::int64_t e0, const std::int64_t* offset) {
#if defined(__AVX2__)
    const __m256i e = _mm256_set1_epi64x(e0);
    std::uint32_t negative = 0;
    for (int h = 0; h < kBlockLanes; h += 4) {
        const __m256i v =
            _mm256_add_epi64(e, _mm256_loadu_si256(reinterpret_cast<const __m256i*>(offset + h)));
        negative |= std::uint32_t(_mm256_movemask_pd(_mm256_castsi256_pd(v))) << h;
    }
    return ~negative & 0xFFFFu;
#else
    std::uint32_t m = 0;
    for (int l = 0; l < kBlockLanes; ++l) m |= std::uint32_t(e0 + offset[l] >= 0) << l;
    return m;
#endif
}

// Lanes whose pixel centre is inside the triangle (the one-sample coverage),
// without a prepared TriangleInTile: for the centroid decision.
inline std::uint32_t centre_coverage(const TriangleSetup& t, int bx, int by) {
    std::uint32_t m = 0xFFFFu;
    alignas(32) std::int64_t offset[kBlockLanes];
    for (int e = 0; e < 3; ++e) {
        lane_offsets(t.A[e], t.B[e], offset);
        m &= nonnegative_mask(edge_at_pixel(t, e, bx, by), offset);
    }
    return m;
}

// Offset of lane l's pixel from the block's top-left pixel, in a row-major
// buffer `row` pixels wide. Lanes 2j and 2j + 1 are neighbours in one row.
inline std::size_t lane_offset_in(std::size_t row, int l) {
    return std::size_t(lane_y(l)) * row + std::size_t(lane_x(l));
}

#if defined(__AVX2__)
// Half a block (lanes h..h+7, h = 0 or 8) is two block rows: lanes 0,1,4,5
// then 2,3,6,7 of the half. This permutation turns lane order into row order
// and back (it is its own inverse); kRowSelect[i] is the lane bit of row
// position i, so a broadcast mask ANDed with it gives row-ordered lane masks.
inline __m256i half_row_order() { return _mm256_setr_epi32(0, 1, 4, 5, 2, 3, 6, 7); }
inline __m256i half_row_mask(std::uint32_t mask_bits) {
    const __m256i select = _mm256_setr_epi32(1, 2, 16, 32, 4, 8, 64, 128);
    return _mm256_cmpeq_epi32(_mm256_and_si256(_mm256_set1_epi32(int(mask_bits & 0xFFu)), select), select);
}
#endif

// The 16 values of a block in lane order from a row-major buffer; lanes
// outside `mask` read 0 unless the whole block is inside the buffer (`full`).
// Masked-out lanes are never touched (the block may straddle the buffer's end).
[[gnu::always_inline]] inline void load_block(const float* p, std::size_t row, bool full, std::uint32_t mask, float* out) {
#if defined(__AVX2__)
    const std::uint32_t m = full ? 0xFFFFu : mask;
    for (int h = 0; h < kBlockLanes; h += 8, p += 2 * row) {
        if (!((m >> h) & 0xFFu)) {
            _mm256_storeu_ps(out + h, _mm256_setzero_ps());
            continue;
        }
        const __m256i mm = half_row_mask(m >> h);
        const __m128 r0 = _mm_maskload_ps(p, _mm256_castsi256_si128(mm));
        const __m128 r1 = _mm_maskload_ps(p + row, _mm256_extracti128_si256(mm, 1));
        _mm256_storeu_ps(out + h, _mm256_permutevar8x32_ps(_mm256_set_m128(r1, r0), half_row_order()));
    }
#else
    if (full) {
        for (int l = 0; l < kBlockLanes; l += 2) std::memcpy(&out[l], p + lane_offset_in(row, l), 2 * sizeof(float));
    } else {
        for (int l = 0; l < kBlockLanes; ++l) out[l] = (mask & (1u << l)) ? p[lane_offset_in(row, l)] : 0.0f;
    }
#endif
}

#if defined(__AVX2__)
// Four values (one block row) into p where `mask` says: a plain store when it
// says all four; when the row lies inside the buffer (`whole`), read, blend
// and write back, since masked stores are slow on some CPUs (AMD's run them
// as microcode); otherwise a masked store, which touches nothing outside.
inline void store_row(float* p, __m128i mask, __m128 v, bool whole) {
    if (_mm_movemask_ps(_mm_castsi128_ps(mask)) == 0xF) _mm_storeu_ps(p, v);
    else if (whole) _mm_storeu_ps(p, _mm_blendv_ps(_mm_loadu_ps(p), v, _mm_castsi128_ps(mask)));
    else _mm_maskstore_ps(p, mask, v);
}
#endif

// `whole`: the block lies inside the buffer (block_inside()).
[[gnu::always_inline]] inline void store_block(float* p, std::size_t row, std::uint32_t mask, const float* v, bool whole) {
#if defined(__AVX2__)
    for (int h = 0; h < kBlockLanes; h += 8, p += 2 * row) {
        if (!((mask >> h) & 0xFFu)) continue;
        const __m256i mm = half_row_mask(mask >> h);
        const __m256 r = _mm256_permutevar8x32_ps(_mm256_loadu_ps(v + h), half_row_order());
        store_row(p, _mm256_castsi256_si128(mm), _mm256_castps256_ps128(r), whole);
        store_row(p + row, _mm256_extracti128_si256(mm, 1), _mm256_extractf128_ps(r, 1), whole);
    }
#else
    (void)whole;
    for (std::uint32_t m = mask; m; m &= m - 1) {
        const int l = __builtin_ctz(m);
        p[lane_offset_in(row, l)] = v[l];
    }
#endif
}

// Winners are tile-local: every block lies inside.
inline void store_winner(std::uint32_t* p, std::size_t row, std::uint32_t mask, std::uint32_t id) {
#if defined(__AVX2__)
    const __m128 v = _mm_castsi128_ps(_mm_set1_epi32(int(id)));
    for (int h = 0; h < kBlockLanes; h += 8, p += 2 * row) {
        if (!((mask >> h) & 0xFFu)) continue;
        const __m256i mm = half_row_mask(mask >> h);
        store_row(reinterpret_cast<float*>(p), _mm256_castsi256_si128(mm), v, true);
        store_row(reinterpret_cast<float*>(p + row), _mm256_extracti128_si256(mm, 1), v, true);
    }
#else
    for (std::uint32_t m = mask; m; m &= m - 1) p[lane_offset_in(row, __builtin_ctz(m))] = id;
#endif
}

// The 16 winners of a block in lane order (tile-local: the block is inside).
inline void load_winners(const std::uint32_t* p, std::size_t row, std::uint32_t* out) {
#if defined(__AVX2__)
    for (int h = 0; h < kBlockLanes; h += 8, p += 2 * row) {
        const __m128i r0 = _mm_loadu_si128(reinterpret_cast<const __m128i*>(p));
        const __m128i r1 = _mm_loadu_si128(reinterpret_cast<const __m128i*>(p + row));
        _mm256_storeu_si256(reinterpret_cast<__m256i*>(out + h),
                            _mm256_permutevar8x32_epi32(_mm256_set_m128i(r1, r0), half_row_order()));
    }
#else
    for (int l = 0; l < kBlockLanes; l += 2)
        std::memcpy(&out[l], p + lane_offset_in(row, l), 2 * sizeof(std::uint32_t));
#endif
}

// Screen-space barycentrics of the 16 lanes from the anchored planes, at the
// pixel centres moved by (sx, sy) pixels (a sample's offset; kOffset false:
// the centres themselves, with exactly the one-sample float operations).
template <bool kOffset>
[[gnu::always_inline]] inline void block_barycentrics(const TriangleSetup& t, int bx, int by, float sx, float sy, float* b0, float* b1,
                               float* b2) {
    const float ox = float(bx - t.ax), oy = float(by - t.ay);
    for (int l = 0; l < kBlockLanes; ++l) {
        float dx = ox + float(lane_x(l)), dy = oy + float(lane_y(l));
        if constexpr (kOffset) {
            dx = dx + sx;
            dy = dy + sy;
        }
        b0[l] = t.bary[0][0] + t.bary[0][1] * dx + t.bary[0][2] * dy;
        b1[l] = t.bary[1][0] + t.bary[1][1] * dx + t.bary[1][2] * dy;
        b2[l] = t.bary[2][0] + t.bary[2][1] * dx + t.bary[2][2] * dy;
    }
}

inline float depth_from_barycentrics(const TriangleSetup& t, float b0, float b1, float b2) {
    const float z = b0 * t.z[0] + b1 * t.z[1] + b2 * t.z[2];
    return std::min(std::max(z, 0.0f), 1.0f);
}

// depth_from_barycentrics for the 16 lanes, eight at a time.
[[gnu::always_inline]] inline void block_depths(const TriangleSetup& t, const float* b0, const float* b1, const float* b2, float* z) {
    for (int h = 0; h < kBlockLanes; h += 8) {
        Lanes8 q0, q1, q2;
        load_lanes(q0, b0 + h);
        load_lanes(q1, b1 + h);
        load_lanes(q2, b2 + h);
        Lanes8 v = q0 * t.z[0] + q1 * t.z[1] + q2 * t.z[2];
        v = v < 0.0f ? 0.0f : v;   // std::max(v, 0): NaN stays NaN
        v = 1.0f < v ? 1.0f : v;   // std::min(v, 1)
        store_lanes(z + h, v);
    }
}

// Window depth of the 16 lanes at sample s (linear in screen space).
inline void sample_depths(const TriangleSetup& t, const SamplePattern& sp, int s, int bx, int by, float* z) {
    alignas(64) float b0[kBlockLanes], b1[kBlockLanes], b2[kBlockLanes];
    if (sp.count == 1) block_barycentrics<false>(t, bx, by, 0.0f, 0.0f, b0, b1, b2);
    else block_barycentrics<true>(t, bx, by, sp.pixel_x(s), sp.pixel_y(s), b0, b1, b2);
    block_depths(t, b0, b1, b2, z);
}

// One block of one triangle, sample by sample: coverage, depth, depth test.
// With one sample the depths come from the centre barycentrics, which are
// kept for the interpolation (b0, b1, b2).
struct BlockSamples {
    std::uint32_t cover[kMaxSamples];
    std::uint32_t pass[kMaxSamples];
    std::uint32_t any_cover = 0, any_pass = 0;
    // No edge crosses the block's sample box, which holds its pixel centres:
    // every centre is inside too (no lane moves to a centroid).
    bool inside = false;
    alignas(64) float z[kMaxSamples][kBlockLanes];
    alignas(64) float b0[kBlockLanes], b1[kBlockLanes], b2[kBlockLanes];
};

// Samples per pixel: 1 at compile time, or the frame's count (MS).
template <bool MS>
inline int samples_of(const TileContext& c) { return MS ? c.sample_count() : 1; }

// The 4x4 block at (bx, by) lies inside the target's planes.
inline bool block_inside(const TileContext& c, int bx, int by) {
    return c.target.local || (bx + kBlockSize <= c.width && by + kBlockSize <= c.height);
}

// Depths of the covered samples and the LESS test against the target (every
// covered sample passes without a depth test). `all_z`: also the depths of
// samples nothing covers (for observers).
template <bool MS>
[[gnu::always_inline]] inline void test_depth(const TriangleSetup& t, const TileContext& c, int bx, int by, bool depth_test, bool all_z,
                       BlockSamples& bs) {
    const TileTarget& tg = c.target;
    const bool full = block_inside(c, bx, by);
    const float* depth = tg.depth + tg.offset(bx, by);
    const int S = samples_of<MS>(c);
    bs.any_pass = 0;
    for (int s = 0; s < S; ++s, depth += tg.plane) {
        bs.pass[s] = 0;
        if (!bs.cover[s] && !all_z) continue;
        if constexpr (MS) {
            sample_depths(t, *c.samples, s, bx, by, bs.z[s]);
        } else {
            block_barycentrics<false>(t, bx, by, 0.0f, 0.0f, bs.b0, bs.b1, bs.b2);
            block_depths(t, bs.b0, bs.b1, bs.b2, bs.z[0]);
        }
        if (!bs.cover[s]) continue;
        if (depth_test) {
            alignas(64) float d[kBlockLanes];
            load_block(depth, tg.row, full, bs.cover[s], d);
            bs.pass[s] = bs.cover[s] & less_mask(bs.z[s], d);
        } else {
            bs.pass[s] = bs.cover[s];
        }
        bs.any_pass |= bs.pass[s];
    }
}

template <class Observer>
inline void observe_fragments(Observer& obs, const TriangleSetup& t, const TileContext& c, int bx, int by,
                              const BlockSamples& bs) {
    if constexpr (Observer::enabled) {
        obs.fragments(t.prim_id, bx, by, bs.any_cover, bs.any_pass, bs.z[0]);
        if constexpr (observes_samples<Observer>) {
            SampleCoverage sc;
            sc.count = c.sample_count();
            for (int s = 0; s < sc.count; ++s) {
                sc.cover[s] = bs.cover[s];
                sc.pass[s] = bs.pass[s];
                sc.z[s] = bs.z[s];
            }
            obs.samples(t.prim_id, bx, by, sc);
        }
    }
    (void)obs; (void)t; (void)c; (void)bx; (void)by; (void)bs;
}

inline void count_fragments(FrameStats& stats, const BlockSamples& bs) {
    stats.fragments_covered += popcount16(bs.any_cover);
    stats.fragments_depth_killed += popcount16(bs.any_cover & ~bs.any_pass);
}

// The samples of the 4x4 block at (bx, by) inside the edges in `partial`
// (the others hold the whole block) and the viewport: bs.cover, bs.any_cover.
template <bool MS>
[[gnu::always_inline]] inline void block_coverage(const TriangleSetup& t, const TileContext& c, const TriangleInTile& p, int bx, int by,
                           unsigned partial, BlockSamples& bs) {
    const int S = samples_of<MS>(c);
    const std::uint32_t scissor = scissor_mask(bx, by, c.width, c.height);
    bs.any_cover = 0;
    const SampleExtent& x = c.extent;
    bs.inside = !partial && x.lo_x <= 0 && x.hi_x >= 0 && x.lo_y <= 0 && x.hi_y >= 0;
    if (!partial) {
        for (int s = 0; s < S; ++s) bs.cover[s] = scissor;
        bs.any_cover = scissor;
        return;
    }
    std::int64_t e0[3];
    for (int e = 0; e < 3; ++e) e0[e] = edge_at_pixel(t, e, bx, by);
    for (int s = 0; s < S; ++s) {
        std::uint32_t m = scissor;
        for (int e = 0; e < 3; ++e)
            if (partial & (1u << e)) m &= nonnegative_mask(e0[e] + p.sample_offset[e][s], p.lane_offset[e]);
        bs.cover[s] = m;
        bs.any_cover |= m;
    }
}

// Calls fn(bx, by, bs) for every 4x4 block of the tile with a covered sample
// (bs.cover and bs.any_cover filled in), hierarchically: 16x16 blocks are
// rejected or found inside per edge, then 4x4 blocks, then samples. A
// triangle whose box (in this tile) lies in one 4x4 block goes to its
// samples at once: the classifications only skip work, so the coverage is
// the same.
template <bool MS, class BlockFn>
[[gnu::always_inline]] inline void for_each_block(const TriangleSetup& t, const TileContext& c, FrameStats& stats, BlockFn&& fn) {
    // The part of the tile the triangle's box overlaps (inclusive pixels).
    const int x0 = std::max(c.x0, t.minx), x1 = std::min(c.x1, t.maxx);
    const int y0 = std::max(c.y0, t.miny), y1 = std::min(c.y1, t.maxy);
    if (x0 > x1 || y0 > y1) return;

    TriangleInTile p;
    prepare_lanes<MS>(t, c, p);
    BlockSamples bs;
    constexpr int kBlockMask = ~(kBlockSize - 1);
    if ((x0 & kBlockMask) == (x1 & kBlockMask) && (y0 & kBlockMask) == (y1 & kBlockMask)) {
        const int bx = x0 & kBlockMask, by = y0 & kBlockMask;
        block_coverage<MS>(t, c, p, bx, by, 7u, bs);
        if (!bs.any_cover) return;
        ++stats.blocks_rasterized;
        fn(bx, by, bs);
        return;
    }
    prepare_spans<MS>(t, c, p);

    for (int cy = y0 & ~(kCoarseBlockSize - 1); cy <= y1; cy += kCoarseBlockSize) {
        for (int cx = x0 & ~(kCoarseBlockSize - 1); cx <= x1; cx += kCoarseBlockSize) {
            unsigned partial = 0;
            bool out = false;
            for (int e = 0; e < 3 && !out; ++e) {
                EdgeClass k = classify_edge(edge_at_pixel(t, e, cx, cy), p.coarse[e]);
                if (k == kEdgeOut) out = true;
                else if (k == kEdgePartial) partial |= 1u << e;
            }
            if (out) continue;
            const int bx_lo = std::max(cx, x0 & kBlockMask), bx_hi = std::min(cx + kCoarseBlockSize - 1, x1);
            const int by_lo = std::max(cy, y0 & kBlockMask), by_hi = std::min(cy + kCoarseBlockSize - 1, y1);
            for (int by = by_lo; by <= by_hi; by += kBlockSize) {
                for (int bx = bx_lo; bx <= bx_hi; bx += kBlockSize) {
                    unsigned block_partial = 0;
                    if (partial) {
                        // Iterate over partials: reject 4x4 blocks, then test samples.
                        bool block_out = false;
                        for (int e = 0; e < 3 && !block_out; ++e) {
                            if (!(partial & (1u << e))) continue;
                            EdgeClass k = classify_edge(edge_at_pixel(t, e, bx, by), p.fine[e]);
                            if (k == kEdgeOut) block_out = true;
                            else if (k == kEdgePartial) block_partial |= 1u << e;
                        }
                        if (block_out) continue;
                    }
                    // With no partial edge every sample is inside.
                    block_coverage<MS>(t, c, p, bx, by, block_partial, bs);
                    if (!bs.any_cover) continue;
                    ++stats.blocks_rasterized;
                    fn(bx, by, bs);
                }
            }
        }
    }
}

// The visibility pass for one triangle of a draw that writes depth and
// replaces colour: depth test and write sample by sample in submission order,
// and the triangle (`winner`, its index in the tile's list) becomes the
// winner of every sample it passes. A draw without a fragment program (depth
// only) passes kNoWinner and leaves the winners, hence the colour, alone.
template <bool MS, class Observer>
void rasterize_depth(const TriangleSetup& t, TileContext& c, bool depth_test, bool depth_write,
                     std::uint32_t winner, Observer& obs) {
    FrameStats& stats = *c.stats;
    const TileTarget& tg = c.target;
    for_each_block<MS>(t, c, stats, [&](int bx, int by, BlockSamples& bs) {
        test_depth<MS>(t, c, bx, by, depth_test, Observer::enabled, bs);
        count_fragments(stats, bs);
        stats.fragments_written += popcount16(bs.any_pass);
        observe_fragments(obs, t, c, bx, by, bs);
        if (!bs.any_pass) return;
        float* depth = tg.depth + tg.offset(bx, by);
        std::uint32_t* win = tg.winner ? tg.winner + tg.winner_offset(bx, by) : nullptr;
        const bool inside = block_inside(c, bx, by);
        for (int s = 0; s < samples_of<MS>(c); ++s, depth += tg.plane) {
            if (!bs.pass[s]) continue;
            if (depth_write) store_block(depth, tg.row, bs.pass[s], bs.z[s], inside);
            if (winner != kNoWinner) store_winner(win + s * tg.wplane, tg.wrow, bs.pass[s], winner);
        }
        if (winner != kNoWinner) c.mark_dirty(bx, by);
    });
}

} // namespace raster_detail
} // namespace prast

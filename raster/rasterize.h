// Tile rasterization: for one screen tile, walk its bins in submission order and
// for each triangle reject or accept 16x16 blocks, then 4x4 blocks, then pixels
// (exact integer edge tests), run the early depth test, interpolate varyings
// perspective-correctly and call the fragment shader once per 4x4 block.
// One thread owns a tile at a time, so colour and depth need no locking.
#pragma once

#include <algorithm>
#include <cstdint>
#include <cstring>

#if defined(__AVX2__)
#include <immintrin.h>
#endif

#include "raster/bin.h"
#include "raster/draw_state.h"
#include "raster/fragment.h"
#include "raster/framebuffer.h"
#include "raster/observer.h"
#include "raster/setup.h"
#include "raster/stats.h"

namespace prast {

// Everything a tile needs from its draw call.
struct TileContext {
    Framebuffer* fb;
    const TileGrid* grid;
    const DrawState* state;
    const float* vertices;       // post-vertex-shader array
    const BinJob* jobs;
    int job_count;
    int stride;                  // floats per vertex: 4 + varyings
};

namespace detail {

inline int popcount16(std::uint32_t m) { return __builtin_popcount(m & 0xFFFFu); }

// Lanes of the 4x4 block at (bx, by) that are inside the viewport.
inline std::uint32_t scissor_mask(int bx, int by, int width, int height) {
    if (bx + kBlockSize <= width && by + kBlockSize <= height) return 0xFFFFu;
    std::uint32_t m = 0;
    for (int l = 0; l < kBlockLanes; ++l)
        if (bx + lane_x(l) < width && by + lane_y(l) < height) m |= 1u << l;
    return m;
}

// Per-triangle data prepared once per tile: lane offsets of the edge functions,
// the extremes of each edge function over a 16x16 and a 4x4 block relative to
// its top-left pixel (classify_block() of setup.h, whose terms do not depend on
// the block), and the varyings of the three vertices as (v0, v1 - v0, v2 - v0).
template <int NV>
struct TriangleInTile {
    std::int64_t lane_offset[3][kBlockLanes];
    std::int64_t coarse_hi[3], coarse_lo[3], fine_hi[3], fine_lo[3];
    float v0[NV > 0 ? NV : 1], d1[NV > 0 ? NV : 1], d2[NV > 0 ? NV : 1];
};

// classify_block(t, e, x, y, size) with the block-independent terms taken
// from TriangleInTile: the same integer sums, hence the same answer.
inline EdgeClass classify_edge(std::int64_t e0, std::int64_t hi, std::int64_t lo) {
    if (e0 + hi < 0) return kEdgeOut;
    if (e0 + lo >= 0) return kEdgeIn;
    return kEdgePartial;
}

template <int NV>
void prepare_triangle(const TriangleSetup& t, const TileContext& ctx, const BinJob& job,
                      TriangleInTile<NV>& p) {
    for (int e = 0; e < 3; ++e) {
        // A x + B y at the lanes' pixel offsets (fragment.h's lane order), by
        // exact integer sums: quad (qx, qy) adds 2 qx A + 2 qy B to quad 0.
        typedef std::int64_t Int64x4 __attribute__((vector_size(32)));
        const std::int64_t a = t.A[e], b = t.B[e];
        const std::int64_t a1 = a * kSubPixelScale, b1 = b * kSubPixelScale;
        const Int64x4 quad0 = {0, a1, b1, a1 + b1};
        const Int64x4 quad1 = quad0 + 2 * a1, quad2 = quad0 + 2 * b1, quad3 = quad1 + 2 * b1;
        std::memcpy(&p.lane_offset[e][0], &quad0, sizeof quad0);
        std::memcpy(&p.lane_offset[e][4], &quad1, sizeof quad1);
        std::memcpy(&p.lane_offset[e][8], &quad2, sizeof quad2);
        std::memcpy(&p.lane_offset[e][12], &quad3, sizeof quad3);
        const std::int64_t coarse = std::int64_t(kCoarseBlockSize - 1) * kSubPixelScale;
        const std::int64_t fine = std::int64_t(kBlockSize - 1) * kSubPixelScale;
        p.coarse_hi[e] = (a > 0 ? a : 0) * coarse + (b > 0 ? b : 0) * coarse;
        p.coarse_lo[e] = (a < 0 ? a : 0) * coarse + (b < 0 ? b : 0) * coarse;
        p.fine_hi[e] = (a > 0 ? a : 0) * fine + (b > 0 ? b : 0) * fine;
        p.fine_lo[e] = (a < 0 ? a : 0) * fine + (b < 0 ? b : 0) * fine;
    }
    const float* v[3];
    for (int i = 0; i < 3; ++i) {
        std::uint32_t r = t.vtx[i];
        v[i] = (r & kClippedVertexBit) ? &job.clip_pool[std::size_t(r & ~kClippedVertexBit) * ctx.stride]
                                       : &ctx.vertices[std::size_t(r) * ctx.stride];
    }
    for (int k = 0; k < NV; ++k) {
        p.v0[k] = v[0][4 + k];
        p.d1[k] = v[1][4 + k] - v[0][4 + k];
        p.d2[k] = v[2][4 + k] - v[0][4 + k];
    }
}

// Eight floats with lane-wise IEEE arithmetic (the GCC/Clang vector
// extension), for the block loops that the auto-vectoriser gets wrong: given
// the interpolation loop, it vectorises across varyings and transposes. Only
// ever a local variable: as a parameter or return value by value its ABI would
// depend on AVX (-Wpsabi).
typedef float Lanes8 __attribute__((vector_size(32)));
inline void load_lanes(Lanes8& v, const float* p) { std::memcpy(&v, p, sizeof v); }
inline void store_lanes(float* p, const Lanes8& v) { std::memcpy(p, &v, sizeof v); }

// Offset of lane l's pixel from the block's top-left pixel, in a row-major
// buffer `width` pixels wide. Lanes 2j and 2j + 1 are neighbours in one row.
inline std::size_t lane_offset_in(int width, int l) {
    return std::size_t(lane_y(l)) * std::size_t(width) + std::size_t(lane_x(l));
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

// Depth test, interpolation, shading and write-back of one 4x4 block.
template <class Program, class Observer>
void shade_block(const Program& program, const TileContext& ctx, const TriangleSetup& t,
                 const TriangleInTile<Program::kVaryings>& p, int bx, int by, std::uint32_t mask,
                 FrameStats& stats, Observer& obs) {
    constexpr int NV = Program::kVaryings;
    Framebuffer& fb = *ctx.fb;
    const DrawState& st = *ctx.state;
    const bool full = bx + kBlockSize <= fb.width && by + kBlockSize <= fb.height;
    const std::size_t block_offset = std::size_t(by) * std::size_t(fb.width) + std::size_t(bx);

    // Screen-space barycentrics from the anchored planes, then depth.
    alignas(64) float b0[kBlockLanes], b1[kBlockLanes], b2[kBlockLanes];
    FragmentBlock<NV> in;
    const float ox = float(bx - t.minx), oy = float(by - t.miny);
    for (int l = 0; l < kBlockLanes; ++l) {
        float dx = ox + float(lane_x(l)), dy = oy + float(lane_y(l));
        b0[l] = t.bary[0][0] + t.bary[0][1] * dx + t.bary[0][2] * dy;
        b1[l] = t.bary[1][0] + t.bary[1][1] * dx + t.bary[1][2] * dy;
        b2[l] = t.bary[2][0] + t.bary[2][1] * dx + t.bary[2][2] * dy;
        float z = b0[l] * t.z[0] + b1[l] * t.z[1] + b2[l] * t.z[2];
        in.z[l] = std::min(std::max(z, 0.0f), 1.0f);
    }

    // Early depth test (the shader never writes depth): the buffer's depths in
    // lane order, then one vector compare.
    std::uint32_t pass = mask;
    if (st.depth_test) {
        alignas(64) float d[kBlockLanes];
        const float* depth = &fb.depth[block_offset];
        if (full) {
            for (int l = 0; l < kBlockLanes; l += 2)
                std::memcpy(&d[l], depth + lane_offset_in(fb.width, l), 2 * sizeof(float));
        } else {
            for (int l = 0; l < kBlockLanes; ++l)
                d[l] = (mask & (1u << l)) ? depth[lane_offset_in(fb.width, l)] : 0.0f;
        }
        pass &= less_mask(in.z, d);
    }
    stats.fragments_covered += popcount16(mask);
    stats.fragments_depth_killed += popcount16(mask & ~pass);
    if constexpr (Observer::enabled) obs.fragments(t.prim_id, bx, by, mask, pass, in.z);
    if (!pass) return;

    // Perspective-correct weights: screen barycentrics over w, renormalised;
    // then every varying, eight lanes at a time.
    for (int h = 0; h < kBlockLanes; h += 8) {
        Lanes8 q0, q1, q2;
        load_lanes(q0, b0 + h);
        load_lanes(q1, b1 + h);
        load_lanes(q2, b2 + h);
        q0 = q0 * t.inv_w[0];
        q1 = q1 * t.inv_w[1];
        q2 = q2 * t.inv_w[2];
        const Lanes8 s = 1.0f / (q0 + q1 + q2);
        const Lanes8 w1 = q1 * s, w2 = q2 * s;
        for (int k = 0; k < NV; ++k) {
            const Lanes8 v = p.v0[k] + w1 * p.d1[k] + w2 * p.d2[k];
            store_lanes(in.var[k] + h, v);
        }
    }
    in.x = bx;
    in.y = by;
    in.mask = pass;
    in.prim_id = t.prim_id;
    in.front_facing = t.front_facing;

    FragmentOut out;
    out.kill = 0;
    program.fragment(in, out);
    std::uint32_t live = pass & ~out.kill;
    for (int q = 0; q < 4; ++q) stats.quads_shaded += ((pass >> (4 * q)) & 0xFu) != 0;
    stats.fragments_shader_killed += popcount16(pass & out.kill);
    stats.fragments_written += popcount16(live);
    if constexpr (Observer::enabled) obs.shaded(in, out, live);

    // Write-back.
    float* depth = &fb.depth[block_offset];
    float* color = &fb.color[block_offset * 4];
    if (st.blend == Blend::Add) {
        for (std::uint32_t m = live; m; m &= m - 1) {
            const int l = __builtin_ctz(m);
            const std::size_t o = lane_offset_in(fb.width, l);
            if (st.depth_write) depth[o] = in.z[l];
            float* c = color + o * 4;
            c[0] += out.r[l]; c[1] += out.g[l]; c[2] += out.b[l]; c[3] += out.a[l];
        }
        return;
    }
    if (live == 0xFFFFu) {
        // Every pixel: lanes 2j and 2j + 1 are neighbours in a row, written
        // as one pair of RGBA pixels.
        if (st.depth_write)
            for (int l = 0; l < kBlockLanes; l += 2)
                std::memcpy(depth + lane_offset_in(fb.width, l), &in.z[l], 2 * sizeof(float));
#if defined(__AVX2__)
        for (int h = 0; h < kBlockLanes; h += 8) {
            const __m256 r = _mm256_load_ps(out.r + h), g = _mm256_load_ps(out.g + h);
            const __m256 b = _mm256_load_ps(out.b + h), a = _mm256_load_ps(out.a + h);
            // Interleave: RGBA of lane h + i in the half of p[i % 4] given by i / 4.
            const __m256d rg_lo = _mm256_castps_pd(_mm256_unpacklo_ps(r, g));
            const __m256d ba_lo = _mm256_castps_pd(_mm256_unpacklo_ps(b, a));
            const __m256d rg_hi = _mm256_castps_pd(_mm256_unpackhi_ps(r, g));
            const __m256d ba_hi = _mm256_castps_pd(_mm256_unpackhi_ps(b, a));
            const __m256 p0 = _mm256_castpd_ps(_mm256_unpacklo_pd(rg_lo, ba_lo));
            const __m256 p1 = _mm256_castpd_ps(_mm256_unpackhi_pd(rg_lo, ba_lo));
            const __m256 p2 = _mm256_castpd_ps(_mm256_unpacklo_pd(rg_hi, ba_hi));
            const __m256 p3 = _mm256_castpd_ps(_mm256_unpackhi_pd(rg_hi, ba_hi));
            _mm256_storeu_ps(color + lane_offset_in(fb.width, h) * 4, _mm256_permute2f128_ps(p0, p1, 0x20));
            _mm256_storeu_ps(color + lane_offset_in(fb.width, h + 2) * 4, _mm256_permute2f128_ps(p2, p3, 0x20));
            _mm256_storeu_ps(color + lane_offset_in(fb.width, h + 4) * 4, _mm256_permute2f128_ps(p0, p1, 0x31));
            _mm256_storeu_ps(color + lane_offset_in(fb.width, h + 6) * 4, _mm256_permute2f128_ps(p2, p3, 0x31));
        }
#else
        for (int l = 0; l < kBlockLanes; l += 2) {
            const float pair[8] = {out.r[l], out.g[l], out.b[l], out.a[l],
                                   out.r[l + 1], out.g[l + 1], out.b[l + 1], out.a[l + 1]};
            std::memcpy(color + lane_offset_in(fb.width, l) * 4, pair, sizeof pair);
        }
#endif
        return;
    }
    for (std::uint32_t m = live; m; m &= m - 1) {
        const int l = __builtin_ctz(m);
        const std::size_t o = lane_offset_in(fb.width, l);
        if (st.depth_write) depth[o] = in.z[l];
        float* c = color + o * 4;
        c[0] = out.r[l]; c[1] = out.g[l]; c[2] = out.b[l]; c[3] = out.a[l];
    }
}

// Coverage mask of a 4x4 block for the edges not already known to be inside.
template <int NV>
inline std::uint32_t block_coverage(const TriangleSetup& t, const TriangleInTile<NV>& p, int bx, int by,
                                    unsigned partial_edges) {
    std::uint32_t mask = 0xFFFFu;
    for (int e = 0; e < 3; ++e) {
        if (!(partial_edges & (1u << e))) continue;
        mask &= nonnegative_mask(edge_at_pixel(t, e, bx, by), p.lane_offset[e]);
    }
    return mask;
}

// One triangle inside one tile.
template <class Program, class Observer>
void rasterize_triangle(const Program& program, const TileContext& ctx, const TriangleSetup& t,
                        const BinJob& job, int tile_x0, int tile_y0, int tile_x1, int tile_y1,
                        FrameStats& stats, Observer& obs) {
    constexpr int NV = Program::kVaryings;
    // The part of the tile the triangle's box overlaps (inclusive pixels).
    int x0 = std::max(tile_x0, t.minx), x1 = std::min(tile_x1, t.maxx);
    int y0 = std::max(tile_y0, t.miny), y1 = std::min(tile_y1, t.maxy);
    if (x0 > x1 || y0 > y1) return;

    TriangleInTile<NV> p;
    prepare_triangle<NV>(t, ctx, job, p);
    const int W = ctx.fb->width, H = ctx.fb->height;

    // Iterate over 16x16 blocks: reject, or learn which edges are fully in.
    for (int cy = y0 & ~(kCoarseBlockSize - 1); cy <= y1; cy += kCoarseBlockSize) {
        for (int cx = x0 & ~(kCoarseBlockSize - 1); cx <= x1; cx += kCoarseBlockSize) {
            unsigned partial = 0;
            bool out = false;
            for (int e = 0; e < 3 && !out; ++e) {
                EdgeClass c = classify_edge(edge_at_pixel(t, e, cx, cy), p.coarse_hi[e], p.coarse_lo[e]);
                if (c == kEdgeOut) out = true;
                else if (c == kEdgePartial) partial |= 1u << e;
            }
            if (out) continue;
            int bx_lo = std::max(cx, x0 & ~(kBlockSize - 1)), bx_hi = std::min(cx + kCoarseBlockSize - 1, x1);
            int by_lo = std::max(cy, y0 & ~(kBlockSize - 1)), by_hi = std::min(cy + kCoarseBlockSize - 1, y1);
            for (int by = by_lo; by <= by_hi; by += kBlockSize) {
                for (int bx = bx_lo; bx <= bx_hi; bx += kBlockSize) {
                    std::uint32_t mask;
                    if (partial == 0) {
                        // Iterate over fulls: every pixel centre is inside.
                        mask = 0xFFFFu;
                    } else {
                        // Iterate over partials: reject 4x4 blocks, then test pixels.
                        unsigned block_partial = 0;
                        bool block_out = false;
                        for (int e = 0; e < 3 && !block_out; ++e) {
                            if (!(partial & (1u << e))) continue;
                            EdgeClass c = classify_edge(edge_at_pixel(t, e, bx, by), p.fine_hi[e], p.fine_lo[e]);
                            if (c == kEdgeOut) block_out = true;
                            else if (c == kEdgePartial) block_partial |= 1u << e;
                        }
                        if (block_out) continue;
                        mask = block_partial ? block_coverage<NV>(t, p, bx, by, block_partial) : 0xFFFFu;
                    }
                    mask &= scissor_mask(bx, by, W, H);
                    if (!mask) continue;
                    ++stats.blocks_rasterized;
                    shade_block<Program, Observer>(program, ctx, t, p, bx, by, mask, stats, obs);
                }
            }
        }
    }
}

} // namespace detail

// Runs every bin of `tile` in submission order.
template <class Program, class Observer>
void rasterize_tile(const Program& program, const TileContext& ctx, int tile, FrameStats& stats,
                    Observer& obs) {
    const TileGrid& g = *ctx.grid;
    int tx0 = (tile % g.tiles_x) * g.tile_size, ty0 = (tile / g.tiles_x) * g.tile_size;
    int tx1 = std::min(tx0 + g.tile_size, g.width) - 1, ty1 = std::min(ty0 + g.tile_size, g.height) - 1;
    // The depth test reads the tile's depths first: ask for them all now, so
    // that the cache misses overlap instead of stalling block after block.
    const Framebuffer& fb = *ctx.fb;
    for (int y = ty0; y <= ty1; ++y) {
        const float* row = &fb.depth[std::size_t(y) * std::size_t(fb.width)];
        for (int x = tx0; x <= tx1; x += 16) __builtin_prefetch(row + x);
        __builtin_prefetch(row + tx1);
    }
    bool touched = false;
    for (int j = 0; j < ctx.job_count; ++j) {
        const BinJob& job = ctx.jobs[j];
        std::uint32_t begin = job.tile_offsets[tile], end = job.tile_offsets[tile + 1];
        touched |= begin != end;
        for (std::uint32_t i = begin; i < end; ++i)
            detail::rasterize_triangle<Program, Observer>(program, ctx, job.setups[job.items[i]], job,
                                                          tx0, ty0, tx1, ty1, stats, obs);
    }
    stats.tiles_touched += touched;
}

} // namespace prast

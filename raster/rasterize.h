// Tile rasterization: for one screen tile, walk its bins in submission order and
// for each triangle reject or accept 16x16 blocks, then 4x4 blocks, then pixels
// (exact integer edge tests), run the early depth test, interpolate varyings
// perspective-correctly and call the fragment shader once per 4x4 block.
// One thread owns a tile at a time, so colour and depth need no locking.
#pragma once

#include <algorithm>
#include <cstdint>
#include <cstring>

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

// Per-triangle data prepared once per tile: lane offsets of the edge functions
// and the varyings of the three vertices as (v0, v1 - v0, v2 - v0).
template <int NV>
struct TriangleInTile {
    std::int64_t lane_offset[3][kBlockLanes];
    float v0[NV > 0 ? NV : 1], d1[NV > 0 ? NV : 1], d2[NV > 0 ? NV : 1];
};

template <int NV>
void prepare_triangle(const TriangleSetup& t, const TileContext& ctx, const BinJob& job,
                      TriangleInTile<NV>& p) {
    for (int e = 0; e < 3; ++e)
        for (int l = 0; l < kBlockLanes; ++l)
            p.lane_offset[e][l] = std::int64_t(t.A[e]) * (lane_x(l) * kSubPixelScale) +
                                  std::int64_t(t.B[e]) * (lane_y(l) * kSubPixelScale);
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

// Depth test, interpolation, shading and write-back of one 4x4 block.
template <class Program, class Observer>
void shade_block(const Program& program, const TileContext& ctx, const TriangleSetup& t,
                 const TriangleInTile<Program::kVaryings>& p, int bx, int by, std::uint32_t mask,
                 FrameStats& stats, Observer& obs) {
    constexpr int NV = Program::kVaryings;
    Framebuffer& fb = *ctx.fb;
    const DrawState& st = *ctx.state;
    const bool full = bx + kBlockSize <= fb.width && by + kBlockSize <= fb.height;

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

    // Early depth test (the shader never writes depth).
    std::uint32_t pass = mask;
    if (st.depth_test) {
        std::uint32_t less = 0;
        if (full) {
            for (int l = 0; l < kBlockLanes; ++l) {
                float d = fb.depth[std::size_t(by + lane_y(l)) * fb.width + bx + lane_x(l)];
                less |= std::uint32_t(in.z[l] < d) << l;
            }
        } else {
            for (int l = 0; l < kBlockLanes; ++l)
                if (mask & (1u << l)) {
                    float d = fb.depth[std::size_t(by + lane_y(l)) * fb.width + bx + lane_x(l)];
                    less |= std::uint32_t(in.z[l] < d) << l;
                }
        }
        pass &= less;
    }
    stats.fragments_covered += popcount16(mask);
    stats.fragments_depth_killed += popcount16(mask & ~pass);
    if constexpr (Observer::enabled) obs.fragments(t.prim_id, bx, by, mask, pass, in.z);
    if (!pass) return;

    // Perspective-correct weights: screen barycentrics over w, renormalised.
    alignas(64) float w1[kBlockLanes], w2[kBlockLanes];
    for (int l = 0; l < kBlockLanes; ++l) {
        float q0 = b0[l] * t.inv_w[0], q1 = b1[l] * t.inv_w[1], q2 = b2[l] * t.inv_w[2];
        float s = 1.0f / (q0 + q1 + q2);
        w1[l] = q1 * s;
        w2[l] = q2 * s;
    }
    for (int k = 0; k < NV; ++k) {
        const float v0 = p.v0[k], d1 = p.d1[k], d2 = p.d2[k];
        for (int l = 0; l < kBlockLanes; ++l) in.var[k][l] = v0 + w1[l] * d1 + w2[l] * d2;
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
    for (int l = 0; l < kBlockLanes; ++l) {
        if (!(live & (1u << l))) continue;
        std::size_t idx = std::size_t(by + lane_y(l)) * fb.width + bx + lane_x(l);
        if (st.depth_write) fb.depth[idx] = in.z[l];
        float* c = &fb.color[idx * 4];
        if (st.blend == Blend::Add) {
            c[0] += out.r[l]; c[1] += out.g[l]; c[2] += out.b[l]; c[3] += out.a[l];
        } else {
            c[0] = out.r[l]; c[1] = out.g[l]; c[2] = out.b[l]; c[3] = out.a[l];
        }
    }
}

// Coverage mask of a 4x4 block for the edges not already known to be inside.
template <int NV>
inline std::uint32_t block_coverage(const TriangleSetup& t, const TriangleInTile<NV>& p, int bx, int by,
                                    unsigned partial_edges) {
    std::uint32_t mask = 0xFFFFu;
    for (int e = 0; e < 3; ++e) {
        if (!(partial_edges & (1u << e))) continue;
        std::int64_t e0 = edge_at_pixel(t, e, bx, by);
        std::uint32_t m = 0;
        for (int l = 0; l < kBlockLanes; ++l) m |= std::uint32_t(e0 + p.lane_offset[e][l] >= 0) << l;
        mask &= m;
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
                EdgeClass c = classify_block(t, e, cx, cy, kCoarseBlockSize);
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
                            EdgeClass c = classify_block(t, e, bx, by, kBlockSize);
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

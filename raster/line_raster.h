// Lines and points inside one tile (rules in line.h): the covered pixels of
// each primitive, gathered into 4x4 blocks; per block the depth of each
// pixel, the LESS test of every sample, the fragment program (derivatives
// zero) and the write-back, replacing or blending. Always in submission
// order (never through the visibility pass): a line's blocks are sparse,
// and a pixel's samples all take the same value.
#pragma once

#include <cstdint>
#include <cstring>

#include "raster/bin.h"
#include "raster/draw_state.h"
#include "raster/fragment.h"
#include "raster/line.h"
#include "raster/rasterize.h"
#include "raster/shade.h"

namespace prast {
namespace raster_detail {

// A primitive's varyings as (v0, v1 - v0).
template <int NV>
struct LineVaryings {
    float v0[NV > 0 ? NV : 1], d[NV > 0 ? NV : 1];
};

template <int NV>
inline void prepare_line_varyings(const LineSetup& l, const float* vertices, const BinJob& job, LineVaryings<NV>& p) {
    constexpr int stride = 4 + NV;
    const float* v[2];
    for (int i = 0; i < 2; ++i) {
        const std::uint32_t r = l.vtx[i];
        v[i] = (r & kClippedVertexBit) ? &job.clip_pool[std::size_t(r & ~kClippedVertexBit) * stride]
                                       : &vertices[std::size_t(r) * stride];
    }
    p.v0[0] = p.d[0] = 0.0f;
    for (int k = 0; k < NV; ++k) {
        p.v0[k] = v[0][4 + k];
        p.d[k] = v[1][4 + k] - v[0][4 + k];
    }
}

// One block of one primitive: `lanes` are its covered pixels there.
template <bool MS, bool kShade, class Program>
void line_block(const Program& program, const DrawState& st, bool depth_only, const LineSetup& l,
                const LineVaryings<Program::kVaryings>& pv, TileContext& c, int bx, int by, std::uint32_t lanes) {
    constexpr int NV = Program::kVaryings;
    FrameStats& stats = *c.stats;
    const TileTarget& tg = c.target;
    const int S = samples_of<MS>(c);

    // Depth and the perspective-correct weight of P1 at each covered pixel.
    alignas(64) float z[kBlockLanes] = {};
    alignas(64) float w1[kBlockLanes] = {};
    for (std::uint32_t m = lanes; m; m &= m - 1) {
        const int ln = __builtin_ctz(m);
        const float t = line_parameter(l, bx + lane_x(ln), by + lane_y(ln));
        const float zt = l.z0 + t * (l.z1 - l.z0);
        z[ln] = std::min(std::max(zt, 0.0f), 1.0f);
        const float q0 = (1.0f - t) * l.inv_w0, q1 = t * l.inv_w1;
        w1[ln] = t > 0.0f ? q1 / (q0 + q1) : 0.0f;
    }

    // Every sample of a covered pixel is covered, at the pixel's depth.
    const bool inside = block_inside(c, bx, by);
    const std::size_t o = tg.offset(bx, by);
    std::uint32_t pass[kMaxSamples];
    std::uint32_t any_pass = 0;
    for (int s = 0; s < S; ++s) {
        if (st.depth_test) {
            alignas(64) float d[kBlockLanes];
            load_block(tg.depth + o + s * tg.plane, tg.row, inside, lanes, d);
            pass[s] = lanes & less_mask(z, d);
        } else {
            pass[s] = lanes;
        }
        any_pass |= pass[s];
    }
    ++stats.blocks_rasterized;
    stats.fragments_covered += popcount16(lanes);
    stats.fragments_depth_killed += popcount16(lanes & ~any_pass);
    if (!any_pass) return;

    std::uint32_t live = any_pass;
    FragmentOut out;
    out.kill = 0;
    if constexpr (kShade) {
        if (!depth_only) {
            // Zero derivatives: each call gets at most one pixel per quad, and
            // that pixel's values fill its quad's four lanes.
            alignas(64) float var[NV > 0 ? NV : 1][kBlockLanes];
            for (std::uint32_t m = any_pass; m; m &= m - 1) {
                const int ln = __builtin_ctz(m);
                for (int k = 0; k < NV; ++k) var[k][ln] = pv.v0[k] + w1[ln] * pv.d[k];
            }
            std::uint32_t rest = any_pass;
            while (rest) {
                std::uint32_t group = 0;
                for (int q = 0; q < 4; ++q) {
                    const std::uint32_t quad = (rest >> (4 * q)) & 0xFu;
                    if (quad) group |= (quad & (~quad + 1u)) << (4 * q);  // its lowest pixel
                }
                rest &= ~group;
                const int first = __builtin_ctz(group);
                FragmentBlock<NV> in;
                for (int q = 0; q < 4; ++q) {
                    const std::uint32_t quad = (group >> (4 * q)) & 0xFu;
                    const int src = quad ? 4 * q + __builtin_ctz(quad) : first;
                    for (int j = 4 * q; j < 4 * q + 4; ++j) {
                        in.z[j] = z[src];
                        for (int k = 0; k < NV; ++k) in.var[k][j] = var[k][src];
                    }
                }
                if constexpr (NV == 0) in.var[0][0] = 0.0f;
                in.x = bx;
                in.y = by;
                in.mask = group;
                in.prim_id = l.prim_id;
                in.front_facing = true;
                in.centroid_mask = 0;
                FragmentOut g;
                g.kill = 0;
                program.fragment(in, g);
                for (std::uint32_t m = group; m; m &= m - 1) {
                    const int ln = __builtin_ctz(m);
                    out.r[ln] = g.r[ln];
                    out.g[ln] = g.g[ln];
                    out.b[ln] = g.b[ln];
                    out.a[ln] = g.a[ln];
                }
                out.kill |= g.kill & group;
                for (int q = 0; q < 4; ++q) stats.quads_shaded += ((group >> (4 * q)) & 0xFu) != 0;
            }
            live = any_pass & ~out.kill;
            stats.fragments_shaded += popcount16(any_pass);
            stats.fragments_shader_killed += popcount16(any_pass & out.kill);
        }
    }
    stats.fragments_written += popcount16(live);

    for (int s = 0; s < S; ++s) {
        const std::uint32_t m = pass[s] & live;
        if (!m) continue;
        if (st.depth_write) store_block(tg.depth + o + s * tg.plane, tg.row, m, z, inside);
        if constexpr (kShade) {
            if (depth_only) continue;  // as depth-only triangles: colour and winners untouched
            if (tg.winner) store_winner(tg.winner + tg.winner_offset(bx, by) + s * tg.wplane, tg.wrow, m, kNoWinner);
        }
    }
    if constexpr (kShade) {
        if (!depth_only && tg.color) write_planes(tg, o, S, pass, live, out, st.blend, inside);
    }
}

// Items [begin, end) of a line or point job in this tile, in order.
template <bool MS, bool kShade, class Program>
void rasterize_lines(const Program& program, const DrawState& st, bool depth_only, const float* vertices,
                     const BinJob& job, std::uint32_t begin, std::uint32_t end, TileContext& c) {
    struct Entry {
        int bx, by;
        std::uint32_t lanes;
    };
    // A primitive covers at most six pixels per column (row) of a block
    // column (row), visited in order, so the blocks being filled are the
    // last three: a tile's worth fits, and merging only saves calls (the
    // pixels are distinct, so a block processed in two parts is the same).
    constexpr int kEntries = 3 * (kMaxTileSize / kBlockSize) + 8;
    Entry entries[kEntries];
    for (std::uint32_t i = begin; i < end; ++i) {
        const LineSetup& l = job.lines[job.items[i]];
        LineVaryings<Program::kVaryings> pv;
        prepare_line_varyings<Program::kVaryings>(l, vertices, job, pv);
        int n = 0;
        auto flush = [&] {
            for (int e = 0; e < n; ++e)
                line_block<MS, kShade>(program, st, depth_only, l, pv, c, entries[e].bx, entries[e].by,
                                       entries[e].lanes);
            n = 0;
        };
        for_each_line_pixel(l, c.x0, c.y0, c.x1, c.y1, [&](int x, int y) {
            const int bx = x & ~(kBlockSize - 1), by = y & ~(kBlockSize - 1);
            const int px = x - bx, py = y - by;  // lane order of fragment.h
            const std::uint32_t bit = 1u << (4 * ((px >> 1) + 2 * (py >> 1)) + (px & 1) + 2 * (py & 1));
            for (int e = n - 1; e >= 0 && e >= n - 4; --e)
                if (entries[e].bx == bx && entries[e].by == by) {
                    entries[e].lanes |= bit;
                    return;
                }
            if (n == kEntries) flush();
            entries[n++] = {bx, by, bit};
        });
        flush();
    }
}

} // namespace raster_detail
} // namespace prast

// Shading a 4x4 block: interpolate a triangle's varyings perspective-correctly
// for the block's lanes, call the fragment program once for the block (once
// per pixel per triangle whatever the sample count), and write its output to
// the samples it owns, replacing or blending. Two callers:
//  - shade_in_order(): draws shaded in submission order (blending, alpha
//    MASK, depth test or write off): depth test, shade, write;
//  - shade_winner(): the visibility pass already wrote depth and chose each
//    sample's winner; this shades a winning triangle for the pixels it won
//    (with the whole block's helper lanes, so derivatives are unchanged).
// A program with fragment_batch() (fragment.h) gets sparse blocks several at
// a time instead: BlockBatch collects them (shade_in_order_batched() for
// draws that never discard, Draw::shade_winners() for winners) and
// flush_batch() shades them with one call and writes them back in order.
#pragma once

#include <cstdint>
#include <cstring>

#include "raster/bin.h"
#include "raster/draw_state.h"
#include "raster/fragment.h"
#include "raster/isa.h"
#include "raster/rasterize.h"
#include "raster/write_avx512.h"

namespace prast {
namespace raster_detail {

// A triangle's varyings as (v0, v1 - v0, v2 - v0), from the draw's vertices or
// the clip pool of the job that made them.
template <int NV>
struct TriangleVaryings {
    float v0[NV > 0 ? NV : 1], d1[NV > 0 ? NV : 1], d2[NV > 0 ? NV : 1];
};

template <int NV>
inline void prepare_varyings(const TriangleSetup& t, const float* vertices, const BinJob& job,
                             TriangleVaryings<NV>& p) {
    if constexpr (NV == 0) {
        p.v0[0] = p.d1[0] = p.d2[0] = 0.0f;  // never read; set so no compiler sees an uninitialised copy
        return;
    }
    constexpr int stride = 4 + NV;
    const float* v[3];
    for (int i = 0; i < 3; ++i) {
        std::uint32_t r = t.vtx[i];
        v[i] = (r & kClippedVertexBit) ? &job.clip_pool[std::size_t(r & ~kClippedVertexBit) * stride]
                                       : &vertices[std::size_t(r) * stride];
    }
    for (int k = 0; k < NV; ++k) {
        p.v0[k] = v[0][4 + k];
        p.d1[k] = v[1][4 + k] - v[0][4 + k];
        p.d2[k] = v[2][4 + k] - v[0][4 + k];
    }
}

// Asks the cache for a triangle's setup (first) and then, once that has
// arrived, its vertices' varyings: the triangles of a tile come in
// submission order from anywhere in the draw's arrays, and waiting for them
// is a good part of a frame of small triangles.
inline void prefetch_setup(const TriangleSetup& t) {
    const char* p = reinterpret_cast<const char*>(&t);
    for (std::size_t o = 0; o < sizeof t; o += 64) __builtin_prefetch(p + o);
    __builtin_prefetch(p + sizeof t - 1);
}
inline void prefetch_varyings(const TriangleSetup& t, const float* vertices, const BinJob& job, int stride) {
    for (int i = 0; i < 3; ++i) {
        const std::uint32_t r = t.vtx[i];
        const float* v = (r & kClippedVertexBit) ? &job.clip_pool[std::size_t(r & ~kClippedVertexBit) * stride]
                                                 : &vertices[std::size_t(r) * stride];
        __builtin_prefetch(v);
        __builtin_prefetch(v + stride - 1);
    }
}

// One lane's varyings and depth at screen barycentrics (b0, b1, b2): the
// float operations of the block loop below, for one lane.
template <int NV>
inline void interpolate_lane(const TriangleSetup& t, const TriangleVaryings<NV>& p, float b0, float b1, float b2,
                             int l, FragmentBlock<NV>& in) {
    in.z[l] = depth_from_barycentrics(t, b0, b1, b2);
    const float q0 = b0 * t.inv_w[0], q1 = b1 * t.inv_w[1], q2 = b2 * t.inv_w[2];
    const float s = 1.0f / (q0 + q1 + q2);
    const float w1 = q1 * s, w2 = q2 * s;
    for (int k = 0; k < NV; ++k) in.var[k][l] = p.v0[k] + w1 * p.d1[k] + w2 * p.d2[k];
}

// The live lanes (`lanes`) whose centre is outside the triangle move to the
// centroid of their covered samples: interpolate_lane() there, eight lanes
// at a time. Coverage: the block loop's per-sample masks (`block_cover`,
// BlockSamples::cover, which agree with these tests on live lanes), or where
// the caller has none the block loop's exact integer tests done here; then
// each lane's sums in sample order, as the per-lane reference takes them.
template <int NV>
void interpolate_centroids(const TriangleSetup& t, const TriangleVaryings<NV>& p, const SamplePattern& sp, int bx,
                           int by, std::uint32_t lanes, FragmentBlock<NV>& in, const std::uint32_t* block_cover) {
    alignas(32) std::int64_t offset[3][kBlockLanes];
    std::int64_t e0[3];
    std::uint32_t centre = 0xFFFFu;
    for (int e = 0; e < 3; ++e) {
        lane_offsets(t.A[e], t.B[e], offset[e]);
        e0[e] = edge_at_pixel(t, e, bx, by);
        centre &= nonnegative_mask(e0[e], offset[e]);
    }
    const std::uint32_t off_centre = lanes & ~centre;
    if (!off_centre) return;
    in.centroid_mask = off_centre;
    std::uint32_t own[kMaxSamples];
    const std::uint32_t* cover = block_cover;
    if (!cover) {
        for (int s = 0; s < sp.count; ++s) {
            std::uint32_t m = 0xFFFFu;
            for (int e = 0; e < 3; ++e)
                m &= nonnegative_mask(e0[e] + std::int64_t(t.A[e]) * sp.fixed_x(s) + std::int64_t(t.B[e]) * sp.fixed_y(s),
                                      offset[e]);
            own[s] = m;
        }
        cover = own;
    }
    typedef std::int32_t Int8 __attribute__((vector_size(32)));
    const Int8 bit = {1, 2, 4, 8, 16, 32, 64, 128};
    for (int h = 0; h < kBlockLanes; h += 8) {
        // centre_var: every lane's centre values, copied here (a memcpy of
        // the whole block is a rep movs, slow to start).
        const std::uint32_t here = (off_centre >> h) & 0xFFu;
        if (!here) {
            for (int k = 0; k < NV; ++k) std::memcpy(in.centre_var[k] + h, in.var[k] + h, 8 * sizeof(float));
            continue;
        }
        Lanes8 sum_x = {}, sum_y = {}, n = {};
        for (int s = 0; s < sp.count; ++s) {
            const Int8 inside = ((Int8{} + std::int32_t((cover[s] >> h) & 0xFFu)) & bit) != 0;
            sum_x = inside ? sum_x + sp.pixel_x(s) : sum_x;
            sum_y = inside ? sum_y + sp.pixel_y(s) : sum_y;
            n = inside ? n + 1.0f : n;  // small integers: exact, float(n) of the reference
        }
        // A live lane always has a covered sample; without one it stays at the centre.
        const Int8 move = (((Int8{} + std::int32_t(here)) & bit) != 0) & (n > 0.0f);
        n = n > 0.0f ? n : 1.0f;
        Int8 lx, ly;
        for (int i = 0; i < 8; ++i) {
            lx[i] = bx + lane_x(h + i) - t.ax;
            ly[i] = by + lane_y(h + i) - t.ay;
        }
        const Lanes8 dx = __builtin_convertvector(lx, Lanes8) + sum_x / n;
        const Lanes8 dy = __builtin_convertvector(ly, Lanes8) + sum_y / n;
        const Lanes8 c0 = t.bary[0][0] + t.bary[0][1] * dx + t.bary[0][2] * dy;
        const Lanes8 c1 = t.bary[1][0] + t.bary[1][1] * dx + t.bary[1][2] * dy;
        const Lanes8 c2 = t.bary[2][0] + t.bary[2][1] * dx + t.bary[2][2] * dy;
        // interpolate_lane(), depth_from_barycentrics() on eight lanes.
        Lanes8 z = c0 * t.z[0] + c1 * t.z[1] + c2 * t.z[2];
        z = z < 0.0f ? 0.0f : z;
        z = 1.0f < z ? 1.0f : z;
        Lanes8 old;
        load_lanes(old, in.z + h);
        store_lanes(in.z + h, move ? z : old);
        const Lanes8 q0 = c0 * t.inv_w[0], q1 = c1 * t.inv_w[1], q2 = c2 * t.inv_w[2];
        const Lanes8 r = 1.0f / (q0 + q1 + q2);
        const Lanes8 w1 = q1 * r, w2 = q2 * r;
        for (int k = 0; k < NV; ++k) {
            const Lanes8 v = p.v0[k] + w1 * p.d1[k] + w2 * p.d2[k];
            load_lanes(old, in.var[k] + h);
            store_lanes(in.centre_var[k] + h, old);
            store_lanes(in.var[k] + h, move ? v : old);
        }
    }
}

// Depth and varyings of the block's lanes at their pixel centres; with
// several samples, the live lanes (`lanes`) whose centre is outside the
// triangle move to the centroid of their covered samples.
// `centre`: the lanes' centre barycentrics and depths when the caller has
// them (one sample: test_depth's), else null. `inside`: every centre is
// known to be inside (BlockSamples::inside), so none moves. `cover`: the
// block loop's coverage of each sample (BlockSamples::cover), or null.
template <bool MS, int NV>
void interpolate_block(const TriangleSetup& t, const TriangleVaryings<NV>& p, const SamplePattern& sp, int bx,
                       int by, std::uint32_t lanes, const BlockSamples* centre, FragmentBlock<NV>& in,
                       bool inside = false, const std::uint32_t* cover = nullptr) {
    alignas(64) float cb0[kBlockLanes], cb1[kBlockLanes], cb2[kBlockLanes];
    const float *b0 = cb0, *b1 = cb1, *b2 = cb2;
    if (centre) {
        b0 = centre->b0;
        b1 = centre->b1;
        b2 = centre->b2;
        std::memcpy(in.z, centre->z[0], sizeof in.z);
    } else {
        block_barycentrics<false>(t, bx, by, 0.0f, 0.0f, cb0, cb1, cb2);
        block_depths(t, cb0, cb1, cb2, in.z);
    }

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
    in.centroid_mask = 0;
    if constexpr (MS) {
        if (!inside) interpolate_centroids(t, p, sp, bx, by, lanes, in, cover);
    }
}

// Colour of the lanes in `mask` (one sample plane, `row` pixels wide) from
// the program's output. `whole`: the block lies inside the plane
// (block_inside()), so a pair of pixels may be read, blended and written back
// instead of a (slow) masked store.
inline void write_color(float* color, std::size_t row, std::uint32_t mask, const FragmentOut& out, Blend blend,
                        bool whole) {
    if (blend == Blend::Add) {
        for (std::uint32_t m = mask; m; m &= m - 1) {
            const int l = __builtin_ctz(m);
            float* c = color + lane_offset_in(row, l) * 4;
            c[0] += out.r[l]; c[1] += out.g[l]; c[2] += out.b[l]; c[3] += out.a[l];
        }
        return;
    }
    if (blend == Blend::Alpha) {
        for (std::uint32_t m = mask; m; m &= m - 1) {
            const int l = __builtin_ctz(m);
            float* c = color + lane_offset_in(row, l) * 4;
            const float a = out.a[l], keep = 1.0f - a;
            c[0] = out.r[l] * a + c[0] * keep;
            c[1] = out.g[l] * a + c[1] * keep;
            c[2] = out.b[l] * a + c[2] * keep;
            c[3] = out.a[l] * a + c[3] * keep;
        }
        return;
    }
#if defined(__AVX2__)
    // Lanes 2j and 2j + 1 are neighbours in a row: each pair of RGBA pixels is
    // one 8-float store (masked to the pixels in `mask`).
    for (int h = 0; h < kBlockLanes; h += 8) {
        if (!((mask >> h) & 0xFFu)) continue;
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
        const __m256 pairs[4] = {_mm256_permute2f128_ps(p0, p1, 0x20), _mm256_permute2f128_ps(p2, p3, 0x20),
                                 _mm256_permute2f128_ps(p0, p1, 0x31), _mm256_permute2f128_ps(p2, p3, 0x31)};
        for (int j = 0; j < 4; ++j) {
            const int l = h + 2 * j;
            const std::uint32_t two = (mask >> l) & 3u;
            float* c = color + lane_offset_in(row, l) * 4;
            if (two == 3u) {
                _mm256_storeu_ps(c, pairs[j]);
            } else if (two) {
                const __m256i left = _mm256_setr_epi32(-1, -1, -1, -1, 0, 0, 0, 0);
                const __m256i right = _mm256_setr_epi32(0, 0, 0, 0, -1, -1, -1, -1);
                const __m256i pick = two == 1u ? left : right;
                if (whole) _mm256_storeu_ps(c, _mm256_blendv_ps(_mm256_loadu_ps(c), pairs[j], _mm256_castsi256_ps(pick)));
                else _mm256_maskstore_ps(c, pick, pairs[j]);
            }
        }
    }
#else
    (void)whole;
    if (mask == 0xFFFFu) {
        for (int l = 0; l < kBlockLanes; l += 2) {
            const float pair[8] = {out.r[l], out.g[l], out.b[l], out.a[l],
                                   out.r[l + 1], out.g[l + 1], out.b[l + 1], out.a[l + 1]};
            std::memcpy(color + lane_offset_in(row, l) * 4, pair, sizeof pair);
        }
        return;
    }
    for (std::uint32_t m = mask; m; m &= m - 1) {
        const int l = __builtin_ctz(m);
        float* c = color + lane_offset_in(row, l) * 4;
        c[0] = out.r[l]; c[1] = out.g[l]; c[2] = out.b[l]; c[3] = out.a[l];
    }
#endif
}

// write_color() into sample planes s < S of the block at offset o of the
// target's planes, of the lanes write[s] & live. Replacing, with AVX-512,
// one masked store a row and plane (write_avx512.h).
inline void write_planes(const TileTarget& tg, std::size_t o, int S, const std::uint32_t* write, std::uint32_t live,
                         const FragmentOut& out, Blend blend, bool inside) {
#if PRAST_CALLS_AVX512 || (defined(PRAST_SIMD16) && defined(__AVX512VL__))
    if (blend == Blend::Replace
#if PRAST_CALLS_AVX512
        && use_avx512()
#endif
    ) {
        std::uint32_t masks[kMaxSamples];
        for (int s = 0; s < S; ++s) masks[s] = write[s] & live;
#if PRAST_CALLS_AVX512
        write_planes_avx512(tg.color + o * 4, tg.row, tg.plane, masks, S, out);
#else
        write_planes_avx512_inline<0>(tg.color + o * 4, tg.row, tg.plane, masks, S, out);
#endif
        return;
    }
#endif
    for (int s = 0; s < S; ++s) {
        const std::uint32_t m = write[s] & live;
        if (m) write_color(tg.color + (o + s * tg.plane) * 4, tg.row, m, out, blend, inside);
    }
}

// A block's fragment inputs: its lanes interpolated, its place, mask and triangle.
template <bool MS, int NV>
inline void fill_block(const TriangleSetup& t, const TriangleVaryings<NV>& pv, const TileContext& c, int bx, int by,
                       std::uint32_t lanes, const BlockSamples* centre, FragmentBlock<NV>& in, bool inside = false,
                       const std::uint32_t* cover = nullptr) {
    interpolate_block<MS, NV>(t, pv, *c.samples, bx, by, lanes, centre, in, inside, cover);
    in.x = bx;
    in.y = by;
    in.mask = lanes;
    in.prim_id = t.prim_id;
    in.front_facing = t.front_facing;
}

inline void count_quads(FrameStats& stats, std::uint32_t lanes) {
    for (int q = 0; q < 4; ++q) stats.quads_shaded += ((lanes >> (4 * q)) & 0xFu) != 0;
}

// Depth test, shading and write-back of one covered block of a draw shaded
// in submission order.
template <bool MS, class Program, class Observer>
void shade_in_order(const Program& program, const DrawState& st, const TriangleSetup& t,
                    const TriangleVaryings<Program::kVaryings>& pv, TileContext& c, int bx, int by,
                    BlockSamples& bs, Observer& obs) {
    constexpr int NV = Program::kVaryings;
    FrameStats& stats = *c.stats;
    test_depth<MS>(t, c, bx, by, st.depth_test, Observer::enabled, bs);
    count_fragments(stats, bs);
    observe_fragments(obs, t, c, bx, by, bs);
    if (!bs.any_pass) return;

    FragmentBlock<NV> in;
    fill_block<MS, NV>(t, pv, c, bx, by, bs.any_pass, MS ? nullptr : &bs, in, bs.inside, bs.cover);
    FragmentOut out;
    out.kill = 0;
    program.fragment(in, out);
    const std::uint32_t live = bs.any_pass & ~out.kill;
    count_quads(stats, bs.any_pass);
    stats.fragments_shaded += popcount16(bs.any_pass);
    stats.fragments_shader_killed += popcount16(bs.any_pass & out.kill);
    stats.fragments_written += popcount16(live);
    if constexpr (Observer::enabled) obs.shaded(in, out, live);

    const TileTarget& tg = c.target;
    const std::size_t o = tg.offset(bx, by);
    const bool inside = block_inside(c, bx, by);
    for (int s = 0; s < samples_of<MS>(c); ++s) {
        const std::uint32_t m = bs.pass[s] & live;
        if (!m) continue;
        if (st.depth_write) store_block(tg.depth + o + s * tg.plane, tg.row, m, bs.z[s], inside);
        if (tg.winner) store_winner(tg.winner + tg.winner_offset(bx, by) + s * tg.wplane, tg.wrow, m, kNoWinner);
    }
    if (tg.color) write_planes(tg, o, samples_of<MS>(c), bs.pass, live, out, st.blend, inside);
}

// Shades the pixels `lanes` of a block for the triangle that won samples
// `won[s]` there in the visibility pass, and writes those samples' colour.
template <bool MS, class Program, class Observer>
void shade_winner(const Program& program, const float* vertices, const BinJob& job, const TriangleSetup& t,
                  TileContext& c, int bx, int by, std::uint32_t lanes, const std::uint32_t* won, Observer& obs) {
    constexpr int NV = Program::kVaryings;
    FrameStats& stats = *c.stats;
    TriangleVaryings<NV> pv;
    prepare_varyings<NV>(t, vertices, job, pv);
    FragmentBlock<NV> in;
    fill_block<MS, NV>(t, pv, c, bx, by, lanes, nullptr, in);
    FragmentOut out;
    out.kill = 0;
    program.fragment(in, out);
    // A kill here breaks DrawState::may_discard's contract: honoured as
    // "colour not written" (the depth was written in the visibility pass).
    const std::uint32_t live = lanes & ~out.kill;
    count_quads(stats, lanes);
    stats.fragments_shaded += popcount16(lanes);
    if constexpr (Observer::enabled) obs.shaded(in, out, live);

    const TileTarget& tg = c.target;
    const std::size_t o = tg.offset(bx, by);
    write_planes(tg, o, samples_of<MS>(c), won, live, out, Blend::Replace, block_inside(c, bx, by));
}

// Sparse blocks of one draw waiting for one fragment_batch() call, each with
// the samples it colours (write[i][s]).
template <int NV>
struct BlockBatch {
    FragmentBlock<NV> in[kMaxBatchBlocks];
    FragmentOut out[kMaxBatchBlocks];
    std::uint32_t write[kMaxBatchBlocks][kMaxSamples];
    int count = 0, lanes = 0;

    bool fits(std::uint32_t mask) const {
        return count < kMaxBatchBlocks && lanes + popcount16(mask) <= kBlockLanes;
    }
    bool holds_block(int bx, int by) const {
        for (int i = 0; i < count; ++i)
            if (in[i].x == bx && in[i].y == by) return true;
        return false;
    }
    // The next block: the caller fills in[] and write[].
    int add(std::uint32_t mask) {
        lanes += popcount16(mask);
        out[count].kill = 0;
        return count++;
    }
};

// The statistics and colour of one shaded block: samples write[s] of the
// lanes the shader kept. `in_order`: also count kills and writes (the
// visibility pass counted a winner's writes).
template <bool MS>
inline void write_block(TileContext& c, int bx, int by, std::uint32_t lanes, const FragmentOut& out,
                        const std::uint32_t* write, Blend blend, bool in_order) {
    FrameStats& stats = *c.stats;
    const std::uint32_t live = lanes & ~out.kill;
    count_quads(stats, lanes);
    stats.fragments_shaded += popcount16(lanes);
    if (in_order) {
        stats.fragments_shader_killed += popcount16(lanes & out.kill);
        stats.fragments_written += popcount16(live);
    }
    const TileTarget& tg = c.target;
    if (!tg.color) return;
    const std::size_t o = tg.offset(bx, by);
    write_planes(tg, o, samples_of<MS>(c), write, live, out, blend, block_inside(c, bx, by));
}

// Shades the batch with one call and writes its blocks back in the order
// they were added (a later triangle's colour lands last), then empties it.
template <bool MS, class Program>
[[gnu::noinline]] void flush_batch(const Program& program, BlockBatch<Program::kVaryings>& batch, TileContext& c, Blend blend,
                 bool in_order) {
    if (!batch.count) return;
    const FragmentBlock<Program::kVaryings>* in[kMaxBatchBlocks];
    FragmentOut* out[kMaxBatchBlocks];
    for (int i = 0; i < batch.count; ++i) {
        in[i] = &batch.in[i];
        out[i] = &batch.out[i];
    }
    program.fragment_batch(in, out, batch.count);
    for (int i = 0; i < batch.count; ++i)
        write_block<MS>(c, batch.in[i].x, batch.in[i].y, batch.in[i].mask, batch.out[i], batch.write[i], blend,
                        in_order);
    batch.count = 0;
    batch.lanes = 0;
}

// shade_in_order() for a draw that never discards (DrawState::may_discard
// false) and whose program takes batches: depth is tested and written at
// once, since no shader may take a fragment back; a sparse block joins the
// batch, a dense one is shaded alone (after the batch, if the batch holds its
// pixels, so that colours land in submission order).
template <bool MS, class Program>
[[gnu::always_inline]] inline void shade_in_order_batched(const Program& program, const DrawState& st, const TriangleSetup& t,
                            const TriangleVaryings<Program::kVaryings>& pv, TileContext& c, int bx, int by,
                            BlockSamples& bs, BlockBatch<Program::kVaryings>& batch) {
    constexpr int NV = Program::kVaryings;
    test_depth<MS>(t, c, bx, by, st.depth_test, false, bs);
    count_fragments(*c.stats, bs);
    if (!bs.any_pass) return;
    const TileTarget& tg = c.target;
    const std::size_t o = tg.offset(bx, by);
    const bool inside = block_inside(c, bx, by);
    for (int s = 0; s < samples_of<MS>(c); ++s) {
        if (!bs.pass[s]) continue;
        if (st.depth_write) store_block(tg.depth + o + s * tg.plane, tg.row, bs.pass[s], bs.z[s], inside);
        if (tg.winner) store_winner(tg.winner + tg.winner_offset(bx, by) + s * tg.wplane, tg.wrow, bs.pass[s], kNoWinner);
    }
    const BlockSamples* centre = MS ? nullptr : &bs;
    // A dense block fills up a batch it fits in (a triangle's half of a
    // block and its neighbour's), or is shaded alone.
    if (popcount16(bs.any_pass) > kBatchBlockLanes && !(batch.count && batch.fits(bs.any_pass))) {
        if (batch.holds_block(bx, by)) flush_batch<MS>(program, batch, c, st.blend, true);
        FragmentBlock<NV> in;
        fill_block<MS, NV>(t, pv, c, bx, by, bs.any_pass, centre, in, bs.inside, bs.cover);
        FragmentOut out;
        out.kill = 0;
        program.fragment(in, out);
        write_block<MS>(c, bx, by, bs.any_pass, out, bs.pass, st.blend, true);
        return;
    }
    if (!batch.fits(bs.any_pass)) flush_batch<MS>(program, batch, c, st.blend, true);
    const int i = batch.add(bs.any_pass);
    fill_block<MS, NV>(t, pv, c, bx, by, bs.any_pass, centre, batch.in[i], bs.inside, bs.cover);
    for (int s = 0; s < samples_of<MS>(c); ++s) batch.write[i][s] = bs.pass[s];
}

} // namespace raster_detail
} // namespace prast

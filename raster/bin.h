// Binning: every set-up triangle is listed in each screen tile its edges reach.
// A binning job owns a contiguous range of one draw's triangles and writes its
// own bins (CSR: per-tile offsets into one item array), so walking the jobs of
// a frame in order (draw by draw, job by job) gives each tile its triangles in
// submission order, whatever the thread count. bin_triangles() is the whole
// per-job stage: assemble, clip, cull, set up, bin.
#pragma once

#include <algorithm>
#include <cstdint>
#include <vector>

#include "raster/clip.h"
#include "raster/line.h"
#include "raster/observer.h"
#include "raster/samples.h"
#include "raster/setup.h"
#include "raster/stats.h"
#include "raster/vertex.h"

namespace prast {

struct TileGrid {
    int width = 0, height = 0;   // viewport
    int tile_size = kDefaultTileSize;
    int tiles_x = 0, tiles_y = 0;
    TileGrid() = default;
    TileGrid(int w, int h, int ts)
        : width(w), height(h), tile_size(ts), tiles_x((w + ts - 1) / ts), tiles_y((h + ts - 1) / ts) {}
    int count() const { return tiles_x * tiles_y; }
};

// BinJob::tile_cover's unit: 1/kCoverScale pixel.
constexpr std::uint64_t kCoverScale = 2 * std::uint64_t(kSubPixelScale) * std::uint64_t(kSubPixelScale);

struct BinJob {
    std::vector<TriangleSetup> setups;
    std::vector<LineSetup> lines;            // a job of a line or point draw: its items index these
    std::vector<float> clip_pool;            // vertices made by clipping, `stride` floats each
    std::vector<std::uint64_t> pairs;        // (tile << 32 | setup index), before sorting
    std::vector<std::uint32_t> tile_offsets; // tiles + 1
    std::vector<std::uint32_t> items;        // setup indices grouped by tile
    // Per tile, the area its triangles are estimated to cover there (the
    // tile pass's overdraw estimate, frame.h), in 1/131072 pixel: a triangle
    // inside one tile brings its area, one that spans several half its box's
    // part in each. Integers, so that the frame's sum over jobs is exact
    // whatever the jobs. Summed here, where the setups are still in cache.
    std::vector<std::uint64_t> tile_cover;
    std::vector<std::uint32_t> scratch_cursor;
    FrameStats stats;

    void reset(int tile_count) {
        tile_cover.assign(std::size_t(tile_count), 0);
        setups.clear();
        lines.clear();
        clip_pool.clear();
        pairs.clear();
        stats = FrameStats{};
    }
};

// Appends the tiles that triangle `index` of `job` touches to job.pairs
// (tiles whose every sample is outside one edge are skipped).
template <class OnBin>
inline void bin_triangle(BinJob& job, std::uint32_t index, const TileGrid& grid, const SampleExtent& samples,
                         OnBin&& on_bin) {
    const TriangleSetup& t = job.setups[index];
    int tx0 = t.minx / grid.tile_size, tx1 = t.maxx / grid.tile_size;
    int ty0 = t.miny / grid.tile_size, ty1 = t.maxy / grid.tile_size;
    if (tx0 == tx1 && ty0 == ty1) {
        const std::uint32_t tile = std::uint32_t(ty0 * grid.tiles_x + tx0);
        job.pairs.push_back((std::uint64_t(tile) << 32) | index);
        // area = twice-area / 131072 rounded to a float: times 131072 an integer.
        job.tile_cover[tile] += std::uint64_t(double(t.area) * double(kCoverScale));
        on_bin(tile);
        return;
    }
    const EdgeSpan span[3] = {edge_span(t, 0, grid.tile_size, samples), edge_span(t, 1, grid.tile_size, samples),
                              edge_span(t, 2, grid.tile_size, samples)};
    for (int ty = ty0; ty <= ty1; ++ty)
        for (int tx = tx0; tx <= tx1; ++tx) {
            int x = tx * grid.tile_size, y = ty * grid.tile_size;
            if (classify_edge(edge_at_pixel(t, 0, x, y), span[0]) == kEdgeOut ||
                classify_edge(edge_at_pixel(t, 1, x, y), span[1]) == kEdgeOut ||
                classify_edge(edge_at_pixel(t, 2, x, y), span[2]) == kEdgeOut)
                continue;
            std::uint32_t tile = std::uint32_t(ty * grid.tiles_x + tx);
            job.pairs.push_back((std::uint64_t(tile) << 32) | index);
            const int w = std::min(t.maxx, std::min(x + grid.tile_size, grid.width) - 1) - std::max(t.minx, x) + 1;
            const int h = std::min(t.maxy, std::min(y + grid.tile_size, grid.height) - 1) - std::max(t.miny, y) + 1;
            job.tile_cover[tile] += std::uint64_t(w) * std::uint64_t(h) * (kCoverScale / 2);
            on_bin(tile);
        }
}

// Groups job.pairs by tile into tile_offsets/items, keeping submission order
// inside each tile (a stable counting sort).
void sort_bins(BinJob& job, int tile_count);

// Assembles triangles [tri_begin, tri_end) of a draw from its post-vertex
// array (`stride` floats per vertex), drops invalid ones, culls, clips, sets
// up and bins them into `job`, counting each submitted triangle once.
template <class Observer>
void bin_triangles(BinJob& job, std::size_t tri_begin, std::size_t tri_end, const std::uint32_t* indices,
                   const float* vertices, const std::uint16_t* codes, const WindowVertex* window,
                   std::uint32_t vertex_count, int stride, const TileGrid& grid, const SampleExtent& samples,
                   bool cull_back, Observer& obs) {
    const GuardBand gb = GuardBand::for_viewport(grid.width, grid.height);
    float polygon[kMaxClippedVertices * (4 + kMaxVaryings)];
    FrameStats& st = job.stats;

    // Sets up one (piece of a) triangle and bins it. Counting is left to the
    // caller, so that a clipped triangle counts once however many pieces it has.
    // Unclipped triangles use the vertex pass's projections (`window`).
    auto emit = [&](const float* const clip[3], const std::uint32_t ref[3], std::uint32_t prim,
                    bool clipped) __attribute__((always_inline)) -> SetupResult {
        TriangleSetup t;
        SetupResult r;
        if (clipped) {
            r = setup_triangle(clip, ref, grid.width, grid.height, cull_back, t, samples);
        } else {
            const WindowVertex* const v[3] = {&window[ref[0]], &window[ref[1]], &window[ref[2]]};
            r = setup_triangle(v, ref, grid.width, grid.height, cull_back, t, samples);
        }
        if (r == SetupResult::CulledBack) {
            if constexpr (Observer::enabled) obs.triangle(prim, TriangleFate::CulledBack, clipped, nullptr);
            return r;
        }
        if (r == SetupResult::Degenerate) {
            if constexpr (Observer::enabled) obs.triangle(prim, TriangleFate::Degenerate, clipped, nullptr);
            return r;
        }
        t.prim_id = prim;
        std::uint32_t index = std::uint32_t(job.setups.size());
        job.setups.push_back(t);
        ++st.triangles_setup;
        if constexpr (Observer::enabled) obs.triangle(prim, TriangleFate::SetUp, clipped, &job.setups.back());
        bin_triangle(job, index, grid, samples, [&](std::uint32_t tile) {
            if constexpr (Observer::enabled) obs.binned(prim, int(tile));
            (void)tile;
        });
        return r;
    };
    auto count = [&](bool any_setup, bool any_back) {
        if (any_back) ++st.triangles_culled_back;
        else if (!any_setup) ++st.triangles_degenerate;
    };

    for (std::size_t tri = tri_begin; tri < tri_end; ++tri) {
        const std::uint32_t prim = std::uint32_t(tri);
        ++st.triangles_in;
        std::uint32_t ref[3] = {indices[3 * tri], indices[3 * tri + 1], indices[3 * tri + 2]};
        // Assemble; drop triangles with bad indices or non-finite positions
        // (codes: project_vertices() of the vertex pass).
        bool valid = ref[0] < vertex_count && ref[1] < vertex_count && ref[2] < vertex_count;
        const float* clip[3] = {nullptr, nullptr, nullptr};
        std::uint32_t oc0 = 0, oc1 = 0, oc2 = 0;
        if (valid) {
            for (int i = 0; i < 3; ++i) clip[i] = &vertices[std::size_t(ref[i]) * stride];
            oc0 = codes[ref[0]];
            oc1 = codes[ref[1]];
            oc2 = codes[ref[2]];
            valid = !((oc0 | oc1 | oc2) & kVertexNotFinite);
        }
        if (!valid) {
            ++st.triangles_invalid;
            if constexpr (Observer::enabled) obs.triangle(prim, TriangleFate::Invalid, false, nullptr);
            continue;
        }
        if (oc0 & oc1 & oc2 & kFrustumBits) {
            ++st.triangles_culled_frustum;
            if constexpr (Observer::enabled) obs.triangle(prim, TriangleFate::CulledFrustum, false, nullptr);
            continue;
        }
        std::uint32_t planes = (oc0 | oc1 | oc2) & kClipNeededBits;
        if (!planes) {
            SetupResult r = emit(clip, ref, prim, false);
            count(r == SetupResult::Ok, r == SetupResult::CulledBack);
            continue;
        }
        // Clip; the polygon's vertices go to this job's pool and the pieces are a fan.
        ++st.triangles_clipped;
        int n = clip_triangle(clip, stride, planes, gb, polygon);
        bool positive_w = n >= 3;
        for (int i = 0; i < n; ++i) positive_w &= polygon[i * stride + 3] > 0.0f;
        if (!positive_w) {
            ++st.triangles_culled_frustum;
            if constexpr (Observer::enabled) obs.triangle(prim, TriangleFate::CulledFrustum, true, nullptr);
            continue;
        }
        std::uint32_t base = std::uint32_t(job.clip_pool.size() / stride);
        job.clip_pool.insert(job.clip_pool.end(), polygon, polygon + n * stride);
        bool any_setup = false, any_back = false;
        for (int i = 1; i + 1 < n; ++i) {
            std::uint32_t pref[3] = {(base | kClippedVertexBit), ((base + i) | kClippedVertexBit),
                                     ((base + i + 1) | kClippedVertexBit)};
            // Pool pointers are taken after the insert, so they stay valid.
            const float* pclip[3] = {&job.clip_pool[std::size_t(base) * stride],
                                     &job.clip_pool[std::size_t(base + i) * stride],
                                     &job.clip_pool[std::size_t(base + i + 1) * stride]};
            SetupResult r = emit(pclip, pref, prim, true);
            any_setup |= r == SetupResult::Ok;
            any_back |= r == SetupResult::CulledBack;
        }
        count(any_setup, any_back);
    }
}

// Appends the tiles that line or point `index` of `job` may cover to
// job.pairs: tile columns (x-major) or rows along the segment, and in each
// the tiles of the minor axis within a pixel of it.
inline void bin_line(BinJob& job, std::uint32_t index, const TileGrid& grid) {
    const LineSetup& l = job.lines[index];
    const int T = grid.tile_size;
    auto push = [&](int tx, int ty) {
        job.pairs.push_back((std::uint64_t(std::uint32_t(ty * grid.tiles_x + tx)) << 32) | index);
    };
    if (l.point) {
        push(l.minx / T, l.miny / T);
        return;
    }
    const int major_min = l.x_major ? l.minx : l.miny, major_max = l.x_major ? l.maxx : l.maxy;
    const int minor_min = l.x_major ? l.miny : l.minx, minor_max = l.x_major ? l.maxy : l.maxx;
    for (int t = major_min / T; t <= major_max / T; ++t) {
        const int p0 = std::max(t * T, major_min), p1 = std::min(t * T + T - 1, major_max);
        int lo, hi;
        if (!raster_detail::line_minor_range(l, p0, p1, lo, hi)) continue;
        lo = std::max(lo, minor_min);
        hi = std::min(hi, minor_max);
        for (int u = lo / T; lo <= hi && u <= hi / T; ++u) {
            if (l.x_major) push(t, u);
            else push(u, t);
        }
    }
}

// The stage of bin_triangles() for a draw of lines (`points` false: index
// pairs) or points: assemble, drop invalid ones, clip (lines; points outside
// the near or far plane are dropped), set up and bin primitives
// [begin, end). Observers are not told of lines and points (they speak of
// triangles); they see the draw's vertices.
inline void bin_lines(BinJob& job, std::size_t begin, std::size_t end, const std::uint32_t* indices,
                      const float* vertices, const std::uint16_t* codes, const WindowVertex* window,
                      std::uint32_t vertex_count, int stride, const TileGrid& grid, bool points) {
    const GuardBand gb = GuardBand::for_viewport(grid.width, grid.height);
    const int per = points ? 1 : 2;
    float seg[2 * (4 + kMaxVaryings)];
    for (std::size_t p = begin; p < end; ++p) {
        std::uint32_t ref[2] = {indices[per * p], indices[per * p + per - 1]};
        if (ref[0] >= vertex_count || ref[1] >= vertex_count ||
            ((codes[ref[0]] | codes[ref[1]]) & kVertexNotFinite))
            continue;
        const std::uint32_t oc0 = codes[ref[0]], oc1 = codes[ref[1]];
        LineSetup l;
        bool ok;
        if (points) {
            ok = !(oc0 & (kOutNear | kOutFar)) && setup_point(window[ref[0]], ref[0], grid.width, grid.height, l);
        } else if (oc0 & oc1 & kFrustumBits) {
            ok = false;
        } else if (const std::uint32_t planes = (oc0 | oc1) & kClipNeededBits) {
            ok = clip_line(&vertices[std::size_t(ref[0]) * stride], &vertices[std::size_t(ref[1]) * stride], stride,
                           planes, gb, seg);
            if (ok) {
                const std::uint32_t base = std::uint32_t(job.clip_pool.size() / std::size_t(stride));
                job.clip_pool.insert(job.clip_pool.end(), seg, seg + 2 * stride);
                const std::uint32_t pref[2] = {base | kClippedVertexBit, (base + 1) | kClippedVertexBit};
                ok = setup_line(window_vertex(seg, grid.width, grid.height),
                                window_vertex(seg + stride, grid.width, grid.height), pref, grid.width, grid.height, l);
            }
        } else {
            ok = setup_line(window[ref[0]], window[ref[1]], ref, grid.width, grid.height, l);
        }
        if (!ok) continue;
        l.prim_id = std::uint32_t(p);
        const std::uint32_t index = std::uint32_t(job.lines.size());
        job.lines.push_back(l);
        bin_line(job, index, grid);
    }
}

} // namespace prast

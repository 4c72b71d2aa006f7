// The draw call: vertex stage, clip/cull/setup/bin stage, tile stage, each a
// parallel pass over the renderer's thread pool. A Program supplies
//
//   static constexpr int kVaryings;                        // floats per vertex after xyzw
//   void vertex(std::uint32_t index, float clip[4], float* varyings) const;
//   void fragment(const FragmentBlock<kVaryings>&, FragmentOut&) const;
//
// Both are called through templates, never virtually. An Observer (observer.h)
// sees each stage; the default NullObserver compiles to nothing.
#pragma once

#include <chrono>
#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <vector>

#include "raster/bin.h"
#include "raster/clip.h"
#include "raster/draw_state.h"
#include "raster/framebuffer.h"
#include "raster/observer.h"
#include "raster/rasterize.h"
#include "raster/setup.h"
#include "raster/stats.h"
#include "raster/thread_pool.h"

namespace prast {

struct RendererOptions {
    int threads = 0;                      // 0 = all hardware threads
    int tile_size = kDefaultTileSize;     // power of two in [16, 256]
};

class Renderer {
public:
    explicit Renderer(const RendererOptions& options = {});

    int threads() const { return pool_.size(); }
    int tile_size() const { return tile_size_; }
    ThreadPool& pool() { return pool_; }

    // Clears colour and depth with the pool's threads (rows in chunks).
    void clear(Framebuffer& fb, float r, float g, float b, float a, float z = 1.0f);

    // Counters accumulate over draws until the next begin_frame().
    void begin_frame() { stats_ = FrameStats{}; tile_entries_.clear(); }
    const FrameStats& stats() const { return stats_; }
    // Bin entries per tile over this frame's draws (row-major tiles of the
    // last framebuffer size): the `tiles` debug view and the stepper show it.
    const std::vector<std::uint32_t>& tile_entries() const { return tile_entries_; }

    // Draws an indexed triangle list (index_count / 3 triangles). Indices out of
    // range and non-finite positions drop their triangle (counted as invalid).
    template <class Program, class Observer = NullObserver>
    void draw(Framebuffer& fb, const Program& program, std::uint32_t vertex_count,
              const std::uint32_t* indices, std::size_t index_count, const DrawState& state,
              Observer& observer);

    template <class Program>
    void draw(Framebuffer& fb, const Program& program, std::uint32_t vertex_count,
              const std::uint32_t* indices, std::size_t index_count, const DrawState& state = {}) {
        NullObserver none;
        draw(fb, program, vertex_count, indices, index_count, state, none);
    }

private:
    using Clock = std::chrono::steady_clock;
    static double ms_since(Clock::time_point t0) {
        return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
    }

    template <class Observer>
    void setup_and_bin(BinJob& job, std::size_t tri_begin, std::size_t tri_end, const std::uint32_t* indices,
                       std::uint32_t vertex_count, int stride, const TileGrid& grid,
                       const DrawState& state, Observer& obs);

    ThreadPool pool_;
    int tile_size_;
    std::vector<float> vertices_;          // post-vertex-shader, reused across draws
    std::vector<BinJob> jobs_;
    std::vector<FrameStats> worker_stats_;
    std::vector<std::uint32_t> tile_entries_;
    FrameStats stats_;
};

template <class Observer>
void Renderer::setup_and_bin(BinJob& job, std::size_t tri_begin, std::size_t tri_end,
                             const std::uint32_t* indices, std::uint32_t vertex_count, int stride,
                             const TileGrid& grid, const DrawState& state, Observer& obs) {
    const GuardBand gb = GuardBand::for_viewport(grid.width, grid.height);
    const bool cull_back = state.cull == CullMode::Back;
    float polygon[kMaxClippedVertices * (4 + kMaxVaryings)];
    FrameStats& st = job.stats;

    // Sets up one (piece of a) triangle and bins it. Counting is left to the
    // caller, so that a clipped triangle counts once however many pieces it has.
    auto emit = [&](const float* const clip[3], const std::uint32_t ref[3], std::uint32_t prim,
                    bool clipped) -> SetupResult {
        TriangleSetup t;
        SetupResult r = setup_triangle(clip, ref, grid.width, grid.height, cull_back, t);
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
        bin_triangle(job, index, grid, [&](std::uint32_t tile) {
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
        // Assemble; drop triangles with bad indices or non-finite positions.
        bool valid = ref[0] < vertex_count && ref[1] < vertex_count && ref[2] < vertex_count;
        const float* clip[3] = {nullptr, nullptr, nullptr};
        if (valid) {
            for (int i = 0; i < 3; ++i) {
                clip[i] = &vertices_[std::size_t(ref[i]) * stride];
                for (int c = 0; c < 4; ++c) valid &= std::isfinite(clip[i][c]);
            }
        }
        if (!valid) {
            ++st.triangles_invalid;
            if constexpr (Observer::enabled) obs.triangle(prim, TriangleFate::Invalid, false, nullptr);
            continue;
        }
        std::uint32_t oc0 = outcode(clip[0], gb), oc1 = outcode(clip[1], gb), oc2 = outcode(clip[2], gb);
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

template <class Program, class Observer>
void Renderer::draw(Framebuffer& fb, const Program& program, std::uint32_t vertex_count,
                    const std::uint32_t* indices, std::size_t index_count, const DrawState& state,
                    Observer& obs) {
    constexpr int NV = Program::kVaryings;
    static_assert(NV >= 0 && NV <= kMaxVaryings, "too many varyings");
    constexpr int stride = 4 + NV;
    if (fb.width <= 0 || fb.height <= 0 || fb.width > kMaxViewportSize || fb.height > kMaxViewportSize)
        throw std::invalid_argument("framebuffer size out of range");
    const std::size_t tri_count = index_count / 3;
    ++stats_.draws;
    if (tri_count == 0) return;
    const int workers = pool_.size();
    worker_stats_.assign(std::size_t(workers), FrameStats{});

    // Vertex stage: chunks of vertices.
    auto t0 = Clock::now();
    vertices_.resize(std::size_t(vertex_count) * stride);
    constexpr std::uint32_t kVertexChunk = 4096;
    const int vchunks = int((std::uint64_t(vertex_count) + kVertexChunk - 1) / kVertexChunk);
    pool_.run(vchunks, [&](int chunk, int) {
        std::uint32_t begin = std::uint32_t(chunk) * kVertexChunk;
        std::uint32_t end = std::min<std::uint32_t>(vertex_count, begin + kVertexChunk);
        for (std::uint32_t v = begin; v < end; ++v) {
            float* out = &vertices_[std::size_t(v) * stride];
            program.vertex(v, out, out + 4);
            if constexpr (Observer::enabled) obs.vertex(v, out, out + 4, NV);
        }
    });
    stats_.vertices += vertex_count;
    stats_.ms_vertex += ms_since(t0);

    // Clip, cull, set up and bin: chunks of triangles, one bin set per chunk.
    t0 = Clock::now();
    const TileGrid grid(fb.width, fb.height, tile_size_);
    std::size_t per_job = std::max<std::size_t>(kTrianglesPerJob, (tri_count + kMaxJobs - 1) / kMaxJobs);
    const int job_count = int((tri_count + per_job - 1) / per_job);
    if (int(jobs_.size()) < job_count) jobs_.resize(std::size_t(job_count));
    pool_.run(job_count, [&](int j, int) {
        BinJob& job = jobs_[std::size_t(j)];
        job.reset();
        std::size_t begin = std::size_t(j) * per_job, end = std::min(tri_count, begin + per_job);
        job.setups.reserve(end - begin);
        setup_and_bin(job, begin, end, indices, vertex_count, stride, grid, state, obs);
        sort_bins(job, grid.count());
    });
    for (int j = 0; j < job_count; ++j) stats_.add_counters(jobs_[std::size_t(j)].stats);
    stats_.ms_setup_bin += ms_since(t0);

    // Tiles: each tile is owned by one thread, its bins run in submission order.
    t0 = Clock::now();
    TileContext ctx{&fb, &grid, &state, vertices_.data(), jobs_.data(), job_count, stride};
    if (tile_entries_.size() != std::size_t(grid.count())) tile_entries_.assign(std::size_t(grid.count()), 0);
    pool_.run(grid.count(), [&](int tile, int worker) {
        std::uint32_t entries = 0;
        for (int j = 0; j < job_count; ++j)
            entries += jobs_[std::size_t(j)].tile_offsets[tile + 1] - jobs_[std::size_t(j)].tile_offsets[tile];
        tile_entries_[std::size_t(tile)] += entries;
        if (entries == 0) return;
        rasterize_tile<Program, Observer>(program, ctx, tile, worker_stats_[std::size_t(worker)], obs);
    });
    for (const FrameStats& ws : worker_stats_) stats_.add_counters(ws);
    stats_.ms_raster += ms_since(t0);
}

} // namespace prast

// A frame: every draw submitted between Renderer::begin() and end() is
// vertex-shaded, clipped, set up and binned (in parallel, across draws), then
// ONE tile pass runs each tile's bins over all draws in submission order:
//
//   clear (or load) -> per draw, per binned triangle:
//       visibility pass (depth only; each sample remembers its winner), or
//       shading in order (blending, alpha MASK, depth test/write off), or
//       depth only (no fragment program)
//   -> shade the winners (once per pixel per triangle) -> resolve the
//   samples -> the frame's tile hook (e.g. tone map to 8 bits).
//
// Draws differ in program type: each is recorded as a DrawRecord whose
// virtual entries are instantiated from the Program and Observer templates,
// called once per (triangle, tile), per (winner, block), per run of a job's
// triangles in a tile or per batch of winners' blocks; the per-lane work
// inside stays inlined.
#pragma once

#include <cstddef>
#include <cstdint>
#include <type_traits>
#include <utility>
#include <vector>

#include "raster/bin.h"
#include "raster/draw_state.h"
#include "raster/fragment.h"
#include "raster/line_raster.h"
#include "raster/observer.h"
#include "raster/rasterize.h"
#include "raster/shade.h"
#include "raster/vertex.h"

namespace prast {

struct FrameOptions {
    int samples = 1;        // per pixel: 1, 2, 4 or 8 (docs/pipeline.md "Anti-aliasing")
    bool clear = true;      // clear colour and depth in the tile pass; false: draw over the target
    float clear_color[4] = {0.0f, 0.0f, 0.0f, 1.0f};
    float clear_depth = 1.0f;
    // Only the tile hook's view of each tile is wanted, not the framebuffer
    // (render writing a PNG): with clear, every tile then lives in its
    // worker's tile-local storage, which stays in cache, and the framebuffer
    // is neither written nor read (it keeps what it held). The hook sees the
    // same colours either way.
    bool transient = false;
    // Optional: a colour per pixel to clear to instead of clear_color (a
    // background image): clear_fill(clear_user, x0, y0, width, height, rgba,
    // row) writes pixel (x0 + i, y0 + j)'s RGBA at rgba[j * row + 4 i]; every
    // sample of a pixel clears to it, so uncovered samples resolve to it.
    using ClearFill = void (*)(const void* user, int x0, int y0, int width, int height, float* rgba,
                               std::size_t row);
    ClearFill clear_fill = nullptr;
    const void* clear_user = nullptr;
    // Shade each sample's winner once (the visibility pass): in every tile
    // (Always), never (every draw shaded in submission order), or in the tiles whose triangles cover more than
    // kOverdrawForVisibility times their area (Auto: elsewhere the pass costs
    // more than the shading it saves). The bytes are the same in every mode.
    enum class Visibility : std::uint8_t { Auto, Always, Never };
    Visibility visibility = Visibility::Auto;
};

// Auto visibility: the estimated overdraw (covered area over the tile's
// area) above which a tile takes the visibility pass. Measured: docs/pipeline.md, "A frame".
constexpr float kOverdrawForVisibility = 1.5f;

// A finished tile's linear colour, for a frame's tile hook: pixel (x0 + i,
// y0 + j) is rgba[j * row + 4 i .. + 3]. With several samples, the resolved
// (averaged) colour.
struct TileView {
    int x0 = 0, y0 = 0, width = 0, height = 0;
    const float* rgba = nullptr;
    std::size_t row = 0;  // floats
    // Every pixel holds rgba[0..3]: cleared and reached by no draw (a hook
    // may convert one pixel and fill the tile with it).
    bool uniform = false;
};

// A program with a fragment() is shaded; one without is a depth-only program
// (shadow maps): vertex() and kVaryings only.
template <class P, class = void>
struct has_fragment : std::false_type {};
template <class P>
struct has_fragment<P, std::void_t<decltype(std::declval<const P&>().fragment(
                           std::declval<const FragmentBlock<P::kVaryings>&>(), std::declval<FragmentOut&>()))>>
    : std::true_type {};

// A program with fragment_batch() (fragment.h) takes sparse blocks in batches.
template <class P, class = void>
struct has_fragment_batch : std::false_type {};
template <class P>
struct has_fragment_batch<P, std::void_t<decltype(std::declval<const P&>().fragment_batch(
                                 std::declval<const FragmentBlock<P::kVaryings>* const*>(),
                                 std::declval<FragmentOut* const*>(), 0))>> : std::true_type {};

namespace raster_detail {

// A winner's block waiting to be shaded in a batch.
struct WinnerBlock {
    const TriangleSetup* tri;
    const BinJob* job;
    int bx, by;
    std::uint32_t lanes;
    std::uint32_t won[kMaxSamples];
};

enum class DrawMode : std::uint8_t {
    Visible,    // visibility pass, winners shaded once
    InOrder,    // depth test, shade, write, fragment by fragment
    DepthOnly,  // depth test and write, colour untouched
};

class DrawRecord {
public:
    virtual ~DrawRecord() = default;
    virtual void shade_vertices(std::uint32_t begin, std::uint32_t end) = 0;
    virtual void bin(BinJob& job, std::size_t tri_begin, std::size_t tri_end, const TileGrid& grid,
                     const SampleExtent& samples) = 0;
    // Visible and DepthOnly draws: depth test/write, and winner `winner`
    // (kNoWinner for depth only).
    virtual void rasterize_visible(const TriangleSetup& t, TileContext& c, std::uint32_t winner) = 0;
    virtual void rasterize_in_order(const TriangleSetup& t, const BinJob& job, TileContext& c) = 0;
    // Triangles items[begin, end) of a job in order, sparse blocks batched
    // (draws with `batches`).
    virtual void rasterize_in_order_batched(const BinJob& job, std::uint32_t begin, std::uint32_t end,
                                            TileContext& c) = 0;
    virtual void shade_winner(const TriangleSetup& t, const BinJob& job, TileContext& c, int bx, int by,
                              std::uint32_t lanes, const std::uint32_t* won) = 0;
    // Sparse winner blocks of this draw, one batch (count <= kMaxBatchBlocks,
    // kBlockLanes lanes together; draws with `batches`).
    virtual void shade_winners(const WinnerBlock* blocks, int count, TileContext& c) = 0;
    // Lines and points (state.topology): items [begin, end) of a job, in order.
    virtual void rasterize_lines(const BinJob& job, std::uint32_t begin, std::uint32_t end, TileContext& c) = 0;

    DrawState state;
    DrawMode mode = DrawMode::InOrder;
    bool reads_color = false;   // blends with the target: winners must be shaded first
    bool observed = false;      // its observer is enabled
    bool batches = false;       // sparse blocks shaded in batches: fragment_batch(), not observed, never discards
    int stride = 4;
    std::uint32_t vertex_count = 0;
    const std::uint32_t* indices = nullptr;
    std::size_t tri_count = 0;  // primitives: triangles, lines or points (state.topology)
    std::vector<float>* vertices = nullptr;  // post-vertex-shader, stride floats each
    std::vector<std::uint16_t>* outcodes = nullptr;  // project_vertices() of each vertex
    std::vector<WindowVertex>* window = nullptr;     // ... and its window position
    int first_job = 0, job_count = 0;
};

template <class Program, class Observer>
class Draw final : public DrawRecord {
public:
    Draw(const Program& p, Observer& o) : program_(p), obs_(&o) {}

    void shade_vertices(std::uint32_t begin, std::uint32_t end) override {
        prast::shade_vertices(program_, begin, end, vertices->data(), *obs_);
    }
    void bin(BinJob& job, std::size_t tri_begin, std::size_t tri_end, const TileGrid& grid,
             const SampleExtent& samples) override {
        if (state.topology != Topology::Triangles) {
            bin_lines(job, tri_begin, tri_end, indices, vertices->data(), outcodes->data(), window->data(),
                      vertex_count, stride, grid, state.topology == Topology::Points);
            return;
        }
        bin_triangles(job, tri_begin, tri_end, indices, vertices->data(), outcodes->data(), window->data(),
                      vertex_count, stride, grid, samples,
                      state.cull == CullMode::Back, *obs_);
    }
    void rasterize_lines(const BinJob& job, std::uint32_t begin, std::uint32_t end, TileContext& c) override {
        constexpr bool shade = has_fragment<Program>::value;
        const bool depth_only = mode == DrawMode::DepthOnly;
        if (c.sample_count() == 1)
            raster_detail::rasterize_lines<false, shade>(program_, state, depth_only, vertices->data(), job, begin, end, c);
        else
            raster_detail::rasterize_lines<true, shade>(program_, state, depth_only, vertices->data(), job, begin, end, c);
    }
    // Each entry dispatches once on the sample count: one sample is compiled
    // on its own, with the loops over samples gone.
    void rasterize_visible(const TriangleSetup& t, TileContext& c, std::uint32_t winner) override {
        if (c.sample_count() == 1) rasterize_depth<false>(t, c, state.depth_test, state.depth_write, winner, *obs_);
        else rasterize_depth<true>(t, c, state.depth_test, state.depth_write, winner, *obs_);
    }
    void rasterize_in_order(const TriangleSetup& t, const BinJob& job, TileContext& c) override {
        if (c.sample_count() == 1) in_order<false>(t, job, c);
        else in_order<true>(t, job, c);
    }
    void rasterize_in_order_batched(const BinJob& job, std::uint32_t begin, std::uint32_t end,
                                    TileContext& c) override {
        if (c.sample_count() == 1) in_order_batched<false>(job, begin, end, c);
        else in_order_batched<true>(job, begin, end, c);
    }
    void shade_winners(const WinnerBlock* blocks, int count, TileContext& c) override {
        if (c.sample_count() == 1) winners_batched<false>(blocks, count, c);
        else winners_batched<true>(blocks, count, c);
    }
    void shade_winner(const TriangleSetup& t, const BinJob& job, TileContext& c, int bx, int by,
                      std::uint32_t lanes, const std::uint32_t* won) override {
        if constexpr (has_fragment<Program>::value) {
            if (c.sample_count() == 1)
                raster_detail::shade_winner<false>(program_, vertices->data(), job, t, c, bx, by, lanes, won, *obs_);
            else
                raster_detail::shade_winner<true>(program_, vertices->data(), job, t, c, bx, by, lanes, won, *obs_);
        } else {
            (void)t; (void)job; (void)c; (void)bx; (void)by; (void)lanes; (void)won;
        }
    }

private:
    template <bool MS>
    void in_order(const TriangleSetup& t, const BinJob& job, TileContext& c) {
        if constexpr (has_fragment<Program>::value) {
            TriangleVaryings<Program::kVaryings> pv;
            prepare_varyings<Program::kVaryings>(t, vertices->data(), job, pv);
            for_each_block<MS>(t, c, *c.stats, [&](int bx, int by, BlockSamples& bs) {
                shade_in_order<MS>(program_, state, t, pv, c, bx, by, bs, *obs_);
            });
        } else {
            (void)t; (void)job; (void)c;
        }
    }

    template <bool MS>
    void in_order_batched(const BinJob& job, std::uint32_t begin, std::uint32_t end, TileContext& c) {
        if constexpr (has_fragment_batch<Program>::value) {
            BlockBatch<Program::kVaryings> batch;
            for (std::uint32_t i = begin; i < end; ++i) {
                if (i + 2 < end) prefetch_setup(job.setups[job.items[i + 2]]);
                if (i + 1 < end) prefetch_varyings(job.setups[job.items[i + 1]], vertices->data(), job, stride);
                const TriangleSetup& t = job.setups[job.items[i]];
                TriangleVaryings<Program::kVaryings> pv;
                prepare_varyings<Program::kVaryings>(t, vertices->data(), job, pv);
                // Inlined at both of for_each_block's calls: most small
                // triangles take its one-block call, which GCC otherwise
                // left as a call of the lambda and of its depth test.
                for_each_block<MS>(t, c, *c.stats, [&](int bx, int by, BlockSamples& bs) __attribute__((always_inline)) {
                    shade_in_order_batched<MS>(program_, state, t, pv, c, bx, by, bs, batch);
                });
            }
            flush_batch<MS>(program_, batch, c, state.blend, true);
        } else {
            (void)job; (void)begin; (void)end; (void)c;
        }
    }

    template <bool MS>
    void winners_batched(const WinnerBlock* blocks, int count, TileContext& c) {
        if constexpr (has_fragment_batch<Program>::value) {
            BlockBatch<Program::kVaryings> batch;
            for (int i = 0; i < count; ++i) {
                if (i + 1 < count) prefetch_varyings(*blocks[i + 1].tri, vertices->data(), *blocks[i + 1].job, stride);
                const WinnerBlock& w = blocks[i];
                TriangleVaryings<Program::kVaryings> pv;
                prepare_varyings<Program::kVaryings>(*w.tri, vertices->data(), *w.job, pv);
                const int k = batch.add(w.lanes);
                fill_block<MS, Program::kVaryings>(*w.tri, pv, c, w.bx, w.by, w.lanes, nullptr, batch.in[k]);
                for (int s = 0; s < samples_of<MS>(c); ++s) batch.write[k][s] = w.won[s];
            }
            flush_batch<MS>(program_, batch, c, Blend::Replace, false);
        } else {
            (void)blocks; (void)count; (void)c;
        }
    }

    Program program_;
    Observer* obs_;
};

// One worker's tile-local storage, reused tile after tile: the samples of a
// multisampled or transient tile, the winner of each sample (kNoWinner
// between tiles), a dirty bit per 4x4 block holding winners, and the tile's
// winning triangles.
struct TileScratch {
    struct Ref {
        DrawRecord* draw;
        const BinJob* job;
        const TriangleSetup* tri;
    };
    std::vector<float> color, depth;
    std::vector<float> resolved;  // transient frames, several samples: the averages
    std::vector<std::uint32_t> winner;
    std::vector<std::uint64_t> dirty;
    std::vector<Ref> refs;
};

} // namespace raster_detail
} // namespace prast

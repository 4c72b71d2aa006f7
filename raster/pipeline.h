// The renderer: frames of draws over a thread pool that lives as long as it.
// A Program supplies
//
//   static constexpr int kVaryings;                        // floats per vertex after xyzw
//   void vertex(std::uint32_t index, float clip[4], float* varyings) const;
//   void fragment(const FragmentBlock<kVaryings>&, FragmentOut&) const;   // optional: none = depth only
//   void fragment_batch(const FragmentBlock<kVaryings>* const*, FragmentOut* const*, int) const;  // optional
//
// Both are called through templates, never virtually. An Observer (observer.h)
// sees each stage; the default NullObserver compiles to nothing.
//
//   renderer.begin(fb, FrameOptions{...});         // samples, clear colour/depth
//   renderer.submit(program, vertex_count, indices, index_count, state);   // any number, any programs
//   renderer.end(on_tile);                         // vertex, setup/bin, one tile pass; on_tile(const TileView&)
//
// draw() is a frame of one draw that keeps the target's contents (no clear).
#pragma once

#include <chrono>
#include <cstdint>
#include <memory>
#include <stdexcept>
#include <type_traits>
#include <vector>

#include "raster/frame.h"
#include "raster/framebuffer.h"
#include "raster/observer.h"
#include "raster/stats.h"
#include "raster/thread_pool.h"

namespace prast {

struct RendererOptions {
    int threads = 0;                      // 0 = all hardware threads
    int tile_size = kDefaultTileSize;     // power of two in [16, 256]
};

// Whether a draw with a fragment program into a colour target has its
// winners shaded once, after the visibility pass (else it is shaded in
// submission order; always for lines and points): what submit() chooses,
// and what the stepper records.
inline bool shades_after_visibility(const DrawState& state, FrameOptions::Visibility visibility) {
    return visibility != FrameOptions::Visibility::Never && state.topology == Topology::Triangles &&
           state.depth_test && state.depth_write &&
           state.blend == Blend::Replace && !state.may_discard;
}

class Renderer {
public:
    explicit Renderer(const RendererOptions& options = {});
    ~Renderer();
    Renderer(const Renderer&) = delete;
    Renderer& operator=(const Renderer&) = delete;

    int threads() const { return pool_.size(); }
    int tile_size() const { return tile_size_; }
    ThreadPool& pool() { return pool_; }

    // Clears colour and depth with the pool's threads (rows in chunks).
    // (A frame clears in its tile pass: FrameOptions::clear.)
    void clear(Framebuffer& fb, float r, float g, float b, float a, float z = 1.0f);

    // Counters accumulate over frames and draws until the next begin_frame().
    void begin_frame() { stats_ = FrameStats{}; tile_entries_.clear(); tile_usage_ = {}; }
    const FrameStats& stats() const { return stats_; }
    // The tile passes of the counted frames summed over the threads: CPU time
    // and time from starting on a pass to finding no tile left
    // (ThreadPool::Usage); threads() * stats().ms_raster - busy_ms is time a
    // thread waited. For bench.
    const ThreadPool::Usage& tile_usage() const { return tile_usage_; }
    // Bin entries per tile over the counted frames (row-major tiles of the
    // last framebuffer size): the `tiles` debug view and the stepper show it.
    const std::vector<std::uint32_t>& tile_entries() const { return tile_entries_; }

    // Starts a frame into fb (which must outlive end()). Throws
    // std::invalid_argument for a framebuffer size out of range, a sample
    // count other than 1, 2, 4, 8, or a frame already begun.
    void begin(Framebuffer& fb, const FrameOptions& options = {});

    // Records a draw of an indexed triangle list (index_count / 3 triangles),
    // or with state.topology Lines / Points a list of line segments
    // (index_count / 2 index pairs) or points (index_count), drawn 1 pixel
    // wide by the rules of raster/line.h, always shaded in submission order
    // (no visibility pass), observers told of their vertices only.
    // The program is copied; indices, everything the program points to and
    // the observer must live until end(). Indices out of range and non-finite
    // positions drop their triangle (counted as invalid) or line or point.
    template <class Program, class Observer>
    void submit(const Program& program, std::uint32_t vertex_count, const std::uint32_t* indices,
                std::size_t index_count, const DrawState& state, Observer& observer);
    template <class Program>
    void submit(const Program& program, std::uint32_t vertex_count, const std::uint32_t* indices,
                std::size_t index_count, const DrawState& state = {}) {
        submit(program, vertex_count, indices, index_count, state, null_observer_);
    }

    // Runs the frame. on_tile(const TileView&) is called once per finished
    // tile, from the worker thread that ran it (tiles in any order, each
    // once), with the tile's final linear colour: the place for a resolve.
    void end() { finish(nullptr, nullptr); }
    template <class OnTile>
    void end(OnTile&& on_tile) {
        using F = std::remove_reference_t<OnTile>;
        finish([](void* user, const TileView& v) { (*static_cast<F*>(user))(v); },
               const_cast<void*>(static_cast<const void*>(&on_tile)));
    }

    // A frame of one draw over the target's current contents, one sample.
    template <class Program, class Observer = NullObserver>
    void draw(Framebuffer& fb, const Program& program, std::uint32_t vertex_count,
              const std::uint32_t* indices, std::size_t index_count, const DrawState& state,
              Observer& observer) {
        FrameOptions keep;
        keep.clear = false;
        begin(fb, keep);
        try {
            submit(program, vertex_count, indices, index_count, state, observer);
        } catch (...) {
            abandon();
            throw;
        }
        end();
    }
    template <class Program>
    void draw(Framebuffer& fb, const Program& program, std::uint32_t vertex_count,
              const std::uint32_t* indices, std::size_t index_count, const DrawState& state = {}) {
        draw(fb, program, vertex_count, indices, index_count, state, null_observer_);
    }

private:
    using TileHook = void (*)(void*, const TileView&);
    void abandon() { fb_ = nullptr; draws_.clear(); }
    void finish(TileHook hook, void* user);
    void run_tile(int tile, int worker, TileHook hook, void* user);
    void flush_winners(TileContext& c, raster_detail::TileScratch& sc);

    ThreadPool pool_;
    int tile_size_;
    NullObserver null_observer_;

    // The open frame.
    Framebuffer* fb_ = nullptr;
    FrameOptions options_;
    TileGrid grid_;
    std::vector<std::unique_ptr<raster_detail::DrawRecord>> draws_;

    // Storage reused from frame to frame.
    std::vector<std::vector<float>> vertex_buffers_;   // by draw slot
    std::vector<std::vector<std::uint16_t>> outcode_buffers_;  // by draw slot
    std::vector<std::vector<WindowVertex>> window_buffers_;     // by draw slot
    std::vector<BinJob> jobs_;                         // every draw's, in submission order
    std::vector<raster_detail::TileScratch> scratch_;         // by worker
    std::vector<float> uniform_tile_;                  // transient frames: a tile of the resolved clear colour
    std::vector<FrameStats> worker_stats_;
    std::vector<std::uint32_t> frame_entries_;         // per tile, this frame
    std::vector<int> tile_order_;
    std::vector<std::uint32_t> tile_entries_;
    FrameStats stats_;
    ThreadPool::Usage tile_usage_;
};

template <class Program, class Observer>
void Renderer::submit(const Program& program, std::uint32_t vertex_count, const std::uint32_t* indices,
                      std::size_t index_count, const DrawState& state, Observer& observer) {
    constexpr int NV = Program::kVaryings;
    static_assert(NV >= 0 && NV <= kMaxVaryings, "too many varyings");
    if (!fb_) throw std::logic_error("Renderer::submit outside begin()/end()");
    ++stats_.draws;
    const std::size_t per = state.topology == Topology::Triangles ? 3 : state.topology == Topology::Lines ? 2 : 1;
    const std::size_t tri_count = index_count / per;
    if (tri_count == 0) return;
    auto d = std::make_unique<raster_detail::Draw<Program, Observer>>(program, observer);
    d->state = state;
    d->stride = 4 + NV;
    d->vertex_count = vertex_count;
    d->indices = indices;
    d->tri_count = tri_count;
    using raster_detail::DrawMode;
    if (!has_fragment<Program>::value || (!fb_->has_color() && !state.may_discard)) {
        d->mode = DrawMode::DepthOnly;
    } else if (fb_->has_color() && shades_after_visibility(state, options_.visibility)) {
        d->mode = DrawMode::Visible;
    } else {
        d->mode = DrawMode::InOrder;
    }
    d->reads_color = fb_->has_color() && state.blend != Blend::Replace;
    d->observed = Observer::enabled;
    d->batches = has_fragment_batch<Program>::value && !Observer::enabled && !state.may_discard &&
                 state.topology == Topology::Triangles;
    draws_.push_back(std::move(d));
}

} // namespace prast

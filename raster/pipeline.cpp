// The frame's passes (vertex, clip/setup/bin, tiles) and the tile pass
// itself; the per-draw templates live in frame.h, rasterize.h and shade.h.
#include "raster/pipeline.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <numeric>

#if defined(__AVX2__)
#include <immintrin.h>
#endif

#include "raster/tile_storage.h"

namespace prast {

namespace {

using Clock = std::chrono::steady_clock;
double ms_since(Clock::time_point t0) {
    return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

int checked_tile_size(int ts) {
    if (ts < kMinTileSize || ts > kMaxTileSize || (ts & (ts - 1)) != 0)
        throw std::invalid_argument("tile size must be a power of two in [16, 256]");
    return ts;
}

// Bit l: ids[l] == k.
inline std::uint32_t equal_mask(const std::uint32_t* ids, std::uint32_t k) {
#if defined(__AVX2__)
    const __m256i key = _mm256_set1_epi32(int(k));
    const __m256i lo = _mm256_cmpeq_epi32(_mm256_loadu_si256(reinterpret_cast<const __m256i*>(ids)), key);
    const __m256i hi = _mm256_cmpeq_epi32(_mm256_loadu_si256(reinterpret_cast<const __m256i*>(ids + 8)), key);
    return std::uint32_t(_mm256_movemask_ps(_mm256_castsi256_ps(lo))) |
           (std::uint32_t(_mm256_movemask_ps(_mm256_castsi256_ps(hi))) << 8);
#else
    std::uint32_t m = 0;
    for (int l = 0; l < kBlockLanes; ++l) m |= std::uint32_t(ids[l] == k) << l;
    return m;
#endif
}

} // namespace

Renderer::Renderer(const RendererOptions& options)
    : pool_(options.threads > 0 ? options.threads : ThreadPool::hardware_threads()),
      tile_size_(checked_tile_size(options.tile_size)) {}

Renderer::~Renderer() = default;

void Renderer::clear(Framebuffer& fb, float r, float g, float b, float a, float z) {
    fb.allocate();
    constexpr int kRows = 32;
    const int chunks = (fb.height + kRows - 1) / kRows;
    pool_.run(chunks, [&](int chunk, int) {
        const std::size_t begin = std::size_t(chunk) * kRows * fb.width;
        const std::size_t end = std::min<std::size_t>(std::size_t(fb.height), std::size_t(chunk + 1) * kRows) * fb.width;
        for (std::size_t i = begin; i < end; ++i) {
            if (fb.has_color()) {
                float* c = &fb.color[i * 4];
                c[0] = r; c[1] = g; c[2] = b; c[3] = a;
            }
            fb.depth[i] = z;
        }
    });
}

void Renderer::begin(Framebuffer& fb, const FrameOptions& options) {
    if (fb_) throw std::logic_error("Renderer::begin: a frame is already open");
    if (fb.width <= 0 || fb.height <= 0 || fb.width > kMaxViewportSize || fb.height > kMaxViewportSize)
        throw std::invalid_argument("framebuffer size out of range");
    if (!valid_sample_count(options.samples))
        throw std::invalid_argument("samples per pixel must be 1, 2, 4 or 8");
    fb_ = &fb;
    options_ = options;
    options_.transient = options.transient && options.clear;  // a frame that loads the target keeps it
    if (!options_.transient) fb.allocate();  // a deferred framebuffer's first kept frame
    grid_ = TileGrid(fb.width, fb.height, tile_size_);
    draws_.clear();
}

void Renderer::finish(TileHook hook, void* user) {
    if (!fb_) throw std::logic_error("Renderer::end without begin()");
    struct Close {
        Renderer* r;
        ~Close() { r->fb_ = nullptr; r->draws_.clear(); }
    } close{this};
    const int workers = pool_.size();
    const int ndraws = int(draws_.size());
    const SamplePattern& pattern = sample_pattern(options_.samples);
    const SampleExtent extent = sample_extent(pattern);

    // Vertex stage: chunks of vertices of every draw, one pass.
    auto t0 = Clock::now();
    if (vertex_buffers_.size() < draws_.size()) vertex_buffers_.resize(draws_.size());
    if (outcode_buffers_.size() < draws_.size()) outcode_buffers_.resize(draws_.size());
    if (window_buffers_.size() < draws_.size()) window_buffers_.resize(draws_.size());
    const GuardBand guard_band = GuardBand::for_viewport(grid_.width, grid_.height);
    std::vector<int> vchunk_end(std::size_t(ndraws) + 1, 0);
    for (int d = 0; d < ndraws; ++d) {
        raster_detail::DrawRecord& dr = *draws_[std::size_t(d)];
        dr.vertices = &vertex_buffers_[std::size_t(d)];
        dr.vertices->resize(std::size_t(dr.vertex_count) * std::size_t(dr.stride));
        dr.outcodes = &outcode_buffers_[std::size_t(d)];
        dr.outcodes->resize(dr.vertex_count);
        dr.window = &window_buffers_[std::size_t(d)];
        dr.window->resize(dr.vertex_count);
        const int chunks = int((std::uint64_t(dr.vertex_count) + kVertexChunk - 1) / kVertexChunk);
        vchunk_end[std::size_t(d) + 1] = vchunk_end[std::size_t(d)] + chunks;
        stats_.vertices += dr.vertex_count;
    }
    pool_.run(vchunk_end.back(), [&](int task, int) {
        const int d = int(std::upper_bound(vchunk_end.begin(), vchunk_end.end(), task) - vchunk_end.begin()) - 1;
        raster_detail::DrawRecord& dr = *draws_[std::size_t(d)];
        const std::uint32_t begin = std::uint32_t(task - vchunk_end[std::size_t(d)]) * kVertexChunk;
        const std::uint32_t end = std::min<std::uint32_t>(dr.vertex_count, begin + kVertexChunk);
        dr.shade_vertices(begin, end);
        project_vertices(dr.vertices->data(), dr.stride, begin, end, guard_band, grid_.width, grid_.height,
                         dr.outcodes->data(), dr.window->data());
    });
    stats_.ms_vertex += ms_since(t0);

    // Clip, cull, set up and bin: chunks of triangles of every draw, one bin
    // set per chunk, one pass.
    t0 = Clock::now();
    struct JobRange {
        int draw;
        std::size_t begin, end;
    };
    std::vector<JobRange> ranges;
    for (int d = 0; d < ndraws; ++d) {
        raster_detail::DrawRecord& dr = *draws_[std::size_t(d)];
        const std::size_t per_job =
            std::max<std::size_t>(kTrianglesPerJob, (dr.tri_count + kMaxJobs - 1) / kMaxJobs);
        dr.first_job = int(ranges.size());
        for (std::size_t b = 0; b < dr.tri_count; b += per_job)
            ranges.push_back({d, b, std::min(dr.tri_count, b + per_job)});
        dr.job_count = int(ranges.size()) - dr.first_job;
    }
    const int job_count = int(ranges.size());
    if (int(jobs_.size()) < job_count) jobs_.resize(std::size_t(job_count));
    const int tiles = grid_.count();
    pool_.run(job_count, [&](int j, int) {
        BinJob& job = jobs_[std::size_t(j)];
        const JobRange& r = ranges[std::size_t(j)];
        job.reset(tiles);
        if (draws_[std::size_t(r.draw)]->state.topology == Topology::Triangles) job.setups.reserve(r.end - r.begin);
        else job.lines.reserve(r.end - r.begin);
        draws_[std::size_t(r.draw)]->bin(job, r.begin, r.end, grid_, extent);
        sort_bins(job, tiles);
    });
    for (int j = 0; j < job_count; ++j) stats_.add_counters(jobs_[std::size_t(j)].stats);
    stats_.ms_setup_bin += ms_since(t0);

    // Tiles: each tile is owned by one thread and runs its bins in submission
    // order. The busiest tiles go first, so that no thread is left with a
    // heavy tile at the end (the order changes no pixel).
    t0 = Clock::now();
    frame_entries_.assign(std::size_t(tiles), 0);
    for (int j = 0; j < job_count; ++j) {
        const std::vector<std::uint32_t>& off = jobs_[std::size_t(j)].tile_offsets;
        for (int t = 0; t < tiles; ++t) frame_entries_[std::size_t(t)] += off[std::size_t(t) + 1] - off[std::size_t(t)];
    }
    if (tile_entries_.size() != std::size_t(tiles)) tile_entries_.assign(std::size_t(tiles), 0);
    for (int t = 0; t < tiles; ++t) tile_entries_[std::size_t(t)] += frame_entries_[std::size_t(t)];
    tile_order_.clear();
    for (int t = 0; t < tiles; ++t)
        if (options_.clear || frame_entries_[std::size_t(t)]) tile_order_.push_back(t);
    std::stable_sort(tile_order_.begin(), tile_order_.end(),
                     [&](int a, int b) { return frame_entries_[std::size_t(a)] > frame_entries_[std::size_t(b)]; });

    // Tile-local storage: samples (several per pixel) and winners, which stay
    // kNoWinner between tiles.
    const int S = options_.samples;
    const std::size_t plane = std::size_t(tile_size_) * std::size_t(tile_size_);
    const int blocks = (tile_size_ / kBlockSize) * (tile_size_ / kBlockSize);
    if (scratch_.size() != std::size_t(workers)) scratch_.resize(std::size_t(workers));
    const bool transient = options_.transient;
    // A transient tile no draw reaches shows S cleared samples resolved: the
    // clear colour, or infinities where the sums overflow (resolve.cpp).
    float uniform_color[4];
    std::memcpy(uniform_color, options_.clear_color, sizeof uniform_color);
    if (S > 1) {
        float samples[kMaxSamples * 4];
        for (int s = 0; s < S; ++s) std::memcpy(samples + 4 * s, options_.clear_color, 4 * sizeof(float));
        resolve_samples_local(samples, 1, S, 1, 1, uniform_color);
    }
    for (raster_detail::TileScratch& sc : scratch_) {
        if (sc.winner.size() != plane * std::size_t(S)) sc.winner.assign(plane * std::size_t(S), kNoWinner);
        sc.dirty.assign(std::size_t((blocks + 63) / 64), 0);
        if (S > 1 || transient) {
            sc.depth.resize(plane * std::size_t(S));
            sc.color.resize(fb_->has_color() ? plane * std::size_t(S) * 4 : 0);
        }
        if (transient && fb_->has_color() && S > 1) sc.resolved.resize(plane * 4);
    }
    // One tile of that colour for every worker (read only in the pass),
    // refilled when the colour or the tile size changes.
    if (transient && fb_->has_color() &&
        (uniform_tile_.size() != plane * 4 || std::memcmp(uniform_tile_.data(), uniform_color, sizeof uniform_color))) {
        uniform_tile_.resize(plane * 4);
        for (std::size_t i = 0; i < plane * 4; i += 4) std::memcpy(&uniform_tile_[i], uniform_color, sizeof uniform_color);
    }
    worker_stats_.assign(std::size_t(workers), FrameStats{});
    pool_.reset_usage();
    pool_.run(int(tile_order_.size()), [&](int task, int worker) {
        run_tile(tile_order_[std::size_t(task)], worker, hook, user);
    });
    for (const FrameStats& ws : worker_stats_) stats_.add_counters(ws);
    stats_.ms_raster += ms_since(t0);
    const ThreadPool::Usage usage = pool_.usage();
    tile_usage_.cpu_ms += usage.cpu_ms;
    tile_usage_.busy_ms += usage.busy_ms;
}

void Renderer::run_tile(int tile, int worker, TileHook hook, void* user) {
    Framebuffer& fb = *fb_;
    raster_detail::TileScratch& sc = scratch_[std::size_t(worker)];
    FrameStats& stats = worker_stats_[std::size_t(worker)];
    const int S = options_.samples;
    const int T = tile_size_;
    TileRect r;
    r.x0 = (tile % grid_.tiles_x) * T;
    r.y0 = (tile / grid_.tiles_x) * T;
    r.x1 = std::min(r.x0 + T, fb.width) - 1;
    r.y1 = std::min(r.y0 + T, fb.height) - 1;

    TileContext c;
    c.width = fb.width;
    c.height = fb.height;
    c.samples = &sample_pattern(S);
    c.extent = sample_extent(*c.samples);
    c.x0 = r.x0; c.y0 = r.y0; c.x1 = r.x1; c.y1 = r.y1;
    c.stats = &stats;
    c.dirty = sc.dirty.data();
    c.blocks_x = T / kBlockSize;
    TileTarget& tg = c.target;
    const bool transient = options_.transient;
    if (S == 1 && !transient) {
        tg.color = fb.has_color() ? fb.color.data() : nullptr;
        tg.depth = fb.depth.data();
        tg.row = std::size_t(fb.width);
        tg.plane = 0;
        tg.ox = tg.oy = 0;
        tg.local = false;
    } else {
        tg.color = fb.has_color() ? sc.color.data() : nullptr;
        tg.depth = sc.depth.data();
        tg.row = std::size_t(T);
        tg.plane = std::size_t(T) * std::size_t(T);
        tg.ox = r.x0;
        tg.oy = r.y0;
        tg.local = true;
    }
    tg.winner = sc.winner.data();
    tg.wrow = std::size_t(T);
    tg.wplane = std::size_t(T) * std::size_t(T);
    tg.wox = r.x0;
    tg.woy = r.y0;

    // A tile no draw reaches keeps its cleared colour and depth (one colour
    // unless a fill paints a background).
    bool reached = false;
    for (const std::unique_ptr<raster_detail::DrawRecord>& dp : draws_)
        for (int j = dp->first_job; j < dp->first_job + dp->job_count && !reached; ++j) {
            const BinJob& job = jobs_[std::size_t(j)];
            reached = job.tile_offsets[std::size_t(tile)] != job.tile_offsets[std::size_t(tile) + 1];
        }
    const bool uniform = options_.clear && !options_.clear_fill && !reached;
    // Several samples all cleared to one value resolve to exactly that value
    // (resolve.cpp: pairwise sums of equal values, times 1/S), unless the
    // sums overflow: such a tile is cleared in the framebuffer directly.
    bool direct = S == 1 && !transient;
    if (uniform && S > 1 && !transient) {
        direct = true;
        for (int k = 0; k < 4; ++k) direct &= std::fabs(options_.clear_color[k]) <= 0x1p100f;
    }

    // Start: clear, or (several samples) load the target's pixels.
    if (options_.clear) {
        // Streamed at one sample, where it measured faster on 2 threads (bench
        // --alternate, bottle); with several samples the difference was in the noise.
        if (uniform && transient) {}  // the hook sees uniform_tile_
        else if (uniform && direct && S == 1) clear_tile_streaming(fb, r, options_.clear_color, options_.clear_depth);
        else if (direct) clear_tile(fb, r, options_.clear_color, options_.clear_depth);
        else clear_samples(tg.color, tg.depth, T, S, options_.clear_color, options_.clear_depth);
        if (options_.clear_fill && tg.color) {
            if (!tg.local) {
                options_.clear_fill(options_.clear_user, r.x0, r.y0, r.width(), r.height(),
                                    &fb.color[(std::size_t(r.y0) * std::size_t(fb.width) + std::size_t(r.x0)) * 4],
                                    std::size_t(fb.width) * 4);
            } else {
                // Plane 0, then the same pixels into every other sample's plane.
                const std::size_t plane = std::size_t(T) * std::size_t(T) * 4;
                options_.clear_fill(options_.clear_user, r.x0, r.y0, r.width(), r.height(), tg.color,
                                    std::size_t(T) * 4);
                for (int s = 1; s < S; ++s)
                    for (int y = 0; y < r.height(); ++y)
                        std::memcpy(tg.color + s * plane + std::size_t(y) * std::size_t(T) * 4,
                                    tg.color + std::size_t(y) * std::size_t(T) * 4,
                                    std::size_t(r.width()) * 4 * sizeof(float));
            }
        }
    } else if (S > 1) {
        load_samples(fb, r, tg.color, tg.depth, T, S);
    }

    // Visibility pass or shading in order for the draws that may take either
    // (the bytes are the same): by the tile's estimated overdraw. Observed
    // draws always take the pass, so that their events do not depend on tiling.
    bool defer = options_.visibility == FrameOptions::Visibility::Always;
    if (options_.visibility == FrameOptions::Visibility::Auto) {
        std::uint64_t covered = 0;  // 1/kCoverScale pixel
        for (const std::unique_ptr<raster_detail::DrawRecord>& dp : draws_) {
            if (dp->mode != raster_detail::DrawMode::Visible) continue;
            defer |= dp->observed;
            for (int j = dp->first_job; j < dp->first_job + dp->job_count; ++j)
                covered += jobs_[std::size_t(j)].tile_cover[std::size_t(tile)];
        }
        defer |= double(covered) > double(kOverdrawForVisibility) * double(kCoverScale) * double(r.width()) * double(r.height());
    }

    // Every draw's bins, in submission order. Shading in order returns the
    // samples it writes to kNoWinner; while no winner is pending (none yet,
    // or flush_winners() just returned them all) they already are, so those
    // draws see no winner plane (tg.winner null) and skip the stores.
    std::uint32_t* const winners = tg.winner;
    bool touched = false, pending = false;
    sc.refs.clear();
    for (const std::unique_ptr<raster_detail::DrawRecord>& dp : draws_) {
        raster_detail::DrawRecord& d = *dp;
        // Shaded here, triangle by triangle (not depth only, not left to the
        // visibility pass's winners).
        const bool in_order = d.mode == raster_detail::DrawMode::InOrder || (d.mode == raster_detail::DrawMode::Visible && !defer);
        bool flushed = false;
        for (int j = d.first_job; j < d.first_job + d.job_count; ++j) {
            const BinJob& job = jobs_[std::size_t(j)];
            const std::uint32_t begin = job.tile_offsets[std::size_t(tile)];
            const std::uint32_t end = job.tile_offsets[std::size_t(tile) + 1];
            if (begin == end) continue;
            touched = true;
            if (d.reads_color && pending && !flushed) {
                tg.winner = winners;
                flush_winners(c, sc);
                pending = false;
                flushed = true;
            }
            tg.winner = (pending || !in_order) ? winners : nullptr;
            if (d.state.topology != Topology::Triangles) {
                d.rasterize_lines(job, begin, end, c);
                continue;
            }
            if (d.batches && in_order) {
                d.rasterize_in_order_batched(job, begin, end, c);
                continue;
            }
            for (std::uint32_t i = begin; i < end; ++i) {
                if (i + 2 < end) raster_detail::prefetch_setup(job.setups[job.items[i + 2]]);
                if (i + 1 < end && in_order)
                    raster_detail::prefetch_varyings(job.setups[job.items[i + 1]], d.vertices->data(), job, d.stride);
                const TriangleSetup& t = job.setups[job.items[i]];
                switch (d.mode) {
                case raster_detail::DrawMode::Visible:
                    if (!defer) {
                        d.rasterize_in_order(t, job, c);
                        break;
                    }
                    d.rasterize_visible(t, c, std::uint32_t(sc.refs.size()));
                    sc.refs.push_back({&d, &job, &t});
                    pending = true;
                    break;
                case raster_detail::DrawMode::DepthOnly:
                    d.rasterize_visible(t, c, kNoWinner);
                    break;
                case raster_detail::DrawMode::InOrder:
                    d.rasterize_in_order(t, job, c);
                    break;
                }
            }
        }
    }
    tg.winner = winners;
    if (pending) flush_winners(c, sc);
    stats.tiles_touched += touched;

    // End: resolve the samples, then hand the tile's colour to the hook.
    if (!direct && !transient) resolve_samples(tg.color, tg.depth, T, S, r, fb);
    if (hook && fb.has_color()) {
        TileView v;
        v.x0 = r.x0;
        v.y0 = r.y0;
        v.width = r.width();
        v.height = r.height();
        if (!transient) {
            v.rgba = &fb.color[(std::size_t(r.y0) * std::size_t(fb.width) + std::size_t(r.x0)) * 4];
            v.row = std::size_t(fb.width) * 4;
        } else {
            if (uniform) {
                v.rgba = uniform_tile_.data();
            } else if (S == 1) {
                v.rgba = tg.color;
            } else {
                resolve_samples_local(tg.color, T, S, r.width(), r.height(), sc.resolved.data());
                v.rgba = sc.resolved.data();
            }
            v.row = std::size_t(T) * 4;
        }
        v.uniform = uniform;
        hook(user, v);
    }
}

// Shades every winner of the tile once per block it won samples in, then
// returns the winners to kNoWinner.
void Renderer::flush_winners(TileContext& c, raster_detail::TileScratch& sc) {
    const int S = c.sample_count();
    const TileTarget& tg = c.target;
    const std::size_t words = sc.dirty.size();
    // Sparse winner blocks wait for a batch of their draw (winners own their
    // samples, so the order of the writes does not matter).
    raster_detail::WinnerBlock batch[kMaxBatchBlocks];
    raster_detail::DrawRecord* batch_draw = nullptr;
    int batch_count = 0, batch_lanes = 0;
    auto flush_batch = [&] {
        if (batch_count) batch_draw->shade_winners(batch, batch_count, c);
        batch_count = batch_lanes = 0;
    };
    for (std::size_t w = 0; w < words; ++w) {
        for (std::uint64_t bits = sc.dirty[w]; bits; bits &= bits - 1) {
            const int b = int(w * 64) + __builtin_ctzll(bits);
            const int bx = c.x0 + (b % c.blocks_x) * kBlockSize, by = c.y0 + (b / c.blocks_x) * kBlockSize;
            std::uint32_t* win = tg.winner + tg.winner_offset(bx, by);
            alignas(32) std::uint32_t ids[kMaxSamples][kBlockLanes];
            std::uint32_t remaining[kMaxSamples];
            for (int s = 0; s < S; ++s) {
                raster_detail::load_winners(win + s * tg.wplane, tg.wrow, ids[s]);
                remaining[s] = ~equal_mask(ids[s], kNoWinner) & 0xFFFFu;
            }
            for (int s0 = 0; s0 < S; ++s0) {
                while (remaining[s0]) {
                    const std::uint32_t k = ids[s0][__builtin_ctz(remaining[s0])];
                    std::uint32_t won[kMaxSamples], lanes = 0;
                    for (int s = 0; s < S; ++s) {
                        won[s] = equal_mask(ids[s], k) & remaining[s];
                        remaining[s] &= ~won[s];
                        lanes |= won[s];
                    }
                    const raster_detail::TileScratch::Ref& ref = sc.refs[k];
                    const int n = __builtin_popcount(lanes);
                    const bool joins = batch_count && batch_draw == ref.draw && batch_count < kMaxBatchBlocks &&
                                       batch_lanes + n <= kBlockLanes;
                    if (!ref.draw->batches || (n > kBatchBlockLanes && !joins)) {
                        ref.draw->shade_winner(*ref.tri, *ref.job, c, bx, by, lanes, won);
                        continue;
                    }
                    if (!joins) flush_batch();
                    raster_detail::prefetch_setup(*ref.tri);  // read when the batch is shaded
                    raster_detail::WinnerBlock& wb = batch[batch_count++];
                    wb.tri = ref.tri;
                    wb.job = ref.job;
                    wb.bx = bx;
                    wb.by = by;
                    wb.lanes = lanes;
                    for (int s = 0; s < S; ++s) wb.won[s] = won[s];
                    batch_draw = ref.draw;
                    batch_lanes += n;
                }
                raster_detail::store_winner(win + s0 * tg.wplane, tg.wrow, 0xFFFFu, kNoWinner);
            }
        }
        sc.dirty[w] = 0;
    }
    flush_batch();
    sc.refs.clear();
}

} // namespace prast

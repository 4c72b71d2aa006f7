// The recording observer and the frames it records; see recording.h.
#include "stepper/recording.h"

#include <algorithm>
#include <chrono>
#include <cstring>

#include "stepper/frame_loop.h"

namespace prast::stepper {

const DrawRecord& Recording::draw_of(std::uint32_t tri) const {
    // Draws are in triangle order: the last one starting at or before tri.
    auto it = std::upper_bound(draws.begin(), draws.end(), tri,
                               [](std::uint32_t t, const DrawRecord& d) { return t < d.first_triangle; });
    return *(it == draws.begin() ? it : it - 1);
}

std::size_t Recording::bytes() const {
    std::size_t n = sizeof(Recording);
    for (const DrawRecord& d : draws) n += sizeof d + d.vertices.size() * sizeof(float);
    n += triangles.size() * sizeof(TriangleRecord) + pieces.size() * sizeof(PieceRecord) +
         setups.size() * sizeof(TriangleSetup) + piece_tiles.size() * sizeof(std::uint32_t);
    for (const TileRecord& t : tiles)
        n += sizeof t + t.pieces.size() * sizeof(std::uint32_t) + t.blocks.size() * sizeof(BlockRecord) +
             t.z.size() * sizeof(float);
    return n;
}

namespace {

// Triangle and bin events of one draw, in arrival order; sorted by (prim,
// seq) afterwards, where seq counts each triangle's own events (a triangle
// is set up and binned by one thread, so its events arrive in order).
struct BinEvent {
    std::uint32_t prim;
    std::uint32_t seq;
    bool is_triangle;
    TriangleFate fate;
    bool clipped;
    std::uint32_t value;  // triangle: slot of the setup copy (kNone without); bin: tile
};

class RecordingObserver {
public:
    static constexpr bool enabled = true;

    explicit RecordingObserver(Recording& rec) : rec_(rec) {}

    void begin_draw(int mesh, std::uint32_t first, std::uint32_t triangles, std::uint32_t vertices,
                    const DrawState& st) {
        finish_draw();
        DrawRecord d;
        d.mesh = mesh;
        d.state = st;
        d.first_triangle = first;
        d.triangle_count = triangles;
        d.vertex_count = vertices;
        d.vertices.assign(std::size_t(vertices) * kStride, 0.0f);
        rec_.draws.push_back(std::move(d));
        seq_.assign(triangles, 0);
        events_.clear();
        setups_.clear();
        block_start_.resize(rec_.tiles.size());
        for (std::size_t t = 0; t < rec_.tiles.size(); ++t) block_start_[t] = rec_.tiles[t].blocks.size();
        open_ = true;
    }

    void vertex(std::uint32_t v, const float* clip, const float* var, int nv) {
        float* d = &rec_.draws.back().vertices[std::size_t(v) * kStride];
        std::memcpy(d, clip, 4 * sizeof(float));
        std::memcpy(d + 4, var, std::size_t(std::min(nv, int(kPbrVaryings))) * sizeof(float));
    }

    void triangle(std::uint32_t prim, TriangleFate fate, bool clipped, const TriangleSetup* t) {
        const std::uint32_t seq = seq_[prim]++;
        std::lock_guard<std::mutex> lock(mutex_);
        std::uint32_t slot = kNone;
        if (t) {
            slot = std::uint32_t(setups_.size());
            setups_.push_back(*t);
        }
        events_.push_back({prim, seq, true, fate, clipped, slot});
    }

    void binned(std::uint32_t prim, int tile) {
        const std::uint32_t seq = seq_[prim]++;
        std::lock_guard<std::mutex> lock(mutex_);
        events_.push_back({prim, seq, false, TriangleFate::SetUp, false, std::uint32_t(tile)});
    }

    void fragments(std::uint32_t prim, int bx, int by, std::uint32_t mask, std::uint32_t pass, const float* z) {
        TileRecord& t = rec_.tiles[std::size_t(rec_.tile_of(bx, by))];
        BlockRecord b;
        b.piece = rec_.draws.back().first_triangle + prim;  // the triangle, until finish_draw()
        b.bx = std::uint16_t(bx);
        b.by = std::uint16_t(by);
        b.mask = std::uint16_t(mask);
        b.pass = std::uint16_t(pass);
        b.live = 0;
        b.z = std::uint32_t(t.z.size());
        for (std::uint32_t m = mask & 0xFFFFu; m; m &= m - 1) t.z.push_back(z[__builtin_ctz(m)]);
        t.blocks.push_back(b);
    }

    template <int NV>
    void shaded(const FragmentBlock<NV>& in, const FragmentOut&, std::uint32_t live) {
        // The tile's thread calls this after fragments() for the same block:
        // today right after it; searched from the back so that a pipeline
        // shading later in the tile is recorded as well.
        std::vector<BlockRecord>& blocks = rec_.tiles[std::size_t(rec_.tile_of(in.x, in.y))].blocks;
        const std::uint32_t tri = rec_.draws.back().first_triangle + in.prim_id;
        for (std::size_t i = blocks.size(); i-- > 0;) {
            BlockRecord& b = blocks[i];
            if (b.bx == in.x && b.by == in.y && b.piece == tri) {
                b.live = std::uint16_t(live);
                return;
            }
        }
    }

    // Turns the draw's events into triangles, pieces and bins, and names the
    // piece of each block it drew.
    void finish_draw() {
        if (!open_) return;
        open_ = false;
        const DrawRecord& d = rec_.draws.back();
        std::sort(events_.begin(), events_.end(), [](const BinEvent& a, const BinEvent& b) {
            return a.prim != b.prim ? a.prim < b.prim : a.seq < b.seq;
        });
        const std::size_t first_piece = rec_.pieces.size();
        std::size_t e = 0;
        for (std::uint32_t prim = 0; prim < d.triangle_count; ++prim) {
            TriangleRecord& tr = rec_.triangles[d.first_triangle + prim];
            tr.first_piece = std::uint32_t(rec_.pieces.size());
            bool any_setup = false, any_back = false;
            TriangleFate last = TriangleFate::Invalid;
            for (; e < events_.size() && events_[e].prim == prim; ++e) {
                const BinEvent& ev = events_[e];
                tr.seen = true;
                if (ev.is_triangle) {
                    tr.clipped = ev.clipped;
                    last = ev.fate;
                    any_setup |= ev.fate == TriangleFate::SetUp;
                    any_back |= ev.fate == TriangleFate::CulledBack;
                    // Invalid and frustum-culled triangles never became pieces.
                    if (ev.fate == TriangleFate::Invalid || ev.fate == TriangleFate::CulledFrustum) continue;
                    PieceRecord p;
                    p.triangle = d.first_triangle + prim;
                    p.fate = ev.fate;
                    if (ev.value != kNone) {
                        p.setup = std::uint32_t(rec_.setups.size());
                        rec_.setups.push_back(setups_[ev.value]);
                    }
                    p.first_tile = std::uint32_t(rec_.piece_tiles.size());
                    rec_.pieces.push_back(p);
                } else {
                    rec_.piece_tiles.push_back(ev.value);
                    ++rec_.pieces.back().tile_count;
                }
            }
            tr.piece_count = std::uint32_t(rec_.pieces.size()) - tr.first_piece;
            tr.fate = any_setup ? TriangleFate::SetUp : any_back ? TriangleFate::CulledBack : last;
        }
        // Each tile runs its bins in submission order: pieces in order.
        for (std::size_t p = first_piece; p < rec_.pieces.size(); ++p) {
            const PieceRecord& pr = rec_.pieces[p];
            for (std::uint32_t i = 0; i < pr.tile_count; ++i)
                rec_.tiles[rec_.piece_tiles[pr.first_tile + i]].pieces.push_back(std::uint32_t(p));
        }
        // A block belongs to the one piece of its triangle that covers its
        // first covered pixel (pieces of a clipped triangle never overlap).
        for (std::size_t t = 0; t < rec_.tiles.size(); ++t) {
            std::vector<BlockRecord>& blocks = rec_.tiles[t].blocks;
            for (std::size_t i = block_start_[t]; i < blocks.size(); ++i) {
                BlockRecord& b = blocks[i];
                const TriangleRecord& tr = rec_.triangles[b.piece];
                std::uint32_t piece = tr.first_piece;
                if (tr.piece_count > 1) {
                    const int lane = __builtin_ctz(b.mask);
                    const int x = b.bx + lane_x(lane), y = b.by + lane_y(lane);
                    for (std::uint32_t k = 0; k < tr.piece_count; ++k) {
                        const PieceRecord& pr = rec_.pieces[tr.first_piece + k];
                        if (pr.setup == kNone) continue;
                        const TriangleSetup& s = rec_.setups[pr.setup];
                        if (edge_at_pixel(s, 0, x, y) >= 0 && edge_at_pixel(s, 1, x, y) >= 0 &&
                            edge_at_pixel(s, 2, x, y) >= 0) {
                            piece = tr.first_piece + k;
                            break;
                        }
                    }
                }
                b.piece = piece;
            }
        }
    }

private:
    Recording& rec_;
    std::mutex mutex_;
    std::vector<BinEvent> events_;
    std::vector<TriangleSetup> setups_;
    std::vector<std::uint32_t> seq_;
    std::vector<std::size_t> block_start_;
    bool open_ = false;
};

double ms_since(std::chrono::steady_clock::time_point t0) {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

} // namespace

void record_frame(StepScene& s, Recording& rec) {
    rec = Recording{};
    rec.width = s.width();
    rec.height = s.height();
    rec.tile_size = s.renderer->tile_size();
    rec.tiles_x = (rec.width + rec.tile_size - 1) / rec.tile_size;
    rec.tiles_y = (rec.height + rec.tile_size - 1) / rec.tile_size;
    rec.tiles.resize(std::size_t(rec.tiles_x) * rec.tiles_y);
    std::size_t total = 0;
    for (const Mesh& m : s.scene.meshes)
        if (!m.indices.empty()) total += m.indices.size() / 3;
    rec.triangles.resize(total);
    rec.fb.resize(rec.width, rec.height);

    RecordingObserver obs(rec);
    const auto t0 = std::chrono::steady_clock::now();
    draw_frame(s, rec.fb, obs);
    obs.finish_draw();
    rec.record_ms = ms_since(t0);
    rec.stats = s.renderer->stats();
}

void draw_upto(StepScene& s, std::uint64_t triangles, Framebuffer& fb) {
    fb.resize(s.width(), s.height());
    NullObserver none;
    draw_frame(s, fb, none, triangles);
}

void draw_plain(StepScene& s, Framebuffer& fb) {
    fb.resize(s.width(), s.height());
    s.scene_renderer->render(s.settings, fb);
}

} // namespace prast::stepper

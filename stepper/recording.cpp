// The recording observer and the frames it records; see recording.h.
#include "stepper/recording.h"

#include <algorithm>
#include <chrono>
#include <cstring>
#include <memory>


namespace prast::stepper {

const DrawRecord& Recording::draw_of(std::uint32_t tri) const {
    // Draws are in triangle order: the last one starting at or before tri.
    auto it = std::upper_bound(draws.begin(), draws.end(), tri,
                               [](std::uint32_t t, const DrawRecord& d) { return t < d.first_triangle; });
    return *(it == draws.begin() ? it : it - 1);
}

void DrawRecord::full_vertex(std::uint32_t v, float* out) const {
    std::memcpy(out, &vertices[std::size_t(v) * kStride], sizeof(float) * std::size_t(std::min(kStride, stride())));
    const int m = more_count();
    if (m) std::memcpy(out + kStride, &more[std::size_t(v) * std::size_t(m)], sizeof(float) * std::size_t(m));
}

int draw_varyings(const FrameSetup& s, const SceneDraw& d) {
    const Mesh& mesh = s.scene.meshes[std::size_t(d.mesh)];
    const BoundMaterial& bm = s.scene_renderer->material_of(mesh);
    const DebugView view = s.settings.view;
    if (mesh.topology != Mesh::Topology::Triangles && mesh.normals.empty() &&
        (view == DebugView::None || view == DebugView::Tiles))
        return UnlitProgram::kVaryings;
    return needs_extended_varyings(mesh, bm) ? kPbrVaryingsExt : kPbrVaryings;
}

std::size_t Recording::bytes() const {
    std::size_t n = sizeof(Recording);
    for (const DrawRecord& d : draws) n += sizeof d + (d.vertices.size() + d.more.size()) * sizeof(float);
    n += triangles.size() * sizeof(TriangleRecord) + pieces.size() * sizeof(PieceRecord) +
         setups.size() * sizeof(TriangleSetup) + piece_tiles.size() * sizeof(std::uint32_t);
    for (const TileRecord& t : tiles)
        n += sizeof t + t.pieces.size() * sizeof(std::uint32_t) + t.blocks.size() * sizeof(BlockRecord) +
             t.z.size() * sizeof(float) + t.masks.size() * sizeof(std::uint16_t);
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

// Records a frame. Each draw gets its own tap (the observer the pipeline
// calls for that draw), which tells the recorder the draw's number: so the
// draws of a frame may run one after another or all in one tile pass.
class RecordingObserver {
public:
    explicit RecordingObserver(Recording& rec) : rec_(rec) {}

    struct Tap {
        static constexpr bool enabled = true;
        RecordingObserver* r;
        std::size_t draw;
        void vertex(std::uint32_t v, const float* clip, const float* var, int nv) { r->vertex(draw, v, clip, var, nv); }
        void triangle(std::uint32_t prim, TriangleFate f, bool clipped, const TriangleSetup* t) {
            r->triangle(draw, prim, f, clipped, t);
        }
        void binned(std::uint32_t prim, int tile) { r->binned(draw, prim, tile); }
        void fragments(std::uint32_t prim, int bx, int by, std::uint32_t mask, std::uint32_t pass, const float* z) {
            r->fragments(draw, prim, bx, by, mask, pass, z);
        }
        void samples(std::uint32_t, int bx, int by, const SampleCoverage& sc) { r->samples(bx, by, sc); }
        template <int NV>
        void shaded(const FragmentBlock<NV>& in, const FragmentOut&, std::uint32_t live) {
            r->shaded(draw, in.x, in.y, in.prim_id, in.mask, live);
        }
    };

    // A new draw (before the pipeline runs it): its record and its tap.
    Tap tap(int mesh, std::uint32_t first, std::uint32_t triangles, std::uint32_t vertices, const DrawState& st,
            int varyings, std::uint32_t primitives) {
        DrawRecord d;
        d.mesh = mesh;
        d.varyings = varyings;
        d.topology = st.topology;
        d.primitives = primitives;
        d.state = st;
        d.visible = shades_after_visibility(st, rec_.visibility);
        d.first_triangle = first;
        d.triangle_count = triangles;
        d.vertex_count = vertices;
        d.vertices.assign(std::size_t(vertices) * kStride, 0.0f);
        d.more.assign(std::size_t(vertices) * std::size_t(d.more_count()), 0.0f);
        rec_.draws.push_back(std::move(d));
        auto ev = std::make_unique<DrawEvents>();
        ev->seq.assign(triangles, 0);
        events_.push_back(std::move(ev));
        return Tap{this, rec_.draws.size() - 1};
    }

    // After the frame: triangles, pieces and bins from the events, and the
    // piece of every recorded block.
    void finish();

private:
    // Triangle and bin events of one draw, in arrival order; sorted by (prim,
    // seq) afterwards, where seq counts each triangle's own events (a triangle
    // is set up and binned by one thread, so its events arrive in order).
    struct DrawEvents {
        std::mutex mutex;
        std::vector<std::uint32_t> seq;
        std::vector<BinEvent> events;
        std::vector<TriangleSetup> setups;
    };

    void vertex(std::size_t draw, std::uint32_t v, const float* clip, const float* var, int nv) {
        DrawRecord& dr = rec_.draws[draw];
        if (nv != dr.varyings) {
            std::lock_guard<std::mutex> lock(mismatch_mutex_);
            ++rec_.layout_mismatches;
            return;
        }
        float* d = &dr.vertices[std::size_t(v) * kStride];
        std::memcpy(d, clip, 4 * sizeof(float));
        std::memcpy(d + 4, var, std::size_t(std::min(nv, int(kPbrVaryings))) * sizeof(float));
        const int m = dr.more_count();
        if (m) std::memcpy(&dr.more[std::size_t(v) * std::size_t(m)], var + kPbrVaryings, std::size_t(m) * sizeof(float));
    }

    void triangle(std::size_t draw, std::uint32_t prim, TriangleFate fate, bool clipped, const TriangleSetup* t) {
        DrawEvents& e = *events_[draw];
        const std::uint32_t seq = e.seq[prim]++;
        std::lock_guard<std::mutex> lock(e.mutex);
        std::uint32_t slot = kNone;
        if (t) {
            slot = std::uint32_t(e.setups.size());
            e.setups.push_back(*t);
        }
        e.events.push_back({prim, seq, true, fate, clipped, slot});
    }

    void binned(std::size_t draw, std::uint32_t prim, int tile) {
        DrawEvents& e = *events_[draw];
        const std::uint32_t seq = e.seq[prim]++;
        std::lock_guard<std::mutex> lock(e.mutex);
        e.events.push_back({prim, seq, false, TriangleFate::SetUp, false, std::uint32_t(tile)});
    }

    void fragments(std::size_t draw, std::uint32_t prim, int bx, int by, std::uint32_t mask, std::uint32_t pass,
                   const float* z) {
        // A tile is run by one thread at a time: its list needs no lock.
        TileRecord& t = rec_.tiles[std::size_t(rec_.tile_of(bx, by))];
        BlockRecord b;
        b.piece = rec_.draws[draw].first_triangle + prim;  // the triangle, until finish()
        b.bx = std::uint16_t(bx);
        b.by = std::uint16_t(by);
        b.mask = std::uint16_t(mask);
        b.pass = std::uint16_t(pass);
        b.shaded = 0;
        b.live = 0;
        b.z = std::uint32_t(t.z.size());  // the depths come with samples(), right after
        b.masks = std::uint32_t(t.masks.size());
        t.blocks.push_back(b);
        (void)z;
    }

    void samples(int bx, int by, const SampleCoverage& sc) {
        // Right after fragments() for the same block, on the same thread.
        TileRecord& t = rec_.tiles[std::size_t(rec_.tile_of(bx, by))];
        for (int s = 0; s < sc.count; ++s)
            for (std::uint32_t m = sc.cover[s] & 0xFFFFu; m; m &= m - 1) t.z.push_back(sc.z[s][__builtin_ctz(m)]);
        if (sc.count == 1) return;
        for (int s = 0; s < sc.count; ++s) t.masks.push_back(std::uint16_t(sc.cover[s]));
        for (int s = 0; s < sc.count; ++s) t.masks.push_back(std::uint16_t(sc.pass[s]));
    }

    void shaded(std::size_t draw, int x, int y, std::uint32_t prim, std::uint32_t in_mask, std::uint32_t live) {
        // The tile's thread calls this after fragments() for the same block:
        // today right after it; searched from the back so that a pipeline
        // shading later in the tile is recorded as well.
        std::vector<BlockRecord>& blocks = rec_.tiles[std::size_t(rec_.tile_of(x, y))].blocks;
        const std::uint32_t tri = rec_.draws[draw].first_triangle + prim;
        // Two pieces of a clipped triangle may share a block: the one whose
        // coverage holds the shaded lanes, not shaded yet.
        for (std::size_t i = blocks.size(); i-- > 0;) {
            BlockRecord& b = blocks[i];
            if (b.bx == x && b.by == y && b.piece == tri && b.shaded == 0 && (b.mask & in_mask) == in_mask) {
                b.shaded = std::uint16_t(in_mask);
                b.live = std::uint16_t(live);
                return;
            }
        }
    }

    Recording& rec_;
    std::vector<std::unique_ptr<DrawEvents>> events_;  // per draw
    std::mutex mismatch_mutex_;
};

void RecordingObserver::finish() {
    for (std::size_t di = 0; di < rec_.draws.size(); ++di) {
        const DrawRecord& d = rec_.draws[di];
        std::vector<BinEvent>& events = events_[di]->events;
        const std::vector<TriangleSetup>& setups = events_[di]->setups;
        std::sort(events.begin(), events.end(), [](const BinEvent& a, const BinEvent& b) {
            return a.prim != b.prim ? a.prim < b.prim : a.seq < b.seq;
        });
        std::size_t e = 0;
        for (std::uint32_t prim = 0; prim < d.triangle_count; ++prim) {
            TriangleRecord& tr = rec_.triangles[d.first_triangle + prim];
            tr.first_piece = std::uint32_t(rec_.pieces.size());
            bool any_setup = false, any_back = false;
            TriangleFate last = TriangleFate::Invalid;
            for (; e < events.size() && events[e].prim == prim; ++e) {
                const BinEvent& ev = events[e];
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
                        rec_.setups.push_back(setups[ev.value]);
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
        events_[di].reset();
    }
    // Each tile runs its bins in submission order: pieces in order.
    for (std::size_t p = 0; p < rec_.pieces.size(); ++p) {
        const PieceRecord& pr = rec_.pieces[p];
        for (std::uint32_t i = 0; i < pr.tile_count; ++i)
            rec_.tiles[rec_.piece_tiles[pr.first_tile + i]].pieces.push_back(std::uint32_t(p));
    }
    // A block belongs to the one piece of its triangle that covers its
    // first covered sample (pieces of a clipped triangle never overlap).
    const SamplePattern& sp = sample_pattern(rec_.samples);
    for (TileRecord& t : rec_.tiles)
        for (BlockRecord& b : t.blocks) {
            const TriangleRecord& tr = rec_.triangles[b.piece];
            std::uint32_t piece = tr.first_piece;
            if (tr.piece_count > 1) {
                int s = 0;
                while (!rec_.cover(t, b, s)) ++s;
                const int lane = __builtin_ctz(rec_.cover(t, b, s));
                const int x = b.bx + lane_x(lane), y = b.by + lane_y(lane);
                for (std::uint32_t k = 0; k < tr.piece_count; ++k) {
                    const PieceRecord& pr = rec_.pieces[tr.first_piece + k];
                    if (pr.setup == kNone) continue;
                    const TriangleSetup& st = rec_.setups[pr.setup];
                    bool inside = true;
                    for (int e = 0; e < 3; ++e)
                        inside &= edge_at_pixel(st, e, x, y) + std::int64_t(st.A[e]) * sp.fixed_x(s) +
                                      std::int64_t(st.B[e]) * sp.fixed_y(s) >= 0;
                    if (inside) {
                        piece = tr.first_piece + k;
                        break;
                    }
                }
            }
            b.piece = piece;
        }
}

double ms_since(std::chrono::steady_clock::time_point t0) {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

} // namespace

void record_frame(FrameSetup& s, Recording& rec) {
    rec = Recording{};
    rec.width = s.width();
    rec.height = s.height();
    rec.tile_size = s.renderer->tile_size();
    rec.tiles_x = (rec.width + rec.tile_size - 1) / rec.tile_size;
    rec.tiles_y = (rec.height + rec.tile_size - 1) / rec.tile_size;
    rec.tiles.resize(std::size_t(rec.tiles_x) * rec.tiles_y);
    rec.samples = s.settings.samples;
    rec.visibility = s.settings.visibility;
    std::size_t total = 0;
    for (const Mesh& m : s.scene.meshes)
        if (m.topology == Mesh::Topology::Triangles) total += m.indices.size() / 3;
    rec.triangles.resize(total);
    rec.fb.resize(rec.width, rec.height);

    RecordingObserver obs(rec);
    const auto t0 = std::chrono::steady_clock::now();
    s.scene_renderer->render(s.settings, rec.fb, nullptr, [&](const SceneDraw& d) {
        const Mesh& mesh = s.scene.meshes[std::size_t(d.mesh)];
        const std::size_t n = mesh.indices.size();
        const std::uint32_t prims = d.state.topology == Topology::Lines ? std::uint32_t(n / 2)
                                    : d.state.topology == Topology::Points ? std::uint32_t(n) : 0;
        return obs.tap(d.mesh, d.first_triangle, d.triangle_count, d.vertex_count, d.state, draw_varyings(s, d), prims);
    });
    obs.finish();
    rec.record_ms = ms_since(t0);
    rec.stats = s.renderer->stats();
}

void draw_upto(FrameSetup& s, std::uint64_t triangles, Framebuffer& fb) {
    fb.resize(s.width(), s.height());
    std::uint64_t total = 0;
    for (const Mesh& m : s.scene.meshes)
        if (m.topology == Mesh::Topology::Triangles) total += m.indices.size() / 3;
    // The renderer stops before the first draw past the limit: at the total,
    // line and point draws after the last triangle would be left out.
    s.scene_renderer->render(s.settings, fb, nullptr, NoTaps{}, triangles >= total ? kAllTriangles : triangles);
}

void draw_plain(FrameSetup& s, Framebuffer& fb) {
    fb.resize(s.width(), s.height());
    s.scene_renderer->render(s.settings, fb);
}

} // namespace prast::stepper

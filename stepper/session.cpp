// The command interpreter; see session.h.
#include "stepper/session.h"

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <mutex>
#include <sstream>
#include <stdexcept>

#include "scene/write_image.h"
#include "shading/tonemap.h"
#include "stepper/explain.h"
#include "stepper/format.h"
#include "stepper/replay.h"
#include "stepper/stages.h"
#include "stepper/views.h"

namespace prast::stepper {

std::vector<std::string> split_words(const std::string& line) {
    std::vector<std::string> words;
    std::string w;
    for (char c : line) {
        if (c == ' ' || c == '\t' || c == '\r' || c == '\n') {
            if (!w.empty()) words.push_back(w);
            w.clear();
        } else {
            w += c;
        }
    }
    if (!w.empty()) words.push_back(w);
    return words;
}

bool parse_int(const std::string& word, long lo, long hi, long& out) {
    // Digits only (an optional '-'), at most 18 of them: no overflow, no "1e3", no "0x10".
    std::size_t i = word.size() > 1 && word[0] == '-' ? 1 : 0;
    if (word.empty() || word.size() - i > 18 || i == word.size()) return false;
    long v = 0;
    for (; i < word.size(); ++i) {
        if (word[i] < '0' || word[i] > '9') return false;
        v = v * 10 + (word[i] - '0');
    }
    if (word[0] == '-') v = -v;
    if (v < lo || v > hi) return false;
    out = v;
    return true;
}

namespace {

// Writes bytes next to `path` under a temporary name, then renames it over
// `path`: no truncated file is ever left behind.
void write_bytes_atomic(const std::string& path, const std::vector<std::uint8_t>& bytes) {
    const std::string tmp = path + ".tmp";
    std::FILE* f = std::fopen(tmp.c_str(), "wb");
    if (!f) throw std::runtime_error(path + ": cannot write (" + std::strerror(errno) + ")");
    const bool ok = std::fwrite(bytes.data(), 1, bytes.size(), f) == bytes.size();
    if (std::fclose(f) != 0 || !ok || std::rename(tmp.c_str(), path.c_str()) != 0) {
        const std::string why = std::strerror(errno);
        std::remove(tmp.c_str());
        throw std::runtime_error(path + ": cannot write (" + why + ")");
    }
}

Reply error(const std::string& message) { return Reply{false, false, "error: " + message + "\n"}; }

std::string count_range(long n) { return n > 0 ? "0.." + std::to_string(n - 1) : "none"; }

// Checks a re-rendered frame against the recording: the same events in the
// same order, and the values the stepper recomputes equal to the pipeline's.
class VerifyObserver {
public:
    VerifyObserver(const FrameSetup& s, const Recording& rec)
        : s_(s), rec_(rec), ctx_(s.shading_context()), cursor_(rec.tiles.size(), 0) {}

    // The observer of one draw.
    struct Tap {
        static constexpr bool enabled = true;
        VerifyObserver* v;
        std::size_t draw;
        void vertex(std::uint32_t i, const float* clip, const float* var, int nv) { v->vertex(draw, i, clip, var, nv); }
        void triangle(std::uint32_t, TriangleFate, bool, const TriangleSetup*) {}
        void binned(std::uint32_t, int) {}
        void fragments(std::uint32_t prim, int bx, int by, std::uint32_t mask, std::uint32_t pass, const float*) {
            v->fragments(draw, prim, bx, by, mask, pass);
        }
        void samples(std::uint32_t, int bx, int by, const SampleCoverage& sc) { v->samples(bx, by, sc); }
        template <int NV>
        void shaded(const FragmentBlock<NV>& in, const FragmentOut& out, std::uint32_t live) {
            v->shaded(draw, in, out, live);
        }
    };
    Tap tap() { return Tap{this, draws_++}; }

    void vertex(std::size_t draw, std::uint32_t v, const float* clip, const float* var, int nv) {
        const DrawRecord& d = rec_.draws[draw];
        ++vertices_;
        if (nv != d.varyings)
            return fail("draw " + std::to_string(draw) + " writes " + std::to_string(nv) + " varyings, the recording keeps " +
                        std::to_string(d.varyings));
        float r[kMaxStride];
        d.full_vertex(v, r);
        if (std::memcmp(r, clip, 4 * sizeof(float)) || std::memcmp(r + 4, var, std::size_t(nv) * sizeof(float)))
            fail("vertex " + std::to_string(v) + " of draw " + std::to_string(draw) + " differs");
    }

    void fragments(std::size_t draw, std::uint32_t prim, int bx, int by, std::uint32_t mask, std::uint32_t pass) {
        const std::size_t tile = std::size_t(rec_.tile_of(bx, by));
        const TileRecord& t = rec_.tiles[tile];
        ++blocks_;
        if (cursor_[tile] >= t.blocks.size()) return fail("tile " + std::to_string(tile) + " has more blocks");
        const BlockRecord& b = t.blocks[cursor_[tile]++];
        const std::uint32_t tri = rec_.draws[draw].first_triangle + prim;
        if (!(b.bx == bx && b.by == by && b.mask == mask && b.pass == pass && rec_.pieces[b.piece].triangle == tri))
            fail("block " + std::to_string(bx) + "," + std::to_string(by) + " of tri " + std::to_string(tri) +
                 " differs from the recording");
    }

    // Right after fragments(): the block's samples against the recording.
    void samples(int bx, int by, const SampleCoverage& sc) {
        const std::size_t tile = std::size_t(rec_.tile_of(bx, by));
        const TileRecord& t = rec_.tiles[tile];
        if (cursor_[tile] == 0 || cursor_[tile] > t.blocks.size()) return;
        const BlockRecord& b = t.blocks[cursor_[tile] - 1];
        bool same = sc.count == rec_.samples;
        for (int s = 0; s < sc.count && same; ++s) {
            same = rec_.cover(t, b, s) == (sc.cover[s] & 0xFFFFu) && rec_.pass(t, b, s) == (sc.pass[s] & 0xFFFFu);
            for (std::uint32_t m = sc.cover[s] & 0xFFFFu; m && same; m &= m - 1) {
                const int l = __builtin_ctz(m);
                same = rec_.depth(t, b, s, l) == sc.z[s][l];
            }
            samples_ += std::uint64_t(__builtin_popcount(sc.cover[s] & 0xFFFFu));
        }
        if (!same) fail("block " + std::to_string(bx) + "," + std::to_string(by) +
                        ": sample coverage, depth tests or depths differ from the recording");
    }

    template <int NV>
    void shaded(std::size_t draw, const FragmentBlock<NV>& in, const FragmentOut& out, std::uint32_t live) {
        // The recorded block of this (block, triangle): shading may come
        // right after fragments() or later in the tile (visibility pass).
        const std::size_t tile = std::size_t(rec_.tile_of(in.x, in.y));
        const std::vector<BlockRecord>& blocks = rec_.tiles[tile].blocks;
        const std::uint32_t tri = rec_.draws[draw].first_triangle + in.prim_id;
        auto same_inputs = [&](const FragmentBlock<NV>& ri) {
            return !std::memcmp(ri.var, in.var, sizeof in.var) && !std::memcmp(ri.z, in.z, sizeof in.z) &&
                   ri.mask == in.mask && ri.front_facing == in.front_facing && ri.prim_id == in.prim_id &&
                   ri.centroid_mask == in.centroid_mask &&
                   (!in.centroid_mask || !std::memcmp(ri.centre_var, in.centre_var, sizeof in.centre_var));
        };
        // The pieces of a clipped triangle can each shade the same lanes of a
        // block (a pixel on their shared edge, its samples split between them):
        // the block is the latest of those whose replay gives the rasterizer's
        // inputs, and the latest of them all if none does.
        std::size_t latest = 0;
        const BlockRecord* found = nullptr;
        ReplayedBlock rb;
        for (std::size_t i = cursor_[tile]; i > 0 && !found; --i) {
            const BlockRecord& c = blocks[i - 1];
            if (!(c.bx == in.x && c.by == in.y && rec_.pieces[c.piece].triangle == tri && c.shaded == in.mask)) continue;
            if (!latest) latest = i;
            replay_block(s_, rec_, c, rb);
            if (rb.varyings == NV && same_inputs(program_block<NV>(rb))) found = &c;
        }
        if (!latest) return fail("a shaded block the recording does not have");
        if (!found) replay_block(s_, rec_, blocks[latest - 1], rb);
        const BlockRecord& b = found ? *found : blocks[latest - 1];
        ++shaded_blocks_;
        const std::string where = "block " + std::to_string(in.x) + "," + std::to_string(in.y) + " of tri " +
                                  std::to_string(rec_.pieces[b.piece].triangle);
        if (live != b.live) fail(where + ": written lanes differ");
        if (rb.varyings != NV) return fail(where + ": replayed with " + std::to_string(rb.varyings) + " varyings, drawn with " +
                                           std::to_string(NV));
        if (!found) fail(where + ": recomputed varyings or depths differ from the rasterizer's");
        centroid_lanes_ += std::uint64_t(__builtin_popcount(in.centroid_mask));
        const BoundMaterial& bm = material_of(s_, rec_, rec_.pieces[b.piece].triangle);
        for (std::uint32_t m = live; m; m &= m - 1) {
            const int l = __builtin_ctz(m);
            const LaneShading sh = shade_lane(ctx_, bm, rb, l);
            ++pixels_;
            const float c[3] = {out.r[l], out.g[l], out.b[l]};
            if (std::memcmp(c, &sh.Lo, sizeof c) || sh.killed || !sh.matches_shade_surface)
                fail(where + " lane " + std::to_string(l) + ": recomputed shading " + vec(sh.Lo) +
                     " differs from the shader's " + vec(glm::vec3(c[0], c[1], c[2])));
        }
    }

    void fail(const std::string& what) {
        std::lock_guard<std::mutex> lock(mutex_);
        if (failures_++ == 0) first_ = what;
    }

    const FrameSetup& s_;
    const Recording& rec_;
    const ShadingContext ctx_;
    std::vector<std::size_t> cursor_;
    std::size_t draws_ = 0;
    std::atomic<std::uint64_t> vertices_{0}, blocks_{0}, samples_{0}, shaded_blocks_{0}, pixels_{0}, centroid_lanes_{0};
    std::uint64_t line_prims_ = 0, line_pixels_ = 0;
    std::mutex mutex_;
    std::uint64_t failures_ = 0;
    std::string first_;
};

double ms_since(std::chrono::steady_clock::time_point t0) {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

double median(std::vector<double> v) {
    std::sort(v.begin(), v.end());
    const std::size_t n = v.size();
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

} // namespace

Reply Session::help() const {
    std::string t =
        "commands (a triangle number N counts in submission order over all draws, 0.." +
        std::to_string(long(rec_.triangle_count()) - 1) + "):\n"
        "  help                 this list\n"
        "  frame                the frame's counters, camera, lights and the recording's size\n"
        "  tri N                triangle N: clip coordinates, clipping, fixed-point setup, edges, bins, tile walk\n"
        "  tri draw D triangle P  the same for triangle P of draw D (the name pixel and render --pixel print)\n"
        "  tile X Y [FILTER]    tile X Y (column, row): a summary, then its bins in order; FILTER: tri N,\n"
        "                       pixel X Y (the bins that cover that pixel) or --summary\n"
        "  pixel X Y            the history of pixel X Y and the shading breakdown of the winning fragment\n"
        "  draws                one line a draw: mesh, material, primitives, visible or culled, alpha, program\n"
        "  draw N               draw N's state: material factors, maps and samplers, cull/depth/blend, lights\n"
        "  textures             every texture ID (material maps, shadowL maps, env) with size, format, levels\n"
        "  texture ID [LEVEL [FILE]]  a texture's format and levels; writes the level (default 0) as a PNG\n"
        "                       (default texture-ID-level-L.png)\n"
        "  texel ID LEVEL X Y   one texel of that level (X, Y as in its PNG): stored and linear values\n"
        "  json VIEW ...        the JSON of draws, draw, textures, texture, texel, vertices or tile, on one line\n"
        "  vertices N [FIRST [COUNT]]  draw N's vertices in and out of the vertex stage (16 from 0; at most 1000)\n"
        "  upto N [FILE]        write the image after the first N triangles (default upto-N.png); pixel then\n"
        "                       explains a pixel as it stands after them (upto all: at the frame's end again)\n"
        "  stage NAME [FILE]    write one stage image (default stage-NAME.png); NAME is one of:\n"
        "                      ";
    int col = 22;
    for (const StageInfo& st : stage_list()) {
        const int len = int(std::strlen(st.name)) + 1;
        if (col + len > 100) {
            t += "\n                      ";
            col = 22;
        }
        t += " ";
        t += st.name;
        col += len;
    }
    t += "\n"
         "  verify               re-render the frame and compare every recomputed number with the pipeline's\n"
         "  cost                 time and memory of a recording against a plain frame\n"
         "  quit                 end the session (so does the end of the input)\n";
    return Reply{true, false, t};
}

Reply Session::run(const std::string& line) {
    const std::vector<std::string> w = split_words(line);
    if (w.empty() || w[0][0] == '#') return Reply{};
    const std::string& cmd = w[0];
    auto args = [&](std::size_t lo, std::size_t hi) { return w.size() - 1 >= lo && w.size() - 1 <= hi; };
    long a = 0, b = 0;
    if (cmd == "help") return help();
    if (cmd == "quit" || cmd == "exit") return Reply{true, true, ""};
    if (cmd == "frame") {
        if (!args(0, 0)) return error("frame takes no arguments");
        return Reply{true, false, frame_text(s_, rec_)};
    }
    if (cmd == "tri") {
        // tri N (the frame triangle) or tri draw D triangle P, as pixel and render --pixel name it.
        if (args(4, 4) && w[1] == "draw" && w[3] == "triangle") {
            std::uint32_t tri = 0;
            if (!parse_int(w[2], 0, long(rec_.draws.size()) - 1, a) || !parse_int(w[4], 0, 1L << 40, b) ||
                !frame_triangle(rec_, a, b, tri))
                return error("tri draw '" + w[2] + "' triangle '" + w[4] + "': no such triangle (draws " +
                             count_range(long(rec_.draws.size())) + ", triangles within the draw's mesh)");
            return Reply{true, false, triangle_text(s_, rec_, tri)};
        }
        if (!args(1, 1)) return error("usage: tri N | tri draw D triangle P");
        if (!parse_int(w[1], 0, long(rec_.triangle_count()) - 1, a))
            return error("tri '" + w[1] + "': not a triangle number (" + count_range(rec_.triangle_count()) + ")");
        return Reply{true, false, triangle_text(s_, rec_, std::uint32_t(a))};
    }
    if (cmd == "json") {
        // The JSON the page's API serves for a view: one line.
        static const char* kViews[] = {"draws", "draw", "textures", "texture", "texel", "vertices", "tile"};
        if (w.size() < 2 || std::find(std::begin(kViews), std::end(kViews), w[1]) == std::end(kViews))
            return error("usage: json draws | draw N | textures | texture ID [LEVEL] | texel ID LEVEL X Y | "
                         "vertices N [FIRST [COUNT]] | tile X Y [FILTER]");
        if (w[1] == "texture" && w.size() > 4) return error("usage: json texture ID [LEVEL]");
        std::string rest;
        for (std::size_t i = 1; i < w.size(); ++i) rest += (i > 1 ? " " : "") + w[i];
        return run_view(rest, true);
    }
    if (cmd == "tile" || cmd == "draws" || cmd == "draw" || cmd == "textures" || cmd == "texture" ||
        cmd == "texel" || cmd == "vertices")
        return run_view(line, false);
    return run_rest(w);
}

Reply Session::run_view(const std::string& line, bool as_json) {
    const std::vector<std::string> w = split_words(line);
    const std::string& cmd = w[0];
    auto args = [&](std::size_t lo, std::size_t hi) { return w.size() - 1 >= lo && w.size() - 1 <= hi; };
    auto reply = [&](const auto& v) { return Reply{true, false, as_json ? v.json().dump(-1, ' ', false, nlohmann::json::error_handler_t::replace) + "\n"
                                                  : v.text()}; };
    if (cmd == "tile") {
        TileView v;
        const std::string e = make_tile(s_, rec_, std::vector<std::string>(w.begin() + 1, w.end()), v);
        return e.empty() ? reply(v) : error(e);
    }
    if (cmd == "draws") {
        if (!args(0, 0)) return error("draws takes no arguments");
        DrawsView v;
        make_draws(s_, rec_, v);
        return reply(v);
    }
    if (cmd == "draw") {
        if (!args(1, 1)) return error("usage: draw N (draws lists them)");
        DrawView v;
        const std::string e = make_draw(s_, rec_, w[1], v);
        return e.empty() ? reply(v) : error(e);
    }
    if (cmd == "textures") {
        if (!args(0, 0)) return error("textures takes no arguments");
        TexturesView v;
        make_textures(s_, rec_, v);
        return reply(v);
    }
    if (cmd == "texture") {
        if (!args(1, 3)) return error("usage: texture ID [LEVEL [FILE]] (textures lists the IDs)");
        const std::string level = w.size() > 2 ? w[2] : "";
        TextureView v;
        std::string e = make_texture(s_, rec_, w[1], level, v);
        if (!e.empty()) return error(e);
        if (as_json) return reply(v);
        const std::string file =
            w.size() > 3 ? w[3] : "texture-" + w[1] + "-level-" + std::to_string(v.level) + ".png";
        std::vector<std::uint8_t> png;
        e = texture_png(s_, rec_, w[1], level, png);
        if (!e.empty()) return error(e);
        try {
            write_bytes_atomic(file, png);
        } catch (const std::exception& ex) {
            return error(ex.what());
        }
        return Reply{true, false,
                     v.text() + "texture " + w[1] + " " + std::to_string(v.level) + " -> wrote " + file + "\n"};
    }
    if (cmd == "texel") {
        if (!args(4, 4)) return error("usage: texel ID LEVEL X Y (textures lists the IDs, texture ID the levels)");
        TexelView v;
        const std::string e = make_texel(s_, rec_, w[1], w[2], w[3], w[4], v);
        return e.empty() ? reply(v) : error(e);
    }
    if (cmd == "vertices") {
        if (!args(1, 3)) return error("usage: vertices N [FIRST [COUNT]] (draw N; FIRST 0 and COUNT " +
                                      std::to_string(kDefaultVertexRows) + " by default)");
        VerticesView v;
        const std::string e =
            make_vertices(s_, rec_, w[1], w.size() > 2 ? w[2] : "", w.size() > 3 ? w[3] : "", v);
        return e.empty() ? reply(v) : error(e);
    }
    return error("unknown command '" + cmd + "'");
}

Reply Session::run_rest(const std::vector<std::string>& w) {
    const std::string& cmd = w[0];
    auto args = [&](std::size_t lo, std::size_t hi) { return w.size() - 1 >= lo && w.size() - 1 <= hi; };
    long a = 0, b = 0;
    if (cmd == "pixel") {
        if (!args(2, 2)) return error("usage: pixel X Y");
        if (!parse_int(w[1], 0, rec_.width - 1, a) || !parse_int(w[2], 0, rec_.height - 1, b))
            return error("pixel '" + w[1] + " " + w[2] + "': outside the " + std::to_string(rec_.width) + "x" +
                         std::to_string(rec_.height) + " image");
        return Reply{true, false, pixel_text(s_, rec_, explain(int(a), int(b), upto_))};
    }
    if (cmd == "upto") {
        if (!args(1, 2)) return error("usage: upto N [FILE] | upto all");
        if (w[1] == "all") {
            if (w.size() > 2) return error("upto all takes no file (upto N FILE writes one)");
            upto_ = kAllTriangles;
            return Reply{true, false, "upto all: pixel explains a pixel at the frame's end\n"};
        }
        if (!parse_int(w[1], 0, long(rec_.triangle_count()), a))
            return error("upto '" + w[1] + "': not a triangle count (0.." + std::to_string(rec_.triangle_count()) +
                         ") or all");
        const std::string file = w.size() > 2 ? w[2] : "upto-" + std::to_string(a) + ".png";
        try {
            const std::vector<std::uint8_t> rgba = upto_rgba(std::uint64_t(a));
            write_png_atomic(file, rec_.width, rec_.height, rgba.data());
        } catch (const std::exception& e) {
            return error(e.what());
        }
        // Errors above leave the point where it was.
        upto_ = std::uint64_t(a) >= rec_.triangle_count() ? kAllTriangles : std::uint64_t(a);
        const std::string now = upto_ == kAllTriangles ? "pixel X Y explains a pixel at the frame's end\n"
                                                       : "pixel X Y now explains a pixel as it stands after these " +
                                                             std::to_string(a) + " triangles (upto all: at the end)\n";
        return Reply{true, false, "upto " + std::to_string(a) + ": wrote " + file + " (the frame after the first " +
                                      std::to_string(a) + " of " + std::to_string(rec_.triangle_count()) +
                                      " triangles)\n" + now};
    }
    if (cmd == "stage") {
        if (!args(1, 2)) return error("usage: stage NAME [FILE]");
        if (!find_stage(w[1])) return error("stage '" + w[1] + "': unknown (help lists the stages)");
        const std::string file = w.size() > 2 ? w[2] : "stage-" + w[1] + ".png";
        std::vector<std::uint8_t> rgba;
        draw_stage(s_, rec_, w[1], rgba);
        try {
            write_png_atomic(file, rec_.width, rec_.height, rgba.data());
        } catch (const std::exception& e) {
            return error(e.what());
        }
        return Reply{true, false, "stage " + w[1] + ": wrote " + file + "\n"};
    }
    if (cmd == "verify") {
        if (!args(0, 0)) return error("verify takes no arguments");
        return verify();
    }
    if (cmd == "cost") {
        if (!args(0, 0)) return error("cost takes no arguments");
        return cost();
    }
    std::string shown = cmd.size() > 40 ? cmd.substr(0, 40) + "..." : cmd;
    for (char& c : shown)
        if (static_cast<unsigned char>(c) < 32 || static_cast<unsigned char>(c) >= 127) c = '?';
    return error("unknown command '" + shown + "' (help lists the commands)");
}

std::vector<std::uint8_t> Session::stage_png(const std::string& name) {
    std::vector<std::uint8_t> rgba;
    draw_stage(s_, rec_, name, rgba);
    return encode_png(rec_.width, rec_.height, rgba.data());
}

const Framebuffer& Session::upto_frame(std::uint64_t triangles) {
    if (triangles >= rec_.triangle_count()) return rec_.fb;
    if (frame_upto_ != triangles) {
        frame_upto_ = kAllTriangles;  // a throw below leaves no half-drawn frame named
        draw_upto(s_, triangles, frame_);
        frame_upto_ = triangles;
    }
    return frame_;
}

PixelExplanation Session::explain(int x, int y, std::uint64_t upto) {
    if (upto >= rec_.triangle_count()) return explain_pixel(s_, rec_, x, y);
    return explain_pixel(s_, rec_, x, y, upto, &upto_frame(upto));
}

std::vector<std::uint8_t> Session::upto_rgba(std::uint64_t triangles) {
    const Framebuffer& fb = upto_frame(triangles);
    std::vector<std::uint8_t> rgba(std::size_t(fb.width) * fb.height * 4);
    resolve_to_srgb8(fb.color.data(), fb.width, fb.height, s_.exposure(), s_.tonemap(), rgba.data());
    return rgba;
}

std::vector<std::uint8_t> Session::upto_png(std::uint64_t triangles) {
    return encode_png(rec_.width, rec_.height, upto_rgba(triangles).data());
}

Reply Session::verify() {
    VerifyObserver obs(s_, rec_);
    Framebuffer fb(rec_.width, rec_.height);
    s_.scene_renderer->render(s_.settings, fb, nullptr, [&](const SceneDraw&) { return obs.tap(); });
    for (std::size_t t = 0; t < rec_.tiles.size(); ++t)
        if (obs.cursor_[t] != rec_.tiles[t].blocks.size()) obs.fail("tile " + std::to_string(t) + " has fewer blocks");
    if (std::memcmp(fb.color.data(), rec_.fb.color.data(), fb.color.size() * sizeof(float)) ||
        fb.depth != rec_.fb.depth)
        obs.fail("the re-rendered framebuffer differs from the recorded one");
    // Lines and points: the pipeline's observers see their vertices only, so
    // every pixel one covers is explained (set up again, covered by line.h's
    // test, depth-tested and shaded in order) and its colour compared with the frame's.
    std::vector<std::uint8_t> line_pixel(std::size_t(rec_.width) * std::size_t(rec_.height), 0);
    for (std::size_t di = 0; di < rec_.draws.size(); ++di) {
        const DrawRecord& d = rec_.draws[di];
        if (d.topology == Topology::Triangles) continue;
        for (std::uint32_t prim = 0; prim < d.primitives; ++prim) {
            const LineReplay l = replay_line(s_, rec_, di, prim);
            if (!l.drawn) continue;
            ++obs.line_prims_;
            for_each_line_pixel(l.setup, 0, 0, rec_.width - 1, rec_.height - 1,
                                [&](int x, int y) { line_pixel[std::size_t(y) * std::size_t(rec_.width) + std::size_t(x)] = 1; });
        }
    }
    for (int y = 0; y < rec_.height; ++y)
        for (int x = 0; x < rec_.width; ++x) {
            if (!line_pixel[std::size_t(y) * std::size_t(rec_.width) + std::size_t(x)]) continue;
            ++obs.line_pixels_;
            const PixelExplanation px = explain_pixel(s_, rec_, x, y);
            const float* c = rec_.fb.pixel(x, y);
            const glm::vec3 frame(c[0], c[1], c[2]);
            bool shading_ok = true;
            for (const HistoryEntry& h : px.history)
                shading_ok &= !h.shaded || h.shading.matches_shade_surface;
            if (std::memcmp(&frame, &px.linear, sizeof frame) || !shading_ok)
                obs.fail("pixel " + std::to_string(x) + "," + std::to_string(y) + " (a line or point covers it): explained " +
                         vec(px.linear) + ", the frame holds " + vec(frame));
        }
    if (rec_.layout_mismatches)
        obs.fail(std::to_string(rec_.layout_mismatches) + " vertices recorded with another varying count than the draw's");
    Framebuffer plain;
    draw_plain(s_, plain);
    if (std::memcmp(plain.color.data(), rec_.fb.color.data(), plain.color.size() * sizeof(float)))
        obs.fail("SceneRenderer::render draws a different frame");
    std::ostringstream o;
    o << "verify: re-rendered the frame and compared it with the recording\n"
      << "  " << obs.vertices_ << " vertices: clip coordinates and varyings\n"
      << "  " << obs.blocks_ << " blocks: coverage and depth-test masks, in each tile's order\n"
      << "  " << obs.samples_ << " covered samples (" << rec_.samples << " per pixel): coverage, depth test, depth\n"
      << "  " << obs.shaded_blocks_ << " shaded blocks: recomputed barycentrics, depths and varyings of all 16 lanes ("
      << obs.centroid_lanes_ << " lanes at a centroid)\n"
      << "  " << obs.pixels_ << " written pixels: recomputed shading (scalar path) against the shader's output\n";
    if (obs.line_prims_)
        o << "  " << obs.line_prims_ << " lines and points set up again, " << obs.line_pixels_
          << " pixels they cover explained: colour against the frame's\n";
    o
      << "  the framebuffer against the recording's and SceneRenderer::render's\n";
    if (obs.failures_) {
        o << "verify: FAILED (" << obs.failures_ << " differences; first: " << obs.first_ << ")\n";
        return Reply{false, false, o.str()};
    }
    o << "verify: ok, all identical\n";
    return Reply{true, false, o.str()};
}

Reply Session::cost() {
    constexpr int kRuns = 5;
    std::vector<double> plain_ms, record_ms;
    Framebuffer fb;
    for (int i = 0; i < kRuns; ++i) {
        auto t0 = std::chrono::steady_clock::now();
        draw_plain(s_, fb);
        plain_ms.push_back(ms_since(t0));
        Recording r;
        record_frame(s_, r);
        record_ms.push_back(r.record_ms);
    }
    char buf[512];
    const double plain = median(plain_ms), recorded = median(record_ms);
    std::snprintf(buf, sizeof buf,
                  "cost of a recording, %dx%d, %d thread%s, median of %d frames:\n"
                  "  plain frame (SceneRenderer::render) %.1f ms\n"
                  "  recorded frame %.1f ms (%.2fx)\n"
                  "  recording %zu bytes (%.1f MiB), plus the frame's own framebuffer %zu bytes\n",
                  rec_.width, rec_.height, s_.renderer->threads(), s_.renderer->threads() == 1 ? "" : "s", kRuns,
                  plain, recorded, recorded / plain, rec_.bytes(), double(rec_.bytes()) / 1048576.0,
                  (rec_.fb.color.size() + rec_.fb.depth.size()) * sizeof(float));
    std::ostringstream o;
    o << buf;
    return Reply{true, false, o.str()};
}

} // namespace prast::stepper

// Frames (raster/frame.h): a frame of many draws equals the same draws drawn
// one by one; the visibility pass gives exactly the bytes of shading in
// submission order (overdraw, equal depths, alpha-mask discards, double-sided
// draws, blending in between) while shading each visible pixel once; alpha
// blending and depth-only draws against hand-computed values; the tile hook
// sees every pixel once with its final colour; bad frame use is refused.
#include <doctest/doctest.h>

#include <atomic>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <mutex>
#include <stdexcept>
#include <vector>

#include <glm/glm.hpp>

#include "raster/stream_fill.h"
#include "shading/output8.h"
#include "shading/tonemap.h"
#include "tests/raster_test_util.h"

using namespace prast;
using namespace prast::test;

namespace {

// Colour from three varyings plus their derivatives (so helper lanes matter),
// and optionally a discard pattern and a translucent alpha.
struct PaintProgram {
    static constexpr int kVaryings = 3;
    const glm::vec4* clip = nullptr;
    const float* varyings = nullptr;
    bool discard = false;
    float alpha = 1.0f;
    void vertex(std::uint32_t i, float out[4], float* var) const {
        out[0] = clip[i].x; out[1] = clip[i].y; out[2] = clip[i].z; out[3] = clip[i].w;
        for (int k = 0; k < 3; ++k) var[k] = varyings[3 * i + std::uint32_t(k)];
    }
    void fragment(const FragmentBlock<3>& in, FragmentOut& out) const {
        out.kill = 0;
        for (int l = 0; l < kBlockLanes; ++l) {
            out.r[l] = in.var[0][l] + 8.0f * in.ddx(0, l);
            out.g[l] = in.var[1][l] + 8.0f * in.ddy(1, l);
            out.b[l] = in.var[2][l] * (in.front_facing ? 1.0f : 0.5f);
            out.a[l] = alpha;
            // Discard a pattern that depends on the varyings, like an alpha mask.
            if (discard && std::fmod(std::fabs(in.var[0][l] * 7.0f + in.var[1][l] * 5.0f), 1.0f) < 0.3f)
                out.kill |= 1u << l;
        }
    }
};

// What the batch-taking program below saw.
struct BatchCounters {
    std::atomic<int> several{0};  // batches of more than one block
    std::atomic<int> broken{0};   // batches breaking fragment.h's promises
};

// PaintProgram that takes sparse blocks in batches (fragment.h), shading each
// block as fragment() does.
struct BatchPaintProgram : PaintProgram {
    BatchCounters* counters = nullptr;
    void fragment_batch(const FragmentBlock<3>* const* in, FragmentOut* const* out, int count) const {
        int lanes = 0;
        for (int b = 0; b < count; ++b) lanes += __builtin_popcount(in[b]->mask);
        if (count < 1 || count > kMaxBatchBlocks || lanes > kBlockLanes) ++counters->broken;
        if (count > 1) ++counters->several;
        for (int b = 0; b < count; ++b) fragment(*in[b], *out[b]);
    }
};

// A depth-only program: no fragment().
struct DepthProgram {
    static constexpr int kVaryings = 0;
    const glm::vec4* clip = nullptr;
    void vertex(std::uint32_t i, float out[4], float*) const {
        out[0] = clip[i].x; out[1] = clip[i].y; out[2] = clip[i].z; out[3] = clip[i].w;
    }
};

struct Draw {
    std::vector<std::uint32_t> idx;
    DrawState state;
    bool discard = false, depth_only = false;
    float alpha = 1.0f;
};

// Overlapping triangles at random depths (with exact ties: some triangles
// are drawn twice, or share a plane), in several draws of different kinds.
struct OverdrawScene {
    int W, H;
    std::vector<glm::vec4> clip;
    std::vector<float> var;
    std::vector<Draw> draws;

    OverdrawScene(int w, int h, std::uint64_t seed, bool with_blending) : W(w), H(h) {
        Random rng(seed);
        auto tri = [&](std::vector<std::uint32_t>& idx, double size) {
            const double cx = rng.range(-0.1, 1.1) * W, cy = rng.range(-0.1, 1.1) * H;
            const double z = rng.range(-0.9, 0.9);
            const bool flat = rng.uniform() < 0.3;  // equal depth at every pixel: ties
            for (int k = 0; k < 3; ++k) {
                const double zk = flat ? std::floor(z * 8.0) / 8.0 : z + rng.range(-0.3, 0.3);
                clip.push_back(at(cx + rng.range(-size, size), cy + rng.range(-size, size), W, H, zk,
                                  rng.range(0.5, 2.0)));
                var.insert(var.end(), {float(rng.uniform()), float(rng.uniform()), float(rng.uniform())});
            }
            const std::uint32_t b = std::uint32_t(clip.size() - 3);
            idx.insert(idx.end(), {b, b + 1, b + 2});
            if (rng.uniform() < 0.1) idx.insert(idx.end(), {b, b + 1, b + 2});  // the same triangle again
        };
        for (int d = 0; d < 7; ++d) {
            Draw dr;
            const int n = d == 0 ? 2600 : 300;  // the first draw spans several binning jobs
            for (int i = 0; i < n; ++i) tri(dr.idx, d == 0 ? rng.range(3.0, 30.0) : rng.range(10.0, 120.0));
            dr.state.cull = d % 2 ? CullMode::None : CullMode::Back;  // double-sided draws
            if (d == 2) {  // alpha MASK
                dr.discard = true;
                dr.state.may_discard = true;
            }
            if (d == 3) dr.depth_only = true;
            if (d == 4) dr.state.depth_write = false;
            if (d == 5 && with_blending) {
                dr.state.blend = Blend::Alpha;
                dr.state.depth_write = false;
                dr.alpha = 0.375f;
            }
            draws.push_back(dr);
        }
    }

    // batch: submit the batch-taking program, counting into it.
    void submit(Renderer& r, BatchCounters* batch = nullptr) const {
        for (const Draw& d : draws) {
            if (d.depth_only) {
                DepthProgram p{clip.data()};
                r.submit(p, std::uint32_t(clip.size()), d.idx.data(), d.idx.size(), d.state);
            } else if (batch) {
                BatchPaintProgram p;
                p.clip = clip.data();
                p.varyings = var.data();
                p.discard = d.discard;
                p.alpha = d.alpha;
                p.counters = batch;
                r.submit(p, std::uint32_t(clip.size()), d.idx.data(), d.idx.size(), d.state);
            } else {
                PaintProgram p{clip.data(), var.data(), d.discard, d.alpha};
                r.submit(p, std::uint32_t(clip.size()), d.idx.data(), d.idx.size(), d.state);
            }
        }
    }
    void draw_one_by_one(Renderer& r, Framebuffer& fb) const {
        for (const Draw& d : draws) {
            if (d.depth_only) {
                DepthProgram p{clip.data()};
                r.draw(fb, p, std::uint32_t(clip.size()), d.idx.data(), d.idx.size(), d.state);
            } else {
                PaintProgram p{clip.data(), var.data(), d.discard, d.alpha};
                r.draw(fb, p, std::uint32_t(clip.size()), d.idx.data(), d.idx.size(), d.state);
            }
        }
    }
};

FrameOptions frame_options(FrameOptions::Visibility v, int samples = 1) {
    FrameOptions o;
    o.visibility = v;
    o.samples = samples;
    o.clear_color[0] = 0.25f; o.clear_color[1] = 0.5f; o.clear_color[2] = 0.125f; o.clear_color[3] = 1.0f;
    o.clear_depth = 1.0f;
    return o;
}

std::uint64_t render_frame(const OverdrawScene& sc, int threads, int tile, FrameOptions::Visibility v,
                           FrameStats* stats = nullptr, int samples = 1, BatchCounters* batch = nullptr) {
    Renderer r({threads, tile});
    Framebuffer fb(sc.W, sc.H);
    r.begin_frame();
    r.begin(fb, frame_options(v, samples));
    sc.submit(r, batch);
    r.end();
    if (stats) *stats = r.stats();
    return hash_framebuffer(fb);
}

// What a frame's tile hook was handed (it runs on the worker threads): each
// pixel's RGBA, how many times the pixel came, and the uniform tiles.
struct HookCapture {
    int W, H;
    std::vector<float> seen;
    std::vector<int> count;
    int uniform_tiles = 0;
    std::mutex m;
    HookCapture(int w, int h) : W(w), H(h), seen(std::size_t(w) * std::size_t(h) * 4, -7.0f), count(std::size_t(w) * std::size_t(h), 0) {}
    void operator()(const TileView& v) {
        std::lock_guard<std::mutex> lock(m);
        uniform_tiles += v.uniform;
        for (int y = 0; y < v.height; ++y)
            for (int x = 0; x < v.width; ++x) {
                const std::size_t p = std::size_t(v.y0 + y) * std::size_t(W) + std::size_t(v.x0 + x);
                ++count[p];
                std::memcpy(&seen[p * 4], &v.rgba[std::size_t(y) * v.row + 4 * std::size_t(x)], 4 * sizeof(float));
            }
    }
    int not_once() const {
        int n = 0;
        for (int c : count) n += c != 1;
        return n;
    }
};

} // namespace

TEST_SUITE("frame") {

TEST_CASE("frame: many draws in one frame equal the same draws drawn one by one") {
    const OverdrawScene sc(203, 131, 7, true);
    // Draw by draw over a cleared target, each draw its own frame, shading in order.
    Renderer r({2, 64});
    Framebuffer fb(sc.W, sc.H);
    fb.clear(0.25f, 0.5f, 0.125f, 1.0f);
    sc.draw_one_by_one(r, fb);
    const std::uint64_t ref = hash_framebuffer(fb);
    for (int threads : {1, 2, 3, 8})
        for (int tile : {16, 32, 64, 128, 256})
            for (auto v : {FrameOptions::Visibility::Auto, FrameOptions::Visibility::Always,
                           FrameOptions::Visibility::Never}) {
                CAPTURE(threads);
                CAPTURE(tile);
                CAPTURE(int(v));
                CHECK(render_frame(sc, threads, tile, v) == ref);
            }
}

TEST_CASE("visibility: byte-identical to shading in order, each visible pixel shaded once") {
    for (bool blending : {false, true}) {
        CAPTURE(blending);
        const OverdrawScene sc(256, 160, 11 + blending, blending);
        FrameStats in_order, visible, automatic;
        const std::uint64_t ref = render_frame(sc, 1, 64, FrameOptions::Visibility::Never, &in_order);
        CHECK(render_frame(sc, 2, 32, FrameOptions::Visibility::Always, &visible) == ref);
        CHECK(render_frame(sc, 3, 128, FrameOptions::Visibility::Auto, &automatic) == ref);
        // The depth test saw the same fragments in the same order.
        CHECK(visible.fragments_covered == in_order.fragments_covered);
        CHECK(visible.fragments_depth_killed == in_order.fragments_depth_killed);
        CHECK(visible.fragments_written == in_order.fragments_written);
        CHECK(visible.fragments_shader_killed == in_order.fragments_shader_killed);
        // Heavy overdraw and discards were exercised.
        CHECK(in_order.fragments_written > 3u * 256u * 160u);
        CHECK(in_order.fragments_shader_killed > 1000u);
        CHECK(in_order.fragments_depth_killed > 10000u);
        // Through the visibility pass far fewer fragments were shaded.
        CHECK(visible.fragments_shaded * 2 < in_order.fragments_shaded);
    }
}

TEST_CASE("batches: sparse blocks shaded together give the bytes and counts of block by block") {
    for (bool blending : {false, true}) {
        const OverdrawScene sc(256, 160, 21 + blending, blending);
        for (int samples : {1, 4})
            for (auto v : {FrameOptions::Visibility::Auto, FrameOptions::Visibility::Always,
                           FrameOptions::Visibility::Never}) {
                CAPTURE(blending);
                CAPTURE(samples);
                CAPTURE(int(v));
                FrameStats plain, batched;
                BatchCounters counters;
                const std::uint64_t ref = render_frame(sc, 1, 64, v, &plain, samples);
                CHECK(render_frame(sc, 2, 32, v, &batched, samples, &counters) == ref);
                CHECK(counters.broken == 0);
                CHECK(counters.several > 100);
                CHECK(batched.fragments_covered == plain.fragments_covered);
                CHECK(batched.fragments_depth_killed == plain.fragments_depth_killed);
                CHECK(batched.fragments_shaded == plain.fragments_shaded);
                CHECK(batched.fragments_shader_killed == plain.fragments_shader_killed);
                CHECK(batched.fragments_written == plain.fragments_written);
                CHECK(batched.quads_shaded == plain.quads_shaded);
            }
    }
}

TEST_CASE("visibility: a single opaque draw shades each covered pixel exactly once") {
    // Without discards or blending, the shader runs once per visible pixel:
    // fragments_shaded equals the number of pixels that end up covered.
    const OverdrawScene sc(160, 120, 5, false);
    Renderer r({2, 32});
    Framebuffer fb(sc.W, sc.H);
    FrameOptions o = frame_options(FrameOptions::Visibility::Always);
    r.begin_frame();
    r.begin(fb, o);
    PaintProgram p{sc.clip.data(), sc.var.data(), false, 1.0f};
    r.submit(p, std::uint32_t(sc.clip.size()), sc.draws[0].idx.data(), sc.draws[0].idx.size(), sc.draws[0].state);
    r.end();
    std::uint64_t covered = 0;
    for (float d : fb.depth) covered += d < 1.0f;
    CHECK(covered > 5000u);
    CHECK(r.stats().fragments_shaded == covered);
    CHECK(r.stats().fragments_written > covered);
}

namespace {
// Per pixel: the last triangle whose depth test passed there (from
// fragments(), in order) and the triangle shaded there (from shaded()).
struct WinnerObserver {
    static constexpr bool enabled = true;
    int W, H;
    std::mutex m;
    std::vector<std::int64_t> last_pass, shaded_prim;
    std::vector<int> shaded_count;
    bool order_broken = false;
    std::vector<std::int64_t> last_seen;
    WinnerObserver(int w, int h)
        : W(w), H(h), last_pass(std::size_t(w) * h, -1), shaded_prim(std::size_t(w) * h, -1),
          shaded_count(std::size_t(w) * h, 0), last_seen(std::size_t(w) * h, -1) {}
    void vertex(std::uint32_t, const float*, const float*, int) {}
    void triangle(std::uint32_t, TriangleFate, bool, const TriangleSetup*) {}
    void binned(std::uint32_t, int) {}
    void fragments(std::uint32_t prim, int bx, int by, std::uint32_t mask, std::uint32_t pass, const float*) {
        std::lock_guard<std::mutex> lock(m);
        for (int l = 0; l < kBlockLanes; ++l) {
            const std::size_t p = std::size_t(by + lane_y(l)) * std::size_t(W) + std::size_t(bx + lane_x(l));
            if (mask & (1u << l)) {
                order_broken |= std::int64_t(prim) < last_seen[p];
                last_seen[p] = prim;
            }
            if (pass & (1u << l)) last_pass[p] = prim;
        }
    }
    template <int NV>
    void shaded(const FragmentBlock<NV>& in, const FragmentOut&, std::uint32_t live) {
        std::lock_guard<std::mutex> lock(m);
        for (int l = 0; l < kBlockLanes; ++l)
            if (live & (1u << l)) {
                const std::size_t p = std::size_t(in.y + lane_y(l)) * std::size_t(W) + std::size_t(in.x + lane_x(l));
                shaded_prim[p] = in.prim_id;
                ++shaded_count[p];
            }
    }
};
} // namespace

TEST_CASE("observer: through the visibility pass every fragment comes in order, each winner is shaded once") {
    const OverdrawScene sc(150, 110, 21, false);
    const Draw& d = sc.draws[0];
    for (int threads : {1, 3}) {
        CAPTURE(threads);
        Renderer r({threads, 32});
        Framebuffer fb(sc.W, sc.H);
        WinnerObserver obs(sc.W, sc.H);
        PaintProgram p{sc.clip.data(), sc.var.data(), false, 1.0f};
        r.begin_frame();
        r.begin(fb, frame_options(FrameOptions::Visibility::Always));
        r.submit(p, std::uint32_t(sc.clip.size()), d.idx.data(), d.idx.size(), d.state, obs);
        r.end();
        CHECK(!obs.order_broken);
        int wrong = 0, shaded = 0;
        for (std::size_t i = 0; i < obs.last_pass.size(); ++i) {
            wrong += obs.shaded_prim[i] != obs.last_pass[i];
            wrong += obs.shaded_count[i] > 1;
            shaded += obs.shaded_count[i];
        }
        CHECK(wrong == 0);
        CHECK(std::uint64_t(shaded) == r.stats().fragments_shaded);
        CHECK(r.stats().fragments_written > std::uint64_t(shaded));
    }
}

TEST_CASE("blend: alpha over a known background is src * a + dst * (1 - a), depth tested, not written") {
    const int W = 32, H = 32;
    // An opaque quad in the left half at z_ndc 0 (window depth 0.5), then a
    // blended full-screen quad at z_ndc 0.5 (0.75): behind the opaque one, in
    // front of the background.
    std::vector<glm::vec4> clip = {at(0, 0, W, H, 0.0), at(0, H, W, H, 0.0), at(16, H, W, H, 0.0), at(16, 0, W, H, 0.0),
                                   at(0, 0, W, H, 0.5), at(0, H, W, H, 0.5), at(W, H, W, H, 0.5), at(W, 0, W, H, 0.5)};
    std::vector<float> var = {0.5f, 0.25f, 1.0f, 0.5f, 0.25f, 1.0f, 0.5f, 0.25f, 1.0f, 0.5f, 0.25f, 1.0f,
                              1.0f, 0.75f, 0.0f, 1.0f, 0.75f, 0.0f, 1.0f, 0.75f, 0.0f, 1.0f, 0.75f, 0.0f};
    const std::vector<std::uint32_t> opaque = {0, 1, 2, 0, 2, 3}, glass = {4, 5, 6, 4, 6, 7};
    for (int samples : {1, 4}) {
        CAPTURE(samples);
        Renderer r({2, 16});
        Framebuffer fb(W, H);
        FrameOptions o;
        o.samples = samples;
        o.clear_color[0] = 0.0f; o.clear_color[1] = 0.5f; o.clear_color[2] = 1.0f; o.clear_color[3] = 1.0f;
        r.begin(fb, o);
        PaintProgram solid{clip.data(), var.data(), false, 1.0f};
        PaintProgram tinted{clip.data(), var.data(), false, 0.25f};
        DrawState blend;
        blend.blend = Blend::Alpha;
        blend.depth_write = false;
        r.submit(solid, std::uint32_t(clip.size()), opaque.data(), opaque.size());
        r.submit(tinted, std::uint32_t(clip.size()), glass.data(), glass.size(), blend);
        r.end();
        // Left: the opaque quad (r = 0.5 + 8 * ddx = 0.5: constant varyings), untouched.
        const float* left = fb.pixel(5, 10);
        CHECK(left[0] == 0.5f);
        CHECK(left[1] == 0.25f);
        CHECK(left[2] == 1.0f);
        CHECK(fb.depth[10 * W + 5] == 0.5f);
        // Right: (1, 0.75, 0, a 0.25) over (0, 0.5, 1, 1).
        const float* right = fb.pixel(25, 10);
        CHECK(right[0] == 1.0f * 0.25f + 0.0f * 0.75f);
        CHECK(right[1] == 0.75f * 0.25f + 0.5f * 0.75f);
        CHECK(right[2] == 0.0f * 0.25f + 1.0f * 0.75f);
        CHECK(right[3] == 0.25f * 0.25f + 1.0f * 0.75f);
        CHECK(fb.depth[10 * W + 25] == 1.0f);  // not written
    }
}

TEST_CASE("depth only: a program without fragment() writes depth and leaves colour alone") {
    const int W = 40, H = 24;
    // A plane whose NDC depth runs from -0.5 at the left edge to 0.5 at the right.
    std::vector<glm::vec4> clip = {at(0, 0, W, H, -0.5), at(0, H, W, H, -0.5), at(W, H, W, H, 0.5), at(W, 0, W, H, 0.5)};
    const std::vector<std::uint32_t> idx = {0, 1, 2, 0, 2, 3};
    DepthProgram p{clip.data()};
    for (int samples : {1, 4}) {
        CAPTURE(samples);
        Renderer r({2, 16});
        // A depth target (no colour), and a colour target whose colour must survive.
        Framebuffer shadow = Framebuffer::depth_only(W, H);
        Framebuffer both(W, H);
        both.clear(0.125f, 0.25f, 0.375f, 0.5f);
        FrameOptions o;
        o.samples = samples;
        r.begin(shadow, o);
        r.submit(p, 4, idx.data(), idx.size());
        r.end();
        FrameOptions keep = o;
        keep.clear = false;
        r.begin(both, keep);
        r.submit(p, 4, idx.data(), idx.size());
        r.end();
        CHECK(shadow.color.empty());
        int bad_depth = 0, bad_color = 0;
        for (int y = 0; y < H; ++y)
            for (int x = 0; x < W; ++x) {
                // Window depth at the pixel centre: (z_ndc + 1) / 2 with z_ndc
                // linear in x; the nearest sample's with several samples.
                const double nearest_x = samples == 1 ? x + 0.5 : x + 0.5 - 6.0 / 16.0;
                const double expect = 0.25 + 0.5 * nearest_x / W;
                const float d = shadow.depth[std::size_t(y) * W + x];
                bad_depth += std::fabs(d - expect) > 1e-6;
                bad_depth += both.depth[std::size_t(y) * W + x] != d;
                const float* c = both.pixel(x, y);
                bad_color += c[0] != 0.125f || c[1] != 0.25f || c[2] != 0.375f || c[3] != 0.5f;
            }
        CHECK(bad_depth == 0);
        CHECK(bad_color == 0);
    }
}

TEST_CASE("frame: the tile hook sees every pixel once, with its final colour") {
    const OverdrawScene sc(150, 97, 3, true);
    for (int samples : {1, 4}) {
        for (int tile : {16, 64}) {
            CAPTURE(samples);
            CAPTURE(tile);
            Renderer r({3, tile});
            Framebuffer fb(sc.W, sc.H);
            HookCapture hook(sc.W, sc.H);
            r.begin(fb, frame_options(FrameOptions::Visibility::Auto, samples));
            sc.submit(r);
            r.end(hook);
            CHECK(hook.not_once() == 0);
            CHECK(hook.seen == fb.color);
        }
    }
}

TEST_CASE("frame: tiles no draw reaches hold the resolved clear value and are handed over as uniform") {
    // One small triangle in the top-left corner: most 16x16 tiles are never
    // reached. Such a tile is cleared in the framebuffer directly (no samples)
    // and converted to 8 bits from one pixel; the values must be what the
    // sample clear and resolve give: the pairwise mean of S equal values,
    // which is the value itself unless the sums overflow (3e38 below).
    const int W = 150, H = 97;
    const std::vector<glm::vec4> clip = {at(3, 2, W, H), at(30, 5, W, H), at(9, 28, W, H)};
    const std::vector<float> var = {1, 0, 0, 0, 1, 0, 0, 0, 1};
    const std::vector<std::uint32_t> idx = {0, 1, 2};
    const float clears[2][4] = {{0.25f, 0.5f, 0.125f, 1.0f}, {0.25f, 3e38f, -0.0f, 0.75f}};
    for (const float* clear : clears)
        for (int samples : {1, 2, 4, 8}) {
            CAPTURE(samples);
            CAPTURE(clear[1]);
            float want[4];
            for (int k = 0; k < 4; ++k) {
                float v[8];
                for (int s = 0; s < samples; ++s) v[s] = clear[k];
                for (int n = samples; n > 1; n /= 2)
                    for (int i = 0; i < n / 2; ++i) v[i] = v[2 * i] + v[2 * i + 1];
                want[k] = samples == 1 ? clear[k] : v[0] * (1.0f / float(samples));
            }
            CHECK(std::isinf(want[1]) == (clear[1] > 1e30f && samples > 1));
            Renderer r({3, 16});
            Framebuffer fb(W, H);
            FrameOptions o = frame_options(FrameOptions::Visibility::Auto, samples);
            for (int k = 0; k < 4; ++k) o.clear_color[k] = clear[k];
            o.clear_depth = 0.75f;
            std::vector<std::uint8_t> tiles(std::size_t(W) * H * 4, 7), whole(tiles.size(), 9);
            TileResolve resolve;
            resolve.rgba8 = tiles.data();
            resolve.width = W;
            int uniform_tiles = 0, wrong_uniform = 0;
            std::mutex m;
            PaintProgram p{clip.data(), var.data(), false, 1.0f};
            r.begin(fb, o);
            DrawState st;
            st.cull = CullMode::None;
            r.submit(p, 3, idx.data(), idx.size(), st);
            r.end([&](const TileView& v) {
                resolve(v);
                std::lock_guard<std::mutex> lock(m);
                if (!v.uniform) return;
                ++uniform_tiles;
                for (int y = 0; y < v.height; ++y)
                    for (int x = 0; x < v.width; ++x)
                        for (int c = 0; c < 4; ++c)
                            wrong_uniform += std::memcmp(&v.rgba[std::size_t(y) * v.row + 4 * std::size_t(x) + std::size_t(c)], &v.rgba[c], sizeof(float)) != 0;
            });
            CHECK(uniform_tiles > 40);
            CHECK(wrong_uniform == 0);
            int drawn = 0, wrong = 0;
            for (int y = 0; y < H; ++y)
                for (int x = 0; x < W; ++x) {
                    const float* px = fb.pixel(x, y);
                    if (fb.depth[std::size_t(y) * W + std::size_t(x)] != 0.75f) {
                        ++drawn;
                        continue;
                    }
                    for (int c = 0; c < 4; ++c) wrong += std::memcmp(&px[c], &want[c], sizeof(float)) != 0;
                }
            CHECK(drawn > 200);
            CHECK(wrong == 0);
            resolve_to_srgb8(fb.color.data(), W, H, 1.0f, ToneMap::Aces, whole.data());
            CHECK(tiles == whole);
        }
}

TEST_CASE("stream_fill: the bytes of a plain fill at any alignment and length, and nothing around them") {
    // The fill of untouched tiles and their 8-bit output: non-temporal 32-byte
    // stores in the middle, 4-byte ones at both ends; plain stores for an
    // address or a length not in 4-byte units.
    const unsigned char pattern[16] = {1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15, 16};
    int wrong = 0, cases = 0;
    for (std::size_t size : {std::size_t(4), std::size_t(16)})
        for (std::size_t offset = 0; offset < 40; ++offset)
            for (std::size_t bytes = 0; bytes < 200; bytes += size) {
                alignas(64) unsigned char got[320];
                unsigned char want[320];
                std::memset(got, 0xAB, sizeof got);
                std::memset(want, 0xAB, sizeof want);
                for (std::size_t i = 0; i < bytes; ++i) want[64 + offset + i] = pattern[i % size];
                stream_fill(got + 64 + offset, bytes, StreamPattern(pattern, size));
                stream_fence();
                wrong += std::memcmp(got, want, sizeof got) != 0;
                ++cases;
            }
    CHECK(cases == 40 * (50 + 13));  // lengths 0..196 by 4 and 0..192 by 16, 40 offsets each
    CHECK(wrong == 0);
}

TEST_CASE("frame: a transient frame hands the hook the same colours and leaves the framebuffer alone") {
    // FrameOptions::transient keeps each tile in tile-local storage. Against
    // the same frame kept in the framebuffer: every sample count, two tile
    // sizes, a background fill, a clear whose sums overflow (uniform tiles
    // resolve to infinity at several samples), and tiles no draw reaches.
    const OverdrawScene sc(150, 97, 5, true);
    const std::vector<std::uint32_t> corner = {0, 1, 2};
    auto fill = [](const void*, int x0, int y0, int w, int h, float* rgba, std::size_t row) {
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x)
                for (int c = 0; c < 4; ++c) rgba[std::size_t(y) * row + 4 * std::size_t(x) + std::size_t(c)] = float(((x0 + x) * 3 + (y0 + y) * 5 + c) % 17) / 16.0f;
    };
    for (int variant = 0; variant < 3; ++variant)
        for (int samples : {1, 2, 4, 8})
            for (int tile : {16, 64}) {
                CAPTURE(variant);
                CAPTURE(samples);
                CAPTURE(tile);
                HookCapture kept(sc.W, sc.H), transient(sc.W, sc.H);
                HookCapture* hooks[2] = {&kept, &transient};
                Framebuffer fbs[2] = {Framebuffer(sc.W, sc.H), Framebuffer(sc.W, sc.H)};
                fbs[1].clear(-1.0f, -2.0f, -3.0f, -4.0f, 0.5f);
                const Framebuffer before = fbs[1];
                for (int t = 0; t < 2; ++t) {
                    Renderer r({3, tile});
                    FrameOptions o = frame_options(FrameOptions::Visibility::Auto, samples);
                    o.transient = t == 1;
                    if (variant == 1) o.clear_fill = fill;
                    if (variant == 2) o.clear_color[1] = 3e38f;
                    r.begin(fbs[t], o);
                    if (variant == 2) {  // one corner triangle: most tiles stay uniform
                        PaintProgram p{sc.clip.data(), sc.var.data(), false, 1.0f};
                        r.submit(p, std::uint32_t(sc.clip.size()), corner.data(), corner.size());
                    } else {
                        sc.submit(r);
                    }
                    r.end(*hooks[t]);
                    CHECK(hooks[t]->not_once() == 0);
                }
                const std::size_t bytes = kept.seen.size() * sizeof(float);
                CHECK(std::memcmp(kept.seen.data(), transient.seen.data(), bytes) == 0);
                CHECK(std::memcmp(kept.seen.data(), fbs[0].color.data(), bytes) == 0);
                CHECK(fbs[1].color == before.color);
                CHECK(fbs[1].depth == before.depth);
                if (variant == 2) {
                    CHECK(transient.uniform_tiles > (tile == 16 ? 40 : 2));
                    CHECK(transient.seen.back() == 1.0f);  // alpha
                    CHECK(std::isinf(transient.seen[transient.seen.size() - 3]) == (samples > 1));
                }
            }
}

TEST_CASE("frame: a deferred framebuffer stays empty through transient frames and fills on the first kept one") {
    // Framebuffer::deferred: what render and bench use. Transient frames at 1
    // and 4 samples hand the hook the colours of a frame into an allocated
    // framebuffer and allocate nothing; the first kept frame allocates it and
    // leaves the same pixels as a framebuffer allocated from the start.
    const OverdrawScene sc(150, 97, 5, true);
    for (int samples : {1, 4}) {
        CAPTURE(samples);
        const FrameOptions base = frame_options(FrameOptions::Visibility::Auto, samples);
        Renderer r({2, 32});
        Framebuffer full(sc.W, sc.H);
        HookCapture want(sc.W, sc.H);
        r.begin(full, base);
        sc.submit(r);
        r.end(want);

        Framebuffer fb = Framebuffer::deferred(sc.W, sc.H);
        CHECK(fb.is_deferred());
        CHECK(fb.has_color());
        for (int frame = 0; frame < 2; ++frame) {
            FrameOptions o = base;
            o.transient = true;
            HookCapture got(sc.W, sc.H);
            r.begin(fb, o);
            sc.submit(r);
            r.end(got);
            CHECK(got.not_once() == 0);
            CHECK(std::memcmp(got.seen.data(), want.seen.data(), want.seen.size() * sizeof(float)) == 0);
            CHECK(fb.color.empty());
            CHECK(fb.depth.empty());
        }
        HookCapture kept(sc.W, sc.H);
        r.begin(fb, base);
        sc.submit(r);
        r.end(kept);
        CHECK_FALSE(fb.is_deferred());
        CHECK(fb.color == full.color);
        CHECK(fb.depth == full.depth);
        CHECK(std::memcmp(kept.seen.data(), want.seen.data(), want.seen.size() * sizeof(float)) == 0);
    }
    Framebuffer cleared = Framebuffer::deferred(5, 3);  // Renderer::clear allocates too
    Renderer r({1, 16});
    r.clear(cleared, 0.25f, 0.5f, 0.75f, 1.0f, 0.5f);
    CHECK(cleared.color.size() == 5 * 3 * 4);
    CHECK(cleared.color[6] == 0.75f);
    CHECK(cleared.depth[14] == 0.5f);
}

TEST_CASE("frame: a renderer's transient frames show each frame's own clear colour") {
    // The tile of the clear colour that empty transient tiles hand over is
    // kept between frames: a new colour, sample count or tile must refill it.
    Renderer r({2, 16});
    Framebuffer fb(40, 20);
    for (int samples : {1, 4})
        for (float green : {0.5f, 0.25f, 0.25f}) {
            CAPTURE(samples);
            CAPTURE(green);
            FrameOptions o = frame_options(FrameOptions::Visibility::Auto, samples);
            o.transient = true;
            o.clear_color[1] = green;
            HookCapture hook(40, 20);
            r.begin(fb, o);
            r.end(hook);
            CHECK(hook.not_once() == 0);
            CHECK(hook.uniform_tiles == 3 * 2);  // 16x16 tiles
            int wrong = 0;
            for (std::size_t i = 0; i < hook.seen.size(); ++i) wrong += hook.seen[i] != o.clear_color[i % 4];
            CHECK(wrong == 0);
        }
}

TEST_CASE("frame: misuse is refused") {
    Renderer r({1, 16});
    Framebuffer fb(8, 8);
    CountProgram p;
    std::vector<glm::vec4> clip = {glm::vec4(0, 0, 0, 1)};
    CHECK_THROWS_AS(r.submit(p, 1, nullptr, 0), std::logic_error);
    CHECK_THROWS_AS(r.end(), std::logic_error);
    FrameOptions bad;
    bad.samples = 3;
    CHECK_THROWS_AS(r.begin(fb, bad), std::invalid_argument);
    r.begin(fb);
    CHECK_THROWS_AS(r.begin(fb), std::logic_error);
    r.end();
    Framebuffer empty;
    CHECK_THROWS_AS(r.begin(empty), std::invalid_argument);
    // The renderer is still usable.
    r.begin(fb);
    r.end();
    CHECK(fb.depth[0] == 1.0f);
}

} // TEST_SUITE

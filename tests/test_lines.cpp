// Lines and points (raster/line.h): exact covered pixels by the diamond-exit
// rule against a reference that moves the segment by a small concrete
// (e, e^2) and searches the L1 distance exactly, the pixel a point lies in,
// strips drawing a shared endpoint once, depth against triangles, every
// sample of a covered pixel, the same bytes on any thread count and tile
// size, near-plane clipping, degenerate and hostile input.
#include <doctest/doctest.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <set>
#include <utility>
#include <vector>

#include <glm/gtc/matrix_transform.hpp>

#include "raster/line.h"
#include "raster_test_util.h"
#include "renderer/scene_renderer.h"

using namespace prast;
using namespace prast::test;

namespace {

using Pixels = std::set<std::pair<int, int>>;

__extension__ typedef __int128 Int128;

// The reference rule: pixel (px, py) is covered when the segment moved by
// (e, e^2) meets the open diamond |x - cx| + |y - cy| < 1/2 and its moved end
// is outside it. Coordinates in 1/256 pixel times 2^34, so e = 2^17 units
// (2^-25 pixel) and e^2 = 1 unit are exact; e is small enough that no
// comparison without a tie changes for segments shorter than 2^6 pixels.
// The L1 distance to the centre is convex and piecewise linear along the
// segment: its minimum is at an end or where x or y crosses the centre.
bool reference_covers(double x0, double y0, double x1, double y1, int px, int py) {
    const Int128 kScale = Int128(1) << 34, kE = Int128(1) << 17, kE2 = 1;
    auto fixed = [&](double v) { return Int128(std::llrint(v * 256.0)) * kScale; };
    const Int128 cx = (Int128(px) * 256 + 128) * kScale, cy = (Int128(py) * 256 + 128) * kScale;
    const Int128 half = Int128(128) * kScale;
    const Int128 ax = fixed(x0) + kE - cx, ay = fixed(y0) + kE2 - cy;
    const Int128 dx = fixed(x1) - fixed(x0), dy = fixed(y1) - fixed(y0);
    auto abs128 = [](Int128 v) { return v < 0 ? -v : v; };
    if (abs128(ax + dx) + abs128(ay + dy) < half) return false;  // ends inside
    // f(t) = |ax + t dx| + |ay + t dy| at t = num / den, times den (den > 0).
    auto below_half = [&](Int128 num, Int128 den) {
        if (den < 0) { num = -num; den = -den; }
        if (num < 0 || num > den) return false;  // outside [0, 1]
        // |ax den + num dx| + |ay den + num dy| < half den (below 2^100: exact).
        return abs128(ax * den + num * dx) + abs128(ay * den + num * dy) < half * den;
    };
    if (below_half(0, 1) || below_half(1, 1)) return true;
    if (dx != 0 && below_half(-ax, dx)) return true;
    if (dy != 0 && below_half(-ay, dy)) return true;
    return false;
}

// Counts per pixel: every covered fragment adds 1 to red (no depth test).
struct Counter {
    static constexpr int kVaryings = 0;
    const glm::vec4* clip = nullptr;
    void vertex(std::uint32_t i, float out[4], float*) const {
        out[0] = clip[i].x; out[1] = clip[i].y; out[2] = clip[i].z; out[3] = clip[i].w;
    }
    void fragment(const FragmentBlock<0>&, FragmentOut& out) const {
        for (int l = 0; l < kBlockLanes; ++l) { out.r[l] = 1; out.g[l] = 0; out.b[l] = 0; out.a[l] = 0; }
    }
};

DrawState count_state(Topology t) {
    DrawState st;
    st.topology = t;
    st.blend = Blend::Add;
    st.depth_test = false;
    st.depth_write = false;
    return st;
}

// Draws window-space points (pixels, y down) as lines or points into a
// W x H target cleared to 0 and returns the red channel.
std::vector<float> count(int W, int H, const std::vector<glm::dvec2>& pts, const std::vector<std::uint32_t>& idx,
                         Topology t, int threads = 2, int tile = 64) {
    std::vector<glm::vec4> clip;
    for (const glm::dvec2& p : pts) clip.push_back(at(p.x, p.y, W, H));
    Framebuffer fb(W, H);
    Renderer r(RendererOptions{threads, tile});
    r.clear(fb, 0, 0, 0, 0);
    Counter prog;
    prog.clip = clip.data();
    r.draw(fb, prog, std::uint32_t(clip.size()), idx.data(), idx.size(), count_state(t));
    std::vector<float> red(std::size_t(W) * H);
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x) red[std::size_t(y) * W + x] = fb.pixel(x, y)[0];
    return red;
}

Pixels covered(const std::vector<float>& red, int W) {
    Pixels s;
    for (std::size_t i = 0; i < red.size(); ++i)
        if (red[i] != 0.0f) s.insert({int(i % std::size_t(W)), int(i / std::size_t(W))});
    return s;
}

Pixels line_pixels(double x0, double y0, double x1, double y1, int W = 32, int H = 32) {
    const std::vector<float> red = count(W, H, {{x0, y0}, {x1, y1}}, {0, 1}, Topology::Lines);
    for (float v : red) CHECK((v == 0.0f || v == 1.0f));
    return covered(red, W);
}

Pixels reference_pixels(double x0, double y0, double x1, double y1, int W = 32, int H = 32) {
    Pixels s;
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x)
            if (reference_covers(x0, y0, x1, y1, x, y)) s.insert({x, y});
    return s;
}

Pixels row(int y, int x0, int x1) {
    Pixels s;
    for (int x = x0; x <= x1; ++x) s.insert({x, y});
    return s;
}

} // namespace

TEST_SUITE("lines") {

TEST_CASE("the reference agrees with hand-worked lines") {
    // A shallow line through centres: one pixel per column, the exact tie at
    // column 2 (the line through a corner shared by two diamonds) goes to the
    // row above because the segment moves right (+e) before it moves down.
    const Pixels shallow = {{0, 0}, {1, 0}, {2, 0}, {3, 1}, {4, 1}, {5, 1}, {6, 1}, {7, 2}};
    CHECK(reference_pixels(0.5, 0.5, 8.5, 2.5) == shallow);
    CHECK(reference_pixels(2.5, 3.5, 7.5, 3.5) == row(3, 2, 6));
}

TEST_CASE("horizontal, vertical and 45 degree lines between centres") {
    // The end pixel is not drawn (the segment ends inside its diamond).
    CHECK(line_pixels(2.5, 3.5, 7.5, 3.5) == row(3, 2, 6));
    CHECK(line_pixels(7.5, 3.5, 2.5, 3.5) == row(3, 3, 7));  // reversed: the other end is left out
    CHECK(line_pixels(3.5, 1.5, 3.5, 6.5) == Pixels{{3, 1}, {3, 2}, {3, 3}, {3, 4}, {3, 5}});
    CHECK(line_pixels(1.5, 1.5, 5.5, 5.5) == Pixels{{1, 1}, {2, 2}, {3, 3}, {4, 4}});
    CHECK(line_pixels(5.5, 1.5, 1.5, 5.5) == Pixels{{5, 1}, {4, 2}, {3, 3}, {2, 4}});
}

TEST_CASE("shallow and steep lines: one pixel per column or row, ties by the rule") {
    CHECK(line_pixels(0.5, 0.5, 8.5, 2.5) == Pixels{{0, 0}, {1, 0}, {2, 0}, {3, 1}, {4, 1}, {5, 1}, {6, 1}, {7, 2}});
    // Steep: at rows 2 and 6 the line passes exactly between two columns;
    // moved right by e it lies in the right one.
    CHECK(line_pixels(1.5, 0.5, 3.5, 8.5) == Pixels{{1, 0}, {1, 1}, {2, 2}, {2, 3}, {2, 4}, {2, 5}, {3, 6}, {3, 7}});
}

TEST_CASE("ends exactly on pixel edges") {
    // Ending on the edge x = 6 (pixel 6's left corner): the moved end lies in
    // pixel 6's diamond, so pixel 6 is left to the next segment; pixel 5 is drawn.
    CHECK(line_pixels(2.5, 3.5, 6.0, 3.5) == row(3, 2, 5));
    // Starting on the edge x = 2: the start is in pixel 2's diamond, which the line exits.
    CHECK(line_pixels(2.0, 3.5, 5.5, 3.5) == row(3, 2, 4));
    // A line lying on the row edge y = 3 covers the row below it.
    CHECK(line_pixels(1.25, 3.0, 6.25, 3.0) == row(3, 1, 5));
    // A vertical line on the column edge x = 4 covers the column right of it.
    CHECK(line_pixels(4.0, 1.25, 4.0, 4.25) == Pixels{{4, 1}, {4, 2}, {4, 3}});
    // Ending in a diamond but short of the centre: still not drawn.
    CHECK(line_pixels(0.5, 2.5, 3.25, 2.5) == row(2, 0, 2));
}

TEST_CASE("every covered set equals the reference (ties on coarse grids, and random lines)") {
    Random rng(21);
    int checked = 0;
    for (int i = 0; i < 600; ++i) {
        // Half the lines on a quarter- or half-pixel grid (many exact ties),
        // the others anywhere on the 1/256 grid.
        const double grid = i % 3 == 0 ? 0.5 : i % 3 == 1 ? 0.25 : 1.0 / 256.0;
        auto coord = [&] { return std::round(rng.range(-3.0, 35.0) / grid) * grid; };
        const double x0 = coord(), y0 = coord(), x1 = coord(), y1 = coord();
        const Pixels got = line_pixels(x0, y0, x1, y1);
        const Pixels want = reference_pixels(x0, y0, x1, y1);
        CHECK_MESSAGE(got == want, "line (" << x0 << ", " << y0 << ") -> (" << x1 << ", " << y1 << ")");
        checked += int(want.size());
    }
    CHECK(checked > 3000);
}

TEST_CASE("a strip draws each shared endpoint's pixel once") {
    // Additive: a pixel drawn twice would count 2. Corners on a centre or on
    // an edge (inside a diamond once moved), and anywhere between segments
    // that are both x-major or both y-major. (A sharp turn from a y-major to
    // an x-major segment at a vertex outside every diamond may cross one
    // diamond twice, as the rule says; the OpenGL rule does the same.)
    const std::vector<std::vector<glm::dvec2>> strips = {
        {{1.5, 1.5}, {5.5, 1.5}, {5.5, 6.5}, {1.5, 6.5}, {1.5, 1.5}},          // a closed loop through centres
        {{1.5, 1.5}, {4.0, 1.5}, {4.0, 5.5}, {8.0, 9.0}},                      // corners on pixel edges
        {{0.3, 0.7}, {7.1, 3.9}, {12.6, 2.2}, {20.0, 6.3}, {27.9, 1.1}},       // x-major, anywhere
        {{1.2, 0.4}, {3.9, 9.8}, {1.1, 17.3}, {6.6, 30.2}},                    // y-major, anywhere
        {{3.5, 3.5}, {9.5, 3.5}, {15.5, 3.5}, {21.5, 3.5}},                    // collinear pieces
    };
    for (const auto& pts : strips) {
        std::vector<std::uint32_t> idx;
        for (std::uint32_t i = 0; i + 1 < pts.size(); ++i) idx.insert(idx.end(), {i, i + 1});
        const std::vector<float> red = count(32, 32, pts, idx, Topology::Lines);
        Pixels want;
        for (std::size_t i = 0; i + 1 < pts.size(); ++i) {
            const Pixels seg = reference_pixels(pts[i].x, pts[i].y, pts[i + 1].x, pts[i + 1].y);
            want.insert(seg.begin(), seg.end());
        }
        CHECK(covered(red, 32) == want);
        // Each vertex's pixel (where it is inside a diamond) counts once.
        for (std::size_t i = 0; i < red.size(); ++i)
            CHECK_MESSAGE((red[i] == 0.0f || red[i] == 1.0f), "pixel " << i % 32 << ", " << i / 32 << ": " << red[i]);
    }
    // The collinear strip is the single line's pixels.
    CHECK(covered(count(32, 32, {{3.5, 3.5}, {9.5, 3.5}, {15.5, 3.5}, {21.5, 3.5}}, {0, 1, 1, 2, 2, 3},
                       Topology::Lines), 32) == row(3, 3, 20));
}

TEST_CASE("points cover the pixel containing them; edges go right and down") {
    const std::vector<glm::dvec2> pts = {{2.5, 2.5}, {3.0, 4.0}, {5.0, 2.75}, {0.0, 0.0}, {7.99609375, 9.0},
                                         {31.99609375, 31.99609375}, {32.0, 5.0}, {-0.00390625, 6.0}, {10.0, 32.0}};
    std::vector<std::uint32_t> idx;
    for (std::uint32_t i = 0; i < pts.size(); ++i) idx.push_back(i);
    const std::vector<float> red = count(32, 32, pts, idx, Topology::Points);
    // (32, 5), (-1/256, 6) and (10, 32) lie in pixels outside the viewport.
    CHECK(covered(red, 32) == Pixels{{2, 2}, {3, 4}, {5, 2}, {0, 0}, {7, 9}, {31, 31}});
    for (float v : red) CHECK((v == 0.0f || v == 1.0f));
    // Two points in one pixel are two fragments.
    CHECK(count(32, 32, {{4.25, 4.25}, {4.75, 4.5}}, {0, 1}, Topology::Points)[4 * 32 + 4] == 2.0f);
}

TEST_CASE("zero-length lines draw nothing; a short line exiting a diamond draws it") {
    CHECK(line_pixels(4.5, 4.5, 4.5, 4.5).empty());
    CHECK(line_pixels(4.2, 4.7, 4.2, 4.7).empty());
    CHECK(line_pixels(4.5, 4.5, 4.5 + 1.0 / 1024.0, 4.5).empty());  // snaps to zero length
    CHECK(line_pixels(4.5, 4.5, 4.5 + 1.0 / 256.0, 4.5).empty());   // ends in the diamond it starts in
    CHECK(line_pixels(2.5, 2.5, 3.1, 2.5) == Pixels{{2, 2}});        // exits pixel 2's diamond, ends in 3's
}

TEST_CASE("depth: lines against a triangle, both ways, written per pixel") {
    const int W = 32, H = 32;
    // A full-screen triangle at NDC depth 0, red.
    std::vector<glm::vec4> tri = {at(-10, -10, W, H, 0.0), at(80, -10, W, H, 0.0), at(-10, 80, W, H, 0.0)};
    const float tri_var[9] = {1, 0, 0, 1, 0, 0, 1, 0, 0};
    // Green lines: row 4 in front (-0.5), row 8 behind (+0.5), row 12 from
    // in front to behind (crossing the triangle halfway).
    std::vector<glm::vec4> ln = {at(2.5, 4.5, W, H, -0.5), at(30.5, 4.5, W, H, -0.5), at(2.5, 8.5, W, H, 0.5),
                                 at(30.5, 8.5, W, H, 0.5), at(0.5, 12.5, W, H, -0.5), at(32.5, 12.5, W, H, 0.6)};
    std::vector<float> ln_var(ln.size() * 3, 0.0f);
    for (std::size_t i = 0; i < ln.size(); ++i) ln_var[i * 3 + 1] = 1.0f;
    const std::uint32_t tri_idx[3] = {0, 1, 2};
    const std::uint32_t ln_idx[6] = {0, 1, 2, 3, 4, 5};
    for (int order = 0; order < 2; ++order) {
        Framebuffer fb(W, H);
        Renderer r(RendererOptions{2, 16});
        r.begin(fb);
        ClipProgram<3> tp{tri.data(), tri_var}, lp{ln.data(), ln_var.data()};
        DrawState ls, ts;
        ls.topology = Topology::Lines;
        ts.cull = CullMode::None;
        if (order == 0) r.submit(tp, 3, tri_idx, 3, ts);
        r.submit(lp, std::uint32_t(ln.size()), ln_idx, 6, ls);
        if (order == 1) r.submit(tp, 3, tri_idx, 3, ts);
        r.end();
        for (int x = 2; x <= 29; ++x) {
            CHECK(fb.pixel(x, 4)[1] == 1.0f);  // in front, either order
            CHECK(fb.pixel(x, 8)[0] == 1.0f);  // behind, either order
        }
        // The crossing line: NDC depth -0.5 + 1.1 t at pixel x (t = x / 32),
        // in front of the triangle up to x = 14.5.
        for (int x = 0; x < 32; ++x) {
            const bool front = x <= 14;
            CHECK(fb.pixel(x, 12)[front ? 1 : 0] == 1.0f);
        }
        // Written depth: window depth (z_ndc + 1) / 2 of the line on row 4.
        CHECK(fb.depth[std::size_t(4) * W + 10] == doctest::Approx(0.25f).epsilon(1e-6));
    }
}

TEST_CASE("multisampling: a covered pixel covers every sample, each depth-tested") {
    const int W = 32, H = 32;
    for (int S : {2, 4, 8}) {
        // A red triangle in front covering the left part of the target with a
        // slanted edge; a green line behind it crossing the edge.
        std::vector<glm::vec4> tri = {at(-10, -10, W, H, -0.5), at(20.3, -10, W, H, -0.5), at(-10, 40.7, W, H, -0.5)};
        const float tri_var[9] = {1, 0, 0, 1, 0, 0, 1, 0, 0};
        std::vector<glm::vec4> ln = {at(0.5, 8.5, W, H, 0.5), at(31.5, 8.5, W, H, 0.5)};
        const float ln_var[6] = {0, 1, 0, 0, 1, 0};
        const std::uint32_t tri_idx[3] = {0, 1, 2}, ln_idx[2] = {0, 1};
        Framebuffer fb(W, H);
        Renderer r(RendererOptions{2, 16});
        FrameOptions fo;
        fo.samples = S;
        r.begin(fb, fo);
        ClipProgram<3> tp{tri.data(), tri_var}, lp{ln.data(), ln_var};
        DrawState ls, ts;
        ls.topology = Topology::Lines;
        ts.cull = CullMode::None;
        r.submit(tp, 3, tri_idx, 3, ts);
        r.submit(lp, 2, ln_idx, 2, ls);
        r.end();
        int partial = 0;
        for (int x = 0; x < 31; ++x) {
            const float* c = fb.pixel(x, 8);
            // Every sample is the triangle's or the line's: the two add up to 1,
            // in steps of 1 / S.
            CHECK(c[0] + c[1] == doctest::Approx(1.0f));
            CHECK(std::fabs(c[1] * float(S) - std::round(c[1] * float(S))) < 1e-5f);
            partial += c[0] > 0.0f && c[1] > 0.0f;
        }
        CHECK(partial >= 1);  // the edge pixel: some samples each
        // Off the triangle the line's pixels are wholly green (all samples),
        // and the pixel past its end is background.
        CHECK(fb.pixel(30, 8)[1] == 1.0f);
        CHECK(fb.pixel(31, 8)[1] == 0.0f);
        CHECK(fb.pixel(30, 9)[1] == 0.0f);
    }
}

TEST_CASE("the same bytes on 1, 2 and 3 threads and tiles 16, 64 and 256") {
    const int W = 173, H = 131;
    Random rng(7);
    std::vector<glm::vec4> clip;
    std::vector<float> var;
    std::vector<std::uint32_t> lines, points, tris;
    for (int i = 0; i < 400; ++i) {
        clip.push_back(at(rng.range(-40, W + 40), rng.range(-40, H + 40), W, H, rng.range(-1, 1)));
        for (int k = 0; k < 3; ++k) var.push_back(float(rng.uniform()));
    }
    for (std::uint32_t i = 0; i + 1 < 400; i += 2) lines.insert(lines.end(), {i, i + 1});
    for (std::uint32_t i = 0; i < 400; i += 3) points.push_back(i);
    for (std::uint32_t i = 0; i + 2 < 60; i += 3) tris.insert(tris.end(), {i, i + 1, i + 2});
    for (int S : {1, 4}) {
        std::uint64_t first = 0;
        for (int threads : {1, 2, 3})
            for (int tile : {16, 64, 256}) {
                Framebuffer fb(W, H);
                Renderer r(RendererOptions{threads, tile});
                FrameOptions fo;
                fo.samples = S;
                r.begin(fb, fo);
                ClipProgram<3> p{clip.data(), var.data()};
                DrawState ls, ps, blend;
                ls.topology = Topology::Lines;
                ps.topology = Topology::Points;
                blend.topology = Topology::Lines;
                blend.blend = Blend::Add;
                blend.depth_write = false;
                r.submit(p, 400, tris.data(), tris.size());
                r.submit(p, 400, lines.data(), lines.size(), ls);
                r.submit(p, 400, points.data(), points.size(), ps);
                r.submit(p, 400, lines.data(), lines.size(), blend);
                r.end();
                const std::uint64_t h = hash_framebuffer(fb);
                if (!first) first = h;
                CHECK(h == first);
            }
    }
}

TEST_CASE("perspective-correct varyings along a line") {
    // A line in depth under a perspective projection: the varying (its eye
    // depth) at each pixel equals the eye depth of the ray through the pixel
    // centre's projection onto the line.
    const int W = 64, H = 64;
    const glm::mat4 proj = glm::perspective(glm::radians(60.0f), 1.0f, 0.1f, 100.0f);
    const glm::vec3 a(-1.0f, -0.2f, -2.0f), b(1.5f, 0.3f, -9.0f);
    std::vector<glm::vec4> clip = {proj * glm::vec4(a, 1.0f), proj * glm::vec4(b, 1.0f)};
    const float var[2] = {-a.z, -b.z};
    Framebuffer fb(W, H);
    Renderer r(RendererOptions{2, 64});
    r.clear(fb, -1, 0, 0, 0);
    ClipProgram<1> p{clip.data(), var};
    DrawState ls;
    ls.topology = Topology::Lines;
    const std::uint32_t idx[2] = {0, 1};
    r.draw(fb, p, 2, idx, 2, ls);
    // Window positions of the ends.
    // Snapped to 1/256 pixel, as the rasterizer does.
    auto win = [&](const glm::vec4& c) {
        const double x = (double(c.x) / c.w + 1.0) * 0.5 * W, y = (1.0 - double(c.y) / c.w) * 0.5 * H;
        return glm::dvec2(std::nearbyint(x * 256.0) / 256.0, std::nearbyint(y * 256.0) / 256.0);
    };
    const glm::dvec2 w0 = win(clip[0]), w1 = win(clip[1]);
    int n = 0;
    double worst = 0.0;
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x) {
            const float v = fb.pixel(x, y)[0];
            if (v < 0.0f) continue;
            ++n;
            const glm::dvec2 c(x + 0.5, y + 0.5), d = w1 - w0;
            const double t = glm::clamp(glm::dot(c - w0, d) / glm::dot(d, d), 0.0, 1.0);
            // 1/z is linear in screen space.
            const double z = 1.0 / ((1.0 - t) / double(-a.z) + t / double(-b.z));
            worst = std::max(worst, std::fabs(double(v) - z));
        }
    CHECK(n > 20);
    CHECK(worst < 1e-4);
}

TEST_CASE("a line crossing the near plane is clipped there, without wrapping") {
    const int W = 64, H = 64;
    const glm::mat4 proj = glm::perspective(glm::radians(90.0f), 1.0f, 0.5f, 100.0f);
    // From 3 units ahead to 3 units behind the eye, off to the lower left of it.
    const glm::vec3 a(-1.0f, -1.0f, -3.0f), b(-0.2f, -0.2f, 3.0f);
    std::vector<glm::vec4> clip = {proj * glm::vec4(a, 1.0f), proj * glm::vec4(b, 1.0f)};
    const std::vector<float> red = [&] {
        Framebuffer fb(W, H);
        Renderer r(RendererOptions{2, 16});
        r.clear(fb, 0, 0, 0, 0);
        Counter prog;
        prog.clip = clip.data();
        const std::uint32_t idx[2] = {0, 1};
        r.draw(fb, prog, 2, idx, 2, count_state(Topology::Lines));
        std::vector<float> out;
        for (int y = 0; y < H; ++y)
            for (int x = 0; x < W; ++x) out.push_back(fb.pixel(x, y)[0]);
        return out;
    }();
    // The visible part runs from a's projection to where the segment meets
    // z = -0.5, whose projection is off the lower left of the screen.
    const float t = (-0.5f - a.z) / (b.z - a.z);
    const glm::vec3 n = a + t * (b - a);
    auto win = [&](const glm::vec3& p) {
        const glm::vec4 c = proj * glm::vec4(p, 1.0f);
        return glm::dvec2((c.x / c.w + 1.0) * 0.5 * W, (1.0 - c.y / c.w) * 0.5 * H);
    };
    const glm::dvec2 p0 = win(a), p1 = win(n);
    int lit = 0;
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x) {
            if (red[std::size_t(y) * W + x] == 0.0f) continue;
            ++lit;
            CHECK(red[std::size_t(y) * W + x] == 1.0f);
            // Within a pixel of the segment p0 -> p1.
            const glm::dvec2 c(x + 0.5, y + 0.5), d = p1 - p0;
            const double s = glm::clamp(glm::dot(c - p0, d) / glm::dot(d, d), 0.0, 1.0);
            CHECK(glm::length(c - (p0 + s * d)) < 1.0);
        }
    // From a's pixel to the screen's edge, one pixel per column (45 degrees).
    CHECK(p1.x < 0.0);
    CHECK(lit >= int(std::min(p0.x, double(H) - p0.y)) - 1);
    CHECK(lit <= int(std::max(p0.x, double(H) - p0.y)) + 2);
}

TEST_CASE("a huge line beyond the guard band covers exactly its row") {
    const std::vector<float> red = count(64, 16, {{-1e7, 5.5}, {1e7, 5.5}, {3.5, -1e9}, {3.5, 1e9}}, {0, 1, 2, 3},
                                         Topology::Lines);
    Pixels want = row(5, 0, 63);
    for (int y = 0; y < 16; ++y) want.insert({3, y});
    CHECK(covered(red, 64) == want);
    CHECK(red[5 * 64 + 3] == 2.0f);  // where the two cross
}

TEST_CASE("hostile values never crash or hang") {
    const float inf = std::numeric_limits<float>::infinity(), nan = std::numeric_limits<float>::quiet_NaN();
    const std::vector<glm::vec4> clip = {
        {0, 0, 0, 1},       {nan, 0, 0, 1},    {inf, 0, 0, 1},   {0, -inf, 0, 1}, {1e30f, 1e30f, 0, 1},
        {-1e30f, 1e30f, 0, 1}, {0.5f, 0.5f, 0, 0}, {0.2f, 0.1f, 0.5f, -1}, {1e30f, 0, 0, 1e-30f},
        {0.1f, 0.2f, 0.3f, 1e-38f}, {3e38f, -3e38f, 3e38f, 3e38f}, {0.3f, 0.3f, 2, 1}};
    std::vector<std::uint32_t> idx;
    for (std::uint32_t i = 0; i < clip.size(); ++i)
        for (std::uint32_t j = 0; j < clip.size(); ++j) idx.insert(idx.end(), {i, j});
    idx.insert(idx.end(), {0, 99, 99, 0, 0xFFFFFFFFu, 1});  // out of range
    for (Topology t : {Topology::Lines, Topology::Points})
        for (int S : {1, 4}) {
            Framebuffer fb(97, 61);
            Renderer r(RendererOptions{2, 16});
            FrameOptions fo;
            fo.samples = S;
            r.begin(fb, fo);
            Counter prog;
            prog.clip = clip.data();
            r.submit(prog, std::uint32_t(clip.size()), idx.data(), idx.size(), count_state(t));
            r.end();
            // Each pixel counts its fragments: whole numbers; the valid
            // primitives through the centre vertex draw.
            double total = 0.0;
            for (std::size_t i = 0; i < fb.color.size(); i += 4) {
                CHECK(fb.color[i] == std::floor(fb.color[i]));
                total += fb.color[i];
            }
            CHECK(total > 0.0);
            CHECK(std::isfinite(total));
        }
}

TEST_CASE("scene meshes of lines and points: unlit without normals, lit with them") {
    Scene scene;
    Material m;
    m.base_color_factor = glm::vec4(0.5f, 0.25f, 1.0f, 1.0f);
    scene.materials.push_back(m);
    Mesh lines;
    lines.topology = Mesh::Topology::Lines;
    lines.positions = {{-0.8f, 0.1f, 0.0f}, {0.8f, 0.1f, 0.0f}};
    lines.colors = {{1.0f, 1.0f, 1.0f, 1.0f}, {1.0f, 1.0f, 1.0f, 1.0f}};
    lines.indices = {0, 1, 1};  // an odd index count: the last one is left out
    Mesh points;
    points.topology = Mesh::Topology::Points;
    points.positions = {{0.0f, -0.4f, 0.0f}};
    points.normals = {{0.0f, 0.0f, 1.0f}};
    points.indices = {0};
    scene.meshes = {lines, points};
    Renderer r(RendererOptions{2, 64});
    SceneRenderer sr(scene, r);
    FrameSettings fs;
    fs.camera.eye = {0.0f, 0.0f, 3.0f};
    fs.camera.target = {0.0f, 0.0f, 0.0f};
    fs.lights = default_light_rig();
    fs.background = Background::Color;
    Framebuffer fb(64, 64);
    sr.render(fs, fb);
    // The unlit line is exactly the base colour times the vertex colour.
    int unlit = 0, lit = 0;
    for (int y = 0; y < 64; ++y)
        for (int x = 0; x < 64; ++x) {
            const float* c = fb.pixel(x, y);
            if (c[0] == 0.5f && c[1] == 0.25f && c[2] == 1.0f) ++unlit;
            else if (c[0] > 0.0f || c[1] > 0.0f || c[2] > 0.0f) ++lit;
            CHECK(std::isfinite(c[0]));
        }
    CHECK(unlit > 20);
    CHECK(lit == 1);  // the lit point
}

} // TEST_SUITE

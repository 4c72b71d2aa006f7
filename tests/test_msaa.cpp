// Multisampling (docs/conventions.md, "Multisampling and blending"): the standard
// sample positions; coverage along a long straight edge against the exact
// covered area; pixels fully inside a triangle identical to the 1-sample
// image; a watertight mesh covering every sample exactly once (watched
// through the observer's per-sample masks); centroid interpolation keeping
// varyings inside the triangle; determinism over threads and tile sizes for
// every sample count.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <mutex>
#include <vector>

#include <glm/glm.hpp>

#include "tests/raster_test_util.h"

using namespace prast;
using namespace prast::test;

namespace {

FrameOptions samples_options(int samples) {
    FrameOptions o;
    o.samples = samples;
    o.clear_color[3] = 0.0f;
    return o;
}

// Area of the unit pixel square [x, x+1] x [y, y+1] where a X + b Y + c >= 0.
double covered_area(double a, double b, double c, double x, double y) {
    double poly[8][2] = {{x, y}, {x + 1, y}, {x + 1, y + 1}, {x, y + 1}};
    double out[8][2];
    int n = 0;
    for (int i = 0; i < 4; ++i) {
        const double* p = poly[i];
        const double* q = poly[(i + 1) % 4];
        const double fp = a * p[0] + b * p[1] + c, fq = a * q[0] + b * q[1] + c;
        if (fp >= 0) { out[n][0] = p[0]; out[n][1] = p[1]; ++n; }
        if ((fp >= 0) != (fq >= 0)) {
            const double t = fp / (fp - fq);
            out[n][0] = p[0] + t * (q[0] - p[0]);
            out[n][1] = p[1] + t * (q[1] - p[1]);
            ++n;
        }
    }
    double s = 0;
    for (int i = 0; i < n; ++i) s += out[i][0] * out[(i + 1) % n][1] - out[(i + 1) % n][0] * out[i][1];
    return std::fabs(s) / 2;
}

// Counts, through the observer, how often each sample of each pixel is covered.
struct SampleCounter {
    static constexpr bool enabled = true;
    int W, H, S;
    std::vector<int> count;
    bool wrong_count = false;
    std::mutex m;
    SampleCounter(int w, int h, int s) : W(w), H(h), S(s), count(std::size_t(w) * h * s, 0) {}
    void vertex(std::uint32_t, const float*, const float*, int) {}
    void triangle(std::uint32_t, TriangleFate, bool, const TriangleSetup*) {}
    void binned(std::uint32_t, int) {}
    void fragments(std::uint32_t, int, int, std::uint32_t, std::uint32_t, const float*) {}
    template <int NV>
    void shaded(const FragmentBlock<NV>&, const FragmentOut&, std::uint32_t) {}
    void samples(std::uint32_t, int bx, int by, const SampleCoverage& sc) {
        std::lock_guard<std::mutex> lock(m);
        wrong_count |= sc.count != S;
        for (int s = 0; s < S; ++s)
            for (int l = 0; l < kBlockLanes; ++l)
                if (sc.cover[s] & (1u << l))
                    ++count[(std::size_t(by + lane_y(l)) * W + std::size_t(bx + lane_x(l))) * S + std::size_t(s)];
    }
};

// Varyings as colour; alpha = the triangle's id + 1 and its square in blue, so
// that a resolved pixel whose samples all come from one triangle is told
// apart (mean(id^2) == mean(id)^2 only then).
struct IdProgram {
    static constexpr int kVaryings = 2;
    const glm::vec4* clip = nullptr;
    const float* uv = nullptr;
    void vertex(std::uint32_t i, float out[4], float* var) const {
        out[0] = clip[i].x; out[1] = clip[i].y; out[2] = clip[i].z; out[3] = clip[i].w;
        var[0] = uv[2 * i];
        var[1] = uv[2 * i + 1];
    }
    void fragment(const FragmentBlock<2>& in, FragmentOut& out) const {
        const float id = float(in.prim_id + 1);
        for (int l = 0; l < kBlockLanes; ++l) {
            // Value and derivatives, as texture sampling would use them.
            out.r[l] = in.var[0][l] + 3.0f * in.ddx(0, l) + 5.0f * in.ddy(1, l);
            out.g[l] = in.var[1][l];
            out.b[l] = id * id;
            out.a[l] = id;
        }
    }
};

// Writes the smallest and largest of three varyings, and whether the lane
// was interpolated at a centroid.
struct MinMaxProgram {
    static constexpr int kVaryings = 3;
    const glm::vec4* clip;
    const float* var;
    void vertex(std::uint32_t i, float out[4], float* v) const {
        out[0] = clip[i].x; out[1] = clip[i].y; out[2] = clip[i].z; out[3] = clip[i].w;
        for (int k = 0; k < 3; ++k) v[k] = var[3 * i + std::uint32_t(k)];
    }
    void fragment(const FragmentBlock<3>& in, FragmentOut& out) const {
        for (int l = 0; l < kBlockLanes; ++l) {
            out.r[l] = std::min({in.var[0][l], in.var[1][l], in.var[2][l]});
            out.g[l] = std::max({in.var[0][l], in.var[1][l], in.var[2][l]});
            out.b[l] = in.centroid_mask & (1u << l) ? 1.0f : 0.0f;
            out.a[l] = 1.0f;
        }
    }
};

// A perspective grid of quads, jittered, as one watertight mesh.
struct GridMesh {
    std::vector<glm::vec4> clip;
    std::vector<float> uv;
    std::vector<std::uint32_t> idx;
    GridMesh(int W, int H, int nx, int ny, std::uint64_t seed) {
        Random rng(seed);
        for (int j = 0; j <= ny; ++j)
            for (int i = 0; i <= nx; ++i) {
                const bool border = i == 0 || j == 0 || i == nx || j == ny;
                const double x = (i + (border ? 0.0 : rng.range(-0.35, 0.35))) * (W + 20.0) / nx - 10.0;
                const double y = (j + (border ? 0.0 : rng.range(-0.35, 0.35))) * (H + 20.0) / ny - 10.0;
                const double w = 1.0 + 0.8 * double(j) / ny;
                clip.push_back(at(x, y, W, H, -0.2 + 0.4 * double(i) / nx, w));
                uv.push_back(float(i) / float(nx));
                uv.push_back(float(j) / float(ny));
            }
        for (int j = 0; j < ny; ++j)
            for (int i = 0; i < nx; ++i) {
                const std::uint32_t a = std::uint32_t(j * (nx + 1) + i), b = a + 1, c = a + std::uint32_t(nx) + 2,
                                    d = a + std::uint32_t(nx) + 1;
                idx.insert(idx.end(), {a, d, c, a, c, b});
            }
    }
};

Framebuffer render_grid(const GridMesh& g, int W, int H, int samples, int threads = 2, int tile = 32) {
    Renderer r({threads, tile});
    Framebuffer fb(W, H);
    IdProgram p{g.clip.data(), g.uv.data()};
    DrawState st;
    st.cull = CullMode::None;
    r.begin(fb, samples_options(samples));
    r.submit(p, std::uint32_t(g.clip.size()), g.idx.data(), g.idx.size(), st);
    r.end();
    return fb;
}

} // namespace

TEST_SUITE("msaa") {

TEST_CASE("msaa: the standard sample positions, inside the pixel, distinct, on the 1/16 grid") {
    // docs/conventions.md gives the 4x positions within the pixel.
    const SamplePattern& four = sample_pattern(4);
    const double expect[4][2] = {{0.375, 0.125}, {0.875, 0.375}, {0.125, 0.625}, {0.625, 0.875}};
    for (int s = 0; s < 4; ++s) {
        CHECK(0.5 + four.pixel_x(s) == expect[s][0]);
        CHECK(0.5 + four.pixel_y(s) == expect[s][1]);
    }
    for (int n : {1, 2, 4, 8}) {
        const SamplePattern& p = sample_pattern(n);
        CHECK(p.count == n);
        double mx = 0, my = 0;
        for (int s = 0; s < n; ++s) {
            CHECK(std::abs(p.x[s]) < 8);
            CHECK(std::abs(p.y[s]) < 8);
            mx += p.x[s];
            my += p.y[s];
            for (int t = 0; t < s; ++t) CHECK((p.x[s] != p.x[t] || p.y[s] != p.y[t]));
        }
        CHECK(mx == 0.0);  // centred on the pixel centre
        CHECK(my == 0.0);
    }
    CHECK(!valid_sample_count(3));
    CHECK(!valid_sample_count(16));
}

TEST_CASE("msaa: along a long straight edge each pixel is within one sample's weight of the exact area") {
    // A white triangle over a black background whose long edge runs across
    // the image at a slope of 1:10, -1:10 and 8:1; the vertices sit on the
    // 1/256-pixel grid, so the analytic edge is the rasterizer's edge. Near
    // the diagonal the standard patterns are coarser: at 1:1 the error of 4
    // and 8 samples reaches 0.22 (measured over every offset), so that edge
    // is held to two samples' weight.
    const int W = 160, H = 120;
    struct Edge { double x0, y0, x1, y1; double bound_per_sample; };
    const Edge edges[] = {
        {-20.0, 40.25, 180.0, 60.25, 1.0},   // 1:10, falling to the right
        {-20.0, 80.5, 180.0, 60.5, 1.0},     // 1:10, rising
        {70.125, -20.0, 90.125, 140.0, 1.0}, // steep: 8:1
        {-20.0, -9.6875, 150.0, 160.3125, 2.0},  // 1:1, off the pixel corners: the patterns' worst case
    };
    for (int samples : {1, 2, 4, 8}) {
        for (const Edge& e : edges) {
            CAPTURE(samples);
            CAPTURE(e.x0);
            // The triangle: the edge plus a far third vertex on its right side.
            const double dx = e.x1 - e.x0, dy = e.y1 - e.y0;
            const double fx = (e.x0 + e.x1) / 2 - dy * 10, fy = (e.y0 + e.y1) / 2 + dx * 10;
            std::vector<glm::vec4> clip = {at(e.x0, e.y0, W, H), at(e.x1, e.y1, W, H), at(fx, fy, W, H)};
            std::vector<std::uint32_t> idx = {0, 1, 2};
            ClipProgram<0> p;
            p.clip = clip.data();
            DrawState st;
            st.cull = CullMode::None;
            Renderer r({2, 32});
            Framebuffer fb(W, H);
            r.begin(fb, samples_options(samples));
            r.submit(p, 3, idx.data(), idx.size(), st);
            r.end();
            // Inside: E(X, Y) = (x1 - x0)(Y - y0) - (y1 - y0)(X - x0) has the third vertex's sign.
            double a = -dy, b = dx, c = dy * e.x0 - dx * e.y0;
            if (a * fx + b * fy + c < 0) { a = -a; b = -b; c = -c; }
            double worst = 0;
            int edge_pixels = 0, over = 0;
            for (int y = 0; y < H; ++y)
                for (int x = 0; x < W; ++x) {
                    const double area = covered_area(a, b, c, x, y);
                    const double err = std::fabs(double(fb.pixel(x, y)[0]) - area);
                    if (area > 0 && area < 1) ++edge_pixels;
                    worst = std::max(worst, err);
                    // With one sample the bound is 1: a pixel is in or out.
                    over += err > e.bound_per_sample / samples + 1e-6;
                }
            MESSAGE(samples << " samples, edge from (" << e.x0 << ", " << e.y0 << "): worst |resolved - area| "
                            << worst << " over " << edge_pixels << " edge pixels");
            CHECK(edge_pixels > 100);
            CHECK(over == 0);
        }
    }
}

TEST_CASE("msaa: pixels whose samples all belong to one triangle equal the 1-sample image") {
    const int W = 120, H = 90;
    const GridMesh g(W, H, 13, 9, 42);
    const Framebuffer one = render_grid(g, W, H, 1);
    for (int samples : {2, 4, 8}) {
        CAPTURE(samples);
        const Framebuffer many = render_grid(g, W, H, samples);
        int inside = 0, differ = 0, edge = 0;
        for (int y = 0; y < H; ++y)
            for (int x = 0; x < W; ++x) {
                const float* m = many.pixel(x, y);
                const float* o = one.pixel(x, y);
                // One triangle at every sample (and the same one at the centre).
                const bool single = m[2] == m[3] * m[3] && m[3] == o[3];
                if (!single) {
                    ++edge;
                    continue;
                }
                ++inside;
                differ += m[0] != o[0] || m[1] != o[1];
            }
        CHECK(inside > W * H * 7 / 10);
        CHECK(edge > 500);
        CHECK(differ == 0);
    }
}

TEST_CASE("msaa: a watertight mesh covers every sample exactly once") {
    const int W = 97, H = 75;
    const GridMesh g(W, H, 11, 8, 9);
    for (int samples : {1, 2, 4, 8}) {
        CAPTURE(samples);
        SampleCounter counter(W, H, samples);
        Renderer r({3, 16});
        Framebuffer fb(W, H);
        CountProgram p;
        p.clip = g.clip.data();
        DrawState st;
        st.cull = CullMode::None;
        st.blend = Blend::Add;
        st.depth_test = false;
        st.depth_write = false;
        r.begin(fb, samples_options(samples));
        r.submit(p, std::uint32_t(g.clip.size()), g.idx.data(), g.idx.size(), st, counter);
        r.end();
        int not_once = 0, not_one = 0;
        for (int c : counter.count) not_once += c != 1;
        // Added per sample, then averaged: exactly 1 everywhere.
        for (int y = 0; y < H; ++y)
            for (int x = 0; x < W; ++x) not_one += fb.pixel(x, y)[0] != 1.0f;
        CHECK(!counter.wrong_count);
        CHECK(not_once == 0);
        CHECK(not_one == 0);
    }
}

TEST_CASE("msaa: centroid interpolation keeps a covered pixel's varyings inside the triangle") {
    // Varying 0 is the barycentric weight of vertex 0: inside the triangle it
    // lies in [0, 1]; at an edge pixel's centre outside it would not.
    const int W = 64, H = 64;
    std::vector<glm::vec4> clip = {at(3.3, 2.9, W, H), at(60.7, 20.2, W, H), at(17.9, 61.4, W, H)};
    std::vector<float> var = {1, 0, 0, 0, 1, 0, 0, 0, 1};
    std::vector<std::uint32_t> idx = {0, 1, 2};
    for (int samples : {2, 4, 8}) {
        CAPTURE(samples);
        MinMaxProgram p{clip.data(), var.data()};
        DrawState st;
        st.cull = CullMode::None;
        Renderer r({1, 16});
        Framebuffer fb(W, H);
        r.begin(fb, samples_options(samples));
        r.submit(p, 3, idx.data(), idx.size(), st);
        r.end();
        int centroid_pixels = 0, outside = 0;
        for (int y = 0; y < H; ++y)
            for (int x = 0; x < W; ++x) {
                const float* c = fb.pixel(x, y);
                if (c[3] == 0.0f) continue;  // no sample covered
                centroid_pixels += c[2] > 0.0f;
                // The resolved value mixes the background (0) in; the covered
                // samples' own values are >= 0 and <= 1, and so is any mix.
                outside += c[0] < -1e-6f || c[1] > 1.0f + 1e-6f;
            }
        CHECK(centroid_pixels > 20);
        CHECK(outside == 0);
    }
}

TEST_CASE("msaa: every sample count gives the same bytes on 1/2/3/8 threads and tiles 16..256") {
    const int W = 143, H = 101;
    Random rng(1234);
    std::vector<glm::vec4> clip;
    std::vector<float> uv;
    std::vector<std::uint32_t> idx;
    for (int t = 0; t < 3000; ++t) {
        const double cx = rng.range(-0.1, 1.1) * W, cy = rng.range(-0.1, 1.1) * H, size = rng.range(1.5, 40.0);
        for (int k = 0; k < 3; ++k) {
            clip.push_back(at(cx + rng.range(-size, size), cy + rng.range(-size, size), W, H, rng.range(-1.1, 1.1),
                              rng.range(0.4, 2.5)));
            uv.push_back(float(rng.uniform()));
            uv.push_back(float(rng.uniform()));
            idx.push_back(std::uint32_t(clip.size() - 1));
        }
    }
    DrawState st;
    st.cull = CullMode::None;
    for (int samples : {1, 2, 4, 8}) {
        CAPTURE(samples);
        auto render = [&](int threads, int tile, FrameOptions::Visibility v) {
            Renderer r({threads, tile});
            Framebuffer fb(W, H);
            IdProgram p{clip.data(), uv.data()};
            FrameOptions o = samples_options(samples);
            o.visibility = v;
            r.begin(fb, o);
            r.submit(p, std::uint32_t(clip.size()), idx.data(), idx.size() / 2, st);
            r.submit(p, std::uint32_t(clip.size()), idx.data() + idx.size() / 2, idx.size() / 2, st);
            r.end();
            return hash_framebuffer(fb);
        };
        const std::uint64_t ref = render(1, 64, FrameOptions::Visibility::Never);
        for (int threads : {1, 2, 3, 8})
            for (int tile : {16, 32, 64, 128, 256}) {
                CAPTURE(threads);
                CAPTURE(tile);
                CHECK(render(threads, tile, FrameOptions::Visibility::Always) == ref);
                CHECK(render(threads, tile, FrameOptions::Visibility::Auto) == ref);
            }
    }
}

} // TEST_SUITE

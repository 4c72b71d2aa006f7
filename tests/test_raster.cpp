// The raster pipeline against the conventions (docs/conventions.md:
// "Spaces and cameras", "Coverage", "Interpolation"): watertightness, the
// top-left fill rule, perspective-correct varyings, clipping, depth, thread and
// tile invariance, a golden image, the observer hooks and the frame counters.
// Every expectation is computed analytically (ray casts, exact half-pixel
// geometry) rather than read back from the rasterizer's own arithmetic.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <memory>
#include <mutex>
#include <set>
#include <string>
#include <vector>

#include <glm/glm.hpp>
#include <glm/gtc/matrix_transform.hpp>
#include <stb_image_write.h>

#include "scene/image_diff.h"
#include "tests/raster_test_util.h"

using namespace prast;
using namespace prast::test;

namespace {

// ---------------------------------------------------------------------------
// Small tools

constexpr double kPi = 3.14159265358979323846;

DrawState count_state(CullMode cull = CullMode::None) {
    DrawState s;
    s.cull = cull;
    s.blend = Blend::Add;
    s.depth_test = false;
    s.depth_write = false;
    return s;
}

// Draws with the additive counter and returns the per-pixel write counts.
std::vector<int> draw_counts(Renderer& r, int W, int H, const std::vector<glm::vec4>& clip,
                             const std::vector<std::uint32_t>& idx, CullMode cull = CullMode::None,
                             FrameStats* stats = nullptr) {
    Framebuffer fb(W, H);
    CountProgram p;
    p.clip = clip.data();
    r.begin_frame();
    r.draw(fb, p, std::uint32_t(clip.size()), idx.data(), idx.size(), count_state(cull));
    if (stats) *stats = r.stats();
    std::vector<int> c(std::size_t(W) * H);
    for (std::size_t i = 0; i < c.size(); ++i) {
        float v = fb.color[4 * i];
        c[i] = (std::isfinite(v) && v == std::floor(v)) ? int(v) : -1000;  // non-integer: flagged
    }
    return c;
}

int count_not_equal(const std::vector<int>& c, int value) {
    return int(std::count_if(c.begin(), c.end(), [&](int v) { return v != value; }));
}

// Window position (pixels, y down) to clip space with a given w (same NDC point).
glm::vec4 win(double x, double y, int W, int H, double z_ndc = 0.0, double w = 1.0) {
    double xn = x / W * 2.0 - 1.0, yn = 1.0 - y / H * 2.0;
    return glm::vec4(float(xn * w), float(yn * w), float(z_ndc * w), float(w));
}

// Every counter identity that holds for any draw.
void check_stats_invariants(const FrameStats& s) {
    CHECK(s.fragments_written == s.fragments_covered - s.fragments_depth_killed - s.fragments_shader_killed);
    CHECK(s.fragments_covered <= s.blocks_rasterized * 16);
    CHECK(s.quads_shaded <= s.blocks_rasterized * 4);
    CHECK(s.fragments_shaded <= s.quads_shaded * 4);
    CHECK(s.fragments_shaded <= s.fragments_written + s.fragments_shader_killed);
    CHECK(s.triangles_invalid + s.triangles_culled_frustum <= s.triangles_in);
}

// A camera with analytic pixel rays (double precision throughout).
struct Camera {
    int W = 0, H = 0;
    double fov_deg = 60, near = 0.1, far = 100;
    glm::dvec3 eye{0.0}, forward{0.0};
    glm::dmat4 view{1.0}, proj{1.0};
    double tan_half = 0, aspect = 1;

    Camera(int w, int h, glm::dvec3 e, glm::dvec3 target, double fov, double n, double f)
        : W(w), H(h), fov_deg(fov), near(n), far(f), eye(e) {
        aspect = double(W) / double(H);
        tan_half = std::tan(glm::radians(fov_deg) * 0.5);
        view = glm::lookAt(eye, target, glm::dvec3(0, 1, 0));
        proj = glm::perspective(glm::radians(fov_deg), aspect, near, far);
        forward = glm::normalize(target - eye);
    }
    glm::vec4 clip(glm::dvec3 p) const { return glm::vec4(proj * view * glm::dvec4(p, 1.0)); }
    // Ray direction (world) through window point (x, y).
    glm::dvec3 ray(double x, double y) const {
        double xn = 2.0 * x / W - 1.0, yn = 1.0 - 2.0 * y / H;
        glm::dvec3 dv(xn * aspect * tan_half, yn * tan_half, -1.0);
        glm::dmat3 inv_rot = glm::transpose(glm::dmat3(view));
        return inv_rot * dv;
    }
    double view_depth(glm::dvec3 p) const { return -(view * glm::dvec4(p, 1.0)).z; }
    double window_depth(double d) const {
        double zn = (far + near) / (far - near) - 2.0 * far * near / ((far - near) * d);
        return (zn + 1.0) * 0.5;
    }
};

// The value of `pred` at (x, y), or -1 when it changes within `margin` pixels
// (sampled on a circle and a cross): boundary pixels are skipped.
template <class Pred>
int stable_class(const Pred& pred, double x, double y, double margin) {
    int c = pred(x, y);
    for (int k = 0; k < 16; ++k) {
        double a = 2.0 * kPi * k / 16.0;
        if (pred(x + margin * std::cos(a), y + margin * std::sin(a)) != c) return -1;
    }
    for (double f : {0.5, 0.25})
        for (int k = 0; k < 4; ++k) {
            double a = kPi * 0.5 * k;
            if (pred(x + f * margin * std::cos(a), y + f * margin * std::sin(a)) != c) return -1;
        }
    return c;
}

bool inside_triangle_3d(glm::dvec3 a, glm::dvec3 b, glm::dvec3 c, glm::dvec3 p) {
    glm::dvec3 n = glm::cross(b - a, c - a);
    return glm::dot(glm::cross(b - a, p - a), n) >= 0 && glm::dot(glm::cross(c - b, p - b), n) >= 0 &&
           glm::dot(glm::cross(a - c, p - c), n) >= 0;
}

// Ray from the eye through window point (x, y) against the triangle; returns the
// hit's view depth or +inf.
double ray_triangle_depth(const Camera& cam, double x, double y, glm::dvec3 a, glm::dvec3 b, glm::dvec3 c) {
    glm::dvec3 d = cam.ray(x, y), n = glm::cross(b - a, c - a);
    double den = glm::dot(d, n);
    if (den == 0) return std::numeric_limits<double>::infinity();
    double t = glm::dot(a - cam.eye, n) / den;
    if (t <= 0) return std::numeric_limits<double>::infinity();
    glm::dvec3 p = cam.eye + t * d;
    if (!inside_triangle_3d(a, b, c, p)) return std::numeric_limits<double>::infinity();
    return cam.view_depth(p);
}

// Reference coverage of the spec: centre strictly inside, or on an edge that is
// a top edge (horizontal, interior below: y down) or a left edge (interior to
// its right); on several edges (a vertex), on top/left edges only. Exact for
// the 1/256-pixel coordinates used with it (small dyadic values).
bool spec_covers(const glm::dvec2 v[3], double px, double py) {
    double area = (v[1].x - v[0].x) * (v[2].y - v[0].y) - (v[2].x - v[0].x) * (v[1].y - v[0].y);
    if (area == 0) return false;
    for (int e = 0; e < 3; ++e) {
        glm::dvec2 a = v[e], b = v[(e + 1) % 3], o = v[(e + 2) % 3];
        // Inward normal: perpendicular to the edge, towards the opposite vertex.
        glm::dvec2 n(-(b.y - a.y), b.x - a.x);
        if (glm::dot(n, o - a) < 0) n = -n;
        double s = n.x * (px - a.x) + n.y * (py - a.y);
        if (s > 0) continue;
        if (s < 0) return false;
        bool top = n.x == 0 && n.y > 0;
        bool left = n.x > 0;
        if (!top && !left) return false;
    }
    return true;
}

// ---------------------------------------------------------------------------
// Meshes

struct MeshD {
    std::vector<glm::dvec3> pos;
    std::vector<std::uint32_t> idx;
};

// Closed UV sphere (poles are single vertices, the seam shares its vertices).
MeshD uv_sphere(int nseg, int nring, double radius, glm::dvec3 centre) {
    MeshD m;
    m.pos.push_back(centre + glm::dvec3(0, radius, 0));
    for (int r = 1; r < nring; ++r) {
        double th = kPi * r / nring;
        for (int s = 0; s < nseg; ++s) {
            double ph = 2.0 * kPi * s / nseg;
            m.pos.push_back(centre + radius * glm::dvec3(std::sin(th) * std::cos(ph), std::cos(th),
                                                         std::sin(th) * std::sin(ph)));
        }
    }
    m.pos.push_back(centre + glm::dvec3(0, -radius, 0));
    const std::uint32_t south = std::uint32_t(m.pos.size() - 1);
    auto ring = [&](int r, int s) { return std::uint32_t(1 + (r - 1) * nseg + (s % nseg)); };
    for (int s = 0; s < nseg; ++s) {
        m.idx.insert(m.idx.end(), {0u, ring(1, s), ring(1, s + 1)});
        for (int r = 1; r + 1 < nring; ++r) {
            std::uint32_t a = ring(r, s), b = ring(r, s + 1), c = ring(r + 1, s), d = ring(r + 1, s + 1);
            m.idx.insert(m.idx.end(), {a, c, d, a, d, b});
        }
        m.idx.insert(m.idx.end(), {south, ring(nring - 1, s + 1), ring(nring - 1, s)});
    }
    for (std::size_t t = 0; t < m.idx.size(); t += 3) {
        glm::dvec3 a = m.pos[m.idx[t]] - centre, b = m.pos[m.idx[t + 1]] - centre, c = m.pos[m.idx[t + 2]] - centre;
        if (glm::dot(glm::cross(b - a, c - a), a + b + c) < 0) std::swap(m.idx[t + 1], m.idx[t + 2]);
    }
    return m;
}

// Radius of the largest centred ball inside the (convex-ish) mesh: the least
// distance from the centre to a face plane.
double inscribed_radius(const MeshD& m, glm::dvec3 centre) {
    double r = std::numeric_limits<double>::infinity();
    for (std::size_t t = 0; t < m.idx.size(); t += 3) {
        glm::dvec3 a = m.pos[m.idx[t]], b = m.pos[m.idx[t + 1]], c = m.pos[m.idx[t + 2]];
        glm::dvec3 n = glm::normalize(glm::cross(b - a, c - a));
        r = std::min(r, std::abs(glm::dot(n, a - centre)));
    }
    return r;
}

std::vector<glm::vec4> project(const Camera& cam, const std::vector<glm::dvec3>& pos) {
    std::vector<glm::vec4> clip;
    clip.reserve(pos.size());
    for (const glm::dvec3& p : pos) clip.push_back(cam.clip(p));
    return clip;
}

// A jittered grid of triangles covering the viewport and a margin around it,
// random diagonals and random windings. `lattice` > 0 rounds positions to
// multiples of 1/lattice pixel (so many edges pass exactly through centres).
void jittered_grid(int W, int H, int cells_x, int cells_y, double lattice, std::uint64_t seed,
                   std::vector<glm::vec4>& clip, std::vector<std::uint32_t>& idx) {
    Random rng(seed);
    const double x0 = -9.0, y0 = -9.0;
    const double sx = (W + 18.0) / cells_x, sy = (H + 18.0) / cells_y;
    clip.clear();
    idx.clear();
    for (int j = 0; j <= cells_y; ++j)
        for (int i = 0; i <= cells_x; ++i) {
            double x = x0 + i * sx + rng.range(-0.35, 0.35) * sx;
            double y = y0 + j * sy + rng.range(-0.35, 0.35) * sy;
            if (lattice > 0) {
                x = std::round(x * lattice) / lattice;
                y = std::round(y * lattice) / lattice;
            }
            clip.push_back(win(x, y, W, H, 0.0, rng.range(0.5, 2.0)));
        }
    auto node = [&](int i, int j) { return std::uint32_t(j * (cells_x + 1) + i); };
    // Window-space signed area (y down): a, b, c / a, b, d, ... of an unjittered
    // cell are clockwise on screen, i.e. positive.
    auto area = [&](std::uint32_t p, std::uint32_t q, std::uint32_t r) {
        glm::dvec2 P(clip[p].x / clip[p].w, -clip[p].y / clip[p].w), Q(clip[q].x / clip[q].w, -clip[q].y / clip[q].w),
            R(clip[r].x / clip[r].w, -clip[r].y / clip[r].w);
        return (Q.x - P.x) * (R.y - P.y) - (R.x - P.x) * (Q.y - P.y);
    };
    for (int j = 0; j < cells_y; ++j)
        for (int i = 0; i < cells_x; ++i) {
            std::uint32_t a = node(i, j), b = node(i + 1, j), c = node(i, j + 1), d = node(i + 1, j + 1);
            // A jittered cell may be non-convex: then only the diagonal through its
            // reflex corner splits it into two triangles that do not fold over.
            bool diag_ad_ok = area(a, b, d) > 0 && area(a, d, c) > 0;
            bool diag_bc_ok = area(a, b, c) > 0 && area(b, d, c) > 0;
            REQUIRE((diag_ad_ok || diag_bc_ok));
            bool use_ad = rng.below(2) ? diag_ad_ok : !diag_bc_ok;
            std::uint32_t t[6];
            if (use_ad) { std::uint32_t u[6] = {a, b, d, a, d, c}; std::copy(u, u + 6, t); }
            else { std::uint32_t u[6] = {a, b, c, b, d, c}; std::copy(u, u + 6, t); }
            for (int k = 0; k < 2; ++k) {
                if (rng.below(2)) std::swap(t[3 * k + 1], t[3 * k + 2]);
                idx.insert(idx.end(), {t[3 * k], t[3 * k + 1], t[3 * k + 2]});
            }
        }
}

// A fan of n triangles around (cx, cy) with outer vertices on a circle.
void fan(int W, int H, double cx, double cy, double radius, int n, std::uint64_t seed,
         std::vector<glm::vec4>& clip, std::vector<std::uint32_t>& idx) {
    Random rng(seed);
    clip.clear();
    idx.clear();
    clip.push_back(win(cx, cy, W, H));
    for (int k = 0; k < n; ++k) {
        double a = 2.0 * kPi * (k + rng.range(-0.3, 0.3)) / n;
        clip.push_back(win(cx + radius * std::cos(a), cy + radius * std::sin(a), W, H));
    }
    for (int k = 0; k < n; ++k) {
        std::uint32_t a = std::uint32_t(1 + k), b = std::uint32_t(1 + (k + 1) % n);
        idx.insert(idx.end(), {0u, a, b});
    }
}

// ---------------------------------------------------------------------------
// Programs

// Records what each stage saw; used with threads = 1 (or locks).
struct RecordingObserver {
    static constexpr bool enabled = true;
    int W = 0, H = 0;
    std::mutex mutex;
    std::uint64_t vertices = 0;
    std::vector<std::vector<TriangleFate>> fates;   // per submitted triangle
    std::vector<std::set<int>> tiles;               // per submitted triangle
    std::vector<std::uint64_t> covered;             // per submitted triangle
    std::vector<int> pixel_fragments;               // per pixel
    std::vector<std::vector<std::uint32_t>> pixel_prims;  // per pixel, in call order
    std::uint64_t fragment_total = 0, pass_total = 0, live_total = 0;
    bool lane_outside_viewport = false;

    RecordingObserver(int w, int h, std::size_t tris)
        : W(w), H(h), fates(tris), tiles(tris), covered(tris), pixel_fragments(std::size_t(w) * h),
          pixel_prims(std::size_t(w) * h) {}

    void vertex(std::uint32_t, const float*, const float*, int) {
        std::lock_guard<std::mutex> lock(mutex);
        ++vertices;
    }
    void triangle(std::uint32_t prim, TriangleFate fate, bool, const TriangleSetup*) {
        std::lock_guard<std::mutex> lock(mutex);
        fates.at(prim).push_back(fate);
    }
    void binned(std::uint32_t prim, int tile) {
        std::lock_guard<std::mutex> lock(mutex);
        tiles.at(prim).insert(tile);
    }
    void fragments(std::uint32_t prim, int bx, int by, std::uint32_t mask, std::uint32_t pass, const float*) {
        std::lock_guard<std::mutex> lock(mutex);
        for (int l = 0; l < kBlockLanes; ++l) {
            if (!(mask & (1u << l))) continue;
            int x = bx + lane_x(l), y = by + lane_y(l);
            if (x < 0 || y < 0 || x >= W || y >= H) { lane_outside_viewport = true; continue; }
            ++pixel_fragments[std::size_t(y) * W + x];
            pixel_prims[std::size_t(y) * W + x].push_back(prim);
            ++covered.at(prim);
            ++fragment_total;
        }
        pass_total += std::uint64_t(__builtin_popcount(pass & 0xFFFFu));
    }
    template <int NV>
    void shaded(const FragmentBlock<NV>&, const FragmentOut&, std::uint32_t live) {
        std::lock_guard<std::mutex> lock(mutex);
        live_total += std::uint64_t(__builtin_popcount(live & 0xFFFFu));
    }
};

// The golden scene's shader: varyings = normal xyz, albedo rgb, checker u v
// (u < 0: no checker). Lambert with a fixed light plus a constant ambient.
struct SceneProgram {
    static constexpr int kVaryings = 8;
    const glm::vec4* clip = nullptr;
    const float* varyings = nullptr;
    glm::vec3 light{0.0f};
    void vertex(std::uint32_t i, float out[4], float* var) const {
        out[0] = clip[i].x; out[1] = clip[i].y; out[2] = clip[i].z; out[3] = clip[i].w;
        for (int k = 0; k < kVaryings; ++k) var[k] = varyings[i * kVaryings + k];
    }
    void fragment(const FragmentBlock<kVaryings>& in, FragmentOut& out) const {
        for (int l = 0; l < kBlockLanes; ++l) {
            out.r[l] = out.g[l] = out.b[l] = 0.0f;
            out.a[l] = 1.0f;
            if (!(in.mask & (1u << l))) continue;  // helper lanes: nothing to compute
            glm::vec3 n(in.var[0][l], in.var[1][l], in.var[2][l]);
            n = n / std::sqrt(glm::dot(n, n));
            if (!in.front_facing) n = -n;
            float ndl = std::max(glm::dot(n, light), 0.0f);
            float k = 0.18f + 0.82f * ndl;
            if (in.var[6][l] >= 0.0f) {
                int cu = int(std::floor(in.var[6][l] * 8.0f)), cv = int(std::floor(in.var[7][l] * 8.0f));
                if ((cu + cv) & 1) k *= 0.45f;
            }
            out.r[l] = in.var[3][l] * k;
            out.g[l] = in.var[4][l] * k;
            out.b[l] = in.var[5][l] * k;
        }
    }
};

// kMaxVaryings varyings: var0 = u, var1 = v and var_k = a_k u + b_k v + c_k,
// so every varying is an affine function of the surface position and must come
// out consistent with u, v. Writes u, v and the largest deviation as r, g, b.
struct ManyVaryingsProgram {
    static constexpr int kVaryings = kMaxVaryings;
    const glm::vec4* clip = nullptr;
    const float* varyings = nullptr;
    static float ka(int k) { return 0.25f * float(k) - 3.0f; }
    static float kb(int k) { return 1.5f - 0.125f * float(k); }
    static float kc(int k) { return float(k % 5) - 2.0f; }
    void vertex(std::uint32_t i, float out[4], float* var) const {
        out[0] = clip[i].x; out[1] = clip[i].y; out[2] = clip[i].z; out[3] = clip[i].w;
        for (int k = 0; k < kVaryings; ++k) var[k] = varyings[i * kVaryings + k];
    }
    void fragment(const FragmentBlock<kVaryings>& in, FragmentOut& out) const {
        for (int l = 0; l < kBlockLanes; ++l) {
            float u = in.var[0][l], v = in.var[1][l], dev = 0.0f;
            for (int k = 2; k < kVaryings; ++k)
                dev = std::max(dev, std::abs(in.var[k][l] - (ka(k) * u + kb(k) * v + kc(k))));
            out.r[l] = u; out.g[l] = v; out.b[l] = dev; out.a[l] = 1.0f;
        }
    }
};

// Varyings = window position of the vertex (use with w = 1): checks lane
// placement, derivatives, prim_id, front_facing and shader kills.
struct ProbeProgram {
    static constexpr int kVaryings = 2;
    const glm::vec4* clip = nullptr;
    const float* varyings = nullptr;
    void vertex(std::uint32_t i, float out[4], float* var) const {
        out[0] = clip[i].x; out[1] = clip[i].y; out[2] = clip[i].z; out[3] = clip[i].w;
        var[0] = varyings[2 * i]; var[1] = varyings[2 * i + 1];
    }
    static bool killed(int x, int y) { return (x + 2 * y) % 7 == 0; }
    void fragment(const FragmentBlock<2>& in, FragmentOut& out) const {
        out.kill = 0;
        for (int l = 0; l < kBlockLanes; ++l) {
            int x = in.x + lane_x(l), y = in.y + lane_y(l);
            out.r[l] = in.var[0][l] - (float(x) + 0.5f);
            out.g[l] = in.var[1][l] - (float(y) + 0.5f);
            out.b[l] = std::abs(in.ddx(0, l) - 1.0f) + std::abs(in.ddy(1, l) - 1.0f) + std::abs(in.ddx(1, l)) +
                       std::abs(in.ddy(0, l));
            out.a[l] = float(in.prim_id) + (in.front_facing ? 0.0f : 1000.0f);
            if (killed(x, y)) out.kill |= 1u << l;
        }
    }
};

std::uint8_t to_byte(float v) {
    v = std::min(std::max(v, 0.0f), 1.0f);
    return std::uint8_t(std::lround(v * 255.0f));
}

} // namespace

TEST_SUITE("raster") {

// ===========================================================================
// 1. Watertightness

TEST_CASE("watertight: jittered grid covers every pixel exactly once") {
    const int W = 250, H = 190;
    Renderer r(RendererOptions{2, 64});
    std::vector<glm::vec4> clip;
    std::vector<std::uint32_t> idx;
    for (double lattice : {0.0, 2.0, 1.0}) {  // free positions, half-pixel lattice (centres), whole pixels
        for (std::uint64_t seed : {1u, 2u}) {
            CAPTURE(lattice);
            CAPTURE(seed);
            jittered_grid(W, H, 23, 17, lattice, seed, clip, idx);
            FrameStats s;
            std::vector<int> c = draw_counts(r, W, H, clip, idx, CullMode::None, &s);
            CHECK(count_not_equal(c, 1) == 0);
            CHECK(s.triangles_in == idx.size() / 3);
            CHECK(s.fragments_covered == std::uint64_t(W) * H);
            check_stats_invariants(s);
        }
    }
}

TEST_CASE("watertight: fan around an inner centre with the outer ring far outside") {
    const int W = 200, H = 150;
    Renderer r(RendererOptions{2, 32});
    std::vector<glm::vec4> clip;
    std::vector<std::uint32_t> idx;
    // 4000 px stays inside the guard band; 3e7 px forces guard-band clipping of every triangle.
    for (double radius : {4000.0, 3.0e7}) {
        for (int n : {100, 97}) {
            CAPTURE(radius);
            CAPTURE(n);
            fan(W, H, 101.37, 77.81, radius, n, std::uint64_t(n), clip, idx);
            FrameStats s;
            std::vector<int> c = draw_counts(r, W, H, clip, idx, CullMode::None, &s);
            CHECK(count_not_equal(c, 1) == 0);
            if (radius > 1.0e6) CHECK(s.triangles_clipped == std::uint64_t(n));
            else CHECK(s.triangles_clipped == 0);
        }
    }
    // The centre exactly on a pixel centre, on a pixel corner.
    for (glm::dvec2 ctr : {glm::dvec2(100.5, 75.5), glm::dvec2(100.0, 75.0)}) {
        fan(W, H, ctr.x, ctr.y, 5000.0, 100, 7, clip, idx);
        CHECK(count_not_equal(draw_counts(r, W, H, clip, idx), 1) == 0);
    }
}

TEST_CASE("watertight: fan polygon inside the viewport covers its interior exactly once") {
    const int W = 200, H = 150;
    Renderer r(RendererOptions{2, 16});
    std::vector<glm::vec4> clip;
    std::vector<std::uint32_t> idx;
    for (int n : {100, 37, 8}) {
        CAPTURE(n);
        const double cx = 97.3, cy = 71.6, radius = 61.7;
        fan(W, H, cx, cy, radius, n, std::uint64_t(100 + n), clip, idx);
        std::vector<int> c = draw_counts(r, W, H, clip, idx);
        // Polygon edges (window space, from the same outer vertices as the fan).
        std::vector<glm::dvec2> poly;
        for (int k = 1; k <= n; ++k)
            poly.push_back({(double(clip[k].x) + 1.0) * 0.5 * W, (1.0 - double(clip[k].y)) * 0.5 * H});
        int ones = 0, bad = 0, inner_checked = 0, outer_checked = 0;
        for (int y = 0; y < H; ++y)
            for (int x = 0; x < W; ++x) {
                int v = c[std::size_t(y) * W + x];
                if (v != 0 && v != 1) ++bad;
                ones += v == 1;
                glm::dvec2 p(x + 0.5, y + 0.5);
                double dmin = std::numeric_limits<double>::infinity();
                for (int k = 0; k < n; ++k) {
                    glm::dvec2 a = poly[std::size_t(k)], b = poly[std::size_t((k + 1) % n)];
                    glm::dvec2 e = glm::normalize(b - a);
                    glm::dvec2 inward(-e.y, e.x);  // polygon is clockwise on screen (y down)
                    if (glm::dot(inward, glm::dvec2(cx, cy) - a) < 0) inward = -inward;
                    dmin = std::min(dmin, glm::dot(inward, p - a));
                }
                if (dmin > 1.0) { ++inner_checked; bad += v != 1; }
                if (dmin < -1.0) { ++outer_checked; bad += v != 0; }
            }
        CHECK(bad == 0);
        CHECK(inner_checked > 8000);
        CHECK(outer_checked > 10000);
        CHECK(ones > inner_checked);
    }
}

namespace {

struct SphereView {
    Camera cam;
    MeshD mesh;
    std::vector<glm::vec4> clip;
    double r_out_pix = 0, r_in_pix = 0;  // silhouette radius of the true sphere, of its inscribed ball
};

SphereView make_sphere_view(int W, int H) {
    const double radius = 1.0;
    const glm::dvec3 centre(0.2, -0.1, -0.3);
    const glm::dvec3 eye = centre + glm::dvec3(0.4, 0.9, 3.2);
    SphereView v{Camera(W, H, eye, centre, 50.0, 0.1, 100.0), uv_sphere(48, 24, radius, centre), {}, 0, 0};
    v.clip = project(v.cam, v.mesh.pos);
    const double dist = glm::length(eye - centre);
    const double r_in = inscribed_radius(v.mesh, centre);
    auto silhouette = [&](double r) { return std::tan(std::asin(r / dist)) / v.cam.tan_half * H * 0.5; };
    v.r_out_pix = silhouette(radius);
    v.r_in_pix = silhouette(r_in);
    return v;
}

// Counts 0/1 everywhere, 1 inside the silhouette (minus margin), 0 outside (plus margin).
void check_sphere_counts(Renderer& r, const SphereView& v, int W, int H) {
    FrameStats s;
    std::vector<int> c = draw_counts(r, W, H, v.clip, v.mesh.idx, CullMode::Back, &s);
    int bad = 0, inside = 0, outside = 0;
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x) {
            int n = c[std::size_t(y) * W + x];
            double d = std::hypot(x + 0.5 - W * 0.5, y + 0.5 - H * 0.5);
            if (n != 0 && n != 1) ++bad;
            if (d < v.r_in_pix - 1.5) { ++inside; bad += n != 1; }
            if (d > v.r_out_pix + 1.5) { ++outside; bad += n != 0; }
        }
    CHECK(bad == 0);
    CHECK(inside > 10000);
    CHECK(outside > 10000);
    CHECK(s.triangles_culled_back > 0);
}

} // namespace

TEST_CASE("watertight: perspective UV sphere, back faces culled, covers its silhouette disc once") {
    const int W = 256, H = 192;
    SphereView v = make_sphere_view(W, H);
    REQUIRE(v.r_in_pix > 50.0);
    REQUIRE(v.r_out_pix - v.r_in_pix < 0.5);
    Renderer r(RendererOptions{2, 64});
    check_sphere_counts(r, v, W, H);
}

TEST_CASE("watertight: sphere and grid under every thread count and tile size") {
    const int W = 256, H = 192;
    SphereView v = make_sphere_view(W, H);
    std::vector<glm::vec4> grid_clip;
    std::vector<std::uint32_t> grid_idx;
    jittered_grid(W, H, 19, 13, 2.0, 99, grid_clip, grid_idx);
    for (int threads : {1, 2, 3, 8}) {
        for (int tile : {16, 64, 256}) {
            CAPTURE(threads);
            CAPTURE(tile);
            Renderer r(RendererOptions{threads, tile});
            REQUIRE(r.threads() == threads);
            REQUIRE(r.tile_size() == tile);
            check_sphere_counts(r, v, W, H);
            CHECK(count_not_equal(draw_counts(r, W, H, grid_clip, grid_idx), 1) == 0);
        }
    }
}

// ===========================================================================
// 2. Fill rule

namespace {

// Window-space triangle list (coordinates exact in clip space for power-of-two viewports).
struct WinTris {
    int W, H;
    std::vector<glm::vec4> clip;
    std::vector<std::uint32_t> idx;
    void add(glm::dvec2 a, glm::dvec2 b, glm::dvec2 c) {
        std::uint32_t base = std::uint32_t(clip.size());
        for (glm::dvec2 p : {a, b, c}) clip.push_back(win(p.x, p.y, W, H));
        idx.insert(idx.end(), {base, base + 1, base + 2});
    }
};

std::string pixel_list(const std::vector<int>& c, int W, int H) {
    std::string s;
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x)
            if (c[std::size_t(y) * W + x]) s += "(" + std::to_string(x) + "," + std::to_string(y) + ")";
    return s;
}

} // namespace

TEST_CASE("fill rule: square with corners on pixel centres covers [x0, x1) x [y0, y1) in every split") {
    const int W = 16, H = 16;
    Renderer r(RendererOptions{1, 16});
    // (x0, y0) - (x1, y1): corners at centres; expected pixels x in [x0 - .5, x1 - .5).
    const double squares[][4] = {{2.5, 2.5, 6.5, 6.5}, {9.5, 3.5, 13.5, 12.5}, {0.5, 10.5, 3.5, 15.5}};
    for (const auto& sq : squares) {
        glm::dvec2 p00(sq[0], sq[1]), p10(sq[2], sq[1]), p01(sq[0], sq[3]), p11(sq[2], sq[3]);
        for (int diag = 0; diag < 2; ++diag)
            for (int flip = 0; flip < 2; ++flip)        // winding
                for (int rot = 0; rot < 3; ++rot) {     // which vertex comes first
                    WinTris t{W, H, {}, {}};
                    glm::dvec2 tri[2][3];
                    if (diag == 0) { tri[0][0] = p00; tri[0][1] = p10; tri[0][2] = p11; tri[1][0] = p00; tri[1][1] = p11; tri[1][2] = p01; }
                    else { tri[0][0] = p00; tri[0][1] = p10; tri[0][2] = p01; tri[1][0] = p10; tri[1][1] = p11; tri[1][2] = p01; }
                    for (auto& tr : tri) {
                        glm::dvec2 v[3] = {tr[rot % 3], tr[(rot + 1) % 3], tr[(rot + 2) % 3]};
                        if (flip) std::swap(v[1], v[2]);
                        t.add(v[0], v[1], v[2]);
                    }
                    std::vector<int> c = draw_counts(r, W, H, t.clip, t.idx, CullMode::None);
                    int bad = 0;
                    for (int y = 0; y < H; ++y)
                        for (int x = 0; x < W; ++x) {
                            bool in = x + 0.5 >= sq[0] && x + 0.5 < sq[2] && y + 0.5 >= sq[1] && y + 0.5 < sq[3];
                            bad += c[std::size_t(y) * W + x] != (in ? 1 : 0);
                        }
                    CAPTURE(diag);
                    CAPTURE(flip);
                    CAPTURE(rot);
                    CAPTURE(pixel_list(c, W, H));
                    CHECK(bad == 0);
                }
    }
    // Mirrored images of the first square (x -> W - x, y -> H - y) are squares too.
    {
        WinTris t{W, H, {}, {}};
        t.add({16 - 2.5, 2.5}, {16 - 6.5, 2.5}, {16 - 6.5, 6.5});
        t.add({16 - 2.5, 2.5}, {16 - 6.5, 6.5}, {16 - 2.5, 6.5});
        std::vector<int> c = draw_counts(r, W, H, t.clip, t.idx, CullMode::None);
        for (int y = 0; y < H; ++y)
            for (int x = 0; x < W; ++x) {
                bool in = x >= 9 && x <= 12 && y >= 2 && y <= 5;
                CHECK(c[std::size_t(y) * W + x] == (in ? 1 : 0));
            }
    }
}

TEST_CASE("fill rule: diamond with vertices on pixel centres keeps its left edges and left vertex only") {
    const int W = 32, H = 32;
    Renderer r(RendererOptions{1, 16});
    const double cx = 15.5, cy = 14.5, R = 6.0;
    glm::dvec2 top(cx, cy - R), right(cx + R, cy), bottom(cx, cy + R), left(cx - R, cy);
    for (int split = 0; split < 2; ++split)
        for (int flip = 0; flip < 2; ++flip) {
            WinTris t{W, H, {}, {}};
            auto add = [&](glm::dvec2 a, glm::dvec2 b, glm::dvec2 c) { flip ? t.add(a, c, b) : t.add(a, b, c); };
            if (split == 0) { add(top, right, bottom); add(top, bottom, left); }
            else { add(left, top, right); add(left, right, bottom); }
            std::vector<int> c = draw_counts(r, W, H, t.clip, t.idx, CullMode::None);
            int bad = 0;
            for (int y = 0; y < H; ++y)
                for (int x = 0; x < W; ++x) {
                    double dx = x + 0.5 - cx, dy = y + 0.5 - cy, s = std::abs(dx) + std::abs(dy);
                    bool in = s < R || (s == R && dx < 0);  // on the boundary: the two left edges, left vertex
                    bad += c[std::size_t(y) * W + x] != (in ? 1 : 0);
                }
            CAPTURE(split);
            CAPTURE(flip);
            CHECK(bad == 0);
        }
}

TEST_CASE("fill rule: horizontal top edge included, bottom excluded; left vertical edge included, right excluded") {
    const int W = 16, H = 16;
    Renderer r(RendererOptions{1, 16});
    auto single = [&](glm::dvec2 a, glm::dvec2 b, glm::dvec2 c) {
        WinTris t{W, H, {}, {}};
        t.add(a, b, c);
        return draw_counts(r, W, H, t.clip, t.idx, CullMode::None);
    };
    auto row = [&](const std::vector<int>& c, int y) {
        std::vector<int> xs;
        for (int x = 0; x < W; ++x) if (c[std::size_t(y) * W + x]) xs.push_back(x);
        return xs;
    };
    auto col = [&](const std::vector<int>& c, int x) {
        std::vector<int> ys;
        for (int y = 0; y < H; ++y) if (c[std::size_t(y) * W + x]) ys.push_back(y);
        return ys;
    };
    auto range = [](int a, int b) { std::vector<int> v; for (int i = a; i <= b; ++i) v.push_back(i); return v; };
    for (int flip = 0; flip < 2; ++flip) {
        CAPTURE(flip);
        auto tri = [&](glm::dvec2 a, glm::dvec2 b, glm::dvec2 c) { return flip ? single(a, c, b) : single(a, b, c); };
        // Top edge y = 2.5 from x = 2.5 to 10.5, apex below: row 2 is x = 2..9 (the
        // left end vertex sits on the top and a left edge; the right end on a right edge).
        std::vector<int> c = tri({2.5, 2.5}, {10.5, 2.5}, {6.5, 10.5});
        CHECK(row(c, 2) == range(2, 9));
        CHECK(row(c, 1).empty());
        // Bottom edge y = 10.5, apex above: row 10 is empty, row 9 is not.
        c = tri({6.5, 2.5}, {10.5, 10.5}, {2.5, 10.5});
        CHECK(row(c, 10).empty());
        CHECK(!row(c, 9).empty());
        CHECK(row(c, 2) == std::vector<int>{});  // the apex vertex is on a right edge
        // Left vertical edge x = 2.5 from y = 2.5 to 10.5, apex right: column 2 is
        // y = 3..9 (both end vertices also lie on non-left, non-top edges).
        c = tri({2.5, 2.5}, {2.5, 10.5}, {10.5, 6.5});
        CHECK(col(c, 2) == range(3, 9));
        CHECK(col(c, 1).empty());
        // Right vertical edge x = 10.5, apex left: column 10 is empty, column 9 is not.
        c = tri({10.5, 2.5}, {10.5, 10.5}, {2.5, 6.5});
        CHECK(col(c, 10).empty());
        CHECK(!col(c, 9).empty());
        // Its apex (2.5, 6.5) lies on two left edges: covered.
        CHECK(c[6 * W + 2] == 1);
    }
}

TEST_CASE("fill rule: eight triangles around a vertex on a pixel centre cover it exactly once") {
    const int W = 16, H = 16;
    Renderer r(RendererOptions{1, 16});
    const glm::dvec2 ctr(8.5, 8.5);
    const glm::dvec2 ring[8] = {{12.5, 8.5}, {12.5, 4.5}, {8.5, 4.5}, {4.5, 4.5},
                                {4.5, 8.5},  {4.5, 12.5}, {8.5, 12.5}, {12.5, 12.5}};
    for (int flip = 0; flip < 2; ++flip) {
        WinTris t{W, H, {}, {}};
        for (int k = 0; k < 8; ++k) {
            if ((k + flip) % 2) t.add(ctr, ring[k], ring[(k + 1) % 8]);
            else t.add(ring[(k + 1) % 8], ring[k], ctr);  // mixed windings and starting vertices
        }
        std::vector<int> c = draw_counts(r, W, H, t.clip, t.idx, CullMode::None);
        CHECK(c[8 * W + 8] == 1);
        int bad = 0;
        for (int y = 0; y < H; ++y)
            for (int x = 0; x < W; ++x) {
                bool in = x >= 4 && x <= 11 && y >= 4 && y <= 11;
                bad += c[std::size_t(y) * W + x] != (in ? 1 : 0);
            }
        CHECK(bad == 0);
    }
    // The same vertex with an irregular ring far outside: every pixel once.
    {
        WinTris t{W, H, {}, {}};
        Random rng(5);
        std::vector<glm::dvec2> far_ring;
        for (int k = 0; k < 8; ++k) {
            double a = 2.0 * kPi * (k + rng.range(-0.3, 0.3)) / 8.0;
            far_ring.push_back(ctr + 300.0 * glm::dvec2(std::cos(a), std::sin(a)));
        }
        for (int k = 0; k < 8; ++k) t.add(ctr, far_ring[std::size_t(k)], far_ring[std::size_t((k + 1) % 8)]);
        std::vector<int> c = draw_counts(r, W, H, t.clip, t.idx, CullMode::None);
        CHECK(count_not_equal(c, 1) == 0);
    }
}

TEST_CASE("fill rule: random triangles on the half-pixel lattice match the top-left rule exactly") {
    const int W = 32, H = 32;
    Renderer r(RendererOptions{1, 16});
    Random rng(2024);
    int drawn = 0, on_edge_pixels = 0, mismatches = 0;
    for (int i = 0; i < 400; ++i) {
        glm::dvec2 v[3];
        for (auto& p : v) p = {rng.below(2 * W + 8) * 0.5 - 2.0, rng.below(2 * H + 8) * 0.5 - 2.0};
        double area = (v[1].x - v[0].x) * (v[2].y - v[0].y) - (v[2].x - v[0].x) * (v[1].y - v[0].y);
        if (area == 0) continue;
        WinTris t{W, H, {}, {}};
        t.add(v[0], v[1], v[2]);
        std::vector<int> c = draw_counts(r, W, H, t.clip, t.idx, CullMode::None);
        ++drawn;
        for (int y = 0; y < H; ++y)
            for (int x = 0; x < W; ++x) {
                bool expect = spec_covers(v, x + 0.5, y + 0.5);
                int got = c[std::size_t(y) * W + x];
                if (got != (expect ? 1 : 0)) {
                    if (mismatches < 5)
                        MESSAGE("triangle (" << v[0].x << "," << v[0].y << ") (" << v[1].x << "," << v[1].y << ") ("
                                             << v[2].x << "," << v[2].y << ") pixel " << x << "," << y << " got "
                                             << got << " expected " << expect);
                    ++mismatches;
                }
                // Count centres lying exactly on an edge line, to know the rule was exercised.
                for (int e = 0; e < 3; ++e) {
                    glm::dvec2 a = v[e], b = v[(e + 1) % 3];
                    double s = (b.x - a.x) * (y + 0.5 - a.y) - (b.y - a.y) * (x + 0.5 - a.x);
                    if (s == 0 && x + 0.5 >= std::min(a.x, b.x) && x + 0.5 <= std::max(a.x, b.x) &&
                        y + 0.5 >= std::min(a.y, b.y) && y + 0.5 <= std::max(a.y, b.y))
                        ++on_edge_pixels;
                }
            }
    }
    CHECK(drawn > 350);
    CHECK(on_edge_pixels > 1000);
    CHECK(mismatches == 0);
}

TEST_CASE("fill rule: long triangles (edges to 2,000 px, far from the view) match the top-left rule exactly") {
    // One vertex near the 64x64 view, two up to 1,000 px away: edge values at
    // the view's blocks reach 2^36 and more (beyond 32 bits), the blocks'
    // classifications meet long edges at every angle, and most edges stay
    // under 2,048 px in |dx| + |dy|, a few beyond.
    const int W = 64, H = 64;
    Random rng(4242);
    int narrow = 0, wide = 0, covered = 0, mismatches = 0;
    for (int split = 0; split < 2; ++split) {
        Renderer r(RendererOptions{1 + split, split ? 16 : 64});
        for (int i = 0; i < 150; ++i) {
            glm::dvec2 v[3];
            v[0] = {rng.below(2 * (W + 16)) * 0.5 - 8.0, rng.below(2 * (H + 16)) * 0.5 - 8.0};
            for (int k = 1; k < 3; ++k) v[k] = {rng.below(4128) * 0.5 - 1000.0, rng.below(4128) * 0.5 - 1000.0};
            const double area = (v[1].x - v[0].x) * (v[2].y - v[0].y) - (v[2].x - v[0].x) * (v[1].y - v[0].y);
            if (area == 0) continue;
            double longest = 0;
            for (int e = 0; e < 3; ++e)
                longest = std::max(longest, std::abs(v[(e + 1) % 3].x - v[e].x) + std::abs(v[(e + 1) % 3].y - v[e].y));
            (longest <= 2048 ? narrow : wide) += 1;
            WinTris t{W, H, {}, {}};
            t.add(v[0], v[1], v[2]);
            const std::vector<int> c = draw_counts(r, W, H, t.clip, t.idx, CullMode::None);
            for (int y = 0; y < H; ++y)
                for (int x = 0; x < W; ++x) {
                    const bool expect = spec_covers(v, x + 0.5, y + 0.5);
                    const int got = c[std::size_t(y) * W + x];
                    covered += got == 1;
                    if (got != (expect ? 1 : 0) && ++mismatches <= 5)
                        MESSAGE("triangle (" << v[0].x << "," << v[0].y << ") (" << v[1].x << "," << v[1].y << ") ("
                                             << v[2].x << "," << v[2].y << ") pixel " << x << "," << y << " got "
                                             << got << " expected " << expect);
                }
        }
    }
    CHECK(mismatches == 0);
    CHECK(narrow > 150);
    CHECK(wide > 10);
    CHECK(covered > 100000);
}

// ===========================================================================
// 3. Perspective-correct interpolation

namespace {

struct GroundScene {
    Camera cam;
    double x0, x1, z0, z1;  // quad extent on the plane y = 0
    std::vector<glm::dvec3> pos;
    std::vector<float> uv;
    std::vector<std::uint32_t> idx;
    GroundScene(const Camera& c, double xa, double xb, double za, double zb)
        : cam(c), x0(xa), x1(xb), z0(za), z1(zb) {
        pos = {{x0, 0, z0}, {x1, 0, z0}, {x1, 0, z1}, {x0, 0, z1}};
        for (const glm::dvec3& p : pos) {
            uv.push_back(float((p.x - x0) / (x1 - x0)));
            uv.push_back(float((p.z - z0) / (z1 - z0)));
        }
        idx = {0, 2, 1, 0, 3, 2};  // the quad faces up (+y)
    }
    // Analytic hit of the pixel-centre ray with the plane: false if none.
    bool hit(double x, double y, glm::dvec3& p) const {
        glm::dvec3 d = cam.ray(x, y);
        if (d.y >= 0) return false;
        double t = -cam.eye.y / d.y;
        p = cam.eye + t * d;
        return true;
    }
    glm::dvec2 uv_at(glm::dvec3 p) const { return {(p.x - x0) / (x1 - x0), (p.z - z0) / (z1 - z0)}; }
    // Coverage predicate: on the quad, between the near and far planes.
    int covered(double x, double y) const {
        glm::dvec3 p(0.0);
        if (!hit(x, y, p)) return 0;
        if (p.x < x0 || p.x > x1 || p.z < z0 || p.z > z1) return 0;
        double d = cam.view_depth(p);
        return d >= cam.near && d <= cam.far;
    }
};

struct UvResult {
    double max_err = 0;
    int covered = 0, coverage_mismatch = 0, coverage_checked = 0, non_finite = 0, depth_out_of_range = 0;
};

// Draws the ground quad with ClipProgram<2> (u, v -> r, g) and compares every
// covered pixel with the analytic mapping. `affine`: pass clip positions divided
// by w, which makes interpolation screen-linear.
UvResult render_ground_uv(Renderer& r, const GroundScene& g, bool affine, Framebuffer* out_fb = nullptr,
                          FrameStats* out_stats = nullptr) {
    const int W = g.cam.W, H = g.cam.H;
    std::vector<glm::vec4> clip = project(g.cam, g.pos);
    if (affine)
        for (glm::vec4& c : clip) c = glm::vec4(c.x / c.w, c.y / c.w, c.z / c.w, 1.0f);
    Framebuffer fb(W, H);
    fb.clear(0, 0, 0, 0);
    ClipProgram<2> p;
    p.clip = clip.data();
    p.varyings = g.uv.data();
    DrawState st;
    st.cull = CullMode::None;
    r.begin_frame();
    r.draw(fb, p, std::uint32_t(clip.size()), g.idx.data(), g.idx.size(), st);
    UvResult res;
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x) {
            const float* c = fb.pixel(x, y);
            float z = fb.depth[std::size_t(y) * W + x];
            if (!std::isfinite(c[0]) || !std::isfinite(c[1]) || !std::isfinite(c[3]) || !std::isfinite(z)) ++res.non_finite;
            if (!(z >= 0.0f && z <= 1.0f)) ++res.depth_out_of_range;
            bool cov = c[3] == 1.0f;
            int expect = stable_class([&](double px, double py) { return g.covered(px, py); }, x + 0.5, y + 0.5, 1.0);
            if (expect >= 0) {
                ++res.coverage_checked;
                res.coverage_mismatch += int(cov) != expect;
            }
            if (!cov) continue;
            ++res.covered;
            glm::dvec3 hp(0.0);
            if (!g.hit(x + 0.5, y + 0.5, hp)) { res.max_err = std::numeric_limits<double>::infinity(); continue; }
            glm::dvec2 uv = g.uv_at(hp);
            double err = std::max(std::abs(uv.x - c[0]), std::abs(uv.y - c[1]));
            res.max_err = std::max(res.max_err, err);
        }
    if (out_fb) *out_fb = fb;
    if (out_stats) *out_stats = r.stats();
    return res;
}

} // namespace

TEST_CASE("perspective: varyings of a steep ground plane match the ray-plane mapping; affine would not") {
    const int W = 240, H = 180;
    // Eye 1.5 above the plane, looking 15 degrees below the horizon (75 degrees
    // from the plane's normal at the centre of the view).
    const double pitch = glm::radians(15.0);
    Camera cam(W, H, {0, 1.5, 0}, {0, 0, -1.5 / std::tan(pitch)}, 60.0, 0.1, 100.0);
    GroundScene g(cam, -4.0, 4.0, -30.0, -1.0);
    Renderer r(RendererOptions{2, 64});
    UvResult persp = render_ground_uv(r, g, false);
    UvResult affine = render_ground_uv(r, g, true);
    MESSAGE("max UV error: perspective-correct " << persp.max_err << ", screen-linear " << affine.max_err
                                                 << " over " << persp.covered << " pixels");
    CHECK(persp.covered > W * H / 4);
    CHECK(persp.non_finite == 0);
    CHECK(persp.coverage_mismatch == 0);
    CHECK(persp.coverage_checked > W * H * 9 / 10);
    CHECK(persp.max_err < 1e-3);
    // The same pipeline with w = 1 interpolates in screen space and is far off:
    // the test above can fail.
    CHECK(affine.covered > W * H / 4);
    CHECK(affine.max_err > 0.01);
}

TEST_CASE("perspective: all kMaxVaryings varyings are interpolated consistently, through near clipping") {
    const int W = 160, H = 120;
    Camera cam(W, H, {0, 1, 0}, {0, 0, -4}, 60.0, 1.5, 100.0);
    GroundScene g(cam, -50.0, 50.0, -60.0, 20.0);
    std::vector<glm::vec4> clip = project(cam, g.pos);
    std::vector<float> var;
    for (std::size_t i = 0; i < g.pos.size(); ++i) {
        float u = g.uv[2 * i], v = g.uv[2 * i + 1];
        var.push_back(u);
        var.push_back(v);
        for (int k = 2; k < kMaxVaryings; ++k)
            var.push_back(ManyVaryingsProgram::ka(k) * u + ManyVaryingsProgram::kb(k) * v + ManyVaryingsProgram::kc(k));
    }
    ManyVaryingsProgram p;
    p.clip = clip.data();
    p.varyings = var.data();
    Framebuffer fb(W, H);
    fb.clear(0, 0, 0, 0);
    DrawState st;
    st.cull = CullMode::None;
    Renderer r(RendererOptions{2, 32});
    r.begin_frame();
    r.draw(fb, p, std::uint32_t(clip.size()), g.idx.data(), g.idx.size(), st);
    CHECK(r.stats().triangles_clipped == 2);
    int covered = 0;
    double max_uv = 0, max_dev = 0;
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x) {
            const float* c = fb.pixel(x, y);
            if (c[3] != 1.0f) continue;
            ++covered;
            glm::dvec3 hp(0.0);
            REQUIRE(g.hit(x + 0.5, y + 0.5, hp));
            glm::dvec2 uv = g.uv_at(hp);
            max_uv = std::max({max_uv, std::abs(uv.x - c[0]), std::abs(uv.y - c[1])});
            max_dev = std::max(max_dev, double(c[2]));
        }
    MESSAGE(kMaxVaryings << " varyings: max UV error " << max_uv << ", max deviation of the others " << max_dev);
    CHECK(covered > W * H / 4);
    CHECK(max_uv < 1e-3);
    CHECK(max_dev < 1e-3);
}

// ===========================================================================
// 4. Clipping

TEST_CASE("clipping: ground quad through the near plane and behind the camera") {
    const int W = 240, H = 180;
    // Near = 1.5 cuts away the bottom rows (the ground there is nearer than 1.5);
    // the quad's back edge (z = +20) is behind the eye, so two vertices have w < 0.
    Camera cam(W, H, {0, 1, 0}, {0, 0, -4}, 60.0, 1.5, 100.0);
    GroundScene g(cam, -50.0, 50.0, -60.0, 20.0);
    std::vector<glm::vec4> clip = project(cam, g.pos);
    int negative_w = 0;
    for (const glm::vec4& c : clip) negative_w += c.w < 0;
    REQUIRE(negative_w == 2);
    Renderer r(RendererOptions{2, 32});
    Framebuffer fb;
    FrameStats s;
    UvResult res = render_ground_uv(r, g, false, &fb, &s);
    MESSAGE("near-clipped ground: max UV error " << res.max_err << " over " << res.covered << " pixels");
    CHECK(res.non_finite == 0);
    CHECK(res.depth_out_of_range == 0);
    CHECK(res.coverage_mismatch == 0);
    CHECK(res.coverage_checked > W * H * 9 / 10);
    CHECK(res.max_err < 1e-3);
    CHECK(s.triangles_clipped == 2);
    CHECK(s.triangles_invalid == 0);
    check_stats_invariants(s);
    // Sanity of the analytic expectation itself: the sky (top row) is empty, the
    // middle row is ground, and the bottom row is cut by the near plane.
    CHECK(g.covered(W * 0.5, 0.5) == 0);
    CHECK(g.covered(W * 0.5, H * 0.5) == 1);
    CHECK(g.covered(W * 0.5, H - 0.5) == 0);
    int bottom_rows_covered = 0;
    for (int x = 0; x < W; ++x) bottom_rows_covered += fb.pixel(x, H - 1)[3] == 1.0f;
    CHECK(bottom_rows_covered == 0);
}

TEST_CASE("clipping: triangle entirely behind the camera is culled and counted") {
    const int W = 64, H = 48;
    Camera cam(W, H, {0, 1, 0}, {0, 1, -5}, 60.0, 0.1, 100.0);
    // Behind the eye, large and centred on the view axis: projected naively it would
    // land on screen (mirrored).
    std::vector<glm::dvec3> pos = {{-3, -2, 4}, {3, -2, 4}, {0, 4, 4}, {-30, -20, 1}, {30, -20, 1}, {0, 40, 0.5}};
    std::vector<glm::vec4> clip = project(cam, pos);
    for (const glm::vec4& c : clip) REQUIRE(c.w < 0);
    std::vector<std::uint32_t> idx = {0, 1, 2, 3, 4, 5, 0, 2, 1};
    Renderer r(RendererOptions{1, 16});
    FrameStats s;
    std::vector<int> c = draw_counts(r, W, H, clip, idx, CullMode::None, &s);
    CHECK(count_not_equal(c, 0) == 0);
    CHECK(s.triangles_in == 3);
    CHECK(s.triangles_culled_frustum == 3);
    CHECK(s.triangles_setup == 0);
    CHECK(s.fragments_covered == 0);
}

TEST_CASE("clipping: triangle through the far plane draws only the part nearer than far") {
    const int W = 240, H = 180;
    Camera cam(W, H, {0, 1, 0}, {0, 0.6, -10}, 60.0, 0.5, 12.0);
    // A ground triangle reaching from in front of the near plane to far beyond far.
    std::vector<glm::dvec3> pos = {{-6, 0, -1}, {6, 0, -1}, {0.7, 0, -80}};
    std::vector<glm::vec4> clip = project(cam, pos);
    std::vector<std::uint32_t> idx = {0, 1, 2};
    auto covered = [&](double x, double y) {
        double d = ray_triangle_depth(cam, x, y, pos[0], pos[1], pos[2]);
        return int(d >= cam.near && d <= cam.far);
    };
    auto beyond_far = [&](double x, double y) {
        double d = ray_triangle_depth(cam, x, y, pos[0], pos[1], pos[2]);
        return int(std::isfinite(d) && d > cam.far);
    };
    Renderer r(RendererOptions{2, 64});
    // Coverage with depth testing off (so nothing is hidden by a clamped depth).
    FrameStats s;
    std::vector<int> c = draw_counts(r, W, H, clip, idx, CullMode::None, &s);
    // Depth with a plain draw.
    Framebuffer fb(W, H);
    ClipProgram<0> p;
    p.clip = clip.data();
    DrawState st;
    st.cull = CullMode::None;
    r.draw(fb, p, 3, idx.data(), 3, st);
    int mismatch = 0, checked = 0, beyond = 0, written = 0, depth_bad = 0;
    double max_depth_err = 0;
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x) {
            double px = x + 0.5, py = y + 0.5;
            int n = c[std::size_t(y) * W + x];
            int e = stable_class(covered, px, py, 1.0);
            if (e >= 0) { ++checked; mismatch += n != e; }
            beyond += stable_class(beyond_far, px, py, 1.0) == 1;
            float z = fb.depth[std::size_t(y) * W + x];
            if (!(z >= 0.0f && z <= 1.0f)) ++depth_bad;
            if (n == 1) {
                ++written;
                double d = ray_triangle_depth(cam, px, py, pos[0], pos[1], pos[2]);
                if (std::isfinite(d) && d <= cam.far) max_depth_err = std::max(max_depth_err, std::abs(cam.window_depth(d) - z));
            }
        }
    MESSAGE("far clip: " << written << " pixels, max depth error " << max_depth_err);
    CHECK(beyond > 200);  // the analytic triangle really does extend beyond far on screen
    CHECK(checked > W * H * 9 / 10);
    CHECK(mismatch == 0);
    CHECK(depth_bad == 0);
    CHECK(written > 2000);
    CHECK(max_depth_err < 2e-5);
    CHECK(s.triangles_clipped == 1);
}

TEST_CASE("clipping: huge triangles far beyond the guard band cover the viewport exactly once") {
    const int W = 200, H = 150;
    Renderer r(RendererOptions{2, 64});
    // NDC +-2e4 is 2e6 pixels away: beyond the 2^20-pixel guard band.
    for (int variant = 0; variant < 3; ++variant) {
        CAPTURE(variant);
        std::vector<glm::vec4> clip;
        std::vector<std::uint32_t> idx;
        const double ws[4] = {1.0, 2.5, 0.5, 3.0};
        auto add = [&](double xn, double yn, int k) {
            double w = variant == 0 ? 1.0 : ws[k];
            clip.push_back(glm::vec4(float(xn * w), float(yn * w), float(0.25 * w), float(w)));
        };
        if (variant < 2) {  // one triangle
            add(-2.0e4, -2.0e4, 0);
            add(6.0e4, -2.0e4, 1);
            add(-2.0e4, 6.0e4, 2);
            idx = {0, 1, 2};
        } else {            // a quad: the shared diagonal is clipped by both triangles
            add(-3.0e4, -2.0e4, 0);
            add(2.0e4, -3.0e4, 1);
            add(3.0e4, 2.5e4, 2);
            add(-2.0e4, 3.0e4, 3);
            idx = {0, 1, 2, 0, 2, 3};
        }
        FrameStats s;
        std::vector<int> c = draw_counts(r, W, H, clip, idx, CullMode::None, &s);
        CHECK(count_not_equal(c, 1) == 0);
        CHECK(s.triangles_clipped == idx.size() / 3);
        CHECK(s.fragments_covered == std::uint64_t(W) * H);
        // Depth: z_ndc = 0.25 everywhere -> window depth 0.625.
        Framebuffer fb(W, H);
        ClipProgram<0> p;
        p.clip = clip.data();
        DrawState st;
        st.cull = CullMode::None;
        r.draw(fb, p, std::uint32_t(clip.size()), idx.data(), idx.size(), st);
        float zmin = *std::min_element(fb.depth.begin(), fb.depth.end());
        float zmax = *std::max_element(fb.depth.begin(), fb.depth.end());
        CHECK(zmin >= 0.625f - 1e-4f);
        CHECK(zmax <= 0.625f + 1e-4f);
    }
}

TEST_CASE("clipping: degenerate and invalid triangles are dropped and counted") {
    const int W = 32, H = 32;
    Renderer r(RendererOptions{2, 16});
    const float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
    std::vector<glm::vec4> clip = {
        win(2.5, 2.5, W, H), win(20.5, 2.5, W, H), win(11.5, 2.5, W, H),   // 0-2: collinear
        win(3.0, 20.0, W, H), win(28.0, 25.0, W, H),                        // 3-4
        win(3.1, 3.1, W, H), win(3.4, 3.1, W, H), win(3.1, 3.4, W, H),      // 5-7: between pixel centres
        win(9.1, 9.1, W, H), win(9.1 + 1e-4, 9.1, W, H), win(9.1, 9.1 + 1e-4, W, H),  // 8-10: snaps to a point
        glm::vec4(nan, 0, 0, 1), glm::vec4(0, inf, 0, 1), glm::vec4(0, 0, -inf, 1), glm::vec4(0, 0, 0, nan),  // 11-14
        win(16, 16, W, H),                                                  // 15
    };
    const std::uint32_t n = std::uint32_t(clip.size());
    std::vector<std::uint32_t> idx = {
        0, 1, 2,          // collinear
        3, 3, 4,          // repeated vertex
        5, 6, 7,          // no pixel centre inside
        8, 9, 10,         // zero area after snapping
        11, 3, 4,         // NaN x
        3, 12, 4,         // +Inf y
        3, 4, 13,         // -Inf z
        14, 3, 4,         // NaN w
        3, 4, n,          // index out of range
        0xFFFFFFFFu, 3, 4 // index far out of range
    };
    Framebuffer fb(W, H);
    ClipProgram<0> p;
    p.clip = clip.data();
    DrawState st;
    st.cull = CullMode::None;
    r.begin_frame();
    r.draw(fb, p, n, idx.data(), idx.size(), st);
    const FrameStats& s = r.stats();
    CHECK(s.triangles_in == 10);
    CHECK(s.triangles_degenerate == 4);
    CHECK(s.triangles_invalid == 6);
    CHECK(s.triangles_setup == 0);
    CHECK(s.fragments_covered == 0);
    CHECK(s.vertices == n);
    for (float v : fb.color) CHECK_MESSAGE(v == 0.0f, "something was drawn");
    for (float z : fb.depth) CHECK_MESSAGE(z == 1.0f, "depth was written");
    // An index count that is not a multiple of 3: the tail is ignored.
    std::vector<std::uint32_t> tail = {3, 4, 15, 3, 4};
    r.begin_frame();
    r.draw(fb, p, n, tail.data(), tail.size(), st);
    CHECK(r.stats().triangles_in == 1);
    // A framebuffer outside the supported range is refused.
    Framebuffer empty;
    CHECK_THROWS_AS(r.draw(empty, p, n, tail.data(), 3, st), std::invalid_argument);
}

TEST_CASE("clipping: a vertex at clip (0, 0, 0, 0) drops its triangle, it does not draw garbage") {
    // gl_Position = vec4(0) is the usual way to kill a vertex; the point satisfies
    // -w <= x, y, z <= w, so only an explicit w > 0 requirement keeps it out of
    // the perspective divide (0 / 0).
    const int W = 64, H = 48;
    Renderer r(RendererOptions{1, 16});
    const std::vector<std::vector<glm::vec4>> cases = {
        {glm::vec4(0, 0, 0, 0), glm::vec4(0.5f, 0, 0, 1), glm::vec4(0, 0.5f, 0, 1)},
        {glm::vec4(0, 0, 0, -0.0f), glm::vec4(0.5f, 0, 0, 1), glm::vec4(0, 0.5f, 0, 1)},
        {glm::vec4(0.5f, 0, 0, 1), glm::vec4(0, 0.5f, 0, 1), glm::vec4(0, 0, 0, 0)},
        {glm::vec4(0), glm::vec4(0), glm::vec4(0)},
    };
    for (std::size_t i = 0; i < cases.size(); ++i) {
        CAPTURE(i);
        FrameStats s;
        std::vector<int> c = draw_counts(r, W, H, cases[i], {0, 1, 2}, CullMode::None, &s);
        CHECK(s.triangles_setup == 0);
        CHECK(s.fragments_covered == 0);
        CHECK(count_not_equal(c, 0) == 0);
        CHECK(s.triangles_invalid + s.triangles_culled_frustum + s.triangles_degenerate >= 1);
    }
}

TEST_CASE("clipping: huge finite clip coordinates (1e8 to 3e38) still cover the viewport exactly once") {
    // The guard-band clipper must place its new vertices on the guard band however
    // far away the input vertices are; in single precision the cut point of an
    // edge from -1e12 to +1e12 rounds to the middle of the edge (x = 0) instead.
    const int W = 200, H = 150;
    Renderer r(RendererOptions{1, 64});
    for (float big : {1e8f, 1e12f, 1e20f, 3e38f}) {
        CAPTURE(big);
        std::vector<glm::vec4> clip = {glm::vec4(-big, -1, 0, 1), glm::vec4(big, -1, 0, 1), glm::vec4(0, big, 0, 1)};
        FrameStats s;
        std::vector<int> c = draw_counts(r, W, H, clip, {0, 1, 2}, CullMode::None, &s);
        CHECK(count_not_equal(c, 1) == 0);
        CHECK(s.triangles_clipped == 1);
        CHECK(s.triangles_culled_frustum == 0);
    }
}

// ===========================================================================
// 5. Depth

namespace {

struct CrossingScene {
    Camera cam;
    glm::dvec3 a[3], b[3];
    std::vector<glm::vec4> clip;
    std::vector<float> colours;
    CrossingScene(int W, int H) : cam(W, H, {0.3, 0.2, 3.0}, {0, 0, 0}, 55.0, 0.5, 20.0) {
        // A lies in z = 0.4 x, B in z = -0.4 x + 0.1 y; they cross along y = 8 x.
        a[0] = {-1.5, -1.2, -0.6}; a[1] = {1.5, -1.2, 0.6}; a[2] = {0.0, 1.3, 0.0};
        b[0] = {-1.6, -1.0, 0.54}; b[1] = {1.6, -1.0, -0.74}; b[2] = {0.0, 1.4, 0.14};
        for (int i = 0; i < 3; ++i) { clip.push_back(cam.clip(a[i])); colours.insert(colours.end(), {1, 0, 0}); }
        for (int i = 0; i < 3; ++i) { clip.push_back(cam.clip(b[i])); colours.insert(colours.end(), {0, 1, 0}); }
    }
    // 0: neither, 1: A visible, 2: B visible.
    int visible(double x, double y) const {
        double da = ray_triangle_depth(cam, x, y, a[0], a[1], a[2]);
        double db = ray_triangle_depth(cam, x, y, b[0], b[1], b[2]);
        if (!std::isfinite(da) && !std::isfinite(db)) return 0;
        return da < db ? 1 : 2;
    }
};

std::uint64_t draw_crossing(Renderer& r, const CrossingScene& sc, const std::vector<std::uint32_t>& idx,
                            Framebuffer& fb) {
    fb.resize(sc.cam.W, sc.cam.H);
    fb.clear(0, 0, 0, 0, 1.0f);
    ClipProgram<3> p;
    p.clip = sc.clip.data();
    p.varyings = sc.colours.data();
    DrawState st;
    st.cull = CullMode::None;
    r.draw(fb, p, std::uint32_t(sc.clip.size()), idx.data(), idx.size(), st);
    return hash_framebuffer(fb);
}

} // namespace

TEST_CASE("depth: interpenetrating triangles show the nearer surface, in either draw order") {
    const int W = 200, H = 150;
    CrossingScene sc(W, H);
    Renderer r(RendererOptions{2, 32});
    Framebuffer fb1, fb2;
    std::uint64_t h1 = draw_crossing(r, sc, {0, 1, 2, 3, 4, 5}, fb1);
    std::uint64_t h2 = draw_crossing(r, sc, {3, 4, 5, 0, 1, 2}, fb2);
    CHECK(h1 == h2);
    int counts[3] = {0, 0, 0}, bad = 0;
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x) {
            int e = stable_class([&](double px, double py) { return sc.visible(px, py); }, x + 0.5, y + 0.5, 1.0);
            if (e < 0) continue;
            ++counts[e];
            const float* c = fb1.pixel(x, y);
            int got = c[3] == 0.0f ? 0 : (c[0] == 1.0f && c[1] == 0.0f) ? 1 : (c[0] == 0.0f && c[1] == 1.0f) ? 2 : -1;
            bad += got != e;
        }
    CHECK(bad == 0);
    CHECK(counts[1] > 1500);  // both triangles visible in large parts
    CHECK(counts[2] > 1500);
    CHECK(counts[0] > 1500);
}

TEST_CASE("depth: early depth test kills hidden fragments before shading when drawn front to back") {
    const int W = 200, H = 150;
    // Two parallel window-space rectangles (w = 1): front at z_ndc -0.5, back at +0.5.
    auto rect = [&](double x0, double y0, double x1, double y1, double z, std::vector<glm::vec4>& clip,
                    std::vector<std::uint32_t>& idx) {
        std::uint32_t b = std::uint32_t(clip.size());
        clip.push_back(win(x0, y0, W, H, z));
        clip.push_back(win(x0, y1, W, H, z));
        clip.push_back(win(x1, y1, W, H, z));
        clip.push_back(win(x1, y0, W, H, z));
        idx.insert(idx.end(), {b, b + 1, b + 2, b, b + 2, b + 3});
    };
    std::vector<glm::vec4> clip;
    std::vector<std::uint32_t> front, back;
    rect(20, 20, 120, 100, -0.5, clip, front);   // 100 x 80 pixels
    rect(60, 50, 180, 140, 0.5, clip, back);     // 120 x 90 pixels; overlap 60 x 50
    const std::uint64_t nf = 100 * 80, nb = 120 * 90, overlap = 60 * 50;
    std::vector<float> colours;
    for (int i = 0; i < 4; ++i) colours.insert(colours.end(), {1, 0, 0});
    for (int i = 0; i < 4; ++i) colours.insert(colours.end(), {0, 1, 0});
    ClipProgram<3> p;
    p.clip = clip.data();
    p.varyings = colours.data();
    Renderer r(RendererOptions{2, 64});
    auto run = [&](bool front_first, Framebuffer& fb) {
        fb.resize(W, H);
        r.begin_frame();
        const std::vector<std::uint32_t>& first = front_first ? front : back;
        const std::vector<std::uint32_t>& second = front_first ? back : front;
        r.draw(fb, p, std::uint32_t(clip.size()), first.data(), first.size());
        r.draw(fb, p, std::uint32_t(clip.size()), second.data(), second.size());
        return r.stats();
    };
    Framebuffer f2b, b2f;
    FrameStats s_f2b = run(true, f2b), s_b2f = run(false, b2f);
    CHECK(hash_framebuffer(f2b) == hash_framebuffer(b2f));
    // Front to back: the hidden part of the back rectangle never reaches the shader.
    CHECK(s_f2b.fragments_covered == nf + nb);
    CHECK(s_f2b.fragments_depth_killed == overlap);
    CHECK(s_f2b.fragments_written == nf + nb - overlap);
    // Back to front: everything is shaded and the overlap is overdrawn.
    CHECK(s_b2f.fragments_covered == nf + nb);
    CHECK(s_b2f.fragments_depth_killed == 0);
    CHECK(s_b2f.fragments_written == nf + nb);
    CHECK(s_b2f.draws == 2);
    check_stats_invariants(s_f2b);
    check_stats_invariants(s_b2f);
    // The front rectangle is on top in the overlap.
    CHECK(f2b.pixel(80, 70)[0] == 1.0f);
    CHECK(f2b.pixel(80, 70)[1] == 0.0f);
    CHECK(f2b.depth[70 * W + 80] == 0.25f);
}

TEST_CASE("fragment block: lane positions, derivatives, prim_id, front_facing and shader kills") {
    const int W = 64, H = 48;
    // Triangle 0 counter-clockwise in NDC (front), triangle 1 clockwise (back).
    // Positions on the 1/256-pixel grid, so snapping does not move them away from
    // the varyings that echo them.
    const glm::dvec2 v[6] = {{3.375, 2.75}, {5.125, 44.25}, {40.625, 30.875},
                             {45.25, 3.375}, {61.75, 6.125}, {58.875, 40.25}};
    std::vector<glm::vec4> clip;
    std::vector<float> var;
    for (const glm::dvec2& q : v) {
        clip.push_back(win(q.x, q.y, W, H));
        var.push_back(float(q.x));
        var.push_back(float(q.y));
    }
    std::vector<std::uint32_t> idx = {0, 1, 2, 3, 4, 5};
    auto ndc_area = [&](int t) {
        glm::vec2 a(clip[3 * t]), b(clip[3 * t + 1]), c(clip[3 * t + 2]);
        return (b.x - a.x) * (c.y - a.y) - (c.x - a.x) * (b.y - a.y);
    };
    REQUIRE(ndc_area(0) > 0);
    REQUIRE(ndc_area(1) < 0);
    ProbeProgram p;
    p.clip = clip.data();
    p.varyings = var.data();
    DrawState st;
    st.cull = CullMode::None;
    st.depth_test = false;
    Renderer r(RendererOptions{2, 16});
    // Which pixels each triangle covers, from the counting program.
    std::vector<int> c0 = draw_counts(r, W, H, clip, {0, 1, 2});
    std::vector<int> c1 = draw_counts(r, W, H, clip, {3, 4, 5});
    Framebuffer fb(W, H);
    fb.clear(-1, -1, -1, -1);
    r.begin_frame();
    r.draw(fb, p, std::uint32_t(clip.size()), idx.data(), idx.size(), st);
    const FrameStats& s = r.stats();
    int bad = 0, written = 0, killed = 0;
    double max_pos_err = 0, max_deriv_err = 0;
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x) {
            const float* c = fb.pixel(x, y);
            int n0 = c0[std::size_t(y) * W + x], n1 = c1[std::size_t(y) * W + x];
            REQUIRE(n0 + n1 <= 1);
            if (n0 + n1 == 0 || ProbeProgram::killed(x, y)) {
                killed += n0 + n1;
                bad += c[0] != -1.0f || c[3] != -1.0f;  // untouched
                continue;
            }
            ++written;
            bad += c[3] != (n0 ? 0.0f : 1001.0f);
            max_pos_err = std::max({max_pos_err, double(std::abs(c[0])), double(std::abs(c[1]))});
            max_deriv_err = std::max(max_deriv_err, double(c[2]));
        }
    CHECK(bad == 0);
    CHECK(max_pos_err < 1e-3);
    CHECK(max_deriv_err < 1e-3);
    CHECK(killed > 20);
    CHECK(s.fragments_shader_killed == std::uint64_t(killed));
    CHECK(s.fragments_written == std::uint64_t(written));
    CHECK(s.fragments_covered == std::uint64_t(written + killed));
    check_stats_invariants(s);
}

TEST_CASE("draw state: depth write off keeps the depth buffer; Replace overwrites, Add accumulates") {
    const int W = 32, H = 32;
    std::vector<glm::vec4> clip = {win(-1, -1, W, H, -0.5), win(-1, 40, W, H, -0.5), win(40, -1, W, H, -0.5)};
    std::vector<float> col = {0.25f, 0.5f, 0.75f, 0.25f, 0.5f, 0.75f, 0.25f, 0.5f, 0.75f};
    std::vector<std::uint32_t> idx = {0, 1, 2};
    ClipProgram<3> p;
    p.clip = clip.data();
    p.varyings = col.data();
    Renderer r(RendererOptions{1, 16});
    Framebuffer fb(W, H);
    fb.clear(1, 1, 1, 1, 0.5f);
    DrawState st;
    st.depth_write = false;
    r.draw(fb, p, 3, idx.data(), 3, st);   // z_win 0.25 < 0.5: passes, depth kept
    CHECK(fb.depth[5 * W + 5] == 0.5f);
    CHECK(fb.pixel(5, 5)[0] == 0.25f);
    CHECK(fb.pixel(5, 5)[2] == 0.75f);
    st.blend = Blend::Add;
    r.draw(fb, p, 3, idx.data(), 3, st);
    CHECK(fb.pixel(5, 5)[0] == 0.5f);
    CHECK(fb.pixel(5, 5)[1] == 1.0f);
    CHECK(fb.pixel(5, 5)[3] == 2.0f);
    st.depth_write = true;
    st.blend = Blend::Replace;
    r.draw(fb, p, 3, idx.data(), 3, st);
    CHECK(fb.depth[5 * W + 5] == 0.25f);
    r.begin_frame();
    r.draw(fb, p, 3, idx.data(), 3, st);   // equal depth fails LESS
    CHECK(r.stats().fragments_written == 0);
    CHECK(r.stats().fragments_depth_killed == r.stats().fragments_covered);
    // Tile sizes outside [16, 256] or not powers of two are refused.
    for (int bad_tile : {8, 48, 100, 512})
        CHECK_THROWS_AS(Renderer(RendererOptions{1, bad_tile}), std::invalid_argument);
}

// ===========================================================================
// 6. Thread-count and tile-size invariance

namespace {

struct RandomScene {
    std::vector<glm::vec4> clip;
    std::vector<float> colours;
    std::vector<std::uint32_t> idx;
};

RandomScene random_scene(int W, int H, int tris, std::uint64_t seed) {
    Random rng(seed);
    RandomScene sc;
    for (int t = 0; t < tris; ++t) {
        int kind = rng.below(100);
        double cx = rng.range(-0.2, 1.2) * W, cy = rng.range(-0.2, 1.2) * H;
        double size = kind < 85 ? rng.range(2.0, 40.0) : rng.range(40.0, 400.0);
        for (int k = 0; k < 3; ++k) {
            double x = cx + rng.range(-size, size), y = cy + rng.range(-size, size);
            double z = rng.range(-1.15, 1.15);  // some cross near or far
            double w = rng.range(0.3, 3.0);
            glm::vec4 c = win(x, y, W, H, z, w);
            if (kind >= 95 && k == 0) c.w = -c.w;                    // a vertex behind the eye
            if (kind >= 92 && kind < 95 && k == 0) { c.x *= 3e4f; c.y *= 2e4f; }  // beyond the guard band
            sc.clip.push_back(c);
            sc.colours.insert(sc.colours.end(), {float(rng.uniform()), float(rng.uniform()), float(rng.uniform())});
        }
        std::uint32_t b = std::uint32_t(3 * t);
        sc.idx.insert(sc.idx.end(), {b, b + 1, b + 2});
    }
    return sc;
}

std::uint64_t render_random(const RandomScene& sc, int W, int H, int threads, int tile, FrameStats* stats = nullptr) {
    Renderer r(RendererOptions{threads, tile});
    Framebuffer fb(W, H);
    ClipProgram<3> p;
    p.clip = sc.clip.data();
    p.varyings = sc.colours.data();
    DrawState st;
    st.cull = CullMode::None;
    r.begin_frame();
    // Two draws; the first has more than kTrianglesPerJob triangles, so it is
    // set up and binned by several jobs.
    std::size_t half = std::min(sc.idx.size(), std::size_t(3 * (kTrianglesPerJob + 1500)));
    r.draw(fb, p, std::uint32_t(sc.clip.size()), sc.idx.data(), half, st);
    r.draw(fb, p, std::uint32_t(sc.clip.size()), sc.idx.data() + half, sc.idx.size() - half, st);
    if (stats) *stats = r.stats();
    return hash_framebuffer(fb);
}

} // namespace

TEST_CASE("invariance: thread count and tile size do not change a single byte") {
    for (glm::ivec2 size : {glm::ivec2(256, 192), glm::ivec2(203, 117), glm::ivec2(61, 250)}) {
        const int W = size.x, H = size.y;
        CAPTURE(W);
        CAPTURE(H);
        RandomScene sc = random_scene(W, H, 4500, std::uint64_t(W * 1000 + H));
        FrameStats ref_stats;
        const std::uint64_t ref = render_random(sc, W, H, 1, 64, &ref_stats);
        CHECK(ref_stats.triangles_clipped > 100);
        CHECK(ref_stats.triangles_culled_frustum > 100);
        CHECK(ref_stats.fragments_depth_killed > 1000);
        CHECK(ref_stats.fragments_written > std::uint64_t(W) * H);
        for (int threads : {1, 2, 3, 8})
            for (int tile : {16, 32, 64, 128, 256}) {
                CAPTURE(threads);
                CAPTURE(tile);
                FrameStats s;
                CHECK(render_random(sc, W, H, threads, tile, &s) == ref);
                // Counters that do not depend on tiling are equal too.
                CHECK(s.fragments_covered == ref_stats.fragments_covered);
                CHECK(s.fragments_written == ref_stats.fragments_written);
                CHECK(s.fragments_depth_killed == ref_stats.fragments_depth_killed);
                CHECK(s.triangles_setup == ref_stats.triangles_setup);
                CHECK(s.triangles_clipped == ref_stats.triangles_clipped);
            }
    }
}

// ===========================================================================
// 7. Golden image

namespace {

struct SceneBuilder {
    std::vector<glm::vec4> clip;
    std::vector<float> var;
    std::vector<std::uint32_t> idx;
    const Camera* cam = nullptr;
    glm::dmat4 vp{1.0};
    std::uint32_t vertex(glm::dvec3 p, glm::vec3 n, glm::vec3 albedo, float u = -1.0f, float v = -1.0f) {
        clip.push_back(glm::vec4(vp * glm::dvec4(p, 1.0)));
        var.insert(var.end(), {n.x, n.y, n.z, albedo.r, albedo.g, albedo.b, u, v});
        return std::uint32_t(clip.size() - 1);
    }
};

// 160 x 120: a sphere (subdivided octahedron: no trigonometry, so the bytes do
// not depend on libm) on a checkered ground plane, with two interpenetrating
// coloured triangles behind it. The projection is built with glm::frustum
// (no tan) for the same reason.
std::vector<std::uint8_t> render_golden_scene(int threads, int tile) {
    const int W = 160, H = 120;
    const double n = 0.1, f = 50.0, t = n * 0.41421356237309503, rgt = t * double(W) / H;  // 45 degrees
    glm::dmat4 proj = glm::frustum(-rgt, rgt, -t, t, n, f);
    glm::dmat4 view = glm::lookAt(glm::dvec3(0.6, 1.5, 4.4), glm::dvec3(0.0, 0.35, 0.0), glm::dvec3(0, 1, 0));
    SceneBuilder b;
    b.vp = proj * view;
    // Ground: y = -0.6, facing up, checker in u, v.
    const glm::vec3 up(0, 1, 0), ground(0.85f, 0.85f, 0.8f);
    std::uint32_t g0 = b.vertex({-4, -0.6, -6}, up, ground, 0, 0), g1 = b.vertex({4, -0.6, -6}, up, ground, 1, 0),
                  g2 = b.vertex({4, -0.6, 3}, up, ground, 1, 1), g3 = b.vertex({-4, -0.6, 3}, up, ground, 0, 1);
    b.idx.insert(b.idx.end(), {g0, g3, g2, g0, g2, g1});
    // Sphere: radius 1 at (-0.9, 0.4, 0.2), eight octants subdivided 10 times each.
    const glm::vec3 gold(0.95f, 0.7f, 0.25f);
    const int L = 10;
    for (int oct = 0; oct < 8; ++oct) {
        glm::dvec3 A((oct & 1) ? -1 : 1, 0, 0), B(0, (oct & 2) ? -1 : 1, 0), C(0, 0, (oct & 4) ? -1 : 1);
        auto point = [&](int i, int j) {
            glm::dvec3 q = (A * double(L - i - j) + B * double(i) + C * double(j)) / double(L);
            q = q / std::sqrt(glm::dot(q, q));
            return q;
        };
        auto tri = [&](glm::dvec3 p0, glm::dvec3 p1, glm::dvec3 p2) {
            if (glm::dot(glm::cross(p1 - p0, p2 - p0), p0 + p1 + p2) < 0) std::swap(p1, p2);
            const glm::dvec3 c(-0.9, 0.4, 0.2);
            for (glm::dvec3 q : {p0, p1, p2}) b.idx.push_back(b.vertex(c + q, glm::vec3(q), gold));
        };
        for (int i = 0; i < L; ++i)
            for (int j = 0; i + j < L; ++j) {
                tri(point(i, j), point(i + 1, j), point(i, j + 1));
                if (i + j + 2 <= L) tri(point(i + 1, j), point(i + 1, j + 1), point(i, j + 1));
            }
    }
    // Two triangles leaning across each other above and behind the sphere; they
    // interpenetrate (red's apex is behind blue's upper part, its base in front).
    const glm::vec3 fwd(0, 0, 1), red(0.9f, 0.15f, 0.1f), blue(0.15f, 0.3f, 0.95f);
    std::uint32_t r0 = b.vertex({0.3, -0.6, -1.4}, fwd, red), r1 = b.vertex({1.5, -0.6, -1.2}, fwd, red),
                  r2 = b.vertex({2.9, 1.7, -2.9}, fwd, red);
    std::uint32_t c0 = b.vertex({2.0, -0.6, -2.4}, fwd, blue), c1 = b.vertex({3.3, -0.6, -2.6}, fwd, blue),
                  c2 = b.vertex({0.7, 1.6, -1.5}, fwd, blue);
    b.idx.insert(b.idx.end(), {r0, r1, r2, c0, c1, c2});

    Renderer r(RendererOptions{threads, tile});
    Framebuffer fb(W, H);
    fb.clear(0, 0, 0, 1);
    SceneProgram p;
    p.clip = b.clip.data();
    p.varyings = b.var.data();
    glm::vec3 l(0.5f, 1.0f, 0.6f);
    p.light = l / std::sqrt(glm::dot(l, l));
    DrawState st;
    st.cull = CullMode::None;
    r.draw(fb, p, std::uint32_t(b.clip.size()), b.idx.data(), b.idx.size(), st);
    std::vector<std::uint8_t> rgb(std::size_t(W) * H * 3);
    for (std::size_t i = 0; i < std::size_t(W) * H; ++i)
        for (int k = 0; k < 3; ++k) rgb[3 * i + std::size_t(k)] = to_byte(fb.color[4 * i + std::size_t(k)]);
    return rgb;
}

} // namespace

TEST_CASE("golden image: small sphere/ground/triangles scene is byte-identical to tests/golden/raster_scene.png") {
    namespace fs = std::filesystem;
    const int W = 160, H = 120;
    const fs::path golden = fs::path(PRAST_SOURCE_DIR) / "tests" / "golden" / "raster_scene.png";
    std::vector<std::uint8_t> img = render_golden_scene(2, 64);
    // The image itself must not depend on the thread count or tile size.
    CHECK(render_golden_scene(1, 16) == img);
    CHECK(render_golden_scene(3, 256) == img);
    if (!fs::exists(golden)) {
        fs::create_directories(golden.parent_path());
        int ok = stbi_write_png(golden.string().c_str(), W, H, 3, img.data(), W * 3);
        REQUIRE(ok != 0);
        FAIL("golden image did not exist: created " << golden.string()
                                                   << " -- review it by eye and commit it, then re-run");
    }
    const Image8 expected = read_image8(golden.string());
    REQUIRE(expected.width == W);
    REQUIRE(expected.height == H);
    const Image8 actual = Image8::from_rgb(W, H, img.data());
    const DiffResult diff = diff_images(actual, expected, {0, 0.0});  // exact
    if (!diff.match) {
        const fs::path out = fs::temp_directory_path() / "raster_scene_actual.png";
        const fs::path heat = fs::temp_directory_path() / "raster_scene_heatmap.png";
        stbi_write_png(out.string().c_str(), W, H, 3, img.data(), W * 3);
        const std::vector<std::uint8_t> heat_rgba = diff_heatmap(actual, expected, {0, 0.0});
        stbi_write_png(heat.string().c_str(), W, H, 4, heat_rgba.data(), W * 4);
        MESSAGE(format_diff(diff, {0, 0.0}) << "actual image written to " << out.string() << ", heat map to "
                                            << heat.string());
    }
    CHECK(diff.match);
}

// ===========================================================================
// 8. Observer

TEST_CASE("observer: binned tiles, fragments per pixel and stage counts agree with the draw") {
    const int W = 100, H = 80, T = 16;
    const int tiles_x = (W + T - 1) / T;
    Renderer r(RendererOptions{1, T});
    // 0: small triangle whose box overlaps 2 x 2 tiles, with pixels in each.
    // 1: a thin diagonal sliver whose box spans many tiles it never touches.
    // 2: a back face (culled in a single-sided draw), 3: degenerate, 4: off screen.
    std::vector<glm::vec4> clip = {
        win(10.3, 9.7, W, H), win(27.6, 12.2, W, H), win(12.9, 25.1, W, H),
        win(2.2, 3.1, W, H), win(95.7, 74.4, W, H), win(97.1, 76.3, W, H),
        win(40.2, 40.6, W, H), win(44.9, 58.3, W, H), win(60.1, 44.7, W, H),
        win(5.5, 60.5, W, H), win(20.5, 60.5, W, H), win(35.5, 60.5, W, H),
        glm::vec4(3, 3, 0, 1), glm::vec4(4, 3, 0, 1), glm::vec4(3, 4, 0, 1),
    };
    std::vector<std::uint32_t> idx = {0, 2, 1, 3, 5, 4, 6, 7, 8, 9, 10, 11, 12, 13, 14};
    // Make 0, 1 front faces (counter-clockwise in NDC) and 2 a back face.
    auto ccw = [&](std::uint32_t t) {
        glm::vec2 a(clip[idx[3 * t]]), b(clip[idx[3 * t + 1]]), c(clip[idx[3 * t + 2]]);
        return (b.x - a.x) * (c.y - a.y) - (c.x - a.x) * (b.y - a.y) > 0;
    };
    for (std::uint32_t t = 0; t < 3; ++t)
        if (ccw(t) != (t < 2)) std::swap(idx[3 * t + 1], idx[3 * t + 2]);
    RecordingObserver obs(W, H, idx.size() / 3);
    Framebuffer fb(W, H);
    CountProgram p;
    p.clip = clip.data();
    r.begin_frame();
    r.draw(fb, p, std::uint32_t(clip.size()), idx.data(), idx.size(), count_state(CullMode::Back), obs);
    const FrameStats& s = r.stats();

    CHECK(obs.vertices == clip.size());
    CHECK(!obs.lane_outside_viewport);
    // Fates: one per triangle (none is clipped).
    REQUIRE(obs.fates.size() == 5);
    CHECK(obs.fates[0] == std::vector<TriangleFate>{TriangleFate::SetUp});
    CHECK(obs.fates[1] == std::vector<TriangleFate>{TriangleFate::SetUp});
    CHECK(obs.fates[2] == std::vector<TriangleFate>{TriangleFate::CulledBack});
    CHECK(obs.fates[3] == std::vector<TriangleFate>{TriangleFate::Degenerate});
    CHECK(obs.fates[4] == std::vector<TriangleFate>{TriangleFate::CulledFrustum});
    // Tiles of triangle 0: exactly those its pixel box overlaps (pixels 10..27 x 10..24).
    auto box_tiles = [&](double x0, double y0, double x1, double y1) {
        std::set<int> t;
        int px0 = int(std::ceil(x0 - 0.5)), px1 = int(std::floor(x1 - 0.5));
        int py0 = int(std::ceil(y0 - 0.5)), py1 = int(std::floor(y1 - 0.5));
        for (int ty = py0 / T; ty <= py1 / T; ++ty)
            for (int tx = px0 / T; tx <= px1 / T; ++tx) t.insert(ty * tiles_x + tx);
        return t;
    };
    std::set<int> expect0 = box_tiles(10.3, 9.7, 27.6, 25.1);
    CHECK(expect0 == std::set<int>{0, 1, tiles_x, tiles_x + 1});
    CHECK(obs.tiles[0] == expect0);
    // Triangle 1: within its box, at least every tile where it has fragments, and
    // not the box's far corners, which lie wholly outside one edge.
    std::set<int> box1 = box_tiles(2.2, 3.1, 97.1, 76.3), frag_tiles1;
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x)
            for (std::uint32_t prim : obs.pixel_prims[std::size_t(y) * W + x])
                if (prim == 1) frag_tiles1.insert((y / T) * tiles_x + x / T);
    for (int t : obs.tiles[1]) CHECK(box1.count(t) == 1);
    for (int t : frag_tiles1) CHECK(obs.tiles[1].count(t) == 1);
    CHECK(obs.tiles[1].count((H - 1) / T * tiles_x) == 0);  // bottom-left corner tile
    CHECK(obs.tiles[1].count(tiles_x - 1) == 0);            // top-right corner tile
    CHECK(frag_tiles1.size() >= 6);
    for (int t = 2; t < 5; ++t) CHECK(obs.tiles[std::size_t(t)].empty());
    std::uint64_t entries = 0;
    for (const auto& ts : obs.tiles) entries += ts.size();
    CHECK(entries == s.bin_entries);
    // Fragments: per pixel equal to the written counts, totals equal to the stats.
    int mismatch = 0;
    std::uint64_t counted = 0;
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x) {
            int n = int(fb.pixel(x, y)[0]);
            counted += std::uint64_t(n);
            mismatch += n != obs.pixel_fragments[std::size_t(y) * W + x];
        }
    CHECK(mismatch == 0);
    CHECK(obs.fragment_total == s.fragments_covered);
    CHECK(obs.fragment_total == counted);
    CHECK(obs.covered[0] + obs.covered[1] == s.fragments_covered);
    CHECK(obs.covered[0] > 100);
    CHECK(obs.covered[1] > 20);
    CHECK(obs.pass_total == s.fragments_covered);      // no depth test
    CHECK(obs.live_total == s.fragments_written);
    // Every covered pixel of triangle 0 lies within its box.
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x)
            for (std::uint32_t prim : obs.pixel_prims[std::size_t(y) * W + x])
                if (prim == 0) CHECK((x >= 10 && x <= 27 && y >= 10 && y <= 24));
}

TEST_CASE("observer: every pixel sees its triangles in submission order, whatever the threads") {
    const int W = 203, H = 117;
    RandomScene sc = random_scene(W, H, 2500, 77);
    for (int threads : {1, 4}) {
        CAPTURE(threads);
        Renderer r(RendererOptions{threads, 32});
        RecordingObserver obs(W, H, sc.idx.size() / 3);
        Framebuffer fb(W, H);
        ClipProgram<3> p;
        p.clip = sc.clip.data();
        p.varyings = sc.colours.data();
        DrawState st;
        st.cull = CullMode::None;
        r.begin_frame();
        r.draw(fb, p, std::uint32_t(sc.clip.size()), sc.idx.data(), sc.idx.size(), st, obs);
        int out_of_order = 0;
        for (const auto& prims : obs.pixel_prims)
            for (std::size_t i = 1; i < prims.size(); ++i) out_of_order += prims[i] < prims[i - 1];
        CHECK(out_of_order == 0);
        CHECK(obs.fragment_total == r.stats().fragments_covered);
        // Through the visibility pass only each pixel's winner is shaded.
        CHECK(obs.live_total == r.stats().fragments_shaded);
        CHECK(obs.live_total < r.stats().fragments_written);
        CHECK(obs.live_total <= std::uint64_t(W) * H);
        CHECK(obs.pass_total == r.stats().fragments_covered - r.stats().fragments_depth_killed);
        std::uint64_t entries = 0, setups = 0;
        for (const auto& ts : obs.tiles) entries += ts.size();
        for (const auto& fs : obs.fates)
            for (TriangleFate f : fs) setups += f == TriangleFate::SetUp;
        // A clipped triangle's pieces may share tiles, so entries >= distinct tiles.
        CHECK(entries <= r.stats().bin_entries);
        CHECK(setups == r.stats().triangles_setup);
    }
}

// ===========================================================================
// 9. Stats

TEST_CASE("stats: counters of a closed sphere, single- and double-sided") {
    const int W = 256, H = 192;
    SphereView v = make_sphere_view(W, H);
    const std::uint64_t tris = v.mesh.idx.size() / 3;
    Renderer r(RendererOptions{2, 64});

    FrameStats one;
    std::vector<int> c1 = draw_counts(r, W, H, v.clip, v.mesh.idx, CullMode::Back, &one);
    CHECK(one.draws == 1);
    CHECK(one.vertices == v.clip.size());
    CHECK(one.triangles_in == tris);
    CHECK(one.triangles_invalid == 0);
    CHECK(one.triangles_clipped == 0);
    CHECK(one.triangles_culled_frustum == 0);
    CHECK(one.triangles_culled_back + one.triangles_setup + one.triangles_degenerate == tris);
    // Seen from 3.3 radii, a bit more than half of the sphere faces away.
    CHECK(one.triangles_culled_back > tris * 45 / 100);
    CHECK(one.triangles_culled_back < tris * 70 / 100);
    CHECK(one.triangles_setup > tris * 25 / 100);
    std::uint64_t sum1 = 0;
    for (int n : c1) sum1 += std::uint64_t(n);
    CHECK(one.fragments_covered == sum1);
    CHECK(one.fragments_written == sum1);
    CHECK(one.fragments_depth_killed == 0);
    CHECK(one.bin_entries >= one.triangles_setup);
    CHECK(one.tiles_touched <= std::uint64_t(((W + 63) / 64) * ((H + 63) / 64)));
    CHECK(one.tiles_touched >= 4);
    check_stats_invariants(one);

    FrameStats two;
    std::vector<int> c2 = draw_counts(r, W, H, v.clip, v.mesh.idx, CullMode::None, &two);
    CHECK(two.triangles_culled_back == 0);
    CHECK(two.triangles_setup + two.triangles_degenerate == tris);
    // A ray from outside enters a closed surface as often as it leaves it, so
    // with watertight coverage every pixel sees as many back faces as front faces.
    std::uint64_t sum2 = 0;
    int not_double = 0;
    for (std::size_t i = 0; i < c2.size(); ++i) {
        sum2 += std::uint64_t(c2[i]);
        not_double += c2[i] != 2 * c1[i];
    }
    CHECK(two.fragments_covered == sum2);
    CHECK(not_double == 0);
    CHECK(sum2 == 2 * sum1);
    check_stats_invariants(two);

    // Counters accumulate over draws until begin_frame().
    Framebuffer fb(W, H);
    CountProgram p;
    p.clip = v.clip.data();
    r.begin_frame();
    r.draw(fb, p, std::uint32_t(v.clip.size()), v.mesh.idx.data(), v.mesh.idx.size(), count_state(CullMode::Back));
    r.draw(fb, p, std::uint32_t(v.clip.size()), v.mesh.idx.data(), v.mesh.idx.size(), count_state(CullMode::Back));
    CHECK(r.stats().draws == 2);
    CHECK(r.stats().triangles_in == 2 * tris);
    CHECK(r.stats().fragments_covered == 2 * one.fragments_covered);
    r.begin_frame();
    CHECK(r.stats().draws == 0);
    CHECK(r.stats().fragments_covered == 0);
    // An empty draw counts as a draw and nothing else.
    r.draw(fb, p, 0, nullptr, 0, count_state());
    CHECK(r.stats().draws == 1);
    CHECK(r.stats().triangles_in == 0);
    CHECK(!r.stats().to_string().empty());
}

TEST_CASE("stats: a back face split by clipping counts once in triangles_culled_back") {
    // Clockwise in NDC and far beyond the guard band: the clipper cuts it into a
    // fan of pieces, but one submitted triangle was culled.
    const int W = 64, H = 48;
    Renderer r(RendererOptions{1, 16});
    std::vector<glm::vec4> clip = {glm::vec4(-2e4f, -2e4f, 0, 1), glm::vec4(-2e4f, 6e4f, 0, 1), glm::vec4(6e4f, -2e4f, 0, 1)};
    FrameStats s;
    std::vector<int> c = draw_counts(r, W, H, clip, {0, 1, 2}, CullMode::Back, &s);
    CHECK(count_not_equal(c, 0) == 0);
    CHECK(s.triangles_in == 1);
    CHECK(s.triangles_clipped == 1);
    CHECK(s.triangles_setup == 0);
    CHECK(s.triangles_culled_back == 1);
    // Drawn double-sided it covers everything once, from several pieces.
    c = draw_counts(r, W, H, clip, {0, 1, 2}, CullMode::None, &s);
    CHECK(count_not_equal(c, 1) == 0);
    CHECK(s.triangles_setup >= 2);
}

// raster/shade.h write_planes(), Replace: exactly the masked lanes of each
// sample plane get the block's colours, nothing else is touched, for every
// sample count, random masks (full and empty ones too) and a block whose
// lower rows lie past the end of its plane (the one-sample framebuffer's
// last rows; AddressSanitizer would see a store there). Where the CPU has
// AVX-512 this is the masked-store copy (write_avx512.h), and the test also
// calls write_color(), the AVX2 and portable path, for the same result.
TEST_CASE("colour write: each sample plane gets exactly its masked lanes, AVX-512 copy and default alike") {
    constexpr float kUntouched = -7.0f;
    std::uint32_t seed = 12345u;
    auto next = [&] {
        seed = seed * 1664525u + 1013904223u;
        return seed >> 8;
    };
    FragmentOut out;
    for (int l = 0; l < kBlockLanes; ++l) {
        out.r[l] = float(l) + 0.25f;
        out.g[l] = float(l) + 0.5f;
        out.b[l] = -float(l);
        out.a[l] = 1.0f / float(l + 1);
    }
    for (int S : {1, 2, 4, 8}) {
        for (int trial = 0; trial < 200; ++trial) {
            // Planes of 6 x 4 pixels (row 6, block at x = 2), or the last plane
            // only 2 rows high: then only lanes 0-7 (rows 0, 1) may be set.
            const bool short_last = trial % 4 == 3;
            const std::size_t row = 6, plane = row * 4;
            const std::size_t size = (plane * std::size_t(S) - (short_last ? 2 * row : 0)) * 4;
            std::uint32_t write[kMaxSamples];
            for (int s = 0; s < S; ++s) {
                const std::uint32_t pick = next() % 4;
                write[s] = pick == 0 ? 0u : pick == 1 ? 0xFFFFu : next() & 0xFFFFu;
                if (short_last && s == S - 1) write[s] &= 0xFFu;
            }
            const std::uint32_t live = trial % 5 == 0 ? (next() & 0xFFFFu) : 0xFFFFu;
            std::vector<float> expect(size, kUntouched);
            for (int s = 0; s < S; ++s)
                for (int l = 0; l < kBlockLanes; ++l) {
                    if (!((write[s] & live) >> l & 1u)) continue;
                    const std::size_t at = (std::size_t(s) * plane + std::size_t(lane_y(l)) * row + 2 + std::size_t(lane_x(l))) * 4;
                    expect[at] = out.r[l];
                    expect[at + 1] = out.g[l];
                    expect[at + 2] = out.b[l];
                    expect[at + 3] = out.a[l];
                }
            // Its own allocation, so that a store past `size` is a heap overflow.
            std::unique_ptr<float[]> got(new float[size]);
            std::fill(got.get(), got.get() + size, kUntouched);
            TileTarget tg;
            tg.color = got.get();
            tg.row = row;
            tg.plane = plane;
            raster_detail::write_planes(tg, 2, S, write, live, out, Blend::Replace, false);
            bool same = std::equal(expect.begin(), expect.end(), got.get());
            CHECK_MESSAGE(same, "write_planes, samples " << S << ", trial " << trial);
            std::fill(got.get(), got.get() + size, kUntouched);
            for (int s = 0; s < S; ++s)
                if (write[s] & live)
                    raster_detail::write_color(got.get() + (std::size_t(s) * plane + 2) * 4, row, write[s] & live, out,
                                               Blend::Replace, false);
            same = std::equal(expect.begin(), expect.end(), got.get());
            CHECK_MESSAGE(same, "write_color, samples " << S << ", trial " << trial);
        }
    }
}

} // TEST_SUITE

// Shadow maps (docs/shadows-and-transparency.md): the outline of a square occluder's shadow
// against its exact projection, no acne on a lit plane, no light leaking at
// a contact, a point light's cube map, determinism across threads and tiles.
// Images use the diffuse debug view (Lambert only, no tone map): a lit plane
// under a sun is one exact value, a shadowed one exactly 0.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include <glm/glm.hpp>

#include "scene/default_scene.h"
#include "renderer/scene_renderer.h"
#include "shading/tonemap.h"

using namespace prast;

namespace {

// A quad (two triangles, counter-clockwise seen from +normal) as its own mesh.
void add_quad(Scene& s, glm::vec3 a, glm::vec3 b, glm::vec3 c, glm::vec3 d, int material = 0) {
    Mesh m;
    m.positions = {a, b, c, d};
    const glm::vec3 n = glm::normalize(glm::cross(b - a, c - a));
    m.normals.assign(4, n);
    m.indices = {0, 1, 2, 0, 2, 3};
    m.material = material;
    s.meshes.push_back(m);
}

// The plane y = 0, |x|, |z| <= h, facing up.
// The horizontal square of half-side h at height y, counter-clockwise seen
// from above: the floor, the occluders and the shadows they cast.
std::vector<glm::vec3> square(float h, float y) { return {{-h, y, h}, {h, y, h}, {h, y, -h}, {-h, y, -h}}; }

void add_square(Scene& s, float h, float y) {
    const std::vector<glm::vec3> c = square(h, y);
    add_quad(s, c[0], c[1], c[2], c[3]);
}

void add_floor(Scene& s, float h) { add_square(s, h, 0.0f); }

// An axis-aligned box [lo, hi], faces outwards.
void add_box(Scene& s, glm::vec3 lo, glm::vec3 hi) {
    const float x0 = lo.x, y0 = lo.y, z0 = lo.z, x1 = hi.x, y1 = hi.y, z1 = hi.z;
    add_quad(s, {x0, y1, z1}, {x1, y1, z1}, {x1, y1, z0}, {x0, y1, z0});  // +y
    add_quad(s, {x0, y0, z0}, {x1, y0, z0}, {x1, y0, z1}, {x0, y0, z1});  // -y
    add_quad(s, {x1, y0, z1}, {x1, y0, z0}, {x1, y1, z0}, {x1, y1, z1});  // +x
    add_quad(s, {x0, y0, z0}, {x0, y0, z1}, {x0, y1, z1}, {x0, y1, z0});  // -x
    add_quad(s, {x0, y0, z1}, {x1, y0, z1}, {x1, y1, z1}, {x0, y1, z1});  // +z
    add_quad(s, {x1, y0, z0}, {x0, y0, z0}, {x0, y1, z0}, {x1, y1, z0});  // -z
}

Scene base_scene() {
    Scene s;
    Material m;
    m.base_color_factor = {0.8f, 0.8f, 0.8f, 1.0f};
    m.roughness_factor = 1.0f;
    s.materials.push_back(m);
    return s;
}

struct Frame {
    int w = 0, h = 0;
    std::vector<float> rgba;
    float r(int x, int y) const { return rgba[(std::size_t(y) * w + x) * 4]; }
};

Frame render(const Scene& scene, const Camera& cam, const std::vector<ShadingLight>& lights, bool shadows,
             int w, int h, int threads = 2, int tile = 64, int size = 1024, DebugView view = DebugView::Diffuse) {
    Renderer r({threads, tile});
    SceneRenderer sr(scene, r);
    FrameSettings fs;
    fs.camera = cam;
    fs.lights = lights;
    fs.view = view;
    fs.shadows.enabled = shadows;
    fs.shadows.size = size;
    Framebuffer fb(w, h);
    sr.render(fs, fb);
    return {w, h, fb.color};
}

// Screen position (pixels, y down) of a world point.
glm::vec2 project(const Camera& cam, int w, int h, glm::vec3 p) {
    const glm::vec4 c = cam.view_projection(float(w) / float(h)) * glm::vec4(p, 1.0f);
    return {(c.x / c.w * 0.5f + 0.5f) * float(w), (0.5f - c.y / c.w * 0.5f) * float(h)};
}

// Signed distance (pixels) from q to a convex polygon's outline: > 0 inside.
float signed_distance(const std::vector<glm::vec2>& poly, glm::vec2 q) {
    float area = 0.0f;
    for (std::size_t i = 0; i < poly.size(); ++i) {
        const glm::vec2 a = poly[i], b = poly[(i + 1) % poly.size()];
        area += a.x * b.y - b.x * a.y;
    }
    const float orient = area > 0.0f ? 1.0f : -1.0f;
    bool inside = true;
    float to_line = 1e30f, to_segment = 1e30f;
    for (std::size_t i = 0; i < poly.size(); ++i) {
        const glm::vec2 a = poly[i], b = poly[(i + 1) % poly.size()], e = b - a;
        const float side = orient * (e.x * (q.y - a.y) - e.y * (q.x - a.x)) / glm::length(e);
        inside &= side > 0.0f;
        to_line = std::min(to_line, std::fabs(side));
        const float t = std::clamp(glm::dot(q - a, e) / glm::dot(e, e), 0.0f, 1.0f);
        to_segment = std::min(to_segment, glm::length(q - (a + t * e)));
    }
    return inside ? to_line : -to_segment;
}

std::vector<glm::vec2> project_all(const Camera& cam, int w, int h, const std::vector<glm::vec3>& pts) {
    std::vector<glm::vec2> out;
    for (const glm::vec3& p : pts) out.push_back(project(cam, w, h, p));
    return out;
}

// The convex hull (screen) of a box's eight corners, for skipping the pixels
// the occluder itself covers.
std::vector<glm::vec2> hull(std::vector<glm::vec2> p) {
    std::sort(p.begin(), p.end(), [](glm::vec2 a, glm::vec2 b) { return a.x < b.x || (a.x == b.x && a.y < b.y); });
    auto cross = [](glm::vec2 o, glm::vec2 a, glm::vec2 b) { return (a.x - o.x) * (b.y - o.y) - (a.y - o.y) * (b.x - o.x); };
    std::vector<glm::vec2> h(2 * p.size());
    std::size_t k = 0;
    for (std::size_t i = 0; i < p.size(); ++i) {
        while (k >= 2 && cross(h[k - 2], h[k - 1], p[i]) <= 0.0f) --k;
        h[k++] = p[i];
    }
    for (std::size_t i = p.size() - 1, t = k + 1; i-- > 0;) {
        while (k >= t && cross(h[k - 2], h[k - 1], p[i]) <= 0.0f) --k;
        h[k++] = p[i];
    }
    h.resize(k - 1);
    return h;
}

std::vector<glm::vec3> box_corners(glm::vec3 lo, glm::vec3 hi) {
    std::vector<glm::vec3> c;
    for (int i = 0; i < 8; ++i) c.push_back({(i & 1) ? hi.x : lo.x, (i & 2) ? hi.y : lo.y, (i & 4) ? hi.z : lo.z});
    return c;
}

ShadingLight sun(glm::vec3 toward) {
    ShadingLight L;
    L.direction = glm::normalize(toward);
    L.radiance = glm::vec3(3.0f);
    return L;
}

// What a shadow check found: pixels in each class and the failures.
struct Outline {
    int inside = 0, outside = 0, bad_inside = 0, bad_outside = 0, band = 0, bad_band = 0;
};

// Pixels of `shadowed` on the floor (`floor_poly`), away from `skip` by 2
// pixels: deeper than `margin` inside `shadow` must be exactly 0, farther
// than `margin` outside it exactly as in `lit` (the image without shadows),
// and those between must lie between the two.
Outline check_outline(const Frame& shadowed, const Frame& lit, const std::vector<glm::vec2>& floor_poly,
                      const std::vector<glm::vec2>& shadow, const std::vector<glm::vec2>& skip, float margin) {
    Outline o;
    for (int y = 0; y < shadowed.h; ++y)
        for (int x = 0; x < shadowed.w; ++x) {
            const glm::vec2 q(float(x) + 0.5f, float(y) + 0.5f);
            if (signed_distance(floor_poly, q) < 2.0f) continue;
            if (!skip.empty() && signed_distance(skip, q) > -2.0f) continue;
            const float d = signed_distance(shadow, q), v = shadowed.r(x, y), l = lit.r(x, y);
            if (d >= margin) {
                ++o.inside;
                o.bad_inside += v != 0.0f;
            } else if (d <= -margin) {
                ++o.outside;
                o.bad_outside += v != l;
            } else {
                ++o.band;
                o.bad_band += !(v >= 0.0f && v <= l);
            }
        }
    return o;
}

} // namespace

TEST_SUITE("shadows") {

TEST_CASE("a square occluder lit straight down casts its projection, outline within 2 pixels") {
    Scene s = base_scene();
    add_floor(s, 2.0f);
    add_square(s, 0.5f, 0.5f);
    Camera cam;
    cam.eye = {0.3f, 2.5f, 3.0f};
    cam.target = {0.0f, 0.0f, 0.0f};
    cam.near_plane = 0.5f;
    cam.far_plane = 10.0f;
    const int W = 256, H = 192;
    const std::vector<ShadingLight> lights = {sun({0, 1, 0})};
    const Frame on = render(s, cam, lights, true, W, H);
    const Frame off = render(s, cam, lights, false, W, H);
    const auto floor_poly = project_all(cam, W, H, square(2.0f, 0.0f));
    const auto shadow = project_all(cam, W, H, square(0.5f, 0.0f));
    const auto occluder = project_all(cam, W, H, square(0.5f, 0.5f));
    const Outline o = check_outline(on, off, floor_poly, shadow, occluder, 2.0f);
    MESSAGE("inside " << o.inside << ", outside " << o.outside << ", outline band " << o.band);
    CHECK(o.inside > 500);  // the visible part of the shadow is large enough to mean something
    CHECK(o.outside > 10000);
    CHECK(o.bad_inside == 0);
    CHECK(o.bad_outside == 0);
    CHECK(o.bad_band == 0);
}

TEST_CASE("a lit plane with no occluder has no acne: every pixel as without shadows, suns up to 75 degrees off the normal") {
    // (The diffuse lobe carries 1 - F(v.h), so a lit plane is not one value
    // across the image; the exact statement is: every pixel's visibility
    // is 1, i.e. each pixel equals its unshadowed value bit for bit.)
    Scene s = base_scene();
    add_floor(s, 2.0f);
    Camera cam;
    cam.eye = {0.0f, 2.0f, 3.0f};
    cam.near_plane = 0.5f;
    cam.far_plane = 10.0f;
    const int W = 200, H = 150;
    const auto floor_poly = project_all(cam, W, H, square(2.0f, 0.0f));
    for (float deg : {0.0f, 30.0f, 60.0f, 75.0f}) {
        const float a = glm::radians(deg);
        const std::vector<ShadingLight> lights = {sun({std::sin(a) * 0.6f, std::cos(a), std::sin(a) * 0.8f})};
        const Frame on = render(s, cam, lights, true, W, H);
        const Frame off = render(s, cam, lights, false, W, H);
        int floor_px = 0, differ = 0, lit = 0;
        for (int y = 0; y < H; ++y)
            for (int x = 0; x < W; ++x) {
                if (signed_distance(floor_poly, {float(x) + 0.5f, float(y) + 0.5f}) < 1.0f) continue;
                ++floor_px;
                differ += on.r(x, y) != off.r(x, y);
                lit += on.r(x, y) > 0.0f;
            }
        INFO("sun " << deg << " degrees from the normal");
        CHECK(floor_px > 10000);
        CHECK(lit == floor_px);
        CHECK(differ == 0);
    }
}

TEST_CASE("no light leaks where a box stands on the plane") {
    Scene s = base_scene();
    add_floor(s, 2.0f);
    const glm::vec3 lo(-0.25f, 0.0f, -0.25f), hi(0.25f, 0.5f, 0.25f);
    add_box(s, lo, hi);
    Camera cam;
    cam.eye = {-2.5f, 1.6f, 1.2f};
    cam.target = {-0.45f, 0.0f, 0.0f};
    cam.near_plane = 0.3f;
    cam.far_plane = 10.0f;
    const int W = 256, H = 192;
    // Light from +x, 45 degrees up: the shadow is x in [-0.75, -0.25].
    const std::vector<ShadingLight> lights = {sun({1, 1, 0})};
    const Frame on = render(s, cam, lights, true, W, H);
    const Frame off = render(s, cam, lights, false, W, H);
    const auto floor_poly = project_all(cam, W, H, square(2.0f, 0.0f));
    const auto box = hull(project_all(cam, W, H, box_corners(lo, hi)));
    // The shadow runs on under the box (hidden there): its edge at the foot
    // x = -0.25 is no outline, the pixels right next to the foot must be
    // fully dark.
    const auto shadow = project_all(cam, W, H, {{-0.75f, 0, 0.25f}, {0.0f, 0, 0.25f}, {0.0f, 0, -0.25f}, {-0.75f, 0, -0.25f}});
    // The pixels next to the box's foot, 1 to 3 pixels from its outline: in
    // shadow, they must be dark (a leak lights a thin line there).
    int foot = 0, leaks = 0;
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x) {
            const glm::vec2 q(float(x) + 0.5f, float(y) + 0.5f);
            const float db = -signed_distance(box, q);
            if (db < 1.0f || db > 3.0f || signed_distance(shadow, q) < 3.0f) continue;
            ++foot;
            leaks += on.r(x, y) != 0.0f;
        }
    MESSAGE("pixels at the foot of the box " << foot);
    CHECK(foot > 20);
    CHECK(leaks == 0);
    const Outline o = check_outline(on, off, floor_poly, shadow, box, 2.0f);
    MESSAGE("inside " << o.inside << ", outside " << o.outside << ", outline band " << o.band);
    CHECK(o.inside > 300);
    CHECK(o.bad_inside == 0);
    CHECK(o.bad_outside == 0);
    CHECK(o.bad_band == 0);
}

TEST_CASE("a point light's cube map: the occluder's shadow is its central projection, no seams between faces") {
    Scene s = base_scene();
    add_floor(s, 3.0f);
    // Light at height 2, occluder square of side 0.5 at height 1: the shadow
    // is the square of side 1 on the floor.
    add_square(s, 0.25f, 1.0f);
    ShadingLight lamp;
    lamp.point = true;
    lamp.position = {0.0f, 2.0f, 0.0f};
    lamp.radiance = glm::vec3(8.0f);
    Camera cam;
    cam.eye = {0.4f, 3.2f, 4.0f};
    cam.target = {0.0f, 0.0f, -0.3f};
    cam.fov_y_deg = 60.0f;
    cam.near_plane = 0.5f;
    cam.far_plane = 12.0f;
    const int W = 256, H = 192;
    const Frame on = render(s, cam, {lamp}, true, W, H);
    const Frame off = render(s, cam, {lamp}, false, W, H);
    const auto floor_poly = project_all(cam, W, H, square(3.0f, 0.0f));
    const auto shadow = project_all(cam, W, H, square(0.5f, 0.0f));
    const auto occluder = project_all(cam, W, H, square(0.25f, 1.0f));
    // The floor beyond 2 m from the light's foot is seen by the side faces:
    // lit exactly as without shadows there too (checked with the rest).
    const Outline o = check_outline(on, off, floor_poly, shadow, occluder, 2.0f);
    MESSAGE("inside " << o.inside << ", outside " << o.outside << ", outline band " << o.band);
    CHECK(o.inside > 300);
    CHECK(o.outside > 10000);
    CHECK(o.bad_inside == 0);
    CHECK(o.bad_outside == 0);
    CHECK(o.bad_band == 0);
}

TEST_CASE("shadowed frames are byte-identical for any thread count and tile size") {
    DefaultScene d = make_default_scene();
    ShadingLight lamp;
    lamp.point = true;
    lamp.position = {0.5f, 2.5f, 1.5f};
    lamp.radiance = glm::vec3(6.0f);
    std::vector<ShadingLight> lights = default_light_rig();
    lights.push_back(lamp);
    const int W = 203, H = 117;
    const Frame ref = render(d.scene, d.camera, lights, true, W, H, 1, 64, 512, DebugView::None);
    const Frame off = render(d.scene, d.camera, lights, false, W, H, 1, 64, 512, DebugView::None);
    CHECK(ref.rgba != off.rgba);  // the shadows show
    for (int threads : {2, 3, 8}) CHECK(render(d.scene, d.camera, lights, true, W, H, threads, 64, 512, DebugView::None).rgba == ref.rgba);
    for (int tile : {16, 32, 128}) CHECK(render(d.scene, d.camera, lights, true, W, H, 2, tile, 512, DebugView::None).rgba == ref.rgba);
}

TEST_CASE("the directional map fits the visible part of the scene, snapped to whole texels") {
    Bounds b;
    b.add({-10.0f, 0.0f, -10.0f});
    b.add({10.0f, 1.0f, 10.0f});
    Camera far_cam;  // sees the whole scene
    far_cam.eye = {0.0f, 30.0f, 30.0f};
    far_cam.near_plane = 1.0f;
    far_cam.far_plane = 100.0f;
    Camera near_cam = far_cam;  // sees a corner: the map shrinks
    near_cam.eye = {8.0f, 1.0f, 8.0f};
    near_cam.target = {9.0f, 0.0f, 9.0f};
    near_cam.far_plane = 4.0f;
    glm::mat4 vp;
    float range = 0.0f;
    const ShadowMap whole = fit_directional_shadow({0, 1, 0}, b, far_cam, 1.5f, 1024, vp, range);
    const ShadowMap part = fit_directional_shadow({0, 1, 0}, b, near_cam, 1.5f, 1024, vp, range);
    CHECK(whole.texel >= 20.0f / 1024.0f);
    CHECK(part.texel < whole.texel / 2.0f);
    CHECK(part.offset_u == std::floor(part.offset_u));
    CHECK(part.offset_v == std::floor(part.offset_v));
    // The frustum's corner points fall inside the map.
    const glm::vec3 q = glm::vec3(9.0f, 0.0f, 9.0f) - part.origin;
    const float u = glm::dot(q, part.axis_u) + part.offset_u, v = glm::dot(q, part.axis_v) + part.offset_v;
    CHECK(u > 0.0f);
    CHECK(u < 1024.0f);
    CHECK(v > 0.0f);
    CHECK(v < 1024.0f);
    // The depth range holds the whole scene along the light (casters outside the view still cast).
    CHECK(range >= 1.0f);
}


TEST_CASE("a MASK caster's vertex colour alpha cuts its shadow out, as it cuts the surface") {
    // The occluder square at y = 0.5 under a sun straight down: with vertex
    // colour alpha 0 under a 0.5 cutoff it is discarded in the image and in
    // the shadow map, with alpha 1 it casts as an opaque one does.
    Camera cam;
    cam.eye = {0.3f, 2.5f, 3.0f};
    cam.target = {0.0f, 0.0f, 0.0f};
    cam.near_plane = 0.5f;
    cam.far_plane = 10.0f;
    const int W = 128, H = 96;
    const std::vector<ShadingLight> lights = {sun({0, 1, 0})};
    auto scene_with_alpha = [](float alpha) {
        Scene s = base_scene();
        Material mask = s.materials[0];
        mask.alpha_mode = AlphaMode::Mask;
        mask.alpha_cutoff = 0.5f;
        s.materials.push_back(mask);
        add_floor(s, 2.0f);
        add_square(s, 0.5f, 0.5f);
        s.meshes.back().material = 1;
        s.meshes.back().colors.assign(4, glm::vec4(1.0f, 1.0f, 1.0f, alpha));
        return s;
    };
    Scene floor_only = base_scene();
    add_floor(floor_only, 2.0f);
    const Frame bare = render(floor_only, cam, lights, true, W, H);
    const Frame cut = render(scene_with_alpha(0.0f), cam, lights, true, W, H);
    const Frame kept = render(scene_with_alpha(1.0f), cam, lights, true, W, H);
    CHECK(cut.rgba == bare.rgba);
    // A floor point in the shadow that the occluder does not hide from the
    // eye (the ray to it crosses y = 0.5 at z = 0.92), and one far outside.
    const glm::vec2 c = project(cam, W, H, {0.0f, 0.0f, 0.4f});
    const glm::vec2 e = project(cam, W, H, {1.5f, 0.0f, 1.5f});
    CHECK(kept.r(int(c.x), int(c.y)) == 0.0f);
    CHECK(bare.r(int(c.x), int(c.y)) > 0.0f);
    CHECK(kept.r(int(e.x), int(e.y)) > 0.0f);
}

}

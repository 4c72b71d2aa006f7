// The whole shading path on whole scenes: the built-in scene against its
// golden image, thread/tile invariance of PBR frames, and the real assets of
// ../shared/assets rendered without NaN.
#include <doctest/doctest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>


#include "scene/default_scene.h"
#include "scene/image_diff.h"
#include "scene/write_image.h"
#include "scene/load_scene.h"
#include "renderer/scene_renderer.h"
#include "shading/tonemap.h"

using namespace prast;
namespace fs = std::filesystem;

namespace {

std::vector<std::uint8_t> render_rgba8(const Scene& scene, const Camera& cam, int w, int h, int threads,
                                       int tile, DebugView view = DebugView::None) {
    Renderer r({threads, tile});
    SceneRenderer sr(scene, r);
    FrameSettings fs;
    fs.camera = cam;
    fs.lights = shading_lights(scene);
    if (fs.lights.empty()) fs.lights = default_light_rig();
    fs.view = view;
    Framebuffer fb(w, h);
    sr.render(fs, fb);
    std::vector<std::uint8_t> px(std::size_t(w) * h * 4);
    resolve_to_srgb8(fb.color.data(), w, h, 1.0f, ToneMap::Aces, px.data());
    return px;
}

bool has_nan(const Framebuffer& fb) {
    for (float f : fb.color)
        if (!std::isfinite(f)) return true;
    return false;
}

} // namespace

TEST_SUITE("scene") {

TEST_CASE("built-in scene matches its golden image") {
    // Golden: made once by this test, reviewed by eye (spheres sweep
    // roughness left to right, metallic bottom to top; tiled floor with
    // visible bevels from the normal map). Tolerance: float shading may move a
    // channel by 1/255 on at most 0.1% of pixels between compilers; this build
    // is expected to match exactly.
    const int W = 192, H = 108;
    DefaultScene d = make_default_scene();
    std::vector<std::uint8_t> px = render_rgba8(d.scene, d.camera, W, H, 2, 64);
    const std::string golden = std::string(PRAST_SOURCE_DIR) + "/tests/golden/default_scene.png";
    if (!fs::exists(golden)) {
        write_png_atomic(golden, W, H, px.data());
        FAIL("golden image created at " << golden << ": review it and commit it");
    }
    // Pixels beyond 0 (tolerance 0) are counted; the largest difference must stay <= 1.
    const Image8 actual = Image8::from_rgba(W, H, px.data(), false);
    const Image8 expected = read_image8(golden);
    REQUIRE(expected.width == W);
    REQUIRE(expected.height == H);
    const DiffResult diff = diff_images(actual, expected, {0, 0.001});
    MESSAGE("golden: max channel difference " << diff.max_diff << ", differing pixels " << diff.differing);
    CHECK(diff.max_diff <= 1);
    CHECK(diff.match);  // at most floor(0.001 * W * H) pixels differ at all
}

TEST_CASE("PBR frames are byte-identical for any thread count and tile size") {
    DefaultScene d = make_default_scene();
    const int W = 203, H = 117;  // not a multiple of 4 or of any tile size
    std::vector<std::uint8_t> ref = render_rgba8(d.scene, d.camera, W, H, 1, 64);
    for (int threads : {2, 3, 8})
        CHECK(render_rgba8(d.scene, d.camera, W, H, threads, 64) == ref);
    for (int tile : {16, 32, 128, 256})
        CHECK(render_rgba8(d.scene, d.camera, W, H, 2, tile) == ref);
}

TEST_CASE("every debug view renders the built-in scene without NaN") {
    DefaultScene d = make_default_scene();
    for (const char* name : {"albedo", "normal", "roughness", "metallic", "uv", "depth", "overdraw", "tiles",
                             "ndf", "fresnel", "geometry", "diffuse", "specular"}) {
        DebugView v;
        REQUIRE(parse_debug_view(name, v));
        Renderer r({2, 64});
        SceneRenderer sr(d.scene, r);
        FrameSettings fs;
        fs.camera = d.camera;
        fs.lights = shading_lights(d.scene);
        fs.view = v;
        Framebuffer fb(96, 54);
        sr.render(fs, fb);
        INFO(name);
        CHECK_FALSE(has_nan(fb));
        // Something is drawn: not every pixel is the black background.
        bool any = false;
        for (std::size_t i = 0; i < fb.color.size(); i += 4) any |= fb.color[i] + fb.color[i + 1] + fb.color[i + 2] > 0.0f;
        CHECK(any);
    }
}

TEST_CASE("real assets render without NaN and are not black") {
    const fs::path root = PRAST_SHARED_ASSETS;
    if (!fs::exists(root)) {
        MESSAGE("skipped: " << root.string() << " is absent");
        return;
    }
    struct Case { const char* file; glm::vec3 eye, target; float fov; };
    const Case cases[] = {
        {"tea-set-01/gltf/tea_set_01_1k.gltf", {0.02f, 0.60f, 1.35f}, {0.02f, 0.04f, -0.04f}, 32},
        {"tea-set-01/obj/tea_set_01.obj", {0.02f, 0.60f, 1.35f}, {0.02f, 0.04f, -0.04f}, 32},
        {"normal-tangent-test/NormalTangentTest.glb", {0, -0.125f, 3.9f}, {0, -0.125f, 0}, 45},
        {"normal-tangent-test/obj/NormalTangentTest.obj", {0, -0.125f, 3.9f}, {0, -0.125f, 0}, 45},
        {"stanford-bunny/stanford-bunny.obj", {-0.017f, 0.13f, 0.36f}, {-0.017f, 0.108f, 0}, 35},
    };
    for (const Case& c : cases) {
        INFO(c.file);
        Scene scene = load_scene((root / c.file).string());
        Camera cam;
        cam.eye = c.eye;
        cam.target = c.target;
        cam.fov_y_deg = c.fov;
        fit_clip_planes(cam, scene.bounds());
        Renderer r({2, 64});
        SceneRenderer sr(scene, r);
        CHECK(sr.warnings().empty());
        FrameSettings fs;
        fs.camera = cam;
        fs.lights = default_light_rig();
        Framebuffer fb(160, 120);
        sr.render(fs, fb);
        CHECK_FALSE(has_nan(fb));
        double sum = 0;
        for (std::size_t i = 0; i < fb.color.size(); i += 4) sum += fb.color[i] + fb.color[i + 1] + fb.color[i + 2];
        CHECK(sum / (160.0 * 120.0) > 0.02);
        CHECK(r.stats().fragments_written > 160u * 120u / 10u);
    }
}
}

TEST_SUITE("scene") {

namespace {
// A unit quad in the z = 0 plane facing +z, one material, seen from the eye.
Scene quad_scene(const Material& m) {
    Scene s;
    Mesh q;
    q.positions = {{-1, -1, 0}, {1, -1, 0}, {1, 1, 0}, {-1, 1, 0}};
    q.normals.assign(4, glm::vec3(0, 0, 1));
    q.uvs = {{0, 1}, {1, 1}, {1, 0}, {0, 0}};
    q.tangents.assign(4, glm::vec4(1, 0, 0, 1));
    q.indices = {0, 1, 2, 0, 2, 3};
    s.meshes.push_back(q);
    s.materials.push_back(m);
    return s;
}

Framebuffer render_quad(const Scene& s, glm::vec3 eye, glm::vec3 towards_light) {
    Renderer r({1, 64});
    SceneRenderer sr(s, r);
    FrameSettings fs;
    fs.camera.eye = eye;
    fs.camera.target = glm::vec3(0.0f);
    fs.camera.near_plane = 0.1f;
    fs.camera.far_plane = 10.0f;
    ShadingLight sun;
    sun.direction = glm::normalize(towards_light);
    sun.radiance = glm::vec3(2.0f);
    fs.lights = {sun};
    fs.ambient = glm::vec3(0.0f);
    Framebuffer fb(32, 32);
    sr.render(fs, fb);
    return fb;
}
} // namespace

TEST_CASE("alpha mode MASK discards fragments below the cutoff, keeps those above") {
    Material m;
    m.alpha_mode = AlphaMode::Mask;
    m.alpha_cutoff = 0.5f;
    m.base_color_factor = glm::vec4(0.8f, 0.8f, 0.8f, 0.3f);
    Framebuffer below = render_quad(quad_scene(m), {0, 0, 3}, {0, 0, 1});
    CHECK(below.pixel(16, 16)[0] == 0.0f);
    CHECK(below.depth[16 * 32 + 16] == 1.0f);  // a discarded fragment writes no depth
    m.base_color_factor.a = 0.7f;
    Framebuffer above = render_quad(quad_scene(m), {0, 0, 3}, {0, 0, 1});
    CHECK(above.pixel(16, 16)[0] > 0.1f);
    CHECK(above.depth[16 * 32 + 16] < 1.0f);
}

TEST_CASE("a double-sided material shades its back face with the normal flipped") {
    Material m;
    m.double_sided = true;
    // Seen from behind and lit from behind: the flipped normal faces the light.
    Framebuffer lit = render_quad(quad_scene(m), {0, 0, -3}, {0, 0, -1});
    CHECK(lit.pixel(16, 16)[0] > 0.1f);
    // Seen from behind, lit from the front: the back face is dark.
    Framebuffer dark = render_quad(quad_scene(m), {0, 0, -3}, {0, 0, 1});
    CHECK(dark.pixel(16, 16)[0] == 0.0f);
    CHECK(dark.depth[16 * 32 + 16] < 1.0f);  // drawn, just unlit
    // Single-sided: the back face is culled.
    m.double_sided = false;
    Framebuffer culled = render_quad(quad_scene(m), {0, 0, -3}, {0, 0, -1});
    CHECK(culled.depth[16 * 32 + 16] == 1.0f);
}
}

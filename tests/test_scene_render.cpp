// The whole shading path on whole scenes: the built-in scene against its
// golden image, thread/tile invariance of PBR frames, the real assets of
// ../shared/assets rendered without NaN, the one frame set-up
// (renderer/frame_setup.h) that render and step share, and SceneRenderer's
// per-draw taps and triangle limit (what step records through).
#include <doctest/doctest.h>

#include <atomic>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>


#include "apps/frame_request.h"
#include "apps/render_options.h"
#include "renderer/frame_setup.h"
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

TEST_CASE("the built-in scene's images are the same made on 1, 2, 4 or all threads") {
    const DefaultScene one = make_default_scene(1);
    REQUIRE(one.scene.images.size() == 3);
    REQUIRE(one.scene.environment);
    for (int threads : {2, 4, 0}) {
        CAPTURE(threads);
        const DefaultScene d = make_default_scene(threads);
        REQUIRE(d.scene.images.size() == one.scene.images.size());
        for (std::size_t i = 0; i < d.scene.images.size(); ++i) {
            CHECK(d.scene.images[i].name == one.scene.images[i].name);
            CHECK(d.scene.images[i].decoded->rgba == one.scene.images[i].decoded->rgba);
        }
        CHECK(d.scene.environment->rgba == one.scene.environment->rgba);
        CHECK(d.scene.environment->width == 512);
    }
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

namespace {

RenderOptions parse_flags(std::vector<std::string> args) {
    std::vector<const char*> argv = {"render"};
    for (const std::string& a : args) argv.push_back(a.c_str());
    RenderOptions opt;
    const std::string err = parse_render_args(int(argv.size()), argv.data(), opt);
    REQUIRE_MESSAGE(err.empty(), err);
    return opt;
}

// A tap that counts what one draw reports.
struct CountingTap {
    static constexpr bool enabled = true;
    std::atomic<std::uint64_t>* vertices;
    std::atomic<std::uint64_t>* triangles;
    void vertex(std::uint32_t, const float*, const float*, int) { ++*vertices; }
    void triangle(std::uint32_t, TriangleFate, bool, const TriangleSetup*) { ++*triangles; }
    void binned(std::uint32_t, int) {}
    void fragments(std::uint32_t, int, int, std::uint32_t, std::uint32_t, const float*) {}
    template <int NV>
    void shaded(const FragmentBlock<NV>&, const FragmentOut&, std::uint32_t) {}
};

} // namespace

TEST_SUITE("scene") {

TEST_CASE("frame set-up: render's and step's requests for the same flags give the same frame") {
    const std::string env = std::string(PRAST_SOURCE_DIR) + "/assets/env/studio_small.hdr";
    const std::string cornell = std::string(PRAST_SOURCE_DIR) + "/assets/cornell/cornell.obj";
    const std::vector<std::vector<std::string>> command_lines = {
        {"--size", "96x64"},
        {"--size", "96x64", "--msaa", "1", "--shadows", "on", "--shadow-size", "256", "--sun", "1,2,3:2,2,2"},
        {cornell, "--size", "80x60", "--eye", "0,1,4", "--fov", "50", "--near", "0.5", "--brdf", "gltf"},
        {cornell, "--size", "80x60", "--env", env, "--env-intensity", "2", "--energy", "conserve",
         "--background", "blur", "--ambient", "0.2,0.2,0.2"},
    };
    for (const std::vector<std::string>& args : command_lines) {
        INFO(args.front() << " ... " << args.back());
        const RenderOptions opt = parse_flags(args);
        const FrameRequest render_req = render_frame_request(opt), step_req = step_frame_request(opt);
        CHECK(step_req.recording);
        CHECK(!render_req.recording);
        FrameSetup r, s;
        REQUIRE(!prepare_scene(render_req, r));
        REQUIRE(!prepare_scene(step_req, s));
        REQUIRE(!r.orbit(0.0));
        REQUIRE(!s.orbit(0.0));
        const FrameSettings &a = r.settings, &b = s.settings;
        const Camera &ca = a.camera, &cb = b.camera;
        CHECK(ca.eye == cb.eye);
        CHECK(ca.target == cb.target);
        CHECK(ca.up == cb.up);
        CHECK(ca.fov_y_deg == cb.fov_y_deg);
        CHECK(ca.near_plane == cb.near_plane);
        CHECK(ca.far_plane == cb.far_plane);
        REQUIRE(a.lights.size() == b.lights.size());
        for (std::size_t i = 0; i < a.lights.size(); ++i) {
            CHECK(a.lights[i].point == b.lights[i].point);
            CHECK(a.lights[i].direction == b.lights[i].direction);
            CHECK(a.lights[i].position == b.lights[i].position);
            CHECK(a.lights[i].radiance == b.lights[i].radiance);
        }
        CHECK(a.ambient == b.ambient);
        CHECK(a.model == b.model);
        CHECK(a.view == b.view);
        CHECK(a.energy == b.energy);
        CHECK(a.background == b.background);
        CHECK(a.background_color == b.background_color);
        CHECK(a.samples == b.samples);
        CHECK(a.samples == opt.msaa);
        CHECK(a.shadows.enabled == b.shadows.enabled);
        CHECK(a.shadows.size == b.shadows.size);
        CHECK(r.exposure() == s.exposure());
        CHECK(r.tonemap() == s.tonemap());
        CHECK(bool(r.environment_image) == bool(s.environment_image));
        CHECK(r.used_default_rig == s.used_default_rig);
        CHECK(r.notes == s.notes);
    }
}

TEST_CASE("frame set-up: the default rig, the notes and the errors with their exit codes") {
    const std::string cornell = std::string(PRAST_SOURCE_DIR) + "/assets/cornell/cornell.obj";
    const std::string env = std::string(PRAST_SOURCE_DIR) + "/assets/env/studio_small.hdr";
    {
        // No light in the model or the flags, no environment: the rig, said so.
        FrameSetup f;
        REQUIRE(!prepare_scene(render_frame_request(parse_flags({cornell, "--size", "64x48"})), f));
        CHECK(f.used_default_rig);
        CHECK(f.settings.lights.size() == default_light_rig().size());
        REQUIRE(f.notes.size() == 1);
        CHECK(f.notes[0].find("using the default key+fill rig") != std::string::npos);
    }
    {
        // An environment lights the scene: no rig, and --ambient is said to be unused.
        FrameSetup f;
        REQUIRE(!prepare_scene(render_frame_request(parse_flags({cornell, "--size", "64x48", "--env", env,
                                                                 "--ambient", "0.5,0.5,0.5"})), f));
        CHECK(!f.used_default_rig);
        CHECK(f.settings.lights.empty());
        REQUIRE(f.notes.size() == 1);
        CHECK(f.notes[0] == "warning: --ambient is not used: the environment map replaces the ambient term");
    }
    FrameRequest req = render_frame_request(parse_flags({"--size", "64x48"}));
    req.scene = std::string(PRAST_SOURCE_DIR) + "/assets/no-such-model.obj";
    FrameSetup missing;
    const FrameError e1 = prepare_scene(req, missing);
    CHECK(e1.code == kFrameExitBadFile);
    CHECK(e1.message.find("no-such-model.obj") != std::string::npos);
    req = render_frame_request(parse_flags({"--size", "64x48", "--eye", "1,1,1", "--target", "1,1,1"}));
    FrameSetup same_point;
    const FrameError e2 = prepare_scene(req, same_point);
    CHECK(e2.code == kFrameExitUsage);
    CHECK(e2.message == "--eye/--target: the eye and the target are the same point");
    req = render_frame_request(parse_flags({cornell, "--env", "/nonexistent/sky.hdr"}));
    FrameSetup no_env;
    const FrameError e3 = prepare_scene(req, no_env);
    CHECK(e3.code == kFrameExitBadFile);
    CHECK(e3.message.find("sky.hdr") != std::string::npos);
}

TEST_CASE("SceneRenderer: taps see every draw, change no byte, and a triangle limit stops the frame there") {
    FrameSetup f;
    REQUIRE(!setup_frame(render_frame_request(parse_flags({"--size", "96x64", "--threads", "2"})), f));
    REQUIRE(!f.orbit(0.0));
    SceneRenderer& sr = *f.scene_renderer;
    Framebuffer plain(96, 64), tapped(96, 64);
    sr.render(f.settings, plain);

    std::atomic<std::uint64_t> vertices{0}, triangles{0};
    std::vector<SceneDraw> draws;
    sr.render(f.settings, tapped, nullptr, [&](const SceneDraw& d) {
        draws.push_back(d);
        return CountingTap{&vertices, &triangles};
    });
    CHECK(tapped.color == plain.color);
    CHECK(tapped.depth == plain.depth);
    std::uint64_t total_vertices = 0, total_triangles = 0;
    REQUIRE(!draws.empty());
    for (const SceneDraw& d : draws) {
        const Mesh& m = f.scene.meshes[std::size_t(d.mesh)];
        CHECK(d.first_triangle == total_triangles);  // numbered in submission order
        CHECK(d.triangle_count == m.indices.size() / 3);
        CHECK(d.vertex_count == m.positions.size());
        total_vertices += d.vertex_count;
        total_triangles += d.triangle_count;
    }
    CHECK(total_triangles == f.scene.triangle_count());
    CHECK(vertices.load() == total_vertices);
    CHECK(triangles.load() >= total_triangles);  // one event per triangle, one per clipped piece

    // A limit inside the second draw: no tap for the draws after it, and
    // only the triangles before the limit reported.
    REQUIRE(draws.size() >= 2);
    const std::uint64_t limit = draws[1].first_triangle + 1;
    std::size_t taps = 0;
    std::atomic<std::uint64_t> v2{0}, t2{0};
    Framebuffer cut(96, 64);
    sr.render(f.settings, cut, nullptr, [&](const SceneDraw&) {
        ++taps;
        return CountingTap{&v2, &t2};
    }, limit);
    CHECK(taps == 2);
    CHECK(t2.load() >= limit);
    CHECK(t2.load() < triangles.load());
    // No triangle at all: every sample is the background.
    Framebuffer none(96, 64), background(96, 64);
    sr.render(f.settings, none, nullptr, NoTaps{}, 0);
    const BackgroundFill fill = f.background(96, 64);
    bool all_background = true;
    for (int y = 0; y < 64; ++y)
        for (int x = 0; x < 96; ++x) {
            const glm::vec3 c = fill.at(x, y);
            const float* p = none.pixel(x, y);
            all_background &= p[0] == c.r && p[1] == c.g && p[2] == c.b;
        }
    CHECK(all_background);
    CHECK(cut.color != plain.color);
}

TEST_CASE("SceneRenderer: draws without maps run the position-and-normal layout, with the same bytes") {
    DefaultScene d = make_default_scene();
    // Meshes without maps (the spheres) and with (the floor's normal map), so both layouts run.
    Renderer r({2, 32});
    SceneRenderer sr(d.scene, r);
    int narrow = 0, usual = 0;
    for (const Mesh& m : d.scene.meshes) {
        const bool lite = narrow_varyings_suffice(m, sr.material_of(m), DebugView::None);
        CHECK(lite == !sr.material_of(m).reads_maps());
        CHECK_FALSE(narrow_varyings_suffice(m, sr.material_of(m), DebugView::Uv));
        (lite ? narrow : usual)++;
    }
    REQUIRE(narrow > 0);
    REQUIRE(usual > 0);
    Mesh coloured = d.scene.meshes[0];
    coloured.colors.assign(coloured.positions.size(), glm::vec4(1.0f));
    CHECK_FALSE(narrow_varyings_suffice(coloured, sr.material_of(coloured), DebugView::None));

    // Conductor and layered materials without maps take the scalar path: also the same bytes.
    Scene layered = d.scene;
    for (std::size_t i = 0; i < layered.materials.size(); ++i) {
        Material& m = layered.materials[i];
        if (i % 3 == 0) m.conductor = Conductor::Gold;
        if (i % 3 == 1) {
            m.has_clearcoat = true;
            m.clearcoat_factor = 0.7f;
            m.clearcoat_roughness_factor = 0.2f;
        }
    }
    struct Case {
        const Scene* scene;
        int samples;
        DebugView view;
        IblMode ibl;
    };
    const Case cases[] = {{&d.scene, 1, DebugView::None, IblMode::SplitSum},
                          {&d.scene, 4, DebugView::None, IblMode::SplitSum},
                          {&d.scene, 1, DebugView::Tiles, IblMode::SplitSum},
                          {&d.scene, 1, DebugView::None, IblMode::Reference},
                          {&layered, 1, DebugView::None, IblMode::SplitSum},
                          {&layered, 4, DebugView::None, IblMode::SplitSum}};
    for (const Case& c : cases) {
        CAPTURE(c.samples);
        CAPTURE(int(c.view));
        CAPTURE(int(c.ibl));
        CAPTURE(c.scene == &layered);
        SceneRenderer csr(*c.scene, r);
        FrameSettings fs;
        fs.camera = d.camera;
        fs.lights = default_light_rig();
        fs.samples = c.samples;
        fs.view = c.view;
        fs.ibl = c.ibl;
        fs.ibl_samples = 16;
        Framebuffer lite(96, 64), full(96, 64);
        csr.render(fs, lite);
        fs.narrow_varyings = false;
        csr.render(fs, full);
        CHECK(lite.color == full.color);
        CHECK(lite.depth == full.depth);
    }
}

}

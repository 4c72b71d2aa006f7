// Alpha BLEND (docs/shadows-and-transparency.md): the exact blended value over a known
// background (with 1 and 4 samples), back-to-front order whatever the file
// order, opaque output unchanged by blended meshes, and the sort itself.
#include <doctest/doctest.h>

#include <vector>

#include <glm/glm.hpp>

#include "scene/default_scene.h"
#include "renderer/scene_renderer.h"
#include "renderer/draw_order.h"

using namespace prast;

namespace {

// A quad facing +z at depth z, |x|, |y| <= h, with its own material.
void add_wall(Scene& s, float z, float h, int material) {
    Mesh m;
    m.positions = {{-h, -h, z}, {h, -h, z}, {h, h, z}, {-h, h, z}};
    m.normals.assign(4, glm::vec3(0.0f, 0.0f, 1.0f));
    m.indices = {0, 1, 2, 0, 2, 3};
    m.material = material;
    s.meshes.push_back(m);
}

// An unlit material: black base colour (so no light or ambient adds
// anything), the colour as emission; alpha and mode as given.
Material glow(glm::vec3 emissive, float alpha = 1.0f, AlphaMode mode = AlphaMode::Opaque) {
    Material m;
    m.base_color_factor = {0.0f, 0.0f, 0.0f, alpha};
    m.emissive_factor = emissive;
    m.alpha_mode = mode;
    return m;
}

Camera front_camera() {
    Camera c;
    c.eye = {0.0f, 0.0f, 4.0f};
    c.near_plane = 0.5f;
    c.far_plane = 20.0f;
    return c;
}

std::vector<float> render_linear(const Scene& scene, const Camera& cam, int w, int h, int samples = 1,
                                 int threads = 2, int tile = 64, std::vector<ShadingLight> lights = {}) {
    Renderer r({threads, tile});
    SceneRenderer sr(scene, r);
    FrameSettings fs;
    fs.camera = cam;
    fs.lights = lights;
    fs.ambient = glm::vec3(0.0f);
    fs.samples = samples;
    Framebuffer fb(w, h);
    sr.render(fs, fb);
    return fb.color;
}

float blend(float src, float a, float dst) { return src * a + dst * (1.0f - a); }

} // namespace

TEST_SUITE("transparency") {

TEST_CASE("a half-transparent plane over a known background gives the exact blended value, per sample") {
    Scene s;
    const glm::vec3 back(0.2f, 0.4f, 0.6f), front(1.0f, 0.5f, 0.0f);
    s.materials = {glow(back), glow(front, 0.5f, AlphaMode::Blend)};
    add_wall(s, -1.0f, 10.0f, 0);  // fills the view
    add_wall(s, 0.0f, 1.0f, 1);    // the centre of it
    const int W = 64, H = 64;
    for (int samples : {1, 4}) {
        const std::vector<float> px = render_linear(s, front_camera(), W, H, samples);
        INFO(samples << " samples");
        // Centre: blended; corner: the background alone.
        const float* c = &px[(std::size_t(H / 2) * W + W / 2) * 4];
        CHECK(c[0] == blend(front.r, 0.5f, back.r));
        CHECK(c[1] == blend(front.g, 0.5f, back.g));
        CHECK(c[2] == blend(front.b, 0.5f, back.b));
        const float* k = &px[0];
        CHECK(k[0] == back.r);
        CHECK(k[1] == back.g);
        CHECK(k[2] == back.b);
        // With 4 samples, an edge pixel half covered is the average of the
        // blended and the unblended samples (blending per sample, then the
        // resolve): between the two values, strictly.
        if (samples == 4) {
            int edge = 0;
            for (int x = 0; x < W; ++x) {
                const float r = px[(std::size_t(H / 2) * W + x) * 4];
                if (r != back.r && r != c[0]) {
                    ++edge;
                    CHECK(r > back.r);
                    CHECK(r < c[0]);
                }
            }
            CHECK(edge == 2);  // one pixel at each side of the quad
        }
    }
}

TEST_CASE("blended planes are drawn back to front whatever their file order") {
    const glm::vec3 back(0.1f, 0.2f, 0.3f), far_c(0.9f, 0.0f, 0.3f), near_c(0.0f, 0.7f, 0.5f);
    const float far_a = 0.6f, near_a = 0.3f;
    const int W = 48, H = 48;
    std::vector<float> ref;
    for (bool near_first : {false, true}) {
        Scene s;
        s.materials = {glow(back), glow(far_c, far_a, AlphaMode::Blend), glow(near_c, near_a, AlphaMode::Blend)};
        add_wall(s, -2.0f, 10.0f, 0);
        if (near_first) {
            add_wall(s, 0.5f, 1.0f, 2);
            add_wall(s, -0.5f, 1.0f, 1);
        } else {
            add_wall(s, -0.5f, 1.0f, 1);
            add_wall(s, 0.5f, 1.0f, 2);
        }
        const std::vector<float> px = render_linear(s, front_camera(), W, H);
        const float* c = &px[(std::size_t(H / 2) * W + W / 2) * 4];
        INFO("near plane first in the file: " << near_first);
        CHECK(c[0] == blend(near_c.r, near_a, blend(far_c.r, far_a, back.r)));
        CHECK(c[1] == blend(near_c.g, near_a, blend(far_c.g, far_a, back.g)));
        CHECK(c[2] == blend(near_c.b, near_a, blend(far_c.b, far_a, back.b)));
        if (ref.empty()) ref = px;
        else CHECK(px == ref);
    }
}

TEST_CASE("a blended plane is depth-tested against opaque surfaces and writes no depth") {
    Scene s;
    const glm::vec3 back(0.2f, 0.2f, 0.2f), glass(1.0f, 1.0f, 1.0f), front(0.0f, 0.5f, 0.0f);
    s.materials = {glow(back), glow(glass, 0.5f, AlphaMode::Blend), glow(front)};
    add_wall(s, -1.0f, 10.0f, 0);
    add_wall(s, 0.0f, 1.0f, 1);   // glass in the middle
    add_wall(s, 0.5f, 0.3f, 2);   // an opaque square in front of it, drawn before it
    add_wall(s, -0.5f, 0.3f, 2);  // and one behind it: seen through the glass
    const int W = 64, H = 64;
    const std::vector<float> px = render_linear(s, front_camera(), W, H);
    // The front square hides the glass (it is drawn before it, in file
    // order: the blended plane is tested against its depth).
    const float* c = &px[(std::size_t(H / 2) * W + W / 2) * 4];
    CHECK(c[1] == front.g);
    CHECK(c[0] == front.r);
}

TEST_CASE("opaque output is unchanged by blended meshes where they do not show") {
    DefaultScene d = make_default_scene();
    const int W = 160, H = 90;
    std::vector<ShadingLight> lights = default_light_rig();
    Renderer r({2, 64});
    auto frame = [&](const Scene& s) {
        SceneRenderer sr(s, r);
        FrameSettings fs;
        fs.camera = d.camera;
        fs.lights = lights;
        fs.samples = 4;
        Framebuffer fb(W, H);
        sr.render(fs, fb);
        return fb.color;
    };
    const std::vector<float> ref = frame(d.scene);
    // A blended quad far behind everything, facing the camera, hidden by
    // nothing but outside the view: the frame is bit-identical; then one
    // behind the camera (clipped away): identical too.
    Scene hidden = d.scene;
    Material m = glow(glm::vec3(5.0f), 0.5f, AlphaMode::Blend);
    hidden.materials.push_back(m);
    const int mi = int(hidden.materials.size()) - 1;
    Mesh q;
    const glm::vec3 e = d.camera.eye, f = glm::normalize(d.camera.target - d.camera.eye);
    const glm::vec3 back = e - f * 2.0f;  // behind the eye
    q.positions = {back + glm::vec3(-1, -1, 0), back + glm::vec3(1, -1, 0), back + glm::vec3(1, 1, 0),
                   back + glm::vec3(-1, 1, 0)};
    q.normals.assign(4, -f);
    q.indices = {0, 1, 2, 0, 2, 3, 0, 2, 1, 0, 3, 2};
    q.material = mi;
    hidden.meshes.push_back(q);
    CHECK(frame(hidden) == ref);
    // A fully transparent quad (alpha 0) across the view: c * 0 + dst * 1
    // leaves every pixel as it was.
    Scene clear = d.scene;
    clear.materials.push_back(glow(glm::vec3(5.0f), 0.0f, AlphaMode::Blend));
    Mesh w = q;
    const glm::vec3 mid = e + f * 1.0f;
    w.positions = {mid + glm::vec3(-5, -5, 0), mid + glm::vec3(5, -5, 0), mid + glm::vec3(5, 5, 0),
                   mid + glm::vec3(-5, 5, 0)};
    w.material = int(clear.materials.size()) - 1;
    clear.meshes.push_back(w);
    CHECK(frame(clear) == ref);
}

TEST_CASE("draw order: opaque and MASK meshes in file order, then BLEND back to front, ties in file order") {
    Scene s;
    s.materials = {Material{}, glow(glm::vec3(1.0f), 0.5f, AlphaMode::Blend)};
    s.materials[0].alpha_mode = AlphaMode::Opaque;
    Material mask;
    mask.alpha_mode = AlphaMode::Mask;
    s.materials.push_back(mask);
    // Mesh i: material, centre distance from the eye at the origin.
    const struct { int material; float z; } meshes[] = {
        {1, -2.0f}, {0, -9.0f}, {1, -5.0f}, {2, -1.0f}, {1, -2.0f}, {1, 5.0f}, {0, -3.0f}, {1, -7.0f}};
    for (const auto& m : meshes) add_wall(s, m.z, 0.5f, m.material);
    const std::vector<std::size_t> order = draw_order(s, glm::vec3(0.0f));
    // Opaque/MASK: 1, 3, 6. BLEND by distance 7 (7), 5 (2), 5 (5: behind the
    // eye, same distance, later in the file), 2 (0), 2 (4).
    CHECK(order == std::vector<std::size_t>{1, 3, 6, 7, 2, 5, 0, 4});
    CHECK(mesh_centre(s.meshes[7]) == glm::vec3(0.0f, 0.0f, -7.0f));
}

TEST_CASE("blended frames are byte-identical for any thread count and tile size") {
    Scene s;
    s.materials = {glow(glm::vec3(0.2f, 0.3f, 0.4f)), glow(glm::vec3(0.9f, 0.2f, 0.1f), 0.4f, AlphaMode::Blend),
                   glow(glm::vec3(0.1f, 0.8f, 0.3f), 0.7f, AlphaMode::Blend)};
    add_wall(s, -1.0f, 10.0f, 0);
    add_wall(s, 0.0f, 1.3f, 1);
    add_wall(s, 0.3f, 0.8f, 2);
    const int W = 101, H = 67;
    const std::vector<float> ref = render_linear(s, front_camera(), W, H, 4, 1, 64);
    for (int threads : {2, 3}) CHECK(render_linear(s, front_camera(), W, H, 4, threads, 64) == ref);
    for (int tile : {16, 32}) CHECK(render_linear(s, front_camera(), W, H, 4, 2, tile) == ref);
}

}

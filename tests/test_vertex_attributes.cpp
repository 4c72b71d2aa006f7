// Vertex colours, UV sets and per-texture samplers, on scenes built here in
// C++ (no loader): colours multiply base colour and alpha through the lit
// lane path and the scalar debug views alike, TEXCOORD_1 picks Mesh::uvs1,
// two textures of one image sample through their own samplers, and the glTF
// / OpenGL filters give the texels a hand computation says.
#include <doctest/doctest.h>

#include <cstring>
#include <memory>
#include <vector>

#include "renderer/scene_renderer.h"
#include "scene/image.h"
#include "shading/texture.h"
#include "tests/shading_test_util.h"

using namespace prast;
using prast::test::bits;

namespace {

constexpr int kSize = 32;

// An orthographic camera looking down -z at the square [-1, 1]^2.
Camera square_camera() {
    Camera c;
    c.eye = {0.0f, 0.0f, 3.0f};
    c.target = {0.0f, 0.0f, 0.0f};
    c.orthographic = true;
    c.ortho_ymag = 1.0f;
    return c;
}

// Two triangles filling [x0, x1] x [-1, 1] at z, facing the camera, uv
// (0, 0) top left to (1, 1) bottom right.
Mesh quad(float x0 = -1.0f, float x1 = 1.0f, float z = 0.0f) {
    Mesh m;
    m.positions = {{x0, 1.0f, z}, {x1, 1.0f, z}, {x1, -1.0f, z}, {x0, -1.0f, z}};
    m.normals.assign(4, glm::vec3(0.0f, 0.0f, 1.0f));
    m.uvs = {{0.0f, 0.0f}, {1.0f, 0.0f}, {1.0f, 1.0f}, {0.0f, 1.0f}};
    m.tangents.assign(4, glm::vec4(1.0f, 0.0f, 0.0f, 1.0f));
    m.indices = {0, 2, 1, 0, 3, 2};
    return m;
}

// A float (linear) image, texels listed row by row.
std::shared_ptr<const Image> float_image(int w, int h, const std::vector<glm::vec4>& texels) {
    auto img = std::make_shared<Image>();
    img->width = w;
    img->height = h;
    for (const glm::vec4& t : texels) img->rgba.insert(img->rgba.end(), {t.r, t.g, t.b, t.a});
    return img;
}

ImageSource source(std::shared_ptr<const Image> img) {
    ImageSource s;
    s.name = "test";
    s.decoded = std::move(img);
    return s;
}

// Unlit-like: no lights, no environment, ambient 1, so that the lit image is
// ambient * albedo * occlusion = the albedo exactly; background `bg`.
FrameSettings unlit_settings(DebugView view = DebugView::None, glm::vec3 bg = glm::vec3(0.0f)) {
    FrameSettings fs;
    fs.camera = square_camera();
    fs.ambient = glm::vec3(1.0f);
    fs.scene_environment = false;
    fs.background = Background::Color;
    fs.background_color = bg;
    fs.view = view;
    return fs;
}

Framebuffer draw(const Scene& scene, const FrameSettings& fs, int threads = 1, int tile = 64) {
    Renderer r({threads, tile});
    SceneRenderer sr(scene, r);
    Framebuffer fb(kSize, kSize);
    sr.render(fs, fb);
    return fb;
}

glm::vec4 pixel(const Framebuffer& fb, int x, int y) {
    const float* p = &fb.color[(std::size_t(y) * std::size_t(fb.width) + std::size_t(x)) * 4];
    return {p[0], p[1], p[2], p[3]};
}

bool same_bits(const Framebuffer& a, const Framebuffer& b) {
    return a.color.size() == b.color.size() &&
           std::memcmp(a.color.data(), b.color.data(), a.color.size() * sizeof(float)) == 0;
}

} // namespace

TEST_SUITE("vertex_attributes") {

TEST_CASE("a vertex-coloured quad: base colour factor times the colour, exactly, lit and in the albedo view") {
    Scene scene;
    Material m;
    m.base_color_factor = {0.5f, 0.75f, 1.0f, 1.0f};
    scene.materials.push_back(m);
    Mesh q = quad();
    q.colors.assign(4, glm::vec4(0.25f, 0.5f, 0.8f, 1.0f));
    scene.meshes.push_back(q);
    const glm::vec3 expect(0.5f * 0.25f, 0.75f * 0.5f, 1.0f * 0.8f);
    for (DebugView view : {DebugView::None, DebugView::Albedo}) {
        const Framebuffer fb = draw(scene, unlit_settings(view));
        for (int y = 0; y < kSize; ++y)
            for (int x = 0; x < kSize; ++x) {
                const glm::vec4 p = pixel(fb, x, y);
                INFO("view ", int(view), " pixel ", x, ",", y);
                REQUIRE(bits(p.r) == bits(expect.r));
                REQUIRE(bits(p.g) == bits(expect.g));
                REQUIRE(bits(p.b) == bits(expect.b));
            }
    }
    // Without colours: the factor alone (white).
    scene.meshes[0].colors.clear();
    const Framebuffer plain = draw(scene, unlit_settings());
    CHECK(bits(pixel(plain, 7, 9).r) == bits(0.5f));
    CHECK(bits(pixel(plain, 7, 9).g) == bits(0.75f));
}

TEST_CASE("interpolated vertex colours: the lane path equals the scalar albedo view bit for bit, on 1 and 2 threads") {
    Scene scene;
    Material m;
    m.base_color_factor = {0.9f, 0.8f, 0.7f, 1.0f};
    scene.materials.push_back(m);
    Mesh q = quad();
    q.colors = {{1.0f, 0.0f, 0.0f, 1.0f}, {0.0f, 1.0f, 0.0f, 1.0f}, {0.0f, 0.0f, 1.0f, 1.0f}, {1.0f, 1.0f, 1.0f, 1.0f}};
    scene.meshes.push_back(q);
    // A small triangle too, so that sparse blocks take the packed lane path.
    Mesh small;
    small.positions = {{-0.9f, 0.9f, 0.5f}, {-0.8f, 0.9f, 0.5f}, {-0.9f, 0.8f, 0.5f}};
    small.normals.assign(3, glm::vec3(0.0f, 0.0f, 1.0f));
    small.colors = {{0.2f, 0.4f, 0.6f, 1.0f}, {0.6f, 0.2f, 0.4f, 1.0f}, {0.4f, 0.6f, 0.2f, 1.0f}};
    small.indices = {0, 2, 1};
    scene.meshes.push_back(small);
    const Framebuffer lit = draw(scene, unlit_settings());
    const Framebuffer albedo = draw(scene, unlit_settings(DebugView::Albedo));
    CHECK(same_bits(lit, albedo));
    // Red at the top-left corner, blue at the bottom right, something between.
    const glm::vec4 tl = pixel(lit, 0, 0), br = pixel(lit, kSize - 1, kSize - 1);
    CHECK(tl.r > 0.85f * 0.9f);
    CHECK(br.b > 0.6f * 0.7f);
    CHECK(same_bits(lit, draw(scene, unlit_settings(), 2, 16)));
}

TEST_CASE("alpha from the vertex colour blends exactly over what is behind") {
    Scene scene;
    Material m;
    m.base_color_factor = {1.0f, 0.5f, 0.25f, 0.5f};
    m.alpha_mode = AlphaMode::Blend;
    scene.materials.push_back(m);
    Mesh q = quad();
    q.colors.assign(4, glm::vec4(0.5f, 1.0f, 1.0f, 0.5f));
    scene.meshes.push_back(q);
    const glm::vec3 bg(0.2f, 0.4f, 0.6f);
    const Framebuffer fb = draw(scene, unlit_settings(DebugView::None, bg));
    // src = factor * colour, a = 0.5 * 0.5; out = src a + dst (1 - a).
    const float a = 0.5f * 0.5f, keep = 1.0f - a;
    const glm::vec3 src(1.0f * 0.5f, 0.5f * 1.0f, 0.25f * 1.0f);
    const glm::vec4 p = pixel(fb, 11, 20);
    CHECK(bits(p.r) == bits(src.r * a + bg.r * keep));
    CHECK(bits(p.g) == bits(src.g * a + bg.g * keep));
    CHECK(bits(p.b) == bits(src.b * a + bg.b * keep));
    // Colour alpha 1 leaves the factor's alpha alone.
    scene.meshes[0].colors.assign(4, glm::vec4(0.5f, 1.0f, 1.0f, 1.0f));
    const glm::vec4 p1 = pixel(draw(scene, unlit_settings(DebugView::None, bg)), 11, 20);
    CHECK(bits(p1.r) == bits(src.r * 0.5f + bg.r * 0.5f));
}

TEST_CASE("TEXCOORD_1: a texture whose texcoord is 1 reads Mesh::uvs1") {
    Scene scene;
    const glm::vec4 red(1.0f, 0.0f, 0.0f, 1.0f), green(0.0f, 1.0f, 0.0f, 1.0f);
    scene.images.push_back(source(float_image(2, 1, {red, green})));
    Material m;
    m.base_color_factor = glm::vec4(1.0f);
    m.base_color.image = 0;
    m.base_color.mag_filter = Filter::Nearest;
    scene.materials.push_back(m);
    Mesh q = quad();
    q.uvs.assign(4, glm::vec2(0.25f, 0.5f));   // the red texel
    q.uvs1.assign(4, glm::vec2(0.75f, 0.5f));  // the green one
    scene.meshes.push_back(q);
    for (DebugView view : {DebugView::None, DebugView::Albedo}) {
        scene.materials[0].base_color.texcoord = 0;
        CHECK(pixel(draw(scene, unlit_settings(view)), 16, 16) == red);
        scene.materials[0].base_color.texcoord = 1;
        CHECK(pixel(draw(scene, unlit_settings(view)), 16, 16) == green);
    }
    // Each set with its own derivatives: uvs1 sweeps the 2 texels across
    // the quad while uvs stays put; with NEAREST both colours appear.
    scene.meshes[0].uvs1 = {{0.0f, 0.5f}, {1.0f, 0.5f}, {1.0f, 0.5f}, {0.0f, 0.5f}};
    const Framebuffer fb = draw(scene, unlit_settings());
    CHECK(pixel(fb, 2, 16) == red);
    CHECK(pixel(fb, kSize - 3, 16) == green);
    CHECK(same_bits(fb, draw(scene, unlit_settings(DebugView::Albedo))));
}

TEST_CASE("two textures of one image: one decoded storage, each its own wrap modes") {
    Scene scene;
    const glm::vec4 a(0.1f, 0.2f, 0.3f, 1.0f), b(0.4f, 0.5f, 0.6f, 1.0f), c(0.7f, 0.8f, 0.9f, 1.0f),
        d(0.9f, 0.1f, 0.5f, 1.0f);
    scene.images.push_back(source(float_image(4, 1, {a, b, c, d})));
    Material rep, clamp;
    rep.base_color_factor = clamp.base_color_factor = glm::vec4(1.0f);
    rep.base_color.image = clamp.base_color.image = 0;
    clamp.base_color.wrap_s = clamp.base_color.wrap_t = Wrap::ClampToEdge;
    scene.materials = {rep, clamp};
    // u = 1.125: Repeat reads texel 0 (u 0.125), ClampToEdge the last one.
    Mesh left = quad(-1.0f, 0.0f), right = quad(0.0f, 1.0f);
    left.uvs.assign(4, glm::vec2(1.125f, 0.5f));
    right.uvs.assign(4, glm::vec2(1.125f, 0.5f));
    right.material = 1;
    scene.meshes = {left, right};
    Renderer r({1, 64});
    SceneRenderer sr(scene, r);
    REQUIRE(sr.materials().size() == 2);
    const Texture* t0 = sr.materials()[0].base_color;
    const Texture* t1 = sr.materials()[1].base_color;
    REQUIRE(t0);
    REQUIRE(t1);
    CHECK(t0 != t1);
    CHECK(t0->shares_storage(*t1));
    CHECK(t0->wrap_s() == Wrap::Repeat);
    CHECK(t1->wrap_s() == Wrap::ClampToEdge);
    Framebuffer fb(kSize, kSize);
    sr.render(unlit_settings(), fb);
    CHECK(pixel(fb, 4, 16) == a);
    CHECK(pixel(fb, kSize - 4, 16) == d);
}

TEST_CASE("NEAREST magnification is exactly a texel; LINEAR blends") {
    Scene scene;
    const glm::vec4 t00(0.1f, 0.2f, 0.3f, 1.0f), t10(0.9f, 0.7f, 0.5f, 1.0f), t01(0.3f, 0.6f, 0.9f, 1.0f),
        t11(0.5f, 0.5f, 0.1f, 1.0f);
    scene.images.push_back(source(float_image(2, 2, {t00, t10, t01, t11})));
    Material m;
    m.base_color_factor = glm::vec4(1.0f);
    m.base_color.image = 0;
    m.base_color.mag_filter = Filter::Nearest;
    scene.materials.push_back(m);
    scene.meshes.push_back(quad());
    for (DebugView view : {DebugView::None, DebugView::Albedo}) {
        const Framebuffer fb = draw(scene, unlit_settings(view));
        int not_texel = 0;
        for (int y = 0; y < kSize; ++y)
            for (int x = 0; x < kSize; ++x) {
                const glm::vec4 p = pixel(fb, x, y);
                // Pixel centres at (x + 0.5) / 32: columns 0-15 are texel x 0.
                const glm::vec4 expect = y < kSize / 2 ? (x < kSize / 2 ? t00 : t10) : (x < kSize / 2 ? t01 : t11);
                not_texel += p != expect;
            }
        CHECK(not_texel == 0);
    }
    scene.materials[0].base_color.mag_filter = Filter::Linear;
    const Framebuffer fb = draw(scene, unlit_settings());
    int blended = 0;
    for (int y = 0; y < kSize; ++y)
        for (int x = 0; x < kSize; ++x) {
            const glm::vec4 p = pixel(fb, x, y);
            blended += p != t00 && p != t10 && p != t01 && p != t11;
        }
    CHECK(blended > kSize * kSize / 2);
    CHECK(same_bits(fb, draw(scene, unlit_settings(DebugView::Albedo))));
}

TEST_CASE("each minification filter against a hand computation") {
    // 4x4 texels, value 16 y + x in red: level 1 is the 2x2 box means, level 2 the mean.
    std::vector<glm::vec4> texels;
    for (int y = 0; y < 4; ++y)
        for (int x = 0; x < 4; ++x) texels.push_back({float(16 * y + x), 0.0f, 0.0f, 1.0f});
    const Texture base = Texture::from_image(*float_image(4, 4, texels), Wrap::Repeat, Wrap::Repeat);
    REQUIRE(base.levels() == 3);
    auto with = [&](Filter mag, MinFilter min) { return base.with_sampler({Wrap::Repeat, Wrap::Repeat, mag, min}); };
    // (u, v) inside texel (2, 1) of level 0, texel (1, 0) of level 1.
    const float u = 0.6f, v = 0.3f;
    const glm::vec4 near0 = base.texel(0, 2, 1), near1 = base.texel(1, 1, 0), near2 = base.texel(2, 0, 0);
    CHECK(near0.r == 18.0f);
    const glm::vec4 lin0 = base.sample_bilinear(u, v, 0), lin1 = base.sample_bilinear(u, v, 1);
    CHECK(lin0 != near0);

    // NEAREST / LINEAR: level 0 whatever lambda.
    CHECK(with(Filter::Linear, MinFilter::Nearest).sample_lod(u, v, 1.7f) == near0);
    CHECK(with(Filter::Linear, MinFilter::Linear).sample_lod(u, v, 1.7f) == lin0);
    // MIPMAP_NEAREST: level ceil(lambda + 1/2) - 1.
    CHECK(with(Filter::Nearest, MinFilter::NearestMipmapNearest).sample_lod(u, v, 0.5f) == near0);
    CHECK(with(Filter::Nearest, MinFilter::NearestMipmapNearest).sample_lod(u, v, 0.51f) == near1);
    CHECK(with(Filter::Nearest, MinFilter::NearestMipmapNearest).sample_lod(u, v, 1.5f) == near1);
    CHECK(with(Filter::Nearest, MinFilter::NearestMipmapNearest).sample_lod(u, v, 1.5001f) == near2);
    CHECK(with(Filter::Nearest, MinFilter::NearestMipmapNearest).sample_lod(u, v, 9.0f) == near2);
    CHECK(with(Filter::Linear, MinFilter::LinearMipmapNearest).sample_lod(u, v, 1.2f) == lin1);
    CHECK(with(Filter::Linear, MinFilter::LinearMipmapNearest).sample_lod(u, v, 0.3f) == lin0);
    // MIPMAP_LINEAR: levels floor(lambda) and + 1, blended by the fraction.
    const glm::vec4 nml = with(Filter::Nearest, MinFilter::NearestMipmapLinear).sample_lod(u, v, 0.25f);
    CHECK(nml == near0 + (near1 - near0) * 0.25f);
    const glm::vec4 lml = with(Filter::Linear, MinFilter::LinearMipmapLinear).sample_lod(u, v, 1.25f);
    CHECK(lml == lin1 + (base.sample_bilinear(u, v, 2) - lin1) * 0.25f);
    CHECK(lml == base.sample_trilinear(u, v, 1.25f));
    // Magnification (lambda <= c): the mag filter on level 0. c = 0.5 for
    // mag LINEAR with NEAREST_MIPMAP_NEAREST / NEAREST_MIPMAP_LINEAR.
    CHECK(with(Filter::Linear, MinFilter::NearestMipmapNearest).sample_lod(u, v, 0.5f) == lin0);
    CHECK(with(Filter::Linear, MinFilter::NearestMipmapNearest).sample_lod(u, v, 0.6f) == near1);
    CHECK(with(Filter::Linear, MinFilter::NearestMipmapLinear).sample_lod(u, v, 0.4f) == lin0);
    CHECK(with(Filter::Linear, MinFilter::LinearMipmapNearest).sample_lod(u, v, 0.4f) == lin0);  // c = 0: minified, level 0
    CHECK(with(Filter::Linear, MinFilter::Nearest).sample_lod(u, v, 0.01f) == near0);             // c = 0
    CHECK(with(Filter::Nearest, MinFilter::Linear).sample_lod(u, v, 0.0f) == near0);
    CHECK(with(Filter::Nearest, MinFilter::Linear).sample_lod(u, v, -3.0f) == near0);
    // Default filters: the same function as the trilinear sampler.
    CHECK(base.default_filters());
    CHECK(base.sample_lod(u, v, 0.7f) == base.sample_trilinear(u, v, 0.7f));
}

TEST_CASE("NEAREST texel indices follow floor(u w) under every wrap mode") {
    std::vector<glm::vec4> texels;
    for (int x = 0; x < 5; ++x) texels.push_back({float(x), 0.0f, 0.0f, 1.0f});
    const Texture base = Texture::from_image(*float_image(5, 1, texels), Wrap::Repeat, Wrap::Repeat);
    auto nearest = [&](Wrap w, float u) {
        return base.with_sampler({w, Wrap::Repeat, Filter::Nearest, MinFilter::Nearest}).sample_lod(u, 0.5f, 0.0f).r;
    };
    const float eps = 1e-9f;  // folds to 1 under Repeat: still texel 4 (floor(-eps * 5) = -1)
    CHECK(nearest(Wrap::Repeat, -eps) == 4.0f);
    CHECK(nearest(Wrap::Repeat, 0.0f) == 0.0f);
    CHECK(nearest(Wrap::Repeat, 1.0f) == 0.0f);
    CHECK(nearest(Wrap::Repeat, 1.39f) == 1.0f);
    CHECK(nearest(Wrap::Repeat, -0.1f) == 4.0f);
    CHECK(nearest(Wrap::ClampToEdge, 1.0f) == 4.0f);
    CHECK(nearest(Wrap::ClampToEdge, -2.0f) == 0.0f);
    CHECK(nearest(Wrap::MirroredRepeat, -eps) == 0.0f);
    CHECK(nearest(Wrap::MirroredRepeat, 1.0f) == 4.0f);   // mirrored: index 5 -> 4
    CHECK(nearest(Wrap::MirroredRepeat, 1.1f) == 4.0f);
    CHECK(nearest(Wrap::MirroredRepeat, 1.5f) == 2.0f);
    CHECK(nearest(Wrap::MirroredRepeat, -0.1f) == 0.0f);
    CHECK(nearest(Wrap::MirroredRepeat, -0.3f) == 1.0f);
}

TEST_CASE("meshes without colours or UV set 1 and default samplers bind the decoded texture itself") {
    Scene scene;
    scene.images.push_back(source(float_image(2, 2, {glm::vec4(0.2f), glm::vec4(0.4f), glm::vec4(0.6f), glm::vec4(0.8f)})));
    Material m;
    m.base_color.image = 0;
    m.emissive.image = 0;
    scene.materials.push_back(m);
    scene.meshes.push_back(quad());
    Renderer r({1, 64});
    SceneRenderer sr(scene, r);
    const BoundMaterial& bm = sr.materials()[0];
    REQUIRE(bm.base_color);
    CHECK(bm.base_color->default_filters());
    CHECK_FALSE(bm.reads_extra_uv_sets());
    CHECK_FALSE(needs_extended_varyings(scene.meshes[0], bm));
    scene.meshes[0].colors.assign(4, glm::vec4(1.0f));
    CHECK(needs_extended_varyings(scene.meshes[0], bm));
    // White vertex colours change no bit of the image.
    const Framebuffer coloured = draw(scene, unlit_settings());
    scene.meshes[0].colors.clear();
    CHECK(same_bits(coloured, draw(scene, unlit_settings())));
}

} // TEST_SUITE

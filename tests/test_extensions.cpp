// glTF extensions on small files the test writes (tests/gltf_writer.h), with
// pixels the specifications fix: KHR_texture_transform moving the texels of a
// NEAREST checker to the pixels its T R S matrix says (rotation included, and
// the level of detail through the matrix), KHR_materials_unlit giving the
// base colour term exactly, and KHR_lights_punctual spot cones and ranges
// against the extension's reference formulas; hostile numbers are warnings.
#include <doctest/doctest.h>

#include <cmath>
#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include "renderer/scene_renderer.h"
#include "scene/image.h"
#include "scene/load_scene.h"
#include "scene/write_image.h"
#include "shading/color.h"
#include "tests/cli_util.h"
#include "tests/gltf_writer.h"
#include "tests/scratch.h"
#include "tests/shading_test_util.h"

using namespace prast;
using prast::gltf_test::GltfWriter;
using prast::test::bits;
using json = nlohmann::json;

namespace {

constexpr int kSize = 32;
constexpr double kPi = 3.14159265358979323846;

// A quad x, y in [-1, 1] at z facing +z, UV (0, 0) at the top left and
// (1, 1) at the bottom right; `extra` attributes added.
int add_quad(GltfWriter& g, int material, float z = 0.0f, const json& extra = json::object(), float half = 1.0f) {
    const int pos = g.floats({-half, -half, z, half, -half, z, half, half, z, -half, half, z}, "VEC3", 3);
    json attrs = {{"POSITION", pos}, {"NORMAL", g.floats({0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1}, "VEC3", 3)},
                  {"TEXCOORD_0", g.floats({0, 1, 1, 1, 1, 0, 0, 0}, "VEC2", 2)}};
    for (auto it = extra.begin(); it != extra.end(); ++it) attrs[it.key()] = it.value();
    const int ind = g.u16({0, 1, 2, 0, 2, 3}, "SCALAR", 1);
    g.doc["meshes"].push_back({{"primitives", json::array({{{"attributes", attrs}, {"indices", ind}, {"material", material}}})}});
    return int(g.doc["meshes"].size()) - 1;
}


// One node per mesh, then light nodes: each {light index, translation}.
void finish_scene(GltfWriter& g, const std::vector<std::pair<int, glm::vec3>>& light_nodes = {}) {
    json roots = json::array();
    for (std::size_t m = 0; m < g.doc["meshes"].size(); ++m) {
        g.doc["nodes"].push_back({{"mesh", m}});
        roots.push_back(g.doc["nodes"].size() - 1);
    }
    for (const auto& [light, at] : light_nodes) {
        g.doc["nodes"].push_back({{"translation", {at.x, at.y, at.z}},
                                  {"extensions", {{"KHR_lights_punctual", {{"light", light}}}}}});
        roots.push_back(g.doc["nodes"].size() - 1);
    }
    g.doc["scenes"] = json::array({{{"nodes", roots}}});
    g.doc["scene"] = 0;
}

// The byte of texel k of the 4x4 checker, channel c: sixteen distinct colours.
std::uint8_t checker_byte(int k, int c) {
    const int r = 16 * k + 8;
    return std::uint8_t(c == 0 ? r : c == 1 ? 255 - r : c == 2 ? (k % 2) * 255 : 255);
}

std::vector<unsigned char> checker_png() {
    std::vector<std::uint8_t> rgba(4 * 4 * 4);
    for (int k = 0; k < 16; ++k)
        for (int c = 0; c < 4; ++c) rgba[std::size_t(k * 4 + c)] = checker_byte(k, c);
    return encode_png(4, 4, rgba.data());
}

// An n x n black and white checker of single texels.
std::vector<unsigned char> fine_checker_png(int n) {
    std::vector<std::uint8_t> rgba(std::size_t(n * n * 4));
    for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x)
            for (int c = 0; c < 4; ++c)
                rgba[std::size_t((y * n + x) * 4 + c)] = c == 3 || (x + y) % 2 ? 255 : 0;
    return encode_png(n, n, rgba.data());
}

FrameSettings settings(const Scene& scene, glm::vec3 ambient = glm::vec3(0.0f)) {
    FrameSettings fs;
    fs.camera.eye = {0.0f, 0.0f, 3.0f};
    fs.camera.target = {0.0f, 0.0f, 0.0f};
    fs.camera.orthographic = true;
    fs.camera.ortho_ymag = 1.0f;
    fs.ambient = ambient;
    fs.scene_environment = false;
    fs.background = Background::Color;
    fs.background_color = glm::vec3(0.0f);
    fs.lights = shading_lights(scene);
    return fs;
}

struct Frame {
    Framebuffer fb{kSize, kSize};
    std::vector<std::uint8_t> rgba8 = std::vector<std::uint8_t>(kSize * kSize * 4);
    glm::vec3 at(int x, int y) const {
        const float* p = &fb.color[(std::size_t(y) * kSize + std::size_t(x)) * 4];
        return {p[0], p[1], p[2]};
    }
};

Frame draw(const Scene& scene, const FrameSettings& fs, int threads = 1) {
    Renderer r({threads, 16});
    SceneRenderer sr(scene, r);
    Frame f;
    ImageOutput out;
    out.rgba8 = f.rgba8.data();
    out.tonemap = ToneMap::None;
    sr.render(fs, f.fb, &out);
    return f;
}

Scene load(const test::TempDir& dir, const GltfWriter& g, const std::string& name) {
    const std::string path = dir.file(name);
    test::write_text(path, g.text());
    return load_scene(path);
}

bool has_warning(const Scene& s, const std::string& part) {
    for (const std::string& w : s.warnings)
        if (w.find(part) != std::string::npos) return true;
    return false;
}

// The UV of pixel (i, j)'s centre on the quad.
glm::dvec2 pixel_uv(int i, int j) { return {(i + 0.5) / kSize, (j + 0.5) / kSize}; }

// The extension's T R S, R counter-clockwise in UV space (u right, v down):
// the matrix of its example (offset [0, 1], rotation pi/2, scale 0.5 reads
// the lower left quadrant) and of the TextureTransformTest sample model.
glm::dvec2 spec_transform(glm::dvec2 uv, glm::dvec2 offset, double rotation, glm::dvec2 scale) {
    const double c = std::cos(rotation), s = std::sin(rotation);
    const double su = uv.x * scale.x, sv = uv.y * scale.y;
    return {c * su + s * sv + offset.x, -s * su + c * sv + offset.y};
}

// The checker texel at uv, REPEAT; -1 within `margin` texels of an edge.
int checker_texel(glm::dvec2 uv, double margin = 0.02) {
    const double x = uv.x * 4.0, y = uv.y * 4.0;
    const double fx = x - std::floor(x), fy = y - std::floor(y);
    if (fx < margin || fx > 1.0 - margin || fy < margin || fy > 1.0 - margin) return -1;
    const int tx = ((int(std::floor(x)) % 4) + 4) % 4, ty = ((int(std::floor(y)) % 4) + 4) % 4;
    return ty * 4 + tx;
}

// What an 8-bit sRGB texture gives for byte b: its 15-bit code / 32640.
float srgb_code_value(int b) { return float(test::reference_code(b, true)) / 32640.0f; }

glm::vec3 texel_linear(int k) {
    return {srgb_code_value(checker_byte(k, 0)), srgb_code_value(checker_byte(k, 1)),
            srgb_code_value(checker_byte(k, 2))};
}

// An unlit quad with the checker as its base colour (NEAREST), the transform
// `xf` on its textureInfo (none when null).
GltfWriter checker_model(const json& xf) {
    GltfWriter g;
    const int img = g.image_png(checker_png());
    const int tex = g.texture(img, 9728, 9728);
    json info = {{"index", tex}};
    if (!xf.is_null()) info["extensions"] = {{"KHR_texture_transform", xf}};
    const int mat = add_material(g, {{"pbrMetallicRoughness", {{"baseColorTexture", info}}},
                                     {"extensions", {{"KHR_materials_unlit", json::object()}}}});
    add_quad(g, mat);
    finish_scene(g);
    g.doc["extensionsUsed"] = {"KHR_texture_transform", "KHR_materials_unlit"};
    return g;
}

// An 8-bit RGBA texture of random bytes (sRGB colour channels when `srgb`).
Texture random_texture(std::mt19937& rng, int w, int h, bool srgb) {
    std::uniform_int_distribution<int> byte(0, 255);
    Image img;
    img.width = w;
    img.height = h;
    img.channels = 4;
    img.srgb = srgb;
    img.pixels.resize(img.texel_count() * 4);
    for (std::uint8_t& c : img.pixels) c = std::uint8_t(byte(rng));
    return Texture::from_image(std::move(img), Wrap::Repeat, Wrap::MirroredRepeat);
}

} // namespace

TEST_SUITE("extensions") {

TEST_CASE("KHR_texture_transform: offset, rotation and scale move each checker texel to the pixels T R S names") {
    test::TempDir dir("extensions");
    struct Case {
        glm::dvec2 offset;
        double rotation;
        glm::dvec2 scale;
    };
    const Case cases[] = {
        {{0.25, 0.5}, 0.0, {1.0, 1.0}},      // offset
        {{0.0, 0.0}, 0.0, {2.0, 0.5}},       // scale
        {{0.0, 0.0}, 0.4, {1.0, 1.0}},       // rotation
        {{0.1, 0.3}, -1.1, {1.5, 0.75}},     // all three
        {{0.0, 1.0}, kPi / 2, {0.5, 0.5}},   // the extension's example: the lower left quadrant
    };
    int n = 0;
    for (const Case& c : cases) {
        INFO("case ", n);
        const GltfWriter g = checker_model({{"offset", {c.offset.x, c.offset.y}}, {"rotation", c.rotation},
                                            {"scale", {c.scale.x, c.scale.y}}});
        const Scene scene = load(dir, g, "tt" + std::to_string(n++) + ".gltf");
        CHECK(scene.warnings.empty());
        REQUIRE(scene.materials.size() == 1);
        CHECK(scene.materials[0].base_color.transform.present);
        const Frame f = draw(scene, settings(scene));
        int checked = 0, opposite_differs = 0;
        for (int j = 0; j < kSize; ++j)
            for (int i = 0; i < kSize; ++i) {
                const glm::dvec2 uv = pixel_uv(i, j);
                const int k = checker_texel(spec_transform(uv, c.offset, c.rotation, c.scale));
                if (k < 0) continue;
                ++checked;
                const int back = checker_texel(spec_transform(uv, c.offset, -c.rotation, c.scale), 0.0);
                opposite_differs += back != k;
                const glm::vec3 want = texel_linear(k), got = f.at(i, j);
                INFO("pixel ", i, ", ", j, " texel ", k);
                CHECK(bits(got.r) == bits(want.r));
                CHECK(bits(got.g) == bits(want.g));
                CHECK(bits(got.b) == bits(want.b));
            }
        CHECK(checked > kSize * kSize / 2);
        // A rotation turned the other way would show other texels: the test tells the two apart.
        if (c.rotation != 0.0) CHECK(opposite_differs > checked / 4);
    }
    // The example reads the lower left quadrant only: texels with x < 2 and y >= 2.
    const GltfWriter g = checker_model({{"offset", {0, 1}}, {"rotation", kPi / 2}, {"scale", {0.5, 0.5}}});
    const Scene scene = load(dir, g, "example.gltf");
    const Frame f = draw(scene, settings(scene));
    for (int j = 0; j < kSize; ++j)
        for (int i = 0; i < kSize; ++i) {
            bool lower_left = false;
            for (int k = 0; k < 16; ++k)
                if (k % 4 < 2 && k / 4 >= 2 && f.at(i, j) == texel_linear(k)) lower_left = true;
            CHECK(lower_left);
        }
}

TEST_CASE("KHR_texture_transform: the texCoord override picks the UV set; an identity transform is none") {
    test::TempDir dir("extensions");
    // TEXCOORD_1 mirrors u: the texel of (1 - u, v).
    GltfWriter g;
    const int img = g.image_png(checker_png());
    const int tex = g.texture(img, 9728, 9728);
    const int set1 = g.floats({1, 1, 0, 1, 0, 0, 1, 0}, "VEC2", 2);
    const int mat = add_material(
        g, {{"pbrMetallicRoughness",
             {{"baseColorTexture", {{"index", tex}, {"extensions", {{"KHR_texture_transform", {{"texCoord", 1}}}}}}}}},
            {"extensions", {{"KHR_materials_unlit", json::object()}}}});
    add_quad(g, mat, 0.0f, {{"TEXCOORD_1", set1}});
    finish_scene(g);
    const Scene scene = load(dir, g, "override.gltf");
    CHECK(scene.warnings.empty());
    CHECK(scene.materials[0].base_color.texcoord == 1);
    CHECK(!scene.materials[0].base_color.transform.present);
    const Frame f = draw(scene, settings(scene));
    for (int j = 0; j < kSize; ++j)
        for (int i = 0; i < kSize; ++i) {
            const glm::dvec2 uv = pixel_uv(i, j);
            const int k = checker_texel({1.0 - uv.x, uv.y});
            if (k < 0) continue;
            CHECK(f.at(i, j) == texel_linear(k));
        }
}

TEST_CASE("KHR_texture_transform: the level of detail follows the scale (the derivatives through the matrix)") {
    test::TempDir dir("extensions");
    // An 8x8 single-texel checker repeated 8 times over 32 pixels: two texels
    // a pixel, lambda = 1, level 1 -- the exact mean, the same everywhere.
    // Without the derivatives scaled it would be magnified: black and white.
    for (const bool scaled : {true, false}) {
        GltfWriter g;
        const int img = g.image_png(fine_checker_png(8));
        g.doc["textures"] = json::array({{{"source", img}}});
        json info = {{"index", 0}};
        if (scaled) info["extensions"] = {{"KHR_texture_transform", {{"scale", {8, 8}}}}};
        const int mat = add_material(g, {{"pbrMetallicRoughness", {{"baseColorTexture", info}}},
                                         {"extensions", {{"KHR_materials_unlit", json::object()}}}});
        add_quad(g, mat);
        finish_scene(g);
        const Scene scene = load(dir, g, scaled ? "lod.gltf" : "plain.gltf");
        const Frame f = draw(scene, settings(scene));
        float lo = 1e9f, hi = -1e9f;
        for (int j = 0; j < kSize; ++j)
            for (int i = 0; i < kSize; ++i) {
                lo = std::min(lo, f.at(i, j).r);
                hi = std::max(hi, f.at(i, j).r);
            }
        if (scaled) {
            CHECK(lo == hi);
            CHECK(lo > 0.3f);
            CHECK(lo < 0.7f);
        } else {
            CHECK(hi - lo > 0.5f);
        }
    }
}

TEST_CASE("KHR_materials_unlit: the pixel is the base colour term, sRGB-encoded exactly; lights, ambient and emissive aside") {
    test::TempDir dir("extensions");
    GltfWriter g;
    const glm::vec4 factor(0.2f, 0.5f, 0.8f, 1.0f);
    const int mat = add_material(g, {{"pbrMetallicRoughness", {{"baseColorFactor", {0.2, 0.5, 0.8, 1.0}}}},
                                     {"emissiveFactor", {1, 1, 1}},
                                     {"extensions", {{"KHR_materials_unlit", json::object()}}}});
    const int colored = add_material(g, {{"pbrMetallicRoughness", {{"baseColorFactor", {0.2, 0.5, 0.8, 1.0}}}},
                                         {"extensions", {{"KHR_materials_unlit", json::object()}}}});
    add_quad(g, mat, 0.0f, json::object(), 0.5f);
    const int colours = g.floats({0.5f, 0.25f, 1.0f, 1.0f, 0.5f, 0.25f, 1.0f, 1.0f, 0.5f, 0.25f, 1.0f, 1.0f,
                                  0.5f, 0.25f, 1.0f, 1.0f}, "VEC4", 4);
    add_quad(g, colored, -0.5f, {{"COLOR_0", colours}});
    g.doc["extensions"] = {{"KHR_lights_punctual", {{"lights", json::array({{{"type", "directional"}, {"intensity", 5}}})}}}};
    finish_scene(g, {{0, glm::vec3(0.0f)}});
    g.doc["extensionsUsed"] = {"KHR_materials_unlit", "KHR_lights_punctual"};
    g.doc["extensionsRequired"] = {"KHR_materials_unlit"};
    const Scene scene = load(dir, g, "unlit.gltf");
    CHECK(scene.warnings.empty());
    REQUIRE(scene.lights.size() == 1);
    CHECK(scene.materials[0].unlit);
    FrameSettings fs = settings(scene, glm::vec3(0.5f));
    fs.shadows.enabled = true;
    for (int threads : {1, 2}) {
        const Frame f = draw(scene, fs, threads);
        // Inside the small quad (x, y in [-0.5, 0.5]): the factor.
        for (int j = 10; j < 22; ++j)
            for (int i = 10; i < 22; ++i) {
                CHECK(f.at(i, j) == glm::vec3(factor));
                for (int c = 0; c < 3; ++c)
                    CHECK(int(f.rgba8[std::size_t((j * kSize + i) * 4 + c)]) == int(linear_to_srgb8(factor[c])));
            }
        // Outside it, the vertex-coloured quad behind: factor x colour.
        CHECK(f.at(2, 2) == glm::vec3(factor) * glm::vec3(0.5f, 0.25f, 1.0f));
    }
    // The albedo view shows the same colour (the scalar path agrees with the lanes).
    fs.view = DebugView::Albedo;
    CHECK(draw(scene, fs).at(16, 16) == glm::vec3(factor));
}

TEST_CASE("KHR_materials_unlit: an unlit quad still casts its shadow on a lit floor") {
    test::TempDir dir("extensions");
    for (const bool occluder : {true, false}) {
        GltfWriter g;
        const int floor = add_material(g, {{"pbrMetallicRoughness", {{"metallicFactor", 0}, {"roughnessFactor", 1}}}});
        const int unlit = add_material(g, {{"extensions", {{"KHR_materials_unlit", json::object()}}}});
        add_quad(g, floor);
        if (occluder) add_quad(g, unlit, 0.5f, json::object(), 0.25f);
        // A sun towards (1, 0, 1): the shadow falls 0.5 to the -x side, around x = -0.5.
        json light = {{"type", "directional"}, {"intensity", 3}};
        g.doc["extensions"] = {{"KHR_lights_punctual", {{"lights", json::array({light})}}}};
        finish_scene(g);
        const double a = kPi / 4;  // -Z turned about +y by 45 degrees: shines along (-1, 0, -1) / sqrt 2
        g.doc["nodes"].push_back({{"rotation", {0.0, std::sin(a / 2), 0.0, std::cos(a / 2)}},
                                  {"extensions", {{"KHR_lights_punctual", {{"light", 0}}}}}});
        g.doc["scenes"][0]["nodes"].push_back(g.doc["nodes"].size() - 1);
        const Scene scene = load(dir, g, occluder ? "shadow.gltf" : "open.gltf");
        REQUIRE(scene.lights.size() == 1);
        FrameSettings fs = settings(scene);
        fs.shadows.enabled = true;
        const Frame f = draw(scene, fs);
        const glm::vec3 shadowed = f.at(8, 16);  // x = -0.47, y = -0.03
        if (occluder) CHECK(shadowed == glm::vec3(0.0f));
        else CHECK(shadowed.r > 0.1f);
    }
}

TEST_CASE("KHR_lights_punctual spot: the point light's value inside the inner cone, 0 outside the outer, the smooth falloff between") {
    test::TempDir dir("extensions");
    const double inner = 0.2, outer = 0.4, height = 2.0;
    auto model = [&](const char* type, double range) {
        GltfWriter g;
        const int mat = add_material(g, {{"pbrMetallicRoughness", {{"metallicFactor", 0}, {"roughnessFactor", 1}}}});
        add_quad(g, mat);
        json light = {{"type", type}, {"intensity", 8}, {"color", {1.0, 0.9, 0.8}}};
        if (std::string(type) == "spot") light["spot"] = {{"innerConeAngle", inner}, {"outerConeAngle", outer}};
        if (range > 0) light["range"] = range;
        g.doc["extensions"] = {{"KHR_lights_punctual", {{"lights", json::array({light})}}}};
        finish_scene(g, {{0, glm::vec3(0.0f, 0.0f, float(height))}});
        return g;
    };
    const Scene spot = load(dir, model("spot", 0), "spot.gltf");
    const Scene point = load(dir, model("point", 0), "point.gltf");
    CHECK(spot.warnings.empty());
    REQUIRE(spot.lights.size() == 1);
    CHECK(spot.lights[0].type == Light::Type::Spot);
    const Frame fs = draw(spot, settings(spot)), fp = draw(point, settings(point));
    int inside = 0, between = 0, outside = 0;
    for (int j = 0; j < kSize; ++j)
        for (int i = 0; i < kSize; ++i) {
            const double x = -1.0 + (i + 0.5) * 2.0 / kSize, y = 1.0 - (j + 0.5) * 2.0 / kSize;
            const double theta = std::atan2(std::sqrt(x * x + y * y), height);
            const glm::vec3 s = fs.at(i, j), p = fp.at(i, j);
            INFO("pixel ", i, ", ", j, " angle ", theta);
            if (theta < inner - 1e-3) {
                ++inside;
                CHECK(bits(s.r) == bits(p.r));
                CHECK(bits(s.g) == bits(p.g));
                CHECK(bits(s.b) == bits(p.b));
            } else if (theta > outer + 1e-3) {
                ++outside;
                CHECK(s == glm::vec3(0.0f));
            } else if (theta > inner + 1e-3 && theta < outer - 1e-3) {
                ++between;
                const double a = (std::cos(theta) - std::cos(outer)) / (std::cos(inner) - std::cos(outer));
                REQUIRE(p.g > 0.0f);
                CHECK(std::fabs(double(s.g) / double(p.g) - a * a) <= 1e-5);
                CHECK(std::fabs(double(s.r) / double(p.r) - a * a) <= 1e-5);
            }
        }
    CHECK(inside > 20);
    CHECK(between > 50);
    CHECK(outside > 100);

    // range: 0 beyond it, the window 1 - (d / range)^4 within it.
    const double range = 2.2;
    const Scene ranged = load(dir, model("point", range), "range.gltf");
    CHECK(ranged.warnings.empty());
    CHECK(ranged.lights[0].range == float(range));
    const Frame fr = draw(ranged, settings(ranged));
    int beyond = 0, within = 0;
    for (int j = 0; j < kSize; ++j)
        for (int i = 0; i < kSize; ++i) {
            const double x = -1.0 + (i + 0.5) * 2.0 / kSize, y = 1.0 - (j + 0.5) * 2.0 / kSize;
            const double d = std::sqrt(x * x + y * y + height * height);
            const glm::vec3 r = fr.at(i, j), p = fp.at(i, j);
            if (d > range + 1e-3) {
                ++beyond;
                CHECK(r == glm::vec3(0.0f));
            } else if (d < range - 1e-3) {
                ++within;
                CHECK(std::fabs(double(r.g) / double(p.g) - (1.0 - std::pow(d / range, 4.0))) <= 1e-5);
            }
        }
    CHECK(beyond > 50);
    CHECK(within > 200);
}

TEST_CASE("--file-lights off: the flags' lights (or the default rig) replace the file's, through render") {
    cli_test::CliSandbox box;
    auto model = [&](bool with_light) {
        GltfWriter g;
        const int mat = add_material(g, {{"pbrMetallicRoughness", {{"metallicFactor", 0}, {"roughnessFactor", 0.6}}}});
        add_quad(g, mat);
        if (with_light) {
            json light = {{"type", "spot"}, {"intensity", 30}, {"color", {1.0, 0.2, 0.1}},
                          {"spot", {{"innerConeAngle", 0.1}, {"outerConeAngle", 0.3}}}};
            g.doc["extensions"] = {{"KHR_lights_punctual", {{"lights", json::array({light})}}}};
            g.doc["extensionsUsed"] = {"KHR_lights_punctual"};
        }
        finish_scene(g, with_light ? std::vector<std::pair<int, glm::vec3>>{{0, glm::vec3(0.3f, 0.0f, 2.0f)}}
                                   : std::vector<std::pair<int, glm::vec3>>{});
        return g.text();
    };
    cli_test::write_text(box.path("lit.gltf"), model(true));
    cli_test::write_text(box.path("plain.gltf"), model(false));
    const std::vector<std::string> view = {"--size", "48x48", "--eye", "0,0,3", "--target", "0,0,0"};
    auto render = [&](const std::string& file, std::vector<std::string> flags, const std::string& out) {
        std::vector<std::string> args = {file, "-o", out};
        args.insert(args.end(), view.begin(), view.end());
        args.insert(args.end(), flags.begin(), flags.end());
        const cli_test::CliRun r = box.run_exe(PRAST_RENDER_EXE, args);
        INFO(file, " ", out, ": ", r.err);
        REQUIRE(r.code == 0);
        return cli_test::read_bytes(box.path(out));
    };
    const std::vector<std::string> sun = {"--sun", "0.2,0.3,1:1,1,1"};
    std::vector<std::string> off_sun = {"--file-lights", "off"};
    off_sun.insert(off_sun.end(), sun.begin(), sun.end());
    // Off with a sun: exactly the file without its light, lit by that sun.
    CHECK(render("lit.gltf", off_sun, "a.png") == render("plain.gltf", sun, "b.png"));
    // Off alone: the file has no light left, so the key and fill rig, as for the plain file.
    CHECK(render("lit.gltf", {"--file-lights", "off"}, "c.png") == render("plain.gltf", {}, "d.png"));
    // On (the default): the spot and the sun together, not the sun alone.
    const auto both = render("lit.gltf", sun, "e.png");
    CHECK(both == render("lit.gltf", {"--file-lights", "on", "--sun", "0.2,0.3,1:1,1,1"}, "f.png"));
    CHECK(both != render("plain.gltf", sun, "g.png"));
    const cli_test::CliRun bad = box.run_exe(PRAST_RENDER_EXE, {"lit.gltf", "--file-lights", "maybe"});
    CHECK(bad.code == 2);
    CHECK(bad.err.find("--file-lights") != std::string::npos);
}

TEST_CASE("hostile extension values: NaN-like and huge numbers, cones out of order or past pi/2, negative ranges are warnings") {
    test::TempDir dir("extensions");
    GltfWriter g;
    const int img = g.image_png(checker_png());
    const int tex = g.texture(img, 9728, 9728);
    auto info = [&](const json& xf) { return json{{"index", tex}, {"extensions", {{"KHR_texture_transform", xf}}}}; };
    const int mat = add_material(
        g, {{"pbrMetallicRoughness", {{"baseColorTexture", info({{"offset", {1e39, 0}}, {"rotation", "x"}})},
                                      {"metallicRoughnessTexture", info({{"scale", {1e30, -1e30}}, {"texCoord", 7}})}}},
            {"normalTexture", info({{"offset", {0.5}}, {"scale", "big"}})},
            {"emissiveTexture", info({{"scale", {1, 2, 3}}, {"rotation", 1e39}})},
            {"emissiveFactor", {1, 1, 1}}});
    add_quad(g, mat);
    const json lights = json::array({
        {{"type", "spot"}, {"spot", {{"innerConeAngle", 1.0}, {"outerConeAngle", 0.5}}}},
        {{"type", "spot"}, {"spot", {{"innerConeAngle", 0.1}, {"outerConeAngle", 3.0}}}},
        {{"type", "spot"}, {"spot", {{"innerConeAngle", -1.0}, {"outerConeAngle", -2.0}}}, {"range", -1.0}},
        {{"type", "point"}, {"range", -5.0}},
        {{"type", "directional"}, {"range", 3.0}},
    });
    g.doc["extensions"] = {{"KHR_lights_punctual", {{"lights", lights}}}};
    finish_scene(g, {{0, {0, 0, 2}}, {1, {0, 0, 2}}, {2, {0, 0, 2}}, {3, {0, 0, 2}}, {4, {0, 0, 2}}});
    g.doc["extensionsUsed"] = {"KHR_texture_transform", "KHR_lights_punctual"};
    g.doc["extensionsRequired"] = {"KHR_texture_transform", "KHR_lights_punctual"};
    const Scene scene = load(dir, g, "hostile.gltf");
    for (const char* w : {"baseColorTexture KHR_texture_transform: bad offset", "bad rotation",
                          "texCoord override not 0 or 1", "normalTexture KHR_texture_transform: bad offset",
                          "bad scale", "emissiveTexture KHR_texture_transform: bad scale",
                          "innerConeAngle not in [0, outerConeAngle)", "outerConeAngle above pi/2",
                          "outerConeAngle not above 0", "range is not a positive number", "range of directional light"}) {
        INFO(std::string(w));
        CHECK(has_warning(scene, w));
    }
    for (const std::string& w : scene.warnings) CHECK(w.find('\n') == std::string::npos);
    REQUIRE(scene.lights.size() == 5);
    CHECK(scene.lights[0].inner_cone == 0.0f);
    CHECK(scene.lights[0].outer_cone == 0.5f);
    CHECK(scene.lights[1].outer_cone == float(kPi / 2));
    CHECK(scene.lights[2].range == 0.0f);
    const Material& m = scene.materials[0];
    CHECK(m.base_color.transform.offset == glm::vec2(0.0f));
    CHECK(m.metallic_roughness.transform.scale == glm::vec2(1e30f, -1e30f));
    CHECK(m.metallic_roughness.texcoord == 0);
    // Drawn without a crash, every pixel finite, on 1 and 2 threads alike.
    FrameSettings fs = settings(scene, glm::vec3(0.1f));
    fs.shadows.enabled = true;
    const Frame a = draw(scene, fs, 1), b = draw(scene, fs, 2);
    for (float v : a.fb.color) CHECK(std::isfinite(v));
    CHECK(a.fb.color == b.fb.color);

    // A literal NaN is no JSON: a one-line load error, never a crash.
    const std::string path = dir.file("nan.gltf");
    std::string text = checker_model({{"offset", {0.5, 0.5}}}).text();
    const std::size_t at = text.find("0.5");
    REQUIRE(at != std::string::npos);
    text.replace(at, 3, "NaN");
    test::write_text(path, text);
    try {
        const Scene s = load_scene(path);
        CHECK(s.materials.size() >= 1);
    } catch (const LoadError& e) {
        CHECK(std::string(e.what()).find('\n') == std::string::npos);
    }
}

TEST_CASE("texture transforms and spot lights: the same bytes on 1, 2 and 3 threads") {
    test::TempDir dir("extensions");
    GltfWriter g;
    const int img = g.image_png(fine_checker_png(8));
    g.doc["textures"] = json::array({{{"source", img}}});
    const json xf = {{"KHR_texture_transform", {{"offset", {0.3, 0.1}}, {"rotation", 0.7}, {"scale", {3, 2}}}}};
    const int mat = add_material(g, {{"pbrMetallicRoughness", {{"baseColorTexture", {{"index", 0}, {"extensions", xf}}},
                                                               {"metallicRoughnessTexture", {{"index", 0}}}}},
                                     {"normalTexture", {{"index", 0}, {"extensions", xf}}}});
    add_quad(g, mat);
    json light = {{"type", "spot"}, {"intensity", 8}, {"range", 2.6}, {"spot", {{"outerConeAngle", 0.5}}}};
    g.doc["extensions"] = {{"KHR_lights_punctual", {{"lights", json::array({light})}}}};
    finish_scene(g, {{0, {0.2f, 0.1f, 2.0f}}});
    const Scene scene = load(dir, g, "threads.gltf");
    CHECK(scene.warnings.empty());
    FrameSettings fs = settings(scene, glm::vec3(0.05f));
    fs.shadows.enabled = true;
    const Frame one = draw(scene, fs, 1);
    CHECK(one.fb.color == draw(scene, fs, 2).fb.color);
    CHECK(one.fb.color == draw(scene, fs, 3).fb.color);
}

TEST_CASE("texture transforms and spot lights: the lit lanes equal sample_material() and shade_surface() bit for bit") {
    std::mt19937 rng(11);
    std::uniform_real_distribution<float> uni(0.0f, 1.0f), sym(-1.0f, 1.0f);
    std::uniform_int_distribution<int> count(1, 16), coin(0, 1);
    for (int round = 0; round < 300; ++round) {
        Texture albedo = random_texture(rng, 32, 32, true), normal = random_texture(rng, 32, 32, false);
        Texture orm = random_texture(rng, 16, 64, false);
        Material m;
        m.base_color_factor = {uni(rng), uni(rng), uni(rng), 1.0f};
        m.metallic_factor = uni(rng);
        m.roughness_factor = uni(rng);
        m.emissive_factor = {uni(rng), 0.0f, uni(rng)};
        m.unlit = round % 7 == 0;
        BoundMaterial bm;
        bm.m = &m;
        bm.base_color = &albedo;
        bm.normal = &normal;
        bm.metallic_roughness = &orm;
        bm.occlusion = &orm;  // one texture twice: with its own transform or the same one
        bm.emissive = &albedo;
        for (int map : {int(BoundMaterial::kBaseColor), int(BoundMaterial::kNormal), int(BoundMaterial::kMetalRough),
                        int(BoundMaterial::kOcclusion), int(BoundMaterial::kEmissive)}) {
            if (coin(rng)) continue;
            TextureTransform t;
            t.present = true;
            t.offset = {sym(rng), sym(rng)};
            t.rotation = 3.0f * sym(rng);
            t.scale = {0.2f + 4.0f * uni(rng), sym(rng) * 3.0f};
            bm.transformed = std::uint8_t(bm.transformed | (1u << map));
            bm.xf[map] = UvTransform::of(t);
        }
        if (coin(rng)) bm.xf[BoundMaterial::kEmissive] = bm.xf[BoundMaterial::kBaseColor];  // equal transforms share
        ShadingContext ctx;
        ctx.eye = {sym(rng), 2.0f, 5.0f};
        ctx.ambient = {0.1f, 0.1f, 0.1f};
        test::add_test_lights(ctx, rng);
        ShadingLight spot;
        spot.point = spot.spot = true;
        spot.position = {0.0f, 0.0f, 2.0f};
        spot.direction = {0.0f, 0.0f, 1.0f};
        spot.radiance = {9.0f, 9.0f, 9.0f};
        spot_cone(0.1f, 0.6f, spot.cone_scale, spot.cone_offset);
        spot.range_inv2 = coin(rng) ? 1.0f / 6.0f : 0.0f;
        ctx.lights.push_back(spot);
        PbrProgram prog;
        prog.material = &bm;
        prog.ctx = &ctx;

        FragmentBlock<kPbrVaryings> in;
        const float scale = 0.2f + 20.0f * uni(rng);
        for (int l = 0; l < kBlockLanes; ++l) {
            for (int k = 0; k < kPbrVaryings; ++k) in.var[k][l] = sym(rng);
            in.var[kVarN + 2][l] = 1.0f;
            in.var[kVarUV][l] = 0.3f + scale * 0.02f * float(lane_x(l)) + 0.001f * sym(rng);
            in.var[kVarUV + 1][l] = 0.6f + scale * 0.03f * float(lane_y(l)) + 0.001f * sym(rng);
            in.z[l] = uni(rng);
        }
        const int live = count(rng);
        in.mask = 0;
        for (int i = 0; in.mask == 0 || __builtin_popcount(in.mask) < live; ++i) in.mask |= 1u << (rng() % 16);
        in.front_facing = coin(rng);
        FragmentOut out;
        prog.fragment(in, out);
        MaterialLods lods;
        for (int l = 0; l < kBlockLanes; ++l) {
            if (!((in.mask >> l) & 1u)) continue;
            const SurfacePoint sp = PbrProgram::surface_point(in, l);
            lods = material_lods(bm, sp);
            const MaterialSample ms = sample_material(bm, sp, lods);
            const glm::vec3 ref = shade_surface(ms, sp, ctx);
            INFO("round ", round, " lane ", l);
            CHECK(bits(out.r[l]) == bits(ref.r));
            CHECK(bits(out.g[l]) == bits(ref.g));
            CHECK(bits(out.b[l]) == bits(ref.b));
        }
    }
}

}

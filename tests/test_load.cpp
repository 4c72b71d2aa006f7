// Scene loading: OBJ + MTL and glTF 2.0 (.gltf with a data-URI buffer, .glb)
// written by hand into a scratch directory, the real assets of ../shared/assets
// when present, hostile files, and fuzzed copies that must load or throw
// LoadError, never crash or hang.
#include <doctest/doctest.h>

#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <random>
#include <string>
#include <tuple>
#include <vector>

#include <stb_image_write.h>

#include "tests/gltf_writer.h"
#include "tests/scratch.h"

#include "scene/load_scene.h"
#include "scene/tangents.h"
#include "tests/load_error.h"

namespace fs = std::filesystem;
using namespace prast;
using prast::test::load_error;
using prast::test::TempDir;
using prast::test::read_bytes;
using prast::test::write_bytes;
using prast::test::write_text;

namespace {

// ---- Scratch files

// A 2x2 RGB PNG, in memory.
std::vector<unsigned char> tiny_png() {
    const unsigned char rgb[12] = {255, 0, 0, 0, 255, 0, 0, 0, 255, 255, 255, 255};
    std::vector<unsigned char> out;
    stbi_write_png_to_func(
        [](void* ctx, void* data, int size) {
            auto* v = static_cast<std::vector<unsigned char>*>(ctx);
            v->insert(v->end(), static_cast<unsigned char*>(data), static_cast<unsigned char*>(data) + size);
        },
        &out, 2, 2, 3, rgb, 6);
    return out;
}

void replace_once(std::string& s, const std::string& from, const std::string& to) {
    const std::size_t at = s.find(from);
    REQUIRE_MESSAGE(at != std::string::npos, "test JSON lacks: " << from);
    s.replace(at, from.size(), to);
}

bool contains(const std::string& s, const std::string& part) { return s.find(part) != std::string::npos; }

bool any_warning(const Scene& s, const std::string& part) {
    for (const std::string& w : s.warnings)
        if (contains(w, part)) return true;
    return false;
}

// A failure must be one line naming the file.
void check_load_error(const std::string& path, const std::string& must_contain = "") {
    const std::string msg = load_error(path);
    INFO("file: " << path << "  message: " << msg);
    CHECK(!msg.empty());
    CHECK(contains(msg, fs::path(path).filename().string()));
    CHECK(!contains(msg, "\n"));
    if (!must_contain.empty()) CHECK(contains(msg, must_contain));
}

bool finite(const glm::vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

// Invariants every loaded scene must satisfy, whatever the file.
void check_sane(const Scene& scene) {
    REQUIRE(!scene.meshes.empty());
    REQUIRE(!scene.materials.empty());
    std::size_t bad_index = 0, bad_position = 0, bad_normal = 0, bad_uv = 0, bad_tangent = 0, bad_image = 0;
    for (const Mesh& m : scene.meshes) {
        const std::size_t n = m.positions.size();
        const bool triangles = m.topology == Mesh::Topology::Triangles;
        const std::size_t corners = triangles ? 3 : m.topology == Mesh::Topology::Lines ? 2 : 1;
        // Lines and points may come without normals (drawn unlit), and then without tangents.
        REQUIRE((m.normals.size() == n || (!triangles && m.normals.empty())));
        REQUIRE((m.uvs.empty() || m.uvs.size() == n));
        REQUIRE((m.uvs1.empty() || m.uvs1.size() == n));
        REQUIRE((m.colors.empty() || m.colors.size() == n));
        REQUIRE((m.tangents.empty() || m.tangents.size() == n));
        if (!m.uvs.empty() && !m.normals.empty()) REQUIRE(m.tangents.size() == n);
        if (m.uvs.empty() && m.uvs1.empty()) REQUIRE(m.tangents.empty());
        REQUIRE(!m.indices.empty());
        REQUIRE(m.indices.size() % corners == 0);
        REQUIRE(m.material >= 0);
        REQUIRE(std::size_t(m.material) < scene.materials.size());
        for (std::uint32_t i : m.indices) bad_index += i >= n;
        for (std::size_t i = 0; i < n; ++i) {
            bad_position += !finite(m.positions[i]);
            if (!m.normals.empty())
                bad_normal += !finite(m.normals[i]) || std::abs(glm::length(m.normals[i]) - 1.0f) > 1e-3f;
            if (!m.uvs.empty()) bad_uv += !std::isfinite(m.uvs[i].x) || !std::isfinite(m.uvs[i].y);
            if (!m.colors.empty())
                bad_uv += !(glm::all(glm::greaterThanEqual(m.colors[i], glm::vec4(0.0f))) &&
                            glm::all(glm::lessThanEqual(m.colors[i], glm::vec4(1.0f))));
            if (!m.tangents.empty()) {
                const glm::vec3 t(m.tangents[i]);
                bad_tangent += !finite(t) || std::abs(glm::length(t) - 1.0f) > 1e-3f ||
                               std::abs(glm::dot(t, m.normals[i])) > 1e-3f ||
                               std::abs(m.tangents[i].w) != 1.0f;
            }
        }
    }
    for (const Material& mat : scene.materials)
        for (const TextureRef* t : {&mat.base_color, &mat.metallic_roughness, &mat.roughness, &mat.metallic,
                                    &mat.normal, &mat.occlusion, &mat.emissive})
            bad_image += t->image >= int(scene.images.size());
    CHECK(bad_index == 0);
    CHECK(bad_position == 0);
    CHECK(bad_normal == 0);
    CHECK(bad_uv == 0);
    CHECK(bad_tangent == 0);
    CHECK(bad_image == 0);
}

// ---- The small glTF used by several tests

// Quad (0,0,0)-(1,1,0) facing +Z, glTF UVs (v = 0 at the top edge y = 1),
// tangents +X; indices 0 1 2, 0 2 3 (u16). Layout: positions 0..47, normals
// 48..95, uvs 96..127, tangents 128..191, indices 192..203.
std::vector<unsigned char> quad_buffer() {
    std::vector<unsigned char> b;
    auto f = [&](float v) {
        unsigned char p[4];
        std::memcpy(p, &v, 4);
        b.insert(b.end(), p, p + 4);
    };
    const float pos[12] = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0};
    for (float v : pos) f(v);
    for (int i = 0; i < 4; ++i) { f(0); f(0); f(1); }
    const float uv[8] = {0, 1, 1, 1, 1, 0, 0, 0};
    for (float v : uv) f(v);
    for (int i = 0; i < 4; ++i) { f(1); f(0); f(0); f(1); }
    const std::uint16_t idx[6] = {0, 1, 2, 0, 2, 3};
    for (std::uint16_t i : idx) {
        b.push_back(std::uint8_t(i & 0xff));
        b.push_back(std::uint8_t(i >> 8));
    }
    return b;
}

// BUFFER is replaced by the buffer's "uri" member (or nothing, for .glb),
// IMAGE by the image's source.
const char* kQuadGltf = R"({
  "asset": {"version": "2.0"},
  "scene": 0,
  "scenes": [{"nodes": [0]}],
  "nodes": [
    {"name": "parent", "translation": [10, 0, 0], "children": [1, 2, 3]},
    {"name": "quad", "mesh": 0, "translation": [1, 2, 3],
     "rotation": [0, 0.70710678, 0, 0.70710678], "scale": [2, 2, 2]},
    {"name": "sun", "rotation": [-0.70710678, 0, 0, 0.70710678],
     "extensions": {"KHR_lights_punctual": {"light": 0}}},
    {"name": "lamp", "translation": [0, 5, 0], "extensions": {"KHR_lights_punctual": {"light": 1}}}
  ],
  "extensionsUsed": ["KHR_lights_punctual", "KHR_materials_emissive_strength"],
  "extensions": {"KHR_lights_punctual": {"lights": [
    {"type": "directional", "color": [1, 0.9, 0.8], "intensity": 3},
    {"type": "spot", "intensity": 20, "spot": {}}
  ]}},
  "meshes": [{"name": "quad", "primitives": [{
    "attributes": {"POSITION": 0, "NORMAL": 1, "TEXCOORD_0": 2, "TANGENT": 3},
    "indices": 4, "material": 0}]}],
  "materials": [{
    "name": "mat",
    "pbrMetallicRoughness": {"baseColorFactor": [0.5, 0.6, 0.7, 0.8], "metallicFactor": 0.25,
                             "roughnessFactor": 0.75, "baseColorTexture": {"index": 0}},
    "normalTexture": {"index": 1, "scale": 0.5},
    "emissiveFactor": [1, 0.5, 0.25],
    "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": 4}},
    "alphaMode": "MASK", "alphaCutoff": 0.3, "doubleSided": true}],
  "textures": [{"source": 0, "sampler": 0}, {"source": 0}],
  "samplers": [{"wrapS": 33071, "wrapT": 33648}],
  "images": [{IMAGE}],
  "buffers": [{BUFFER "byteLength": 204}],
  "bufferViews": [
    {"buffer": 0, "byteOffset": 0, "byteLength": 48},
    {"buffer": 0, "byteOffset": 48, "byteLength": 48},
    {"buffer": 0, "byteOffset": 96, "byteLength": 32},
    {"buffer": 0, "byteOffset": 128, "byteLength": 64},
    {"buffer": 0, "byteOffset": 192, "byteLength": 12}
  ],
  "accessors": [
    {"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3"},
    {"bufferView": 1, "componentType": 5126, "count": 4, "type": "VEC3"},
    {"bufferView": 2, "componentType": 5126, "count": 4, "type": "VEC2"},
    {"bufferView": 3, "componentType": 5126, "count": 4, "type": "VEC4"},
    {"bufferView": 4, "componentType": 5123, "count": 6, "type": "SCALAR"}
  ]
})";

std::string data_uri(const std::vector<unsigned char>& bytes, const char* mime) {
    return std::string("data:") + mime + ";base64," + prast::gltf_test::base64(bytes);
}

// The .gltf text with a data-URI buffer and a data-URI PNG.
std::string quad_gltf() {
    std::string json = kQuadGltf;
    replace_once(json, "BUFFER", "\"uri\": \"" + data_uri(quad_buffer(), "application/octet-stream") + "\",");
    replace_once(json, "IMAGE", "\"uri\": \"" + data_uri(tiny_png(), "image/png") + "\"");
    return json;
}

void put32(std::vector<unsigned char>& out, std::uint32_t v) {
    for (int i = 0; i < 4; ++i) out.push_back(std::uint8_t(v >> (8 * i)));
}

std::vector<unsigned char> make_glb(std::string json, std::vector<unsigned char> bin) {
    while (json.size() % 4) json += ' ';
    while (bin.size() % 4) bin.push_back(0);
    std::vector<unsigned char> out;
    put32(out, 0x46546C67); // "glTF"
    put32(out, 2);
    put32(out, std::uint32_t(12 + 8 + json.size() + (bin.empty() ? 0 : 8 + bin.size())));
    put32(out, std::uint32_t(json.size()));
    put32(out, 0x4E4F534A); // "JSON"
    out.insert(out.end(), json.begin(), json.end());
    if (!bin.empty()) {
        put32(out, std::uint32_t(bin.size()));
        put32(out, 0x004E4942); // "BIN\0"
        out.insert(out.end(), bin.begin(), bin.end());
    }
    return out;
}

// The same quad as a .glb: the buffer is the BIN chunk.
std::vector<unsigned char> quad_glb() {
    std::string json = kQuadGltf;
    replace_once(json, "BUFFER", "");
    replace_once(json, "IMAGE", "\"uri\": \"" + data_uri(tiny_png(), "image/png") + "\"");
    return make_glb(json, quad_buffer());
}

void check_vec(const glm::vec3& got, const glm::vec3& want, float eps = 1e-5f) {
    INFO("got (" << got.x << ", " << got.y << ", " << got.z << ") want (" << want.x << ", " << want.y
                 << ", " << want.z << ")");
    CHECK(glm::length(got - want) < eps);
}

// Shared checks of the hand-written quad glTF / glb.
void check_quad_scene(const Scene& s) {
    check_sane(s);
    REQUIRE(s.meshes.size() == 1);
    REQUIRE(s.materials.size() == 1);
    REQUIRE(s.images.size() == 1);
    const Mesh& m = s.meshes[0];
    REQUIRE(m.positions.size() == 4);
    CHECK(m.indices == std::vector<std::uint32_t>{0, 1, 2, 0, 2, 3});

    // world = T(10,0,0) * T(1,2,3) * R_y(90) * S(2); R_y(90): (x, y, z) -> (z, y, -x)
    check_vec(m.positions[0], {11, 2, 3});
    check_vec(m.positions[1], {11, 2, 1});
    check_vec(m.positions[2], {11, 4, 1});
    check_vec(m.positions[3], {11, 4, 3});
    for (const glm::vec3& n : m.normals) check_vec(n, {1, 0, 0});
    for (const glm::vec4& t : m.tangents) {
        check_vec(glm::vec3(t), {0, 0, -1});
        CHECK(t.w == 1.0f);
    }
    CHECK(m.uvs[0] == glm::vec2(0, 1)); // glTF UVs are kept as they are
    CHECK(m.uvs[2] == glm::vec2(1, 0));

    const Material& mat = s.materials[std::size_t(m.material)];
    CHECK(mat.name == "mat");
    CHECK(mat.base_color_factor == glm::vec4(0.5f, 0.6f, 0.7f, 0.8f));
    CHECK(mat.metallic_factor == doctest::Approx(0.25));
    CHECK(mat.roughness_factor == doctest::Approx(0.75));
    check_vec(mat.emissive_factor, {4, 2, 1}); // times KHR_materials_emissive_strength
    CHECK(mat.alpha_mode == AlphaMode::Mask);
    CHECK(mat.alpha_cutoff == doctest::Approx(0.3));
    CHECK(mat.double_sided);
    CHECK(mat.normal_scale == doctest::Approx(0.5));
    CHECK(mat.base_color.image == 0);
    CHECK(mat.base_color.wrap_s == Wrap::ClampToEdge);
    CHECK(mat.base_color.wrap_t == Wrap::MirroredRepeat);
    CHECK(mat.normal.image == 0); // same image, no sampler: REPEAT
    CHECK(mat.normal.wrap_s == Wrap::Repeat);
    CHECK(mat.normal.wrap_t == Wrap::Repeat);
    CHECK(!mat.metallic_roughness.valid());
    CHECK(s.images[0].bytes == tiny_png());
    CHECK(s.images[0].path.empty());

    REQUIRE(s.lights.size() == 2);
    CHECK(s.lights[0].type == Light::Type::Directional);
    check_vec(s.lights[0].direction, {0, 1, 0}); // -Z turned down by R_x(-90): towards the light is up
    check_vec(s.lights[0].color, {1, 0.9f, 0.8f});
    CHECK(s.lights[0].intensity == doctest::Approx(3));
    CHECK(s.lights[1].type == Light::Type::Spot);
    check_vec(s.lights[1].position, {10, 5, 0});
    CHECK(s.lights[1].intensity == doctest::Approx(20));
    CHECK(!any_warning(s, "spot"));
}

// ---- The small OBJ used by several tests

const char* kQuadObj = R"(# quad in the XY plane, OBJ UVs (v = 0 at the bottom edge y = 0)
mtllib quad.mtl
o quad
v 0 0 0
v 1 0 0
v 1 1 0
v 0 1 0
vt 0 0
vt 1 0
vt 1 1
vt 0 1
usemtl full
f 1/1 2/2 3/3 4/4
)";

const char* kQuadMtl = R"(newmtl full
Kd 0.5 0.25 1
Pr 0.3
Pm 0.7
Ke 2 0 0
Pc gold
map_Kd albedo.png
map_Pr rough.png
map_Pm metal.png
map_Ke emit.png
norm -bm 0.5 normal.png
map_Ka ao.png
)";

void write_pngs(const TempDir& dir, std::initializer_list<const char*> names) {
    const std::vector<unsigned char> png = tiny_png();
    for (const char* n : names) write_bytes(dir.file(n), png);
}

// ---- Fuzzing

// Small random edits: byte flips, digit changes, truncation, duplicated or
// deleted lines (or byte ranges in a binary file).
std::string mutate(std::string s, std::mt19937& rng, bool text) {
    auto pick = [&](std::size_t n) { return n == 0 ? 0 : std::size_t(rng() % n); };
    const int edits = 1 + int(rng() % 3);
    for (int e = 0; e < edits && !s.empty(); ++e) {
        switch (rng() % 5) {
        case 0: s[pick(s.size())] = char(rng() & 0xff); break;
        case 1: {
            // A digit changed: offsets, counts and indices turn wrong but stay numbers.
            for (int tries = 0; tries < 64; ++tries) {
                const std::size_t at = pick(s.size());
                if (s[at] >= '0' && s[at] <= '9') {
                    s[at] = "0123456789-9"[rng() % 12];
                    break;
                }
            }
            break;
        }
        case 2: s.resize(pick(s.size())); break;
        case 3: {
            const std::size_t a = pick(s.size());
            if (text) {
                const std::size_t begin = s.rfind('\n', a) == std::string::npos ? 0 : s.rfind('\n', a) + 1;
                const std::size_t end = s.find('\n', a) == std::string::npos ? s.size() : s.find('\n', a) + 1;
                s.insert(begin, s.substr(begin, end - begin));
            } else {
                s.insert(a, s.substr(a, 1 + pick(64)));
            }
            break;
        }
        default: {
            const std::size_t a = pick(s.size());
            s.erase(a, text ? s.find('\n', a) - a : 1 + pick(16));
            break;
        }
        }
    }
    return s;
}

// Loads `path` `iterations` times after rewriting it with a mutated `original`:
// each try must load a sane scene or throw LoadError.
void fuzz(const std::string& path, const std::string& original, bool text, int iterations,
          std::uint32_t seed, const std::string& load_path) {
    std::mt19937 rng(seed);
    int loaded = 0, rejected = 0;
    const auto start = std::chrono::steady_clock::now();
    for (int i = 0; i < iterations; ++i) {
        const std::string bytes = mutate(original, rng, text);
        write_text(path, bytes);
        try {
            const Scene s = load_scene(load_path);
            check_sane(s);
            ++loaded;
        } catch (const LoadError& e) {
            ++rejected;
            CHECK(!contains(e.what(), "\n"));
        }
        // "Never hang": each try of these tiny files takes well under a second.
        REQUIRE(std::chrono::steady_clock::now() - start < std::chrono::seconds(60));
    }
    MESSAGE(fs::path(path).filename().string() << ": " << loaded << " loaded, " << rejected
                                               << " rejected with LoadError");
    CHECK(loaded + rejected == iterations);
}

std::string assets() { return PRAST_SHARED_ASSETS; }

bool have_assets() {
    if (fs::is_directory(assets())) return true;
    MESSAGE("skipped: " << assets() << " not found (the shared test assets)");
    return false;
}

} // namespace

TEST_SUITE("load") {

// ---- OBJ

TEST_CASE("OBJ quad with every map: counts, factors, maps, v flip, normals, tangents") {
    TempDir dir("load");
    write_text(dir.file("quad.obj"), kQuadObj);
    write_text(dir.file("quad.mtl"), kQuadMtl);
    write_pngs(dir, {"albedo.png", "rough.png", "metal.png", "emit.png", "normal.png", "ao.png"});

    const Scene s = load_scene(dir.file("quad.obj"));
    check_sane(s);
    CHECK(s.warnings.empty());
    REQUIRE(s.meshes.size() == 1);
    REQUIRE(s.materials.size() == 1);
    CHECK(s.images.size() == 6);
    CHECK(s.triangle_count() == 2);
    const Mesh& m = s.meshes[0];
    CHECK(m.positions.size() == 4); // the quad's corners are shared by both triangles
    CHECK(m.name == "quad");

    const Material& mat = s.materials[0];
    CHECK(mat.name == "full");
    CHECK(mat.base_color_factor == glm::vec4(0.5f, 0.25f, 1.0f, 1.0f));
    CHECK(mat.roughness_factor == doctest::Approx(0.3));
    CHECK(mat.metallic_factor == doctest::Approx(0.7));
    check_vec(mat.emissive_factor, {2, 0, 0});
    CHECK(mat.normal_scale == doctest::Approx(0.5));
    CHECK(mat.conductor == Conductor::Gold);
    CHECK(!mat.double_sided); // MTL has no key for it
    CHECK(!mat.metallic_roughness.valid());
    auto image_name = [&](const TextureRef& t) {
        REQUIRE(t.valid());
        return fs::path(s.images[std::size_t(t.image)].path).filename().string();
    };
    CHECK(image_name(mat.base_color) == "albedo.png");
    CHECK(image_name(mat.roughness) == "rough.png");
    CHECK(image_name(mat.metallic) == "metal.png");
    CHECK(image_name(mat.emissive) == "emit.png");
    CHECK(image_name(mat.normal) == "normal.png");
    CHECK(image_name(mat.occlusion) == "ao.png");

    for (std::size_t i = 0; i < m.positions.size(); ++i) {
        const glm::vec3 p = m.positions[i];
        // OBJ v = y; internal v = 1 - v_obj, so v = 0 at the top edge y = 1.
        CHECK(m.uvs[i].x == doctest::Approx(p.x));
        CHECK(m.uvs[i].y == doctest::Approx(1.0f - p.y));
        check_vec(m.normals[i], {0, 0, 1}); // computed: no vn in the file
        // T along +u (= +X); B = cross(N, T) * w points up the image (-v internal = +Y).
        check_vec(glm::vec3(m.tangents[i]), {1, 0, 0});
        const glm::vec3 b = glm::cross(m.normals[i], glm::vec3(m.tangents[i])) * m.tangents[i].w;
        check_vec(b, {0, 1, 0});
    }
}

TEST_CASE("OBJ transparency: d and Tr map to alpha BLEND with the base colour's alpha; d wins over Tr") {
    TempDir dir("load");
    write_text(dir.file("t.mtl"), "newmtl solid\nKd 1 1 1\n\nnewmtl half\nKd 1 0 0\nd 0.5\n\n"
                                  "newmtl tr\nTr 0.25\n\nnewmtl both\nd 0.4\nTr 0.9\n\nnewmtl one\nd 1\n");
    write_text(dir.file("t.obj"), "mtllib t.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\n"
                                  "usemtl solid\nf 1 2 3\nusemtl half\nf 1 2 3\nusemtl tr\nf 1 2 3\n"
                                  "usemtl both\nf 1 2 3\nusemtl one\nf 1 2 3\n");
    const Scene s = load_scene(dir.file("t.obj"));
    check_sane(s);
    REQUIRE(s.materials.size() == 5);
    CHECK(s.materials[0].alpha_mode == AlphaMode::Opaque);
    CHECK(s.materials[0].base_color_factor.a == 1.0f);
    CHECK(s.materials[1].alpha_mode == AlphaMode::Blend);
    CHECK(s.materials[1].base_color_factor == glm::vec4(1.0f, 0.0f, 0.0f, 0.5f));
    CHECK(s.materials[2].alpha_mode == AlphaMode::Blend);
    CHECK(s.materials[2].base_color_factor.a == 0.75f);
    CHECK(s.materials[3].alpha_mode == AlphaMode::Blend);
    CHECK(s.materials[3].base_color_factor.a == doctest::Approx(0.4f));
    CHECK(s.materials[4].alpha_mode == AlphaMode::Opaque);
}

TEST_CASE("OBJ factors: absent keys count as 1 with a map, else the defaults") {
    TempDir dir("load");
    // "kd" first: tinyobjloader keeps its has_kd flag across materials, which
    // the loader must not inherit.
    write_text(dir.file("m.mtl"), "newmtl kd\nKd 0.1 0.2 0.3\n\n"
                                  "newmtl maps\nmap_Kd a.png\nmap_Pr a.png\nmap_Pm a.png\nmap_Ke a.png\n\n"
                                  "newmtl bare\nNs 10\n\n"
                                  "newmtl zero\nKd 0 0 0\nPr 0\nPm 0\nmap_Pr a.png\n");
    write_pngs(dir, {"a.png"});
    write_text(dir.file("m.obj"), "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\n"
                                  "usemtl kd\nf 1 2 3\nusemtl maps\nf 2 4 3\n"
                                  "usemtl bare\nf 1 3 2\nusemtl zero\nf 2 3 4\n");
    const Scene s = load_scene(dir.file("m.obj"));
    check_sane(s);
    REQUIRE(s.materials.size() == 4);
    CHECK(s.images.size() == 1); // one file, one image
    CHECK(s.meshes.size() == 4);

    const Material& kd = s.materials[0];
    CHECK(kd.base_color_factor == glm::vec4(0.1f, 0.2f, 0.3f, 1.0f));
    CHECK(kd.roughness_factor == 0.5f);
    CHECK(kd.metallic_factor == 0.0f);

    const Material& maps = s.materials[1];
    CHECK(maps.base_color_factor == glm::vec4(1.0f));
    CHECK(maps.roughness_factor == 1.0f);
    CHECK(maps.metallic_factor == 1.0f);
    CHECK(maps.emissive_factor == glm::vec3(1.0f));
    CHECK(maps.base_color.valid());

    const Material& bare = s.materials[2];
    CHECK(bare.base_color_factor == glm::vec4(0.8f, 0.8f, 0.8f, 1.0f));
    CHECK(bare.roughness_factor == 0.5f);
    CHECK(bare.metallic_factor == 0.0f);
    CHECK(bare.emissive_factor == glm::vec3(0.0f));
    CHECK(bare.conductor == Conductor::None);

    const Material& zero = s.materials[3];
    CHECK(zero.base_color_factor == glm::vec4(0.0f, 0.0f, 0.0f, 1.0f));
    CHECK(zero.roughness_factor == 0.0f); // present keys win over the map rule
    CHECK(zero.metallic_factor == 0.0f);
}

TEST_CASE("OBJ with two materials in one object gives two meshes") {
    TempDir dir("load");
    write_text(dir.file("two.mtl"), "newmtl red\nKd 1 0 0\nnewmtl blue\nKd 0 0 1\n");
    write_text(dir.file("two.obj"), "mtllib two.mtl\no thing\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n"
                                    "v 2 0 0\nv 2 1 0\n"
                                    "usemtl red\nf 1 2 3 4\nusemtl blue\nf 2 5 6 3\n");
    const Scene s = load_scene(dir.file("two.obj"));
    check_sane(s);
    REQUIRE(s.meshes.size() == 2);
    CHECK(s.triangle_count() == 4);
    REQUIRE(s.materials.size() == 2);
    CHECK(s.meshes[0].material != s.meshes[1].material);
    for (const Mesh& m : s.meshes) {
        CHECK(m.positions.size() == 4);
        CHECK(m.uvs.empty());
        CHECK(m.tangents.empty());
        const glm::vec3 color(s.materials[std::size_t(m.material)].base_color_factor);
        // The red quad lies in x <= 1, the blue one in x >= 1.
        if (color == glm::vec3(1, 0, 0)) {
            for (const glm::vec3& p : m.positions) CHECK(p.x <= 1.0f);
        } else {
            CHECK(color == glm::vec3(0, 0, 1));
            for (const glm::vec3& p : m.positions) CHECK(p.x >= 1.0f);
        }
    }
}

TEST_CASE("OBJ smooth normals are area-weighted and shared across UV seams") {
    TempDir dir("load");
    // Two triangles folded along the X axis, with different UVs for the
    // shared edge: the edge's normals are the area-weighted mean.
    write_text(dir.file("fold.obj"), "v 0 0 0\nv 1 0 0\nv 0 2 0\nv 0 0 1\n"
                                     "vt 0 0\nvt 1 0\nvt 0 1\nvt 0.5 0.5\n"
                                     "f 1/1 2/2 3/3\nf 2/4 1/4 4/4\n");
    const Scene s = load_scene(dir.file("fold.obj"));
    check_sane(s);
    const Mesh& m = s.meshes[0];
    CHECK(m.positions.size() == 6); // corners split by their UV index
    // Face normals: +Z with area 1, +Y with area 0.5 -> mean (0, 0.5, 1) / |.|
    const glm::vec3 edge = glm::normalize(glm::vec3(0, 0.5f, 1));
    for (std::size_t i = 0; i < m.positions.size(); ++i)
        if (m.positions[i].y == 0 && m.positions[i].z == 0) check_vec(m.normals[i], edge);
}

TEST_CASE("OBJ: an MTL naming a missing map warns and falls back") {
    TempDir dir("load");
    write_text(dir.file("quad.obj"), kQuadObj);
    write_text(dir.file("quad.mtl"), "newmtl full\nmap_Kd missing.png\nmap_Pr rough.png\n");
    write_pngs(dir, {"rough.png"});
    const Scene s = load_scene(dir.file("quad.obj"));
    check_sane(s);
    CHECK(any_warning(s, "missing.png"));
    CHECK(contains(s.warnings.at(0), "quad.obj"));
    const Material& mat = s.materials.at(0);
    CHECK(!mat.base_color.valid());
    CHECK(mat.base_color_factor == glm::vec4(0.8f, 0.8f, 0.8f, 1.0f)); // as if there were no map
    CHECK(mat.roughness.valid());
    CHECK(mat.roughness_factor == 1.0f);
}

TEST_CASE("OBJ: a missing MTL file warns and uses the default material") {
    TempDir dir("load");
    write_text(dir.file("quad.obj"), kQuadObj);
    const Scene s = load_scene(dir.file("quad.obj"));
    check_sane(s);
    CHECK(any_warning(s, "quad.mtl"));
    REQUIRE(s.materials.size() == 1);
    CHECK(s.materials[0].base_color_factor == glm::vec4(0.8f, 0.8f, 0.8f, 1.0f));
}

TEST_CASE("OBJ: triangles with NaN or Inf corners are dropped with a warning") {
    TempDir dir("load");
    // tinyobjloader reads 0e999 as 0 * inf = NaN and 1e999 as inf.
    write_text(dir.file("nan.obj"), "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0e999 0 0\nv 1e999 1 0\n"
                                    "f 1 2 3\nf 1 2 4\nf 2 3 5\nf 4 5 1\n");
    const Scene s = load_scene(dir.file("nan.obj"));
    check_sane(s);
    CHECK(s.triangle_count() == 1);
    CHECK(s.meshes[0].positions.size() == 3); // the NaN vertices are gone too
    CHECK(any_warning(s, "dropped 3 triangles"));
    CHECK(!s.bounds().empty());
    CHECK(std::isfinite(s.bounds().radius()));

    write_text(dir.file("allnan.obj"), "v 0e999 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
    check_load_error(dir.file("allnan.obj"), "no triangles");
}

TEST_CASE("OBJ: out-of-range face indices and huge polygons are LoadErrors") {
    TempDir dir("load");
    write_text(dir.file("range.obj"), "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 7\n");
    check_load_error(dir.file("range.obj"), "out of range");
    write_text(dir.file("range_quad.obj"), "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3 9\n");
    check_load_error(dir.file("range_quad.obj"));
    write_text(dir.file("range_neg.obj"), "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 -9\n");
    check_load_error(dir.file("range_neg.obj"));
    write_text(dir.file("range_vt.obj"), "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nf 1/1 2/1 3/5\n");
    check_load_error(dir.file("range_vt.obj"), "texcoord");
    write_text(dir.file("range_vn.obj"), "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nf 1//1 2//1 3//2\n");
    check_load_error(dir.file("range_vn.obj"), "normal");

    std::string big = "v 0 0 0\n", face = "f";
    for (int i = 1; i <= 1000; ++i) {
        big += "v " + std::to_string(std::cos(i * 0.00628)) + " " + std::to_string(std::sin(i * 0.00628)) + " 0\n";
        face += " " + std::to_string(i + 1);
    }
    write_text(dir.file("big_polygon.obj"), big + face + "\n");
    check_load_error(dir.file("big_polygon.obj"), "vertices");

    write_text(dir.file("pentagon.obj"), "v 0 0 0\nv 2 0 0\nv 3 1 0\nv 1 2 0\nv -1 1 0\nf 1 2 3 4 5\n");
    CHECK(load_scene(dir.file("pentagon.obj")).triangle_count() == 3);
    write_text(dir.file("no_faces.obj"), "v 0 0 0\nv 1 0 0\nv 0 1 0\n");
    check_load_error(dir.file("no_faces.obj"), "no triangles");
}

// ---- glTF

TEST_CASE("glTF with a data-URI buffer: transforms, indices, material, lights") {
    TempDir dir("load");
    write_text(dir.file("quad.gltf"), quad_gltf());
    const Scene s = load_scene(dir.file("quad.gltf"));
    check_quad_scene(s);
}

TEST_CASE("glb: the same quad from the BIN chunk") {
    TempDir dir("load");
    write_bytes(dir.file("quad.glb"), quad_glb());
    check_quad_scene(load_scene(dir.file("quad.glb")));
    // Extensions are case-insensitive.
    write_bytes(dir.file("QUAD.GLB"), quad_glb());
    CHECK(load_scene(dir.file("QUAD.GLB")).triangle_count() == 2);
}

TEST_CASE("glTF: a mirroring node flips the winding and the tangent handedness") {
    TempDir dir("load");
    std::string json = quad_gltf();
    replace_once(json, "\"scale\": [2, 2, 2]", "\"scale\": [-2, 2, 2]");
    write_text(dir.file("mirror.gltf"), json);
    const Scene s = load_scene(dir.file("mirror.gltf"));
    check_sane(s);
    const Mesh& m = s.meshes.at(0);
    CHECK(m.indices == std::vector<std::uint32_t>{0, 2, 1, 0, 3, 2});
    // The winding still agrees with the normal: counter-clockwise seen from it.
    const glm::vec3 face = glm::cross(m.positions[m.indices[1]] - m.positions[m.indices[0]],
                                      m.positions[m.indices[2]] - m.positions[m.indices[0]]);
    CHECK(glm::dot(face, m.normals[0]) > 0.0f);
    for (const glm::vec4& t : m.tangents) CHECK(t.w == -1.0f);

    // Tangents computed from the UVs agree with the file's.
    replace_once(json, ", \"TANGENT\": 3", "");
    write_text(dir.file("mirror_computed.gltf"), json);
    const Scene c = load_scene(dir.file("mirror_computed.gltf"));
    check_sane(c);
    for (std::size_t i = 0; i < 4; ++i) {
        check_vec(glm::vec3(c.meshes[0].tangents[i]), glm::vec3(m.tangents[i]));
        CHECK(c.meshes[0].tangents[i].w == m.tangents[i].w);
    }
}

TEST_CASE("glTF: without NORMAL, normals are computed; without TANGENT, tangents") {
    TempDir dir("load");
    std::string json = quad_gltf();
    replace_once(json, "\"NORMAL\": 1, ", "");
    replace_once(json, ", \"TANGENT\": 3", "");
    write_text(dir.file("bare.gltf"), json);
    const Scene s = load_scene(dir.file("bare.gltf"));
    check_sane(s);
    const Mesh& m = s.meshes.at(0);
    for (std::size_t i = 0; i < 4; ++i) {
        check_vec(m.normals[i], {1, 0, 0});
        check_vec(glm::vec3(m.tangents[i]), {0, 0, -1});
        // B = cross(N, T) * w runs up the image: towards -v (glTF v = 0 is the top).
        const glm::vec3 b = glm::cross(m.normals[i], glm::vec3(m.tangents[i])) * m.tangents[i].w;
        check_vec(b, {0, 1, 0});
    }
}

TEST_CASE("glTF: recoverable problems are warnings") {
    TempDir dir("load");
    SUBCASE("missing external image") {
        std::string json = quad_gltf();
        const std::string png_uri = data_uri(tiny_png(), "image/png");
        replace_once(json, png_uri, "textures/missing.png");
        write_text(dir.file("noimage.gltf"), json);
        const Scene s = load_scene(dir.file("noimage.gltf"));
        check_sane(s);
        CHECK(any_warning(s, "missing.png"));
        CHECK(!s.materials[0].base_color.valid());
        CHECK(s.images.empty());
    }
    SUBCASE("external image found") {
        std::string json = quad_gltf();
        replace_once(json, data_uri(tiny_png(), "image/png"), "tex%20a.png");
        write_pngs(dir, {"tex a.png"});
        write_text(dir.file("extimage.gltf"), json);
        const Scene s = load_scene(dir.file("extimage.gltf"));
        REQUIRE(s.images.size() == 1);
        CHECK(fs::path(s.images[0].path).filename() == "tex a.png");
        CHECK(s.images[0].bytes.empty());
    }
    SUBCASE("BLEND, texCoord 1 without TEXCOORD_1, KHR_materials_*, points, bad material") {
        std::string json = quad_gltf();
        replace_once(json, "\"MASK\"", "\"BLEND\"");
        replace_once(json, "\"normalTexture\": {\"index\": 1,", "\"normalTexture\": {\"index\": 1, \"texCoord\": 1,");
        replace_once(json, "\"extensions\": {\"KHR_materials_emissive_strength\"",
                     "\"extensions\": {\"KHR_materials_anisotropy\": {}, \"KHR_materials_emissive_strength\"");
        replace_once(json, "\"indices\": 4, \"material\": 0}",
                     "\"indices\": 4, \"material\": 0}, {\"attributes\": {\"POSITION\": 0}, \"mode\": 0},"
                     " {\"attributes\": {\"POSITION\": 0}, \"material\": 7}");
        write_text(dir.file("warn.gltf"), json);
        const Scene s = load_scene(dir.file("warn.gltf"));
        check_sane(s);
        CHECK(s.materials[0].alpha_mode == AlphaMode::Blend);
        CHECK(!any_warning(s, "BLEND"));
        CHECK(s.materials[0].normal.valid());
        CHECK(s.materials[0].normal.texcoord == 1);
        CHECK(any_warning(s, "mesh 0 primitive 0: its material reads TEXCOORD_1, which it lacks (sampled at 0, 0)"));
        CHECK(s.meshes[0].tangents.size() == 4);  // from TEXCOORD_0, the set the mesh has
        CHECK(any_warning(s, "KHR_materials_anisotropy"));
        CHECK(!any_warning(s, "mode 0"));
        CHECK(any_warning(s, "material 7"));
        REQUIRE(s.meshes.size() == 3); // the point primitive is drawn as points
        CHECK(s.meshes[1].topology == Mesh::Topology::Points);
        CHECK(s.meshes[1].normals.empty());
        CHECK(s.materials.size() == 2); // the bad index gets a default material
        for (const std::string& w : s.warnings) CHECK(contains(w, "warn.gltf"));
    }
}

TEST_CASE("glTF: corrupt files are LoadErrors naming the file") {
    TempDir dir("load");
    struct Case {
        const char* name;
        const char* from;
        const char* to;
        const char* expect;
    };
    const Case cases[] = {
        {"bad_buffer_index.gltf", "{\"buffer\": 0, \"byteOffset\": 0,", "{\"buffer\": 3, \"byteOffset\": 0,", "buffer"},
        {"accessor_index.gltf", "\"POSITION\": 0", "\"POSITION\": 42", "accessor 42"},
        {"bufferview_index.gltf", "{\"bufferView\": 0,", "{\"bufferView\": 9,", "bufferView 9"},
        {"accessor_range.gltf", "\"count\": 4, \"type\": \"VEC3\"}", "\"count\": 5, \"type\": \"VEC3\"}", "exceeds"},
        {"accessor_offset.gltf", "{\"bufferView\": 1,", "{\"bufferView\": 1, \"byteOffset\": 4,", "exceeds"},
        {"view_range.gltf", "\"byteOffset\": 192, \"byteLength\": 12", "\"byteOffset\": 196, \"byteLength\": 12", "exceeds"},
        {"huge_count.gltf", "\"count\": 6, \"type\": \"SCALAR\"", "\"count\": 4294967296, \"type\": \"SCALAR\"", ""},
        {"index_type.gltf", "\"componentType\": 5123", "\"componentType\": 5126", ""},
        {"wrong_type.gltf", "\"count\": 4, \"type\": \"VEC2\"", "\"count\": 4, \"type\": \"VEC4\"", "type"},
        {"node_cycle.gltf", "\"scale\": [2, 2, 2]", "\"scale\": [2, 2, 2], \"children\": [0]", ""},
        {"self_cycle.gltf", "\"scale\": [2, 2, 2]", "\"scale\": [2, 2, 2], \"children\": [1]", ""},
        {"node_child.gltf", "\"children\": [1, 2, 3]", "\"children\": [1, 2, 30]", "out of range"},
        {"scene_node.gltf", "\"nodes\": [0]", "\"nodes\": [12]", "out of range"},
        {"node_mesh.gltf", "\"mesh\": 0", "\"mesh\": 5", "mesh 5"},
        {"required_ext.gltf", "\"extensionsUsed\"", "\"extensionsRequired\": [\"KHR_texture_basisu\"], \"extensionsUsed\"", "KHR_texture"},
        {"invalid_json.gltf", "\"scenes\": [", "\"scenes\": [[", ""},
    };
    for (const Case& c : cases) {
        std::string json = quad_gltf();
        replace_once(json, c.from, c.to);
        write_text(dir.file(c.name), json);
        check_load_error(dir.file(c.name), c.expect);
    }

    // An index past the vertices.
    {
        std::string json = quad_gltf();
        std::vector<unsigned char> buf = quad_buffer();
        buf[192 + 4] = 9; // third index: 2 -> 9
        replace_once(json, data_uri(quad_buffer(), "application/octet-stream"),
                     data_uri(buf, "application/octet-stream"));
        write_text(dir.file("index_value.gltf"), json);
        check_load_error(dir.file("index_value.gltf"), "out of range");
    }
    // A missing .bin buffer.
    {
        std::string json = quad_gltf();
        replace_once(json, data_uri(quad_buffer(), "application/octet-stream"), "missing.bin");
        write_text(dir.file("missing_bin.gltf"), json);
        check_load_error(dir.file("missing_bin.gltf"));
    }
    // JSON nested absurdly deep.
    write_text(dir.file("deep.gltf"), "{\"asset\": {\"version\": \"2.0\"}, \"extras\": " +
                                          std::string(100000, '[') + std::string(100000, ']') + "}");
    check_load_error(dir.file("deep.gltf"), "deep");
    write_text(dir.file("garbage.gltf"), "this is not JSON");
    check_load_error(dir.file("garbage.gltf"));
}

TEST_CASE("glb: bad headers and chunk lengths are LoadErrors") {
    TempDir dir("load");
    const std::vector<unsigned char> good = quad_glb();
    auto with = [&](const char* name, std::vector<unsigned char> bytes, const char* expect = "") {
        write_bytes(dir.file(name), bytes);
        check_load_error(dir.file(name), expect);
    };
    auto set32 = [](std::vector<unsigned char> b, std::size_t at, std::uint32_t v) {
        for (int i = 0; i < 4; ++i) b[at + std::size_t(i)] = std::uint8_t(v >> (8 * i));
        return b;
    };
    std::vector<unsigned char> bad_magic = good;
    bad_magic[0] = 'x';
    with("bad_magic.glb", bad_magic, "magic");
    with("version1.glb", set32(good, 4, 1), "version");
    with("long.glb", set32(good, 8, std::uint32_t(good.size() + 100)), "truncated");
    with("json_len.glb", set32(good, 12, 0x7fffffff));
    with("json_type.glb", set32(good, 16, 0x12345678));
    with("short.glb", std::vector<unsigned char>(good.begin(), good.begin() + 10), "truncated");
    with("cut.glb", std::vector<unsigned char>(good.begin(), good.end() - 16));
    // A BIN chunk claiming the rest of the file without its own 8-byte header:
    // tinygltf 2.7.0 alone would read past the end.
    const std::size_t bin_at = 20 + (std::size_t(good[12]) | std::size_t(good[13]) << 8 |
                                     std::size_t(good[14]) << 16 | std::size_t(good[15]) << 24);
    with("bin_len.glb", set32(good, bin_at, std::uint32_t(good.size() - bin_at)), "BIN");
    with("text.glb", std::vector<unsigned char>{'{', '}', ' ', ' '}, "magic");
}

// ---- Any file

TEST_CASE("missing, directory, empty and unknown files are LoadErrors") {
    TempDir dir("load");
    check_load_error(dir.file("nope.obj"), "no such file");
    check_load_error(dir.file("nope.gltf"), "no such file");
    fs::create_directories(dir.file("folder.obj"));
    check_load_error(dir.file("folder.obj"), "directory");
    CHECK_THROWS_AS(load_obj(dir.file("folder.obj")), LoadError);
    CHECK_THROWS_AS(load_gltf(dir.file("folder.obj")), LoadError);
    for (const char* name : {"empty.obj", "empty.gltf", "empty.glb"}) {
        write_text(dir.file(name), "");
        check_load_error(dir.file(name), "empty");
    }
    write_text(dir.file("model.xyz"), "v 0 0 0\n");
    CHECK(load_error(dir.file("model.xyz")) ==
          dir.file("model.xyz") + ": unknown extension '.xyz' (expected .obj, .gltf or .glb)");
    write_text(dir.file("QUAD.OBJ"), "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
    CHECK(load_scene(dir.file("QUAD.OBJ")).triangle_count() == 1);
}

TEST_CASE("tangents: degenerate UVs give a perpendicular unit tangent") {
    Mesh m;
    m.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
    m.uvs = {{0.5f, 0.5f}, {0.5f, 0.5f}, {0.5f, 0.5f}};
    m.indices = {0, 1, 2};
    compute_normals(m);
    compute_tangents(m);
    REQUIRE(m.tangents.size() == 3);
    for (const glm::vec4& t : m.tangents) {
        CHECK(std::abs(glm::length(glm::vec3(t)) - 1.0f) < 1e-5f);
        CHECK(std::abs(glm::dot(glm::vec3(t), glm::vec3(0, 0, 1))) < 1e-5f);
        CHECK(t.w == 1.0f);
    }
}

// ---- Fuzzing

TEST_CASE("fuzzed OBJ, MTL, glTF and glb files load or throw LoadError") {
    TempDir dir("load");
    write_pngs(dir, {"albedo.png", "rough.png", "metal.png", "emit.png", "normal.png", "ao.png"});
    const std::string obj = std::string(kQuadObj) + "vn 0 0 1\nf 1/1/1 3/3/1 4/4/1\nusemtl other\nf 1 2 -1\n";
    const std::string mtl = std::string(kQuadMtl) + "newmtl other\nKd 1 1 1\nmap_bump -bm 2 normal.png\n";

    write_text(dir.file("quad.mtl"), mtl);
    fuzz(dir.file("quad.obj"), obj, true, 400, 1234u, dir.file("quad.obj"));
    write_text(dir.file("quad.obj"), obj);
    fuzz(dir.file("quad.mtl"), mtl, true, 300, 5678u, dir.file("quad.obj"));

    const std::string gltf = quad_gltf();
    fuzz(dir.file("quad.gltf"), gltf, true, 400, 42u, dir.file("quad.gltf"));

    // JSON edits that keep the text valid JSON reach the loader's own checks.
    std::string ext_gltf = gltf;
    replace_once(ext_gltf, data_uri(quad_buffer(), "application/octet-stream"), "quad.bin");
    write_bytes(dir.file("quad.bin"), quad_buffer());
    std::mt19937 rng(7);
    int loaded = 0;
    for (int i = 0; i < 300; ++i) {
        std::string s = ext_gltf;
        for (int e = 0; e < 2; ++e) {
            for (int tries = 0; tries < 64; ++tries) {
                const std::size_t at = rng() % s.size();
                if (s[at] >= '0' && s[at] <= '9') {
                    s[at] = "0123456789"[rng() % 10];
                    break;
                }
            }
        }
        write_text(dir.file("digits.gltf"), s);
        try {
            check_sane(load_scene(dir.file("digits.gltf")));
            ++loaded;
        } catch (const LoadError&) {
        }
    }
    MESSAGE("digits.gltf: " << loaded << " of 300 loaded");

    const std::vector<unsigned char> glb = quad_glb();
    fuzz(dir.file("quad.glb"), std::string(glb.begin(), glb.end()), false, 400, 99u, dir.file("quad.glb"));
}

// ---- Real assets

TEST_CASE("real assets: tea set glTF and OBJ") {
    if (!have_assets()) return;
    const Scene gltf = load_scene(assets() + "/tea-set-01/gltf/tea_set_01_1k.gltf");
    check_sane(gltf);
    CHECK(gltf.warnings.empty());
    CHECK(gltf.meshes.size() == 10);
    CHECK(gltf.triangle_count() == 40296);
    CHECK(gltf.materials.size() == 1);
    CHECK(gltf.images.size() == 3);
    std::size_t vertices = 0;
    for (const Mesh& m : gltf.meshes) {
        vertices += m.positions.size();
        CHECK(m.tangents.size() == m.positions.size()); // no TANGENT in the file: computed
    }
    CHECK(vertices == 21875);
    const Material& gm = gltf.materials[0];
    CHECK(gm.double_sided);
    CHECK(gm.base_color.valid());
    CHECK(gm.metallic_roughness.valid());
    CHECK(gm.normal.valid());
    CHECK(!gm.occlusion.valid());
    CHECK(!gm.emissive.valid());

    const Scene obj = load_scene(assets() + "/tea-set-01/obj/tea_set_01.obj");
    check_sane(obj);
    CHECK(obj.warnings.empty());
    CHECK(obj.meshes.size() == 10);
    CHECK(obj.triangle_count() == 40296);
    CHECK(obj.materials.size() == 1);
    CHECK(obj.images.size() == 4);
    const Material& om = obj.materials[0];
    CHECK(om.base_color.valid());
    CHECK(om.roughness.valid());
    CHECK(om.metallic.valid());
    CHECK(om.normal.valid());
    CHECK(om.base_color_factor == glm::vec4(1.0f));
    CHECK(om.roughness_factor == 1.0f);
    CHECK(om.metallic_factor == 1.0f);
    CHECK(om.emissive_factor == glm::vec3(0.0f));
    // Same place in the world (the OBJ has the node transforms baked in).
    CHECK(glm::length(gltf.bounds().lo - obj.bounds().lo) < 1e-4f);
    CHECK(glm::length(gltf.bounds().hi - obj.bounds().hi) < 1e-4f);
}

TEST_CASE("real assets: NormalTangentTest glb and OBJ, tangents computed alike") {
    if (!have_assets()) return;
    const Scene glb = load_scene(assets() + "/normal-tangent-test/NormalTangentTest.glb");
    check_sane(glb);
    CHECK(glb.warnings.empty());
    CHECK(glb.meshes.size() == 1);
    CHECK(glb.triangle_count() == 7774);
    CHECK(glb.materials.size() == 1);
    CHECK(glb.images.size() == 3);
    for (const ImageSource& img : glb.images) CHECK(!img.bytes.empty()); // embedded in the BIN chunk
    CHECK(glb.materials[0].occlusion.valid());
    CHECK(glb.materials[0].metallic_roughness.valid());
    CHECK(glb.materials[0].occlusion.image == glb.materials[0].metallic_roughness.image);

    const Scene obj = load_scene(assets() + "/normal-tangent-test/obj/NormalTangentTest.obj");
    check_sane(obj);
    CHECK(obj.warnings.empty());
    CHECK(obj.meshes.size() == 1);
    CHECK(obj.triangle_count() == 7774);
    CHECK(obj.materials.size() == 1);
    CHECK(obj.images.size() == 5);
    CHECK(obj.materials[0].occlusion.valid());

    // Match vertices by position and UV (the OBJ's UVs, flipped on load, must
    // equal the glb's): the tangent frames must agree if both loaders use the
    // same UV convention.
    const Mesh& a = glb.meshes[0];
    const Mesh& b = obj.meshes[0];
    CHECK(a.positions.size() == 3983);
    CHECK(b.positions.size() == 3983);
    auto cell = [](const glm::vec3& p) {
        return std::make_tuple(long(std::lround(p.x * 1e3)), long(std::lround(p.y * 1e3)),
                               long(std::lround(p.z * 1e3)));
    };
    std::multimap<std::tuple<long, long, long>, std::size_t> grid;
    for (std::size_t i = 0; i < a.positions.size(); ++i) grid.emplace(cell(a.positions[i]), i);
    std::size_t matched = 0, agree = 0;
    for (std::size_t j = 0; j < b.positions.size(); ++j) {
        const auto range = grid.equal_range(cell(b.positions[j]));
        for (auto it = range.first; it != range.second; ++it) {
            const std::size_t i = it->second;
            if (glm::length(a.positions[i] - b.positions[j]) > 1e-5f ||
                glm::length(a.uvs[i] - b.uvs[j]) > 1e-4f)
                continue;
            ++matched;
            agree += glm::dot(glm::vec3(a.tangents[i]), glm::vec3(b.tangents[j])) > 0.99f &&
                     a.tangents[i].w == b.tangents[j].w;
            break;
        }
    }
    MESSAGE("NormalTangentTest: " << matched << " of " << b.positions.size() << " OBJ vertices matched, "
                                  << agree << " with the same tangent frame");
    CHECK(matched > b.positions.size() * 9 / 10);
    CHECK(agree > matched * 99 / 100);
}

TEST_CASE("real assets: Stanford bunny") {
    if (!have_assets()) return;
    const Scene s = load_scene(assets() + "/stanford-bunny/stanford-bunny.obj");
    check_sane(s);
    CHECK(s.meshes.size() == 1);
    CHECK(s.triangle_count() == 69451);
    CHECK(s.materials.size() == 1); // the default material
    CHECK(s.images.empty());
    const Mesh& m = s.meshes[0];
    CHECK(m.positions.size() == 34834); // 35947 in the file, 1113 used by no face
    CHECK(m.uvs.empty());
    CHECK(m.tangents.empty());
    // Computed normals point outwards: away from the centre, on average.
    const glm::vec3 c = s.bounds().center();
    double outward = 0.0;
    for (std::size_t i = 0; i < m.positions.size(); ++i)
        outward += glm::dot(m.normals[i], glm::normalize(m.positions[i] - c));
    CHECK(outward / double(m.positions.size()) > 0.3);
}

} // TEST_SUITE

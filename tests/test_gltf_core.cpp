// The loader side of core glTF 2.0: vertex colours (COLOR_0 and OBJ's
// `v x y z r g b`), TEXCOORD_1, per-texture samplers, every primitive mode
// (strips and fans as triangle lists with the spec's winding, lines, loops
// and points), asset.minVersion and required extensions, and
// KHR_materials_pbrSpecularGlossiness converted to metal-rough. Each test
// writes its own small glTF (a data-URI buffer) and checks what load_scene()
// gives; refusals run through the built `render` as a user meets them.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <random>
#include <string>
#include <vector>

#include <stb_image_write.h>

#include "scene/camera.h"
#include "scene/image.h"
#include "scene/load_scene.h"
#include "tests/cli_util.h"
#include "tests/scratch.h"
#include "tests/load_error.h"

using namespace prast;
using prast::test::load_error;

namespace {

std::string base64(const std::string& in) {
    static const char* table = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    std::string out;
    for (std::size_t i = 0; i < in.size(); i += 3) {
        const std::uint32_t b = std::uint32_t(std::uint8_t(in[i])) << 16 |
                                (i + 1 < in.size() ? std::uint32_t(std::uint8_t(in[i + 1])) << 8 : 0u) |
                                (i + 2 < in.size() ? std::uint32_t(std::uint8_t(in[i + 2])) : 0u);
        out += table[b >> 18 & 63];
        out += table[b >> 12 & 63];
        out += i + 1 < in.size() ? table[b >> 6 & 63] : '=';
        out += i + 2 < in.size() ? table[b & 63] : '=';
    }
    return out;
}

// A glTF under construction: one buffer (a data URI), its views and accessors.
struct Gltf {
    std::string bin;
    std::vector<std::string> views, accessors;

    int view(const void* data, std::size_t n) {
        while (bin.size() % 4) bin += '\0';
        views.push_back("{\"buffer\": 0, \"byteOffset\": " + std::to_string(bin.size()) +
                        ", \"byteLength\": " + std::to_string(n) + "}");
        bin.append(static_cast<const char*>(data), n);
        return int(views.size()) - 1;
    }
    int accessor(int v, int component_type, std::size_t count, const char* type, bool normalized = false) {
        accessors.push_back("{\"bufferView\": " + std::to_string(v) + ", \"componentType\": " +
                            std::to_string(component_type) + ", \"count\": " + std::to_string(count) +
                            ", \"type\": \"" + type + "\"" + (normalized ? ", \"normalized\": true" : "") + "}");
        return int(accessors.size()) - 1;
    }
    int floats(const std::vector<float>& v, const char* type, int per) {
        return accessor(view(v.data(), v.size() * 4), 5126, v.size() / std::size_t(per), type);
    }
    int u8(const std::vector<std::uint8_t>& v, const char* type, int per, bool normalized) {
        return accessor(view(v.data(), v.size()), 5121, v.size() / std::size_t(per), type, normalized);
    }
    int u16(const std::vector<std::uint16_t>& v, const char* type, int per, bool normalized) {
        return accessor(view(v.data(), v.size() * 2), 5123, v.size() / std::size_t(per), type, normalized);
    }
    int indices(const std::vector<std::uint32_t>& v) { return accessor(view(v.data(), v.size() * 4), 5125, v.size(), "SCALAR"); }

    // The whole file: `rest` holds the other top-level members, each followed by a comma.
    std::string json(const std::string& rest, const std::string& asset = "{\"version\": \"2.0\"}") const {
        auto list = [](const std::vector<std::string>& v) {
            std::string s;
            for (std::size_t i = 0; i < v.size(); ++i) s += (i ? ", " : "") + v[i];
            return s;
        };
        return "{\"asset\": " + asset + ", " + rest + "\"buffers\": [{\"byteLength\": " + std::to_string(bin.size()) +
               ", \"uri\": \"data:application/octet-stream;base64," + base64(bin) + "\"}], \"bufferViews\": [" +
               list(views) + "], \"accessors\": [" + list(accessors) + "]}";
    }
};

// Five vertices on a zig-zag in the z = 0 plane (a strip's usual layout).
const std::vector<float> kFive = {0, 0, 0, 0, 1, 0, 1, 0, 0, 1, 1, 0, 2, 0, 0};

// One node, one mesh of the given primitives.
std::string one_mesh(const std::string& primitives, const std::string& node_extra = "") {
    return "\"scene\": 0, \"scenes\": [{\"nodes\": [0]}], \"nodes\": [{\"mesh\": 0" + node_extra +
           "}], \"meshes\": [{\"primitives\": [" + primitives + "]}], ";
}

bool any_warning(const Scene& s, const std::string& part) {
    for (const std::string& w : s.warnings)
        if (w.find(part) != std::string::npos) return true;
    return false;
}

std::size_t warnings_with(const Scene& s, const std::string& part) {
    std::size_t n = 0;
    for (const std::string& w : s.warnings) n += w.find(part) != std::string::npos;
    return n;
}

Scene load_text(const test::TempDir& dir, const std::string& name, const std::string& text) {
    test::write_text(dir.file(name), text);
    return load_scene(dir.file(name));
}

// A 2x2 RGBA PNG with the given bytes.
std::string png_rgba(const std::vector<std::uint8_t>& rgba) {
    std::string out;
    stbi_write_png_to_func(
        [](void* ctx, void* data, int size) { static_cast<std::string*>(ctx)->append(static_cast<char*>(data), std::size_t(size)); },
        &out, 2, 2, 4, rgba.data(), 8);
    return out;
}

std::string png_uri(const std::string& png) { return "data:image/png;base64," + base64(png); }

// Invariants of any loaded mesh, whatever its topology.
void check_mesh_sane(const Scene& s) {
    REQUIRE(!s.meshes.empty());
    for (const Mesh& m : s.meshes) {
        const std::size_t n = m.positions.size();
        const std::size_t k = m.topology == Mesh::Topology::Triangles ? 3 : m.topology == Mesh::Topology::Lines ? 2 : 1;
        REQUIRE(!m.indices.empty());
        CHECK(m.indices.size() % k == 0);
        for (std::uint32_t i : m.indices) REQUIRE(i < n);
        CHECK((m.normals.size() == n || (m.normals.empty() && k < 3)));
        CHECK((m.uvs.empty() || m.uvs.size() == n));
        CHECK((m.uvs1.empty() || m.uvs1.size() == n));
        CHECK((m.colors.empty() || m.colors.size() == n));
        CHECK((m.tangents.empty() || m.tangents.size() == n));
        for (const glm::vec4& c : m.colors)
            for (int j = 0; j < 4; ++j) CHECK((c[j] >= 0.0f && c[j] <= 1.0f));
        for (const glm::vec2& uv : m.uvs1) CHECK((std::isfinite(uv.x) && std::isfinite(uv.y)));
        for (const glm::vec3& p : m.positions) CHECK((std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z)));
        CHECK(m.material >= 0);
        CHECK(std::size_t(m.material) < s.materials.size());
    }
}

float f0_of(float ior) {
    const float r = (1.0f - ior) / (1.0f + ior);
    return r * r;
}

} // namespace

TEST_SUITE("gltf_core") {

TEST_CASE("COLOR_0: float VEC3 (alpha 1), normalized unsigned byte and short give exact floats") {
    test::TempDir dir("gltf_core");
    Gltf g;
    const int pos = g.floats({0, 0, 0, 1, 0, 0, 0, 1, 0}, "VEC3", 3);
    const int f3 = g.floats({0.25f, 0.5f, 1, 0, 0.125f, 0.75f, 1, 1, 0}, "VEC3", 3);
    const int b4 = g.u8({255, 0, 128, 1, 0, 255, 17, 254, 51, 102, 153, 204}, "VEC4", 4, true);
    const int s3 = g.u16({65535, 0, 32768, 1, 65534, 4369, 13107, 26214, 39321}, "VEC3", 3, true);
    const std::string prim = "{\"attributes\": {\"POSITION\": " + std::to_string(pos) + ", \"COLOR_0\": ";
    const Scene s = load_text(dir, "colors.gltf",
                              g.json(one_mesh(prim + std::to_string(f3) + "}}, " + prim + std::to_string(b4) +
                                              "}}, " + prim + std::to_string(s3) + "}}")));
    check_mesh_sane(s);
    REQUIRE(s.meshes.size() == 3);
    CHECK(s.warnings.empty());  // COLOR_0 is read, not "ignored"
    const std::vector<glm::vec4>& f = s.meshes[0].colors;
    REQUIRE(f.size() == 3);
    CHECK(f[0] == glm::vec4(0.25f, 0.5f, 1.0f, 1.0f));
    CHECK(f[1] == glm::vec4(0.0f, 0.125f, 0.75f, 1.0f));
    CHECK(f[2] == glm::vec4(1.0f, 1.0f, 0.0f, 1.0f));
    const std::vector<glm::vec4>& b = s.meshes[1].colors;
    REQUIRE(b.size() == 3);
    const std::uint8_t bytes[12] = {255, 0, 128, 1, 0, 255, 17, 254, 51, 102, 153, 204};
    for (int i = 0; i < 12; ++i) CHECK(b[std::size_t(i / 4)][i % 4] == float(bytes[i] / 255.0));
    CHECK(b[0].r == 1.0f);
    CHECK(b[0].g == 0.0f);
    const std::vector<glm::vec4>& sh = s.meshes[2].colors;
    REQUIRE(sh.size() == 3);
    const std::uint16_t shorts[9] = {65535, 0, 32768, 1, 65534, 4369, 13107, 26214, 39321};
    for (int i = 0; i < 9; ++i) CHECK(sh[std::size_t(i / 3)][i % 3] == float(shorts[i] / 65535.0));
    for (const glm::vec4& c : sh) CHECK(c.a == 1.0f);
}

TEST_CASE("COLOR_0 of another form is ignored with a warning; NaN colours become white, others are clamped") {
    test::TempDir dir("gltf_core");
    Gltf g;
    const int pos = g.floats({0, 0, 0, 1, 0, 0, 0, 1, 0}, "VEC3", 3);
    const int raw = g.u8({255, 0, 0, 0, 255, 0, 0, 0, 255}, "VEC3", 3, false);  // not normalized
    const int v2 = g.floats({1, 1, 1, 1, 1, 1}, "VEC2", 2);
    const float nan = std::nanf("");
    const int bad = g.floats({nan, 0, 0, 1, 2, -1, 0.5f, 1, INFINITY, 0.5f, 0.5f, 0.5f}, "VEC4", 4);
    const int short_count = g.floats({1, 0, 0, 0, 1, 0}, "VEC3", 3);
    auto prim = [&](int color) {
        return "{\"attributes\": {\"POSITION\": " + std::to_string(pos) + ", \"COLOR_0\": " + std::to_string(color) + "}}";
    };
    const Scene s = load_text(dir, "badcolors.gltf",
                              g.json(one_mesh(prim(raw) + ", " + prim(v2) + ", " + prim(bad) + ", " + prim(short_count))));
    check_mesh_sane(s);
    REQUIRE(s.meshes.size() == 4);
    CHECK(s.meshes[0].colors.empty());
    CHECK(s.meshes[1].colors.empty());
    CHECK(warnings_with(s, "is not a VEC3/VEC4 of float or normalized unsigned byte/short, ignored") == 2);
    const std::vector<glm::vec4>& c = s.meshes[2].colors;
    REQUIRE(c.size() == 3);
    CHECK(c[0] == glm::vec4(1.0f));                        // NaN: white
    CHECK(c[1] == glm::vec4(1.0f, 0.0f, 0.5f, 1.0f));      // 2 and -1 clamped
    CHECK(c[2] == glm::vec4(1.0f));                        // Inf: white
    CHECK(any_warning(s, "set 2 NaN/Inf vertex colours to white"));
    CHECK(s.meshes[3].colors.empty());
    CHECK(any_warning(s, "COLOR_0 count differs from POSITION, ignored"));
    // An accessor index out of range is corrupt, as for every attribute.
    test::write_text(dir.file("range.gltf"), g.json(one_mesh(prim(42))));
    const std::string err = load_error(dir.file("range.gltf"));
    CHECK(err.find("range.gltf: mesh 0 primitive 0 COLOR_0: accessor 42 out of range") != std::string::npos);
}

TEST_CASE("a file without the new features gives the Scene it always did: no colours, no uvs1, triangles") {
    test::TempDir dir("gltf_core");
    Gltf g;
    const int pos = g.floats({0, 0, 0, 1, 0, 0, 0, 1, 0}, "VEC3", 3);
    const int uv = g.floats({0, 0, 1, 0, 0, 1}, "VEC2", 2);
    const Scene s = load_text(dir, "plain.gltf",
                              g.json(one_mesh("{\"attributes\": {\"POSITION\": " + std::to_string(pos) +
                                              ", \"TEXCOORD_0\": " + std::to_string(uv) + ", \"TEXCOORD_1\": " +
                                              std::to_string(uv) + "}}")));
    REQUIRE(s.meshes.size() == 1);
    const Mesh& m = s.meshes[0];
    CHECK(m.colors.empty());
    CHECK(m.uvs1.empty());  // no material reads TEXCOORD_1: not even read
    CHECK(m.topology == Mesh::Topology::Triangles);
    CHECK(m.indices == std::vector<std::uint32_t>{0, 1, 2});
    CHECK(m.uvs.size() == 3);
    CHECK(m.tangents.size() == 3);
    CHECK(s.warnings.empty());
}

TEST_CASE("TEXCOORD_1 is kept as the file has it; texCoord 0 and 1 are carried, others warned as the file writes them") {
    test::TempDir dir("gltf_core");
    Gltf g;
    const int pos = g.floats({0, 0, 0, 1, 0, 0, 0, 1, 0}, "VEC3", 3);
    const int uv0 = g.floats({0, 0, 1, 0, 0, 1}, "VEC2", 2);
    const int uv1 = g.floats({0.25f, 0.75f, 2, -1, 0.5f, 0.125f}, "VEC2", 2);
    const std::string rest =
        one_mesh("{\"attributes\": {\"POSITION\": " + std::to_string(pos) + ", \"TEXCOORD_0\": " + std::to_string(uv0) +
                 ", \"TEXCOORD_1\": " + std::to_string(uv1) + "}, \"material\": 0}") +
        "\"images\": [{\"uri\": \"" + png_uri(png_rgba(std::vector<std::uint8_t>(16, 200))) + "\"}], "
        "\"textures\": [{\"source\": 0}], \"materials\": [{\"name\": \"m\", "
        "\"pbrMetallicRoughness\": {\"baseColorTexture\": {\"index\": 0, \"texCoord\": 1}, "
        "\"metallicRoughnessTexture\": {\"index\": 0}}, "
        "\"normalTexture\": {\"index\": 0, \"texCoord\": 2}, "
        "\"occlusionTexture\": {\"index\": 0, \"texCoord\": 2147483648}, "
        "\"emissiveTexture\": {\"index\": 0, \"texCoord\": 4294967297}}], ";
    const Scene s = load_text(dir, "uv1.gltf", g.json(rest));
    check_mesh_sane(s);
    const Mesh& m = s.meshes.at(0);
    REQUIRE(m.uvs1.size() == 3);
    CHECK(m.uvs1[0] == glm::vec2(0.25f, 0.75f));
    CHECK(m.uvs1[1] == glm::vec2(2.0f, -1.0f));  // glTF's convention is the project's: no flip
    CHECK(m.uvs1[2] == glm::vec2(0.5f, 0.125f));
    const Material& mat = s.materials.at(0);
    CHECK(mat.base_color.valid());
    CHECK(mat.base_color.texcoord == 1);
    CHECK(mat.metallic_roughness.valid());
    CHECK(mat.metallic_roughness.texcoord == 0);
    CHECK(!mat.normal.valid());
    CHECK(!mat.occlusion.valid());
    CHECK(!mat.emissive.valid());  // 2^32 + 1 is not 1, whatever an int keeps of it
    CHECK(any_warning(s, "normalTexture uses TEXCOORD_2 (only TEXCOORD_0 and TEXCOORD_1 are supported), ignored"));
    CHECK(any_warning(s, "occlusionTexture uses TEXCOORD_2147483648 (only"));
    CHECK(any_warning(s, "emissiveTexture uses TEXCOORD_4294967297 (only"));
}

TEST_CASE("tangents follow the normal map's UV set") {
    test::TempDir dir("gltf_core");
    Gltf g;
    // A quad in z = 0; TEXCOORD_0 runs u along +x, TEXCOORD_1 runs u along +y.
    const int pos = g.floats({0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0}, "VEC3", 3);
    const int uv0 = g.floats({0, 1, 1, 1, 1, 0, 0, 0}, "VEC2", 2);
    const int uv1 = g.floats({0, 0, 0, 1, 1, 1, 1, 0}, "VEC2", 2);
    const int idx = g.indices({0, 1, 2, 0, 2, 3});
    auto file = [&](int texcoord) {
        return g.json(one_mesh("{\"attributes\": {\"POSITION\": " + std::to_string(pos) + ", \"TEXCOORD_0\": " +
                               std::to_string(uv0) + ", \"TEXCOORD_1\": " + std::to_string(uv1) +
                               "}, \"indices\": " + std::to_string(idx) + ", \"material\": 0}") +
                      "\"images\": [{\"uri\": \"" + png_uri(png_rgba(std::vector<std::uint8_t>(16, 128))) +
                      "\"}], \"textures\": [{\"source\": 0}], \"materials\": [{\"normalTexture\": {\"index\": 0, "
                      "\"texCoord\": " + std::to_string(texcoord) + "}}], ");
    };
    const Scene s0 = load_text(dir, "t0.gltf", file(0));
    const Scene s1 = load_text(dir, "t1.gltf", file(1));
    for (const glm::vec4& t : s0.meshes.at(0).tangents) CHECK(glm::length(glm::vec3(t) - glm::vec3(1, 0, 0)) < 1e-6f);
    REQUIRE(s1.meshes.at(0).uvs1.size() == 4);
    for (const glm::vec4& t : s1.meshes.at(0).tangents) CHECK(glm::length(glm::vec3(t) - glm::vec3(0, 1, 0)) < 1e-6f);
    // The handedness from that set too: B = cross(N, T) w runs towards its -v, which is -x here.
    for (const glm::vec4& t : s1.meshes.at(0).tangents) {
        const glm::vec3 b = glm::cross(s1.meshes[0].normals[0], glm::vec3(t)) * t.w;
        CHECK(glm::length(b - glm::vec3(-1, 0, 0)) < 1e-6f);
    }
}

TEST_CASE("samplers are per texture: two textures of one image keep theirs; absent filters are trilinear; bad enums warn once") {
    test::TempDir dir("gltf_core");
    Gltf g;
    const int pos = g.floats({0, 0, 0, 1, 0, 0, 0, 1, 0}, "VEC3", 3);
    const int uv = g.floats({0, 0, 1, 0, 0, 1}, "VEC2", 2);
    const std::string rest =
        one_mesh("{\"attributes\": {\"POSITION\": " + std::to_string(pos) + ", \"TEXCOORD_0\": " + std::to_string(uv) +
                 "}, \"material\": 0}, {\"attributes\": {\"POSITION\": " + std::to_string(pos) + "}, \"material\": 1}") +
        "\"images\": [{\"uri\": \"" + png_uri(png_rgba(std::vector<std::uint8_t>(16, 99))) + "\"}], "
        "\"samplers\": [{\"magFilter\": 9728, \"minFilter\": 9984, \"wrapS\": 33071},"
        " {\"magFilter\": 9729, \"minFilter\": 9985, \"wrapT\": 33648}, {\"minFilter\": 9986}, {\"minFilter\": 9729},"
        " {}, {\"magFilter\": 1234, \"minFilter\": 4294977024}, {\"minFilter\": 9728}],"
        "\"textures\": [{\"source\": 0, \"sampler\": 0}, {\"source\": 0, \"sampler\": 1}, {\"source\": 0, \"sampler\": 2},"
        " {\"source\": 0, \"sampler\": 3}, {\"source\": 0, \"sampler\": 4}, {\"source\": 0, \"sampler\": 5},"
        " {\"source\": 0}, {\"source\": 0, \"sampler\": 6}], "
        "\"materials\": [{\"pbrMetallicRoughness\": {\"baseColorTexture\": {\"index\": 0}, \"metallicRoughnessTexture\": {\"index\": 1}},"
        " \"normalTexture\": {\"index\": 2}, \"occlusionTexture\": {\"index\": 3}, \"emissiveTexture\": {\"index\": 4}},"
        " {\"pbrMetallicRoughness\": {\"baseColorTexture\": {\"index\": 5}, \"metallicRoughnessTexture\": {\"index\": 5}},"
        " \"normalTexture\": {\"index\": 6}, \"emissiveTexture\": {\"index\": 7}}], ";
    const Scene s = load_text(dir, "samplers.gltf", g.json(rest));
    REQUIRE(s.images.size() == 1);  // one decode serves them all
    const Material& a = s.materials.at(0);
    const Material& b = s.materials.at(1);
    for (const TextureRef* t : {&a.base_color, &a.metallic_roughness, &a.normal, &a.occlusion, &a.emissive,
                                &b.base_color, &b.normal, &b.emissive})
        CHECK(t->image == 0);
    CHECK(a.base_color.mag_filter == Filter::Nearest);
    CHECK(a.base_color.min_filter == MinFilter::NearestMipmapNearest);
    CHECK(a.base_color.wrap_s == Wrap::ClampToEdge);
    CHECK(a.base_color.wrap_t == Wrap::Repeat);
    CHECK(a.metallic_roughness.mag_filter == Filter::Linear);
    CHECK(a.metallic_roughness.min_filter == MinFilter::LinearMipmapNearest);
    CHECK(a.metallic_roughness.wrap_s == Wrap::Repeat);
    CHECK(a.metallic_roughness.wrap_t == Wrap::MirroredRepeat);
    CHECK(a.normal.min_filter == MinFilter::NearestMipmapLinear);
    CHECK(a.normal.mag_filter == Filter::Linear);
    CHECK(a.occlusion.min_filter == MinFilter::Linear);
    CHECK(a.emissive.mag_filter == Filter::Linear);  // an empty sampler: the defaults
    CHECK(a.emissive.min_filter == MinFilter::LinearMipmapLinear);
    CHECK(b.base_color.mag_filter == Filter::Linear);  // bad enums: the defaults
    CHECK(b.base_color.min_filter == MinFilter::LinearMipmapLinear);
    CHECK(b.normal.mag_filter == Filter::Linear);  // no sampler
    CHECK(b.normal.min_filter == MinFilter::LinearMipmapLinear);
    CHECK(b.emissive.min_filter == MinFilter::Nearest);
    // One warning per bad value, naming it as the file writes it, though two textures use the sampler.
    CHECK(warnings_with(s, "sampler 5: magFilter 1234 is not NEAREST (9728) or LINEAR (9729), LINEAR used") == 1);
    CHECK(warnings_with(s, "sampler 5: minFilter 4294977024 is not a glTF minification filter") == 1);
    CHECK(s.warnings.size() == 2);
}

TEST_CASE("TRIANGLE_STRIP and TRIANGLE_FAN become triangle lists with the spec's winding") {
    test::TempDir dir("gltf_core");
    Gltf g;
    const int pos = g.floats(kFive, "VEC3", 3);
    const int idx = g.indices({4, 3, 2, 1, 0});
    const std::string p = "{\"attributes\": {\"POSITION\": " + std::to_string(pos) + "}";
    const std::string rest = one_mesh(p + ", \"mode\": 5}, " + p + ", \"mode\": 6}, " + p + ", \"mode\": 5, \"indices\": " +
                                      std::to_string(idx) + "}");
    const Scene s = load_text(dir, "strips.gltf", g.json(rest));
    check_mesh_sane(s);
    REQUIRE(s.meshes.size() == 3);
    // p_i = {v_i, v_(i + 1 + i % 2), v_(i + 2 - i % 2)}
    CHECK(s.meshes[0].indices == std::vector<std::uint32_t>{0, 1, 2, 1, 3, 2, 2, 3, 4});
    // p_i = {v_(i + 1), v_(i + 2), v_0}
    CHECK(s.meshes[1].indices == std::vector<std::uint32_t>{1, 2, 0, 2, 3, 0, 3, 4, 0});
    // Through an index list: v_i is indices[i].
    CHECK(s.meshes[2].indices == std::vector<std::uint32_t>{4, 3, 2, 3, 1, 2, 2, 1, 0});
    for (const Mesh& m : s.meshes) CHECK(m.topology == Mesh::Topology::Triangles);
    // Every strip triangle keeps the first one's facing: all normals point the same way (+z or -z).
    for (const glm::vec3& n : s.meshes[0].normals) CHECK(std::abs(n.z) == doctest::Approx(1.0f));
    const glm::vec3 n0 = s.meshes[0].normals[0];
    for (const glm::vec3& n : s.meshes[0].normals) CHECK(n == n0);

    // A mirroring node turns every triangle around, strips and fans too.
    const Scene m = load_text(dir, "mirror.gltf",
                              g.json(one_mesh(p + ", \"mode\": 5}, " + p + ", \"mode\": 6}", ", \"scale\": [-1, 1, 1]")));
    CHECK(m.meshes.at(0).indices == std::vector<std::uint32_t>{0, 2, 1, 1, 2, 3, 2, 4, 3});
    CHECK(m.meshes.at(1).indices == std::vector<std::uint32_t>{1, 0, 2, 2, 0, 3, 3, 0, 4});
}

TEST_CASE("LINES, LINE_STRIP, LINE_LOOP and POINTS become line pairs and points, without made-up normals") {
    test::TempDir dir("gltf_core");
    Gltf g;
    const int pos = g.floats(kFive, "VEC3", 3);
    const int nrm = g.floats({0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1}, "VEC3", 3);
    const int uv = g.floats({0, 0, 0, 1, 1, 0, 1, 1, 2, 0}, "VEC2", 2);
    const std::string p = "{\"attributes\": {\"POSITION\": " + std::to_string(pos) + "}";
    const std::string rest = one_mesh(p + ", \"mode\": 1}, " + p + ", \"mode\": 3}, " + p + ", \"mode\": 2}, " + p +
                                      ", \"mode\": 0}, {\"attributes\": {\"POSITION\": " + std::to_string(pos) +
                                      ", \"NORMAL\": " + std::to_string(nrm) + ", \"TEXCOORD_0\": " +
                                      std::to_string(uv) + "}, \"mode\": 3}");
    const Scene s = load_text(dir, "lines.gltf", g.json(rest));
    check_mesh_sane(s);
    REQUIRE(s.meshes.size() == 5);
    CHECK(s.meshes[0].topology == Mesh::Topology::Lines);
    CHECK(s.meshes[0].indices == std::vector<std::uint32_t>{0, 1, 2, 3});  // 5 indices: the odd one dropped
    CHECK(any_warning(s, "index count 5 not a multiple of 2, truncated"));
    CHECK(s.meshes[0].positions.size() == 4);  // the unused vertex is removed
    CHECK(s.meshes[1].topology == Mesh::Topology::Lines);
    CHECK(s.meshes[1].indices == std::vector<std::uint32_t>{0, 1, 1, 2, 2, 3, 3, 4});
    CHECK(s.meshes[2].topology == Mesh::Topology::Lines);
    CHECK(s.meshes[2].indices == std::vector<std::uint32_t>{0, 1, 1, 2, 2, 3, 3, 4, 4, 0});  // closed
    CHECK(s.meshes[3].topology == Mesh::Topology::Points);
    CHECK(s.meshes[3].indices == std::vector<std::uint32_t>{0, 1, 2, 3, 4});
    for (int i = 0; i < 4; ++i) {
        CHECK(s.meshes[std::size_t(i)].normals.empty());
        CHECK(s.meshes[std::size_t(i)].tangents.empty());
    }
    // With normals and UVs they are kept (normalised) and tangents are made (no triangle: any perpendicular).
    const Mesh& lit = s.meshes[4];
    REQUIRE(lit.normals.size() == 5);
    for (const glm::vec3& n : lit.normals) CHECK(n == glm::vec3(0, 0, 1));
    REQUIRE(lit.tangents.size() == 5);
    for (const glm::vec4& t : lit.tangents) CHECK(std::abs(glm::dot(glm::vec3(t), lit.normals[0])) < 1e-6f);
    // A file of only lines and points is a scene: its bounds are the vertices'.
    CHECK(s.triangle_count() == 0);
    const Bounds b = s.bounds();
    CHECK(b.lo == glm::vec3(0, 0, 0));
    CHECK(b.hi == glm::vec3(2, 1, 0));
}

TEST_CASE("too few indices for a topology skip the primitive with a warning; NaN vertices drop their lines") {
    test::TempDir dir("gltf_core");
    Gltf g;
    const int pos = g.floats(kFive, "VEC3", 3);
    const int two = g.indices({0, 1});
    const int one = g.indices({2});
    const float nan = std::nanf("");
    const int bad = g.floats({0, 0, 0, nan, 0, 0, 1, 1, 0, 2, 2, 0}, "VEC3", 3);
    auto prim = [&](int mode, int indices) {
        return "{\"attributes\": {\"POSITION\": " + std::to_string(pos) + "}, \"mode\": " + std::to_string(mode) +
               ", \"indices\": " + std::to_string(indices) + "}";
    };
    const std::string rest = one_mesh(prim(5, two) + ", " + prim(6, two) + ", " + prim(3, one) + ", " + prim(2, one) +
                                      ", " + prim(0, one) + ", {\"attributes\": {\"POSITION\": " + std::to_string(bad) +
                                      "}, \"mode\": 3}");
    const Scene s = load_text(dir, "few.gltf", g.json(rest));
    check_mesh_sane(s);
    CHECK(any_warning(s, "mesh 0 primitive 0: 2 indices, too few for a triangle strip (at least 3), skipped"));
    CHECK(any_warning(s, "mesh 0 primitive 1: 2 indices, too few for a triangle fan (at least 3), skipped"));
    CHECK(any_warning(s, "mesh 0 primitive 2: 1 indices, too few for a line strip (at least 2), skipped"));
    CHECK(any_warning(s, "mesh 0 primitive 3: 1 indices, too few for a line loop (at least 2), skipped"));
    REQUIRE(s.meshes.size() == 2);
    CHECK(s.meshes[0].topology == Mesh::Topology::Points);
    CHECK(s.meshes[0].positions.size() == 1);
    CHECK(s.meshes[1].indices == std::vector<std::uint32_t>{0, 1});  // (0,1) and (1,2) touch the NaN vertex; (2,3) is kept
    CHECK(s.meshes[1].positions.size() == 2);
    CHECK(any_warning(s, "dropped 2 lines or points with NaN/Inf positions"));
    // An unknown mode is skipped by name; nothing left to draw is still "no triangles".
    test::write_text(dir.file("mode9.gltf"), g.json(one_mesh(prim(9, two))));
    CHECK(load_error(dir.file("mode9.gltf")).find("mode9.gltf: no triangles") != std::string::npos);
    test::write_text(dir.file("mode9b.gltf"), g.json(one_mesh(prim(9, two) + ", " + prim(0, one))));
    const Scene m9 = load_scene(dir.file("mode9b.gltf"));
    CHECK(any_warning(m9, "mesh 0 primitive 0: mode 9 is not a glTF primitive mode, skipped"));
    // An index out of range in a strip is corrupt.
    const int big = g.indices({0, 1, 7});
    test::write_text(dir.file("big.gltf"), g.json(one_mesh(prim(5, big))));
    CHECK(load_error(dir.file("big.gltf")).find("big.gltf: mesh 0 primitive 0: index 7 out of range (5 vertices)") !=
          std::string::npos);
}

TEST_CASE("asset.minVersion above 2.0 and unimplemented required extensions are refused by render in one line") {
    using namespace prast::cli_test;
    CliSandbox box;
    Gltf g;
    const int pos = g.floats({-1, -1, 0, 1, -1, 0, 0, 1, 0}, "VEC3", 3);
    const std::string rest = one_mesh("{\"attributes\": {\"POSITION\": " + std::to_string(pos) + "}}");
    auto run = [&](const std::string& name, const std::string& json) {
        cli_test::write_text(box.work() / name, json);
        return box.run_exe(PRAST_RENDER_EXE, {name, "-o", "o.png", "--size", "16x16"});
    };
    CliRun r = run("v21.gltf", g.json(rest, "{\"version\": \"2.1\", \"minVersion\": \"2.1\"}"));
    CHECK(r.code == 1);
    CHECK(r.err == "render: v21.gltf: asset.minVersion 2.1 is required, prast loads glTF 2.0\n");
    r = run("v3.gltf", g.json(rest, "{\"version\": \"3.0\", \"minVersion\": \"3.0\"}"));
    CHECK(r.err == "render: v3.gltf: asset.minVersion 3.0 is required, prast loads glTF 2.0\n");
    r = run("v210.gltf", g.json(rest, "{\"version\": \"2.10\", \"minVersion\": \"2.10\"}"));
    CHECK(r.code == 1);
    r = run("bad.gltf", g.json(rest, "{\"version\": \"2.0\", \"minVersion\": \"2.0.1\"}"));
    CHECK(r.code == 1);
    CHECK(r.err == "render: bad.gltf: asset.minVersion '2.0.1' is not a glTF version (MAJOR.MINOR)\n");
    r = run("long.gltf", g.json(rest, "{\"version\": \"2.0\", \"minVersion\": \"" + std::string(5000, '9') + "\"}"));
    CHECK(r.code == 1);
    CHECK(lines_of(r.err).size() == 1);
    CHECK(r.err.size() < 300);
    // 2.0 and a later version with minVersion 2.0 load.
    r = run("v20.gltf", g.json(rest, "{\"version\": \"2.0\", \"minVersion\": \"2.0\"}"));
    CHECK(r.code == 0);
    r = run("v25.gltf", g.json(rest, "{\"version\": \"2.5\", \"minVersion\": \"2.0\"}"));
    CHECK(r.code == 0);

    // A required extension prast does not implement, even a material one it used to tolerate.
    for (const char* ext : {"KHR_materials_iridescence", "KHR_materials_anisotropy", "EXT_foo"}) {
        r = run("req.gltf", g.json("\"extensionsUsed\": [\"" + std::string(ext) + "\"], \"extensionsRequired\": [\"" +
                                   ext + "\"], " + rest));
        CHECK(r.code == 1);
        CHECK(r.err == "render: req.gltf: required extension " + std::string(ext) + " is not supported\n");
    }
    // Implemented ones load; an optional unsupported one is one warning.
    r = run("ok.gltf", g.json("\"extensionsUsed\": [\"KHR_materials_pbrSpecularGlossiness\", \"KHR_mesh_quantization\"],"
                              " \"extensionsRequired\": [\"KHR_materials_pbrSpecularGlossiness\", \"KHR_mesh_quantization\"], " +
                              rest));
    CHECK(r.code == 0);
    r = run("opt.gltf",
            g.json(one_mesh("{\"attributes\": {\"POSITION\": " + std::to_string(pos) + "}, \"material\": 0}") +
                   "\"extensionsUsed\": [\"KHR_materials_anisotropy\"], \"materials\": [{\"extensions\": "
                   "{\"KHR_materials_anisotropy\": {}}}], "));
    CHECK(r.code == 0);
    CHECK(std::count(r.err.begin(), r.err.end(), '\n') >= 1);
    std::size_t clearcoat = 0;
    for (const std::string& line : lines_of(r.err)) clearcoat += line.find("KHR_materials_anisotropy") != std::string::npos;
    CHECK(clearcoat == 1);
}

TEST_CASE("KHR_materials_pbrSpecularGlossiness: factors converted exactly where metal-rough can hold them") {
    test::TempDir dir("gltf_core");
    Gltf g;
    const int pos = g.floats({0, 0, 0, 1, 0, 0, 0, 1, 0}, "VEC3", 3);
    std::string prims;
    const char* const materials[] = {
        R"({"diffuseFactor": [0.5, 0.4, 0.3, 0.8], "specularFactor": [0.2, 0.2, 0.2], "glossinessFactor": 0.7})",
        R"({"diffuseFactor": [0, 0, 0, 1], "specularFactor": [1.0, 0.766, 0.336], "glossinessFactor": 0.9})",
        R"({})",
        R"({"diffuseFactor": [0.6, 0.6, 0.6, 1], "specularFactor": [0.9, 0.5, 0.1], "glossinessFactor": 0.25})",
        R"({"diffuseFactor": [0.5, 0.5, 0.5, 1], "specularFactor": [0.04, 0.04, 0.04]})",
        R"({"diffuseFactor": [0.5, "x", 0.5, 1], "glossinessFactor": 7})",
    };
    std::string mats;
    for (std::size_t i = 0; i < 6; ++i) {
        prims += (i ? ", " : "") + std::string("{\"attributes\": {\"POSITION\": ") + std::to_string(pos) +
                 "}, \"material\": " + std::to_string(i) + "}";
        mats += (i ? ", " : "") + std::string("{\"pbrMetallicRoughness\": {\"baseColorFactor\": [0.1, 0.1, 0.1, 1], "
                                              "\"metallicFactor\": 0.3}, \"extensions\": "
                                              "{\"KHR_materials_pbrSpecularGlossiness\": ") +
                materials[i] + "}}";
    }
    const Scene s = load_text(dir, "sg.gltf",
                              g.json("\"extensionsUsed\": [\"KHR_materials_pbrSpecularGlossiness\"], " + one_mesh(prims) +
                                     "\"materials\": [" + mats + "], "));
    REQUIRE(s.materials.size() >= 6);
    CHECK(!any_warning(s, "KHR_materials_pbrSpecularGlossiness ignored"));

    // Grey specular s over a diffuse colour: metallic 0, base = diffuse (1 - s), f0(ior) = s.
    const Material& a = s.materials[0];
    CHECK(a.metallic_factor == 0.0f);
    CHECK(a.base_color_factor.r == doctest::Approx(0.5 * 0.8).epsilon(1e-7));
    CHECK(a.base_color_factor.g == doctest::Approx(0.4 * 0.8).epsilon(1e-7));
    CHECK(a.base_color_factor.b == doctest::Approx(0.3 * 0.8).epsilon(1e-7));
    CHECK(a.base_color_factor.a == 0.8f);
    CHECK(a.roughness_factor == doctest::Approx(0.3).epsilon(1e-7));
    CHECK(f0_of(a.ior) == doctest::Approx(0.2).epsilon(1e-5));
    CHECK(!a.base_color.valid());
    CHECK(!a.metallic_roughness.valid());

    // No diffuse (a metal): metallic 1, base = specular.
    const Material& b = s.materials[1];
    CHECK(b.metallic_factor == 1.0f);
    CHECK(b.base_color_factor == glm::vec4(1.0f, 0.766f, 0.336f, 1.0f));
    CHECK(b.roughness_factor == doctest::Approx(0.1).epsilon(1e-6));

    // The defaults: diffuse 1, specular 1, glossiness 1 -- c_diff = 0, a smooth white metal.
    const Material& c = s.materials[2];
    CHECK(c.metallic_factor == 1.0f);
    CHECK(c.base_color_factor == glm::vec4(1.0f));
    CHECK(c.roughness_factor == 0.0f);

    // A coloured specular over a diffuse colour: the brightness solve, ior 1.5.
    const Material& d = s.materials[3];
    CHECK(d.ior == 1.5f);
    const double k = 1.0 - 0.9;
    const double bd = std::sqrt((0.299 + 0.587 + 0.114) * (0.6 * k) * (0.6 * k));
    const double bs = std::sqrt(0.299 * 0.81 + 0.587 * 0.25 + 0.114 * 0.01);
    const double qb = bd + bs - 0.08, qc = 0.04 - bs;
    const double metal = (-qb + std::sqrt(qb * qb - 4 * 0.04 * qc)) / 0.08;
    CHECK(d.metallic_factor == doctest::Approx(metal).epsilon(1e-6));
    CHECK(d.roughness_factor == doctest::Approx(0.75).epsilon(1e-7));
    for (int i = 0; i < 3; ++i) CHECK((d.base_color_factor[i] >= 0.0f && d.base_color_factor[i] <= 1.0f));
    const double spec[3] = {0.9, 0.5, 0.1};
    for (int i = 0; i < 3; ++i) {
        const double from_d = 0.6 * k / (1 - metal), from_s = (spec[i] - 0.04 * (1 - metal)) / metal;
        const double want = std::clamp(from_d + (from_s - from_d) * metal * metal, 0.0, 1.0);
        CHECK(d.base_color_factor[i] == doctest::Approx(want).epsilon(1e-6));
    }

    // The dielectric's own specular (0.04 grey): metallic 0, base = 0.96 diffuse, f0 0.04.
    const Material& e = s.materials[4];
    CHECK(e.metallic_factor == 0.0f);
    CHECK(e.base_color_factor.r == doctest::Approx(0.5 * 0.96).epsilon(1e-7));
    CHECK(f0_of(e.ior) == doctest::Approx(0.04).epsilon(1e-5));
    CHECK(e.roughness_factor == 0.0f);

    // Bad values: one warning each, the defaults used (glossiness is clamped like the core factors).
    CHECK(any_warning(s, "KHR_materials_pbrSpecularGlossiness: bad diffuseFactor, default used"));
    CHECK(s.materials[5].roughness_factor == 0.0f);
}

TEST_CASE("KHR_materials_pbrSpecularGlossiness textures: a dielectric's diffuse texture is the base colour; others are converted per texel") {
    test::TempDir dir("gltf_core");
    Gltf g;
    const int pos = g.floats({0, 0, 0, 1, 0, 0, 0, 1, 0}, "VEC3", 3);
    const int uv = g.floats({0, 0, 1, 0, 0, 1}, "VEC2", 2);
    const std::vector<std::uint8_t> diffuse = {255, 128, 0, 255, 10, 200, 30, 128, 0, 0, 0, 255, 64, 64, 64, 0};
    const std::vector<std::uint8_t> sg = {10, 10, 10, 255, 255, 200, 100, 128, 0, 0, 0, 0, 128, 128, 128, 64};
    const std::string dpng = png_rgba(diffuse), spng = png_rgba(sg);
    std::string prims;
    for (int i = 0; i < 2; ++i)
        prims += (i ? ", " : "") + std::string("{\"attributes\": {\"POSITION\": ") + std::to_string(pos) +
                 ", \"TEXCOORD_0\": " + std::to_string(uv) + "}, \"material\": " + std::to_string(i) + "}";
    const std::string rest =
        one_mesh(prims) + "\"images\": [{\"uri\": \"" + png_uri(dpng) + "\"}, {\"uri\": \"" + png_uri(spng) + "\"}], "
        "\"samplers\": [{\"magFilter\": 9728}], "
        "\"textures\": [{\"source\": 0, \"sampler\": 0}, {\"source\": 1}], \"materials\": ["
        "{\"extensions\": {\"KHR_materials_pbrSpecularGlossiness\": {\"diffuseTexture\": {\"index\": 0}, "
        "\"diffuseFactor\": [1, 0.5, 1, 1], \"specularFactor\": [0.25, 0.25, 0.25]}}},"
        "{\"extensions\": {\"KHR_materials_pbrSpecularGlossiness\": {\"diffuseTexture\": {\"index\": 0}, "
        "\"specularGlossinessTexture\": {\"index\": 1}, \"glossinessFactor\": 0.5, \"specularFactor\": [1, 1, 0.5]}}}], ";
    const Scene s = load_text(dir, "sgtex.gltf", g.json(rest));

    const Material& a = s.materials.at(0);
    CHECK(a.base_color.image == 0);  // the diffuse image itself
    CHECK(a.base_color.mag_filter == Filter::Nearest);
    CHECK(a.base_color_factor.r == doctest::Approx(0.75).epsilon(1e-7));
    CHECK(a.base_color_factor.g == doctest::Approx(0.375).epsilon(1e-7));
    CHECK(a.metallic_factor == 0.0f);
    CHECK(f0_of(a.ior) == doctest::Approx(0.25).epsilon(1e-5));

    // Texel by texel: the formulas of the factors on factor x texel.
    const Material& b = s.materials.at(1);
    REQUIRE(b.base_color.valid());
    REQUIRE(b.metallic_roughness.valid());
    CHECK(b.base_color.mag_filter == Filter::Nearest);  // the diffuse texture's sampler
    CHECK(b.base_color_factor == glm::vec4(1.0f));
    CHECK(b.metallic_factor == 1.0f);
    CHECK(b.roughness_factor == 1.0f);
    CHECK(b.ior == 1.5f);
    const ImageSource& bs = s.images.at(std::size_t(b.base_color.image));
    const ImageSource& ms = s.images.at(std::size_t(b.metallic_roughness.image));
    REQUIRE(bs.decoded);
    REQUIRE(ms.decoded);
    REQUIRE(bs.decoded->width == 2);
    const Image dimg = decode_image(s.images[0], true), simg = decode_image(s.images[1], true);
    for (int y = 0; y < 2; ++y)
        for (int x = 0; x < 2; ++x) {
            CAPTURE(x);
            CAPTURE(y);
            const glm::dvec4 dt(dimg.at(x, y)), st(simg.at(x, y));
            const glm::dvec3 spec = glm::dvec3(1, 1, 0.5) * glm::dvec3(st);
            const double gloss = 0.5 * st.a;
            const glm::vec4 base = bs.decoded->at(x, y), mr = ms.decoded->at(x, y);
            CHECK(mr.g == doctest::Approx(1.0 - gloss).epsilon(1e-6));  // roughness
            CHECK(base.a == doctest::Approx(dt.a).epsilon(1e-6));      // alpha
            const double strongest = std::max({spec.r, spec.g, spec.b});
            const glm::dvec3 c_diff = glm::dvec3(dt) * (1.0 - strongest);
            if (c_diff == glm::dvec3(0.0)) {  // metal texels: base = specular, metallic 1
                CHECK(mr.b == 1.0f);
                for (int i = 0; i < 3; ++i) CHECK(base[i] == doctest::Approx(spec[i]).epsilon(1e-6));
            }
            for (int i = 0; i < 4; ++i) CHECK((base[i] >= 0.0f && base[i] <= 1.0f));
            CHECK((mr.b >= 0.0f && mr.b <= 1.0f));
        }
    // The black diffuse texel (1, 0) is a metal whatever its specular.
    CHECK(ms.decoded->at(1, 0).b == 1.0f);
}

TEST_CASE("OBJ vertex colours: v x y z r g b gives colours; a file without keeps none") {
    test::TempDir dir("gltf_core");
    const Scene c = load_text(dir, "c.obj", "v 0 0 0 1 0 0\nv 1 0 0 0 0.5 0\nv 0 1 0 0 0 0.25\nf 1 2 3\n");
    REQUIRE(c.meshes.size() == 1);
    REQUIRE(c.meshes[0].colors.size() == 3);
    CHECK(c.meshes[0].colors[0] == glm::vec4(1, 0, 0, 1));
    CHECK(c.meshes[0].colors[1] == glm::vec4(0, 0.5f, 0, 1));
    CHECK(c.meshes[0].colors[2] == glm::vec4(0, 0, 0.25f, 1));
    const Scene p = load_text(dir, "p.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
    CHECK(p.meshes.at(0).colors.empty());
    // Only some vertices coloured: none are (tinyobjloader's rule).
    const Scene m = load_text(dir, "m.obj", "v 0 0 0 1 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
    CHECK(m.meshes.at(0).colors.empty());
    // Out of [0, 1]: clamped.
    const Scene o = load_text(dir, "o.obj", "v 0 0 0 2 -1 0.5\nv 1 0 0 0 0 0\nv 0 1 0 0 0 0\nf 1 2 3\n");
    CHECK(o.meshes.at(0).colors.at(0) == glm::vec4(1, 0, 0.5f, 1));
}

TEST_CASE("fuzzed files with the new features load sane scenes or throw one-line LoadErrors") {
    test::TempDir dir("gltf_core");
    Gltf g;
    const int pos = g.floats(kFive, "VEC3", 3);
    const int col = g.u8({255, 0, 0, 255, 0, 255, 0, 128, 0, 0, 255, 0, 9, 9, 9, 9, 1, 2, 3, 4}, "VEC4", 4, true);
    const int uv = g.floats({0, 0, 0, 1, 1, 0, 1, 1, 2, 0}, "VEC2", 2);
    const int idx = g.indices({0, 1, 2, 3, 4, 0});
    std::string prims;
    for (int mode = 0; mode <= 6; ++mode)
        prims += (mode ? ", " : "") + std::string("{\"attributes\": {\"POSITION\": ") + std::to_string(pos) +
                 ", \"COLOR_0\": " + std::to_string(col) + ", \"TEXCOORD_0\": " + std::to_string(uv) +
                 ", \"TEXCOORD_1\": " + std::to_string(uv) + "}, \"indices\": " + std::to_string(idx) +
                 ", \"mode\": " + std::to_string(mode) + ", \"material\": " + std::to_string(mode % 2) + "}";
    const std::string original =
        g.json(one_mesh(prims) + "\"images\": [{\"uri\": \"" + png_uri(png_rgba(std::vector<std::uint8_t>(16, 77))) +
                   "\"}], \"samplers\": [{\"magFilter\": 9728, \"minFilter\": 9986}], \"textures\": [{\"source\": 0, "
                   "\"sampler\": 0}], \"materials\": [{\"pbrMetallicRoughness\": {\"baseColorTexture\": {\"index\": 0, "
                   "\"texCoord\": 1}}, \"normalTexture\": {\"index\": 0, \"texCoord\": 1}}, {\"extensions\": "
                   "{\"KHR_materials_pbrSpecularGlossiness\": {\"diffuseTexture\": {\"index\": 0}, "
                   "\"specularGlossinessTexture\": {\"index\": 0, \"texCoord\": 1}}}}], ",
               "{\"version\": \"2.0\", \"minVersion\": \"2.0\"}");
    const Scene s = load_text(dir, "f.gltf", original);
    check_mesh_sane(s);
    CHECK(s.meshes.size() == 7);

    std::mt19937 rng(21);
    int loaded = 0, rejected = 0;
    for (int i = 0; i < 300; ++i) {
        std::string t = original;
        const int edits = 1 + int(rng() % 3);
        for (int e = 0; e < edits; ++e) {
            // Digits changed: modes, counts, indices, enums and offsets turn wrong but stay numbers.
            for (int tries = 0; tries < 64; ++tries) {
                const std::size_t at = rng() % t.size();
                if (t[at] >= '0' && t[at] <= '9' && at < t.find("\"buffers\"")) {
                    t[at] = "0123456789-9"[rng() % 12];
                    break;
                }
            }
        }
        test::write_text(dir.file("f.gltf"), t);
        try {
            const Scene f = load_scene(dir.file("f.gltf"));
            check_mesh_sane(f);
            ++loaded;
        } catch (const LoadError& e) {
            CHECK(std::string(e.what()).find('\n') == std::string::npos);
            ++rejected;
        }
    }
    MESSAGE("gltf_core fuzz: " << loaded << " loaded, " << rejected << " rejected");
    CHECK(loaded > 0);
    CHECK(loaded + rejected == 300);
}

// The extremes of the vertices' projection (NDC) through `cam`.
struct Ndc {
    double x0 = 1e30, x1 = -1e30, y0 = 1e30, y1 = -1e30;
};
Ndc project_all(const Scene& s, const Camera& cam, float aspect) {
    const glm::dmat4 vp = glm::dmat4(cam.projection(aspect)) * glm::dmat4(cam.view());
    Ndc n;
    for (const Mesh& m : s.meshes)
        for (const glm::vec3& p : m.positions) {
            const glm::dvec4 c = vp * glm::dvec4(glm::dvec3(p), 1.0);
            n.x0 = std::min(n.x0, c.x / c.w), n.x1 = std::max(n.x1, c.x / c.w);
            n.y0 = std::min(n.y0, c.y / c.w), n.y1 = std::max(n.y1, c.y / c.w);
        }
    return n;
}

TEST_CASE("default framing: the vertices fill 90% of the tighter axis, centred; a turntable keeps them in frame") {
    // A long bar off the origin and a random cloud: the bounding sphere of
    // either leaves the model small.
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> u(-1.0f, 1.0f);
    for (int shape = 0; shape < 2; ++shape)
        for (const float aspect : {16.0f / 9.0f, 1.0f, 0.5f}) {
            Scene s;
            Mesh m;
            if (shape == 0) {
                for (float x : {-4.0f, 4.0f})
                    for (float y : {0.0f, 0.5f})
                        for (float z : {-0.2f, 0.2f}) m.positions.push_back({x + 10.0f, y + 3.0f, z});
            } else {
                for (int i = 0; i < 500; ++i) m.positions.push_back({u(rng) * 2.0f, u(rng) * 0.3f, u(rng)});
            }
            s.meshes.push_back(m);
            INFO("shape " << shape << " aspect " << aspect);
            const Camera cam = frame_scene(s, 45.0f, aspect);
            const Ndc n = project_all(s, cam, aspect);
            const double fill = kFrameFill, tol = 1e-4;
            CHECK(n.x0 >= -fill - tol);
            CHECK(n.x1 <= fill + tol);
            CHECK(n.y0 >= -fill - tol);
            CHECK(n.y1 <= fill + tol);
            // One axis touches the margin on both sides; both are centred.
            const bool x_tight = n.x1 - n.x0 > n.y1 - n.y0;
            const double w = x_tight ? n.x1 - n.x0 : n.y1 - n.y0;
            CHECK(w == doctest::Approx(2.0 * fill).epsilon(1e-4));
            CHECK(std::fabs(n.x0 + n.x1) <= 1e-4);
            CHECK(std::fabs(n.y0 + n.y1) <= 1e-4);
            // The view direction is the documented one.
            const glm::vec3 d = glm::normalize(cam.eye - cam.target);
            CHECK(d.x == doctest::Approx(0.0).epsilon(1e-6));
            CHECK(d.y / d.z == doctest::Approx(0.35).epsilon(1e-5));

            // A turntable: inside the margin at the 72 sampled angles, inside
            // the frame between them.
            const Camera base = frame_scene(s, 45.0f, aspect, 360.0);
            double worst = 0.0;
            for (int k = 0; k < 144; ++k) {
                const double t = 2.0 * 3.14159265358979323846 * k / 144.0;
                Camera c = base;
                const glm::dvec3 e = glm::dvec3(base.eye - base.target);
                c.eye = base.target + glm::vec3(glm::dvec3(e.x * std::cos(t) + e.z * std::sin(t), e.y,
                                                           -e.x * std::sin(t) + e.z * std::cos(t)));
                const Ndc o = project_all(s, c, aspect);
                const double reach = std::max({-o.x0, o.x1, -o.y0, o.y1});
                if (k % 2 == 0) CHECK(reach <= fill + tol);
                worst = std::max(worst, reach);
            }
            CHECK(worst < 1.0);
        }
    // No area in view (every vertex on one line along the view): the sphere.
    Scene line;
    Mesh m;
    m.positions = {{0, 0, 0}, {0, 0.35f, 1.0f}};
    line.meshes.push_back(m);
    const Camera a = frame_scene(line, 45.0f, 1.0f), b = frame_bounds(line.bounds(), 45.0f, 1.0f);
    CHECK(a.eye == b.eye);
    CHECK(a.target == b.target);
}

} // TEST_SUITE

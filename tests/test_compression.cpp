// Compressed glTF data: EXT_meshopt_compression bufferViews (streams encoded
// by the reference library, libmeshoptimizer, independent of our decoder in
// scene/meshopt_decode.cpp) load to exactly the meshes of the uncompressed
// file and render to the same PNG bytes, each filter agrees with the
// reference decoder; hostile streams are one line naming the extension;
// EXT_texture_webp decodes to the pixels of the PNG it replaces, and
// KHR_texture_basisu falls back to its source image or is refused.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <functional>
#include <string>
#include <vector>

#include <draco/compression/encode.h>
#include <draco/mesh/mesh.h>
#include <nlohmann/json.hpp>
#include <webp/encode.h>

#include "scene/encode_png.h"
#include "scene/draco_decode.h"
#include "scene/image.h"
#include "scene/load_scene.h"
#include "scene/meshopt_decode.h"
#include "tests/cli_util.h"
#include "tests/gltf_writer.h"
#include "tests/scratch.h"
#include "tests/load_error.h"

#if defined(PRAST_HAVE_MESHOPT_ENCODER)
#include <meshoptimizer.h>
#endif

using namespace prast;
using prast::test::load_error;
using json = nlohmann::json;
using prast::gltf_test::base64;
using prast::test::read_bytes;
using prast::test::TempDir;
using prast::test::write_bytes;
using prast::test::write_text;
using prast::cli_test::CliRun;
using prast::cli_test::CliSandbox;

namespace {

std::vector<unsigned char> as_bytes(const void* p, std::size_t n) {
    const auto* b = static_cast<const unsigned char*>(p);
    return std::vector<unsigned char>(b, b + n);
}

// One bufferView's data and how it is compressed.
struct View {
    std::vector<unsigned char> raw;
    std::size_t stride = 0, count = 0;
    std::string mode = "ATTRIBUTES", filter = "NONE";
    std::vector<unsigned char> packed;  // the encoded stream
};

// A bent 9x9 grid: positions, normals and UVs (float), 16-bit triangle indices.
struct Grid {
    std::vector<float> pos, nrm, uv;
    std::vector<std::uint16_t> idx;
    Grid() {
        const int n = 9;
        for (int y = 0; y < n; ++y)
            for (int x = 0; x < n; ++x) {
                const float u = float(x) / (n - 1), v = float(y) / (n - 1);
                const float z = 0.3f * std::sin(3.0f * u) * std::cos(2.0f * v);
                pos.insert(pos.end(), {2.0f * u - 1.0f, 1.0f - 2.0f * v, z});
                const float nx = -0.9f * std::cos(3.0f * u) * std::cos(2.0f * v), ny = 0.6f * std::sin(3.0f * u) * std::sin(2.0f * v);
                const float len = std::sqrt(nx * nx + ny * ny + 1.0f);
                nrm.insert(nrm.end(), {nx / len, ny / len, 1.0f / len});
                uv.insert(uv.end(), {u, v});
            }
        for (int y = 0; y + 1 < n; ++y)
            for (int x = 0; x + 1 < n; ++x) {
                const std::uint16_t a = std::uint16_t(y * n + x), b = std::uint16_t(a + 1), c = std::uint16_t(a + n),
                                    d = std::uint16_t(c + 1);
                idx.insert(idx.end(), {a, c, b, b, c, d});
            }
    }
    std::size_t vertices() const { return pos.size() / 3; }
};

// The glTF of `views` as accessors POSITION, NORMAL, TEXCOORD_0 and indices
// (views 0..3), uncompressed (one data-URI buffer) or compressed as gltfpack
// writes it: buffer 0 a uri-less fallback, buffer 1 the streams.
json grid_model(const std::vector<View>& views, bool compressed, const char* ext = "EXT_meshopt_compression") {
    json doc = {{"asset", {{"version", "2.0"}}}};
    std::vector<unsigned char> raw, packed;
    json bviews = json::array();
    for (const View& v : views) {
        while (raw.size() % 4) raw.push_back(0);
        while (packed.size() % 4) packed.push_back(0);
        json bv = {{"buffer", 0}, {"byteOffset", raw.size()}, {"byteLength", v.raw.size()}};
        if (compressed) {
            bv["extensions"][ext] = {{"buffer", 1},         {"byteOffset", packed.size()}, {"byteLength", v.packed.size()},
                                     {"byteStride", v.stride}, {"count", v.count},          {"mode", v.mode}};
            if (v.filter != "NONE") bv["extensions"][ext]["filter"] = v.filter;
        }
        raw.insert(raw.end(), v.raw.begin(), v.raw.end());
        packed.insert(packed.end(), v.packed.begin(), v.packed.end());
        bviews.push_back(bv);
    }
    doc["bufferViews"] = bviews;
    const std::size_t n = views[0].count;
    doc["accessors"] = json::array({
        {{"bufferView", 0}, {"componentType", 5126}, {"type", "VEC3"}, {"count", n}, {"min", {-1, -1, -1}}, {"max", {1, 1, 1}}},
        {{"bufferView", 1}, {"componentType", 5126}, {"type", "VEC3"}, {"count", n}},
        {{"bufferView", 2}, {"componentType", 5126}, {"type", "VEC2"}, {"count", n}},
        {{"bufferView", 3}, {"componentType", 5123}, {"type", "SCALAR"}, {"count", views[3].count}},
    });
    doc["meshes"] = json::array({{{"primitives", json::array({{{"attributes", {{"POSITION", 0}, {"NORMAL", 1}, {"TEXCOORD_0", 2}}},
                                                               {"indices", 3}}})}}});
    doc["nodes"] = json::array({{{"mesh", 0}}});
    doc["scenes"] = json::array({{{"nodes", {0}}}});
    doc["scene"] = 0;
    if (compressed) {
        doc["extensionsUsed"] = {ext};
        doc["extensionsRequired"] = {ext};
        doc["buffers"] = json::array({{{"byteLength", raw.size()}, {"extensions", {{ext, {{"fallback", true}}}}}},
                                      {{"byteLength", packed.size()},
                                       {"uri", "data:application/octet-stream;base64," + base64(packed)}}});
    } else {
        doc["buffers"] = json::array(
            {{{"byteLength", raw.size()}, {"uri", "data:application/octet-stream;base64," + base64(raw)}}});
    }
    return doc;
}

// A .glb of `doc` with `bin` as its BIN chunk (buffer 0).
std::vector<unsigned char> glb(const json& doc, const std::vector<unsigned char>& bin) {
    std::string text = doc.dump();
    while (text.size() % 4) text += ' ';
    std::vector<unsigned char> b(bin);
    while (b.size() % 4) b.push_back(0);
    std::vector<unsigned char> out;
    const auto u32 = [&](std::uint32_t v) {
        for (int k = 0; k < 4; ++k) out.push_back(static_cast<unsigned char>(v >> (8 * k)));
    };
    out.insert(out.end(), {'g', 'l', 'T', 'F'});
    u32(2);
    u32(std::uint32_t(12 + 8 + text.size() + 8 + b.size()));
    u32(std::uint32_t(text.size()));
    u32(0x4E4F534A);
    out.insert(out.end(), text.begin(), text.end());
    u32(std::uint32_t(b.size()));
    u32(0x004E4942);
    out.insert(out.end(), b.begin(), b.end());
    return out;
}

void check_same_meshes(const Scene& a, const Scene& b) {
    REQUIRE(a.meshes.size() == 1);
    REQUIRE(b.meshes.size() == 1);
    const Mesh &m = a.meshes[0], &n = b.meshes[0];
    CHECK(m.indices == n.indices);
    REQUIRE(m.positions.size() == n.positions.size());
    REQUIRE(m.normals.size() == n.normals.size());
    REQUIRE(m.uvs.size() == n.uvs.size());
    CHECK(std::memcmp(m.positions.data(), n.positions.data(), m.positions.size() * sizeof(m.positions[0])) == 0);
    CHECK(std::memcmp(m.normals.data(), n.normals.data(), m.normals.size() * sizeof(m.normals[0])) == 0);
    CHECK(std::memcmp(m.uvs.data(), n.uvs.data(), m.uvs.size() * sizeof(m.uvs[0])) == 0);
}

// Hand-built streams (no encoder needed): 4-byte elements, one group.
std::vector<unsigned char> attribute_stream(const std::vector<std::uint32_t>& values) {
    // Header, then per byte channel: header bits (3 = 16 raw deltas) and
    // the zigzag deltas from the baseline (0), then the 32-byte tail.
    std::vector<unsigned char> s = {0xa0};
    for (int k = 0; k < 4; ++k) {
        s.push_back(0x03);
        unsigned char prev = 0;
        for (std::size_t i = 0; i < 16; ++i) {
            const unsigned char v = i < values.size() ? static_cast<unsigned char>(values[i] >> (8 * k)) : prev;
            const unsigned char d = static_cast<unsigned char>(v - prev);
            s.push_back(static_cast<unsigned char>((d & 0x80) ? ~(d << 1) : (d << 1)));
            prev = v;
        }
    }
    s.resize(s.size() + 32, 0);  // baseline element 0, padded
    return s;
}

} // namespace

TEST_SUITE("compression") {

TEST_CASE("meshopt: hand-built streams of each mode decode to their values; bad ones name the problem") {
    const std::vector<std::uint32_t> values = {7, 300, 0xdeadbeef, 5, 5, 5, 1, 0, 65536, 9};
    const std::vector<unsigned char> s = attribute_stream(values);
    std::vector<unsigned char> out(values.size() * 4);
    CHECK(meshopt::decode(meshopt::Mode::Attributes, meshopt::Filter::None, s.data(), s.size(), values.size(), 4,
                          out.data()) == "");
    CHECK(out == as_bytes(values.data(), values.size() * 4));
    CHECK(s.size() >= meshopt::min_encoded_size(meshopt::Mode::Attributes, values.size(), 4));
    // Truncated, padded, wrong header, a version-1 stream.
    std::vector<unsigned char> t(s.begin(), s.end() - 40);
    CHECK(meshopt::decode(meshopt::Mode::Attributes, meshopt::Filter::None, t.data(), t.size(), values.size(), 4,
                          out.data()).find("truncated") == 0);
    std::vector<unsigned char> longer(s);
    longer.insert(longer.begin() + 1, 3, 0);
    CHECK(meshopt::decode(meshopt::Mode::Attributes, meshopt::Filter::None, longer.data(), longer.size(),
                          values.size(), 4, out.data()).find("left over") != std::string::npos);
    std::vector<unsigned char> v1(s);
    v1[0] = 0xa1;
    CHECK(meshopt::decode(meshopt::Mode::Attributes, meshopt::Filter::None, v1.data(), v1.size(), values.size(), 4,
                          out.data()) == "attribute stream version 1 is not supported (only 0)");

    // Indices: deltas 5, +3 on baseline 0, then 100 on baseline 1, -2 on baseline 0.
    const auto zz = [](int delta, int baseline) {
        const std::uint32_t z = delta < 0 ? (std::uint32_t(~delta) << 1) | 1 : std::uint32_t(delta) << 1;
        return (z << 1) | std::uint32_t(baseline);
    };
    std::vector<unsigned char> is = {0xd1, static_cast<unsigned char>(zz(5, 0)), static_cast<unsigned char>(zz(3, 0))};
    const std::uint32_t far = zz(100, 1);  // two LEB128 bytes
    is.push_back(static_cast<unsigned char>(0x80 | (far & 127)));
    is.push_back(static_cast<unsigned char>(far >> 7));
    is.push_back(static_cast<unsigned char>(zz(-2, 0)));
    is.insert(is.end(), 4, 0);
    std::vector<unsigned char> io(4 * 4);
    CHECK(meshopt::decode(meshopt::Mode::Indices, meshopt::Filter::None, is.data(), is.size(), 4, 4, io.data()) == "");
    const std::uint32_t want[4] = {5, 8, 100, 6};
    CHECK(std::memcmp(io.data(), want, 16) == 0);
    is[0] = 0xd0;
    CHECK(meshopt::decode(meshopt::Mode::Indices, meshopt::Filter::None, is.data(), is.size(), 4, 4, io.data()) ==
          "bad header byte 0xd0 (an index stream starts with 0xd1)");

    // Triangles: 0xfe with 0x00 (restart, three new vertices), then 0x00
    // (edge 0 = (a, c) of the last pushed, next vertex).
    std::vector<unsigned char> ts = {0xe1, 0xfe, 0x00, 0x00};
    ts.insert(ts.end(), 16, 0);
    std::vector<unsigned char> to(6 * 2);
    CHECK(meshopt::decode(meshopt::Mode::Triangles, meshopt::Filter::None, ts.data(), ts.size(), 6, 2, to.data()) == "");
    const std::uint16_t tri[6] = {0, 1, 2, 0, 2, 3};
    CHECK(std::memcmp(to.data(), tri, 12) == 0);
    // The 0xfe code's extra byte missing: truncated.
    std::vector<unsigned char> tt = {0xe1, 0xfe};
    tt.insert(tt.end(), 16, 0);
    CHECK(meshopt::decode(meshopt::Mode::Triangles, meshopt::Filter::None, tt.data(), tt.size(), 3, 2, to.data())
              .find("truncated") == 0);
    // A first code reading the FIFOs before anything was pushed (fuzz_meshopt
    // against libmeshoptimizer): their contents start as the reference
    // decoder's, every index ~0, not vertex 0. Code 0x00: edge 0 and next;
    // code 0x1c: edge 1 and vertex 12.
    for (const unsigned char code : {0x00, 0x1c}) {
        CAPTURE(int(code));
        std::vector<unsigned char> fs = {0xe1, code};
        fs.insert(fs.end(), 16, 0);
        std::vector<unsigned char> fo(3 * 4);
        CHECK(meshopt::decode(meshopt::Mode::Triangles, meshopt::Filter::None, fs.data(), fs.size(), 3, 4, fo.data()) == "");
        const std::uint32_t fifo[3] = {0xffffffffu, 0xffffffffu, code == 0x00 ? 0u : 0xffffffffu};
        CHECK(std::memcmp(fo.data(), fifo, 12) == 0);
    }

    // Exponential filter: 2^e * m exactly.
    std::vector<unsigned char> ex(8);
    const std::uint32_t e1 = (std::uint32_t(std::uint8_t(-3)) << 24) | 12u, e2 = (4u << 24) | 0xfffffdu;  // 12/8, -3*16
    std::memcpy(ex.data(), &e1, 4);
    std::memcpy(ex.data() + 4, &e2, 4);
    const std::vector<unsigned char> es = attribute_stream({e1, e2});
    CHECK(meshopt::decode(meshopt::Mode::Attributes, meshopt::Filter::Exponential, es.data(), es.size(), 2, 4,
                          ex.data()) == "");
    float f[2];
    std::memcpy(f, ex.data(), 8);
    CHECK(f[0] == 1.5f);
    CHECK(f[1] == -48.0f);
}

#if defined(PRAST_HAVE_MESHOPT_ENCODER)

namespace {

std::vector<unsigned char> encode_vertices(const std::vector<unsigned char>& raw, std::size_t count, std::size_t stride) {
    meshopt_encodeVertexVersion(0);
    std::vector<unsigned char> out(meshopt_encodeVertexBufferBound(count, stride));
    out.resize(meshopt_encodeVertexBuffer(out.data(), out.size(), raw.data(), count, stride));
    return out;
}

View attribute_view(const std::vector<float>& v, std::size_t per) {
    View view;
    view.raw = as_bytes(v.data(), v.size() * 4);
    view.stride = per * 4;
    view.count = v.size() / per;
    view.packed = encode_vertices(view.raw, view.count, view.stride);
    return view;
}

View index_view(const std::vector<std::uint16_t>& idx, std::size_t vertices, bool triangles) {
    View view;
    view.raw = as_bytes(idx.data(), idx.size() * 2);
    view.stride = 2;
    view.count = idx.size();
    view.mode = triangles ? "TRIANGLES" : "INDICES";
    const std::vector<unsigned> wide(idx.begin(), idx.end());
    meshopt_encodeIndexVersion(1);
    if (triangles) {
        view.packed.resize(meshopt_encodeIndexBufferBound(idx.size(), vertices));
        view.packed.resize(meshopt_encodeIndexBuffer(view.packed.data(), view.packed.size(), wide.data(), wide.size()));
    } else {
        view.packed.resize(meshopt_encodeIndexSequenceBound(idx.size(), vertices));
        view.packed.resize(meshopt_encodeIndexSequence(view.packed.data(), view.packed.size(), wide.data(), wide.size()));
    }
    return view;
}

// gltfpack's .glb: the streams in the BIN chunk (buffer 0), buffer 1 the uri-less fallback.
std::vector<unsigned char> gltfpack_glb(const std::vector<View>& views) {
    json doc = grid_model(views, true);
    std::vector<unsigned char> packed;
    for (const View& v : views) {
        while (packed.size() % 4) packed.push_back(0);
        packed.insert(packed.end(), v.packed.begin(), v.packed.end());
    }
    std::swap(doc["buffers"][0], doc["buffers"][1]);
    doc["buffers"][0].erase("uri");
    for (json& bv : doc["bufferViews"]) {
        bv["buffer"] = 1;
        bv["extensions"]["EXT_meshopt_compression"]["buffer"] = 0;
    }
    return glb(doc, packed);
}

std::vector<View> grid_views(bool triangles = true) {
    const Grid g;
    return {attribute_view(g.pos, 3), attribute_view(g.nrm, 3), attribute_view(g.uv, 2),
            index_view(g.idx, g.vertices(), triangles)};
}

} // namespace

TEST_CASE("meshopt: a compressed model loads to exactly the uncompressed one, in .gltf and gltfpack's .glb layout") {
    TempDir dir("compression");
    const std::vector<View> views = grid_views();
    write_text(dir.file("plain.gltf"), grid_model(views, false).dump());
    const Scene plain = load_scene(dir.file("plain.gltf"));
    CHECK(plain.warnings.empty());
    for (bool triangles : {true, false}) {
        CAPTURE(triangles);
        write_text(dir.file("packed.gltf"), grid_model(grid_views(triangles), true).dump());
        const Scene packed = load_scene(dir.file("packed.gltf"));
        CHECK(packed.warnings.empty());
        check_same_meshes(plain, packed);
    }
    // KHR_meshopt_compression with the same (version 0) streams.
    write_text(dir.file("khr.gltf"), grid_model(views, true, "KHR_meshopt_compression").dump());
    check_same_meshes(plain, load_scene(dir.file("khr.gltf")));

    write_bytes(dir.file("packed.glb"), gltfpack_glb(views));
    check_same_meshes(plain, load_scene(dir.file("packed.glb")));
}

TEST_CASE("meshopt: render draws the compressed .glb to the bytes of the uncompressed file") {
    CliSandbox box;
    const std::vector<View> views = grid_views();
    write_text(box.path("plain.gltf"), grid_model(views, false).dump());
    write_bytes(box.path("packed.glb"), gltfpack_glb(views));
    const std::vector<std::string> opts = {"--size", "40x40", "--sun", "0.3,0.4,1:1,1,1"};
    const auto render = [&](const std::string& in, const std::string& out) {
        std::vector<std::string> args = {"-s", "KILL", "60", PRAST_RENDER_EXE, in, "-o", out};
        args.insert(args.end(), opts.begin(), opts.end());
        return box.run_exe("timeout", args);
    };
    const CliRun a = render("plain.gltf", "a.png"), b = render("packed.glb", "b.png");
    CAPTURE(a.err);
    CAPTURE(b.err);
    CHECK(a.code == 0);
    CHECK(b.code == 0);
    CHECK(b.err == a.err);
    const std::vector<unsigned char> pa = read_bytes(box.path("a.png")), pb = read_bytes(box.path("b.png"));
    CHECK(!pa.empty());
    CHECK(pa == pb);
    // step explains a pixel of both alike (the model's name aside).
    const auto step = [&](const std::string& in) {
        std::vector<std::string> args = {"-s", "KILL", "60", PRAST_STEP_EXE, in, "--pixel", "20,21"};
        args.insert(args.end(), opts.begin(), opts.end());
        return box.run_exe("timeout", args);
    };
    const CliRun sa = step("plain.gltf");
    CliRun sb = step("packed.glb");
    CHECK(sa.code == 0);
    CHECK(sb.code == 0);
    for (std::size_t at = sb.out.find("packed.glb"); at != std::string::npos; at = sb.out.find("packed.glb"))
        sb.out.replace(at, 10, "plain.gltf");
    CHECK(sa.out.find("srgb8") != std::string::npos);
    CHECK(sa.out == sb.out);
}

TEST_CASE("meshopt: each filter decodes as the reference decoder does (one unit at most), exponential exactly") {
    const Grid g;
    const std::size_t n = g.vertices();
    std::vector<float> vec4;  // normals with w = 1
    for (std::size_t i = 0; i < n; ++i) vec4.insert(vec4.end(), {g.nrm[3 * i], g.nrm[3 * i + 1], g.nrm[3 * i + 2], 1.0f});
    std::vector<float> quats;
    for (std::size_t i = 0; i < n; ++i) {
        const float a = 0.1f * float(i), b = 0.07f * float(i);
        const float q[4] = {std::sin(a) * std::cos(b), std::sin(a) * std::sin(b), std::cos(a) * 0.6f, std::cos(a) * 0.8f};
        quats.insert(quats.end(), q, q + 4);
    }
    struct Case {
        const char* name;
        meshopt::Filter filter;
        std::size_t stride;
        int max_diff;  // in units of the output integers (floats: exact)
    };
    for (const Case c : {Case{"oct8", meshopt::Filter::Octahedral, 4, 1}, Case{"oct16", meshopt::Filter::Octahedral, 8, 1},
                         Case{"quat", meshopt::Filter::Quaternion, 8, 1}, Case{"exp", meshopt::Filter::Exponential, 12, 0}}) {
        CAPTURE(std::string(c.name));
        std::vector<unsigned char> filtered(n * c.stride);
        if (c.filter == meshopt::Filter::Octahedral)
            meshopt_encodeFilterOct(filtered.data(), n, c.stride, c.stride == 4 ? 8 : 12, vec4.data());
        else if (c.filter == meshopt::Filter::Quaternion)
            meshopt_encodeFilterQuat(filtered.data(), n, c.stride, 11, quats.data());
        else
            meshopt_encodeFilterExp(filtered.data(), n, c.stride, 15, g.pos.data());
        const std::vector<unsigned char> packed = encode_vertices(filtered, n, c.stride);
        std::vector<unsigned char> ours(n * c.stride), ref(n * c.stride);
        REQUIRE(meshopt::decode(meshopt::Mode::Attributes, c.filter, packed.data(), packed.size(), n, c.stride,
                                ours.data()) == "");
        REQUIRE(meshopt_decodeVertexBuffer(ref.data(), n, c.stride, packed.data(), packed.size()) == 0);
        if (c.filter == meshopt::Filter::Octahedral) meshopt_decodeFilterOct(ref.data(), n, c.stride);
        if (c.filter == meshopt::Filter::Quaternion) meshopt_decodeFilterQuat(ref.data(), n, c.stride);
        if (c.filter == meshopt::Filter::Exponential) meshopt_decodeFilterExp(ref.data(), n, c.stride);
        int worst = 0;
        if (c.filter == meshopt::Filter::Exponential) {
            CHECK(ours == ref);
        } else {
            for (std::size_t i = 0; i < ours.size(); i += c.stride / 4) {
                const int a = c.stride == 4 ? int(std::int8_t(ours[i])) : int(std::int16_t(ours[i] | ours[i + 1] << 8));
                const int b = c.stride == 4 ? int(std::int8_t(ref[i])) : int(std::int16_t(ref[i] | ref[i + 1] << 8));
                worst = std::max(worst, std::abs(a - b));
            }
        }
        CHECK(worst <= c.max_diff);
    }
}

TEST_CASE("meshopt: hostile streams and JSON are one line naming the extension, before allocating a claim") {
    TempDir dir("compression_bad");
    const std::vector<View> views = grid_views();
    const std::string ext = "EXT_meshopt_compression";
    struct Case {
        const char* name;
        std::function<void(json&)> edit;
        const char* expect;  // part of the one-line error
    };
    const std::vector<Case> cases = {
        {"truncated", [&](json& d) { d["bufferViews"][0]["extensions"][ext]["byteLength"] = views[0].packed.size() - 7; },
         "bufferView 0: EXT_meshopt_compression: cannot decode: "},
        {"huge_count",
         [&](json& d) {
             d["bufferViews"][0]["extensions"][ext]["count"] = 2000000000;
             d["bufferViews"][0]["byteLength"] = std::uint64_t(24000000000);
         },
         "compressed bytes cannot hold 2000000000 elements"},
        {"wrong_count", [&](json& d) { d["bufferViews"][3]["extensions"][ext]["count"] = 9; }, "is not the bufferView's byteLength"},
        {"bad_mode", [&](json& d) { d["bufferViews"][0]["extensions"][ext]["mode"] = "SPLINES"; },
         "mode 'SPLINES' is not ATTRIBUTES, TRIANGLES or INDICES"},
        {"bad_filter", [&](json& d) { d["bufferViews"][0]["extensions"][ext]["filter"] = "WAVELET"; }, "filter 'WAVELET' is not"},
        {"filter_stride", [&](json& d) { d["bufferViews"][0]["extensions"][ext]["filter"] = "QUATERNION"; },
         "does not suit filter QUATERNION"},
        {"bad_stride", [&](json& d) { d["bufferViews"][3]["extensions"][ext]["byteStride"] = 3; }, "byteStride 3"},
        {"bad_buffer", [&](json& d) { d["bufferViews"][1]["extensions"][ext]["buffer"] = 0; }, "buffer 0 has no data"},
        {"past_buffer", [&](json& d) { d["bufferViews"][2]["extensions"][ext]["byteOffset"] = 100000; }, "exceeds buffer 1"},
        {"uncompressed_view", [&](json& d) { d["bufferViews"][2].erase("extensions"); }, "uri-less meshopt fallback"},
        {"no_count", [&](json& d) { d["bufferViews"][2]["extensions"][ext].erase("count"); }, "no count"},
    };
    for (const Case& c : cases) {
        CAPTURE(std::string(c.name));
        json doc = grid_model(views, true);
        c.edit(doc);
        write_text(dir.file("bad.gltf"), doc.dump());
        const std::string err = load_error(dir.file("bad.gltf"));
        CAPTURE(err);
        CHECK(err.find(c.expect) != std::string::npos);
        CHECK(err.find("EXT_meshopt_compression") != std::string::npos);
        CHECK(err.find('\n') == std::string::npos);
    }
    // A corrupt stream over a fallback that has the data: a warning and the data.
    json doc = grid_model(views, true);
    json plain = grid_model(views, false);
    doc["buffers"][0] = plain["buffers"][0];
    doc["extensionsRequired"] = json::array();
    doc["bufferViews"][0]["extensions"][ext]["byteLength"] = 40;
    write_text(dir.file("fallback.gltf"), doc.dump());
    write_text(dir.file("plain.gltf"), plain.dump());
    const Scene s = load_scene(dir.file("fallback.gltf"));
    REQUIRE(s.warnings.size() == 1);
    CHECK(s.warnings[0].find("bufferView 0: EXT_meshopt_compression: cannot decode (") != std::string::npos);
    check_same_meshes(load_scene(dir.file("plain.gltf")), s);

    // render: one line, exit 1, for the huge claim (within a 4 GB address
    // space, which AddressSanitizer's reservations cannot run in).
#ifndef PRAST_SANITIZE_BUILD
    CliSandbox box;
    json huge = grid_model(views, true);
    huge["bufferViews"][0]["extensions"][ext]["count"] = 2000000000;
    huge["bufferViews"][0]["byteLength"] = std::uint64_t(24000000000);
    write_text(box.path("h.gltf"), huge.dump());
    const CliRun r = box.run_exe("timeout", {"-s", "KILL", "60", PRAST_RENDER_EXE, "h.gltf", "-o", "o.png", "--size", "16x16"},
                                 "ulimit -v 4000000");
    CHECK(r.code == 1);
    CHECK(r.err.find("EXT_meshopt_compression") != std::string::npos);
    CHECK(std::count(r.err.begin(), r.err.end(), '\n') == 1);
#endif
}

namespace {

// The grid as a Draco stream (libdraco's encoder, no quantization: lossless),
// and the ids of its POSITION, NORMAL and TEXCOORD_0 attributes.
std::vector<unsigned char> draco_grid(int method, int ids[3]) {
    const Grid g;
    const std::size_t n = g.vertices();
    draco::Mesh mesh;
    mesh.set_num_points(std::uint32_t(n));
    const std::vector<float>* data[3] = {&g.pos, &g.nrm, &g.uv};
    const draco::GeometryAttribute::Type types[3] = {draco::GeometryAttribute::POSITION, draco::GeometryAttribute::NORMAL,
                                                     draco::GeometryAttribute::TEX_COORD};
    for (int a = 0; a < 3; ++a) {
        const int per = a == 2 ? 2 : 3;
        draco::GeometryAttribute ga;
        ga.Init(types[a], nullptr, std::uint8_t(per), draco::DT_FLOAT32, false, sizeof(float) * std::size_t(per), 0);
        const int id = mesh.AddAttribute(ga, true, std::uint32_t(n));
        for (std::size_t i = 0; i < n; ++i)
            mesh.attribute(id)->SetAttributeValue(draco::AttributeValueIndex(std::uint32_t(i)), &(*data[a])[i * std::size_t(per)]);
        ids[a] = int(mesh.attribute(id)->unique_id());
    }
    for (std::size_t t = 0; t < g.idx.size(); t += 3)
        mesh.AddFace({draco::PointIndex(g.idx[t]), draco::PointIndex(g.idx[t + 1]), draco::PointIndex(g.idx[t + 2])});
    draco::Encoder encoder;
    encoder.SetEncodingMethod(method);
    draco::EncoderBuffer out;
    REQUIRE(encoder.EncodeMeshToBuffer(mesh, &out).ok());
    return std::vector<unsigned char>(out.data(), out.data() + out.size());
}

// The sequential stream with its faces varint (byte 11) claiming 2^31 - 1 faces.
std::vector<unsigned char> huge_faces(const std::vector<unsigned char>& b) {
    std::size_t end = 11;
    while (end < b.size() && (b[end] & 0x80)) ++end;
    std::vector<unsigned char> out(b.begin(), b.begin() + 11);
    out.insert(out.end(), {0xff, 0xff, 0xff, 0xff, 0x07});
    out.insert(out.end(), b.begin() + std::ptrdiff_t(end) + 1, b.end());
    return out;
}

json draco_model(const std::vector<unsigned char>& stream, const int ids[3]) {
    const Grid g;
    const std::size_t n = g.vertices();
    json doc = {{"asset", {{"version", "2.0"}}},
                {"extensionsUsed", {"KHR_draco_mesh_compression"}},
                {"extensionsRequired", {"KHR_draco_mesh_compression"}}};
    doc["buffers"] = json::array({{{"byteLength", stream.size()}, {"uri", "data:application/octet-stream;base64," + base64(stream)}}});
    doc["bufferViews"] = json::array({{{"buffer", 0}, {"byteLength", stream.size()}}});
    doc["accessors"] = json::array({
        {{"componentType", 5126}, {"type", "VEC3"}, {"count", n}, {"min", {-1, -1, -1}}, {"max", {1, 1, 1}}},
        {{"componentType", 5126}, {"type", "VEC3"}, {"count", n}},
        {{"componentType", 5126}, {"type", "VEC2"}, {"count", n}},
        {{"componentType", 5123}, {"type", "SCALAR"}, {"count", g.idx.size()}},
    });
    json ext = {{"bufferView", 0}, {"attributes", {{"POSITION", ids[0]}, {"NORMAL", ids[1]}, {"TEXCOORD_0", ids[2]}}}};
    json prim = {{"attributes", {{"POSITION", 0}, {"NORMAL", 1}, {"TEXCOORD_0", 2}}}, {"indices", 3},
                 {"extensions", {{"KHR_draco_mesh_compression", ext}}}};
    doc["meshes"] = json::array({{{"primitives", json::array({prim})}}});
    doc["nodes"] = json::array({{{"mesh", 0}}});
    doc["scenes"] = json::array({{{"nodes", {0}}}});
    doc["scene"] = 0;
    return doc;
}

}  // namespace

TEST_CASE("KHR_draco_mesh_compression: sequential streams load to exactly the uncompressed mesh and render its bytes") {
    TempDir dir("draco");
    const Grid g;
    int ids[3];
    const std::vector<unsigned char> seq = draco_grid(draco::MESH_SEQUENTIAL_ENCODING, ids);
    draco_gltf::Counts counts;
    CHECK(draco_gltf::read_counts(seq.data(), seq.size(), counts) == "");
    CHECK(counts.faces == g.idx.size() / 3);
    CHECK(counts.vertices == g.vertices());
    // The uncompressed original: the same arrays as plain accessors.
    View pos, nrm, uv, idx;
    pos.raw = as_bytes(g.pos.data(), g.pos.size() * 4);
    nrm.raw = as_bytes(g.nrm.data(), g.nrm.size() * 4);
    uv.raw = as_bytes(g.uv.data(), g.uv.size() * 4);
    idx.raw = as_bytes(g.idx.data(), g.idx.size() * 2);
    pos.count = nrm.count = uv.count = g.vertices();
    idx.count = g.idx.size();
    CliSandbox box;
    write_text(box.path("plain.gltf"), grid_model({pos, nrm, uv, idx}, false).dump());
    write_text(box.path("draco.gltf"), draco_model(seq, ids).dump());
    const Scene plain = load_scene(box.path("plain.gltf")), packed = load_scene(box.path("draco.gltf"));
    CHECK(packed.warnings.empty());
    check_same_meshes(plain, packed);
    const auto render = [&](const std::string& in, const std::string& out) {
        return box.run_exe("timeout", {"-s", "KILL", "60", PRAST_RENDER_EXE, in, "-o", out, "--size", "40x40", "--sun",
                                       "0.3,0.4,1:1,1,1"});
    };
    CHECK(render("plain.gltf", "a.png").code == 0);
    CHECK(render("draco.gltf", "b.png").code == 0);
    const std::vector<unsigned char> pa = read_bytes(box.path("a.png"));
    CHECK(!pa.empty());
    CHECK(pa == read_bytes(box.path("b.png")));

    // Edgebreaker reorders points and faces: the same triangles (as position triples).
    const std::vector<unsigned char> eb = draco_grid(draco::MESH_EDGEBREAKER_ENCODING, ids);
    CHECK(draco_gltf::read_counts(eb.data(), eb.size(), counts) == "");
    CHECK(counts.faces == g.idx.size() / 3);
    write_text(dir.file("eb.gltf"), draco_model(eb, ids).dump());
    const Scene e = load_scene(dir.file("eb.gltf"));
    REQUIRE(e.meshes.size() == 1);
    const auto triangles = [](const Mesh& m) {
        std::vector<std::vector<float>> out;
        for (std::size_t t = 0; t < m.indices.size(); t += 3) {
            std::vector<std::vector<float>> corners;
            for (int c = 0; c < 3; ++c) {
                const glm::vec3 p = m.positions[m.indices[t + std::size_t(c)]];
                corners.push_back({p.x, p.y, p.z});
            }
            // Rotated to start at the smallest corner: the winding is kept.
            const auto first = std::min_element(corners.begin(), corners.end()) - corners.begin();
            std::vector<float> tri;
            for (int c = 0; c < 3; ++c) {
                const auto& k = corners[std::size_t((first + c) % 3)];
                tri.insert(tri.end(), k.begin(), k.end());
            }
            out.push_back(tri);
        }
        std::sort(out.begin(), out.end());
        return out;
    };
    CHECK(triangles(e.meshes[0]) == triangles(plain.meshes[0]));
}

TEST_CASE("KHR_draco_mesh_compression: hostile streams and accessors are one line naming the extension") {
    TempDir dir("draco_bad");
    int ids[3];
    const std::vector<unsigned char> seq = draco_grid(draco::MESH_SEQUENTIAL_ENCODING, ids);
    struct Case {
        const char* name;
        std::function<void(json&, std::vector<unsigned char>&)> edit;
        const char* expect;
    };
    const std::vector<Case> cases = {
        {"truncated", [](json&, std::vector<unsigned char>& b) { b.resize(b.size() / 2); }, "Draco: "},
        {"huge_faces",
         [](json&, std::vector<unsigned char>& b) { b = huge_faces(b); },
         "the stream has 2147483647 faces, the indices accessor 384 indices"},
        {"version", [](json&, std::vector<unsigned char>& b) { b[5] = 3; }, "Draco bitstream 3.2 is not supported"},
        {"not_draco", [](json&, std::vector<unsigned char>& b) { b[0] = 'X'; }, "not a Draco stream"},
        {"count", [](json& d, std::vector<unsigned char>&) { d["accessors"][1]["count"] = 80; }, "accessor count 80, decoded 81 points"},
        {"component", [](json& d, std::vector<unsigned char>&) { d["accessors"][2]["componentType"] = 5123; }, "componentType"},
        {"index_count", [](json& d, std::vector<unsigned char>&) { d["accessors"][3]["count"] = 390; }, "faces, the indices accessor 390"},
        {"bad_id", [&](json& d, std::vector<unsigned char>&) {
             d["meshes"][0]["primitives"][0]["extensions"]["KHR_draco_mesh_compression"]["attributes"]["NORMAL"] = 77;
         }, "no Draco attribute with id 77"},
        {"no_view", [](json& d, std::vector<unsigned char>&) {
             d["meshes"][0]["primitives"][0]["extensions"]["KHR_draco_mesh_compression"]["bufferView"] = 9;
         }, "bufferView 9 out of range"},
        {"mode", [](json& d, std::vector<unsigned char>&) { d["meshes"][0]["primitives"][0]["mode"] = 1; }, "only TRIANGLES"},
    };
    for (const Case& c : cases) {
        CAPTURE(std::string(c.name));
        std::vector<unsigned char> stream = seq;
        json doc = draco_model(seq, ids);
        c.edit(doc, stream);
        if (stream != seq) {
            doc["buffers"][0] = {{"byteLength", stream.size()}, {"uri", "data:application/octet-stream;base64," + base64(stream)}};
            doc["bufferViews"][0]["byteLength"] = stream.size();
        }
        write_text(dir.file("bad.gltf"), doc.dump());
        const std::string err = load_error(dir.file("bad.gltf"));
        CAPTURE(err);
        CHECK(err.find(c.expect) != std::string::npos);
        CHECK(err.find("KHR_draco_mesh_compression") != std::string::npos);
        CHECK(err.find('\n') == std::string::npos);
    }
    // render: the huge claim is one line and exit 1, within a 4 GB address
    // space (not under AddressSanitizer, whose reservations exceed it).
#ifndef PRAST_SANITIZE_BUILD
    CliSandbox box;
    json doc = draco_model(huge_faces(seq), ids);
    doc["accessors"][3]["count"] = std::uint64_t(6442450941);  // 3 x (2^31 - 1), beyond the element limit
    write_text(box.path("h.gltf"), doc.dump());
    const CliRun r = box.run_exe("timeout", {"-s", "KILL", "60", PRAST_RENDER_EXE, "h.gltf", "-o", "o.png", "--size", "16x16"},
                                 "ulimit -v 4000000");
    CAPTURE(r.err);
    CHECK(r.code == 1);
    CHECK(r.err.find("KHR_draco_mesh_compression") != std::string::npos);
    CHECK(std::count(r.err.begin(), r.err.end(), '\n') == 1);
#endif
}

TEST_CASE("KHR_draco_mesh_compression: an edgebreaker stream claiming 40 million faces in 3 KB is refused before libdraco") {
    // libdraco sized its corner table from the claim (about 1 GB) before
    // refusing the stream; the accessors agree with the claim, so only the
    // stream's size can tell (scene/draco_decode.h check_density).
    int ids[3];
    const std::vector<unsigned char> eb = draco_grid(draco::MESH_EDGEBREAKER_ENCODING, ids);
    const std::uint32_t faces = 40000000;
    std::size_t p = 12;  // after the header and the traversal type: vertices, faces, attribute data, symbols
    const auto skip = [&] {
        while (eb[p] & 0x80) ++p;
        ++p;
    };
    skip();
    const std::size_t faces_at = p;
    skip();
    const std::size_t attribute_data = p++;
    skip();
    std::vector<unsigned char> claim;
    for (std::uint32_t v = faces; v; v >>= 7) claim.push_back(static_cast<unsigned char>((v & 127) | (v > 127 ? 128 : 0)));
    std::vector<unsigned char> stream(eb.begin(), eb.begin() + std::ptrdiff_t(faces_at));
    stream.insert(stream.end(), claim.begin(), claim.end());  // faces
    stream.push_back(eb[attribute_data]);
    stream.insert(stream.end(), claim.begin(), claim.end());  // as many symbols (libdraco checks them against the faces)
    stream.insert(stream.end(), eb.begin() + std::ptrdiff_t(p), eb.end());
    REQUIRE(stream.size() < 3000);  // the 9x9 grid, lossless: far fewer bytes than 40,000,000 / 4096
    json doc = draco_model(stream, ids);
    doc["accessors"][3]["count"] = std::uint64_t(faces) * 3;
    TempDir dir("draco_dense");
    write_text(dir.file("dense.gltf"), doc.dump());
    const std::string err = load_error(dir.file("dense.gltf"));
    CAPTURE(err);
    CHECK(err.find("KHR_draco_mesh_compression: the Draco stream claims 40000000 faces in only " +
                   std::to_string(stream.size()) + " bytes (more than 4096 a byte are refused)") != std::string::npos);
    CHECK(err.find('\n') == std::string::npos);
    // The same grid as it was encoded still loads.
    write_text(dir.file("grid.gltf"), draco_model(eb, ids).dump());
    CHECK(load_error(dir.file("grid.gltf")) == "");
}

#endif  // PRAST_HAVE_MESHOPT_ENCODER

TEST_CASE("EXT_texture_webp: a lossless WebP decodes to the pixels of the PNG; the texture prefers it over its source") {
    const int w = 13, h = 7;
    for (int channels : {3, 4}) {
        CAPTURE(channels);
        std::vector<std::uint8_t> px(std::size_t(w * h * channels));
        for (std::size_t i = 0; i < px.size(); ++i) px[i] = std::uint8_t((i * 37 + i / 5) & 255);
        if (channels == 4)
            for (std::size_t i = 3; i < px.size(); i += 4) px[i] = std::uint8_t(40 + i % 200);
        std::uint8_t* out = nullptr;
        const std::size_t n = channels == 4 ? WebPEncodeLosslessRGBA(px.data(), w, h, w * 4, &out)
                                            : WebPEncodeLosslessRGB(px.data(), w, h, w * 3, &out);
        REQUIRE(n > 0);
        ImageSource webp, png;
        webp.bytes.assign(out, out + n);
        WebPFree(out);
        png.bytes = encode_png_pixels(px.data(), w, h, channels);
        const Image a = decode_image(webp, true), b = decode_image(png, true);
        CHECK(a.width == w);
        CHECK(a.height == h);
        CHECK(a.channels == b.channels);
        CHECK(a.pixels == b.pixels);
        CHECK(a.pixels == px);
        int dw = 0, dh = 0, bpt = 0;
        CHECK(image_dimensions(webp, dw, dh, &bpt));
        CHECK(dw == w);
        CHECK(bpt == channels);
        // Truncated: one line.
        webp.bytes.resize(webp.bytes.size() / 2);
        CHECK_THROWS_WITH_AS(decode_image(webp, true), doctest::Contains("WebP"), LoadError);
    }
    // A 16383x16383 header in 100 bytes is refused before anything is allocated.
    std::vector<unsigned char> big = {'R', 'I', 'F', 'F', 0, 0, 0, 0, 'W', 'E', 'B', 'P', 'V', 'P', '8', 'L', 5, 0, 0, 0, 0x2f};
    const std::uint32_t side = 16383;  // 14 bits each, minus one
    const std::uint32_t bitsv = (side - 1) | ((side - 1) << 14);
    for (int k = 0; k < 4; ++k) big.push_back(static_cast<unsigned char>(bitsv >> (8 * k)));
    big[4] = static_cast<unsigned char>(big.size() - 8);
    big.resize(big.size() + 64, 0);
    ImageSource bomb;
    bomb.bytes = big;
    CHECK_THROWS_WITH_AS(decode_image(bomb, true), doctest::Contains("texels from only"), LoadError);
    int bw = 0, bh = 0;
    CHECK(!image_dimensions(bomb, bw, bh));

    // In a model: the WebP is drawn, not the fallback.
    TempDir dir("webp");
    const std::uint8_t red[3] = {255, 0, 0}, blue[3] = {0, 0, 255};
    std::uint8_t* out = nullptr;
    const std::size_t n = WebPEncodeLosslessRGB(blue, 1, 1, 3, &out);
    const std::vector<unsigned char> webp(out, out + n);
    WebPFree(out);
    prast::gltf_test::GltfWriter g;
    const int pos = g.floats({-1, -1, 0, 1, -1, 0, 0, 1, 0}, "VEC3", 3);
    const int uv = g.floats({0, 0, 1, 0, 0, 1}, "VEC2", 2);
    const int fallback = g.image_png(encode_png_pixels(red, 1, 1, 3));
    // As gltfpack stores it: in a bufferView, mimeType image/webp.
    g.add_raw(webp.data(), webp.size(), 5121, "SCALAR", webp.size());
    g.doc["images"].push_back({{"bufferView", g.doc["bufferViews"].size() - 1}, {"mimeType", "image/webp"}});
    const int tex = g.texture(fallback, 9728, 9728);
    g.doc["textures"][std::size_t(tex)]["extensions"]["EXT_texture_webp"] = {{"source", 1}};
    g.doc["materials"].push_back({{"pbrMetallicRoughness", {{"baseColorTexture", {{"index", tex}}}}}});
    json prim = {{"attributes", {{"POSITION", pos}, {"TEXCOORD_0", uv}}}, {"material", 0}};
    g.doc["meshes"].push_back({{"primitives", json::array({prim})}});
    g.scene_of_meshes();
    g.doc["extensionsUsed"] = {"EXT_texture_webp"};
    write_text(dir.file("w.gltf"), g.text());
    const Scene s = load_scene(dir.file("w.gltf"));
    REQUIRE(s.materials.size() == 1);
    REQUIRE(s.materials[0].base_color.valid());
    const Image img = decode_image(s.images[std::size_t(s.materials[0].base_color.image)], true);
    REQUIRE(img.width == 1);
    CHECK(img.pixels == std::vector<std::uint8_t>(blue, blue + 3));
    // As a data URI (tinygltf does not decode image/webp ones): the same.
    json uri_doc = json::parse(g.text());
    uri_doc["images"][1] = {{"uri", "data:image/webp;base64," + base64(webp)}};
    write_text(dir.file("u.gltf"), uri_doc.dump());
    const Scene u = load_scene(dir.file("u.gltf"));
    CHECK(u.warnings.empty());
    REQUIRE(u.materials[0].base_color.valid());
    CHECK(decode_image(u.images[std::size_t(u.materials[0].base_color.image)], true).pixels == img.pixels);

    // KHR_texture_basisu: optional, the source image with one warning; required, refused naming it.
    json doc = json::parse(g.text());
    doc["textures"][0]["extensions"] = {{"KHR_texture_basisu", {{"source", 1}}}};
    doc["extensionsUsed"] = {"KHR_texture_basisu"};
    write_text(dir.file("b.gltf"), doc.dump());
    const Scene b = load_scene(dir.file("b.gltf"));
    REQUIRE(b.warnings.size() == 1);
    CHECK(b.warnings[0].find("KHR_texture_basisu (KTX2) textures are not decoded") != std::string::npos);
    const Image fb = decode_image(b.images[std::size_t(b.materials[0].base_color.image)], true);
    CHECK(fb.pixels == std::vector<std::uint8_t>(red, red + 3));
    doc["extensionsRequired"] = {"KHR_texture_basisu"};
    write_text(dir.file("r.gltf"), doc.dump());
    CHECK(load_error(dir.file("r.gltf")) == dir.file("r.gltf") + ": required extension KHR_texture_basisu is not supported");
}

}  // TEST_SUITE

// A small glTF writer for tests: one data-URI buffer that accessors append
// to, the document as nlohmann::json for the test to fill in (meshes,
// materials, nodes, skins, animations), written as a .gltf text file.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace prast::gltf_test {

inline std::string base64(const std::vector<unsigned char>& in) {
    static const char* table = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    std::string out;
    for (std::size_t i = 0; i < in.size(); i += 3) {
        const std::uint32_t b = std::uint32_t(in[i]) << 16 | (i + 1 < in.size() ? std::uint32_t(in[i + 1]) << 8 : 0u) |
                                (i + 2 < in.size() ? std::uint32_t(in[i + 2]) : 0u);
        out += table[b >> 18 & 63];
        out += table[b >> 12 & 63];
        out += i + 1 < in.size() ? table[b >> 6 & 63] : '=';
        out += i + 2 < in.size() ? table[b & 63] : '=';
    }
    return out;
}

struct GltfWriter {
    nlohmann::json doc = nlohmann::json::object();
    std::vector<unsigned char> bin;

    GltfWriter() {
        doc["asset"] = {{"version", "2.0"}};
        for (const char* k : {"accessors", "bufferViews", "nodes", "meshes", "materials"})
            doc[k] = nlohmann::json::array();
    }
    int add_raw(const void* data, std::size_t bytes, int component, const char* type, std::size_t count) {
        while (bin.size() % 4) bin.push_back(0);
        const std::size_t offset = bin.size();
        bin.insert(bin.end(), static_cast<const unsigned char*>(data), static_cast<const unsigned char*>(data) + bytes);
        doc["bufferViews"].push_back({{"buffer", 0}, {"byteOffset", offset}, {"byteLength", bytes}});
        doc["accessors"].push_back({{"bufferView", doc["bufferViews"].size() - 1},
                                    {"componentType", component},
                                    {"type", type},
                                    {"count", count}});
        return int(doc["accessors"].size()) - 1;
    }
    // Float accessor of `per` components (VEC3 ones get min and max, which POSITION needs).
    int floats(const std::vector<float>& v, const char* type, int per) {
        const int a = add_raw(v.data(), v.size() * 4, 5126, type, v.size() / std::size_t(per));
        if (per == 3) {
            std::vector<float> lo(3, 1e30f), hi(3, -1e30f);
            for (std::size_t i = 0; i < v.size(); ++i) {
                lo[i % 3] = std::min(lo[i % 3], v[i]);
                hi[i % 3] = std::max(hi[i % 3], v[i]);
            }
            doc["accessors"][std::size_t(a)]["min"] = lo;
            doc["accessors"][std::size_t(a)]["max"] = hi;
        }
        return a;
    }
    int u16(const std::vector<std::uint16_t>& v, const char* type, int per) {
        return add_raw(v.data(), v.size() * 2, 5123, type, v.size() / std::size_t(per));
    }
    // A PNG (its bytes) as an image with a data URI; returns the image index.
    int image_png(const std::vector<unsigned char>& png) {
        if (!doc.contains("images")) doc["images"] = nlohmann::json::array();
        doc["images"].push_back({{"uri", "data:image/png;base64," + base64(png)}});
        return int(doc["images"].size()) - 1;
    }
    // A texture of `image` with a sampler of these glTF enums; returns the texture index.
    int texture(int image, int mag, int min, int wrap_s = 10497, int wrap_t = 10497) {
        if (!doc.contains("samplers")) doc["samplers"] = nlohmann::json::array();
        if (!doc.contains("textures")) doc["textures"] = nlohmann::json::array();
        doc["samplers"].push_back({{"magFilter", mag}, {"minFilter", min}, {"wrapS", wrap_s}, {"wrapT", wrap_t}});
        doc["textures"].push_back({{"source", image}, {"sampler", doc["samplers"].size() - 1}});
        return int(doc["textures"].size()) - 1;
    }
    // One node per mesh, all in scene 0.
    void scene_of_meshes() {
        nlohmann::json roots = nlohmann::json::array();
        for (std::size_t m = 0; m < doc["meshes"].size(); ++m) {
            doc["nodes"].push_back({{"mesh", m}});
            roots.push_back(doc["nodes"].size() - 1);
        }
        doc["scenes"] = nlohmann::json::array({{{"nodes", roots}}});
        doc["scene"] = 0;
    }
    std::string text() const {
        nlohmann::json d = doc;
        if (d["materials"].empty()) d.erase("materials");
        d["buffers"] = nlohmann::json::array(
            {{{"byteLength", bin.size()}, {"uri", "data:application/octet-stream;base64," + base64(bin)}}});
        return d.dump();
    }
};

inline int add_material(GltfWriter& g, const nlohmann::json& m) {
    g.doc["materials"].push_back(m);
    return int(g.doc["materials"].size()) - 1;
}

// A UV sphere of radius 1 about the origin (normals, UVs), one primitive
// with `material`: the lobes' whole angular range in one mesh.
inline int add_sphere(GltfWriter& g, int material, int nu = 24, int nv = 12) {
    const double pi = 3.14159265358979323846;
    std::vector<float> pos, nor, uv;
    std::vector<std::uint16_t> ind;
    for (int j = 0; j <= nv; ++j)
        for (int i = 0; i <= nu; ++i) {
            const double th = pi * j / nv, ph = 2.0 * pi * i / nu;
            const float x = float(std::sin(th) * std::cos(ph)), y = float(std::cos(th)), z = float(std::sin(th) * std::sin(ph));
            pos.insert(pos.end(), {x, y, z});
            nor.insert(nor.end(), {x, y, z});
            uv.insert(uv.end(), {float(i) / float(nu), float(j) / float(nv)});
        }
    for (int j = 0; j < nv; ++j)
        for (int i = 0; i < nu; ++i) {
            const std::uint16_t a = std::uint16_t(j * (nu + 1) + i), b = std::uint16_t(a + nu + 1);
            ind.insert(ind.end(), {a, std::uint16_t(a + 1), b, std::uint16_t(a + 1), std::uint16_t(b + 1), b});
        }
    const nlohmann::json attrs = {{"POSITION", g.floats(pos, "VEC3", 3)}, {"NORMAL", g.floats(nor, "VEC3", 3)},
                                  {"TEXCOORD_0", g.floats(uv, "VEC2", 2)}};
    const int indices = g.u16(ind, "SCALAR", 1);
    g.doc["meshes"].push_back(
        {{"primitives", nlohmann::json::array({{{"attributes", attrs}, {"indices", indices}, {"material", material}}})}});
    return int(g.doc["meshes"].size()) - 1;
}

} // namespace prast::gltf_test

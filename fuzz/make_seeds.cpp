// Writes the seed corpora of the harnesses: `fuzz_make_seeds OUT` fills
// OUT/obj, OUT/gltf, OUT/png, OUT/jpeg, OUT/hdr, OUT/webp, OUT/meshopt, OUT/cli and OUT/step with small valid
// inputs that reach every branch the fuzzers should start from (materials
// and maps, every glTF accessor kind, each image channel count, the HDR
// run-length and flat paths, every render flag, compressed glTF data:
// EXT_meshopt_compression in each mode and filter, KHR_draco_mesh_compression,
// EXT_texture_webp, and OUT/webp). Made by the project, so no file of unknown
// origin is needed; scripts/fuzz.sh runs it. The compressed seeds are encoded
// here by libdraco's and libwebp's encoders (in the static libraries render
// links) and by libmeshoptimizer's (shared, found by fuzz/CMakeLists.txt;
// without it the meshopt seeds are left out).
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include <draco/compression/encode.h>
#include <draco/mesh/mesh.h>
#include <nlohmann/json.hpp>
#include <stb_image_write.h>
#include <webp/encode.h>

#if defined(PRAST_HAVE_MESHOPT_ENCODER)
#include <meshoptimizer.h>
#endif

#include "fuzz/png_craft.h"
#include "fuzz/targets.h"

namespace fs = std::filesystem;

namespace {

fs::path g_out;

void put(const std::string& corpus, const std::string& name, const std::string& bytes) {
    fs::create_directories(g_out / corpus);
    std::FILE* f = std::fopen((g_out / corpus / name).string().c_str(), "wb");
    if (!f) std::exit(1);
    std::fwrite(bytes.data(), 1, bytes.size(), f);
    std::fclose(f);
}

void append_bytes(void* ctx, void* data, int size) {
    static_cast<std::string*>(ctx)->append(static_cast<const char*>(data), std::size_t(size));
}

// A smooth test pattern with `comp` channels.
std::vector<unsigned char> pattern8(int w, int h, int comp) {
    std::vector<unsigned char> px(std::size_t(w) * h * comp);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            for (int c = 0; c < comp; ++c)
                px[(std::size_t(y) * w + x) * comp + c] = (unsigned char)((x * 37 + y * 11 + c * 80) & 0xFF);
    return px;
}

void image_seeds() {
    const int sizes[][2] = {{1, 1}, {7, 5}, {16, 16}, {33, 9}};
    for (const auto& s : sizes)
        for (int comp = 1; comp <= 4; ++comp) {
            const std::vector<unsigned char> px = pattern8(s[0], s[1], comp);
            std::string png;
            stbi_write_png_to_func(append_bytes, &png, s[0], s[1], comp, px.data(), s[0] * comp);
            put("png", "p" + std::to_string(s[0]) + "x" + std::to_string(s[1]) + "c" + std::to_string(comp) + ".png", png);
            if (comp == 1 || comp == 3)
                for (int quality : {10, 60, 95}) {
                    std::string jpg;
                    stbi_write_jpg_to_func(append_bytes, &jpg, s[0], s[1], comp, px.data(), quality);
                    put("jpeg", "j" + std::to_string(s[0]) + "x" + std::to_string(s[1]) + "c" + std::to_string(comp) +
                                    "q" + std::to_string(quality) + ".jpg", jpg);
                }
        }
    // PNGs of the kinds stb_image_write never makes, which take libpng's path
    // or the 16-bit one (fuzz/png_craft.h): every bit depth of grey, 16-bit
    // grey+alpha and RGBA, palettes of 1 to 8 bits with and without tRNS,
    // tRNS on grey and RGB, Adam7 interlacing.
    namespace pc = prast::png_craft;
    const auto wave = [](int x, int y) { return std::uint64_t(x * 2654435761u ^ y * 40503u); };
    for (int depth : {1, 2, 4, 8, 16})
        put("png", "grey" + std::to_string(depth) + ".png", pc::file(9, 5, depth, 0, 0, depth, wave));
    put("png", "grey16-alpha.png", pc::file(7, 3, 16, 4, 0, 32, wave));
    put("png", "rgba16.png", pc::file(5, 4, 16, 6, 0, 64, wave));
    put("png", "rgb16-interlaced.png", pc::file(9, 9, 16, 2, 1, 48, wave));
    std::string plte;
    for (int i = 0; i < 256; ++i) plte += {char(i), char(255 - i), char(i * 7)};
    for (int depth : {1, 2, 4, 8}) {
        const std::string palette = pc::chunk("PLTE", plte.substr(0, std::size_t(3) << depth));
        put("png", "palette" + std::to_string(depth) + ".png", pc::file(10, 6, depth, 3, 0, depth, wave, palette));
        put("png", "palette" + std::to_string(depth) + "-trns.png",
            pc::file(10, 6, depth, 3, 0, depth, wave, palette + pc::chunk("tRNS", std::string("\x00\x80\xff", 3))));
    }
    put("png", "grey8-trns.png", pc::file(6, 6, 8, 0, 0, 8, wave, pc::chunk("tRNS", std::string("\x00\x07", 2))));
    put("png", "rgb8-trns.png", pc::file(6, 6, 8, 2, 0, 24, wave, pc::chunk("tRNS", std::string("\x00\x07\x00\x09\x00\x0b", 6))));
    put("png", "rgb8-interlaced.png", pc::file(13, 11, 8, 2, 1, 24, wave));
    put("png", "grey2-interlaced.png", pc::file(17, 3, 2, 0, 1, 2, wave));
    put("png", "palette4-interlaced.png",
        pc::file(12, 12, 4, 3, 1, 4, wave, pc::chunk("PLTE", plte.substr(0, 48))));
    // Sides beyond stb_image's 32768, which only libpng decodes (8 and 16 bits).
    put("png", "grey8-40000x1.png", pc::file(40000, 1, 8, 0, 0, 8, wave));
    put("png", "grey16-1x33000.png", pc::file(1, 33000, 16, 0, 0, 16, wave));
    // A top-down BMP (negative height), whose height stbi_info gives negative.
    std::string bmp = "BM";
    const auto le32 = [&bmp](std::uint32_t v) { bmp += {char(v), char(v >> 8), char(v >> 16), char(v >> 24)}; };
    const auto le16 = [&bmp](unsigned v) { bmp += {char(v), char(v >> 8)}; };
    le32(54 + 2 * 8); le32(0); le32(54); le32(40); le32(2); le32(std::uint32_t(-2)); le16(1); le16(24);
    le32(0); le32(16); le32(2835); le32(2835); le32(0); le32(0);
    bmp += std::string("\x00\x00\xff\x00\xff\x00\x00\x00\xff\x00\x00\xff\xff\xff\x00\x00", 16);
    put("png", "top-down.bmp", bmp);

    // Radiance: width 8..32767 is written run-length encoded, below 8 flat.
    const int hdr_sizes[][2] = {{4, 3}, {8, 2}, {16, 4}, {40, 3}};
    for (const auto& s : hdr_sizes) {
        std::vector<float> px(std::size_t(s[0]) * s[1] * 3);
        for (std::size_t i = 0; i < px.size(); ++i) px[i] = (i / 3 % 5 == 0) ? 1.0f : float(i % 7) * 0.3f;
        std::string hdr;
        stbi_write_hdr_to_func(append_bytes, &hdr, s[0], s[1], 3, px.data());
        put("hdr", "h" + std::to_string(s[0]) + "x" + std::to_string(s[1]) + ".hdr", hdr);
        // The same data under the other signature.
        const std::string magic = "#?RADIANCE\n";
        if (hdr.compare(0, magic.size(), magic) == 0)
            put("hdr", "h" + std::to_string(s[0]) + "x" + std::to_string(s[1]) + "-rgbe.hdr",
                "#?RGBE\n" + hdr.substr(magic.size()));
    }
}

void obj_seeds() {
    const std::string tri = "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nvn 0 0 1\n";
    put("obj", "triangle.obj", tri + "f 1 2 3\n");
    put("obj", "triangle-uv-normal.obj", tri + "f 1/1/1 2/2/1 3/3/1\n");
    put("obj", "negative.obj", tri + "f -3/-3 -2/-2 -1/-1\n");
    put("obj", "quad-polygon.obj",
        "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0.5 1.5 0\ng a\nf 1 2 3 4\no b\nf 1 2 3 5 4\ns 1\nl 1 2\np 3\n");
    const std::string mtl =
        "newmtl red\nKd 1 0 0\nKs 1 1 1\nNs 32\nPr 0.3\nPm 0.1\nKe 0 0 0\nmap_Kd t.png\n"
        "norm -bm 0.5 t.png\nmap_Pr sub/t.png\nmap_Pm -clamp on t.png\nmap_Ke t.png\nmap_Ka t.png\n"
        "newmtl gold\nPc gold\nd 0.5\nmap_d t.png\nbump t.png\n"
        "newmtl odd\nmap_Kd ../t.png\nmap_Ke /etc/passwd\nmap_Pr sub\\t.png\nmap_Pm sub/../../x.png\n";
    put("obj", "materials.obj",
        "mtllib m.mtl\n" + tri + "usemtl red\nf 1/1/1 2/2/1 3/3/1\nusemtl gold\nf 3 2 1\nusemtl odd\nf 1 3 2\n#--mtl--\n" + mtl);
    put("obj", "mtllib-spellings.obj",
        "mtllib m.mtl ./m.mtl sub/../m.mtl missing.mtl\nmtllib .//m.mtl\n" + tri + "usemtl red\nf 1 2 3\n#--mtl--\n" + mtl);
}

std::string base64(const std::string& in) {
    static const char* t = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    std::string out;
    std::size_t i = 0;
    for (; i + 2 < in.size(); i += 3) {
        const unsigned v = (unsigned char)in[i] << 16 | (unsigned char)in[i + 1] << 8 | (unsigned char)in[i + 2];
        out += {t[v >> 18], t[v >> 12 & 63], t[v >> 6 & 63], t[v & 63]};
    }
    if (i + 1 == in.size()) {
        const unsigned v = (unsigned char)in[i] << 16;
        out += {t[v >> 18], t[v >> 12 & 63], '=', '='};
    } else if (i + 2 == in.size()) {
        const unsigned v = (unsigned char)in[i] << 16 | (unsigned char)in[i + 1] << 8;
        out += {t[v >> 18], t[v >> 12 & 63], t[v >> 6 & 63], '='};
    }
    return out;
}

void gltf_seeds() {
    // Buffer: 3 positions, 3 normals, 3 uvs, 3 tangents, 3 uint16 indices (+pad), 1 sparse index and value.
    std::string bin;
    auto f32 = [&](float v) { bin.append(reinterpret_cast<const char*>(&v), 4); };
    auto u16 = [&](std::uint16_t v) { bin.append(reinterpret_cast<const char*>(&v), 2); };
    for (float v : {0.f, 0.f, 0.f, 1.f, 0.f, 0.f, 0.f, 1.f, 0.f}) f32(v);        // 0: positions
    for (int i = 0; i < 3; ++i) for (float v : {0.f, 0.f, 1.f}) f32(v);          // 36: normals
    for (float v : {0.f, 0.f, 1.f, 0.f, 0.f, 1.f}) f32(v);                         // 72: uvs
    for (int i = 0; i < 3; ++i) for (float v : {1.f, 0.f, 0.f, 1.f}) f32(v);     // 96: tangents
    u16(0); u16(1); u16(2); u16(0);                                               // 144: indices
    u16(1); u16(0);                                                               // 152: sparse index
    for (float v : {2.f, 0.f, 0.f}) f32(v);                                       // 156: sparse value
    const std::string views =
        R"("bufferViews":[{"buffer":0,"byteOffset":0,"byteLength":36},{"buffer":0,"byteOffset":36,"byteLength":36},)"
        R"({"buffer":0,"byteOffset":72,"byteLength":24},{"buffer":0,"byteOffset":96,"byteLength":48},)"
        R"({"buffer":0,"byteOffset":144,"byteLength":6},{"buffer":0,"byteOffset":152,"byteLength":2},)"
        R"({"buffer":0,"byteOffset":156,"byteLength":12}],)";
    const std::string accessors =
        R"("accessors":[{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3","min":[0,0,0],"max":[1,1,0]},)"
        R"({"bufferView":1,"componentType":5126,"count":3,"type":"VEC3"},)"
        R"({"bufferView":2,"componentType":5126,"count":3,"type":"VEC2"},)"
        R"({"bufferView":3,"componentType":5126,"count":3,"type":"VEC4"},)"
        R"({"bufferView":4,"componentType":5123,"count":3,"type":"SCALAR"},)"
        R"({"bufferView":0,"componentType":5126,"count":3,"type":"VEC3","sparse":{"count":1,)"
        R"("indices":{"bufferView":5,"componentType":5123},"values":{"bufferView":6}}},)"
        R"({"componentType":5126,"count":3,"type":"VEC3"}],)";
    const std::string rest =
        R"("asset":{"version":"2.0"},"scene":0,"scenes":[{"nodes":[0,3]}],)"
        R"("nodes":[{"children":[1,2],"translation":[0,0,1],"rotation":[0,0,0,1],"scale":[1,2,1]},)"
        R"({"mesh":0,"matrix":[1,0,0,0,0,1,0,0,0,0,1,0,0,0,0,1]},{"mesh":1,"scale":[-1,1,1]},)"
        R"({"extensions":{"KHR_lights_punctual":{"light":0}}}],)"
        R"("extensionsUsed":["KHR_lights_punctual","KHR_materials_emissive_strength"],)"
        R"("extensions":{"KHR_lights_punctual":{"lights":[{"type":"point","color":[1,1,1],"intensity":2},)"
        R"({"type":"directional"},{"type":"spot","spot":{}}]}},)"
        R"("meshes":[{"primitives":[{"attributes":{"POSITION":0,"NORMAL":1,"TEXCOORD_0":2,"TANGENT":3},)"
        R"("indices":4,"material":0}]},{"primitives":[{"attributes":{"POSITION":5},"material":1},)"
        R"({"attributes":{"POSITION":6},"mode":4}]}],)"
        R"("materials":[{"name":"m","pbrMetallicRoughness":{"baseColorFactor":[1,0.5,0.5,1],)"
        R"("baseColorTexture":{"index":0},"metallicRoughnessTexture":{"index":1},"metallicFactor":0.5,)"
        R"("roughnessFactor":0.5},"normalTexture":{"index":0,"scale":0.8},"occlusionTexture":{"index":1},)"
        R"("emissiveTexture":{"index":0},"emissiveFactor":[1,1,1],"alphaMode":"MASK","alphaCutoff":0.3,)"
        R"("doubleSided":true,"extensions":{"KHR_materials_emissive_strength":{"emissiveStrength":2}}},)"
        R"({"name":"plain"}],)"
        R"("samplers":[{"wrapS":33071,"wrapT":33648}],)"
        R"("textures":[{"source":0,"sampler":0},{"source":1}],)";
    const std::string png_bytes = prast::fuzz::tiny_png();
    const unsigned char* png = reinterpret_cast<const unsigned char*>(png_bytes.data());
    const std::size_t png_size = png_bytes.size();
    const std::string png_uri = "data:image/png;base64," + base64(std::string((const char*)png, png_size));

    // Text glTF with an external buffer (b.bin is written by the harness: a
    // triangle and its indices), and one with everything in data URIs.
    put("gltf", "external.gltf",
        R"({"asset":{"version":"2.0"},"buffers":[{"uri":"b.bin","byteLength":42}],)"
        R"("bufferViews":[{"buffer":0,"byteLength":36},{"buffer":0,"byteOffset":36,"byteLength":6}],)"
        R"("accessors":[{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3"},)"
        R"({"bufferView":1,"componentType":5123,"count":3,"type":"SCALAR"}],)"
        R"("meshes":[{"primitives":[{"attributes":{"POSITION":0},"indices":1}]}],"nodes":[{"mesh":0}],)"
        R"("scenes":[{"nodes":[0]}],"images":[{"uri":"t.png"},{"uri":"sub%2F..%2Ft.png"}],)"
        R"("textures":[{"source":0},{"source":1}],"materials":[{"pbrMetallicRoughness":{"baseColorTexture":{"index":0}},)"
        R"("emissiveTexture":{"index":1}}]})");
    put("gltf", "full.gltf",
        "{" + rest + views + accessors +
            R"("images":[{"uri":")" + png_uri + R"("},{"uri":"t.png"}],)" +
            R"("buffers":[{"byteLength":)" + std::to_string(bin.size()) + R"(,"uri":"data:application/octet-stream;base64,)" +
            base64(bin) + R"("}]})");

    // The same as a .glb: JSON chunk and BIN chunk, the image in a bufferView.
    std::string glb_bin = bin;
    while (glb_bin.size() % 4) glb_bin += '\0';
    const std::size_t png_offset = glb_bin.size();
    glb_bin.append((const char*)png, png_size);
    while (glb_bin.size() % 4) glb_bin += '\0';
    std::string views_glb = views.substr(0, views.size() - 2) + R"(,{"buffer":0,"byteOffset":)" +
                            std::to_string(png_offset) + R"(,"byteLength":)" + std::to_string(png_size) + "}],";
    std::string json = "{" + rest + views_glb + accessors +
                       R"("images":[{"bufferView":7,"mimeType":"image/png"},{"uri":")" + png_uri + R"("}],)" +
                       R"("buffers":[{"byteLength":)" + std::to_string(glb_bin.size()) + "}]}";
    while (json.size() % 4) json += ' ';
    std::string glb = "glTF";
    auto u32 = [&](std::uint32_t v) { glb.append(reinterpret_cast<const char*>(&v), 4); };
    u32(2);
    u32(std::uint32_t(12 + 8 + json.size() + 8 + glb_bin.size()));
    u32(std::uint32_t(json.size()));
    u32(0x4E4F534Au);
    glb += json;
    u32(std::uint32_t(glb_bin.size()));
    u32(0x004E4942u);
    glb += glb_bin;
    put("gltf", "full.glb", glb);

    // A required extension with gltfpack's uri-less fallback buffer, and
    // texCoord values beyond an int.
    put("gltf", "meshopt-required.gltf",
        R"({"asset":{"version":"2.0"},"extensionsUsed":["EXT_meshopt_compression"],)"
        R"("extensionsRequired":["EXT_meshopt_compression"],)"
        R"("buffers":[{"byteLength":42,"extensions":{"EXT_meshopt_compression":{"fallback":true}}},)"
        R"({"uri":"b.bin","byteLength":42}],"bufferViews":[{"buffer":0,"byteLength":36,)"
        R"("extensions":{"EXT_meshopt_compression":{"buffer":1,"byteLength":36,"byteStride":12,"count":3}}}],)"
        R"("accessors":[{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3"}],)"
        R"("meshes":[{"primitives":[{"attributes":{"POSITION":0}}]}],"nodes":[{"mesh":0}],"scenes":[{"nodes":[0]}]})");
    put("gltf", "texcoord-range.gltf",
        R"({"asset":{"version":"2.0"},"buffers":[{"uri":"b.bin","byteLength":42}],)"
        R"("bufferViews":[{"buffer":0,"byteLength":36}],)"
        R"("accessors":[{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3"}],)"
        R"("meshes":[{"primitives":[{"attributes":{"POSITION":0},"material":0}]}],"nodes":[{"mesh":0}],)"
        R"("scenes":[{"nodes":[0]}],"images":[{"uri":"t.png"}],"textures":[{"source":0}],)"
        R"("materials":[{"pbrMetallicRoughness":{"baseColorTexture":{"index":0,"texCoord":2147483648}},)"
        R"("normalTexture":{"index":0,"texCoord":4294967296},"emissiveTexture":{"index":0,"texCoord":-1}}]})");

    // Every primitive mode over b.bin's triangle (b.bin is 256 bytes; 3 indices: a one-triangle
    // strip and fan, a 3-segment loop, an odd LINES count), and a bad mode.
    std::string modes = R"({"asset":{"version":"2.0"},"buffers":[{"uri":"b.bin","byteLength":256}],)"
                        R"("bufferViews":[{"buffer":0,"byteLength":36},{"buffer":0,"byteOffset":36,"byteLength":6}],)"
                        R"("accessors":[{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3"},)"
                        R"({"bufferView":1,"componentType":5123,"count":3,"type":"SCALAR"}],"meshes":[{"primitives":[)";
    for (int mode = 0; mode <= 7; ++mode)
        modes += std::string(mode ? "," : "") + R"({"attributes":{"POSITION":0},"indices":1,"mode":)" +
                 std::to_string(mode) + "}";
    modes += R"(,{"attributes":{"POSITION":0},"mode":5}]}],"nodes":[{"mesh":0}],"scenes":[{"nodes":[0]}]})";
    put("gltf", "modes.gltf", modes);

    // COLOR_0 as float VEC4, normalized unsigned byte VEC4 and unsigned short
    // VEC3; TEXCOORD_1 read by a texture; two textures of one image with
    // their own samplers (every filter, and bad enums).
    std::string cb;
    auto cf = [&](float v) { cb.append(reinterpret_cast<const char*>(&v), 4); };
    for (float v : {0.f, 0.f, 0.f, 1.f, 0.f, 0.f, 0.f, 1.f, 0.f}) cf(v);           // 0: positions
    for (float v : {1.f, 0.f, 0.f, 1.f, 0.f, 1.f, 0.f, .5f, 0.f, 0.f, 1.f, 0.f}) cf(v);  // 36: float rgba
    for (int b : {255, 0, 0, 255, 0, 255, 0, 128, 0, 0, 255, 0}) cb += char(b);     // 84: u8 rgba
    for (int i = 0; i < 9; ++i) { const std::uint16_t v = std::uint16_t(i * 8191); cb.append(reinterpret_cast<const char*>(&v), 2); }  // 96: u16 rgb
    cb += std::string(2, '\0');
    for (float v : {0.f, 0.f, 1.f, 0.f, 0.f, 1.f}) cf(v);                           // 116: uv1
    const std::string colors =
        R"({"asset":{"version":"2.0"},"buffers":[{"byteLength":)" + std::to_string(cb.size()) +
        R"(,"uri":"data:application/octet-stream;base64,)" + base64(cb) + R"("}],)"
        R"("bufferViews":[{"buffer":0,"byteLength":36},{"buffer":0,"byteOffset":36,"byteLength":48},)"
        R"({"buffer":0,"byteOffset":84,"byteLength":12},{"buffer":0,"byteOffset":96,"byteLength":18},)"
        R"({"buffer":0,"byteOffset":116,"byteLength":24}],)"
        R"("accessors":[{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3"},)"
        R"({"bufferView":1,"componentType":5126,"count":3,"type":"VEC4"},)"
        R"({"bufferView":2,"componentType":5121,"normalized":true,"count":3,"type":"VEC4"},)"
        R"({"bufferView":3,"componentType":5123,"normalized":true,"count":3,"type":"VEC3"},)"
        R"({"bufferView":4,"componentType":5126,"count":3,"type":"VEC2"}],)"
        R"("meshes":[{"primitives":[{"attributes":{"POSITION":0,"COLOR_0":1,"TEXCOORD_0":4,"TEXCOORD_1":4},"material":0},)"
        R"({"attributes":{"POSITION":0,"COLOR_0":2},"mode":3},{"attributes":{"POSITION":0,"COLOR_0":3},"mode":0},)"
        R"({"attributes":{"POSITION":0,"COLOR_0":0,"COLOR_1":1},"material":1}]}],)"
        R"("nodes":[{"mesh":0}],"scenes":[{"nodes":[0]}],"images":[{"uri":"t.png"}],)"
        R"("samplers":[{"magFilter":9728,"minFilter":9984},{"magFilter":9729,"minFilter":9985},)"
        R"({"minFilter":9986,"wrapS":33648},{"minFilter":9987},{"magFilter":1,"minFilter":4294977024}],)"
        R"("textures":[{"source":0,"sampler":0},{"source":0,"sampler":1},{"source":0,"sampler":2},)"
        R"({"source":0,"sampler":3},{"source":0,"sampler":4}],)"
        R"("materials":[{"pbrMetallicRoughness":{"baseColorTexture":{"index":0,"texCoord":1},)"
        R"("metallicRoughnessTexture":{"index":1}},"normalTexture":{"index":2,"texCoord":1},)"
        R"("occlusionTexture":{"index":3},"emissiveTexture":{"index":4}},{"name":"plain"}]})";
    put("gltf", "colors-uv1-samplers.gltf", colors);

    // Specular-glossiness: factors only, and both textures (converted texel
    // by texel); minVersion 2.0 (loads) and 2.1 (refused).
    put("gltf", "spec-gloss.gltf",
        R"({"asset":{"version":"2.0","minVersion":"2.0"},"extensionsUsed":["KHR_materials_pbrSpecularGlossiness"],)"
        R"("extensionsRequired":["KHR_materials_pbrSpecularGlossiness"],"buffers":[{"uri":"b.bin","byteLength":256}],)"
        R"("bufferViews":[{"buffer":0,"byteLength":36},{"buffer":0,"byteOffset":36,"byteLength":6}],)"
        R"("accessors":[{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3"},)"
        R"({"bufferView":1,"componentType":5123,"count":3,"type":"SCALAR"}],)"
        R"("meshes":[{"primitives":[{"attributes":{"POSITION":0},"indices":1,"material":0},)"
        R"({"attributes":{"POSITION":0},"indices":1,"material":1}]}],"nodes":[{"mesh":0}],"scenes":[{"nodes":[0]}],)"
        R"("images":[{"uri":"t.png"},{"uri":"sub/t.png"}],"textures":[{"source":0},{"source":1}],)"
        R"("materials":[{"extensions":{"KHR_materials_pbrSpecularGlossiness":{"diffuseFactor":[0.5,0.4,0.3,0.8],)"
        R"("specularFactor":[0.2,0.2,0.2],"glossinessFactor":0.7}}},)"
        R"({"extensions":{"KHR_materials_pbrSpecularGlossiness":{"diffuseTexture":{"index":0},)"
        R"("specularGlossinessTexture":{"index":1},"specularFactor":[1,0.8,0.2]}}}]})");
    // A skinned, morphed strip under an animated joint (LINEAR rotation,
    // STEP translation, CUBICSPLINE weights) with a camera and a light on
    // animated nodes.
    std::string sb;
    auto sf = [&](float v) { sb.append(reinterpret_cast<const char*>(&v), 4); };
    auto su = [&](std::uint16_t v) { sb.append(reinterpret_cast<const char*>(&v), 2); };
    for (float v : {-.5f, 0.f, 0.f, .5f, 0.f, 0.f, -.5f, 1.f, 0.f, .5f, 1.f, 0.f}) sf(v);        // 0: positions
    for (int i = 0; i < 4; ++i) for (float v : {0.f, 0.f, 1.f}) sf(v);                         // 48: normals
    for (int i = 0; i < 4; ++i) for (float v : {.1f, 0.f, 0.f}) sf(v);                         // 96: morph deltas
    for (int i = 0; i < 4; ++i) for (std::uint16_t v : {0, 1, 0, 0}) su(v);                    // 144: joints
    for (float v : {1.f, 0.f, 0.f, 0.f, 1.f, 0.f, 0.f, 0.f, .5f, .5f, 0.f, 0.f, 0.f, 1.f, 0.f, 0.f}) sf(v);  // 176: weights
    for (float m : {1.f, 0.f, 0.f, 0.f, 0.f, 1.f, 0.f, 0.f, 0.f, 0.f, 1.f, 0.f, 0.f, 0.f, 0.f, 1.f,
                    1.f, 0.f, 0.f, 0.f, 0.f, 1.f, 0.f, 0.f, 0.f, 0.f, 1.f, 0.f, 0.f, -1.f, 0.f, 1.f}) sf(m);  // 240: ibm
    for (float v : {0.f, 1.f}) sf(v);                                                           // 368: times
    for (float v : {0.f, 0.f, 0.f, 1.f, 0.f, .7071f, 0.f, .7071f}) sf(v);                       // 376: rotations
    for (float v : {0.f, 0.f, 0.f, 0.f, 0.f, 0.f, 0.f, 1.f, 0.f}) sf(v);                        // 408: cubic weights
    for (float v : {0.f, 0.f, 0.f, 0.f, 2.f, 0.f}) sf(v);                                       // 444: translations
    for (std::uint16_t v : {0, 1, 3, 0, 3, 2}) su(v);                                           // 468: indices
    const std::string skin =
        R"({"asset":{"version":"2.0"},"extensionsUsed":["KHR_lights_punctual"],)"
        R"("extensions":{"KHR_lights_punctual":{"lights":[{"type":"point","intensity":3}]}},)"
        R"("buffers":[{"byteLength":)" + std::to_string(sb.size()) +
        R"(,"uri":"data:application/octet-stream;base64,)" + base64(sb) + R"("}],)"
        R"("bufferViews":[{"buffer":0,"byteLength":48},{"buffer":0,"byteOffset":48,"byteLength":48},)"
        R"({"buffer":0,"byteOffset":96,"byteLength":48},{"buffer":0,"byteOffset":144,"byteLength":32},)"
        R"({"buffer":0,"byteOffset":176,"byteLength":64},{"buffer":0,"byteOffset":240,"byteLength":128},)"
        R"({"buffer":0,"byteOffset":368,"byteLength":8},{"buffer":0,"byteOffset":376,"byteLength":32},)"
        R"({"buffer":0,"byteOffset":408,"byteLength":36},{"buffer":0,"byteOffset":444,"byteLength":24},)"
        R"({"buffer":0,"byteOffset":468,"byteLength":12}],)"
        R"("accessors":[{"bufferView":0,"componentType":5126,"count":4,"type":"VEC3","min":[-0.5,0,0],"max":[0.5,1,0]},)"
        R"({"bufferView":1,"componentType":5126,"count":4,"type":"VEC3"},)"
        R"({"bufferView":2,"componentType":5126,"count":4,"type":"VEC3"},)"
        R"({"bufferView":3,"componentType":5123,"count":4,"type":"VEC4"},)"
        R"({"bufferView":4,"componentType":5126,"count":4,"type":"VEC4"},)"
        R"({"bufferView":5,"componentType":5126,"count":2,"type":"MAT4"},)"
        R"({"bufferView":6,"componentType":5126,"count":2,"type":"SCALAR","min":[0],"max":[1]},)"
        R"({"bufferView":7,"componentType":5126,"count":2,"type":"VEC4"},)"
        R"({"bufferView":8,"componentType":5126,"count":6,"type":"SCALAR"},)"
        R"({"bufferView":9,"componentType":5126,"count":2,"type":"VEC3"},)"
        R"({"bufferView":10,"componentType":5123,"count":6,"type":"SCALAR"}],)"
        R"("meshes":[{"weights":[0.5],"primitives":[{"attributes":{"POSITION":0,"NORMAL":1,"JOINTS_0":3,"WEIGHTS_0":4},)"
        R"("targets":[{"POSITION":2}],"indices":10}]}],)"
        R"("skins":[{"joints":[0,1],"inverseBindMatrices":5}],)"
        R"("cameras":[{"type":"perspective","perspective":{"yfov":0.8,"znear":0.1}},)"
        R"({"type":"orthographic","orthographic":{"xmag":1,"ymag":1,"znear":0.1,"zfar":10}}],)"
        R"("nodes":[{"children":[1]},{"translation":[0,1,0]},{"mesh":0,"skin":0},)"
        R"({"camera":0,"translation":[0,0,3],"children":[4]},{"camera":1,"extensions":{"KHR_lights_punctual":{"light":0}}}],)"
        R"("scenes":[{"nodes":[0,2,3]}],)"
        R"("animations":[{"name":"bend","samplers":[{"input":6,"output":7},{"input":6,"output":8,"interpolation":"CUBICSPLINE"},)"
        R"({"input":6,"output":9,"interpolation":"STEP"}],)"
        R"("channels":[{"sampler":0,"target":{"node":1,"path":"rotation"}},{"sampler":1,"target":{"node":2,"path":"weights"}},)"
        R"({"sampler":2,"target":{"node":3,"path":"translation"}}]}]})";
    put("gltf", "skin-morph-animation.gltf", skin);
    // KHR_texture_transform on each kind of texture reference (offset,
    // rotation, scale, texCoord override), KHR_materials_unlit, and spot
    // and ranged lights (KHR_lights_punctual).
    put("gltf", "extensions.gltf",
        R"({"asset":{"version":"2.0"},"extensionsUsed":["KHR_texture_transform","KHR_materials_unlit","KHR_lights_punctual"],)"
        R"("extensionsRequired":["KHR_texture_transform"],)"
        R"("extensions":{"KHR_lights_punctual":{"lights":[{"type":"spot","intensity":4,"range":3,)"
        R"("spot":{"innerConeAngle":0.1,"outerConeAngle":0.6}},{"type":"point","range":0.5}]}},)"
        R"("buffers":[{"uri":"b.bin","byteLength":256}],)"
        R"("bufferViews":[{"buffer":0,"byteLength":36},{"buffer":0,"byteOffset":36,"byteLength":24}],)"
        R"("accessors":[{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3"},)"
        R"({"bufferView":1,"componentType":5126,"count":3,"type":"VEC2"}],)"
        R"("meshes":[{"primitives":[{"attributes":{"POSITION":0,"TEXCOORD_0":1,"TEXCOORD_1":1},"material":0},)"
        R"({"attributes":{"POSITION":0,"TEXCOORD_0":1},"material":1}]}],)"
        R"("nodes":[{"mesh":0},{"translation":[0,0,2],"extensions":{"KHR_lights_punctual":{"light":0}}},)"
        R"({"rotation":[0,0.7071,0,0.7071],"extensions":{"KHR_lights_punctual":{"light":1}}},)"
        R"({"extensions":{"KHR_lights_punctual":{"light":7}}}],"scenes":[{"nodes":[0,1,2,3]}],)"
        R"("images":[{"uri":"t.png"}],"samplers":[{"magFilter":9728}],"textures":[{"source":0,"sampler":0}],)"
        R"("materials":[{"pbrMetallicRoughness":{"baseColorTexture":{"index":0,"extensions":{"KHR_texture_transform":)"
        R"({"offset":[0.5,-0.25],"rotation":1.5707963,"scale":[2,0.5]}}},"metallicRoughnessTexture":{"index":0,)"
        R"("extensions":{"KHR_texture_transform":{"texCoord":1,"scale":[1e30,-1e-30]}}}},)"
        R"("normalTexture":{"index":0,"extensions":{"KHR_texture_transform":{"rotation":"x","offset":[1]}}},)"
        R"("emissiveTexture":{"index":0,"extensions":{"KHR_texture_transform":{"texCoord":7}}}},)"
        R"({"extensions":{"KHR_materials_unlit":{}},"pbrMetallicRoughness":{"baseColorFactor":[0.2,0.4,0.6,0.5],)"
        R"("baseColorTexture":{"index":0}},"alphaMode":"BLEND"}]})");
    // The material extensions (specular, clearcoat with its own normal map,
    // sheen, transmission, volume, each with its textures and transforms) and
    // KHR_materials_variants' mappings, one of them out of range.
    put("gltf", "material-extensions.gltf",
        R"({"asset":{"version":"2.0"},"extensionsUsed":["KHR_materials_specular","KHR_materials_clearcoat",)"
        R"("KHR_materials_sheen","KHR_materials_transmission","KHR_materials_volume","KHR_materials_variants",)"
        R"("KHR_texture_transform"],)"
        R"("extensions":{"KHR_materials_variants":{"variants":[{"name":"red"},{"name":"glass"},{}]}},)"
        R"("buffers":[{"uri":"b.bin","byteLength":256}],)"
        R"("bufferViews":[{"buffer":0,"byteLength":36},{"buffer":0,"byteOffset":36,"byteLength":24}],)"
        R"("accessors":[{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3"},)"
        R"({"bufferView":1,"componentType":5126,"count":3,"type":"VEC2"}],)"
        R"("meshes":[{"primitives":[{"attributes":{"POSITION":0,"TEXCOORD_0":1},"material":0,)"
        R"("extensions":{"KHR_materials_variants":{"mappings":[{"material":1,"variants":[0]},)"
        R"({"material":2,"variants":[1,5]},{"material":9,"variants":[2]}]}}}]}],)"
        R"("nodes":[{"mesh":0}],"scenes":[{"nodes":[0]}],)"
        R"("images":[{"uri":"t.png"}],"textures":[{"source":0}],)"
        R"("materials":[{"extensions":{"KHR_materials_specular":{"specularFactor":0.5,"specularColorFactor":[1,0.5,0],)"
        R"("specularTexture":{"index":0},"specularColorTexture":{"index":0,"texCoord":1}},)"
        R"("KHR_materials_sheen":{"sheenColorFactor":[0.9,0.5,0.8],"sheenRoughnessFactor":0.5,)"
        R"("sheenColorTexture":{"index":0},"sheenRoughnessTexture":{"index":0}}}},)"
        R"({"extensions":{"KHR_materials_clearcoat":{"clearcoatFactor":1,"clearcoatRoughnessFactor":0.2,)"
        R"("clearcoatTexture":{"index":0},"clearcoatRoughnessTexture":{"index":0},)"
        R"("clearcoatNormalTexture":{"index":0,"scale":2,"extensions":{"KHR_texture_transform":{"rotation":1}}}}}},)"
        R"({"extensions":{"KHR_materials_transmission":{"transmissionFactor":1,"transmissionTexture":{"index":0}},)"
        R"("KHR_materials_volume":{"thicknessFactor":0.5,"thicknessTexture":{"index":0},)"
        R"("attenuationDistance":2,"attenuationColor":[1,0.5,0.25]}}}]})");
    put("gltf", "min-version.gltf",
        R"({"asset":{"version":"2.1","minVersion":"2.1"},"buffers":[{"uri":"b.bin","byteLength":256}],)"
        R"("bufferViews":[{"buffer":0,"byteLength":36}],)"
        R"("accessors":[{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3"}],)"
        R"("meshes":[{"primitives":[{"attributes":{"POSITION":0}}]}],"nodes":[{"mesh":0}],"scenes":[{"nodes":[0]}]})");
}

// ---- Compressed glTF data (EXT_meshopt_compression, KHR_draco_mesh_compression, EXT_texture_webp)

using json = nlohmann::json;

std::string data_uri(const std::string& type, const std::string& bytes) {
    return "data:" + type + ";base64," + base64(bytes);
}

// A .glb of `doc` with `bin` as its BIN chunk (buffer 0).
std::string make_glb(const json& doc, std::string bin) {
    std::string text = doc.dump();
    while (text.size() % 4) text += ' ';
    while (bin.size() % 4) bin += '\0';
    std::string out = "glTF";
    const auto u32 = [&](std::size_t v) {
        for (int k = 0; k < 4; ++k) out += char((v >> (8 * k)) & 0xff);
    };
    u32(2);
    u32(12 + 8 + text.size() + 8 + bin.size());
    u32(text.size());
    u32(0x4E4F534Au);
    out += text;
    u32(bin.size());
    u32(0x004E4942u);
    out += bin;
    return out;
}

template <class T> std::string raw_bytes(const std::vector<T>& v) {
    return std::string(reinterpret_cast<const char*>(v.data()), v.size() * sizeof(T));
}

// A bent 4x4 grid (16 vertices, 18 triangles): small, so that the fuzzer
// runs it fast, with every attribute the seeds compress.
struct SeedGrid {
    static constexpr int kSide = 4;
    std::vector<float> pos, nrm, tan, uv;
    std::vector<std::uint32_t> idx;
    SeedGrid() {
        for (int y = 0; y < kSide; ++y)
            for (int x = 0; x < kSide; ++x) {
                const float u = float(x) / (kSide - 1), v = float(y) / (kSide - 1);
                pos.insert(pos.end(), {2.0f * u - 1.0f, 1.0f - 2.0f * v, 0.3f * std::sin(3.0f * u) * std::cos(2.0f * v)});
                const float nx = -0.9f * std::cos(3.0f * u) * std::cos(2.0f * v), ny = 0.6f * std::sin(3.0f * u);
                const float len = std::sqrt(nx * nx + ny * ny + 1.0f);
                nrm.insert(nrm.end(), {nx / len, ny / len, 1.0f / len});
                tan.insert(tan.end(), {1.0f / len, 0.0f, -nx / len, 1.0f});
                uv.insert(uv.end(), {u, v});
            }
        for (int y = 0; y + 1 < kSide; ++y)
            for (int x = 0; x + 1 < kSide; ++x) {
                const std::uint32_t a = std::uint32_t(y * kSide + x), b = a + 1, c = a + kSide, d = c + 1;
                idx.insert(idx.end(), {a, c, b, b, c, d});
            }
    }
    std::size_t vertices() const { return pos.size() / 3; }
};

#if defined(PRAST_HAVE_MESHOPT_ENCODER)
// One bufferView: its decoded bytes, the accessor reading them, and the
// stream libmeshoptimizer encodes them to.
struct MeshoptView {
    std::string raw, packed;
    std::size_t stride = 0, count = 0;
    std::string mode = "ATTRIBUTES", filter = "NONE";
    json accessor;
};

MeshoptView meshopt_attributes(const std::string& raw, std::size_t stride, const std::string& filter, json accessor) {
    MeshoptView v;
    v.raw = raw;
    v.stride = stride;
    v.count = raw.size() / stride;
    v.filter = filter;
    v.accessor = std::move(accessor);
    v.accessor["count"] = v.count;
    std::vector<unsigned char> out(meshopt_encodeVertexBufferBound(v.count, stride));
    out.resize(meshopt_encodeVertexBuffer(out.data(), out.size(), raw.data(), v.count, stride));
    v.packed.assign(out.begin(), out.end());
    return v;
}

MeshoptView meshopt_indices(const std::vector<std::uint32_t>& idx, std::size_t stride, bool triangles, std::size_t vertices) {
    MeshoptView v;
    v.stride = stride;
    v.count = idx.size();
    v.mode = triangles ? "TRIANGLES" : "INDICES";
    for (std::uint32_t i : idx) v.raw.append(reinterpret_cast<const char*>(&i), stride);  // little-endian: the low bytes
    v.accessor = {{"componentType", stride == 2 ? 5123 : 5125}, {"type", "SCALAR"}, {"count", v.count}};
    std::vector<unsigned char> out(triangles ? meshopt_encodeIndexBufferBound(idx.size(), vertices)
                                             : meshopt_encodeIndexSequenceBound(idx.size(), vertices));
    out.resize(triangles ? meshopt_encodeIndexBuffer(out.data(), out.size(), idx.data(), idx.size())
                         : meshopt_encodeIndexSequence(out.data(), out.size(), idx.data(), idx.size()));
    v.packed.assign(out.begin(), out.end());
    return v;
}

// Every mode and filter: POSITION (ATTRIBUTES), NORMAL as normalized bytes
// (OCTAHEDRAL, stride 4), TANGENT as normalized shorts (OCTAHEDRAL, stride
// 8), TEXCOORD_0 (EXPONENTIAL), indices as TRIANGLES (16 and 32 bits) and
// INDICES; an animation's times (ATTRIBUTES, stride 4), rotations
// (QUATERNION) and translations (EXPONENTIAL).
std::vector<MeshoptView> meshopt_views() {
    const SeedGrid g;
    const std::size_t n = g.vertices();
    std::vector<MeshoptView> views;
    views.push_back(meshopt_attributes(raw_bytes(g.pos), 12, "NONE",
                                       {{"componentType", 5126}, {"type", "VEC3"}, {"min", {-1, -1, -1}}, {"max", {1, 1, 1}}}));
    std::vector<float> nrm4;
    for (std::size_t i = 0; i < n; ++i) nrm4.insert(nrm4.end(), {g.nrm[3 * i], g.nrm[3 * i + 1], g.nrm[3 * i + 2], 0.0f});
    std::string oct8(n * 4, '\0'), oct16(n * 8, '\0');
    meshopt_encodeFilterOct(oct8.data(), n, 4, 8, nrm4.data());
    meshopt_encodeFilterOct(oct16.data(), n, 8, 12, g.tan.data());
    views.push_back(meshopt_attributes(oct8, 4, "OCTAHEDRAL", {{"componentType", 5120}, {"normalized", true}, {"type", "VEC3"}}));
    views.push_back(meshopt_attributes(oct16, 8, "OCTAHEDRAL", {{"componentType", 5122}, {"normalized", true}, {"type", "VEC4"}}));
    std::string exp_uv(n * 8, '\0');
    meshopt_encodeFilterExp(exp_uv.data(), n, 8, 15, g.uv.data());
    views.push_back(meshopt_attributes(exp_uv, 8, "EXPONENTIAL", {{"componentType", 5126}, {"type", "VEC2"}}));
    views.push_back(meshopt_indices(g.idx, 2, true, n));
    views.push_back(meshopt_indices(g.idx, 4, false, n));
    views.push_back(meshopt_indices(g.idx, 4, true, n));
    const std::vector<float> times = {0.0f, 0.5f, 1.0f, 2.0f};
    views.push_back(meshopt_attributes(raw_bytes(times), 4, "NONE",
                                       {{"componentType", 5126}, {"type", "SCALAR"}, {"min", {0}}, {"max", {2}}}));
    const float h = 0.70710678f;
    const std::vector<float> quats = {0, 0, 0, 1, 0, h, 0, h, h, 0, 0, h, 0.5f, 0.5f, 0.5f, 0.5f};
    std::string quat(4 * 8, '\0');
    meshopt_encodeFilterQuat(quat.data(), 4, 8, 12, quats.data());
    views.push_back(meshopt_attributes(quat, 8, "QUATERNION", {{"componentType", 5122}, {"normalized", true}, {"type", "VEC4"}}));
    const std::vector<float> moves = {0, 0, 0, 1.5f, -2, 0.25f, 1e-3f, 4, 0, -3, 0, 1};
    std::string exp_t(4 * 12, '\0');
    meshopt_encodeFilterExp(exp_t.data(), 4, 12, 18, moves.data());
    views.push_back(meshopt_attributes(exp_t, 12, "EXPONENTIAL", {{"componentType", 5126}, {"type", "VEC3"}}));
    return views;
}

enum class MeshoptLayout { GltfFallback, GlbGltfpack, GltfWithData };

// The model of meshopt_views() in one of three layouts: a .gltf whose buffer
// 0 is a uri-less fallback (the streams in buffer 1, a data URI); gltfpack's
// .glb (the streams in the BIN chunk, buffer 1 the uri-less fallback); a
// .gltf whose fallback holds the uncompressed data, under
// KHR_meshopt_compression, with the stream of view `broken` given a bad
// header byte (the loader warns and reads the fallback).
std::string meshopt_model(const std::vector<MeshoptView>& views, MeshoptLayout layout, int broken = -1) {
    const char* ext = layout == MeshoptLayout::GltfWithData ? "KHR_meshopt_compression" : "EXT_meshopt_compression";
    const int raw_buffer = layout == MeshoptLayout::GlbGltfpack ? 1 : 0, packed_buffer = 1 - raw_buffer;
    std::string raw, packed;
    json bviews = json::array(), accessors = json::array();
    for (std::size_t i = 0; i < views.size(); ++i) {
        const MeshoptView& v = views[i];
        while (raw.size() % 4) raw += '\0';
        while (packed.size() % 4) packed += '\0';
        json bv = {{"buffer", raw_buffer}, {"byteOffset", raw.size()}, {"byteLength", v.raw.size()}};
        if (v.mode == "ATTRIBUTES" && v.stride % 4 == 0 && v.accessor["type"] != "SCALAR") bv["byteStride"] = v.stride;
        json e = {{"buffer", packed_buffer}, {"byteOffset", packed.size()}, {"byteLength", v.packed.size()},
                  {"byteStride", v.stride},  {"count", v.count},           {"mode", v.mode}};
        if (v.filter != "NONE") e["filter"] = v.filter;
        bv["extensions"][ext] = e;
        bviews.push_back(bv);
        json a = v.accessor;
        a["bufferView"] = i;
        accessors.push_back(a);
        raw += v.raw;
        std::string p = v.packed;
        if (int(i) == broken) p[0] = '\x42';
        packed += p;
    }
    json doc = {{"asset", {{"version", "2.0"}}}, {"extensionsUsed", {ext, "KHR_mesh_quantization"}},
                {"extensionsRequired", {ext, "KHR_mesh_quantization"}}};
    doc["bufferViews"] = bviews;
    doc["accessors"] = accessors;
    doc["meshes"] = json::array({{{"primitives", json::array({
                                      {{"attributes", {{"POSITION", 0}, {"NORMAL", 1}, {"TANGENT", 2}, {"TEXCOORD_0", 3}}},
                                       {"indices", 4}},
                                      {{"attributes", {{"POSITION", 0}}}, {"indices", 5}},
                                      {{"attributes", {{"POSITION", 0}}}, {"indices", 6}, {"mode", 4}},
                                  })}}});
    doc["nodes"] = json::array({{{"mesh", 0}}});
    doc["scenes"] = json::array({{{"nodes", {0}}}});
    doc["scene"] = 0;
    doc["animations"] = json::array({{{"samplers", json::array({{{"input", 7}, {"output", 8}}, {{"input", 7}, {"output", 9}}})},
                                      {"channels", json::array({{{"sampler", 0}, {"target", {{"node", 0}, {"path", "rotation"}}}},
                                                                {{"sampler", 1}, {"target", {{"node", 0}, {"path", "translation"}}}}})}}});
    const json fallback = {{"byteLength", raw.size()}, {"extensions", {{ext, {{"fallback", true}}}}}};
    switch (layout) {
    case MeshoptLayout::GltfFallback:
        doc["buffers"] = json::array({fallback, {{"byteLength", packed.size()}, {"uri", data_uri("application/octet-stream", packed)}}});
        return doc.dump();
    case MeshoptLayout::GltfWithData:
        doc["buffers"] = json::array({{{"byteLength", raw.size()}, {"uri", data_uri("application/octet-stream", raw)}},
                                      {{"byteLength", packed.size()}, {"uri", data_uri("application/octet-stream", packed)}}});
        return doc.dump();
    case MeshoptLayout::GlbGltfpack:
        while (packed.size() % 4) packed += '\0';
        doc["buffers"] = json::array({{{"byteLength", packed.size()}}, fallback});
        return make_glb(doc, packed);
    }
    return "";
}
#endif

// The grid as a Draco stream (libdraco's encoder): `method` sequential or
// edgebreaker, quantized or lossless; the ids of POSITION, NORMAL, TEXCOORD_0.
std::string draco_stream(int method, bool quantize, int ids[3]) {
    const SeedGrid g;
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
    if (quantize) {
        encoder.SetAttributeQuantization(draco::GeometryAttribute::POSITION, 11);
        encoder.SetAttributeQuantization(draco::GeometryAttribute::NORMAL, 8);
        encoder.SetAttributeQuantization(draco::GeometryAttribute::TEX_COORD, 10);
        encoder.SetSpeedOptions(5, 5);
    }
    draco::EncoderBuffer out;
    if (!encoder.EncodeMeshToBuffer(mesh, &out).ok()) {
        std::fprintf(stderr, "fuzz_make_seeds: libdraco could not encode the grid\n");
        std::exit(1);
    }
    return std::string(out.data(), out.size());
}

// A Draco primitive, and a second one that also has uncompressed accessors
// (its fallback: the stream given a wrong face count, so the loader warns
// and reads them). `glb`: the stream in the BIN chunk.
std::string draco_model(const std::string& stream, const int ids[3], bool glb) {
    const SeedGrid g;
    const std::size_t n = g.vertices();
    std::vector<std::uint16_t> idx16(g.idx.begin(), g.idx.end());
    std::string bin = stream;
    while (bin.size() % 4) bin += '\0';
    const std::size_t raw_at = bin.size();
    bin += raw_bytes(g.pos) + raw_bytes(g.nrm) + raw_bytes(g.uv) + raw_bytes(idx16);
    std::string other = stream;
    // One count made wrong: sequential, the faces (byte 11); edgebreaker, the
    // vertices (byte 12, after the traversal type), one more than POSITION's.
    const std::size_t count_at = stream[8] == 1 ? 12 : 11;
    other[count_at] = char(other[count_at] ^ 1);
    while (bin.size() % 4) bin += '\0';
    const std::size_t other_at = bin.size();
    bin += other;
    json doc = {{"asset", {{"version", "2.0"}}},
                {"extensionsUsed", {"KHR_draco_mesh_compression"}},
                {"extensionsRequired", {"KHR_draco_mesh_compression"}}};
    doc["buffers"] = json::array({glb ? json{{"byteLength", bin.size()}}
                                      : json{{"byteLength", bin.size()}, {"uri", data_uri("application/octet-stream", bin)}}});
    const std::size_t p = n * 12, q = n * 24, r = n * 32;
    doc["bufferViews"] = json::array({{{"buffer", 0}, {"byteLength", stream.size()}},
                                      {{"buffer", 0}, {"byteOffset", raw_at}, {"byteLength", p}},
                                      {{"buffer", 0}, {"byteOffset", raw_at + p}, {"byteLength", q - p}},
                                      {{"buffer", 0}, {"byteOffset", raw_at + q}, {"byteLength", r - q}},
                                      {{"buffer", 0}, {"byteOffset", raw_at + r}, {"byteLength", idx16.size() * 2}},
                                      {{"buffer", 0}, {"byteOffset", other_at}, {"byteLength", other.size()}}});
    const json bounds_min = {-1, -1, -1}, bounds_max = {1, 1, 1};
    doc["accessors"] = json::array({
        {{"componentType", 5126}, {"type", "VEC3"}, {"count", n}, {"min", bounds_min}, {"max", bounds_max}},
        {{"componentType", 5126}, {"type", "VEC3"}, {"count", n}},
        {{"componentType", 5126}, {"type", "VEC2"}, {"count", n}},
        {{"componentType", 5123}, {"type", "SCALAR"}, {"count", g.idx.size()}},
        {{"bufferView", 1}, {"componentType", 5126}, {"type", "VEC3"}, {"count", n}, {"min", bounds_min}, {"max", bounds_max}},
        {{"bufferView", 2}, {"componentType", 5126}, {"type", "VEC3"}, {"count", n}},
        {{"bufferView", 3}, {"componentType", 5126}, {"type", "VEC2"}, {"count", n}},
        {{"bufferView", 4}, {"componentType", 5123}, {"type", "SCALAR"}, {"count", g.idx.size()}},
    });
    const json names = {{"POSITION", ids[0]}, {"NORMAL", ids[1]}, {"TEXCOORD_0", ids[2]}};
    doc["meshes"] = json::array({{{"primitives", json::array({
        {{"attributes", {{"POSITION", 0}, {"NORMAL", 1}, {"TEXCOORD_0", 2}}}, {"indices", 3},
         {"extensions", {{"KHR_draco_mesh_compression", {{"bufferView", 0}, {"attributes", names}}}}}},
        {{"attributes", {{"POSITION", 4}, {"NORMAL", 5}, {"TEXCOORD_0", 6}}}, {"indices", 7}, {"mode", 4},
         {"extensions", {{"KHR_draco_mesh_compression", {{"bufferView", 5}, {"attributes", names}}}}}},
    })}}});
    doc["nodes"] = json::array({{{"mesh", 0}}, {{"mesh", 0}, {"translation", {0, 0, -1}}}});
    doc["scenes"] = json::array({{{"nodes", {0, 1}}}});
    doc["scene"] = 0;
    return glb ? make_glb(doc, bin) : doc.dump();
}

// A pattern with some structure (edges and a gradient) for the WebP encoders.
std::vector<std::uint8_t> webp_pattern(int w, int h, int channels) {
    std::vector<std::uint8_t> px(std::size_t(w) * std::size_t(h) * std::size_t(channels));
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            for (int c = 0; c < channels; ++c)
                px[(std::size_t(y) * std::size_t(w) + std::size_t(x)) * std::size_t(channels) + std::size_t(c)] =
                    std::uint8_t(c == 3 ? 40 + (x * 29 + y * 7) % 200 : ((x / 2 + y) % 3) * 90 + c * 20 + x);
    return px;
}

// Lossless and lossy, each without and with alpha (lossy alpha is VP8X with
// an ALPH chunk), small and odd-sized.
std::vector<std::pair<std::string, std::string>> webp_files() {
    struct Kind {
        const char* name;
        int w, h, channels;
        bool lossless;
    };
    const Kind kinds[] = {{"lossless-rgb", 7, 5, 3, true}, {"lossless-rgba", 6, 4, 4, true},
                          {"lossy-rgb", 9, 9, 3, false},   {"lossy-rgba", 8, 6, 4, false},
                          {"lossless-1x1", 1, 1, 3, true}, {"lossy-33x17", 33, 17, 3, false}};
    std::vector<std::pair<std::string, std::string>> files;
    for (const Kind& k : kinds) {
        const std::vector<std::uint8_t> px = webp_pattern(k.w, k.h, k.channels);
        std::uint8_t* out = nullptr;
        const int stride = k.w * k.channels;
        std::size_t n = 0;
        if (k.lossless)
            n = k.channels == 4 ? WebPEncodeLosslessRGBA(px.data(), k.w, k.h, stride, &out)
                                : WebPEncodeLosslessRGB(px.data(), k.w, k.h, stride, &out);
        else
            n = k.channels == 4 ? WebPEncodeRGBA(px.data(), k.w, k.h, stride, 70.0f, &out)
                                : WebPEncodeRGB(px.data(), k.w, k.h, stride, 40.0f, &out);
        if (n == 0) {
            std::fprintf(stderr, "fuzz_make_seeds: libwebp could not encode %s\n", k.name);
            std::exit(1);
        }
        files.emplace_back(k.name, std::string(reinterpret_cast<const char*>(out), n));
        WebPFree(out);
    }
    return files;
}

// EXT_texture_webp textures whose images the loader decodes (a
// specular-glossiness material is converted texel by texel at load), with
// PNG fallbacks: `glb` puts the WebPs in bufferViews (mimeType image/webp,
// as gltfpack does), else in data URIs.
std::string webp_model(const std::vector<std::pair<std::string, std::string>>& webps, bool glb) {
    json doc = {{"asset", {{"version", "2.0"}}},
                {"extensionsUsed", {"EXT_texture_webp", "KHR_materials_pbrSpecularGlossiness"}},
                {"extensionsRequired", {"EXT_texture_webp"}}};
    std::string bin;
    auto f32 = [&](float v) { bin.append(reinterpret_cast<const char*>(&v), 4); };
    for (float v : {0.f, 0.f, 0.f, 1.f, 0.f, 0.f, 0.f, 1.f, 0.f}) f32(v);
    for (float v : {0.f, 0.f, 1.f, 0.f, 0.f, 1.f}) f32(v);
    json views = json::array({{{"buffer", 0}, {"byteLength", 36}}, {{"buffer", 0}, {"byteOffset", 36}, {"byteLength", 24}}});
    json images = json::array({{{"uri", data_uri("image/png", prast::fuzz::tiny_png())}}});
    json textures = json::array();
    for (const auto& [name, bytes] : webps) {
        (void)name;
        if (glb) {
            while (bin.size() % 4) bin += '\0';
            views.push_back({{"buffer", 0}, {"byteOffset", bin.size()}, {"byteLength", bytes.size()}});
            bin += bytes;
            images.push_back({{"bufferView", views.size() - 1}, {"mimeType", "image/webp"}});
        } else {
            images.push_back({{"uri", data_uri("image/webp", bytes)}});
        }
        textures.push_back({{"source", 0}, {"extensions", {{"EXT_texture_webp", {{"source", images.size() - 1}}}}}});
    }
    textures.push_back({{"extensions", {{"EXT_texture_webp", {{"source", 1}}}}}});  // no fallback
    textures.push_back({{"source", 0}, {"extensions", {{"EXT_texture_webp", {{"source", 99}}}}}});  // out of range
    doc["bufferViews"] = views;
    doc["images"] = images;
    doc["textures"] = textures;
    doc["buffers"] = json::array({glb ? json{{"byteLength", bin.size()}}
                                      : json{{"byteLength", bin.size()}, {"uri", data_uri("application/octet-stream", bin)}}});
    doc["accessors"] = json::array({{{"bufferView", 0}, {"componentType", 5126}, {"type", "VEC3"}, {"count", 3},
                                     {"min", {0, 0, 0}}, {"max", {1, 1, 0}}},
                                    {{"bufferView", 1}, {"componentType", 5126}, {"type", "VEC2"}, {"count", 3}}});
    json materials = json::array(), prims = json::array();
    const std::size_t t = textures.size();
    for (std::size_t i = 0; i + 1 < webps.size(); i += 2) {
        materials.push_back({{"extensions", {{"KHR_materials_pbrSpecularGlossiness",
                                              {{"diffuseTexture", {{"index", i}}}, {"specularGlossinessTexture", {{"index", i + 1}}},
                                               {"specularFactor", {1, 0.8, 0.2}}}}}}});
    }
    materials.push_back({{"pbrMetallicRoughness", {{"baseColorTexture", {{"index", t - 2}}}}},
                         {"normalTexture", {{"index", t - 1}}}});
    for (std::size_t m = 0; m < materials.size(); ++m)
        prims.push_back({{"attributes", {{"POSITION", 0}, {"TEXCOORD_0", 1}}}, {"material", m}});
    doc["materials"] = materials;
    doc["meshes"] = json::array({{{"primitives", prims}}});
    doc["nodes"] = json::array({{{"mesh", 0}}});
    doc["scenes"] = json::array({{{"nodes", {0}}}});
    doc["scene"] = 0;
    return glb ? make_glb(doc, bin) : doc.dump();
}

void compression_seeds() {
#if defined(PRAST_HAVE_MESHOPT_ENCODER)
    meshopt_encodeVertexVersion(0);
    meshopt_encodeIndexVersion(1);
    const std::vector<MeshoptView> views = meshopt_views();
    put("gltf", "meshopt-modes-filters.gltf", meshopt_model(views, MeshoptLayout::GltfFallback));
    put("gltf", "meshopt-gltfpack.glb", meshopt_model(views, MeshoptLayout::GlbGltfpack));
    put("gltf", "meshopt-khr-with-data.gltf", meshopt_model(views, MeshoptLayout::GltfWithData, 4));
    // fuzz_meshopt's seeds: each stream behind its 4-byte prefix (fuzz/fuzz_meshopt.cpp).
    for (std::size_t i = 0; i < views.size(); ++i) {
        const MeshoptView& v = views[i];
        const int mode = v.mode == "TRIANGLES" ? 1 : v.mode == "INDICES" ? 2 : 0;
        const int filter = v.filter == "OCTAHEDRAL" ? 1 : v.filter == "QUATERNION" ? 2 : v.filter == "EXPONENTIAL" ? 3 : 0;
        const int stride = mode == 0 ? int(v.stride / 4 - 1) : v.stride == 4 ? 1 : 0;
        const std::string prefix = {char(mode | filter << 2), char(stride), char(v.count & 0xff), char(v.count >> 8)};
        put("meshopt", "view" + std::to_string(i) + "-" + v.mode + "-" + v.filter + "-stride" + std::to_string(v.stride),
            prefix + v.packed);
    }
#else
    std::fprintf(stderr, "fuzz_make_seeds: no libmeshoptimizer (apt-get install libmeshoptimizer-dev): "
                         "no EXT_meshopt_compression seeds but meshopt-required.gltf\n");
#endif
    for (const bool quantize : {false, true}) {
        int ids[3];
        const std::string q = quantize ? "-quantized" : "";
        const std::string seq = draco_stream(draco::MESH_SEQUENTIAL_ENCODING, quantize, ids);
        put("gltf", "draco-sequential" + q + ".gltf", draco_model(seq, ids, false));
        const std::string eb = draco_stream(draco::MESH_EDGEBREAKER_ENCODING, quantize, ids);
        put("gltf", "draco-edgebreaker" + q + ".glb", draco_model(eb, ids, true));
    }
    const std::vector<std::pair<std::string, std::string>> webps = webp_files();
    for (const auto& [name, bytes] : webps) put("webp", name + ".webp", bytes);
    put("gltf", "webp-textures.glb", webp_model(webps, true));
    put("gltf", "webp-textures.gltf", webp_model({webps[0], webps[3]}, false));
}

void cli_seeds() {
    const char* lines[] = {
        "model.glb|-o|out.png|--size|96x64",
        "--eye|1,2,3|--target|0,0,0|--up|0,1,0|--fov|30|--near|0.1|--far|100",
        "--sun|0,1,0:3,3,3|--point|1,2,3:10,10,10|--ambient|0.1,0.1,0.1|--no-default-lights",
        "--brdf=gltf|--exposure|2|--tonemap|neutral|--view|normal",
        "--frames|12|--orbit|-90|-o|t_%04d.png|--frame-range|3-7|--threads|2|--tile|32",
        "--repeat|3|--stats|--pixel|5,6|--size|32x32|-o|a%%b.hdr",
        "--allow-outside-paths|m.obj|--|-weird.obj",
        "--help",
    };
    int n = 0;
    for (const char* line : lines) {
        std::string s = line;
        for (char& c : s)
            if (c == '|') c = '\0';
        put("cli", "args" + std::to_string(n++), s);
    }
}

void step_seeds() {
    put("step", "overview", "help\nframe\ntri 0\ntile 0 0\npixel 24 16\n");
    put("step", "stages", "stage depth\nstage coverage\nupto 3\nverify\n");
    put("step", "errors", "tri -1\ntile 99 0\npixel 48 0\nupto x\nstage nope\nbogus\n# comment\nquit\n");
    put("step", "views", "draws\ndraw 0\ntextures\ntexel 0 0 1 1\njson texel 0 0 0 0\nvertices 0 0 4\n"
                         "json tile 0 0 pixel 1 1\nupto 2\npixel 24 16\nupto all\npixel 24 16\ntexel 0 9 0 0\n");
}

} // namespace

int main(int argc, char** argv) {
    if (argc != 2) {
        std::fprintf(stderr, "usage: fuzz_make_seeds OUTDIR\n");
        return 2;
    }
    g_out = argv[1];
    image_seeds();
    obj_seeds();
    gltf_seeds();
    compression_seeds();
    cli_seeds();
    step_seeds();
    return 0;
}

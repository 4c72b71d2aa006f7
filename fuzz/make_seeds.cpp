// Writes the seed corpora of the harnesses: `fuzz_make_seeds OUT` fills
// OUT/obj, OUT/gltf, OUT/png, OUT/jpeg, OUT/hdr, OUT/cli and OUT/step with small valid
// inputs that reach every branch the fuzzers should start from (materials
// and maps, every glTF accessor kind, each image channel count, the HDR
// run-length and flat paths, every render flag). Made by the project, so no
// file of unknown origin is needed; scripts/fuzz.sh runs it.
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include <stb_image_write.h>

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
    put("gltf", "min-version.gltf",
        R"({"asset":{"version":"2.1","minVersion":"2.1"},"buffers":[{"uri":"b.bin","byteLength":256}],)"
        R"("bufferViews":[{"buffer":0,"byteLength":36}],)"
        R"("accessors":[{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3"}],)"
        R"("meshes":[{"primitives":[{"attributes":{"POSITION":0}}]}],"nodes":[{"mesh":0}],"scenes":[{"nodes":[0]}]})");
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
    cli_seeds();
    step_seeds();
    return 0;
}

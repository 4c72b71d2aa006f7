// What each libFuzzer harness does with one input, shared with the doctest
// case that replays tests/fuzz-regressions/ (tests/test_hostile.cpp), so a
// regression file is run exactly as the fuzzer ran it. Each function returns
// normally for an input handled cleanly (loaded, or refused with LoadError);
// anything else escaping, a crash, a sanitizer report or a hang is a finding.
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include <sys/stat.h>
#include <unistd.h>

#include "apps/render_options.h"
#include "scene/animation.h"
#include "scene/image.h"
#include "scene/load_scene.h"

namespace prast::fuzz {

enum class Target { Obj, Gltf, Png, Jpeg, Hdr, Cli, Webp };

inline void write_file(const std::string& path, const void* data, std::size_t size) {
    std::FILE* f = std::fopen(path.c_str(), "wb");
    if (!f) std::abort();
    if (size && std::fwrite(data, 1, size, f) != size) std::abort();
    std::fclose(f);
}

inline void write_file(const std::string& path, const std::string& text) { write_file(path, text.data(), text.size()); }

// A valid 1x1 grey PNG, 67 bytes.
inline std::string tiny_png() {
    static const unsigned char png[] = {
        0x89, 0x50, 0x4E, 0x47, 0x0D, 0x0A, 0x1A, 0x0A, 0x00, 0x00, 0x00, 0x0D, 0x49, 0x48, 0x44, 0x52,
        0x00, 0x00, 0x00, 0x01, 0x00, 0x00, 0x00, 0x01, 0x08, 0x00, 0x00, 0x00, 0x00, 0x3A, 0x7E, 0x9B,
        0x55, 0x00, 0x00, 0x00, 0x0A, 0x49, 0x44, 0x41, 0x54, 0x78, 0x9C, 0x63, 0x68, 0x00, 0x00, 0x00,
        0x82, 0x00, 0x81, 0x77, 0xCD, 0x72, 0xB6, 0x00, 0x00, 0x00, 0x00, 0x49, 0x45, 0x4E, 0x44, 0xAE,
        0x42, 0x60, 0x82};
    return std::string(reinterpret_cast<const char*>(png), sizeof png);
}

// A fresh scratch folder (on /dev/shm when there is one: the loaders read
// files, and tmpfs keeps that cheap) with what the seeds' models name: t.png,
// sub/t.png, and b.bin (a triangle: 3 float positions, then 3 uint16 indices).
inline std::string make_model_dir(const char* tag) {
    const char* base = access("/dev/shm", W_OK) == 0 ? "/dev/shm" : (std::getenv("TMPDIR") ? std::getenv("TMPDIR") : "/tmp");
    std::string dir = std::string(base) + "/prast_fuzz_" + tag + "_XXXXXX";
    if (!mkdtemp(dir.data())) std::abort();
    write_file(dir + "/t.png", tiny_png());
    mkdir((dir + "/sub").c_str(), 0700);
    write_file(dir + "/sub/t.png", tiny_png());
    std::vector<unsigned char> bin(256, 0);
    const float pos[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
    const std::uint16_t idx[3] = {0, 1, 2};
    std::memcpy(bin.data(), pos, sizeof pos);
    std::memcpy(bin.data() + 36, idx, sizeof idx);
    write_file(dir + "/b.bin", bin.data(), bin.size());
    return dir;
}

// OBJ+MTL: the input is an OBJ text, then, after a line "#--mtl--", the text
// of m.mtl (the seeds' OBJs say mtllib m.mtl).
inline void run_obj(const std::string& dir, const std::uint8_t* data, std::size_t size) {
    const std::string text(reinterpret_cast<const char*>(data), size);
    const std::string sep = "#--mtl--\n";
    const std::size_t cut = text.find(sep);
    write_file(dir + "/model.obj", text.substr(0, cut));
    write_file(dir + "/m.mtl", cut == std::string::npos ? std::string() : text.substr(cut + sep.size()));
    try {
        (void)load_obj(dir + "/model.obj").bounds();
    } catch (const LoadError&) {
    }
}

// glTF: .glb when the input starts with "glTF", else .gltf.
inline void run_gltf(const std::string& dir, const std::uint8_t* data, std::size_t size) {
    const bool glb = size >= 4 && std::memcmp(data, "glTF", 4) == 0;
    const std::string path = dir + (glb ? "/model.glb" : "/model.gltf");
    write_file(path, data, size);
    try {
        Scene scene = load_gltf(path);
        (void)scene.bounds();
        // Posing cannot fail once loaded (scene/animation.h): every
        // animation and each alone, at times before, inside and after the
        // keys, and every camera at one of them.
        if (scene.source) {
            const double t = double(size % 97) / 13.0 - 1.0;
            pose_scene(scene, t, kAllAnimations);
            for (int a = 0; a < int(scene.animation_names.size()) && a < 4; ++a) pose_scene(scene, t * 2.0, a);
            pose_scene(scene, 0.0, kNoAnimation);
            for (int c = 0; c < int(scene.cameras.size()) && c < 4; ++c)
                (void)scene_camera(scene, c, t, 1.5f, kAllAnimations);
            (void)scene.bounds();
        }
    } catch (const LoadError&) {
    }
}

// The decoder accepts images up to 2^28 texels (4 GiB as float RGBA), beyond
// a fuzzer's memory limit by design: bigger headers are skipped.
constexpr long long kMaxFuzzTexels = 1 << 22;

// Images: an input without its format's signature gets it in front, so the
// fuzzer stays on that decoder's path (WebP: a RIFF header naming WEBP, the
// chunks being the input). Returns false when the decoded size
// disagrees with the header (a defect too).
inline bool run_image(Target t, const std::uint8_t* data, std::size_t size) {
    ImageSource src;
    src.name = "fuzz";
    if (t == Target::Webp) {
        // RIFF, the RIFF size (what follows it), WEBP: 12 bytes.
        if (!(size >= 12 && std::memcmp(data, "RIFF", 4) == 0 && std::memcmp(data + 8, "WEBP", 4) == 0)) {
            const std::size_t riff = size + 4;
            src.bytes = {'R', 'I', 'F', 'F', std::uint8_t(riff), std::uint8_t(riff >> 8), std::uint8_t(riff >> 16),
                         std::uint8_t(riff >> 24), 'W', 'E', 'B', 'P'};
        }
    } else {
        const char* sig = t == Target::Png ? "\x89PNG\r\n\x1a\n" : t == Target::Jpeg ? "\xff\xd8\xff" : "#?RADIANCE\n";
        const std::size_t n = std::strlen(sig);
        if (!(size >= n && std::memcmp(data, sig, n) == 0)) src.bytes.assign(sig, sig + n);
    }
    src.bytes.insert(src.bytes.end(), data, data + size);
    int w = 0, h = 0;
    if (image_dimensions(src, w, h) && static_cast<long long>(w) * h > kMaxFuzzTexels) return true;
    try {
        const Image img = decode_image(src, size % 2 == 1);
        return img.width == w && img.height == h;
    } catch (const LoadError&) {
    }
    return true;
}

// render's command line: the arguments are the input split at NUL bytes.
// Returns false when a successful parse leaves options render cannot use.
inline bool run_cli(const std::uint8_t* data, std::size_t size) {
    std::vector<std::string> args = {"render"};
    std::string cur;
    for (std::size_t i = 0; i < size && args.size() < 64; ++i) {
        if (data[i] == 0) {
            args.push_back(cur);
            cur.clear();
        } else {
            cur += char(data[i]);
        }
    }
    if (!cur.empty()) args.push_back(cur);
    std::vector<const char*> argv;
    for (const std::string& a : args) argv.push_back(a.c_str());
    RenderOptions o;
    const std::string err = parse_render_args(int(argv.size()), argv.data(), o, std::uint64_t(8) << 30);
    if (!err.empty() || o.help || o.version) return true;

    const auto within = [](const std::optional<glm::vec3>& v) {
        return !v || (std::fabs(v->x) <= kMaxCameraCoordinate && std::fabs(v->y) <= kMaxCameraCoordinate &&
                      std::fabs(v->z) <= kMaxCameraCoordinate);
    };
    if (o.width < 1 || o.height < 1 || o.width > kMaxViewportSize || o.height > kMaxViewportSize) return false;
    if (!(o.fov_deg >= kMinFovDeg && o.fov_deg < 180.0f)) return false;
    if (o.frames < 1 || o.first_frame < 0 || o.first_frame > o.last_frame || o.last_frame >= o.frames) return false;
    if (o.threads < 0 || o.threads > kMaxThreads || o.repeat < 1) return false;
    if (o.tile_size < kMinTileSize || o.tile_size > kMaxTileSize) return false;
    if (!within(o.eye) || !within(o.target)) return false;
    if (!std::isfinite(o.exposure) || !(o.exposure > 0.0f) || !std::isfinite(o.orbit_deg)) return false;
    if (o.near_plane && o.far_plane && !(*o.near_plane < *o.far_plane)) return false;
    const cli::FramePattern pattern(o.output);
    if (!pattern.error.empty() || (o.frames > 1 && !pattern.has_number)) return false;
    if (pattern.format(o.first_frame).empty() || pattern.format(o.last_frame).empty()) return false;
    if (o.pixel && (o.pixel->x >= o.width || o.pixel->y >= o.height)) return false;
    return true;
}

} // namespace prast::fuzz

// bench: frame times of the full PBR pipeline on the speed workloads
// (docs/performance.md), for speed work. Timing belongs here, never in unit
// tests.
//
//   bench [--workload quad,grid,bottle,tea,bunny,builtin] [--threads 1,2] [--repeat N] [--json]
//   bench [SCENE] [--size WxH] [--threads 1,2] [--tiles 64] [--repeat N] [--view NAME] [--flat]
//         [--shadows on|off|both] [--shadow-size N] [--blend ALPHA]
//                                        (shadow maps on, off, or both side by side per
//                                        configuration; --blend: every material alpha BLEND
//                                        with that alpha, the worst case of transparency;
//                                        --shadows applies to the workloads too)
//                                        (any scene, the built-in one by default; --tiles, --view
//                                        or --flat without SCENE also select this mode)
//   bench --alternate [--threads 1,2] ...  one process, frames of each thread count in
//                                        turn; prints the median of the rounds' speed-ups
//   bench --write-workloads DIR          the synthetic workloads as files, plus DIR/commands.txt
//   bench --side-by-side RENDER_A RENDER_B [--workload ...] [--threads 1,2] [--msaa 1,4]
//                                        [--runs N] [--repeat N] [--json]
//                                        each thread count and sample count in turn
//   bench --psnr A.png B.png
//
// The workloads (1920x1080 unless --size, one sun, ambient 0.05, ACES): quad (two triangles
// filling the frame, four 1024x1024 PNG maps from OBJ+MTL, repeated three
// times across: about 1.5 texels a pixel), grid (480x270 quads = 259,200
// triangles of about 8 pixels, constant material), bottle (a revolved profile
// of 6,912 triangles with three 2048x2048 PNG maps: base colour, normal,
// occlusion-roughness-metal, filling about 12% of the frame), tea (the tea set
// glTF, close-up), bunny (the Stanford bunny) and builtin (the built-in scene,
// its own two lights). The synthetic ones are generated deterministically
// into a directory (--workloads DIR, default /tmp/prast-bench-workloads) and
// loaded from there like any file, so any render binary can draw the same
// files: --side-by-side runs two render executables alternately on them
// (whole process, start to PNG written, and the --repeat frame median).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include <sys/wait.h>
#include <unistd.h>

#include "apps/cli/bench_flags.h"
#include "apps/frame_request.h"
#include "scene/default_scene.h"
#include "scene/encode_png.h"
#include "scene/image.h"
#include "scene/image_diff.h"
#include "scene/load_scene.h"
#include "scene/messages.h"
#include "scene/procedural_images.h"
#include "shading/output8.h"
#include "renderer/scene_renderer.h"
#include "shading/tonemap.h"

using namespace prast;
namespace fs = std::filesystem;

namespace {

using Clock = std::chrono::steady_clock;
double ms_since(Clock::time_point t0) { return std::chrono::duration<double, std::milli>(Clock::now() - t0).count(); }

struct Summary {
    double min = 0, median = 0, max = 0;
};
Summary summarise(std::vector<double> v) {
    Summary s;
    if (v.empty()) return s;
    std::sort(v.begin(), v.end());
    const std::size_t n = v.size();
    s.min = v.front();
    s.max = v.back();
    s.median = n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
    return s;
}

// ---- Deterministic content for the synthetic maps: scene/procedural_images'
// value noise on its Linear lattice.

float hash_unit(int x, int y, std::uint32_t seed) { return lattice_value(x, y, seed, NoiseLattice::Linear); }
float value_noise(float u, float v, int cells, std::uint32_t seed) {
    return prast::value_noise(glm::vec2(u, v), cells, seed, NoiseLattice::Linear);
}
float fbm(float u, float v, std::uint32_t seed) {
    return 0.5f * value_noise(u, v, 8, seed) + 0.3f * value_noise(u, v, 32, seed + 1) +
           0.2f * value_noise(u, v, 128, seed + 2);
}
std::uint8_t to_byte(float x) { return std::uint8_t(std::lround(std::clamp(x, 0.0f, 1.0f) * 255.0f)); }

// A size x size map with `channels` bytes per texel from f(u, v, x, y, out).
template <class F>
std::vector<std::uint8_t> make_map(int size, int channels, F f) {
    std::vector<std::uint8_t> px(std::size_t(size) * std::size_t(size) * std::size_t(channels));
    for (int y = 0; y < size; ++y)
        for (int x = 0; x < size; ++x) {
            float c[4] = {0, 0, 0, 1};
            f((float(x) + 0.5f) / float(size), (float(y) + 0.5f) / float(size), x, y, c);
            for (int k = 0; k < channels; ++k)
                px[(std::size_t(y) * std::size_t(size) + std::size_t(x)) * std::size_t(channels) + std::size_t(k)] =
                    to_byte(c[k]);
        }
    return px;
}

void write_file(const fs::path& path, const void* data, std::size_t n) {
    std::ofstream f(path, std::ios::binary);
    f.write(static_cast<const char*>(data), std::streamsize(n));
    if (!f) throw std::runtime_error(path.string() + ": cannot write");
}
void write_png_file(const fs::path& path, const std::vector<std::uint8_t>& px, int size, int channels) {
    PngOptions o = png_options_threads();
    o.zlib_level = 6;  // assets are written once and read often
    const std::vector<std::uint8_t> png = encode_png_pixels(px.data(), size, size, channels, o);
    write_file(path, png.data(), png.size());
}

// Albedo, tangent-space normal (from a height field), roughness, metal.
void write_material_maps(const fs::path& dir, int size, std::uint32_t seed, bool orm) {
    const std::vector<std::uint8_t> albedo = make_map(size, 3, [&](float u, float v, int x, int y, float* c) {
        const float n = fbm(u, v, seed);
        const bool stripe = std::fmod(u * 6.0f + 0.3f * n, 1.0f) < 0.15f;
        const float grain = 0.04f * (hash_unit(x, y, seed + 9) - 0.5f);
        c[0] = (stripe ? 0.15f : 0.55f + 0.35f * n) + grain;
        c[1] = (stripe ? 0.25f : 0.35f + 0.25f * n) + grain;
        c[2] = (stripe ? 0.65f : 0.20f + 0.15f * n) + grain;
    });
    write_png_file(dir / "albedo.png", albedo, size, 3);
    const float eps = 1.0f / float(size);
    const std::vector<std::uint8_t> normal = make_map(size, 3, [&](float u, float v, int, int, float* c) {
        const float hx = fbm(u + eps, v, seed + 20) - fbm(u - eps, v, seed + 20);
        const float hy = fbm(u, v + eps, seed + 20) - fbm(u, v - eps, seed + 20);
        glm::vec3 n = glm::normalize(glm::vec3(-hx * 12.0f, hy * 12.0f, 1.0f));
        c[0] = n.x * 0.5f + 0.5f;
        c[1] = n.y * 0.5f + 0.5f;
        c[2] = n.z * 0.5f + 0.5f;
    });
    write_png_file(dir / "normal.png", normal, size, 3);
    auto rough = [&](float u, float v) { return 0.25f + 0.5f * fbm(u, v, seed + 40); };
    auto metal = [&](float u, float v) { return value_noise(u, v, 8, seed + 60) > 0.6f ? 1.0f : 0.0f; };
    if (orm) {
        const std::vector<std::uint8_t> px = make_map(size, 3, [&](float u, float v, int, int, float* c) {
            c[0] = 0.7f + 0.3f * fbm(u, v, seed + 80);
            c[1] = rough(u, v);
            c[2] = metal(u, v);
        });
        write_png_file(dir / "orm.png", px, size, 3);
    } else {
        write_png_file(dir / "roughness.png",
                       make_map(size, 1, [&](float u, float v, int, int, float* c) { c[0] = rough(u, v); }), size, 1);
        write_png_file(dir / "metal.png",
                       make_map(size, 1, [&](float u, float v, int, int, float* c) { c[0] = metal(u, v); }), size, 1);
    }
}

// Half extents of the z = 0 plane seen by eye (0, 0, 1), fov 45, 16:9.
constexpr float kHalfH = 0.41421356f;  // tan(22.5 deg)
constexpr float kHalfW = kHalfH * 16.0f / 9.0f;

void write_quad(const fs::path& dir) {
    fs::create_directories(dir);
    write_material_maps(dir, 1024, 11u, false);
    // Slightly larger than the view, so the two triangles fill every pixel.
    const float x = kHalfW * 1.01f, y = kHalfH * 1.01f, uw = 3.0f, vh = 3.0f * y / x;
    std::ofstream obj(dir / "quad.obj");
    obj << "# bench workload: a full-screen quad, four maps repeated three times across\nmtllib quad.mtl\n"
        << "v " << -x << " " << -y << " 0\nv " << x << " " << -y << " 0\nv " << x << " " << y << " 0\nv " << -x << " "
        << y << " 0\n"
        << "vt 0 0\nvt " << uw << " 0\nvt " << uw << " " << vh << "\nvt 0 " << vh << "\nvn 0 0 1\nusemtl maps\n"
        << "f 1/1/1 2/2/1 3/3/1\nf 1/1/1 3/3/1 4/4/1\n";
    std::ofstream mtl(dir / "quad.mtl");
    mtl << "newmtl maps\nKd 1 1 1\nPr 1\nPm 1\nmap_Kd albedo.png\nnorm normal.png\nmap_Pr roughness.png\n"
           "map_Pm metal.png\n";
}

// A glTF 2.0 file with one mesh: positions, normals, optional uvs, indices,
// and either a textured material (maps in the same folder) or a constant one.
void write_gltf(const fs::path& dir, const std::string& name, const std::vector<float>& pos,
                const std::vector<float>& nrm, const std::vector<float>& uv, const std::vector<std::uint32_t>& idx,
                bool textured) {
    std::vector<std::uint8_t> bin;
    auto append = [&](const void* p, std::size_t n) {
        const auto* b = static_cast<const std::uint8_t*>(p);
        bin.insert(bin.end(), b, b + n);
        while (bin.size() % 4) bin.push_back(0);
    };
    const std::size_t verts = pos.size() / 3;
    glm::vec3 lo(1e30f), hi(-1e30f);
    for (std::size_t i = 0; i < verts; ++i) {
        lo = glm::min(lo, glm::vec3(pos[3 * i], pos[3 * i + 1], pos[3 * i + 2]));
        hi = glm::max(hi, glm::vec3(pos[3 * i], pos[3 * i + 1], pos[3 * i + 2]));
    }
    const std::size_t o_pos = bin.size();
    append(pos.data(), pos.size() * 4);
    const std::size_t o_nrm = bin.size();
    append(nrm.data(), nrm.size() * 4);
    const std::size_t o_uv = bin.size();
    if (!uv.empty()) append(uv.data(), uv.size() * 4);
    const std::size_t o_idx = bin.size();
    append(idx.data(), idx.size() * 4);
    write_file(dir / (name + ".bin"), bin.data(), bin.size());

    std::ostringstream j;
    j << "{\"asset\":{\"version\":\"2.0\",\"generator\":\"prast bench\"},\"scene\":0,\"scenes\":[{\"nodes\":[0]}],"
      << "\"nodes\":[{\"mesh\":0}],\"buffers\":[{\"uri\":\"" << name << ".bin\",\"byteLength\":" << bin.size()
      << "}],\"bufferViews\":[" << "{\"buffer\":0,\"byteOffset\":" << o_pos << ",\"byteLength\":" << pos.size() * 4
      << "},{\"buffer\":0,\"byteOffset\":" << o_nrm << ",\"byteLength\":" << nrm.size() * 4 << "},";
    if (!uv.empty()) j << "{\"buffer\":0,\"byteOffset\":" << o_uv << ",\"byteLength\":" << uv.size() * 4 << "},";
    j << "{\"buffer\":0,\"byteOffset\":" << o_idx << ",\"byteLength\":" << idx.size() * 4 << "}],\"accessors\":["
      << "{\"bufferView\":0,\"componentType\":5126,\"count\":" << verts << ",\"type\":\"VEC3\",\"min\":[" << lo.x
      << "," << lo.y << "," << lo.z << "],\"max\":[" << hi.x << "," << hi.y << "," << hi.z << "]},"
      << "{\"bufferView\":1,\"componentType\":5126,\"count\":" << verts << ",\"type\":\"VEC3\"},";
    const int idx_view = uv.empty() ? 2 : 3;
    if (!uv.empty()) j << "{\"bufferView\":2,\"componentType\":5126,\"count\":" << verts << ",\"type\":\"VEC2\"},";
    j << "{\"bufferView\":" << idx_view << ",\"componentType\":5125,\"count\":" << idx.size()
      << ",\"type\":\"SCALAR\"}],\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0,\"NORMAL\":1";
    if (!uv.empty()) j << ",\"TEXCOORD_0\":2";
    j << "},\"indices\":" << idx_view << ",\"material\":0}]}],\"materials\":[";
    if (textured) {
        j << "{\"name\":\"bottle\",\"pbrMetallicRoughness\":{\"baseColorTexture\":{\"index\":0},"
             "\"metallicRoughnessTexture\":{\"index\":2}},\"normalTexture\":{\"index\":1},"
             "\"occlusionTexture\":{\"index\":2}}],"
             "\"samplers\":[{\"wrapS\":10497,\"wrapT\":10497}],"
             "\"textures\":[{\"source\":0,\"sampler\":0},{\"source\":1,\"sampler\":0},{\"source\":2,\"sampler\":0}],"
             "\"images\":[{\"uri\":\"albedo.png\"},{\"uri\":\"normal.png\"},{\"uri\":\"orm.png\"}]}";
    } else {
        j << "{\"name\":\"grey\",\"pbrMetallicRoughness\":{\"baseColorFactor\":[0.7,0.6,0.5,1],"
             "\"metallicFactor\":0.0,\"roughnessFactor\":0.5}}]}";
    }
    std::ofstream f(dir / (name + ".gltf"));
    f << j.str();
}

void write_grid(const fs::path& dir) {
    fs::create_directories(dir);
    const int nx = 480, ny = 270;
    std::vector<float> pos, nrm;
    std::vector<std::uint32_t> idx;
    for (int y = 0; y <= ny; ++y)
        for (int x = 0; x <= nx; ++x) {
            pos.insert(pos.end(), {-kHalfW + 2.0f * kHalfW * float(x) / nx, kHalfH - 2.0f * kHalfH * float(y) / ny, 0.0f});
            nrm.insert(nrm.end(), {0.0f, 0.0f, 1.0f});
        }
    for (int y = 0; y < ny; ++y)
        for (int x = 0; x < nx; ++x) {
            const std::uint32_t a = std::uint32_t(y * (nx + 1) + x), b = a + 1, c = a + std::uint32_t(nx + 1), d = c + 1;
            idx.insert(idx.end(), {a, c, b, b, c, d});  // counter-clockwise seen from +z
        }
    write_gltf(dir, "grid", pos, nrm, {}, idx, false);
}

// A bottle: a profile (radius, height) revolved about +y, 55 rings of 65
// vertices (the seam doubled for the uvs), 6,912 triangles.
void write_bottle(const fs::path& dir) {
    fs::create_directories(dir);
    write_material_maps(dir, 2048, 23u, true);
    const int rings = 55, segments = 64;
    auto profile = [](float t) {  // t in [0, 1] bottom to top -> (radius, height)
        const float h = 0.30f * t;
        float r;
        if (t < 0.02f) r = 0.08f * t / 0.02f;                                  // base
        else if (t < 0.60f) r = 0.08f;                                        // body
        else if (t < 0.80f) r = 0.08f - 0.055f * std::sin((t - 0.6f) / 0.2f * 1.5707963f);  // shoulder
        else if (t < 0.98f) r = 0.025f;                                       // neck
        else r = 0.025f * (1.0f - (t - 0.98f) / 0.02f);                       // top
        return glm::vec2(r, h);
    };
    std::vector<float> pos, nrm, uv;
    std::vector<std::uint32_t> idx;
    for (int i = 0; i < rings; ++i) {
        const float t = float(i) / float(rings - 1);
        const glm::vec2 p = profile(t);
        const glm::vec2 d = profile(std::min(1.0f, t + 0.01f)) - profile(std::max(0.0f, t - 0.01f));
        const glm::vec2 n2 = glm::normalize(glm::vec2(d.y, -d.x));  // outwards
        for (int s = 0; s <= segments; ++s) {
            const float a = 6.2831853f * float(s) / float(segments);
            const float cx = std::sin(a), cz = std::cos(a);
            pos.insert(pos.end(), {p.x * cx, p.y, p.x * cz});
            nrm.insert(nrm.end(), {n2.x * cx, n2.y, n2.x * cz});
            uv.insert(uv.end(), {float(s) / float(segments), 1.0f - t});
        }
    }
    for (int i = 0; i + 1 < rings; ++i)
        for (int s = 0; s < segments; ++s) {
            const std::uint32_t a = std::uint32_t(i * (segments + 1) + s), b = a + 1;
            const std::uint32_t c = a + std::uint32_t(segments + 1), d = c + 1;
            idx.insert(idx.end(), {a, b, c, b, d, c});  // counter-clockwise seen from outside
        }
    write_gltf(dir, "bottle", pos, nrm, uv, idx, true);
}

// ---- The workloads.

struct Workload {
    std::string name;
    std::string file;     // empty: the built-in scene
    glm::vec3 eye, target;
    float fov;
    bool own_lights;      // the built-in scene keeps its sun and point light
    int width = 1920, height = 1080;  // bench --size
};

const char* kSun = "0.35,0.6,0.7:3,3,3";

std::vector<Workload> workloads(const fs::path& dir, const fs::path& assets) {
    return {
        {"quad", (dir / "quad/quad.obj").string(), {0, 0, 1}, {0, 0, 0}, 45, false},
        {"grid", (dir / "grid/grid.gltf").string(), {0, 0, 1}, {0, 0, 0}, 45, false},
        {"bottle", (dir / "bottle/bottle.gltf").string(), {0, 0.15f, 0.52f}, {0, 0.15f, 0}, 45, false},
        {"tea", (assets / "tea-set-01/gltf/tea_set_01_1k.gltf").string(), {-0.2441f, 0.1595f, 0.3123f},
         {-0.347f, 0.065f, 0.061f}, 35, false},
        {"bunny", (assets / "stanford-bunny/stanford-bunny.obj").string(), {-0.017f, 0.13f, 0.36f},
         {-0.017f, 0.108f, 0}, 35, false},
        {"builtin", "", {0, 0, 0}, {0, 0, 0}, 45, true},
    };
}

// The render flags that draw a workload as bench does.
std::vector<std::string> render_args(const Workload& w) {
    char eye[96], target[96], fov[32];
    std::snprintf(eye, sizeof eye, "%g,%g,%g", double(w.eye.x), double(w.eye.y), double(w.eye.z));
    std::snprintf(target, sizeof target, "%g,%g,%g", double(w.target.x), double(w.target.y), double(w.target.z));
    std::snprintf(fov, sizeof fov, "%g", double(w.fov));
    std::vector<std::string> a;
    if (!w.file.empty()) a = {w.file, "--eye", eye, "--target", target, "--fov", fov, "--sun", kSun};
    a.insert(a.end(), {"--size", std::to_string(w.width) + "x" + std::to_string(w.height), "--ambient",
                       "0.05,0.05,0.05", "--tonemap", "aces"});
    return a;
}

void ensure_workloads(const fs::path& dir, bool force) {
    struct Gen { const char* sub; const char* marker; void (*fn)(const fs::path&); };
    for (const Gen& g : {Gen{"quad", "quad.obj", write_quad}, Gen{"grid", "grid.gltf", write_grid},
                         Gen{"bottle", "bottle.gltf", write_bottle}}) {
        if (!force && fs::exists(dir / g.sub / g.marker)) continue;
        std::fprintf(stderr, "bench: writing %s\n", (dir / g.sub).string().c_str());
        g.fn(dir / g.sub);
    }
}

std::string shell_quote(const std::string& s) {
    std::string q = "'";
    for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
    return q + "'";
}

// ---- In-process measurement.

struct Result {
    std::string name;
    int threads = 0;
    std::size_t triangles = 0;
    double load_ms = 0, textures_ms = 0;
    std::size_t texture_bytes = 0;
    int samples = 1, width = 0, height = 0;
    Summary frame, vertex, setup_bin, raster;  // frame: draws and the tile-pass resolve, as render's
    double png_ms = 0;
    std::size_t png_bytes = 0;
    double coverage = 0;  // fraction of pixels drawn
};

// bench --shadows / --shadow-size / --blend.
using FeatureOptions = cli::BenchOptions;

// A workload's frame: render's own frame set-up (renderer/frame_setup.h) for
// the workload's render flags (render_args), so that every measurement draws
// the frame `render` draws for them: its camera with fitted clip planes, its
// lights and one sun, ambient 0.05.
struct LoadedWorkload {
    FrameSetup frame;
    const Scene* scene = nullptr;
    FrameSettings settings;
};

void load_workload(const Workload& w, int samples, LoadedWorkload& out) {
    const std::vector<std::string> args = render_args(w);
    std::vector<const char*> argv = {"render"};
    for (const std::string& a : args) argv.push_back(a.c_str());
    RenderOptions opt;
    const std::string err = parse_render_args(int(argv.size()), argv.data(), opt);
    if (!err.empty()) throw std::runtime_error(err);
    opt.msaa = samples;
    if (FrameError e = prepare_scene(render_frame_request(opt), out.frame)) throw std::runtime_error(e.message);
    if (CameraFault f = out.frame.orbit(0.0)) throw std::runtime_error(f.message);
    out.scene = &out.frame.scene;
    out.settings = out.frame.settings;
}

Result measure(const Workload& w, int threads, int tile, int repeat, int width, int height, int samples,
               bool shadows, int shadow_size) {
    Result r;
    r.name = w.name;
    r.samples = samples;
    r.width = width;
    r.height = height;
    auto t_load = Clock::now();
    LoadedWorkload lw;
    load_workload(w, samples, lw);
    const Scene* scene = lw.scene;
    r.load_ms = ms_since(t_load);
    r.triangles = scene->triangle_count();

    Renderer renderer({threads, tile});
    auto t_tex = Clock::now();
    SceneRenderer sr(*scene, renderer);
    r.textures_ms = ms_since(t_tex);
    std::vector<const Texture*> seen;
    for (const BoundMaterial& b : sr.materials())
        for (const Texture* t : {b.base_color, b.metallic_roughness, b.roughness, b.metallic, b.normal, b.occlusion,
                                 b.emissive})
            if (t && std::find(seen.begin(), seen.end(), t) == seen.end()) {
                seen.push_back(t);
                r.texture_bytes += t->memory_bytes();
            }

    FrameSettings fs = lw.settings;
    fs.shadows.enabled = shadows;
    fs.shadows.size = shadow_size;
    Framebuffer fb = Framebuffer::deferred(width, height);  // as render: allocated by the first (kept) frame
    // The frame writes the 8-bit image in its tile pass (tone map, sRGB), as render does.
    Rgba8Buffer image(std::size_t(width) * std::size_t(height));
    const std::uint8_t* rgba8 = image.data();
    ImageOutput out8;
    out8.rgba8 = image.data();
    out8.tonemap = ToneMap::Aces;
    std::vector<double> frame, vertex, setup, raster;
    for (int i = 0; i <= repeat; ++i) {  // frame 0 warms up and keeps the framebuffer (coverage below)
        out8.keep_framebuffer = i == 0;
        auto t0 = Clock::now();
        sr.render(fs, fb, &out8);
        const double ms = ms_since(t0);
        if (i == 0) continue;
        const FrameStats st = renderer.stats();
        frame.push_back(ms);
        vertex.push_back(st.ms_vertex);
        setup.push_back(st.ms_setup_bin);
        raster.push_back(st.ms_raster);
    }
    r.frame = summarise(frame);
    r.vertex = summarise(vertex);
    r.setup_bin = summarise(setup);
    r.raster = summarise(raster);

    std::vector<std::uint8_t> rgb(std::size_t(width) * std::size_t(height) * 3);
    for (std::size_t i = 0; i < std::size_t(width) * std::size_t(height); ++i)
        for (int c = 0; c < 3; ++c) rgb[3 * i + std::size_t(c)] = rgba8[4 * i + std::size_t(c)];
    auto t_png = Clock::now();
    r.png_bytes = encode_png_pixels(rgb.data(), width, height, 3, png_options_threads(threads)).size();
    r.png_ms = ms_since(t_png);
    std::size_t drawn = 0;
    for (std::size_t i = 0; i < fb.depth.size(); ++i) drawn += fb.depth[i] < 1.0f;
    r.coverage = double(drawn) / double(fb.depth.size());
    return r;
}

// bench --alternate: one renderer per thread count in one process, their
// frames taken in turn (round k: a frame at each count), so that a change in
// the machine's load reaches every count alike. The speed-up is the median of
// the rounds' ratios (first count's frame / this count's frame).
void measure_alternating(const Workload& w, const std::vector<int>& threads, int tile, int repeat, int width,
                         int height, int samples, bool json, std::vector<std::string>& out) {
    LoadedWorkload lw;
    load_workload(w, samples, lw);
    const Scene* scene = lw.scene;
    FrameSettings fs = lw.settings;
    const std::size_t n = threads.size();
    std::vector<std::unique_ptr<Renderer>> renderers;
    std::vector<std::unique_ptr<SceneRenderer>> srs;
    std::vector<Framebuffer> fbs;
    std::vector<Rgba8Buffer> images;
    for (std::size_t i = 0; i < n; ++i) {
        images.emplace_back(std::size_t(width) * std::size_t(height));
        renderers.push_back(std::make_unique<Renderer>(RendererOptions{threads[i], tile}));
        srs.push_back(std::make_unique<SceneRenderer>(*scene, *renderers.back()));
        fbs.push_back(Framebuffer::deferred(width, height));  // transient frames only: never allocated
    }
    std::vector<std::vector<double>> ms(n), ratio(n), pass(n), cpu(n), idle(n);
    for (int k = 0; k <= repeat; ++k) {  // round 0 warms up
        std::vector<double> round(n);
        for (std::size_t i = 0; i < n; ++i) {
            ImageOutput o;
            o.rgba8 = images[i].data();
            o.tonemap = ToneMap::Aces;
            o.keep_framebuffer = false;
            auto t0 = Clock::now();
            srs[i]->render(fs, fbs[i], &o);
            round[i] = ms_since(t0);
            if (k == 0) continue;
            const FrameStats& st = renderers[i]->stats();
            const ThreadPool::Usage& u = renderers[i]->tile_usage();
            pass[i].push_back(st.ms_raster);
            cpu[i].push_back(u.cpu_ms);
            idle[i].push_back(double(renderers[i]->threads()) * st.ms_raster - u.busy_ms);
        }
        if (k == 0) continue;
        for (std::size_t i = 0; i < n; ++i) {
            ms[i].push_back(round[i]);
            ratio[i].push_back(round[0] / round[i]);
        }
    }
    for (std::size_t i = 0; i < n; ++i) {
        const Summary f = summarise(ms[i]), r = summarise(ratio[i]);
        const double pass_ms = summarise(pass[i]).median, cpu_ms = summarise(cpu[i]).median,
                     idle_ms = summarise(idle[i]).median;
        const std::size_t bytes = std::size_t(width) * std::size_t(height) * 4;
        const bool same = std::memcmp(images[i].data(), images[0].data(), bytes) == 0;
        char b[512];
        if (json) {
            std::snprintf(b, sizeof b,
                          "{\"workload\":\"%s\",\"threads\":%d,\"msaa\":%d,\"alternate\":true,"
                          "\"frame_ms\":{\"min\":%.3f,\"median\":%.3f,\"max\":%.3f},"
                          "\"speedup\":{\"min\":%.3f,\"median\":%.3f,\"max\":%.3f},\"tile_pass_ms\":%.3f,"
                          "\"tile_pass_cpu_ms\":%.3f,\"tile_pass_idle_ms\":%.3f,\"same_image\":%s}",
                          w.name.c_str(), threads[i], samples, f.min, f.median, f.max, r.min, r.median, r.max,
                          pass_ms, cpu_ms, idle_ms, same ? "true" : "false");
            out.push_back(b);
        } else {
            std::printf("%-8s threads %d msaa %d: frame_ms min=%.2f median=%.2f max=%.2f  %d -> %d threads: "
                        "%.2fx (rounds %.2fx..%.2fx)  tile pass %.2f ms: CPU %.2f ms, idle %.2f ms%s\n",
                        w.name.c_str(), threads[i], samples, f.min, f.median, f.max, threads[0], threads[i],
                        r.median, r.min, r.max, pass_ms, cpu_ms, idle_ms, same ? "" : "  IMAGE DIFFERS");
            std::fflush(stdout);
        }
    }
}

void print_result(const Result& r) {
    std::printf("%-8s threads %d msaa %d: frame_ms min=%.2f median=%.2f max=%.2f  (vertex %.2f, setup+bin %.2f, "
                "raster+shade+resolve %.2f)  png %.1f ms %zu B | %zu tris, %.1f%% drawn, load %.1f ms, "
                "textures %.1f ms %.1f MB\n",
                r.name.c_str(), r.threads, r.samples, r.frame.min, r.frame.median, r.frame.max, r.vertex.median,
                r.setup_bin.median, r.raster.median, r.png_ms, r.png_bytes, r.triangles,
                100.0 * r.coverage, r.load_ms, r.textures_ms, double(r.texture_bytes) / 1e6);
    std::fflush(stdout);
}

std::string json_result(const Result& r) {
    auto s = [](const Summary& x) {
        char b[128];
        std::snprintf(b, sizeof b, "{\"min\":%.3f,\"median\":%.3f,\"max\":%.3f}", x.min, x.median, x.max);
        return std::string(b);
    };
    char b[512];
    std::snprintf(b, sizeof b,
                  "{\"workload\":\"%s\",\"threads\":%d,\"msaa\":%d,\"width\":%d,\"height\":%d,\"triangles\":%zu,\"coverage\":%.4f,\"load_ms\":%.3f,"
                  "\"textures_ms\":%.3f,\"texture_bytes\":%zu,\"png_ms\":%.3f,\"png_bytes\":%zu,",
                  r.name.c_str(), r.threads, r.samples, r.width, r.height, r.triangles, r.coverage, r.load_ms,
                  r.textures_ms, r.texture_bytes, r.png_ms, r.png_bytes);
    return std::string(b) + "\"frame_ms\":" + s(r.frame) + ",\"vertex_ms\":" + s(r.vertex) +
           ",\"setup_bin_ms\":" + s(r.setup_bin) + ",\"raster_shade_ms\":" + s(r.raster) + "}";
}

// ---- Side by side: two render executables, alternately.

// Runs argv, stdout into `out`; returns the wall time in ms (negative on failure).
double run_process(const std::vector<std::string>& argv, std::string& out) {
    const fs::path log = fs::temp_directory_path() / ("prast_bench_" + std::to_string(long(getpid())) + ".out");
    std::string cmd;
    for (const std::string& a : argv) cmd += shell_quote(a) + " ";
    cmd += "> " + shell_quote(log.string()) + " 2>/dev/null";
    auto t0 = Clock::now();
    const int rc = std::system(cmd.c_str());
    const double ms = ms_since(t0);
    std::ifstream f(log);
    out.assign(std::istreambuf_iterator<char>(f), {});
    fs::remove(log);
    return rc == 0 ? ms : -1.0;
}

double parse_median(const std::string& out) {
    const std::size_t p = out.find("median=");
    return p == std::string::npos ? -1.0 : std::atof(out.c_str() + p + 7);
}

// The value after `key` in --stats output (render, llvmpipe-render), or -1.
double parse_stat(const std::string& out, const std::string& key) {
    const std::size_t p = out.find(key);
    return p == std::string::npos ? -1.0 : std::atof(out.c_str() + p + key.size());
}

// Whether an executable takes --msaa (a build before it did not): whether
// `EXE --msaa 1 --help` succeeds. Its --help text is not enough: a build of
// llvmpipe-render took --msaa (default 4) before its --help listed it, and
// comparing its 4 samples with 1 made its frames look 2x to 3x slower.
bool takes_msaa(const std::string& exe) {
    const std::string cmd = shell_quote(exe) + " --msaa 1 --help > /dev/null 2>&1";
    const int status = std::system(cmd.c_str());
    return status != -1 && WIFEXITED(status) && WEXITSTATUS(status) == 0;
}

// The JSON objects of --json as one array, an object a line.
void print_json_array(const std::vector<std::string>& objects) {
    std::printf("[");
    for (std::size_t i = 0; i < objects.size(); ++i) std::printf("%s%s\n", i ? "," : "", objects[i].c_str());
    std::printf("]\n");
}

// With `json`, each workload's figures go to `out` as a JSON object instead
// of a printed line.
int side_by_side(const std::vector<std::string>& exes, const std::vector<Workload>& list, int runs, int repeat,
                 const std::string& threads, int samples, bool json, std::vector<std::string>& out_json) {
    const fs::path out_png = fs::temp_directory_path() / ("prast_bench_" + std::to_string(long(getpid())) + ".png");
    const bool msaa[2] = {takes_msaa(exes[0]), takes_msaa(exes[1])};
    if (!json)
        std::printf("side by side, %d alternating runs each, %s threads; A = %s (%s), B = %s (%s)\n", runs,
                    threads.c_str(), exes[0].c_str(),
                    msaa[0] ? ("--msaa " + std::to_string(samples)).c_str() : "no --msaa: 1 sample", exes[1].c_str(),
                    msaa[1] ? ("--msaa " + std::to_string(samples)).c_str() : "no --msaa: 1 sample");
    for (const Workload& w : list) {
        std::vector<double> whole[2], frame[2], textures[2];
        for (int i = 0; i < runs; ++i)
            for (int k = 0; k < 2; ++k) {
                const int e = i % 2 == 0 ? k : 1 - k;  // which runs first alternates too
                std::vector<std::string> argv = {exes[std::size_t(e)]};
                for (const std::string& a : render_args(w)) argv.push_back(a);
                if (msaa[e]) argv.insert(argv.end(), {"--msaa", std::to_string(samples)});
                argv.insert(argv.end(), {"--threads", threads, "--stats", "-o", out_png.string()});
                std::string out;
                auto failed = [&] {
                    std::fprintf(stderr, "bench: %s failed on %s\n", exes[std::size_t(e)].c_str(), w.name.c_str());
                    return 1;
                };
                const double ms = run_process(argv, out);
                if (ms < 0) return failed();
                whole[e].push_back(ms);
                textures[e].push_back(parse_stat(out, "time textures"));
                argv.insert(argv.end(), {"--repeat", std::to_string(repeat)});
                if (run_process(argv, out) < 0) return failed();
                frame[e].push_back(parse_median(out));
            }
        const Summary wa = summarise(whole[0]), wb = summarise(whole[1]);
        const Summary fa = summarise(frame[0]), fb = summarise(frame[1]);
        const Summary ta = summarise(textures[0]), tb = summarise(textures[1]);
        // Each round's ratio as well: the two frames of a round ran a few
        // seconds apart, so a change in the machine's speed reaches both.
        std::vector<double> rounds;
        for (int i = 0; i < runs; ++i) rounds.push_back(frame[0][std::size_t(i)] / frame[1][std::size_t(i)]);
        const Summary fr = summarise(rounds);
        if (json) {
            char b[768];
            std::snprintf(b, sizeof b,
                          "{\"workload\":\"%s\",\"threads\":%s,\"msaa\":%d,\"msaa_a\":%d,\"msaa_b\":%d,\"runs\":%d,"
                          "\"whole_ms\":{\"a\":%.3f,\"b\":%.3f},\"frame_ms\":{\"a\":%.3f,\"b\":%.3f},"
                          "\"rounds\":{\"min\":%.4f,\"median\":%.4f,\"max\":%.4f},"
                          "\"textures_ms\":{\"a\":%.3f,\"b\":%.3f}}",
                          w.name.c_str(), threads.c_str(), samples, msaa[0] ? samples : 1, msaa[1] ? samples : 1, runs,
                          wa.median, wb.median, fa.median, fb.median, fr.min, fr.median, fr.max, ta.median, tb.median);
            out_json.push_back(b);
            continue;
        }
        std::printf("%-8s whole process A %.1f ms B %.1f ms (A/B %.2fx) | frame median A %.2f ms B %.2f ms "
                    "(A/B %.2fx; rounds %.2fx, %.2fx..%.2fx) | textures A %.1f ms B %.1f ms\n",
                    w.name.c_str(), wa.median, wb.median, wa.median / wb.median, fa.median, fb.median,
                    fa.median / fb.median, fr.median, fr.min, fr.max, ta.median, tb.median);
        std::fflush(stdout);
    }
    fs::remove(out_png);
    return 0;
}

// ---- PSNR of two 8-bit images (RGB), by scene/image_diff.

int psnr(const std::string& a, const std::string& b) {
    Image8 ia = read_image8(a), ib = read_image8(b);
    if (ia.width != ib.width || ia.height != ib.height) {
        std::fprintf(stderr, "bench: %s and %s differ in size (%dx%d and %dx%d)\n", a.c_str(), b.c_str(), ia.width,
                     ia.height, ib.width, ib.height);
        return 1;
    }
    ia.has_alpha = ib.has_alpha = false;  // colour only
    const DiffResult r = diff_images(ia, ib, DiffTolerance{});
    const double pixels = double(ia.width) * double(ia.height);
    if (r.mse == 0.0) std::printf("psnr inf dB (identical)\n");
    else std::printf("psnr %.2f dB, max channel difference %d, %lld pixels differ (%.3f%%)\n", r.psnr_db, r.max_diff,
                     static_cast<long long>(r.differing), 100.0 * double(r.differing) / pixels);
    return 0;
}

// ---- Any scene, the built-in one by default, with the flat program option.

// Lambert with one fixed light, no textures: the cost of the core.
struct FlatProgram {
    static constexpr int kVaryings = 3;
    const Mesh* mesh = nullptr;
    glm::mat4 view_proj{1.0f};
    void vertex(std::uint32_t i, float clip[4], float* var) const {
        glm::vec4 c = view_proj * glm::vec4(mesh->positions[i], 1.0f);
        clip[0] = c.x; clip[1] = c.y; clip[2] = c.z; clip[3] = c.w;
        var[0] = mesh->normals[i].x; var[1] = mesh->normals[i].y; var[2] = mesh->normals[i].z;
    }
    void fragment(const FragmentBlock<3>& in, FragmentOut& out) const {
        for (int l = 0; l < kBlockLanes; ++l) {
            float ndl = in.var[0][l] * -0.4f + in.var[1][l] * 0.7f + in.var[2][l] * 0.6f;
            float c = 0.03f + 0.8f * (ndl > 0.0f ? ndl : 0.0f);
            out.r[l] = c; out.g[l] = c; out.b[l] = c; out.a[l] = 1.0f;
        }
    }
};

double render_flat(Renderer& renderer, const Scene& scene, const Camera& cam, Framebuffer& fb) {
    auto t0 = Clock::now();
    renderer.clear(fb, 0, 0, 0, 1);
    renderer.begin_frame();
    glm::mat4 vp = cam.view_projection(float(fb.width) / float(fb.height));
    for (const Mesh& m : scene.meshes) {
        FlatProgram p{&m, vp};
        renderer.draw(fb, p, std::uint32_t(m.positions.size()), m.indices.data(), m.indices.size());
    }
    return ms_since(t0);
}

int bench_scene(const std::string& scene_path, int width, int height, const std::vector<int>& threads,
                const std::vector<int>& tiles, int repeat, DebugView view, bool flat, const FeatureOptions& fo) {
    DefaultScene builtin;
    Scene loaded;
    const Scene* scene = nullptr;
    Camera camera;
    const float aspect = float(width) / float(height);
    try {
        if (scene_path.empty()) {
            builtin = make_default_scene();
            scene = &builtin.scene;
            camera = builtin.camera;
        } else {
            loaded = load_scene(scene_path);
            scene = &loaded;
            camera = frame_scene(loaded, 45.0f, aspect);
        }
    } catch (const std::exception& e) {
        std::fprintf(stderr, "bench: %s\n", e.what());
        return 1;
    }
    Scene blended;
    if (fo.blend_alpha >= 0.0f) {
        blended = *scene;
        for (Material& m : blended.materials) {
            m.alpha_mode = AlphaMode::Blend;
            m.base_color_factor.a = fo.blend_alpha;
        }
        scene = &blended;
    }
    std::vector<ShadingLight> lights = shading_lights(*scene);
    if (lights.empty()) lights = default_light_rig();
    std::printf("scene %s, %zu triangles, %dx%d, %d frames per configuration, %s program%s\n",
                scene_path.empty() ? "(built-in)" : scene_path.c_str(), scene->triangle_count(), width, height,
                repeat, flat ? "flat Lambert" : "PBR", fo.blend_alpha >= 0.0f ? ", every material BLEND" : "");
    for (int tile : tiles)
        for (int t : threads)
            for (bool shadows : fo.shadows) {
            Renderer renderer({t, tile});
            SceneRenderer sr(*scene, renderer);
            FrameSettings fs;
            fs.camera = camera;
            fs.lights = lights;
            fs.view = view;
            fs.shadows.enabled = shadows;
            fs.shadows.size = fo.shadow_size;
            Framebuffer fb(width, height);
            std::vector<double> ms;
            FrameStats last;
            for (int r = 0; r <= repeat; ++r) {
                double t_ms;
                if (flat) {
                    t_ms = render_flat(renderer, *scene, camera, fb);
                } else {
                    auto t0 = Clock::now();
                    sr.render(fs, fb);
                    t_ms = ms_since(t0);
                }
                if (r > 0) ms.push_back(t_ms);
                last = renderer.stats();
            }
            const Summary s = summarise(ms);
            std::printf("threads %d tile %3d shadows %-3s: frame_ms min=%.2f median=%.2f max=%.2f  %.1f Mpx/s"
                        "  (vertex %.2f, setup+bin %.2f, raster+shade %.2f ms)\n",
                        t, tile, shadows ? "on" : "off", s.min, s.median, s.max, double(width) * height / s.median / 1000.0,
                        last.ms_vertex, last.ms_setup_bin, last.ms_raster);
        }
    return 0;
}

} // namespace

int main(int argc, char** argv) {
    cli::BenchOptions opt;
    opt.dir = (fs::temp_directory_path() / "prast-bench-workloads").string();
    opt.assets = "../shared/assets";
    if (const char* env = std::getenv("PRAST_SHARED_ASSETS")) opt.assets = env;
    const std::string err = cli::parse_bench_args(argc, argv, opt);
    if (!err.empty()) {
        std::fprintf(stderr, "bench: %s\n", err.c_str());
        return 2;
    }
    if (opt.help) {
        std::fputs(cli::bench_usage(), stdout);
        return 0;
    }
    if (opt.version) {
        std::printf("bench (prast) %s\n", PRAST_VERSION);
        return 0;
    }
    const std::string &scene_path = opt.scene_path, &write_dir = opt.write_dir, &psnr_a = opt.psnr_a,
                      &psnr_b = opt.psnr_b;
    const std::vector<std::string>& exes = opt.exes;
    const fs::path dir = opt.dir, assets = opt.assets;
    const int width = opt.width, height = opt.height, repeat = opt.repeat, runs = opt.runs;
    const std::vector<int>&msaa = opt.msaa, &threads = opt.threads, &tiles = opt.tiles;
    const std::vector<std::string>& names = opt.names;
    const DebugView view = opt.view;
    const bool flat = opt.flat, json = opt.json, alternate = opt.alternate, threads_given = opt.threads_given,
               tiles_given = opt.tiles_given, blend_given = opt.blend_given;
    const FeatureOptions& features = opt;
    try {
        if (!psnr_a.empty()) return psnr(psnr_a, psnr_b);
        // A scene, a tile sweep, a debug view or the flat program: the scene mode.
        if (!scene_path.empty() || flat || tiles_given || view != DebugView::None || blend_given)
            return bench_scene(scene_path, width, height, threads_given ? threads : std::vector<int>{1, 2}, tiles,
                               repeat, view, flat, features);
        if (!write_dir.empty()) {
            ensure_workloads(write_dir, true);
            std::ofstream cmds(fs::path(write_dir) / "commands.txt");
            for (Workload w : workloads(fs::absolute(write_dir), fs::absolute(assets))) {
                w.width = width;
                w.height = height;
                std::string line = "render";
                for (const std::string& arg : render_args(w)) line += " " + shell_quote(arg);
                cmds << w.name << ": " << line << "\n";
            }
            std::printf("workloads written to %s (render command lines in commands.txt)\n", write_dir.c_str());
            return 0;
        }
        const std::vector<Workload> all = workloads(dir, assets);
        ensure_workloads(dir, false);
        std::vector<Workload> list;
        for (Workload w : all) {
            if (!names.empty() && std::find(names.begin(), names.end(), w.name) == names.end()) continue;
            w.width = width;
            w.height = height;
            if (!w.file.empty() && !fs::exists(w.file)) {
                std::fprintf(stderr, "bench: skipping %s: %s not found (--assets DIR)\n", w.name.c_str(),
                             w.file.c_str());
                continue;
            }
            list.push_back(w);
        }
        if (!exes.empty()) {
            std::vector<std::string> out;
            for (int t : threads)
                for (int m : msaa)
                    if (int rc = side_by_side(exes, list, runs, repeat, std::to_string(t), m, json, out)) return rc;
            if (json) print_json_array(out);
            return 0;
        }
        std::vector<std::string> out;
        for (const Workload& w : list)
            for (int m : msaa) {
                if (alternate) {
                    measure_alternating(w, threads, tiles.front(), repeat, width, height, m, json, out);
                    continue;
                }
                for (int t : threads)
                    for (bool shadows : features.shadows) {
                        Result r = measure(w, t, tiles.front(), repeat, width, height, m, shadows,
                                           features.shadow_size);
                        r.threads = t;
                        if (shadows) r.name += "+shadows";
                        if (!json) print_result(r);
                        out.push_back(json_result(r));
                    }
            }
        if (json) print_json_array(out);
    } catch (const std::exception& e) {
        std::fprintf(stderr, "bench: %s\n", e.what());
        return 1;
    }
    return 0;
}

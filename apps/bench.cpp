// bench: frame times of the full PBR pipeline, for speed work and the issue
// notes. Renders the built-in scene (or SCENE) N times per configuration and
// prints the median, minimum and maximum frame time and megapixels per second
// (width * height / median). Timing belongs here, never in unit tests.
//
//   bench [SCENE] [--size WxH] [--threads 1,2] [--tiles 64] [--repeat N] [--view NAME] [--flat]
//
// --flat replaces the PBR program by a one-light Lambert program without
// textures, which measures the pipeline itself rather than the shading.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <sstream>
#include <string>
#include <vector>

#include "scene/default_scene.h"
#include "scene/load_scene.h"
#include "shading/scene_renderer.h"

using namespace prast;

namespace {

std::vector<int> parse_list(const std::string& s) {
    std::vector<int> out;
    std::stringstream ss(s);
    std::string item;
    while (std::getline(ss, item, ',')) out.push_back(std::atoi(item.c_str()));
    return out;
}

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
    auto t0 = std::chrono::steady_clock::now();
    renderer.clear(fb, 0, 0, 0, 1);
    renderer.begin_frame();
    glm::mat4 vp = cam.view_projection(float(fb.width) / float(fb.height));
    for (const Mesh& m : scene.meshes) {
        FlatProgram p{&m, vp};
        renderer.draw(fb, p, std::uint32_t(m.positions.size()), m.indices.data(), m.indices.size());
    }
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

int usage() {
    std::fprintf(stderr, "usage: bench [SCENE] [--size WxH] [--threads 1,2] [--tiles 64] [--repeat N] [--view NAME]\n");
    return 2;
}

} // namespace

int main(int argc, char** argv) {
    std::string scene_path;
    int width = 1920, height = 1080, repeat = 15;
    std::vector<int> threads = {1, 2}, tiles = {kDefaultTileSize};
    DebugView view = DebugView::None;
    bool flat = false;
    for (int i = 1; i < argc; ++i) {
        std::string a = argv[i];
        auto next = [&]() -> std::string { return i + 1 < argc ? argv[++i] : ""; };
        if (a == "--size") {
            if (std::sscanf(next().c_str(), "%dx%d", &width, &height) != 2 || width < 1 || height < 1 ||
                width > kMaxViewportSize || height > kMaxViewportSize)
                return usage();
        } else if (a == "--threads") threads = parse_list(next());
        else if (a == "--tiles") tiles = parse_list(next());
        else if (a == "--repeat") repeat = std::max(1, std::atoi(next().c_str()));
        else if (a == "--view") { if (!parse_debug_view(next(), view)) return usage(); }
        else if (a == "--flat") flat = true;
        else if (!a.empty() && a[0] == '-') return usage();
        else scene_path = a;
    }

    DefaultScene builtin;
    Scene loaded;
    const Scene* scene = nullptr;
    Camera camera;
    std::vector<ShadingLight> lights;
    const float aspect = float(width) / float(height);
    try {
        if (scene_path.empty()) {
            builtin = make_default_scene();
            scene = &builtin.scene;
            camera = builtin.camera;
        } else {
            loaded = load_scene(scene_path);
            scene = &loaded;
            camera = frame_bounds(loaded.bounds(), 45.0f, aspect);
        }
    } catch (const std::exception& e) {
        std::fprintf(stderr, "bench: %s\n", e.what());
        return 1;
    }
    lights = shading_lights(*scene);
    if (lights.empty()) lights = default_light_rig();

    std::printf("scene %s, %zu triangles, %dx%d, %d frames per configuration, %s program\n",
                scene_path.empty() ? "(built-in)" : scene_path.c_str(), scene->triangle_count(), width,
                height, repeat, flat ? "flat Lambert" : "PBR");
    for (int tile : tiles)
        for (int t : threads) {
            Renderer renderer({t, tile});
            SceneRenderer sr(*scene, renderer);
            FrameSettings fs;
            fs.camera = camera;
            fs.lights = lights;
            fs.view = view;
            Framebuffer fb(width, height);
            // The first frame is a warm-up: it pages in the framebuffer and bins.
            std::vector<double> ms;
            FrameStats last;
            for (int r = 0; r <= repeat; ++r) {
                double t;
                if (flat) {
                    t = render_flat(renderer, *scene, camera, fb);
                } else {
                    auto t0 = std::chrono::steady_clock::now();
                    sr.render(fs, fb);
                    t = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
                }
                if (r > 0) ms.push_back(t);
                last = renderer.stats();
            }
            std::sort(ms.begin(), ms.end());
            double median = ms[ms.size() / 2];
            std::printf("threads %d tile %3d: frame_ms min=%.2f median=%.2f max=%.2f  %.1f Mpx/s"
                        "  (vertex %.2f, setup+bin %.2f, raster+shade %.2f ms)\n",
                        t, tile, ms.front(), median, ms.back(), double(width) * height / median / 1000.0,
                        last.ms_vertex, last.ms_setup_bin, last.ms_raster);
        }
    return 0;
}

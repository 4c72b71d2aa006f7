// bench: frame times of the full PBR pipeline, for speed work and the issue
// notes. Renders the built-in scene (or SCENE) N times per configuration and
// prints the median, minimum and maximum frame time and megapixels per second
// (width * height / median). Timing belongs here, never in unit tests.
//
//   bench [SCENE] [--size WxH] [--threads 1,2] [--tiles 64] [--repeat N] [--view NAME]
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <sstream>
#include <string>
#include <vector>

#include "shading/default_scene.h"
#include "shading/load_scene.h"
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

    std::printf("scene %s, %zu triangles, %dx%d, %d frames per configuration\n",
                scene_path.empty() ? "(built-in)" : scene_path.c_str(), scene->triangle_count(), width,
                height, repeat);
    for (int tile : tiles)
        for (int t : threads) {
            Renderer renderer({t, tile});
            SceneRenderer sr(*scene, renderer);
            FrameSettings fs;
            fs.camera = camera;
            fs.lights = lights;
            fs.view = view;
            Framebuffer fb(width, height);
            sr.render(fs, fb);  // warm-up: page in the framebuffer and bins
            std::vector<double> ms;
            FrameStats last;
            for (int r = 0; r < repeat; ++r) {
                auto t0 = std::chrono::steady_clock::now();
                sr.render(fs, fb);
                ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
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

// A pixel test as a project that uses prast would write it: load a model,
// render it with a fixed camera and fixed lights, compare the 8-bit result
// with a golden image, and fail on a mismatch. The comparison is prast's own
// (scene/image_diff.h, the logic behind prast-diff), with a stated tolerance.
//
//   pixel_test MODEL GOLDEN.png [OUT_DIR]
//
// Exit 0 when the render matches the golden image within the tolerance, 1
// when it does not (actual.png and heatmap.png are then written to OUT_DIR,
// default "."), 2 when the model or the golden image cannot be read. A missing
// golden image is written from this render, and the test fails: look at it,
// then commit it.
#include <cstdint>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <string>
#include <vector>

#include <prast/raster/pipeline.h>
#include <prast/scene/camera.h>
#include <prast/scene/image_diff.h>
#include <prast/scene/load_scene.h>
#include <prast/scene/write_image.h>
#include <prast/renderer/scene_renderer.h>
#include <prast/shading/tonemap.h>

namespace {

// Renders are byte-identical for a given build of prast whatever the thread
// count; the tolerance only absorbs a rebuild with another compiler, where
// float shading may move a channel by 1 on a few pixels (as Filament's
// renderdiff allows): 1 unit in 8 bits on at most 0.1% of the pixels.
constexpr prast::DiffTolerance kTolerance{/*channel*/ 1, /*fraction*/ 0.001};
constexpr int kWidth = 160, kHeight = 120;

std::vector<std::uint8_t> render(const prast::Scene& scene) {
    prast::Renderer renderer({/*threads*/ 0, /*tile size*/ 64});
    prast::SceneRenderer scene_renderer(scene, renderer);
    prast::FrameSettings settings;
    settings.camera.eye = {0.0f, 0.7f, 3.1f};
    settings.camera.target = {0.0f, 0.0f, 0.0f};
    settings.camera.fov_y_deg = 45.0f;
    settings.camera.near_plane = 0.5f;
    settings.camera.far_plane = 10.0f;
    prast::ShadingLight key, fill;
    key.direction = glm::normalize(glm::vec3(-0.6f, 0.7f, 0.5f));
    key.radiance = glm::vec3(3.0f, 2.9f, 2.7f);
    fill.direction = glm::normalize(glm::vec3(0.8f, 0.1f, 0.3f));
    fill.radiance = glm::vec3(0.5f, 0.6f, 0.8f);
    settings.lights = {key, fill};
    settings.ambient = glm::vec3(0.05f);

    prast::Framebuffer fb(kWidth, kHeight);
    scene_renderer.render(settings, fb);
    std::vector<std::uint8_t> rgba8(std::size_t(kWidth) * kHeight * 4);
    prast::resolve_to_srgb8(fb.color.data(), kWidth, kHeight, /*exposure*/ 1.0f, prast::ToneMap::Aces,
                            rgba8.data());
    return rgba8;
}

} // namespace

int main(int argc, char** argv) {
    if (argc < 3 || argc > 4) {
        std::fprintf(stderr, "usage: pixel_test MODEL GOLDEN.png [OUT_DIR]\n");
        return 2;
    }
    const std::string model = argv[1], golden_path = argv[2];
    const std::filesystem::path out_dir = argc > 3 ? argv[3] : ".";
    try {
        const prast::Scene scene = prast::load_scene(model);
        const std::vector<std::uint8_t> pixels = render(scene);
        if (!std::filesystem::exists(golden_path)) {
            prast::write_png_atomic(golden_path, kWidth, kHeight, pixels.data());
            std::fprintf(stderr, "pixel_test: %s did not exist: written from this render; review it, commit it\n",
                         golden_path.c_str());
            return 1;
        }
        const prast::Image8 actual = prast::Image8::from_rgba(kWidth, kHeight, pixels.data(), false);
        const prast::Image8 golden = prast::read_image8(golden_path);
        if (golden.width != kWidth || golden.height != kHeight) {
            std::fprintf(stderr, "pixel_test: %s is %dx%d, the render %dx%d\n", golden_path.c_str(), golden.width,
                         golden.height, kWidth, kHeight);
            return 1;
        }
        const prast::DiffResult r = prast::diff_images(actual, golden, kTolerance);
        std::printf("%s vs %s\n%s", model.c_str(), golden_path.c_str(),
                    prast::format_diff(r, kTolerance).c_str());
        if (!r.match) {
            const std::string actual_png = (out_dir / "actual.png").string();
            const std::string heat_png = (out_dir / "heatmap.png").string();
            prast::write_png_atomic(actual_png, kWidth, kHeight, pixels.data());
            const std::vector<std::uint8_t> heat = prast::diff_heatmap(actual, golden, kTolerance);
            prast::write_png_atomic(heat_png, kWidth, kHeight, heat.data());
            std::fprintf(stderr, "pixel_test: FAILED: wrote %s and %s\n", actual_png.c_str(), heat_png.c_str());
            return 1;
        }
        return 0;
    } catch (const std::exception& e) {  // LoadError, WriteError: one line naming the file
        std::fprintf(stderr, "pixel_test: %s\n", e.what());
        return 2;
    }
}

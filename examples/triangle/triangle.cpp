// docs/pipeline.md's program made real: a custom vertex + fragment program drawn
// with prast's pipeline, written as a PNG. Only the installed headers and
// libraries are used (prast::raster for the pipeline, prast::scene for the PNG
// writer).
//
//   triangle [OUT.png]     (default triangle.png)
//
// Exits non-zero when the picture is not what the program draws: the
// triangle's centroid is covered, the corners of the image are not, and the
// number of covered pixels is the triangle's area within 1%.
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <exception>
#include <string>
#include <vector>

#include <prast/raster/fragment.h>
#include <prast/raster/pipeline.h>
#include <prast/scene/write_image.h>

namespace {

// One triangle in clip space (w = 1, so clip = NDC), counter-clockwise in NDC
// as front faces are. Each corner carries two varyings (u, v).
struct MyProgram {
    static constexpr int kVaryings = 2;
    static constexpr float kCorners[3][2] = {{-0.8f, -0.7f}, {0.8f, -0.7f}, {0.0f, 0.8f}};

    void vertex(std::uint32_t index, float clip[4], float* varyings) const {
        clip[0] = kCorners[index][0];
        clip[1] = kCorners[index][1];
        clip[2] = 0.0f;
        clip[3] = 1.0f;
        varyings[0] = index == 0 ? 1.0f : 0.0f;  // u: 1 at the first corner
        varyings[1] = index == 1 ? 1.0f : 0.0f;  // v: 1 at the second
    }

    // Called once per 4x4 block, 16 lanes at a time (structure of arrays):
    // colour (u, v, 1 - u - v), darkened on every other 8x8-pixel cell.
    void fragment(const prast::FragmentBlock<kVaryings>& in, prast::FragmentOut& out) const {
        for (int lane = 0; lane < prast::kBlockLanes; ++lane) {
            const int x = in.x + prast::lane_x(lane), y = in.y + prast::lane_y(lane);
            const float shade = ((x / 8 + y / 8) % 2) ? 0.8f : 1.0f;
            const float u = in.var[0][lane], v = in.var[1][lane];
            out.r[lane] = shade * u;
            out.g[lane] = shade * v;
            out.b[lane] = shade * (1.0f - u - v);
            out.a[lane] = 1.0f;
        }
    }
};

std::uint8_t to_byte(float c) {
    c = c < 0.0f ? 0.0f : (c > 1.0f ? 1.0f : c);
    return std::uint8_t(std::floor(c * 255.0f + 0.5f));
}

} // namespace

int main(int argc, char** argv) {
    const std::string out_path = argc > 1 ? argv[1] : "triangle.png";
    const int W = 256, H = 256;

    prast::Renderer renderer({/*threads*/ 0, /*tile size*/ 64});
    prast::Framebuffer fb(W, H);
    renderer.clear(fb, 0.0f, 0.0f, 0.0f, 1.0f);
    const std::uint32_t indices[3] = {0, 1, 2};
    MyProgram program;
    renderer.draw(fb, program, 3, indices, 3, prast::DrawState{});

    // The program writes display colours: straight to 8 bits, no tone map.
    std::vector<std::uint8_t> rgba8(std::size_t(W) * H * 4);
    for (std::size_t i = 0; i < rgba8.size(); ++i) rgba8[i] = to_byte(fb.color[i]);
    try {
        prast::write_png_atomic(out_path, W, H, rgba8.data());
    } catch (const std::exception& e) {
        std::fprintf(stderr, "triangle: %s\n", e.what());
        return 2;
    }

    // Check what was drawn. Window coordinates: x = (ndc + 1) / 2 * W,
    // y = (1 - ndc) / 2 * H (row 0 on top).
    auto covered = [&](int x, int y) { return fb.depth[std::size_t(y) * W + x] < 1.0f; };
    long count = 0;
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x) count += covered(x, y);
    double sx[3], sy[3];
    for (int i = 0; i < 3; ++i) {
        sx[i] = (MyProgram::kCorners[i][0] + 1.0) / 2.0 * W;
        sy[i] = (1.0 - MyProgram::kCorners[i][1]) / 2.0 * H;
    }
    const double area = std::fabs((sx[1] - sx[0]) * (sy[2] - sy[0]) - (sx[2] - sx[0]) * (sy[1] - sy[0])) / 2.0;
    const int cx = int((sx[0] + sx[1] + sx[2]) / 3.0), cy = int((sy[0] + sy[1] + sy[2]) / 3.0);
    std::printf("%s: %dx%d, %ld pixels covered (triangle area %.1f pixels), %llu triangle set up\n",
                out_path.c_str(), W, H, count, area,
                static_cast<unsigned long long>(renderer.stats().triangles_setup));
    bool ok = covered(cx, cy) && !covered(0, 0) && !covered(W - 1, 0) && !covered(0, H - 1) &&
              !covered(W - 1, H - 1) && std::fabs(double(count) - area) <= 0.01 * area;
    if (!ok) std::fprintf(stderr, "triangle: the image is not the expected triangle\n");
    return ok ? 0 : 1;
}

// Renderer construction; the draw call itself is a template in pipeline.h.
#include "raster/pipeline.h"

#include <algorithm>

namespace prast {

static int checked_tile_size(int ts) {
    if (ts < kMinTileSize || ts > kMaxTileSize || (ts & (ts - 1)) != 0)
        throw std::invalid_argument("tile size must be a power of two in [16, 256]");
    return ts;
}

Renderer::Renderer(const RendererOptions& options)
    : pool_(options.threads > 0 ? options.threads : ThreadPool::hardware_threads()),
      tile_size_(checked_tile_size(options.tile_size)) {}

void Renderer::clear(Framebuffer& fb, float r, float g, float b, float a, float z) {
    constexpr int kRows = 32;
    const int chunks = (fb.height + kRows - 1) / kRows;
    pool_.run(chunks, [&](int chunk, int) {
        const std::size_t begin = std::size_t(chunk) * kRows * fb.width;
        const std::size_t end = std::min<std::size_t>(std::size_t(fb.height), std::size_t(chunk + 1) * kRows) * fb.width;
        for (std::size_t i = begin; i < end; ++i) {
            float* c = &fb.color[i * 4];
            c[0] = r; c[1] = g; c[2] = b; c[3] = a;
            fb.depth[i] = z;
        }
    });
}

} // namespace prast

// Renderer construction; the draw call itself is a template in pipeline.h.
#include "raster/pipeline.h"

namespace prast {

static int checked_tile_size(int ts) {
    if (ts < kMinTileSize || ts > kMaxTileSize || (ts & (ts - 1)) != 0)
        throw std::invalid_argument("tile size must be a power of two in [16, 256]");
    return ts;
}

Renderer::Renderer(const RendererOptions& options)
    : pool_(options.threads > 0 ? options.threads : ThreadPool::hardware_threads()),
      tile_size_(checked_tile_size(options.tile_size)) {}

} // namespace prast

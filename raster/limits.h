// Every size limit of the pipeline, each with the reason it has that value
// (after llvmpipe's lp_limits.h).
#pragma once

#include <cstdint>

namespace prast {

// Vertex positions are snapped to 1/256 pixel before edge setup (docs/conventions.md).
constexpr int kSubPixelBits = 8;
constexpr std::int64_t kSubPixelScale = std::int64_t(1) << kSubPixelBits;
constexpr std::int64_t kHalfPixel = kSubPixelScale / 2;

// Largest framebuffer side. 16384^2 RGBA float colour + depth is 5 GiB, which
// is already more than a sane render; the render CLI refuses earlier by memory.
constexpr int kMaxViewportSize = 16384;

// Guard band: window coordinates of triangle vertices are kept within
// +-kGuardBandPixels; triangles reaching beyond are clipped to it in clip space.
// Bound: fixed-point coordinates are then < 2^(20+8) = 2^28, edge deltas < 2^29,
// and an edge function A*x + B*y + C at any pixel is < 2^60: exact in int64.
constexpr double kGuardBandPixels = double(1 << 20);

// A clipped triangle is a convex polygon of at most 3 + (number of planes)
// vertices: near, far and four guard-band planes.
constexpr int kClipPlanes = 6;
constexpr int kMaxClippedVertices = 3 + kClipPlanes;

// Blocks: coverage and shading run on 4x4 pixel blocks (four 2x2 quads, 16
// lanes: an AVX-512 register of floats); 16x16 blocks are the middle level of
// the hierarchical accept/reject.
constexpr int kBlockSize = 4;
constexpr int kBlockLanes = kBlockSize * kBlockSize;
constexpr int kCoarseBlockSize = 16;

// Tiles: a power of two between 16 and 256. 64 is the default (docs/pipeline.md, "Tile
// size", has the measurement behind it).
constexpr int kDefaultTileSize = 64;
constexpr int kMinTileSize = 16;
constexpr int kMaxTileSize = 256;

// Varyings per vertex, a compile-time constant of each program.
constexpr int kMaxVaryings = 32;

// Samples per pixel (multisampling): 1, 2, 4 or 8, the counts with standard
// positions (samples.h). A lane's per-sample masks fit in a byte.
constexpr int kMaxSamples = 8;

// Binning jobs: triangles are set up and binned in chunks of this many, so the
// per-tile bins stay in submission order whatever the thread count.
constexpr int kTrianglesPerJob = 2048;
constexpr int kMaxJobs = 512;

} // namespace prast

// Binning: every set-up triangle is listed in each screen tile its edges reach.
// A binning job owns a contiguous range of triangles and writes its own bins
// (CSR: per-tile offsets into one item array), so concatenating the jobs' bins
// in job order gives each tile its triangles in submission order, whatever the
// thread count.
#pragma once

#include <cstdint>
#include <vector>

#include "raster/setup.h"
#include "raster/stats.h"

namespace prast {

struct TileGrid {
    int width = 0, height = 0;   // viewport
    int tile_size = kDefaultTileSize;
    int tiles_x = 0, tiles_y = 0;
    TileGrid() = default;
    TileGrid(int w, int h, int ts)
        : width(w), height(h), tile_size(ts), tiles_x((w + ts - 1) / ts), tiles_y((h + ts - 1) / ts) {}
    int count() const { return tiles_x * tiles_y; }
};

struct BinJob {
    std::vector<TriangleSetup> setups;
    std::vector<float> clip_pool;            // vertices made by clipping, `stride` floats each
    std::vector<std::uint64_t> pairs;        // (tile << 32 | setup index), before sorting
    std::vector<std::uint32_t> tile_offsets; // tiles + 1
    std::vector<std::uint32_t> items;        // setup indices grouped by tile
    std::vector<std::uint32_t> scratch_cursor;
    FrameStats stats;

    void reset() {
        setups.clear();
        clip_pool.clear();
        pairs.clear();
        stats = FrameStats{};
    }
};

// Appends the tiles that triangle `index` of `job` touches to job.pairs
// (tiles whose every pixel centre is outside one edge are skipped).
template <class OnBin>
inline void bin_triangle(BinJob& job, std::uint32_t index, const TileGrid& grid, OnBin&& on_bin) {
    const TriangleSetup& t = job.setups[index];
    int tx0 = t.minx / grid.tile_size, tx1 = t.maxx / grid.tile_size;
    int ty0 = t.miny / grid.tile_size, ty1 = t.maxy / grid.tile_size;
    bool single = tx0 == tx1 && ty0 == ty1;
    for (int ty = ty0; ty <= ty1; ++ty)
        for (int tx = tx0; tx <= tx1; ++tx) {
            if (!single) {
                int x = tx * grid.tile_size, y = ty * grid.tile_size;
                if (classify_block(t, 0, x, y, grid.tile_size) == kEdgeOut ||
                    classify_block(t, 1, x, y, grid.tile_size) == kEdgeOut ||
                    classify_block(t, 2, x, y, grid.tile_size) == kEdgeOut)
                    continue;
            }
            std::uint32_t tile = std::uint32_t(ty * grid.tiles_x + tx);
            job.pairs.push_back((std::uint64_t(tile) << 32) | index);
            on_bin(tile);
        }
}

// Groups job.pairs by tile into tile_offsets/items, keeping submission order
// inside each tile (a stable counting sort).
void sort_bins(BinJob& job, int tile_count);

} // namespace prast

// Counting sort of a job's (tile, triangle) pairs; see bin.h.
#include "raster/bin.h"

namespace prast {

void sort_bins(BinJob& job, int tile_count) {
    job.tile_offsets.assign(std::size_t(tile_count) + 1, 0);
    for (std::uint64_t p : job.pairs) ++job.tile_offsets[(p >> 32) + 1];
    for (int i = 0; i < tile_count; ++i) job.tile_offsets[i + 1] += job.tile_offsets[i];
    job.items.resize(job.pairs.size());
    // Pairs were appended in triangle order, so a forward pass keeps that order.
    std::vector<std::uint32_t>& cursor = job.scratch_cursor;
    cursor.assign(job.tile_offsets.begin(), job.tile_offsets.end() - 1);
    for (std::uint64_t p : job.pairs) job.items[cursor[p >> 32]++] = std::uint32_t(p);
    job.stats.bin_entries += job.pairs.size();
}

} // namespace prast

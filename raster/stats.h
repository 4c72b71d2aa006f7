// Per-frame counters of every stage. Integers are summed per worker and then
// added, which is order-independent; times are wall-clock on the caller.
#pragma once

#include <cstdint>
#include <string>

namespace prast {

struct FrameStats {
    std::uint64_t draws = 0;
    std::uint64_t vertices = 0;            // vertex shader invocations
    std::uint64_t triangles_in = 0;        // submitted
    std::uint64_t triangles_invalid = 0;   // NaN/Inf position: dropped
    std::uint64_t triangles_culled_frustum = 0; // entirely outside one frustum plane
    std::uint64_t triangles_culled_back = 0;
    std::uint64_t triangles_degenerate = 0;    // zero area after snapping, or no pixel centre
    std::uint64_t triangles_clipped = 0;   // needed near/far/guard-band clipping
    std::uint64_t triangles_setup = 0;     // reached the bins (after clipping: may exceed triangles_in)
    std::uint64_t bin_entries = 0;         // (triangle, tile) pairs (and (line, tile), (point, tile))
    std::uint64_t tiles_touched = 0;       // tiles with at least one bin entry
    std::uint64_t blocks_rasterized = 0;   // 4x4 blocks with coverage
    std::uint64_t quads_shaded = 0;        // 2x2 quads handed to the fragment shader with >= 1 live lane
    std::uint64_t fragments_covered = 0;   // pixels inside triangles (with a covered sample)
    std::uint64_t fragments_depth_killed = 0; // failed the early depth test (every sample)
    std::uint64_t fragments_shader_killed = 0; // discarded by the shader (alpha mask)
    // Passed the depth test and not discarded, in submission order: written at
    // once (draws shaded in order) or the pixel's winner until a later one
    // passes (the visibility pass); the count drawing one draw at a time would give, either way.
    std::uint64_t fragments_written = 0;
    std::uint64_t fragments_shaded = 0;    // live lanes the fragment program ran for
    double ms_vertex = 0, ms_setup_bin = 0, ms_raster = 0;

    void add_counters(const FrameStats& o);
    std::string to_string() const;  // multi-line, for --stats
};

} // namespace prast

// FrameStats summation and printing.
#include "raster/stats.h"

#include <cstdio>

namespace prast {

void FrameStats::add_counters(const FrameStats& o) {
    draws += o.draws;
    vertices += o.vertices;
    triangles_in += o.triangles_in;
    triangles_invalid += o.triangles_invalid;
    triangles_culled_frustum += o.triangles_culled_frustum;
    triangles_culled_back += o.triangles_culled_back;
    triangles_degenerate += o.triangles_degenerate;
    triangles_clipped += o.triangles_clipped;
    triangles_setup += o.triangles_setup;
    bin_entries += o.bin_entries;
    tiles_touched += o.tiles_touched;
    blocks_rasterized += o.blocks_rasterized;
    quads_shaded += o.quads_shaded;
    fragments_covered += o.fragments_covered;
    fragments_depth_killed += o.fragments_depth_killed;
    fragments_shader_killed += o.fragments_shader_killed;
    fragments_written += o.fragments_written;
    fragments_shaded += o.fragments_shaded;
    ms_vertex += o.ms_vertex;
    ms_setup_bin += o.ms_setup_bin;
    ms_raster += o.ms_raster;
}

std::string FrameStats::to_string() const {
    char buf[1536];
    std::snprintf(buf, sizeof buf,
        "draws                  %llu\n"
        "vertices shaded        %llu\n"
        "triangles in           %llu\n"
        "  invalid (NaN/Inf)    %llu\n"
        "  culled (frustum)     %llu\n"
        "  culled (back face)   %llu\n"
        "  degenerate           %llu\n"
        "  clipped              %llu\n"
        "  set up (post-clip)   %llu\n"
        "bin entries            %llu\n"
        "tiles touched          %llu\n"
        "4x4 blocks rasterized  %llu\n"
        "quads shaded           %llu\n"
        "fragments covered      %llu\n"
        "  killed by depth      %llu\n"
        "  killed by shader     %llu\n"
        "  written              %llu\n"
        "fragments shaded       %llu\n"
        "time vertex            %.3f ms\n"
        "time setup+bin         %.3f ms\n"
        "time raster+shade      %.3f ms\n",
        (unsigned long long)draws, (unsigned long long)vertices,
        (unsigned long long)triangles_in, (unsigned long long)triangles_invalid,
        (unsigned long long)triangles_culled_frustum, (unsigned long long)triangles_culled_back,
        (unsigned long long)triangles_degenerate, (unsigned long long)triangles_clipped,
        (unsigned long long)triangles_setup, (unsigned long long)bin_entries,
        (unsigned long long)tiles_touched, (unsigned long long)blocks_rasterized,
        (unsigned long long)quads_shaded, (unsigned long long)fragments_covered,
        (unsigned long long)fragments_depth_killed, (unsigned long long)fragments_shader_killed,
        (unsigned long long)fragments_written, (unsigned long long)fragments_shaded, ms_vertex, ms_setup_bin, ms_raster);
    return buf;
}

} // namespace prast

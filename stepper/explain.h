// Explanations of the recorded frame, as text (the terminal front end) and
// as JSON (the web page's API): the frame's counters, one triangle's trip
// through clipping, setup, binning and the tile walk, one tile's bins, and
// one pixel's history with the full shading breakdown of the fragment that
// won. Every number is read from the recording or recomputed by replay.h
// with the pipeline's own functions.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <glm/glm.hpp>
#include <nlohmann/json.hpp>

#include "stepper/recording.h"
#include "stepper/replay.h"

namespace prast::stepper {

// What the pipeline's walk did with one piece in one tile (rasterize.h's
// hierarchy, recomputed with setup.h's classify_block()).
struct TileWalk {
    int tile = 0;
    int coarse_rejected = 0, coarse_accepted = 0, coarse_partial = 0;  // 16x16 blocks
    int fine_rejected = 0, fine_accepted = 0, fine_walked = 0;         // 4x4 blocks
    int fine_with_coverage = 0;      // accepted or walked blocks with a covered pixel in the viewport
    int recorded_blocks = 0;         // blocks the recording holds for this piece and tile
    int covered = 0, passed = 0, written = 0;
};
TileWalk walk_tile(const Recording& rec, std::uint32_t piece, int tile);

// One fragment of a pixel's history: a triangle piece covering at least one
// of the pixel's samples, or a line or point covering the pixel, in the order
// the tile ran it.
struct HistoryEntry {
    std::uint32_t piece = 0;      // triangles: the piece (line_draw < 0)
    int line_draw = -1;           // a line or point fragment: its draw (piece and block unused)
    std::uint32_t line_prim = 0;  // ... the line's or point's number in its draw
    LineReplay line;              // ... as set up (clipped ends, fixed-point setup)
    float line_t = 0.0f, line_w1 = 0.0f;  // ... the centre's parameter on the segment, P1's perspective weight
    int lane = 0;
    const BlockRecord* block = nullptr;
    bool visible = false;         // its draw took the visibility pass (else shaded in order)
    std::uint32_t cover = 0;      // bit s: sample s inside the triangle
    std::uint32_t pass = 0;       // bit s: ... and passed the depth test (recorded)
    float z[kMaxSamples] = {};             // depth at each covered sample (recorded)
    float depth_before[kMaxSamples] = {};  // the sample's depth when it was tested
    bool shaded = false;          // the fragment program ran for it (once for the pixel)
    bool written = false, killed = false;  // its colour was written / it was discarded
    std::uint32_t owns = 0;       // bit s: sample s ends the frame with its colour
    int blend_order = 0;          // alpha BLEND: 1 for the pixel's first blended fragment, 2 ...; 0 otherwise
    float alpha = 1.0f;           // alpha BLEND: the weight of its colour
    glm::vec3 blended[kMaxSamples] = {};  // alpha BLEND: each written sample's colour after blending
    ReplayedBlock replay;
    LaneShading shading;          // only when shaded
};

struct PixelExplanation {
    int x = 0, y = 0, lane = 0;
    int samples = 1;
    std::uint64_t upto = kAllTriangles;    // explained after the first `upto` triangles; kAllTriangles: the frame's end
    std::vector<HistoryEntry> history;
    int sample_owner[kMaxSamples];         // history index whose colour sample s holds; -1: cleared
    glm::vec3 sample_color[kMaxSamples];   // each sample's final linear colour
    float sample_depth[kMaxSamples];
    glm::vec3 background{0.0f};            // what every sample clears to: render's background here
    std::vector<int> contributors;         // history indices owning samples, most samples first
    glm::vec3 linear{0.0f};       // the resolve of the samples: what render --output .hdr writes
    glm::vec3 framebuffer{0.0f};  // the frame's value at that point (equal to linear, or a NOTE says so)
    glm::vec3 exposed{0.0f}, toned{0.0f};
    std::uint8_t srgb8[3] = {0, 0, 0};
};
// Short of the frame's end (upto < the frame's triangles), the history holds
// the fragments of the first `upto` triangles (and of the line and point
// draws submitted before them), as draw_upto() draws them: the visibility
// pass's winners at that point are shaded, and `frame` (draw_upto's frame)
// gives the framebuffer's value; at or past the end, the recorded frame's.
PixelExplanation explain_pixel(const FrameSetup& s, const Recording& rec, int x, int y,
                               std::uint64_t upto = kAllTriangles, const Framebuffer* frame = nullptr);

// The resolve of raster/resolve.cpp on one pixel: pairwise sums of the
// samples' linear colours, times 1 / samples.
glm::vec3 resolve_average(const glm::vec3* colors, int samples);

std::string frame_text(const FrameSetup& s, const Recording& rec);
std::string triangle_text(const FrameSetup& s, const Recording& rec, std::uint32_t tri);
std::string tile_text(const FrameSetup& s, const Recording& rec, int tx, int ty);
std::string pixel_text(const FrameSetup& s, const Recording& rec, const PixelExplanation& px);

nlohmann::json frame_json(const FrameSetup& s, const Recording& rec);
nlohmann::json triangle_json(const FrameSetup& s, const Recording& rec, std::uint32_t tri);
nlohmann::json tile_json(const FrameSetup& s, const Recording& rec, int tx, int ty);
nlohmann::json pixel_json(const FrameSetup& s, const Recording& rec, const PixelExplanation& px);

const char* fate_name(TriangleFate f);
// "sampler: mag LINEAR, min LINEAR_MIPMAP_LINEAR, wrap repeat/repeat"
std::string sampler_text(const Texture& tex);
std::string mesh_name(const FrameSetup& s, const Recording& rec, std::uint32_t tri);

// The one name of a triangle both `render --pixel` and `step` print:
// "draw D (mesh 'NAME') triangle P (frame triangle N)", P within the draw's
// mesh, N over the frame in submission order (what `tri N` takes).
std::string triangle_name(const FrameSetup& s, const Recording& rec, std::uint32_t tri);
// A line or point: "draw D (mesh 'NAME') line P" (or point P).
std::string line_name(const FrameSetup& s, const Recording& rec, std::size_t draw, std::uint32_t prim);
// The frame triangle that "draw D ... triangle P" names; false when there is none.
bool frame_triangle(const Recording& rec, long draw, long prim, std::uint32_t& tri);

} // namespace prast::stepper

// One recording of a frame: what every stage of the pipeline did, heard
// through a stage observer (raster/observer.h) while the real frame is drawn.
// Kept compact: per draw the vertex stage's output; per triangle its fate and
// per post-clip piece the TriangleSetup the pipeline built and the tiles it
// was binned to; per tile, in the order the tile ran them, the 4x4 blocks
// with their coverage, depth-test, shaded and written masks, and sample by
// sample (multisampling) the coverage and depth-test masks and the depths of
// the covered samples. Barycentrics, varyings and shading are recomputed on
// demand from these (replay.h), with the pipeline's own data and functions.
//
// Observer calls come from worker threads: vertex and triangle events are
// keyed by their (draw-local) index, block events go to their tile's list
// (a tile is run by one thread at a time), so the recording is the same for
// any thread count.
#pragma once

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <mutex>
#include <string>
#include <vector>

#include "raster/draw_state.h"
#include "raster/framebuffer.h"
#include "raster/observer.h"
#include "raster/pipeline.h"
#include "raster/setup.h"
#include "raster/stats.h"
#include "shading/pbr_program.h"
#include "renderer/frame_setup.h"

namespace prast::stepper {

// A vertex as the recording keeps it: clip xyzw and the first kPbrVaryings
// varyings in DrawRecord::vertices (kStride floats, the layout every draw
// shares); a draw whose program writes more (PbrProgramExt) keeps the rest
// in DrawRecord::more, so the common narrow draws pay nothing for the wide
// ones. A program with fewer (UnlitProgram) leaves the tail of its kStride
// zero. full_vertex() puts a vertex back together (kMaxStride floats).
constexpr int kStride = 4 + kPbrVaryings;
constexpr int kMaxVaryingsRecorded = kPbrVaryingsExt;
constexpr int kMaxStride = 4 + kMaxVaryingsRecorded;
constexpr std::uint32_t kNone = 0xFFFFFFFFu;

struct DrawRecord {
    int mesh = -1;                      // index into the scene's meshes
    DrawState state;
    bool visible = false;               // visibility pass (winners shaded once), else shaded in order
    std::uint32_t first_triangle = 0;   // global number of the draw's triangle 0
    std::uint32_t triangle_count = 0;
    std::uint32_t vertex_count = 0;
    int varyings = kPbrVaryings;        // floats the draw's program writes after clip xyzw
    Topology topology = Topology::Triangles;
    std::uint32_t primitives = 0;       // lines or points: how many the draw submits
    std::vector<float> vertices;        // kStride floats per vertex, as the vertex stage wrote them
    std::vector<float> more;            // varyings past kPbrVaryings: (varyings - kPbrVaryings) per vertex
    int stride() const { return 4 + varyings; }
    int more_count() const { return varyings > kPbrVaryings ? varyings - kPbrVaryings : 0; }
    // Vertex v as the vertex stage wrote it: stride() floats into out.
    void full_vertex(std::uint32_t v, float* out) const;
};

// A post-clip piece of a triangle (an unclipped triangle is one piece).
struct PieceRecord {
    std::uint32_t triangle = 0;         // global triangle number
    TriangleFate fate = TriangleFate::SetUp;
    std::uint32_t setup = kNone;        // index into Recording::setups when set up
    std::uint32_t first_tile = 0, tile_count = 0;  // into Recording::piece_tiles
};

struct TriangleRecord {
    TriangleFate fate = TriangleFate::Invalid;  // SetUp when any piece was set up
    bool clipped = false;
    bool seen = false;                  // false: beyond a triangle limit, never submitted
    std::uint32_t first_piece = 0, piece_count = 0;
};

// One 4x4 block of one triangle piece in a tile: covered (a lane counts when
// any of its samples is), passed the depth test (any sample, at that point
// of the tile's sequence), shaded (the lanes the fragment program ran for:
// all that passed when shaded in order, only the lanes where the triangle
// finally won a sample when shaded after the visibility pass) and written
// (shaded and not discarded).
struct BlockRecord {
    std::uint32_t piece = 0;            // index into Recording::pieces
    std::uint16_t bx = 0, by = 0;       // top-left pixel
    std::uint16_t mask = 0, pass = 0, shaded = 0, live = 0;
    std::uint32_t z = 0;                // first depth in TileRecord::z: sample by sample, covered lanes in lane order
    std::uint32_t masks = 0;            // several samples: first of its 2 x samples masks in TileRecord::masks
};

struct TileRecord {
    std::vector<std::uint32_t> pieces;  // binned pieces, in the order the tile ran them
    std::vector<BlockRecord> blocks;    // in the order the tile ran them
    std::vector<float> z;               // window depth of each covered sample of each block
    std::vector<std::uint16_t> masks;   // several samples: per block cover[0..S-1], pass[0..S-1]
};

struct Recording {
    int width = 0, height = 0, tile_size = 0, tiles_x = 0, tiles_y = 0;
    int samples = 1;                        // per pixel
    FrameOptions::Visibility visibility = FrameOptions::Visibility::Auto;
    std::vector<DrawRecord> draws;
    std::vector<TriangleRecord> triangles;  // global submission order
    std::vector<PieceRecord> pieces;        // grouped by triangle, pieces in fan order
    std::vector<TriangleSetup> setups;      // as setup_triangle() built them
    std::vector<std::uint32_t> piece_tiles; // tiles of each piece, in binning order
    std::vector<TileRecord> tiles;
    FrameStats stats;                       // the renderer's counters for the frame
    Framebuffer fb;                         // the frame itself (linear colour, depth)
    double record_ms = 0.0;                 // wall time of the recorded frame

    int tile_of(int x, int y) const { return (y / tile_size) * tiles_x + x / tile_size; }
    // Which draw holds global triangle `tri` (draws of lines and points hold none).
    const DrawRecord& draw_of(std::uint32_t tri) const;
    std::size_t draw_index(std::uint32_t tri) const { return std::size_t(&draw_of(tri) - draws.data()); }
    // Vertex recording mismatches (a program wrote another varying count
    // than the one the recording laid out for it): 0, or the stepper is wrong.
    std::uint32_t layout_mismatches = 0;
    std::uint32_t triangle_count() const { return std::uint32_t(triangles.size()); }
    std::size_t bytes() const;              // memory held, without the framebuffer

    // Sample s of a recorded block: its coverage and depth-test masks, and
    // the depth of a covered lane.
    std::uint32_t cover(const TileRecord& t, const BlockRecord& b, int s) const {
        return samples == 1 ? b.mask : t.masks[b.masks + std::size_t(s)];
    }
    std::uint32_t pass(const TileRecord& t, const BlockRecord& b, int s) const {
        return samples == 1 ? b.pass : t.masks[b.masks + std::size_t(samples + s)];
    }
    float depth(const TileRecord& t, const BlockRecord& b, int s, int lane) const {
        std::size_t k = b.z;
        for (int i = 0; i < s; ++i) k += std::size_t(__builtin_popcount(cover(t, b, i)));
        return t.z[k + std::size_t(__builtin_popcount(cover(t, b, s) & ((1u << lane) - 1u)))];
    }
};

// The varyings the program of a draw writes (renderer/scene_renderer.h's
// choice: UnlitProgram for lines and points without normals in the lit
// image, PbrProgramExt for vertex colours or a second UV set, else PbrProgram).
int draw_varyings(const FrameSetup& s, const SceneDraw& d);

// Draws the frame (SceneRenderer::render, a recording tap on each draw); `rec` is filled.
void record_frame(FrameSetup& s, Recording& rec);

// No triangle limit: the whole frame.
constexpr std::uint64_t kAllTriangles = ~std::uint64_t(0);

// The frame after the first `triangles` triangles (submission order); all of
// them (or more) is the whole frame, with the line and point draws after the
// last triangle.
void draw_upto(FrameSetup& s, std::uint64_t triangles, Framebuffer& fb);

// The frame as `render` draws it (SceneRenderer, no observer): the cost
// comparison and the check that the recorded frame is the same.
void draw_plain(FrameSetup& s, Framebuffer& fb);

} // namespace prast::stepper

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

// One fragment of a pixel's history.
struct HistoryEntry {
    std::uint32_t piece = 0;
    int lane = 0;
    const BlockRecord* block = nullptr;
    float z = 0.0f;               // the fragment's depth (recorded)
    float depth_before = 1.0f;    // the buffer's depth when it was tested
    glm::vec3 color_before{0.0f}, color_after{0.0f};
    bool passed = false, written = false, killed = false;
    ReplayedBlock replay;
    LaneShading shading;          // only when it passed the depth test (the shader ran)
};

struct PixelExplanation {
    int x = 0, y = 0;
    std::vector<HistoryEntry> history;
    int winner = -1;              // index into history of the last written fragment
    glm::vec3 linear{0.0f};       // the framebuffer's value: what render --output .hdr writes
    glm::vec3 exposed{0.0f}, toned{0.0f};
    std::uint8_t srgb8[3] = {0, 0, 0};
};
PixelExplanation explain_pixel(const StepScene& s, const Recording& rec, int x, int y);

std::string frame_text(const StepScene& s, const Recording& rec);
std::string triangle_text(const StepScene& s, const Recording& rec, std::uint32_t tri);
std::string tile_text(const StepScene& s, const Recording& rec, int tx, int ty);
std::string pixel_text(const StepScene& s, const Recording& rec, const PixelExplanation& px);

nlohmann::json frame_json(const StepScene& s, const Recording& rec);
nlohmann::json triangle_json(const StepScene& s, const Recording& rec, std::uint32_t tri);
nlohmann::json tile_json(const StepScene& s, const Recording& rec, int tx, int ty);
nlohmann::json pixel_json(const StepScene& s, const Recording& rec, const PixelExplanation& px);

const char* fate_name(TriangleFate f);
std::string mesh_name(const StepScene& s, const Recording& rec, std::uint32_t tri);

} // namespace prast::stepper

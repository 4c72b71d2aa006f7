// Views of the recorded frame's inputs, in the manner of a GPU debugger's
// event and resource browsers: the list of draws, one draw's state (its
// material, textures, samplers, fixed-function state, lights, shadows and
// environment), the frame's textures (material maps, shadow maps, the
// environment's levels) with any level as a PNG, a draw's vertices in and out
// of the vertex stage, and one tile's bins with a summary and a filter.
//
// One implementation behind both front ends: each make_*() checks its
// arguments as typed (the words of a command, or a request's parameters),
// fills a view and returns "" or a one-line error (without "error: "); the
// view formats to the terminal's text and to JSON (with that text under
// "text"), so a web endpoint is one call.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <glm/glm.hpp>
#include <nlohmann/json.hpp>

#include "stepper/recording.h"

namespace prast::stepper {

// "1 block", "2 blocks"; "1 vertex", "3 vertices" with the plural given.
std::string plural(std::uint64_t n, const std::string& one, const std::string& many = "");

// ---- draws: one line a draw, in submission order.
struct DrawLine {
    int index = 0;
    int mesh = -1, material = -1;              // scene indices (material -1: the fallback)
    std::string mesh_name, material_name;
    Topology topology = Topology::Triangles;
    std::uint64_t primitives = 0;              // triangles, lines or points the draw submits
    std::uint64_t drawn = 0;                   // ... that survived clipping and culling (set up)
    std::string alpha;                         // "OPAQUE", "MASK 0.5", "BLEND"
    bool double_sided = false;
    int varyings = 0;
    std::string program;                       // "PBR narrow (12 varyings)", "PBR wide (18 ...)", "unlit (6 ...)"
};
struct DrawsView {
    std::vector<DrawLine> draws;
    std::string text() const;
    nlohmann::json json() const;
};
std::string make_draws(const FrameSetup& s, const Recording& rec, DrawsView& out);

// ---- draw N: its state.
struct MapBinding {
    std::string slot;                          // "base_color", "normal", ...
    std::string texture;                       // texture ID (`texture ID`), "" when the map failed to decode
    std::vector<int> images;                   // scene image indices (two: packed roughness + metal)
    std::string description;                   // size, format, levels, sampler, UV set
    int uv_set = 0;
};
struct DrawView {
    DrawLine line;
    std::vector<std::string> lines;            // the text, line by line (without the first)
    nlohmann::json state;                      // the same as data
    std::string text() const;
    nlohmann::json json() const;
};
std::string make_draw(const FrameSetup& s, const Recording& rec, const std::string& n, DrawView& out);

// ---- textures: every texture of the frame, by ID: "0", "1", ... the
// material maps (one per decoded image and sampler), "shadowL" the shadow map
// of light L (a cube's six faces stacked top to bottom: +X -X +Y -Y +Z -Z),
// "env" the environment's specular levels (level 0 the map itself).
struct TextureInfo {
    std::string id;
    std::string kind;                          // "material", "shadow", "environment"
    int width = 0, height = 0, levels = 1;     // level 0
    std::vector<glm::ivec2> level_sizes;
    std::string format;                        // "RGBA 8-bit sRGB", "RGB float32 linear", "depth float32"
    int channels = 4, bits = 8;
    std::string colour_space;                  // "sRGB", "linear", "distance"
    std::string png_rule;                      // how a level becomes the 8-bit PNG
    std::vector<std::string> uses;             // "material 2 'tiles' base_color (UV set 0, sampler: ...)"
    std::vector<std::string> images;           // the scene images: "image 3 'floor.png' 512x512"
    std::string summary() const;               // one line
};
struct TexturesView {
    std::vector<TextureInfo> textures;
    std::string text() const;
    nlohmann::json json() const;
};
std::string make_textures(const FrameSetup& s, const Recording& rec, TexturesView& out);

// ---- texture ID [LEVEL]: its metadata and the level as an 8-bit PNG.
struct TextureView {
    TextureInfo info;
    int level = 0;
    std::string note;                          // the range of a shadow map's ramp, of an HDR level
    std::string text() const;                  // without the file line (the terminal adds "wrote FILE")
    nlohmann::json json() const;               // with "png": the endpoint to fetch the level
};
std::string make_texture(const FrameSetup& s, const Recording& rec, const std::string& id, const std::string& level,
                         TextureView& out);
// The PNG bytes of texture `id`'s level `level` ("" is level 0), by the
// rule TextureInfo::png_rule states; "" or a one-line error.
std::string texture_png(const FrameSetup& s, const Recording& rec, const std::string& id, const std::string& level,
                        std::vector<std::uint8_t>& png);

// ---- texel ID LEVEL X Y: one texel of a level (X, Y in the level's PNG; a
// cube shadow map's faces stacked), as stored and as the samplers read it.
struct TexelView {
    TextureInfo info;
    int level = 0, x = 0, y = 0;
    int width = 0, height = 0;                 // the level's
    int face = -1, fx = 0, fy = 0;             // a cube shadow map: the face and the texel in it
    std::string stored_type;                   // "8-bit", "float32"
    std::vector<std::string> stored_names;     // "R", "G", "B", "A"; "grey"; "roughness", "metal"; "distance"
    std::vector<double> stored;                // as stored: bytes 0..255, or the floats
    std::vector<std::string> decode;           // per linear channel: how it comes from the stored ones
    std::vector<std::string> linear_names;     // "R", "G", "B", "A"; "distance"
    std::vector<double> linear;                // what the samplers read (+inf: a shadow texel without a caster)
    std::vector<int> shown;                    // the level's PNG at the texel (texture ID LEVEL)
    std::string text() const;
    nlohmann::json json() const;
};
std::string make_texel(const FrameSetup& s, const Recording& rec, const std::string& id, const std::string& level,
                       const std::string& x, const std::string& y, TexelView& out);

// ---- vertices N [FIRST [COUNT]]: draw N's vertices in and out.
constexpr long kDefaultVertexRows = 16;
constexpr long kMaxVertexRows = 1000;
struct VertexRow {
    std::uint32_t index = 0;
    glm::vec3 position{0.0f}, normal{0.0f};
    bool has_normal = false, has_uv0 = false, has_uv1 = false, has_tangent = false, has_color = false;
    glm::vec2 uv0{0.0f}, uv1{0.0f};
    glm::vec4 tangent{0.0f}, color{1.0f};
    int influence_sets = 0;                    // JOINTS_n/WEIGHTS_n of the source primitive
    std::vector<std::uint32_t> joints;
    std::vector<float> weights;
    float clip[4] = {0, 0, 0, 0};
    double window[2] = {0, 0};
    float window_z = 0.0f;
    std::vector<float> varyings;               // as the vertex stage wrote them
};
struct VerticesView {
    int draw = 0;
    std::string mesh_name;
    std::uint32_t vertex_count = 0;
    std::uint32_t first = 0;
    long requested = 0;                        // COUNT as asked
    bool capped = false;                       // more were asked than kMaxVertexRows
    int varyings = 0;
    std::string layout;                        // the varyings' names
    std::vector<VertexRow> rows;
    std::string text() const;
    nlohmann::json json() const;
};
std::string make_vertices(const FrameSetup& s, const Recording& rec, const std::string& n, const std::string& first,
                          const std::string& count, VerticesView& out);

// ---- tile X Y [tri N | pixel X Y | --summary]: a summary of the tile, then
// its bins in the order the tile ran them, all or filtered.
struct TileBin {
    std::uint32_t piece = 0, triangle = 0;
    int piece_in_triangle = -1;                // -1: the triangle is one piece
    std::string mesh;
    int blocks = 0, covered = 0, passed = 0, shaded = 0, written = 0;
    std::vector<std::string> block_lines;      // filtered: the blocks themselves
};
struct TileView {
    int tx = 0, ty = 0, x0 = 0, y0 = 0, x1 = 0, y1 = 0;
    std::uint64_t bin_entries = 0, triangles = 0, blocks = 0;
    std::uint64_t covered = 0, passed = 0, failed = 0, shaded = 0, written = 0, pixels_written = 0;
    std::string filter;                        // "" (all), "tri N", "pixel X Y", "--summary"
    bool summary_only = false;
    std::vector<TileBin> bins;
    std::string text() const;
    nlohmann::json json() const;
};
// args: the words after "tile" (X Y and the filter).
std::string make_tile(const FrameSetup& s, const Recording& rec, const std::vector<std::string>& args, TileView& out);

} // namespace prast::stepper

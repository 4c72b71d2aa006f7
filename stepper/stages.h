// Stage images: each stage of the pipeline and each channel of the shading,
// drawn from the recording as an 8-bit RGBA image the size of the frame.
// `stage NAME`, `--out DIR` and the web page all use these.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "stepper/recording.h"

namespace prast::stepper {

struct StageInfo {
    const char* name;
    const char* title;
    const char* about;   // one or two sentences for index.html and the page
};
const std::vector<StageInfo>& stage_list();
const StageInfo* find_stage(const std::string& name);

// How a stage image maps what it shows to a colour, for its legend (the
// page's colour bar and index.html's), taken from the drawing code itself:
//   "ramp": a colour bar; `stops` are its colours at positions t in [0, 1]
//           and the value at t is `map` between `min` and `max`: "linear",
//           "log" (log2 of the value), "log1p" (log2 of 1 + the value) or
//           "x/(1+x)" (min and max unused: 0 at t = 0, infinity at t = 1);
//   "classes": a few fixed colours, each a label;
//   "channels": red, green and blue each carry a number from min to max
//           (`srgb`: through the sRGB transfer function);
//   "picture": no scale (the final image).
// `classes` also lists, for a ramp or channels, the colours that are not on
// the scale (black for no fragment, the tile borders).
struct LegendColour {
    std::uint8_t rgb[3];
    std::string label;
};
struct StageScale {
    std::string kind = "picture";
    std::string quantity;  // what the colour shows
    std::string units;
    std::string map = "linear";
    double min = 0.0, max = 1.0;
    std::vector<std::pair<double, LegendColour>> stops;  // ramp: t, colour (label unused)
    std::vector<std::pair<double, std::string>> ticks;   // ramp: t, label
    std::vector<LegendColour> classes;
    std::vector<std::string> channels;  // channels: what red, green, blue carry
    bool srgb = false;
};
// The scale of stage `name` in this frame (depth's near and far, the
// fullest tile's bin count).
StageScale stage_scale(const FrameSetup& s, const Recording& rec, const std::string& name);
// The stage list as /api/stages serves it: [{name, title, about, scale}],
// colours as "#rrggbb".
nlohmann::json stage_list_json(const FrameSetup& s, const Recording& rec);
// A colour as "#rrggbb".
std::string css_colour(const std::uint8_t rgb[3]);

// Draws stage `name` (a name from stage_list()) into rgba8 (width * height * 4).
void draw_stage(FrameSetup& s, const Recording& rec, const std::string& name, std::vector<std::uint8_t>& rgba8);

// Several surface stages (material channels and BRDF terms) need the same
// per-pixel shading: draws all of `names` in one pass over the pixels.
void draw_stages(FrameSetup& s, const Recording& rec, const std::vector<std::string>& names,
                 std::vector<std::vector<std::uint8_t>>& images);

} // namespace prast::stepper

// Stage images: each stage of the pipeline and each channel of the shading,
// drawn from the recording as an 8-bit RGBA image the size of the frame.
// `stage NAME`, `--out DIR` and the web page all use these.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "stepper/recording.h"

namespace prast::stepper {

struct StageInfo {
    const char* name;
    const char* title;
    const char* about;   // one or two sentences for index.html and the page
};
const std::vector<StageInfo>& stage_list();
const StageInfo* find_stage(const std::string& name);

// Draws stage `name` (a name from stage_list()) into rgba8 (width * height * 4).
void draw_stage(FrameSetup& s, const Recording& rec, const std::string& name, std::vector<std::uint8_t>& rgba8);

// Several surface stages (material channels and BRDF terms) need the same
// per-pixel shading: draws all of `names` in one pass over the pixels.
void draw_stages(FrameSetup& s, const Recording& rec, const std::vector<std::string>& names,
                 std::vector<std::vector<std::uint8_t>>& images);

} // namespace prast::stepper

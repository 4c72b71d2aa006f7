// The debug views of `render --view` and the stepper: one channel of the
// shading pipeline shown instead of the lit colour.
#pragma once

#include <string>

namespace prast {

enum class DebugView {
    None, Albedo, Normal, Roughness, Metallic, Uv, Depth, Overdraw, Tiles,
    Ndf, Fresnel, Geometry, Diffuse, Specular,
};

bool parse_debug_view(const std::string& name, DebugView& out);
const char* debug_view_names();  // "albedo, normal, ..." for messages

} // namespace prast

// The debug views of `render --view` and the stepper: one channel of the
// shading pipeline shown instead of the lit colour.
#pragma once

#include <string>

namespace prast {

enum class DebugView {
    None, Albedo, Normal, Roughness, Metallic, Uv, Depth, Overdraw, Tiles,
    Ndf, Fresnel, Geometry, Diffuse, Specular,
    Irradiance,  // E(n) / pi of the environment (what a white Lambertian surface reflects)
};

bool parse_debug_view(const std::string& name, DebugView& out);

// Views of data rather than colour (normals, roughness, metallic, uv, depth,
// D, F, G): written to 8 bits as they are, without tone map or sRGB encoding,
// so that a byte reads back as the value (byte / 255).
bool debug_view_is_data(DebugView v);
// Views that run the lighting as the image does (none, tiles, diffuse,
// specular): shadow maps are drawn and BLEND meshes blended only for these.
bool debug_view_is_lit(DebugView v);
const char* debug_view_names();  // "albedo, normal, ..." for messages

} // namespace prast

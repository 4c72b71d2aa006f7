// Names of the debug views; see debug_view.h.
#include "shading/debug_view.h"

namespace prast {

namespace {
struct Named { const char* name; DebugView view; };
const Named kViews[] = {
    {"none", DebugView::None},         {"albedo", DebugView::Albedo},
    {"normal", DebugView::Normal},     {"roughness", DebugView::Roughness},
    {"metallic", DebugView::Metallic}, {"uv", DebugView::Uv},
    {"depth", DebugView::Depth},       {"overdraw", DebugView::Overdraw},
    {"tiles", DebugView::Tiles},       {"ndf", DebugView::Ndf},
    {"fresnel", DebugView::Fresnel},   {"geometry", DebugView::Geometry},
    {"diffuse", DebugView::Diffuse},   {"specular", DebugView::Specular},
    {"irradiance", DebugView::Irradiance},
};
} // namespace

bool parse_debug_view(const std::string& name, DebugView& out) {
    for (const Named& n : kViews)
        if (name == n.name) { out = n.view; return true; }
    return false;
}

bool debug_view_is_lit(DebugView v) {
    return v == DebugView::None || v == DebugView::Tiles || v == DebugView::Diffuse || v == DebugView::Specular;
}

bool debug_view_is_data(DebugView v) {
    switch (v) {
    case DebugView::Normal: case DebugView::Roughness: case DebugView::Metallic: case DebugView::Uv:
    case DebugView::Depth: case DebugView::Ndf: case DebugView::Fresnel: case DebugView::Geometry:
        return true;
    default:
        return false;
    }
}

const char* debug_view_names() {
    return "albedo, normal, roughness, metallic, uv, depth, overdraw, tiles, ndf, fresnel, "
           "geometry, diffuse, specular, irradiance";
}

} // namespace prast

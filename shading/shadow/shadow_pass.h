// The shadow maps of a frame (docs/shadows-and-transparency.md): for each
// light, the scene drawn by the pipeline into a depth target from the
// light's view, then turned into distances (shadow_map.h).
//
// - Directional lights: one orthographic map, square, `size` texels a side,
//   fitted to the visible part of the scene: the light-space rectangle where
//   the camera frustum's and the scene bounds' rectangles overlap (receivers
//   outside the frustum need no shadow; casters outside it still cast, since
//   the map's depth range covers the whole scene). Its side is the whole
//   scene's, shrunk in quarter-octave steps, and its centre moves in whole
//   texels: while the camera moves, the texel grid stays put in the world and
//   changes only when the fit jumps a step, so turntables do not shimmer.
// - Point lights (and spot lights, drawn as points): a cube of six 90-degree
//   perspective faces of size / 2 texels, each a little wider than 90 degrees
//   so that the PCF footprint of a point near a face's edge stays on the
//   face. Faces that see no part of the scene are not drawn.
// Casters: every mesh, both faces of every triangle (so open meshes cast);
// alpha MASK materials through their cutoff, BLEND materials as a MASK with
// cutoff 0.5 (a map holds one depth, not a fraction of light).
#pragma once

#include <memory>
#include <vector>

#include <glm/glm.hpp>

#include "raster/pipeline.h"
#include "scene/camera.h"
#include "scene/scene.h"
#include "shading/shadow/shadow_map.h"
#include "shading/surface.h"

namespace prast {

// The cutoff BLEND materials cast shadows with.
constexpr float kBlendShadowCutoff = 0.5f;

// A directional light's map geometry (every field of ShadowMap but the
// distances) fitted to a frame, and the matrix that draws it: clip =
// view_proj * (P - map.origin, 1). Exposed for the tests of the fit.
ShadowMap fit_directional_shadow(const glm::vec3& toward_light, const Bounds& scene, const Camera& camera,
                                 float aspect, int size, glm::mat4& view_proj, float& range);

class ShadowMaps {
public:
    // Draws the map of each light on the renderer and points the light at it
    // (valid until the next call). Lights are left without a map when the
    // scene is empty.
    void draw(const Scene& scene, const std::vector<BoundMaterial>& materials, Renderer& renderer,
              const ShadowSettings& settings, const Camera& camera, float aspect,
              std::vector<ShadingLight>& lights);

    // The last frame's maps, in light order.
    const std::vector<std::unique_ptr<ShadowMap>>& maps() const { return maps_; }

private:
    void draw_casters(const Scene& scene, const std::vector<BoundMaterial>& materials, Renderer& renderer,
                      const glm::mat4& view_proj, const glm::vec3& origin);

    void summarise(Renderer& renderer, ShadowMap& map, int face);

    Bounds bounds_;                   // of the scene's finite positions
    std::vector<Bounds> mesh_bounds_; // each mesh's: meshes outside a map's view are not drawn
    bool bounds_known_ = false;
    std::vector<std::unique_ptr<ShadowMap>> maps_;
    Framebuffer sun_target_, cube_target_;  // depth targets, reused
    Framebuffer* target_ = nullptr;         // the one being drawn
    std::vector<float> row_min_, row_max_, pairs_;  // scratch of summarise()
};

} // namespace prast

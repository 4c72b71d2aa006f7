// The order of alpha-BLEND draws (docs/shadows-and-transparency.md): after every opaque
// and MASK mesh, back to front by the distance from the eye to the centre of
// each mesh's bounds, a stable sort (equal distances keep file order). They
// are depth-tested against the opaque surfaces but write no depth, and blend
// per sample in linear radiance, before the resolve and the tone map.
#pragma once

#include <cstddef>
#include <vector>

#include <glm/glm.hpp>

#include "scene/scene.h"

namespace prast {

// The centre of a mesh's finite positions' bounds (its first position's
// worth of nothing: the origin when it has none).
glm::vec3 mesh_centre(const Mesh& mesh);

// Whether mesh `i` is drawn blended (its material's alphaMode is BLEND).
bool mesh_blended(const Scene& scene, std::size_t i);

// The scene's meshes in drawing order: the others in file order, then the
// blended ones back to front from `eye` (stable).
std::vector<std::size_t> draw_order(const Scene& scene, const glm::vec3& eye);

} // namespace prast

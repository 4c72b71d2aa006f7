// Procedural meshes for the built-in scene and tests, with normals, uvs (v = 0
// at the top of the image) and tangents laid out by the conventions.
#pragma once

#include <glm/glm.hpp>

#include "scene/scene.h"

namespace prast {

// UV sphere, counter-clockwise seen from outside; u runs east around +y, v from
// the north pole (v = 0) to the south pole.
Mesh make_uv_sphere(glm::vec3 center, float radius, int segments, int rings, int material);

// Square in the y = height plane facing +y, cells x cells quads, uv repeated
// `uv_repeat` times: u along +x, v along +z.
Mesh make_floor(glm::vec3 center, float half_size, int cells, float uv_repeat, int material);

} // namespace prast

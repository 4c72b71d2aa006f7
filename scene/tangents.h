// Per-vertex shading frames for meshes whose files do not carry them: smooth
// area-weighted normals, and tangents (xyz + handedness w) from UV derivatives
// in the project's internal UV convention (v = 0 is the top row of an image).
//
// The frame follows docs/conventions.md, "Normal mapping": T runs along +u and the
// bitangent B = cross(N, T) * w points "up the image", which is -v here, so the
// handedness is measured against B = -dP/dv (the assets README: "a renderer that
// builds tangents from raw glTF UVs must use B = -dP/dv_glTF").
#pragma once

#include "scene/scene.h"

namespace prast {

// Fills mesh.normals with per-vertex normals: the sum over the triangles around
// a vertex of their unnormalised face normals (cross product, whose length is
// twice the area), normalised. Triangles with non-finite corners are ignored; a
// vertex that touches only degenerate triangles gets +Z.
void compute_normals(Mesh& mesh);

// Fills mesh.tangents from mesh.positions, mesh.normals and mesh.uvs (all the
// same size; does nothing when uvs is empty). Per triangle, T = dP/du and
// B = -dP/dv are accumulated per corner weighted by the corner angle (as
// MikkTSpace does), then T is orthogonalised against N (Gram-Schmidt) and
// w = sign(dot(cross(N, T), B)). Degenerate UVs: any unit vector perpendicular
// to N, w = 1.
void compute_tangents(Mesh& mesh);
// The same from another UV set of the mesh (e.g. mesh.uvs1, when the normal
// map reads TEXCOORD_1); `uvs` must outlive the call and not be mesh.tangents.
void compute_tangents(Mesh& mesh, const std::vector<glm::vec2>& uvs);

// Any unit vector perpendicular to the unit vector n.
glm::vec3 any_perpendicular(const glm::vec3& n);

} // namespace prast

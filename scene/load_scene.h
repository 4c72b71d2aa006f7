// Scene loading: Wavefront OBJ + MTL (tinyobjloader) and glTF 2.0 (.gltf with
// external or data-URI buffers, and .glb; tinygltf) into the world-space Scene
// of scene.h. Images are not decoded here: the loaders fill ImageSource with a
// path or the encoded bytes, and scene/image.h decodes them.
//
// Errors: a file that cannot be used throws LoadError with one line
// "FILE: problem". A problem the loader can work around (a missing texture, an
// optional extension it does not implement, triangles with NaN corners) is one
// line "FILE: ..." in Scene::warnings, and the scene still loads; at most
// kWarningsPerKind of a kind, then a count (scene/messages.h). No input may
// crash or hang a loader: every index, offset and size in the file is checked,
// every count against a budget before anything is allocated, and every other
// file a model names is read through scene/file_access.h (confined to the
// model's folder). Names from the file are escaped in every message.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "scene/scene.h"

namespace prast {

struct LoadOptions {
    // Let references (mtllib, map_*, uris) leave the model's folder; see
    // scene/file_access.h for the rule this lifts (render --allow-outside-paths).
    bool allow_outside_paths = false;
};

// Dispatches on the extension, case-insensitively: .obj, .gltf or .glb.
Scene load_scene(const std::string& path, const LoadOptions& options = {});

// OBJ + MTL. One Mesh per (object/group, material); UVs become v = 1 - v_obj.
Scene load_obj(const std::string& path, const LoadOptions& options = {});

// glTF 2.0, text (.gltf) or binary (.glb): the default scene's node hierarchy
// is flattened into world-space meshes; KHR_lights_punctual gives the lights.
Scene load_gltf(const std::string& path, const LoadOptions& options = {});

namespace scene_detail {

// Limits that keep a hostile file from exhausting memory; each is far beyond
// the assets the project renders (the largest has 70 k triangles) and the
// 10-million-triangle model of the tests (31 million elements).
constexpr std::size_t kMaxFileBytes = std::size_t(1) << 31;      // 2 GiB
constexpr std::size_t kMaxSceneElements = std::size_t(1) << 27;  // vertices + indices
// glTF accessor elements without a bufferView are zeros made up by the
// loader, not read from the file: a 400-byte file could ask for billions.
constexpr std::size_t kMaxZeroFilledElements = std::size_t(1) << 22;

// The whole regular file (file_access.h's read_regular_file), or LoadError
// "PATH: cannot open file" / "is a directory" / "not a regular file" /
// "empty file" / "file too large".
std::vector<unsigned char> read_file(const std::string& path);

// Lower-case extension with the dot ("" when none).
std::string extension_lower(const std::string& path);

// Shared last step of both loaders: per mesh, drops primitives (triangles,
// lines or points, by Mesh::topology) with an index out of range or a
// non-finite corner (one warning with the count), removes unused vertices,
// repairs or computes normals (lines and points without normals keep none)
// and tangents (on the normal map's UV set), sets NaN/Inf UVs to 0 and
// NaN/Inf vertex colours to white and clamps colours to [0, 1], drops empty
// meshes, makes sure materials is not empty and every mesh's material is
// valid. Throws LoadError "PATH: no triangles" when nothing is left.
void finish_scene(Scene& scene, const std::string& path);

// The UV set a mesh's tangents follow: its normal map's (TEXCOORD_1 when the
// map names it and the mesh has it), else TEXCOORD_0.
const std::vector<glm::vec2>& tangent_uvs(const Mesh& m, const Scene& scene);
// File tangents orthogonalised against the normals and normalised, w a sign;
// false when the sizes differ or any tangent is unusable.
bool repair_tangents(Mesh& m);

} // namespace scene_detail

} // namespace prast

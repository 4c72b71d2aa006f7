// The parts of a glTF model that make meshes move or place a camera: the
// node tree, skins, morph targets, animations and cameras, read from the
// tinygltf model into the Scene's SceneSource (scene/animation.h), checked
// as the loader checks everything (indices and counts in range, budgets
// before allocation, values finite): a defect is a warning that drops the
// part at fault, or a LoadError for a corrupt accessor. Internal to the
// glTF loader (scene/load_gltf.cpp).
#pragma once

#include <cstddef>
#include <functional>
#include <string>

#include "scene/scene.h"

namespace tinygltf {
class Model;
}

namespace prast {

struct GltfGraphContext {
    std::string shown;                               // the model's path, printable, for errors
    std::size_t& elements;                           // accessor elements read so far (the loader's budget)
    std::size_t& zero_filled;                        // of which without a bufferView
    std::function<void(const std::string&)> warn;    // one line, without the file name
};

// After the loader has made the meshes (each with source_node and
// source_primitive) and before finish_scene: fills scene.source (only when
// the model has skins, morph targets, animations or cameras),
// scene.cameras, scene.animation_names and source_vertex of every mesh
// that can move. Throws LoadError for a corrupt accessor.
void read_gltf_graph(const tinygltf::Model& model, Scene& scene, GltfGraphContext& context);

} // namespace prast

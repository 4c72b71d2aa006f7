// Posing a glTF scene: node transforms from animation channels, morph
// targets and skins, applied to the world-space meshes of scene.h; and the
// file's cameras at a time.
//
// The loaders flatten every node into world-space meshes. A file with
// skins, morph targets, animations or cameras also carries a SceneSource
// (filled by scene/gltf_graph.h): the node tree, the local-space vertices
// of every primitive that can move, the skins and the animations, already
// checked (indices in range, values finite, key times increasing), so that
// posing cannot fail. Rules (glTF 2.0, "Animations", "Skins", "Morph
// Targets", "Cameras", and Appendix C "Interpolation"):
//  - before the first key time a channel holds its first value, after the
//    last its last value;
//  - LINEAR: lerp, rotations by slerp along the shorter arc; STEP: the
//    value of the key at or before t; CUBICSPLINE: the cubic Hermite spline
//    of value and in/out tangents, the tangents scaled by the key interval;
//    rotations are normalised afterwards;
//  - morphed attribute = base + sum of weight_i * target_i (POSITION,
//    NORMAL, TANGENT xyz);
//  - skinned position = sum over influences of weight * world(joint) *
//    inverseBind(joint) * position, every JOINTS_n/WEIGHTS_n set; the
//    skinned mesh node's own transform is not applied; normals with the
//    inverse transpose of that matrix, tangents with it, both renormalised.
// Everything is computed serially in double, in a fixed order: the same
// bytes on any thread count.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>

#include "scene/camera.h"
#include "scene/scene.h"

namespace prast {

struct SourceNode {
    int parent = -1;
    bool has_matrix = false;
    glm::dmat4 matrix{1.0};                      // when has_matrix (never animated)
    glm::dvec3 translation{0.0}, scale{1.0};
    glm::dquat rotation{1.0, 0.0, 0.0, 0.0};     // unit
    int mesh = -1, skin = -1, camera = -1;
    std::vector<double> weights;                 // the node's morph weights, or its mesh's
    bool animated = false;                       // a channel targets its TRS
};

struct SourceSkin {
    std::vector<int> joints;                     // node indices
    std::vector<glm::dmat4> inverse_bind;        // one per joint
};

// The local-space vertices of a primitive that moves (morphed or skinned or
// under an animated node), as the file has them.
struct SourcePrimitive {
    bool used = false;                           // read (some Mesh instances it)
    std::vector<glm::vec3> positions, normals;   // normals empty when the file has none
    std::vector<glm::vec4> tangents;             // empty when the file has none
    struct Target {
        std::vector<glm::vec3> position, normal, tangent;  // each empty or one per vertex
    };
    std::vector<Target> targets;
    int influence_sets = 0;                      // JOINTS_n/WEIGHTS_n pairs
    std::vector<std::uint32_t> joints;           // 4 per set per vertex, checked < the skin's joints
    std::vector<float> weights;                  // likewise
};

struct SourceMesh {
    std::vector<SourcePrimitive> primitives;
    std::vector<double> weights;                 // default morph weights
    std::size_t target_count = 0;                // the most targets of any primitive
};

enum class AnimationPath { Translation, Rotation, Scale, Weights };
enum class Interpolation { Linear, Step, CubicSpline };

struct AnimationSampler {
    Interpolation interpolation = Interpolation::Linear;
    std::vector<float> times;                    // strictly increasing, finite, >= 0
    std::vector<float> values;                   // keys * (3 for CUBICSPLINE) * width
    int width = 0;                               // floats per value (3, 4 or the target count)
};

struct AnimationChannel {
    int node = -1;
    AnimationPath path = AnimationPath::Translation;
    int sampler = -1;
};

struct Animation {
    std::string name;
    std::vector<AnimationSampler> samplers;
    std::vector<AnimationChannel> channels;
    double start = 0.0, end = 0.0;               // first and last key time of any channel
};

struct SceneSource {
    std::vector<SourceNode> nodes;
    std::vector<SourceSkin> skins;
    std::vector<SourceMesh> meshes;
    std::vector<Animation> animations;
    std::vector<int> node_order;                 // parents before children
};

// pose_scene's `animation`: every animation, or none (the rest pose).
constexpr int kAllAnimations = -1;
constexpr int kNoAnimation = -2;

// One channel's sampler at time t: `width` floats into out (rotations
// normalised when `rotation`).
void sample_animation(const AnimationSampler& s, double t, bool rotation, double* out);

// The node transforms at time t of `animation` (an index, kAllAnimations:
// each in file order, a later one winning, or kNoAnimation), as world
// matrices, and the morph weights of each node.
struct NodePose {
    std::vector<glm::dmat4> world;
    std::vector<std::vector<double>> weights;
};
NodePose pose_nodes(const SceneSource& source, double t, int animation);

// Recomputes the moving meshes of `scene` (positions, normals, tangents) at
// time t of `animation`; the meshes that never move keep their bytes. A
// scene without a source is left as it is. Time 0 of kNoAnimation is the
// rest pose the loader gives (skins and the default morph weights applied).
void pose_scene(Scene& scene, double t, int animation);

// File camera `index` (into scene.cameras) at time t of `animation`: its
// node's world transform (eye at its origin, looking down its -Z, up its +Y)
// and the camera's projection, for an image of aspect `aspect` (the image's
// aspect wins over the file's aspectRatio, so nothing is stretched).
Camera scene_camera(const Scene& scene, int index, double t, float aspect, int animation = kAllAnimations);

// The animation or camera a command line names: an index, or a name.
// -1 when there is none of that name or number.
int find_named(const std::vector<std::string>& names, const std::string& wanted);

} // namespace prast

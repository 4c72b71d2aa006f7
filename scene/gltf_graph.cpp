// Reading nodes, skins, morph targets, animations and cameras; see gltf_graph.h.
#include "scene/gltf_graph.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <memory>
#include <numeric>

#define TINYGLTF_NO_STB_IMAGE
#define TINYGLTF_NO_STB_IMAGE_WRITE
#define TINYGLTF_NO_INCLUDE_STB_IMAGE
#define TINYGLTF_NO_INCLUDE_STB_IMAGE_WRITE
#include <tiny_gltf.h>

#include "scene/animation.h"
#include "scene/gltf_components.h"
#include "scene/load_scene.h"
#include "scene/messages.h"

namespace prast {

namespace {

using gltf_components_detail::component;
using gltf_components_detail::component_size;

constexpr std::size_t kMaxCount = 0x7fffffff;

int components_of(int type) {
    switch (type) {
    case TINYGLTF_TYPE_SCALAR: return 1;
    case TINYGLTF_TYPE_VEC2: return 2;
    case TINYGLTF_TYPE_VEC3: return 3;
    case TINYGLTF_TYPE_VEC4: return 4;
    case TINYGLTF_TYPE_MAT4: return 16;
    default: return 0;
    }
}

bool all_finite(const std::vector<float>& v) {
    return std::all_of(v.begin(), v.end(), [](float x) { return std::isfinite(x); });
}

class GraphReader {
public:
    GraphReader(const tinygltf::Model& model, Scene& scene, GltfGraphContext& ctx)
        : model_(model), scene_(scene), ctx_(ctx) {}

    void read() {
        scene_.extensions_used = model_.extensionsUsed;
        scene_.extensions_required = model_.extensionsRequired;
        bool has_targets = false;
        for (const tinygltf::Mesh& m : model_.meshes)
            for (const tinygltf::Primitive& p : m.primitives) has_targets |= !p.targets.empty();
        if (model_.skins.empty() && model_.animations.empty() && model_.cameras.empty() && !has_targets) return;

        auto source = std::make_shared<SceneSource>();
        src_ = source.get();
        read_nodes();
        read_meshes();
        read_skins();
        read_animations();
        read_cameras();
        mark_moving_meshes();
        scene_.source = std::move(source);
    }

private:
    [[noreturn]] void fail(const std::string& why) const { throw LoadError(ctx_.shown + ": " + printable(why)); }
    void warn(const std::string& what) { ctx_.warn(what); }

    // ---- Accessors (every offset, stride and count checked before reading)

    const unsigned char* window(int view, std::size_t offset, std::size_t count, std::size_t elem, bool strided,
                                std::size_t& stride, const std::string& what) const {
        if (view < 0 || std::size_t(view) >= model_.bufferViews.size())
            fail(what + ": bufferView " + std::to_string(view) + " out of range (" +
                 std::to_string(model_.bufferViews.size()) + " bufferViews)");
        const tinygltf::BufferView& bv = model_.bufferViews[std::size_t(view)];
        if (bv.buffer < 0 || std::size_t(bv.buffer) >= model_.buffers.size())
            fail(what + ": bufferView " + std::to_string(view) + ": buffer " + std::to_string(bv.buffer) +
                 " out of range");
        const std::vector<unsigned char>& data = model_.buffers[std::size_t(bv.buffer)].data;
        if (bv.byteOffset > data.size() || bv.byteLength > data.size() - bv.byteOffset)
            fail(what + ": bufferView " + std::to_string(view) + " exceeds its buffer");
        stride = strided && bv.byteStride != 0 ? bv.byteStride : elem;
        if (stride < elem) fail(what + ": byteStride smaller than an element");
        if (count == 0) return nullptr;
        if (offset > bv.byteLength || elem > bv.byteLength - offset ||
            count - 1 > (bv.byteLength - offset - elem) / stride)
            fail(what + ": accessor exceeds bufferView " + std::to_string(view));
        return data.data() + bv.byteOffset + offset;
    }

    // Accessor `index` of glTF type `type` as count * components doubles
    // narrowed to T; `normalized` integers mapped to [0, 1] / [-1, 1].
    template <class T>
    std::vector<T> read_accessor(int index, int type, const std::string& context, bool integers = false) {
        const std::string what = context + ": accessor " + std::to_string(index);
        if (index < 0 || std::size_t(index) >= model_.accessors.size())
            fail(what + " out of range (" + std::to_string(model_.accessors.size()) + " accessors)");
        const tinygltf::Accessor& a = model_.accessors[std::size_t(index)];
        const int ncomp = components_of(a.type);
        const std::size_t csize = component_size(a.componentType);
        if (a.type != type || ncomp == 0) fail(what + ": wrong type");
        if (csize == 0) fail(what + ": unsupported componentType " + std::to_string(a.componentType));
        if (integers && (a.normalized || (a.componentType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE &&
                                          a.componentType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT &&
                                          a.componentType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT)))
            fail(what + ": must be unsigned integers");
        if (a.count > kMaxCount) fail(what + ": absurd count " + std::to_string(a.count));
        if (a.bufferView < 0) {
            ctx_.zero_filled += a.count;
            if (ctx_.zero_filled > scene_detail::kMaxZeroFilledElements)
                fail(what + ": " + std::to_string(a.count) + " elements without a bufferView bring the zero-filled "
                     "elements to " + std::to_string(ctx_.zero_filled) + ", more than the limit of " +
                     std::to_string(scene_detail::kMaxZeroFilledElements) + " (2^22)");
        }
        ctx_.elements += a.count;
        if (ctx_.elements > scene_detail::kMaxSceneElements)
            fail(what + ": " + std::to_string(a.count) + " elements bring the scene to " +
                 std::to_string(ctx_.elements) + " accessor elements, more than the limit of " +
                 std::to_string(scene_detail::kMaxSceneElements) + " (2^27)");
        const std::size_t elem = csize * std::size_t(ncomp);
        const bool normalized = a.normalized && !integers;
        std::vector<T> out;
        if (a.bufferView >= 0) {
            std::size_t stride = 0;
            const unsigned char* p = window(a.bufferView, a.byteOffset, a.count, elem, true, stride, what);
            out.resize(a.count * std::size_t(ncomp));
            for (std::size_t i = 0; i < a.count; ++i)
                for (int c = 0; c < ncomp; ++c)
                    out[i * std::size_t(ncomp) + std::size_t(c)] =
                        T(component(p + i * stride + std::size_t(c) * csize, a.componentType, normalized));
        } else {
            out.assign(a.count * std::size_t(ncomp), T(0));
        }
        if (a.sparse.isSparse) {
            const auto& s = a.sparse;
            if (s.count < 0 || std::size_t(s.count) > a.count) fail(what + ": bad sparse count");
            const std::size_t isize = component_size(s.indices.componentType);
            if (s.indices.componentType == TINYGLTF_COMPONENT_TYPE_BYTE ||
                s.indices.componentType == TINYGLTF_COMPONENT_TYPE_SHORT ||
                s.indices.componentType == TINYGLTF_COMPONENT_TYPE_FLOAT || isize == 0)
                fail(what + ": bad sparse index type");
            if (s.indices.byteOffset < 0 || s.values.byteOffset < 0) fail(what + ": bad sparse offset");
            std::size_t istride = 0, vstride = 0;
            const std::size_t n = std::size_t(s.count);
            const unsigned char* ip = window(s.indices.bufferView, std::size_t(s.indices.byteOffset), n, isize, false,
                                             istride, what + " sparse indices");
            const unsigned char* vp = window(s.values.bufferView, std::size_t(s.values.byteOffset), n, elem, false,
                                             vstride, what + " sparse values");
            for (std::size_t j = 0; j < n; ++j) {
                const double target = component(ip + j * istride, s.indices.componentType, false);
                if (target >= double(a.count)) fail(what + ": sparse index out of range");
                for (int c = 0; c < ncomp; ++c)
                    out[std::size_t(target) * std::size_t(ncomp) + std::size_t(c)] =
                        T(component(vp + j * vstride + std::size_t(c) * csize, a.componentType, normalized));
            }
        }
        return out;
    }

    std::vector<glm::vec3> read_vec3(int index, const std::string& what) {
        const std::vector<float> v = read_accessor<float>(index, TINYGLTF_TYPE_VEC3, what);
        std::vector<glm::vec3> out(v.size() / 3);
        for (std::size_t i = 0; i < out.size(); ++i) out[i] = glm::vec3(v[3 * i], v[3 * i + 1], v[3 * i + 2]);
        return out;
    }

    // ---- Nodes (the loader has checked that they form trees)

    void read_nodes() {
        const std::size_t n = model_.nodes.size();
        src_->nodes.resize(n);
        for (std::size_t i = 0; i < n; ++i) {
            const tinygltf::Node& g = model_.nodes[i];
            SourceNode& node = src_->nodes[i];
            for (int c : g.children)
                if (c >= 0 && std::size_t(c) < n) src_->nodes[std::size_t(c)].parent = int(i);
            // The loader's rules for a node's transform, so that the rest
            // pose gives its bytes.
            if (g.matrix.size() == 16) {
                node.has_matrix = true;
                for (int c = 0; c < 4; ++c)
                    for (int r = 0; r < 4; ++r) node.matrix[c][r] = g.matrix[std::size_t(c * 4 + r)];
            }
            if (g.translation.size() == 3) node.translation = glm::dvec3(g.translation[0], g.translation[1], g.translation[2]);
            if (g.scale.size() == 3) node.scale = glm::dvec3(g.scale[0], g.scale[1], g.scale[2]);
            if (g.rotation.size() == 4) {
                const glm::dquat q(g.rotation[3], g.rotation[0], g.rotation[1], g.rotation[2]);
                const double len = glm::length(q);
                if (len > 0.0 && std::isfinite(len)) node.rotation = q / len;
            }
            node.mesh = g.mesh >= 0 && std::size_t(g.mesh) < model_.meshes.size() ? g.mesh : -1;
            node.skin = g.skin;
            node.camera = g.camera;
        }
        // Parents before children: from each root down (the graph is a forest).
        std::vector<int> stack;
        for (std::size_t i = n; i-- > 0;)
            if (src_->nodes[i].parent < 0) stack.push_back(int(i));
        while (!stack.empty()) {
            const int i = stack.back();
            stack.pop_back();
            src_->node_order.push_back(i);
            const auto& children = model_.nodes[std::size_t(i)].children;
            for (auto c = children.rbegin(); c != children.rend(); ++c) stack.push_back(*c);
        }
        if (src_->node_order.size() != n) fail("the node graph is not a forest");
    }

    std::vector<double> weights_of(const std::vector<double>& given, std::size_t targets, const std::string& what) {
        std::vector<double> w(targets, 0.0);
        if (given.empty()) return w;
        if (given.size() != targets)
            warn(what + ": " + std::to_string(given.size()) + " morph weights for " + std::to_string(targets) +
                 " targets, the missing ones 0");
        for (std::size_t i = 0; i < std::min(targets, given.size()); ++i) {
            if (!std::isfinite(given[i])) {
                warn(what + ": non-finite morph weight, 0 used");
                continue;
            }
            w[i] = given[i];
        }
        return w;
    }

    void read_meshes() {
        src_->meshes.resize(model_.meshes.size());
        for (std::size_t m = 0; m < model_.meshes.size(); ++m) {
            SourceMesh& sm = src_->meshes[m];
            const tinygltf::Mesh& gm = model_.meshes[m];
            sm.primitives.resize(gm.primitives.size());
            for (const tinygltf::Primitive& p : gm.primitives) sm.target_count = std::max(sm.target_count, p.targets.size());
            sm.weights = weights_of(gm.weights, sm.target_count, "mesh " + std::to_string(m));
        }
        for (std::size_t i = 0; i < src_->nodes.size(); ++i) {
            SourceNode& node = src_->nodes[i];
            if (node.mesh < 0) continue;
            const SourceMesh& sm = src_->meshes[std::size_t(node.mesh)];
            node.weights = model_.nodes[i].weights.empty()
                               ? sm.weights
                               : weights_of(model_.nodes[i].weights, sm.target_count, "node " + std::to_string(i));
        }
    }

    void read_skins() {
        const std::size_t n = model_.nodes.size();
        for (std::size_t s = 0; s < model_.skins.size(); ++s) {
            const tinygltf::Skin& g = model_.skins[s];
            const std::string what = "skin " + std::to_string(s);
            SourceSkin skin;
            bool ok = !g.joints.empty();
            if (!ok) warn(what + ": no joints, ignored");
            for (int j : g.joints) {
                if (j < 0 || std::size_t(j) >= n) {
                    warn(what + ": joint node " + std::to_string(j) + " out of range (" + std::to_string(n) +
                         " nodes), skin ignored");
                    ok = false;
                    break;
                }
            }
            if (ok) {
                skin.joints = g.joints;
                skin.inverse_bind.assign(g.joints.size(), glm::dmat4(1.0));
                if (g.inverseBindMatrices >= 0) {
                    const std::vector<float> m =
                        read_accessor<float>(g.inverseBindMatrices, TINYGLTF_TYPE_MAT4, what + " inverseBindMatrices");
                    if (m.size() / 16 < g.joints.size()) {
                        warn(what + ": " + std::to_string(m.size() / 16) + " inverseBindMatrices for " +
                             std::to_string(g.joints.size()) + " joints, skin ignored");
                        ok = false;
                    } else if (!all_finite(m)) {
                        warn(what + ": non-finite inverseBindMatrices, skin ignored");
                        ok = false;
                    } else {
                        for (std::size_t j = 0; j < g.joints.size(); ++j)
                            for (int c = 0; c < 4; ++c)
                                for (int r = 0; r < 4; ++r) skin.inverse_bind[j][c][r] = m[16 * j + std::size_t(c * 4 + r)];
                    }
                }
            }
            if (!ok) skin = SourceSkin();
            src_->skins.push_back(std::move(skin));
        }
        for (std::size_t i = 0; i < n; ++i) {
            SourceNode& node = src_->nodes[i];
            if (node.skin < 0) continue;
            if (std::size_t(node.skin) >= src_->skins.size()) {
                warn("node " + std::to_string(i) + ": skin " + std::to_string(node.skin) + " out of range (" +
                     std::to_string(src_->skins.size()) + " skins), drawn unskinned");
                node.skin = -1;
            } else if (src_->skins[std::size_t(node.skin)].joints.empty()) {
                node.skin = -1;
            }
        }
    }

    // ---- Animations

    void read_animations() {
        for (std::size_t a = 0; a < model_.animations.size(); ++a) {
            const tinygltf::Animation& g = model_.animations[a];
            Animation anim;
            anim.name = g.name.empty() ? "animation " + std::to_string(a) : g.name;
            const std::string what = "animation " + std::to_string(a);
            anim.samplers.resize(g.samplers.size());
            std::vector<char> sampler_read(g.samplers.size(), 0), sampler_ok(g.samplers.size(), 0);
            bool timed = false;
            for (std::size_t c = 0; c < g.channels.size(); ++c) {
                const tinygltf::AnimationChannel& gc = g.channels[c];
                const std::string cw = what + " channel " + std::to_string(c);
                if (gc.target_node < 0) continue;  // another extension's target
                if (std::size_t(gc.target_node) >= src_->nodes.size()) {
                    warn(cw + ": node " + std::to_string(gc.target_node) + " out of range, ignored");
                    continue;
                }
                AnimationChannel ch;
                ch.node = gc.target_node;
                SourceNode& node = src_->nodes[std::size_t(ch.node)];
                int width = 0, type = 0;
                if (gc.target_path == "translation") ch.path = AnimationPath::Translation, width = 3, type = TINYGLTF_TYPE_VEC3;
                else if (gc.target_path == "rotation") ch.path = AnimationPath::Rotation, width = 4, type = TINYGLTF_TYPE_VEC4;
                else if (gc.target_path == "scale") ch.path = AnimationPath::Scale, width = 3, type = TINYGLTF_TYPE_VEC3;
                else if (gc.target_path == "weights") ch.path = AnimationPath::Weights, type = TINYGLTF_TYPE_SCALAR;
                else {
                    warn(cw + ": path '" + cut(gc.target_path) + "' not supported, ignored");
                    continue;
                }
                if (ch.path == AnimationPath::Weights) {
                    width = node.mesh >= 0 ? int(src_->meshes[std::size_t(node.mesh)].target_count) : 0;
                    if (width == 0) {
                        warn(cw + ": weights of a node without morph targets, ignored");
                        continue;
                    }
                } else if (node.has_matrix) {
                    warn(cw + ": node " + std::to_string(ch.node) + " has a matrix, which cannot be animated; ignored");
                    continue;
                }
                if (gc.sampler < 0 || std::size_t(gc.sampler) >= g.samplers.size()) {
                    warn(cw + ": sampler " + std::to_string(gc.sampler) + " out of range, ignored");
                    continue;
                }
                const std::size_t si = std::size_t(gc.sampler);
                if (!sampler_read[si]) {
                    sampler_read[si] = 1;
                    sampler_ok[si] = read_sampler(g.samplers[si], type, width, what + " sampler " + std::to_string(si),
                                                  anim.samplers[si]);
                } else if (sampler_ok[si] && (anim.samplers[si].width != width)) {
                    warn(cw + ": sampler " + std::to_string(si) + " serves channels of different kinds, ignored");
                    continue;
                }
                if (!sampler_ok[si]) continue;
                ch.sampler = int(si);
                const AnimationSampler& s = anim.samplers[si];
                anim.start = timed ? std::min(anim.start, double(s.times.front())) : double(s.times.front());
                anim.end = timed ? std::max(anim.end, double(s.times.back())) : double(s.times.back());
                timed = true;
                if (ch.path != AnimationPath::Weights) node.animated = true;
                anim.channels.push_back(ch);
            }
            scene_.animation_names.push_back(anim.name);
            src_->animations.push_back(std::move(anim));
        }
    }

    bool read_sampler(const tinygltf::AnimationSampler& g, int type, int width, const std::string& what,
                      AnimationSampler& out) {
        if (g.interpolation == "LINEAR") out.interpolation = Interpolation::Linear;
        else if (g.interpolation == "STEP") out.interpolation = Interpolation::Step;
        else if (g.interpolation == "CUBICSPLINE") out.interpolation = Interpolation::CubicSpline;
        else {
            warn(what + ": interpolation '" + cut(g.interpolation) + "' unknown, its channels ignored");
            return false;
        }
        out.times = read_accessor<float>(g.input, TINYGLTF_TYPE_SCALAR, what + " input");
        if (out.times.empty()) {
            warn(what + ": no key times, its channels ignored");
            return false;
        }
        // glTF 2.0, "Animations": times[0] >= 0 and strictly increasing.
        for (std::size_t i = 0; i < out.times.size(); ++i) {
            if (!std::isfinite(out.times[i]) || out.times[i] < 0.0f || (i > 0 && !(out.times[i] > out.times[i - 1]))) {
                warn(what + ": key times must be finite, not negative and strictly increasing (key " +
                     std::to_string(i) + "), its channels ignored");
                return false;
            }
        }
        const std::size_t per_key = (out.interpolation == Interpolation::CubicSpline ? 3 : 1) * std::size_t(width);
        const int ncomp = type == TINYGLTF_TYPE_SCALAR ? 1 : width;
        // The count is checked before the values are read (and allocated).
        if (g.output >= 0 && std::size_t(g.output) < model_.accessors.size()) {
            const tinygltf::Accessor& a = model_.accessors[std::size_t(g.output)];
            if (a.type == type && a.count * std::size_t(ncomp) != out.times.size() * per_key) {
                warn(what + ": " + std::to_string(a.count) + " output values for " + std::to_string(out.times.size()) +
                     " key times, its channels ignored");
                return false;
            }
        }
        out.values = read_accessor<float>(g.output, type, what + " output");
        if (!all_finite(out.values)) {
            warn(what + ": non-finite output values, its channels ignored");
            return false;
        }
        out.width = width;
        return true;
    }

    // ---- Cameras

    void read_cameras() {
        // In node order, those of the drawn scene's trees first seen.
        std::vector<char> drawn(src_->nodes.size(), 1);
        if (!model_.scenes.empty()) {
            int s = model_.defaultScene;
            if (s < 0 || std::size_t(s) >= model_.scenes.size()) s = 0;
            std::fill(drawn.begin(), drawn.end(), 0);
            std::vector<int> stack(model_.scenes[std::size_t(s)].nodes);
            while (!stack.empty()) {
                const int i = stack.back();
                stack.pop_back();
                if (i < 0 || std::size_t(i) >= drawn.size() || drawn[std::size_t(i)]) continue;
                drawn[std::size_t(i)] = 1;
                for (int c : model_.nodes[std::size_t(i)].children) stack.push_back(c);
            }
        }
        for (std::size_t i = 0; i < src_->nodes.size(); ++i) {
            const int ci = src_->nodes[i].camera;
            if (ci < 0 || !drawn[i]) continue;
            const std::string what = "node " + std::to_string(i);
            if (std::size_t(ci) >= model_.cameras.size()) {
                warn(what + ": camera " + std::to_string(ci) + " out of range, ignored");
                continue;
            }
            const tinygltf::Camera& g = model_.cameras[std::size_t(ci)];
            SceneCamera cam;
            cam.node = int(i);
            cam.name = !g.name.empty() ? g.name : !model_.nodes[i].name.empty() ? model_.nodes[i].name
                                                                               : "camera " + std::to_string(ci);
            const std::string cw = "camera " + std::to_string(ci);
            auto positive = [](double v) { return std::isfinite(v) && v > 0.0; };
            if (g.type == "perspective") {
                const tinygltf::PerspectiveCamera& p = g.perspective;
                if (!positive(p.yfov) || !(p.yfov < 3.14159) || !positive(p.znear) ||
                    !(p.zfar == 0.0 || (std::isfinite(p.zfar) && p.zfar > p.znear)) ||
                    !(p.aspectRatio == 0.0 || positive(p.aspectRatio))) {
                    warn(cw + ": bad perspective values (yfov in (0, pi), 0 < znear < zfar), ignored");
                    continue;
                }
                cam.yfov = p.yfov;
                cam.aspect_ratio = p.aspectRatio;
                cam.znear = p.znear;
                cam.zfar = p.zfar;
            } else if (g.type == "orthographic") {
                const tinygltf::OrthographicCamera& o = g.orthographic;
                if (!std::isfinite(o.xmag) || o.xmag == 0.0 || !positive(std::fabs(o.ymag)) || !std::isfinite(o.znear) ||
                    o.znear < 0.0 || !std::isfinite(o.zfar) || !(o.zfar > o.znear)) {
                    warn(cw + ": bad orthographic values (xmag, ymag not 0, 0 <= znear < zfar), ignored");
                    continue;
                }
                cam.orthographic = true;
                cam.xmag = std::fabs(o.xmag);
                cam.ymag = std::fabs(o.ymag);
                cam.znear = o.znear;
                cam.zfar = o.zfar;
            } else {
                warn(cw + ": type '" + cut(g.type) + "' unknown, ignored");
                continue;
            }
            scene_.cameras.push_back(cam);
        }
    }

    // ---- The meshes that move, and their local-space vertices

    void mark_moving_meshes() {
        const std::size_t n = src_->nodes.size();
        // A node moves when it or an ancestor is animated (parents come first).
        std::vector<char> moving(n, 0);
        for (int i : src_->node_order) {
            const SourceNode& node = src_->nodes[std::size_t(i)];
            moving[std::size_t(i)] = node.animated || (node.parent >= 0 && moving[std::size_t(node.parent)]);
        }
        for (Mesh& mesh : scene_.meshes) {
            if (mesh.source_node < 0 || std::size_t(mesh.source_node) >= n) continue;
            const SourceNode& node = src_->nodes[std::size_t(mesh.source_node)];
            if (node.mesh < 0) continue;
            const tinygltf::Mesh& gm = model_.meshes[std::size_t(node.mesh)];
            if (mesh.source_primitive < 0 || std::size_t(mesh.source_primitive) >= gm.primitives.size()) continue;
            const tinygltf::Primitive& gp = gm.primitives[std::size_t(mesh.source_primitive)];
            const bool skinned = node.skin >= 0 && gp.attributes.count("JOINTS_0") && gp.attributes.count("WEIGHTS_0");
            if (!moving[std::size_t(mesh.source_node)] && !skinned && gp.targets.empty()) continue;
            SourcePrimitive& sp = src_->meshes[std::size_t(node.mesh)].primitives[std::size_t(mesh.source_primitive)];
            const std::string what = "mesh " + std::to_string(node.mesh) + " primitive " +
                                     std::to_string(mesh.source_primitive);
            if (!sp.used) read_primitive(gp, what, sp, node.mesh);
            if (sp.positions.size() != mesh.positions.size()) continue;  // not the loader's vertices
            mesh.source_vertex.resize(mesh.positions.size());
            std::iota(mesh.source_vertex.begin(), mesh.source_vertex.end(), 0u);
        }
    }

    void read_primitive(const tinygltf::Primitive& gp, const std::string& what, SourcePrimitive& sp, int mesh) {
        sp.used = true;
        const auto attribute = [&](const std::string& name) {
            const auto it = gp.attributes.find(name);
            return it == gp.attributes.end() ? -1 : it->second;
        };
        sp.positions = read_vec3(attribute("POSITION"), what + " POSITION");
        const std::size_t n = sp.positions.size();
        if (attribute("NORMAL") >= 0) {
            sp.normals = read_vec3(attribute("NORMAL"), what + " NORMAL");
            if (sp.normals.size() != n) sp.normals.clear();
        }
        if (attribute("TANGENT") >= 0) {
            const std::vector<float> t = read_accessor<float>(attribute("TANGENT"), TINYGLTF_TYPE_VEC4, what + " TANGENT");
            if (t.size() == 4 * n) {
                sp.tangents.resize(n);
                for (std::size_t i = 0; i < n; ++i) sp.tangents[i] = glm::vec4(t[4 * i], t[4 * i + 1], t[4 * i + 2], t[4 * i + 3]);
            }
        }
        for (std::size_t t = 0; t < gp.targets.size(); ++t) {
            SourcePrimitive::Target target;
            const std::string tw = what + " target " + std::to_string(t);
            for (const auto& [name, index] : gp.targets[t]) {
                std::vector<glm::vec3>* dst = name == "POSITION" ? &target.position
                                              : name == "NORMAL" ? &target.normal
                                              : name == "TANGENT" ? &target.tangent : nullptr;
                if (!dst) continue;  // TEXCOORD_n, COLOR_n deltas are not applied
                *dst = read_vec3(index, tw + " " + name);
                if (dst->size() != n) {
                    warn(tw + ": " + name + " count differs from POSITION, ignored");
                    dst->clear();
                }
                for (const glm::vec3& d : *dst) {
                    if (!std::isfinite(d.x) || !std::isfinite(d.y) || !std::isfinite(d.z)) {
                        warn(tw + ": non-finite " + name + " deltas, ignored");
                        dst->clear();
                        break;
                    }
                }
            }
            sp.targets.push_back(std::move(target));
        }
        for (int set = 0;; ++set) {
            const int j = attribute("JOINTS_" + std::to_string(set)), w = attribute("WEIGHTS_" + std::to_string(set));
            if (j < 0 || w < 0) break;
            const std::string sw = what + " JOINTS_" + std::to_string(set);
            std::vector<std::uint32_t> joints = read_accessor<std::uint32_t>(j, TINYGLTF_TYPE_VEC4, sw, true);
            std::vector<float> weights =
                read_accessor<float>(w, TINYGLTF_TYPE_VEC4, what + " WEIGHTS_" + std::to_string(set));
            if (joints.size() != 4 * n || weights.size() != 4 * n) {
                warn(sw + ": count differs from POSITION, influences ignored");
                break;
            }
            sp.joints.insert(sp.joints.end(), joints.begin(), joints.end());
            sp.weights.insert(sp.weights.end(), weights.begin(), weights.end());
            ++sp.influence_sets;
        }
        // Influences checked once here, so that posing needs no checks:
        // a joint out of range or a weight not finite counts for nothing.
        std::size_t max_joints = SIZE_MAX;
        for (const SourceNode& node : src_->nodes)
            if (node.mesh == mesh && node.skin >= 0)
                max_joints = std::min(max_joints, src_->skins[std::size_t(node.skin)].joints.size());
        std::size_t bad = 0;
        for (std::size_t i = 0; i < sp.joints.size(); ++i) {
            if (!std::isfinite(sp.weights[i]) || (sp.weights[i] != 0.0f && sp.joints[i] >= max_joints)) {
                sp.weights[i] = 0.0f;
                sp.joints[i] = 0;
                ++bad;
            } else if (sp.weights[i] == 0.0f) {
                sp.joints[i] = 0;
            }
        }
        if (bad > 0)
            warn(what + ": " + std::to_string(bad) + " skin influences with a joint out of range or a non-finite "
                 "weight ignored");
    }

    const tinygltf::Model& model_;
    Scene& scene_;
    GltfGraphContext& ctx_;
    SceneSource* src_ = nullptr;
};

} // namespace

void read_gltf_graph(const tinygltf::Model& model, Scene& scene, GltfGraphContext& context) {
    GraphReader(model, scene, context).read();
}

} // namespace prast

// Posing: animation sampling, node transforms, morph targets, skins and
// file cameras; see animation.h.
#include "scene/animation.h"

#include <algorithm>
#include <cmath>

#include <glm/gtc/matrix_transform.hpp>

#include "scene/det_math.h"
#include "scene/load_scene.h"
#include "scene/tangents.h"

namespace prast {

namespace {

// Key k's value (CUBICSPLINE: the middle of in-tangent, value, out-tangent).
const float* key_value(const AnimationSampler& s, std::size_t k, int part) {
    const std::size_t w = std::size_t(s.width);
    if (s.interpolation == Interpolation::CubicSpline) return &s.values[(3 * k + std::size_t(part)) * w];
    return &s.values[k * w];
}

void normalise_quat(double* q) {
    const double len = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
    if (len > 0.0 && std::isfinite(len)) {
        for (int i = 0; i < 4; ++i) q[i] /= len;
    } else {
        q[0] = q[1] = q[2] = 0.0;
        q[3] = 1.0;
    }
}

// The loader's local matrix (translate * rotate * scale) in double.
glm::dmat4 trs(const glm::dvec3& t, const glm::dquat& r, const glm::dvec3& s) {
    return glm::translate(glm::dmat4(1.0), t) * glm::mat4_cast(r) * glm::scale(glm::dmat4(1.0), s);
}

bool finite3(const glm::vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

} // namespace

void sample_animation(const AnimationSampler& s, double t, bool rotation, double* out) {
    const std::size_t w = std::size_t(s.width), keys = s.times.size();
    auto copy = [&](const float* v) {
        for (std::size_t i = 0; i < w; ++i) out[i] = v[i];
    };
    // Before the first key the first value, after the last the last
    // (NaN times count as before the first).
    if (!(t > double(s.times.front())) || keys == 1) {
        copy(key_value(s, 0, 1));
    } else if (t >= double(s.times.back())) {
        copy(key_value(s, keys - 1, 1));
    } else {
        // The key at or before t: times[k] <= t < times[k + 1].
        const std::size_t k =
            std::size_t(std::upper_bound(s.times.begin(), s.times.end(), float(t)) - s.times.begin()) - 1;
        std::size_t k0 = k;
        // float(t) may round up onto the next key: the interval is measured in double.
        while (k0 > 0 && double(s.times[k0]) > t) --k0;
        const double t0 = s.times[k0], t1 = s.times[k0 + 1], td = t1 - t0;
        const double u = std::clamp((t - t0) / td, 0.0, 1.0);
        const float* a = key_value(s, k0, 1);
        const float* b = key_value(s, k0 + 1, 1);
        switch (s.interpolation) {
        case Interpolation::Step: copy(a); break;
        case Interpolation::Linear:
            if (rotation) {
                // Appendix C: slerp along the shorter arc.
                double d = 0.0;
                for (int i = 0; i < 4; ++i) d += double(a[i]) * double(b[i]);
                const double sign = d < 0.0 ? -1.0 : 1.0;
                const double cos_a = std::min(std::fabs(d), 1.0);
                const double angle = det::acos(cos_a);
                double wa = 1.0 - u, wb = u;
                if (angle > 1e-9) {
                    const double sa = det::sin(angle);
                    wa = det::sin(angle * (1.0 - u)) / sa;
                    wb = det::sin(angle * u) / sa;
                }
                for (int i = 0; i < 4; ++i) out[i] = wa * double(a[i]) + sign * wb * double(b[i]);
            } else {
                for (std::size_t i = 0; i < w; ++i) out[i] = double(a[i]) + u * (double(b[i]) - double(a[i]));
            }
            break;
        case Interpolation::CubicSpline: {
            // Appendix C: the Hermite spline with tangents scaled by td.
            const float* bk = key_value(s, k0, 2);      // out-tangent of key k
            const float* ak1 = key_value(s, k0 + 1, 0); // in-tangent of key k + 1
            const double u2 = u * u, u3 = u2 * u;
            const double h00 = 2 * u3 - 3 * u2 + 1, h10 = u3 - 2 * u2 + u, h01 = -2 * u3 + 3 * u2, h11 = u3 - u2;
            for (std::size_t i = 0; i < w; ++i)
                out[i] = h00 * a[i] + h10 * td * bk[i] + h01 * b[i] + h11 * td * ak1[i];
            break;
        }
        }
    }
    if (rotation) normalise_quat(out);
}

NodePose pose_nodes(const SceneSource& src, double t, int animation) {
    const std::size_t n = src.nodes.size();
    std::vector<glm::dvec3> translation(n), scale(n);
    std::vector<glm::dquat> rotation(n);
    NodePose pose;
    pose.weights.resize(n);
    for (std::size_t i = 0; i < n; ++i) {
        translation[i] = src.nodes[i].translation;
        rotation[i] = src.nodes[i].rotation;
        scale[i] = src.nodes[i].scale;
        pose.weights[i] = src.nodes[i].weights;
    }
    std::vector<double> value;
    for (std::size_t a = 0; a < src.animations.size(); ++a) {
        if (animation != kAllAnimations && int(a) != animation) continue;
        for (const AnimationChannel& c : src.animations[a].channels) {
            const AnimationSampler& s = src.animations[a].samplers[std::size_t(c.sampler)];
            value.assign(std::size_t(s.width), 0.0);
            sample_animation(s, t, c.path == AnimationPath::Rotation, value.data());
            const std::size_t i = std::size_t(c.node);
            switch (c.path) {
            case AnimationPath::Translation: translation[i] = glm::dvec3(value[0], value[1], value[2]); break;
            case AnimationPath::Scale: scale[i] = glm::dvec3(value[0], value[1], value[2]); break;
            case AnimationPath::Rotation: rotation[i] = glm::dquat(value[3], value[0], value[1], value[2]); break;
            case AnimationPath::Weights:
                pose.weights[i].assign(value.begin(), value.end());
                break;
            }
        }
    }
    pose.world.assign(n, glm::dmat4(1.0));
    for (int ii : src.node_order) {
        const std::size_t i = std::size_t(ii);
        const SourceNode& node = src.nodes[i];
        const glm::dmat4 local = node.has_matrix ? node.matrix : trs(translation[i], rotation[i], scale[i]);
        // As the loader multiplies: the parent's world (identity at a root) times the local.
        pose.world[i] = (node.parent >= 0 ? pose.world[std::size_t(node.parent)] : glm::dmat4(1.0)) * local;
    }
    return pose;
}

void pose_scene(Scene& scene, double t, int animation) {
    if (!scene.source) return;
    const SceneSource& src = *scene.source;
    const NodePose pose = pose_nodes(src, t, animation);

    std::vector<glm::dmat4> joint_matrices;
    for (Mesh& mesh : scene.meshes) {
        if (mesh.source_vertex.empty() || mesh.source_node < 0 || std::size_t(mesh.source_node) >= src.nodes.size())
            continue;
        const std::size_t ni = std::size_t(mesh.source_node);
        const SourceNode& node = src.nodes[ni];
        if (node.mesh < 0) continue;
        const SourceMesh& sm = src.meshes[std::size_t(node.mesh)];
        if (mesh.source_primitive < 0 || std::size_t(mesh.source_primitive) >= sm.primitives.size()) continue;
        const SourcePrimitive& prim = sm.primitives[std::size_t(mesh.source_primitive)];
        const std::size_t count = prim.positions.size();
        if (!prim.used || mesh.source_vertex.size() != mesh.positions.size()) continue;

        const bool skinned = node.skin >= 0 && prim.influence_sets > 0;
        if (skinned) {
            const SourceSkin& skin = src.skins[std::size_t(node.skin)];
            joint_matrices.resize(skin.joints.size());
            for (std::size_t j = 0; j < skin.joints.size(); ++j)
                joint_matrices[j] = pose.world[std::size_t(skin.joints[j])] * skin.inverse_bind[j];
        }
        const glm::dmat4& world = pose.world[ni];
        const glm::dmat3 linear(world);
        const glm::dmat3 normal_matrix = glm::transpose(glm::inverse(linear));
        // glTF 2.0, "Meshes": the determinant of the node's world transform
        // sets the winding; an animated scale may turn it over. A skinned
        // mesh keeps the loader's (its node's transform is not applied).
        const bool mirrored = skinned ? mesh.mirrored : glm::determinant(linear) < 0.0;
        const std::vector<double>& weights = pose.weights[ni];
        const bool triangles = mesh.topology == Mesh::Topology::Triangles;
        // The loader keeps the file's tangents when the mesh has a UV set
        // (finish_scene then picks the normal map's).
        const bool file_normals = !prim.normals.empty() && (triangles || mesh.normals.size() == mesh.positions.size());
        const bool file_tangents = !prim.tangents.empty() && (!mesh.uvs.empty() || !mesh.uvs1.empty());
        if (file_normals) mesh.normals.resize(mesh.positions.size());
        std::vector<std::size_t> bad_normals;

        for (std::size_t j = 0; j < mesh.positions.size(); ++j) {
            const std::size_t v = mesh.source_vertex[j];
            if (v >= count) continue;
            // Morph targets: base + sum of weight_i * delta_i.
            glm::dvec3 p(prim.positions[v]), nrm(0.0), tan(0.0);
            if (file_normals) nrm = glm::dvec3(prim.normals[v]);
            if (file_tangents) tan = glm::dvec3(prim.tangents[v]);
            for (std::size_t k = 0; k < prim.targets.size() && k < weights.size(); ++k) {
                const double w = weights[k];
                if (w == 0.0) continue;
                const SourcePrimitive::Target& tg = prim.targets[k];
                if (!tg.position.empty()) p += w * glm::dvec3(tg.position[v]);
                if (file_normals && !tg.normal.empty()) nrm += w * glm::dvec3(tg.normal[v]);
                if (file_tangents && !tg.tangent.empty()) tan += w * glm::dvec3(tg.tangent[v]);
            }
            glm::dvec3 wp, wn, wt;
            if (skinned) {
                glm::dmat4 m(0.0);
                double total = 0.0;
                for (int s = 0; s < prim.influence_sets; ++s) {
                    const std::size_t base = (std::size_t(s) * count + v) * 4;
                    for (std::size_t k = 0; k < 4; ++k) {
                        const double w = prim.weights[base + k];
                        if (w == 0.0) continue;
                        m += w * joint_matrices[prim.joints[base + k]];
                        total += w;
                    }
                }
                if (total == 0.0) m = world;  // no influence: where the node puts it
                const glm::dmat3 ml(m);
                wp = glm::dvec3(m * glm::dvec4(p, 1.0));
                wn = glm::normalize(glm::transpose(glm::inverse(ml)) * nrm);
                wt = glm::normalize(ml * tan);
            } else {
                wp = glm::dvec3(world * glm::dvec4(p, 1.0));
                wn = glm::normalize(normal_matrix * nrm);
                wt = glm::normalize(linear * tan);
            }
            const glm::vec3 fp(wp);
            mesh.positions[j] = finite3(fp) ? fp : glm::vec3(0.0f);
            if (file_normals) {
                // finish_scene's normalisation, in float.
                const glm::vec3 fn(wn);
                const float len = finite3(fn) ? glm::length(fn) : 0.0f;
                if (len > 1e-20f && std::isfinite(len)) mesh.normals[j] = fn / len;
                else bad_normals.push_back(j);
            }
            if (file_tangents) {
                const float tw = prim.tangents[v].w < 0.0f ? -1.0f : 1.0f;
                mesh.tangents.resize(mesh.positions.size());
                mesh.tangents[j] = glm::vec4(glm::vec3(wt), mirrored ? -tw : tw);
            }
        }
        if (mirrored != mesh.mirrored) {
            if (triangles)
                for (std::size_t k = 0; k + 2 < mesh.indices.size(); k += 3) std::swap(mesh.indices[k + 1], mesh.indices[k + 2]);
            mesh.mirrored = mirrored;
        }
        // finish_scene's rules: triangles get computed normals where the
        // file's are missing or unusable; lines and points have none then.
        if (!triangles) {
            if (!file_normals || !bad_normals.empty()) mesh.normals.clear();
        } else if (!file_normals || !bad_normals.empty()) {
            std::vector<glm::vec3> given = std::move(mesh.normals);
            compute_normals(mesh);
            if (file_normals) {
                std::vector<glm::vec3> computed = std::move(mesh.normals);
                mesh.normals = std::move(given);
                for (std::size_t j : bad_normals) mesh.normals[j] = computed[j];
            }
        }
        const std::vector<glm::vec2>& tuv = scene_detail::tangent_uvs(mesh, scene);
        if (tuv.empty() || mesh.normals.empty()) mesh.tangents.clear();
        else if (!file_tangents || mesh.tangents.size() != mesh.positions.size() || !scene_detail::repair_tangents(mesh))
            compute_tangents(mesh, tuv);
    }
    // Lights follow their nodes (KHR_lights_punctual: at the node's origin,
    // shining along its -Z), as the loader placed them.
    for (Light& light : scene.lights) {
        if (light.source_node < 0 || std::size_t(light.source_node) >= pose.world.size()) continue;
        const glm::dmat4& world = pose.world[std::size_t(light.source_node)];
        if (light.type != Light::Type::Point) {  // suns and spots shine along the node's -Z
            const glm::dvec3 towards = glm::dmat3(world) * glm::dvec3(0.0, 0.0, 1.0);
            const double len = glm::length(towards);
            if (len > 0.0 && std::isfinite(len)) light.direction = glm::vec3(towards / len);
        }
        if (light.type != Light::Type::Directional) {  // points and spots sit at its origin
            const glm::vec3 p(world * glm::dvec4(0.0, 0.0, 0.0, 1.0));
            if (finite3(p)) light.position = p;
        }
    }
    ++scene.pose_serial;
}

Camera scene_camera(const Scene& scene, int index, double t, float aspect, int animation) {
    Camera cam;
    if (index < 0 || std::size_t(index) >= scene.cameras.size()) return cam;
    const SceneCamera& c = scene.cameras[std::size_t(index)];
    glm::dmat4 world(1.0);
    if (scene.source && c.node >= 0 && std::size_t(c.node) < scene.source->nodes.size())
        world = pose_nodes(*scene.source, t, animation).world[std::size_t(c.node)];
    const glm::dvec3 eye(world * glm::dvec4(0.0, 0.0, 0.0, 1.0));
    glm::dvec3 forward = glm::dmat3(world) * glm::dvec3(0.0, 0.0, -1.0);
    glm::dvec3 up = glm::dmat3(world) * glm::dvec3(0.0, 1.0, 0.0);
    const double fl = glm::length(forward), ul = glm::length(up);
    forward = fl > 0.0 && std::isfinite(fl) ? forward / fl : glm::dvec3(0.0, 0.0, -1.0);
    up = ul > 0.0 && std::isfinite(ul) ? up / ul : glm::dvec3(0.0, 1.0, 0.0);
    cam.eye = glm::vec3(eye);
    cam.target = glm::vec3(eye + forward);
    cam.up = glm::vec3(up);
    cam.near_plane = float(c.znear);
    if (c.orthographic) {
        cam.orthographic = true;
        cam.ortho_ymag = float(c.ymag);
        cam.far_plane = float(c.zfar);
        // The field of view means nothing here; kept for what prints it.
        cam.fov_y_deg = 45.0f;
    } else {
        cam.fov_y_deg = float(glm::degrees(c.yfov));
        cam.infinite_far = c.zfar == 0.0;
        cam.far_plane = cam.infinite_far ? float(c.znear) * 1e6f : float(c.zfar);
    }
    (void)aspect;  // the image's aspect is applied by Camera::projection
    return cam;
}

int find_named(const std::vector<std::string>& names, const std::string& wanted) {
    if (!wanted.empty() && wanted.size() <= 9 &&
        std::all_of(wanted.begin(), wanted.end(), [](char ch) { return ch >= '0' && ch <= '9'; })) {
        const long i = std::stol(wanted);
        return std::size_t(i) < names.size() ? int(i) : -1;
    }
    for (std::size_t i = 0; i < names.size(); ++i)
        if (names[i] == wanted) return int(i);
    return -1;
}

} // namespace prast

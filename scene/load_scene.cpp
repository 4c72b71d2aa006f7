// The format dispatch and what the OBJ and glTF loaders share: reading a file
// defensively and the final clean-up of the meshes (finish_scene).
#include "scene/load_scene.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <system_error>
#include <utility>

#include "scene/file_access.h"
#include "scene/messages.h"
#include "scene/tangents.h"

namespace prast {

namespace fs = std::filesystem;

Scene load_scene(const std::string& path, const LoadOptions& options) {
    std::error_code ec;
    if (fs::is_directory(path, ec)) throw LoadError(printable(path) + ": is a directory, not a file");
    const std::string ext = scene_detail::extension_lower(path);
    if (ext == ".obj") return load_obj(path, options);
    if (ext == ".gltf" || ext == ".glb") return load_gltf(path, options);
    throw LoadError(printable(path) + ": unknown extension '" + printable(fs::path(path).extension().string()) +
                    "' (expected .obj, .gltf or .glb)");
}

namespace scene_detail {

std::string extension_lower(const std::string& path) {
    std::string ext = fs::path(path).extension().string();
    for (char& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
    return ext;
}

std::vector<unsigned char> read_file(const std::string& path) {
    return read_regular_file(path, kMaxFileBytes);
}

namespace {

bool finite3(const glm::vec3& v) {
    return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

// Indices per primitive of a topology: a triangle's three, a line's two, a point's one.
std::size_t corners_of(Mesh::Topology t) {
    return t == Mesh::Topology::Triangles ? 3 : t == Mesh::Topology::Lines ? 2 : 1;
}

// Keeps the primitives (triangles, lines or points) whose corners are in range
// and finite, then the vertices they use, in their first-use order. Returns
// the counts of dropped primitives.
std::pair<std::size_t, std::size_t> drop_bad_primitives(Mesh& m) {
    const std::size_t n = m.positions.size();
    const std::size_t k = corners_of(m.topology);
    std::size_t bad_index = 0, non_finite = 0;
    std::vector<std::uint32_t> kept;
    kept.reserve(m.indices.size());
    for (std::size_t t = 0; t + k <= m.indices.size(); t += k) {
        bool in_range = true, finite = true;
        for (std::size_t c = 0; c < k; ++c) {
            const std::uint32_t i = m.indices[t + c];
            if (i >= n) in_range = false;
            else if (!finite3(m.positions[i])) finite = false;
        }
        if (!in_range) ++bad_index;
        else if (!finite) ++non_finite;
        else kept.insert(kept.end(), m.indices.begin() + std::ptrdiff_t(t), m.indices.begin() + std::ptrdiff_t(t + k));
    }

    // Compact the vertices, keeping their order (also drops the NaN ones, so
    // that bounds stay finite)
    constexpr std::uint32_t kUnused = ~std::uint32_t(0);
    std::vector<std::uint32_t> remap(n, kUnused);
    for (std::uint32_t i : kept) remap[i] = 0;
    std::uint32_t next = 0;
    for (std::uint32_t& r : remap)
        if (r != kUnused) r = next++;
    for (std::uint32_t& i : kept) i = remap[i];
    m.indices = std::move(kept);
    if (next != n) {
        auto compact = [&](auto& attr) {
            if (attr.size() != n) return;
            std::remove_reference_t<decltype(attr)> out(next);
            for (std::size_t i = 0; i < n; ++i)
                if (remap[i] != kUnused) out[remap[i]] = attr[i];
            attr = std::move(out);
        };
        compact(m.positions);
        compact(m.normals);
        compact(m.uvs);
        compact(m.tangents);
        compact(m.uvs1);
        compact(m.colors);
        compact(m.source_vertex);
    }
    return {bad_index, non_finite};
}

// Non-finite texture coordinates become 0; returns how many were.
std::size_t repair_uvs(std::vector<glm::vec2>& uvs) {
    std::size_t bad = 0;
    for (glm::vec2& uv : uvs) {
        if (!std::isfinite(uv.x) || !std::isfinite(uv.y)) {
            uv = glm::vec2(0.0f);
            ++bad;
        }
    }
    return bad;
}

// Vertex colours: a non-finite one becomes white (what no colour means) and
// is counted; finite ones are clamped to [0, 1], the range glTF requires
// of COLOR_0, so that no colour can make light negative or amplify it.
std::size_t repair_colors(std::vector<glm::vec4>& colors) {
    std::size_t bad = 0;
    for (glm::vec4& c : colors) {
        if (!std::isfinite(c.r) || !std::isfinite(c.g) || !std::isfinite(c.b) || !std::isfinite(c.a)) {
            c = glm::vec4(1.0f);
            ++bad;
        } else {
            c = glm::clamp(c, 0.0f, 1.0f);
        }
    }
    return bad;
}

// Normalises the given normals; when any is unusable, the whole set is
// replaced by computed ones for that vertex.
std::size_t repair_normals(Mesh& m) {
    if (m.normals.size() != m.positions.size()) {
        compute_normals(m);
        return 0;
    }
    std::vector<std::size_t> bad;
    for (std::size_t i = 0; i < m.normals.size(); ++i) {
        const glm::vec3 nrm = m.normals[i];
        const float len = finite3(nrm) ? glm::length(nrm) : 0.0f;
        if (len > 1e-20f && std::isfinite(len)) m.normals[i] = nrm / len;
        else bad.push_back(i);
    }
    if (!bad.empty()) {
        std::vector<glm::vec3> given = std::move(m.normals);
        compute_normals(m);
        std::vector<glm::vec3> computed = std::move(m.normals);
        m.normals = std::move(given);
        for (std::size_t i : bad) m.normals[i] = computed[i];
    }
    return bad.size();
}

} // namespace

// The UV set that tangents follow: the one the material's normal map reads
// (glTF 2.0, "Meshes": tangents from "the texture coordinates associated
// with the normal texture"), TEXCOORD_0 when there is no normal map or the
// mesh lacks the set it names.
const std::vector<glm::vec2>& tangent_uvs(const Mesh& m, const Scene& scene) {
    if (m.material >= 0 && std::size_t(m.material) < scene.materials.size()) {
        const TextureRef& normal = scene.materials[std::size_t(m.material)].normal;
        if (normal.valid() && normal.texcoord == 1 && !m.uvs1.empty()) return m.uvs1;
    }
    return m.uvs;
}

// File tangents: xyz orthogonalised against the (possibly repaired) normal and
// normalised, w a sign. Returns false when any is unusable: non-finite, or
// within 0.06 degrees of its normal, where rounding would leave the result
// visibly non-orthogonal.
bool repair_tangents(Mesh& m) {
    if (m.tangents.size() != m.positions.size()) return false;
    for (std::size_t i = 0; i < m.tangents.size(); ++i) {
        glm::vec4& t = m.tangents[i];
        const glm::dvec3 n(m.normals[i]);
        glm::dvec3 xyz(t);
        const double len0 = glm::length(xyz);
        if (!(len0 > 0.0) || !std::isfinite(len0) || !std::isfinite(t.w)) return false;
        xyz /= len0;
        xyz -= n * glm::dot(n, xyz);
        const double len = glm::length(xyz);
        if (!(len > 1e-3)) return false;
        t = glm::vec4(glm::vec3(xyz / len), t.w < 0.0f ? -1.0f : 1.0f);
    }
    return true;
}

void finish_scene(Scene& scene, const std::string& path_in) {
    const std::string path = printable(path_in);
    std::size_t bad_index = 0, non_finite = 0, bad_normals = 0, bad_uvs = 0, bad_colors = 0;
    std::size_t bad_index_lines = 0, non_finite_lines = 0, unlit_normals = 0;
    int default_material = -1;
    std::vector<Mesh> kept;
    kept.reserve(scene.meshes.size());
    for (Mesh& m : scene.meshes) {
        const bool triangles = m.topology == Mesh::Topology::Triangles;
        const std::size_t k = corners_of(m.topology);
        m.indices.resize(m.indices.size() / k * k);
        const auto dropped = drop_bad_primitives(m);
        (triangles ? bad_index : bad_index_lines) += dropped.first;
        (triangles ? non_finite : non_finite_lines) += dropped.second;
        if (m.indices.empty()) continue; // nothing to draw: skip the mesh

        if (m.material < 0 || std::size_t(m.material) >= scene.materials.size()) {
            if (default_material < 0) {
                default_material = int(scene.materials.size());
                scene.materials.push_back(Material());
            }
            m.material = default_material;
        }

        if (triangles) {
            bad_normals += repair_normals(m);
        } else if (m.normals.size() != m.positions.size()) {
            // Lines and points without normals are drawn unlit (glTF's flat
            // normals are a rule for triangles): none are made up.
            m.normals.clear();
        } else if (repair_normals(m) > 0) {
            // A line has no face to compute a normal from.
            m.normals.clear();
            ++unlit_normals;
        }
        if (m.uvs.size() != m.positions.size()) m.uvs.clear();
        if (m.uvs1.size() != m.positions.size()) m.uvs1.clear();
        if (m.colors.size() != m.positions.size()) m.colors.clear();
        bad_uvs += repair_uvs(m.uvs) + repair_uvs(m.uvs1);
        bad_colors += repair_colors(m.colors);
        const std::vector<glm::vec2>& tuv = tangent_uvs(m, scene);
        if (tuv.empty() || m.normals.empty()) m.tangents.clear();
        else if (!repair_tangents(m)) compute_tangents(m, tuv);
        kept.push_back(std::move(m));
    }
    scene.meshes = std::move(kept);
    if (scene.materials.empty()) scene.materials.push_back(Material());

    if (bad_index > 0)
        scene.warnings.push_back(path + ": dropped " + std::to_string(bad_index) +
                                 " triangles with out-of-range vertex indices");
    if (non_finite > 0)
        scene.warnings.push_back(path + ": dropped " + std::to_string(non_finite) +
                                 " triangles with NaN/Inf positions");
    if (bad_index_lines > 0)
        scene.warnings.push_back(path + ": dropped " + std::to_string(bad_index_lines) +
                                 " lines or points with out-of-range vertex indices");
    if (non_finite_lines > 0)
        scene.warnings.push_back(path + ": dropped " + std::to_string(non_finite_lines) +
                                 " lines or points with NaN/Inf positions");
    if (bad_normals > 0)
        scene.warnings.push_back(path + ": replaced " + std::to_string(bad_normals) +
                                 " NaN/zero normals by computed ones");
    if (unlit_normals > 0)
        scene.warnings.push_back(path + ": " + std::to_string(unlit_normals) +
                                 " line or point meshes with NaN/zero normals drawn without normals (unlit)");
    if (bad_uvs > 0)
        scene.warnings.push_back(path + ": set " + std::to_string(bad_uvs) +
                                 " NaN/Inf texture coordinates to 0");
    if (bad_colors > 0)
        scene.warnings.push_back(path + ": set " + std::to_string(bad_colors) +
                                 " NaN/Inf vertex colours to white");
    if (scene.meshes.empty()) throw LoadError(path + ": no triangles");
}

} // namespace scene_detail

} // namespace prast

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
    const std::string ext = detail::extension_lower(path);
    if (ext == ".obj") return load_obj(path, options);
    if (ext == ".gltf" || ext == ".glb") return load_gltf(path, options);
    throw LoadError(printable(path) + ": unknown extension '" + printable(fs::path(path).extension().string()) +
                    "' (expected .obj, .gltf or .glb)");
}

namespace detail {

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

// Keeps the triangles whose corners are in range and finite, then the vertices
// they use, in their first-use order. Returns the counts of dropped triangles.
std::pair<std::size_t, std::size_t> drop_bad_triangles(Mesh& m) {
    const std::size_t n = m.positions.size();
    std::size_t bad_index = 0, non_finite = 0;
    std::vector<std::uint32_t> kept;
    kept.reserve(m.indices.size());
    for (std::size_t t = 0; t + 2 < m.indices.size(); t += 3) {
        const std::uint32_t a = m.indices[t], b = m.indices[t + 1], c = m.indices[t + 2];
        if (a >= n || b >= n || c >= n) {
            ++bad_index;
        } else if (!finite3(m.positions[a]) || !finite3(m.positions[b]) ||
                   !finite3(m.positions[c])) {
            ++non_finite;
        } else {
            kept.insert(kept.end(), {a, b, c});
        }
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
    }
    return {bad_index, non_finite};
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

} // namespace

void finish_scene(Scene& scene, const std::string& path_in) {
    const std::string path = printable(path_in);
    std::size_t bad_index = 0, non_finite = 0, bad_normals = 0, bad_uvs = 0;
    int default_material = -1;
    std::vector<Mesh> kept;
    kept.reserve(scene.meshes.size());
    for (Mesh& m : scene.meshes) {
        m.indices.resize(m.indices.size() / 3 * 3);
        const auto dropped = drop_bad_triangles(m);
        bad_index += dropped.first;
        non_finite += dropped.second;
        if (m.indices.empty()) continue; // nothing to draw: skip the mesh

        bad_normals += repair_normals(m);
        if (m.uvs.size() != m.positions.size()) m.uvs.clear();
        for (glm::vec2& uv : m.uvs) {
            if (!std::isfinite(uv.x) || !std::isfinite(uv.y)) {
                uv = glm::vec2(0.0f);
                ++bad_uvs;
            }
        }
        if (m.uvs.empty()) m.tangents.clear();
        else if (!repair_tangents(m)) compute_tangents(m);

        if (m.material < 0 || std::size_t(m.material) >= scene.materials.size()) {
            if (default_material < 0) {
                default_material = int(scene.materials.size());
                scene.materials.push_back(Material());
            }
            m.material = default_material;
        }
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
    if (bad_normals > 0)
        scene.warnings.push_back(path + ": replaced " + std::to_string(bad_normals) +
                                 " NaN/zero normals by computed ones");
    if (bad_uvs > 0)
        scene.warnings.push_back(path + ": set " + std::to_string(bad_uvs) +
                                 " NaN/Inf texture coordinates to 0");
    if (scene.meshes.empty()) throw LoadError(path + ": no triangles");
}

} // namespace detail

} // namespace prast

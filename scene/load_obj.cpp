// Wavefront OBJ + MTL through tinyobjloader, into world-space meshes and
// metal-roughness materials (docs/conventions.md, "Materials from OBJ + MTL").
//
// tinyobjloader gives absent MTL keys a value (Kd 0, or 0.6 once some map_Kd
// was seen in the file, Pr 0, Pm 0), so "absent" cannot be told from "0". We
// therefore feed it the MTL one `newmtl` block at a time and scan each block
// for the keys ourselves; the scan also reads the non-standard conductor key
// `Pc gold|copper|aluminium|silver`, which tinyobjloader takes for a clearcoat
// number.
#include "scene/load_scene.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <map>
#include <new>
#include <set>
#include <sstream>
#include <stdexcept>
#include <unordered_map>
#include <utility>

#include <tiny_obj_loader.h>

#include "scene/file_access.h"
#include "scene/messages.h"
#include "scene/tangents.h"

namespace prast {

namespace fs = std::filesystem;

namespace {

// tinyobjloader's ear clipping costs O(n^3) in the vertices of a polygon in the
// worst case; real files stay far below this.
constexpr std::size_t kMaxFaceVertices = 256;

// What tinyobjloader's material_t cannot tell: which keys were present.
struct MtlKeys {
    bool kd = false, pr = false, pm = false, ke = false;
    std::string conductor; // value of `Pc` when it is a word
    std::string dir;       // texture paths are relative to the MTL's (canonical) folder
};

// Lines as tinyobjloader's safeGetline splits them: at \n, \r\n or \r.
std::vector<std::string> split_lines(const std::string& text) {
    std::vector<std::string> lines;
    std::size_t start = 0;
    for (std::size_t i = 0; i < text.size(); ++i) {
        if (text[i] != '\n' && text[i] != '\r') continue;
        lines.push_back(text.substr(start, i - start));
        if (text[i] == '\r' && i + 1 < text.size() && text[i + 1] == '\n') ++i;
        start = i + 1;
    }
    if (start < text.size()) lines.push_back(text.substr(start));
    return lines;
}

bool is_space(char c) { return c == ' ' || c == '\t'; }

// The line without trailing blanks and leading blanks, cut at a NUL as
// tinyobjloader's C-string parsing does.
std::string trimmed(const std::string& line) {
    std::string s(line.c_str());
    std::size_t end = s.find_last_not_of(" \t");
    if (end == std::string::npos) return {};
    std::size_t begin = s.find_first_not_of(" \t");
    return s.substr(begin, end + 1 - begin);
}

// True when `line` (trimmed) is `key` followed by a blank and a value.
bool has_key(const std::string& line, const char* key, std::string* value = nullptr) {
    const std::size_t n = std::strlen(key);
    if (line.size() <= n || line.compare(0, n, key) != 0 || !is_space(line[n])) return false;
    if (value) *value = trimmed(line.substr(n + 1));
    return true;
}

std::string lower(std::string s) {
    for (char& c : s) c = char(std::tolower(static_cast<unsigned char>(c)));
    return s;
}

// Reads each `mtllib` file for tinyobjloader (see the file comment), through
// the model's FileScope; each file once, however it is spelled.
class MtlReader : public tinyobj::MaterialReader {
public:
    MtlReader(FileScope& scope, std::vector<MtlKeys>& keys, WarningLog& warnings)
        : scope_(scope), keys_(keys), warnings_(warnings) {}

    bool operator()(const std::string& mat_id, std::vector<tinyobj::material_t>* materials,
                    std::map<std::string, int>* mat_map, std::string* warn,
                    std::string* /*err*/) override {
        const std::string shown = printable(scope_.model());
        const FileScope::Resolved where = scope_.resolve(scope_.root(), mat_id);
        if (!where.ok()) {
            if (where.missing)
                warnings_.add(shown + ": material library '" + printable(cut(mat_id)) +
                              "' not found; default material used");
            else warnings_.add(scope_.refusal("material library", mat_id, where) + "; default material used");
            return false;
        }
        // Already read under another spelling: its materials are there.
        if (!loaded_.insert(where.path).second) return true;
        std::vector<unsigned char> bytes;
        try {
            bytes = read_regular_file(where.path, scene_detail::kMaxFileBytes, mat_id);
            std::string why;
            if (!scope_.charge(bytes.size(), why)) throw LoadError(printable(cut(mat_id)) + ": " + why);
        } catch (const LoadError& e) {
            warnings_.add(shown + ": material library " + e.what() + "; default material used");
            return false;
        }
        const std::string text(bytes.begin(), bytes.end());

        // One tinyobjloader pass per `newmtl` block; text before the first
        // block belongs to no material.
        std::string block;
        MtlKeys keys;
        bool in_block = false;
        auto flush = [&] {
            if (!in_block) return;
            std::map<std::string, int> local_map;
            std::vector<tinyobj::material_t> local;
            std::istringstream in(block);
            std::string w, e;
            tinyobj::LoadMtl(&local_map, &local, &in, &w, &e);
            if (warn) *warn += w;
            if (local.empty()) return;
            mat_map->insert({local.back().name, int(materials->size())}); // first one wins
            materials->push_back(local.back());
            keys_.push_back(keys);
        };
        for (const std::string& raw : split_lines(text)) {
            const std::string line = trimmed(raw);
            if (has_key(line, "newmtl")) {
                flush();
                block.clear();
                keys = MtlKeys();
                keys.dir = folder_of(where.path);
                in_block = true;
            }
            block += raw;
            block += '\n';
            std::string value;
            keys.kd |= has_key(line, "Kd");
            keys.pr |= has_key(line, "Pr");
            keys.pm |= has_key(line, "Pm");
            keys.ke |= has_key(line, "Ke");
            if (has_key(line, "Pc", &value)) {
                char* end = nullptr;
                std::strtod(value.c_str(), &end);
                // A number is tinyobjloader's clearcoat thickness, not ours.
                if (end == value.c_str()) keys.conductor = lower(value);
            }
        }
        flush();
        return true;
    }

private:
    FileScope& scope_;
    std::vector<MtlKeys>& keys_;
    WarningLog& warnings_;
    std::set<std::string> loaded_;  // canonical paths of the libraries read
};

// Rejects what would make tinyobjloader slow: polygons with very many corners.
void prevalidate(const std::string& text, const std::string& path) {
    for (const std::string& raw : split_lines(text)) {
        const std::string line = trimmed(raw);
        if (line.size() < 2 || line[0] != 'f' || !is_space(line[1])) continue;
        std::size_t corners = 0;
        for (std::size_t i = 1; i < line.size(); ++i)
            if (!is_space(line[i]) && is_space(line[i - 1])) ++corners;
        if (corners > kMaxFaceVertices)
            throw LoadError(printable(path) + ": a face has " + std::to_string(corners) +
                            " vertices (at most " + std::to_string(kMaxFaceVertices) +
                            " supported)");
    }
}

struct CornerKey {
    int v, vt, vn;
    bool operator==(const CornerKey& o) const { return v == o.v && vt == o.vt && vn == o.vn; }
};

struct CornerKeyHash {
    std::size_t operator()(const CornerKey& k) const {
        std::size_t h = std::hash<int>()(k.v);
        h = h * 0x9E3779B97F4A7C15ull + std::hash<int>()(k.vt);
        h = h * 0x9E3779B97F4A7C15ull + std::hash<int>()(k.vn);
        return h;
    }
};

// A Mesh under construction: corners keyed by their (v, vt, vn) triple, so
// that vertices shared in the file stay shared (smooth normals need this).
struct MeshBuilder {
    Mesh mesh;
    std::unordered_map<CornerKey, std::uint32_t, CornerKeyHash> corners;
    bool any_uv = false;
};

class ObjLoader {
public:
    ObjLoader(const std::string& path, const LoadOptions& options)
        : path_(path), shown_(printable(path)), scope_(path, options.allow_outside_paths) {}

    Scene load() {
        const std::vector<unsigned char> bytes = scene_detail::read_file(path_);
        const std::string text(bytes.begin(), bytes.end());
        prevalidate(text, path_);

        // Parse
        tinyobj::attrib_t attrib;
        std::vector<tinyobj::shape_t> shapes;
        std::vector<tinyobj::material_t> materials;
        std::string warn, err;
        MtlReader reader(scope_, keys_, log_);
        std::istringstream in(text);
        const bool ok = tinyobj::LoadObj(&attrib, &shapes, &materials, &warn, &err, &in, &reader,
                                         /*triangulate=*/true, /*default_vcols_fallback=*/false);
        if (!ok)
            throw LoadError(shown_ + ": " + printable(cut(first_line(err, "cannot parse OBJ"), 2 * kMaxShownChars)));
        if (keys_.size() != materials.size()) // cannot happen: only MtlReader adds materials
            throw LoadError(shown_ + ": internal error reading materials");

        for (std::size_t i = 0; i < materials.size(); ++i)
            scene_.materials.push_back(convert_material(materials[i], keys_[i]));
        build_meshes(attrib, shapes); // names the first bad index, if any
        // tinyobjloader silently drops quads and polygons with a bad index.
        if (warn.find("out of bounds") != std::string::npos ||
            warn.find("invalid vertex index") != std::string::npos)
            throw LoadError(shown_ + ": face index out of range");
        pass_on_warnings(warn);
        scene_.warnings = log_.lines();
        scene_detail::finish_scene(scene_, path_);
        return std::move(scene_);
    }

private:
    static std::string first_line(const std::string& s, const char* fallback) {
        const std::size_t begin = s.find_first_not_of(" \t\r\n");
        if (begin == std::string::npos) return fallback;
        const std::size_t end = s.find_first_of("\r\n", begin);
        return s.substr(begin, end == std::string::npos ? std::string::npos : end - begin);
    }

    // tinyobjloader's own warnings, once each and a bounded number of them.
    void pass_on_warnings(const std::string& warn) {
        std::set<std::string> seen;
        std::size_t extra = 0;
        for (const std::string& raw : split_lines(warn)) {
            const std::string line = trimmed(raw);
            if (line.empty() || line == "." || !seen.insert(line).second) continue;
            if (line.rfind("Material file [", 0) == 0 || line.rfind("Failed to load material", 0) == 0)
                continue; // MtlReader reported it
            if (seen.size() > 8) { ++extra; continue; }
            log_.add(shown_ + ": " + printable(cut(line, 2 * kMaxShownChars)));
        }
        if (extra > 0) log_.add(shown_ + ": " + std::to_string(extra) + " more parser warnings");
    }

    // The Scene image for a map, or -1 (with a warning) when the file is
    // missing or refused (file_access.h); one image per file however spelled.
    int image_for(const std::string& texname, const MtlKeys& keys, const char* key,
                  const std::string& material) {
        if (texname.empty()) return -1;
        const FileScope::Resolved where = scope_.resolve(keys.dir, texname);
        if (!where.ok()) {
            const std::string what = "material '" + cut(material) + "': " + key;
            if (where.missing)
                log_.add(shown_ + ": " + printable(what) + " '" + printable(cut(texname)) + "' not found, ignored");
            else log_.add(scope_.refusal(what, texname, where) + ", ignored");
            return -1;
        }
        const std::string& normal = where.path;
        const auto it = image_index_.find(normal);
        if (it != image_index_.end()) return it->second;
        ImageSource src;
        src.path = normal;
        src.name = normal;
        scene_.images.push_back(std::move(src));
        image_index_.emplace(normal, int(scene_.images.size()) - 1);
        return int(scene_.images.size()) - 1;
    }

    TextureRef texture(const std::string& texname, const tinyobj::texture_option_t& opt,
                       const MtlKeys& keys, const char* key, const std::string& material) {
        TextureRef ref;
        ref.image = image_for(texname, keys, key, material);
        if (opt.clamp) ref.wrap_s = ref.wrap_t = Wrap::ClampToEdge;
        return ref;
    }

    Material convert_material(const tinyobj::material_t& src, const MtlKeys& keys) {
        Material m;
        m.name = src.name;
        const std::string& name = src.name;
        m.base_color = texture(src.diffuse_texname, src.diffuse_texopt, keys, "map_Kd", name);
        m.roughness = texture(src.roughness_texname, src.roughness_texopt, keys, "map_Pr", name);
        m.metallic = texture(src.metallic_texname, src.metallic_texopt, keys, "map_Pm", name);
        m.emissive = texture(src.emissive_texname, src.emissive_texopt, keys, "map_Ke", name);
        m.occlusion = texture(src.ambient_texname, src.ambient_texopt, keys, "map_Ka", name);
        if (!src.normal_texname.empty()) {
            m.normal = texture(src.normal_texname, src.normal_texopt, keys, "norm", name);
            m.normal_scale = float(src.normal_texopt.bump_multiplier);
        } else if (!src.bump_texname.empty()) {
            m.normal = texture(src.bump_texname, src.bump_texopt, keys, "bump", name);
            m.normal_scale = float(src.bump_texopt.bump_multiplier);
        }
        if (!std::isfinite(m.normal_scale)) m.normal_scale = 1.0f;

        // Factors: the key's value; 1 when only the map is there; else the defaults.
        auto finite_or = [](double v, float fallback) {
            return std::isfinite(v) ? float(v) : fallback;
        };
        if (keys.kd)
            m.base_color_factor = glm::vec4(finite_or(src.diffuse[0], 0.8f),
                                            finite_or(src.diffuse[1], 0.8f),
                                            finite_or(src.diffuse[2], 0.8f), 1.0f);
        else m.base_color_factor = m.base_color.valid() ? glm::vec4(1.0f) : glm::vec4(0.8f, 0.8f, 0.8f, 1.0f);
        if (keys.pr) m.roughness_factor = finite_or(src.roughness, 0.5f);
        else m.roughness_factor = m.roughness.valid() ? 1.0f : 0.5f;
        if (keys.pm) m.metallic_factor = finite_or(src.metallic, 0.0f);
        else m.metallic_factor = m.metallic.valid() ? 1.0f : 0.0f;
        if (keys.ke)
            m.emissive_factor = glm::vec3(finite_or(src.emission[0], 0.0f),
                                          finite_or(src.emission[1], 0.0f),
                                          finite_or(src.emission[2], 0.0f));
        else m.emissive_factor = m.emissive.valid() ? glm::vec3(1.0f) : glm::vec3(0.0f);

        if (!keys.conductor.empty()) {
            const std::string& c = keys.conductor;
            if (c == "gold") m.conductor = Conductor::Gold;
            else if (c == "copper") m.conductor = Conductor::Copper;
            else if (c == "aluminium" || c == "aluminum") m.conductor = Conductor::Aluminium;
            else if (c == "silver") m.conductor = Conductor::Silver;
            else
                log_.add(shown_ + ": material '" + printable(cut(name)) + "': unknown conductor 'Pc " + printable(cut(c)) +
                         "' ignored");
        }
        // Dissolve (`d`, or 1 - `Tr` as tinyobjloader reads it): glTF's BLEND
        // with the base colour's alpha (docs/shadows-and-transparency.md).
        const double dissolve = src.dissolve;
        if (std::isfinite(dissolve) && dissolve < 1.0) {
            m.alpha_mode = AlphaMode::Blend;
            m.base_color_factor.a = float(std::max(0.0, dissolve));
        }
        if (!src.alpha_texname.empty())
            log_.add(shown_ + ": material '" + printable(cut(name)) + "': map_d ignored (d / Tr are used)");
        return m;
    }

    // Smooth area-weighted normals per OBJ position, for corners without `vn`:
    // keyed by position (not by corner) so UV seams do not crease the shading.
    std::vector<glm::vec3> position_normals(const tinyobj::attrib_t& attrib,
                                            const std::vector<tinyobj::shape_t>& shapes) {
        const std::size_t nv = attrib.vertices.size() / 3;
        Mesh all;
        all.positions.resize(nv);
        for (std::size_t i = 0; i < nv; ++i)
            all.positions[i] = {attrib.vertices[3 * i], attrib.vertices[3 * i + 1],
                                attrib.vertices[3 * i + 2]};
        for (const tinyobj::shape_t& shape : shapes)
            for (const tinyobj::index_t& idx : shape.mesh.indices)
                all.indices.push_back(std::uint32_t(idx.vertex_index)); // checked by the caller
        compute_normals(all);
        return std::move(all.normals);
    }

    void build_meshes(const tinyobj::attrib_t& attrib, const std::vector<tinyobj::shape_t>& shapes) {
        const long nv = long(attrib.vertices.size() / 3);
        const long nn = long(attrib.normals.size() / 3);
        const long nt = long(attrib.texcoords.size() / 2);

        // Check every corner before using any
        bool need_normals = false;
        std::size_t total = 0;
        for (const tinyobj::shape_t& shape : shapes) {
            const auto& idx = shape.mesh.indices;
            if (idx.size() % 3 != 0) throw LoadError(shown_ + ": bad face (not a triangle)");
            for (const tinyobj::index_t& c : idx) {
                if (c.vertex_index < 0 || c.vertex_index >= nv)
                    throw LoadError(shown_ + ": face vertex index " + std::to_string(c.vertex_index + 1) +
                                    " out of range (" + std::to_string(nv) + " vertices)");
                if (c.normal_index < -1 || c.normal_index >= nn)
                    throw LoadError(shown_ + ": face normal index " + std::to_string(c.normal_index + 1) +
                                    " out of range (" + std::to_string(nn) + " normals)");
                if (c.texcoord_index < -1 || c.texcoord_index >= nt)
                    throw LoadError(shown_ + ": face texcoord index " +
                                    std::to_string(c.texcoord_index + 1) + " out of range (" +
                                    std::to_string(nt) + " texcoords)");
                need_normals |= c.normal_index < 0;
            }
            total += idx.size();
        }
        if (total > scene_detail::kMaxSceneElements)
            throw LoadError(shown_ + ": too many triangles (" + std::to_string(total / 3) + " corners; at most " +
                            std::to_string(scene_detail::kMaxSceneElements) + ")");
        const std::vector<glm::vec3> smooth =
            need_normals ? position_normals(attrib, shapes) : std::vector<glm::vec3>();

        for (const tinyobj::shape_t& shape : shapes) {
            // One Mesh per material used by the shape, in order of first use
            std::map<int, MeshBuilder> by_material;
            std::vector<int> order;
            const auto& idx = shape.mesh.indices;
            const auto& mat_ids = shape.mesh.material_ids;
            for (std::size_t f = 0; f < idx.size() / 3; ++f) {
                int mat = f < mat_ids.size() ? mat_ids[f] : -1;
                if (mat < 0 || std::size_t(mat) >= scene_.materials.size()) mat = -1;
                auto found = by_material.find(mat);
                if (found == by_material.end()) {
                    found = by_material.emplace(mat, MeshBuilder()).first;
                    order.push_back(mat);
                }
                MeshBuilder& b = found->second;
                for (int k = 0; k < 3; ++k) {
                    const tinyobj::index_t& c = idx[3 * f + std::size_t(k)];
                    b.mesh.indices.push_back(corner(b, attrib, c, smooth));
                }
            }
            for (int mat : order) {
                MeshBuilder& b = by_material[mat];
                b.mesh.material = mat;
                b.mesh.name = shape.name;
                if (order.size() > 1 && mat >= 0) b.mesh.name += "/" + scene_.materials[std::size_t(mat)].name;
                if (!b.any_uv) b.mesh.uvs.clear();
                scene_.meshes.push_back(std::move(b.mesh));
            }
        }
    }

    std::uint32_t corner(MeshBuilder& b, const tinyobj::attrib_t& attrib, const tinyobj::index_t& c,
                         const std::vector<glm::vec3>& smooth) {
        const CornerKey key{c.vertex_index, c.texcoord_index, c.normal_index};
        const auto found = b.corners.find(key);
        if (found != b.corners.end()) return found->second;
        const std::size_t v = std::size_t(c.vertex_index);
        Mesh& m = b.mesh;
        m.positions.push_back({attrib.vertices[3 * v], attrib.vertices[3 * v + 1],
                               attrib.vertices[3 * v + 2]});
        // Vertex colours (`v x y z r g b`): tinyobjloader keeps them only when
        // every vertex has one; taken as linear, as Kd is.
        if (attrib.colors.size() == attrib.vertices.size())
            m.colors.push_back({attrib.colors[3 * v], attrib.colors[3 * v + 1], attrib.colors[3 * v + 2], 1.0f});
        if (c.normal_index >= 0) {
            const std::size_t n = std::size_t(c.normal_index);
            m.normals.push_back({attrib.normals[3 * n], attrib.normals[3 * n + 1],
                                 attrib.normals[3 * n + 2]});
        } else {
            m.normals.push_back(smooth[v]);
        }
        if (c.texcoord_index >= 0) {
            const std::size_t t = std::size_t(c.texcoord_index);
            // OBJ's v = 0 is the bottom row; internally v = 0 is the top row.
            m.uvs.push_back({attrib.texcoords[2 * t], 1.0f - attrib.texcoords[2 * t + 1]});
            b.any_uv = true;
        } else {
            m.uvs.push_back(glm::vec2(0.0f));
        }
        const std::uint32_t index = std::uint32_t(m.positions.size() - 1);
        b.corners.emplace(key, index);
        return index;
    }

    const std::string& path_;
    const std::string shown_;  // path_, printable
    FileScope scope_;
    WarningLog log_;
    Scene scene_;
    std::vector<MtlKeys> keys_;
    std::map<std::string, int> image_index_;
};

} // namespace

Scene load_obj(const std::string& path, const LoadOptions& options) {
    try {
        return ObjLoader(path, options).load();
    } catch (const LoadError&) {
        throw;
    } catch (const std::bad_alloc&) {
        throw LoadError(printable(path) + ": out of memory while loading the model");
    } catch (const std::length_error&) {
        throw LoadError(printable(path) + ": too large to load (a size exceeds what memory can hold)");
    } catch (const std::exception& e) {
        // tinyobjloader and the standard library may throw.
        throw LoadError(printable(path) + ": cannot load: " + printable(e.what()));
    }
}

} // namespace prast

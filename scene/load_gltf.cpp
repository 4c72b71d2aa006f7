// glTF 2.0 (.gltf and .glb) through tinygltf, flattened into world-space meshes.
//
// tinygltf parses the JSON and loads buffers; it does not check accessors,
// buffer views, node graphs or most indices, so everything read here is
// checked first (a corrupt file is a LoadError, a missing texture a warning).
// Two defects of tinygltf 2.7.0 are worked around before it sees the data:
//  - a .glb whose BIN chunk claims up to 8 bytes more than the file holds is
//    read past its end (the chunk header is not counted): the GLB layout is
//    validated here first;
//  - an image in a bufferView is handed to the image callback without checking
//    byteOffset/byteLength against the buffer: the callback ignores those bytes
//    and they are copied here after a bounds check.
// Images are not decoded here (tinygltf is built without stb_image) except
// the textures of a specular-glossiness material, converted texel by texel; and
// tinygltf never opens an image file (TINYGLTF_NO_EXTERNAL_IMAGE): image uris
// are resolved here, buffer uris through file-system callbacks, both by the
// model's FileScope (scene/file_access.h), so no uri leaves the model's folder
// or opens a FIFO, and none is looked up in the current directory.
#include "scene/load_scene.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <map>
#include <new>
#include <optional>
#include <set>
#include <stdexcept>
#include <type_traits>
#include <utility>

#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/quaternion.hpp>
#include <nlohmann/json.hpp>
#include <unistd.h>

#define TINYGLTF_NO_STB_IMAGE
#define TINYGLTF_NO_STB_IMAGE_WRITE
#define TINYGLTF_NO_INCLUDE_STB_IMAGE
#define TINYGLTF_NO_INCLUDE_STB_IMAGE_WRITE
#include <tiny_gltf.h>

#include "scene/animation.h"
#include "scene/gltf_components.h"
#include "scene/file_access.h"
#include "scene/image.h"
#include "scene/gltf_graph.h"
#include "scene/draco_decode.h"
#include "scene/meshopt_decode.h"
#include "scene/messages.h"

namespace prast {

namespace fs = std::filesystem;

namespace {

using gltf_components_detail::component;
using gltf_components_detail::component_size;

// Deeper JSON is refused before parsing: nlohmann::json and tinygltf's
// conversion of extensions both recurse once per level.
constexpr int kMaxJsonDepth = 256;
// No accessor may claim more elements than this (2^31 - 1).
constexpr std::size_t kMaxAccessorCount = 0x7fffffff;
// tinygltf's own messages quote the file: a line of theirs is cut to this.
constexpr std::size_t kMaxLineChars = 2 * kMaxShownChars;
// Bytes that compressed bufferViews (EXT_meshopt_compression) may decode to,
// all of a model's together (as much as the largest file read, kMaxFileBytes).
constexpr std::uint64_t kMaxDecodedBytes = std::uint64_t(1) << 31;
// Stands in for a uri-less fallback buffer (tinygltf refuses a buffer
// without data): one zero byte, dropped after parsing.
constexpr const char* kStandInUri = "data:application/octet-stream;base64,AA==";

// ---- Callbacks handed to tinygltf

// Keeps the encoded bytes of data-URI images only. External files are kept as
// paths (texture.h reads them), and bufferView images are copied after a bounds
// check that tinygltf 2.7.0 does not do (see the file comment).
bool keep_encoded_image(tinygltf::Image* image, const int /*image_idx*/, std::string* /*err*/,
                        std::string* /*warn*/, int /*req_width*/, int /*req_height*/,
                        const unsigned char* bytes, int size, void* /*user*/) {
    if (image->bufferView < 0 && image->uri.empty() && bytes && size > 0)
        image->image.assign(bytes, bytes + size);
    return true;
}

// tinygltf's file system, confined: tinygltf asks FileExists for
// JoinPath(base_dir, uri) and then for "./uri" (the current directory);
// only the first is answered, through the model's FileScope, before anything
// is opened, and ReadWholeFile reads what that resolved to.
struct ScopedFs {
    FileScope* scope = nullptr;
    std::string refused;                          // the first refusal, a whole message
    std::map<std::string, std::string> resolved;  // asked path -> canonical path
};

bool scoped_file_exists(const std::string& path, void* user) {
    ScopedFs& fs_state = *static_cast<ScopedFs*>(user);
    FileScope& scope = *fs_state.scope;
    const std::string prefix = scope.root() == "/" ? "/" : scope.root() + "/";
    if (path.compare(0, prefix.size(), prefix) != 0) return false;  // the current-directory look-up
    const std::string uri = path.substr(prefix.size());
    const FileScope::Resolved where = scope.resolve(scope.root(), uri);
    if (where.ok()) {
        fs_state.resolved[path] = where.path;
        return true;
    }
    if (!where.missing && fs_state.refused.empty()) fs_state.refused = scope.refusal("buffer uri", uri, where);
    return false;
}

std::string keep_path(const std::string& path, void*) { return path; }

bool scoped_read_file(std::vector<unsigned char>* out, std::string* err, const std::string& path, void* user) {
    ScopedFs& fs_state = *static_cast<ScopedFs*>(user);
    const auto it = fs_state.resolved.find(path);
    if (it == fs_state.resolved.end()) {
        if (err) *err += "not resolved: " + path;
        return false;
    }
    try {
        *out = read_regular_file(it->second, scene_detail::kMaxFileBytes);
        std::string why;
        if (!fs_state.scope->charge(out->size(), why)) {
            out->clear();
            if (fs_state.refused.empty()) fs_state.refused = printable(fs_state.scope->model()) + ": " + why;
            if (err) *err += why;
            return false;
        }
    } catch (const LoadError& e) {
        if (err) *err += e.what();
        return false;
    }
    return true;
}

bool refuse_write(std::string* err, const std::string&, const std::vector<unsigned char>&, void*) {
    if (err) *err += "writing is disabled";
    return false;
}

// ---- Pre-checks of the raw bytes

std::uint32_t le32(const unsigned char* p) {
    return std::uint32_t(p[0]) | std::uint32_t(p[1]) << 8 | std::uint32_t(p[2]) << 16 |
           std::uint32_t(p[3]) << 24;
}

// Checks the GLB header and chunk layout; returns the length tinygltf may read.
std::size_t check_glb(const std::vector<unsigned char>& b, const std::string& path) {
    if (b.size() < 20) throw LoadError(path + ": truncated .glb header");
    if (std::memcmp(b.data(), "glTF", 4) != 0) throw LoadError(path + ": not a binary glTF (bad magic)");
    const std::uint32_t version = le32(&b[4]), length = le32(&b[8]);
    const std::uint64_t json_length = le32(&b[12]);
    if (version != 2)
        throw LoadError(path + ": unsupported binary glTF version " + std::to_string(version));
    if (length > b.size())
        throw LoadError(path + ": truncated .glb (header says " + std::to_string(length) +
                        " bytes, file has " + std::to_string(b.size()) + ")");
    if (length < 20 || 20 + json_length > length || json_length == 0)
        throw LoadError(path + ": bad .glb JSON chunk length");
    if (le32(&b[16]) != 0x4E4F534A) throw LoadError(path + ": .glb does not start with a JSON chunk");
    const std::uint64_t bin = 20 + json_length;
    if (bin < length) {
        if (bin + 8 > length) throw LoadError(path + ": truncated .glb chunk header");
        const std::uint64_t bin_length = le32(&b[std::size_t(bin)]);
        if (bin + 8 + bin_length > length)
            throw LoadError(path + ": .glb BIN chunk longer than the file");
    }
    return length;
}

// True when the JSON string token s[0, n) (quotes included) is the key
// `name`, however it is escaped.
bool key_is(const char* s, std::size_t n, const std::string& name) {
    if (std::memchr(s, '\\', n) == nullptr)
        return n == name.size() + 2 && std::memcmp(s + 1, name.data(), name.size()) == 0;
    const nlohmann::json decoded = nlohmann::json::parse(s, s + n, nullptr, false);
    return decoded.is_string() && decoded.get<std::string>() == name;
}

// What is checked before tinygltf loads any buffer, from the top-level object:
// the "extensionsRequired" array as tinygltf will read it (a non-string entry
// is ""), and the texts of the "asset" object and the "samplers" array (the
// samplers' enums as the file writes them: tinygltf keeps the low 32 bits of
// an integer).
struct TopLevel {
    std::vector<std::string> required;
    std::string asset, samplers;  // JSON text, empty when absent
};

// Refuses JSON nested deeper than kMaxJsonDepth (strings are skipped), and
// returns the TopLevel parts; none when the text does not even balance its
// brackets. The last of repeated keys counts, as in tinygltf's parser.
TopLevel check_json(const char* s, std::size_t n, const std::string& path) {
    static const std::string kKeys[] = {"extensionsRequired", "asset", "samplers"};
    constexpr int kNone = -1;
    int depth = 0;
    bool in_string = false;
    std::size_t string_begin = 0, key_begin = 0, key_end = 0;  // the last string closed in the root object
    int key_next = kNone;                                      // after one of kKeys and ':'
    int open_key = kNone;                                      // the kKeys value being scanned
    std::size_t value_begin = 0;
    std::pair<std::size_t, std::size_t> spans[3] = {};
    for (std::size_t i = 0; i < n; ++i) {
        const char c = s[i];
        if (in_string) {
            if (c == '\\') {
                ++i;
            } else if (c == '"') {
                in_string = false;
                if (depth == 1) key_begin = string_begin, key_end = i + 1;
            }
        } else if (c == '"') {
            in_string = true;
            string_begin = i;
            key_next = kNone;
        } else if (c == ':') {
            key_next = kNone;
            if (depth == 1 && key_end > key_begin)
                for (int k = 0; k < 3; ++k)
                    if (key_is(s + key_begin, key_end - key_begin, kKeys[k])) key_next = k;
        } else if (c == '{' || c == '[') {
            if (++depth > kMaxJsonDepth) throw LoadError(path + ": JSON nested too deeply");
            // extensionsRequired and samplers are arrays, asset an object.
            if (depth == 2 && key_next != kNone && (c == '[') == (key_next != 1)) {
                open_key = key_next;
                value_begin = i;
            }
            key_next = kNone;
        } else if (c == '}' || c == ']') {
            if (depth == 2 && open_key != kNone) {
                spans[open_key] = {value_begin, i + 1};
                open_key = kNone;
            }
            --depth;
        } else if (c != ' ' && c != '\t' && c != '\n' && c != '\r') {
            key_next = kNone;
        }
    }
    TopLevel top;
    if (in_string || depth != 0) return top;
    if (spans[1].second > 0) top.asset.assign(s + spans[1].first, s + spans[1].second);
    if (spans[2].second > 0) top.samplers.assign(s + spans[2].first, s + spans[2].second);
    if (spans[0].second == 0) return top;
    const nlohmann::json array = nlohmann::json::parse(s + spans[0].first, s + spans[0].second, nullptr, false);
    if (!array.is_array()) return top;
    for (const nlohmann::json& e : array) top.required.push_back(e.is_string() ? e.get<std::string>() : std::string());
    return top;
}

// The extensions prast implements: a file may require these (and only these).
// Others it uses optionally are ignored with a warning where they appear.
bool implemented_extension(const std::string& ext) {
    static const char* const kImplemented[] = {
        "EXT_meshopt_compression",
        "EXT_texture_webp",
        "KHR_draco_mesh_compression",
        "KHR_lights_punctual",
        "KHR_materials_clearcoat",
        "KHR_materials_emissive_strength",
        "KHR_materials_ior",
        "KHR_materials_pbrSpecularGlossiness",  // converted to metal-rough at load
        "KHR_materials_sheen",
        "KHR_materials_specular",
        "KHR_materials_transmission",
        "KHR_materials_unlit",
        "KHR_materials_variants",
        "KHR_materials_volume",
        "KHR_meshopt_compression",  // its version-0 streams: EXT_meshopt_compression's bitstream
        "KHR_mesh_quantization",
        "KHR_texture_transform",
    };
    for (const char* e : kImplemented)
        if (ext == e) return true;
    return false;
}

// A glTF version string "MAJOR.MINOR" (glTF 2.0, "Asset": each a decimal of
// one to nine digits without leading zeros); false when `s` is not one.
bool parse_version(const std::string& s, unsigned long& major, unsigned long& minor) {
    const std::size_t dot = s.find('.');
    if (dot == std::string::npos) return false;
    const auto number = [](const std::string& part, unsigned long& out) {
        if (part.empty() || part.size() > 9 || (part.size() > 1 && part[0] == '0')) return false;
        for (char ch : part)
            if (ch < '0' || ch > '9') return false;
        out = std::stoul(part);
        return true;
    };
    return number(s.substr(0, dot), major) && number(s.substr(dot + 1), minor);
}

std::string first_line(const std::string& s, const char* fallback) {
    const std::size_t begin = s.find_first_not_of(" \t\r\n");
    if (begin == std::string::npos) return fallback;
    const std::size_t end = s.find_first_of("\r\n", begin);
    return s.substr(begin, end == std::string::npos ? std::string::npos : end - begin);
}

// Percent-decoding of a relative URI into a file name.
std::string decode_uri(const std::string& uri) {
    auto hex = [](char c) -> int {
        if (c >= '0' && c <= '9') return c - '0';
        if (c >= 'a' && c <= 'f') return c - 'a' + 10;
        if (c >= 'A' && c <= 'F') return c - 'A' + 10;
        return -1;
    };
    std::string out;
    for (std::size_t i = 0; i < uri.size(); ++i) {
        if (uri[i] == '%' && i + 2 < uri.size() && hex(uri[i + 1]) >= 0 && hex(uri[i + 2]) >= 0) {
            out += char(hex(uri[i + 1]) * 16 + hex(uri[i + 2]));
            i += 2;
        } else {
            out += uri[i];
        }
    }
    return out;
}

// The bytes of base64 text from `begin` on (RFC 4648; stops at '=' or the
// end, "" at a character outside the alphabet).
std::string base64_bytes(const std::string& text, std::size_t begin) {
    std::string out;
    std::uint32_t bits = 0;
    int count = 0;
    for (std::size_t i = begin; i < text.size() && text[i] != '='; ++i) {
        const char c = text[i];
        int v = -1;
        if (c >= 'A' && c <= 'Z') v = c - 'A';
        else if (c >= 'a' && c <= 'z') v = c - 'a' + 26;
        else if (c >= '0' && c <= '9') v = c - '0' + 52;
        else if (c == '+') v = 62;
        else if (c == '/') v = 63;
        if (v < 0) return "";
        bits = bits << 6 | std::uint32_t(v);
        if (++count == 4) {
            out += char(bits >> 16 & 255);
            out += char(bits >> 8 & 255);
            out += char(bits & 255);
            bits = 0;
            count = 0;
        }
    }
    if (count == 2) out += char(bits >> 4 & 255);
    if (count == 3) {
        out += char(bits >> 10 & 255);
        out += char(bits >> 2 & 255);
    }
    return out;
}

int type_components(int type) {
    switch (type) {
    case TINYGLTF_TYPE_SCALAR: return 1;
    case TINYGLTF_TYPE_VEC2: return 2;
    case TINYGLTF_TYPE_VEC3: return 3;
    case TINYGLTF_TYPE_VEC4: return 4;
    default: return 0;
    }
}

bool finite_values(const std::vector<double>& v) {
    return std::all_of(v.begin(), v.end(), [](double x) { return std::isfinite(x); });
}

// Converted specular-glossiness textures are float RGBA, 16 bytes a texel:
// at most a 2048 x 2048 texture's worth each.
constexpr std::int64_t kMaxBakeTexels = std::int64_t(1) << 22;

// A metal-rough material (prast's BRDF, docs/conventions.md "Shading": F0 =
// mix(f0(ior), albedo, metallic), diffuse = (1 - F) (1 - metallic) albedo,
// alpha = roughness^2) for specular-glossiness values (the extension: F0 =
// specular, diffuse = (1 - F) c_diff with c_diff = diffuse (1 - max(specular)),
// alpha = (1 - glossiness)^2).
struct MetalRough {
    glm::dvec3 base{1.0};
    double metallic = 0.0, roughness = 1.0, ior = 1.5;
};

// roughness = 1 - glossiness always (the same alpha). The rest:
//  - no diffuse light (c_diff = 0): metallic 1, base = specular: exact;
//  - a grey specular s < 1 and `exact_ior`: metallic 0, base = c_diff and
//    ior = (1 + sqrt(s)) / (1 - sqrt(s)), so that f0(ior) = s: exact;
//  - otherwise (a coloured specular over a diffuse colour) no metal-rough
//    material matches: ior 1.5 (f0 0.04), and metallic is solved on perceived
//    brightness b(c) = sqrt(0.299 r^2 + 0.587 g^2 + 0.114 b^2) as the
//    extension's conversion example does, with prast's diffuse term:
//    0.04 m^2 + (b(c_diff) + b(S) - 0.08) m + (0.04 - b(S)) = 0 (0 when
//    b(S) < 0.04); base = mix(c_diff / (1 - m), (S - 0.04 (1 - m)) / m, m^2),
//    clamped to [0, 1]. Exact only where the two agree (S = 0.04 grey).
MetalRough specular_glossiness_to_metal_rough(const glm::dvec3& diffuse, const glm::dvec3& specular,
                                              double glossiness, bool exact_ior) {
    MetalRough out;
    out.roughness = std::clamp(1.0 - glossiness, 0.0, 1.0);
    const double strongest = std::max({specular.r, specular.g, specular.b});
    const glm::dvec3 c_diff = diffuse * (1.0 - strongest);
    if (c_diff == glm::dvec3(0.0)) {
        out.metallic = 1.0;
        out.base = specular;
        return out;
    }
    if (exact_ior && specular.r == specular.g && specular.g == specular.b && strongest < 1.0) {
        const double r = std::sqrt(strongest);
        out.ior = (1.0 + r) / (1.0 - r);
        out.base = c_diff;
        return out;
    }
    constexpr double kF0 = 0.04;
    const auto brightness = [](const glm::dvec3& c) {
        return std::sqrt(0.299 * c.r * c.r + 0.587 * c.g * c.g + 0.114 * c.b * c.b);
    };
    const double bd = brightness(c_diff), bs = brightness(specular);
    double m = 0.0;
    if (bs >= kF0) {
        const double a = kF0, b = bd + bs - 2.0 * kF0, c = kF0 - bs;
        m = std::clamp((-b + std::sqrt(std::max(b * b - 4.0 * a * c, 0.0))) / (2.0 * a), 0.0, 1.0);
    }
    const glm::dvec3 from_diffuse = c_diff / std::max(1.0 - m, 1e-6);
    const glm::dvec3 from_specular = (specular - glm::dvec3(kF0 * (1.0 - m))) / std::max(m, 1e-6);
    out.metallic = m;
    out.base = glm::clamp(glm::mix(from_diffuse, from_specular, m * m), 0.0, 1.0);
    return out;
}

Wrap wrap_mode(int mode, bool& known) {
    known = true;
    switch (mode) {
    case TINYGLTF_TEXTURE_WRAP_CLAMP_TO_EDGE: return Wrap::ClampToEdge;
    case TINYGLTF_TEXTURE_WRAP_MIRRORED_REPEAT: return Wrap::MirroredRepeat;
    case TINYGLTF_TEXTURE_WRAP_REPEAT: return Wrap::Repeat;
    default: known = false; return Wrap::Repeat;
    }
}

class GltfLoader {
public:
    GltfLoader(const std::string& path, const LoadOptions& options)
        : path_(path), shown_(printable(path)), scope_(path, options.allow_outside_paths) {}

    Scene load() {
        parse();
        check_required_extensions();
        decode_meshopt_views();
        decode_draco_primitives();
        image_map_.assign(model_.images.size(), kNotYet);
        for (std::size_t i = 0; i < model_.materials.size(); ++i)
            scene_.materials.push_back(convert_material(model_.materials[i], i));
        read_variants();
        traverse_scene();
        GltfGraphContext graph{shown_, elements_, zero_filled_, [this](const std::string& w) { warn(w); }};
        read_gltf_graph(model_, scene_, graph);  // skins, morph targets, animations, cameras
        scene_.warnings = log_.lines();
        scene_detail::finish_scene(scene_, path_);
        pose_scene(scene_, 0.0, kNoAnimation);  // the rest pose: skins and default morph weights applied
        return std::move(scene_);
    }

private:
    static constexpr int kNotYet = -2;

    // The texCoord values as the file writes them, by "material/parent/key";
    // read only for file_texcoord().
    bool texcoords_read_ = false;
    std::map<std::string, std::string> texcoords_;

    // The "samplers" array's text from check_json, parsed on first use.
    std::string samplers_json_;
    bool samplers_parsed_ = false;
    nlohmann::json raw_samplers_;

    // Messages hold names from the file: escaped here, once for all.
    [[noreturn]] void fail(const std::string& why) const { throw LoadError(shown_ + ": " + printable(why)); }
    void warn(const std::string& what) { log_.add(shown_ + ": " + printable(what)); }
    void warn_once(const std::string& what) {
        if (warned_.insert(what).second) warn(what);
    }

    // ---- Parsing (tinygltf)

    void parse() {
        std::vector<unsigned char> bytes = scene_detail::read_file(path_);
        const bool glb = bytes.size() >= 4 && std::memcmp(bytes.data(), "glTF", 4) == 0;
        if (!glb && scene_detail::extension_lower(path_) == ".glb")
            fail("not a binary glTF (bad magic)");

        tinygltf::TinyGLTF ctx;
        ctx.SetImageLoader(&keep_encoded_image, nullptr);
        ScopedFs fs_state;
        fs_state.scope = &scope_;
        tinygltf::FsCallbacks callbacks;
        callbacks.FileExists = &scoped_file_exists;
        callbacks.ExpandFilePath = &keep_path;
        callbacks.ReadWholeFile = &scoped_read_file;
        callbacks.WriteWholeFile = &refuse_write;
        callbacks.user_data = &fs_state;
        ctx.SetFsCallbacks(callbacks);

        base_dir_ = scope_.root();
        std::string err, warnings;
        bool ok = false;
        if (glb) {
            check_glb(bytes, shown_);
            check_top_level(check_json(reinterpret_cast<const char*>(&bytes[20]), le32(&bytes[12]), shown_));
            stand_in_fallbacks(bytes, true);
            const std::size_t length = check_glb(bytes, shown_);
            ok = ctx.LoadBinaryFromMemory(&model_, &err, &warnings, bytes.data(),
                                          static_cast<unsigned int>(length), base_dir_);
        } else {
            check_top_level(check_json(reinterpret_cast<const char*>(bytes.data()), bytes.size(), shown_));
            stand_in_fallbacks(bytes, false);
            ok = ctx.LoadASCIIFromString(&model_, &err, &warnings,
                                         reinterpret_cast<const char*>(bytes.data()),
                                         static_cast<unsigned int>(bytes.size()), base_dir_);
        }
        if (!ok && !fs_state.refused.empty()) throw LoadError(fs_state.refused);
        if (!ok) fail(cut(first_line(err, "cannot parse glTF"), kMaxLineChars));

        // tinygltf's warnings, except the missing images that image_for() reports.
        std::size_t start = 0;
        while (start < warnings.size()) {
            std::size_t end = warnings.find('\n', start);
            if (end == std::string::npos) end = warnings.size();
            const std::string line = warnings.substr(start, end - start);
            start = end + 1;
            if (line.empty() || line.rfind("File not found", 0) == 0 ||
                line.rfind("Failed to load external 'uri' for image", 0) == 0)
                continue;
            warn_once(cut(line, kMaxLineChars));
        }
    }

    // Before tinygltf reads anything else: a model that needs what is not
    // supported (a newer glTF, an extension) is refused naming that, not for
    // what its buffers lack (a compressed model's fallback buffer has no uri).
    void check_top_level(const TopLevel& top) {
        check_min_version(top.asset);
        for (const std::string& ext : top.required)
            if (!implemented_extension(ext)) fail("required extension " + cut(ext) + " is not supported");
        samplers_json_ = top.samplers;
    }

    // glTF 2.0, "Asset": a client MUST support asset.minVersion to load the
    // asset; prast implements 2.0.
    void check_min_version(const std::string& asset_text) const {
        if (asset_text.empty()) return;
        const nlohmann::json asset = nlohmann::json::parse(asset_text, nullptr, false);
        if (!asset.is_object()) return;  // tinygltf names the problem
        const auto it = asset.find("minVersion");
        if (it == asset.end()) return;
        if (!it->is_string()) fail("asset.minVersion is not a version string");
        const std::string v = it->get<std::string>();
        unsigned long major = 0, minor = 0;
        if (!parse_version(v, major, minor))
            fail("asset.minVersion '" + cut(v) + "' is not a glTF version (MAJOR.MINOR)");
        if (major > 2 || (major == 2 && minor > 0))
            fail("asset.minVersion " + v + " is required, prast loads glTF 2.0");
    }

    // ---- EXT_meshopt_compression (and KHR_meshopt_compression)

    // A file using meshopt compression may have buffers without a uri (the
    // fallback that only a decoder fills, as gltfpack writes them; in a .glb
    // any but buffer 0, the BIN chunk). tinygltf refuses those, so each gets a
    // one-byte stand-in before parsing and its byteLength is kept here; the
    // JSON is rewritten only then, other files reach tinygltf unchanged.
    // Likewise tinygltf refuses a primitive whose indices accessor has no
    // bufferView, which is how KHR_draco_mesh_compression primitives are
    // written: such an accessor gets the Draco bufferView (or view 0) as a
    // stand-in, taken away again after parsing (decode_draco_primitives).
    void stand_in_fallbacks(std::vector<unsigned char>& bytes, bool glb) {
        static const std::string kMeshopt = "_meshopt_compression", kDraco = "KHR_draco_mesh_compression";
        const bool meshopt_named = std::search(bytes.begin(), bytes.end(), kMeshopt.begin(), kMeshopt.end()) != bytes.end();
        const bool draco_named = std::search(bytes.begin(), bytes.end(), kDraco.begin(), kDraco.end()) != bytes.end();
        if (!meshopt_named && !draco_named) return;
        const std::size_t begin = glb ? 20 : 0, length = glb ? le32(&bytes[12]) : bytes.size();
        nlohmann::json doc = nlohmann::json::parse(bytes.begin() + std::ptrdiff_t(begin),
                                                   bytes.begin() + std::ptrdiff_t(begin + length), nullptr, false);
        if (!doc.is_object()) return;  // tinygltf names the problem
        const auto used = doc.find("extensionsUsed");
        if (used == doc.end() || !used->is_array()) return;
        bool meshopt = false, draco = false;
        for (const nlohmann::json& e : *used) {
            meshopt = meshopt || e == "EXT_meshopt_compression" || e == "KHR_meshopt_compression";
            draco = draco || e == "KHR_draco_mesh_compression";
        }
        bool changed = draco && stand_in_draco_indices(doc);
        const auto buffers = doc.find("buffers");
        if (meshopt && buffers != doc.end() && buffers->is_array())
        for (std::size_t i = glb ? 1 : 0; i < buffers->size(); ++i) {
            nlohmann::json& b = (*buffers)[i];
            if (!b.is_object() || b.contains("uri")) continue;
            const auto bl = b.find("byteLength");
            if (bl == b.end() || !bl->is_number_unsigned()) continue;  // tinygltf names the problem
            fallback_lengths_[i] = bl->get<std::uint64_t>();
            b["uri"] = kStandInUri;
            b["byteLength"] = 1;
            changed = true;
        }
        if (!changed) return;
        std::string text = doc.dump();
        if (!glb) {
            bytes.assign(text.begin(), text.end());
            return;
        }
        while (text.size() % 4) text += ' ';  // GLB chunks are 4-byte aligned
        const std::size_t file_length = le32(&bytes[8]);
        std::vector<unsigned char> out(bytes.begin(), bytes.begin() + 20);
        out.insert(out.end(), text.begin(), text.end());
        out.insert(out.end(), bytes.begin() + std::ptrdiff_t(begin + length), bytes.begin() + std::ptrdiff_t(file_length));
        const auto put32 = [&](std::size_t at, std::size_t v) {
            for (int k = 0; k < 4; ++k) out[at + std::size_t(k)] = static_cast<unsigned char>(v >> (8 * k));
        };
        put32(8, out.size());
        put32(12, text.size());
        bytes = std::move(out);
    }

    bool stand_in_draco_indices(nlohmann::json& doc) {
        const auto meshes = doc.find("meshes"), accessors = doc.find("accessors"), views = doc.find("bufferViews");
        if (meshes == doc.end() || !meshes->is_array() || accessors == doc.end() || !accessors->is_array() ||
            views == doc.end() || !views->is_array() || views->empty())
            return false;
        bool changed = false;
        for (nlohmann::json& mesh : *meshes) {
            if (!mesh.is_object() || !mesh.contains("primitives") || !mesh["primitives"].is_array()) continue;
            for (nlohmann::json& prim : mesh["primitives"]) {
                if (!prim.is_object() || !prim.contains("indices") || !prim["indices"].is_number_unsigned() ||
                    !prim.contains("extensions") || !prim["extensions"].is_object() ||
                    !prim["extensions"].contains("KHR_draco_mesh_compression"))
                    continue;
                const std::uint64_t a = prim["indices"].get<std::uint64_t>();
                if (a >= accessors->size() || !(*accessors)[a].is_object() || (*accessors)[a].contains("bufferView")) continue;
                const nlohmann::json& ext = prim["extensions"]["KHR_draco_mesh_compression"];
                std::uint64_t view = 0;
                if (ext.is_object() && ext.contains("bufferView") && ext["bufferView"].is_number_unsigned() &&
                    ext["bufferView"].get<std::uint64_t>() < views->size())
                    view = ext["bufferView"].get<std::uint64_t>();
                (*accessors)[a]["bufferView"] = view;
                draco_stand_ins_.insert(std::size_t(a));
                changed = true;
            }
        }
        return changed;
    }

    // Every bufferView with the extension decoded into a buffer of its own
    // (the view then points at it), so that accessors, images and the graph
    // read it as any other. Checked first: the extension's rules, the source
    // range, that the stream can hold what it claims (meshopt::min_encoded_size,
    // before the output is allocated) and kMaxDecodedBytes. A stream that does
    // not decode is refused naming the extension, unless the view's own buffer
    // holds the uncompressed data (then a warning and that data).
    void decode_meshopt_views() {
        std::set<std::size_t> stand_ins;
        for (const auto& [i, bytes] : fallback_lengths_) {
            (void)bytes;
            if (i < model_.buffers.size()) {
                model_.buffers[i].data.clear();
                stand_ins.insert(i);
            }
        }
        const std::size_t original_buffers = model_.buffers.size();
        for (std::size_t v = 0; v < model_.bufferViews.size(); ++v) {
            tinygltf::BufferView& bv = model_.bufferViews[v];
            const char* name = "EXT_meshopt_compression";
            auto ext = bv.extensions.find(name);
            if (ext == bv.extensions.end()) {
                name = "KHR_meshopt_compression";
                ext = bv.extensions.find(name);
            }
            if (ext == bv.extensions.end()) {
                if (bv.buffer >= 0 && stand_ins.count(std::size_t(bv.buffer)))
                    fail("bufferView " + std::to_string(v) + ": buffer " + std::to_string(bv.buffer) +
                         " is a uri-less meshopt fallback (no data), and the bufferView has no "
                         "EXT_meshopt_compression to decode");
                continue;
            }
            decode_meshopt_view(v, name, ext->second, stand_ins, original_buffers);
        }
    }

    void decode_meshopt_view(std::size_t v, const std::string& name, const tinygltf::Value& e,
                             const std::set<std::size_t>& stand_ins, std::size_t original_buffers) {
        tinygltf::BufferView& bv = model_.bufferViews[v];
        const std::string what = "bufferView " + std::to_string(v) + ": " + name;
        if (!e.IsObject()) fail(what + ": not an object");
        const auto integer = [&](const char* key, bool required, std::uint64_t fallback) -> std::uint64_t {
            const tinygltf::Value& x = e.Get(key);
            if (x.Type() == tinygltf::NULL_TYPE) {
                if (required) fail(what + ": no " + key);
                return fallback;
            }
            const double d = x.IsNumber() ? x.GetNumberAsDouble() : -1.0;
            if (!(d >= 0.0 && d <= 9007199254740992.0 && d == std::floor(d)))
                fail(what + ": " + key + " is not a non-negative integer");
            return std::uint64_t(d);
        };
        const auto text = [&](const char* key, const char* fallback) -> std::string {
            const tinygltf::Value& x = e.Get(key);
            if (x.Type() == tinygltf::NULL_TYPE) {
                if (!fallback) fail(what + ": no " + key);
                return fallback;
            }
            if (!x.IsString()) fail(what + ": " + key + " is not a string");
            return x.Get<std::string>();
        };
        const std::uint64_t buffer = integer("buffer", true, 0), offset = integer("byteOffset", false, 0),
                            length = integer("byteLength", true, 0), stride = integer("byteStride", true, 0),
                            count = integer("count", true, 0);
        const std::string mode_name = text("mode", nullptr), filter_name = text("filter", "NONE");
        meshopt::Mode mode = meshopt::Mode::Attributes;
        if (mode_name == "TRIANGLES") mode = meshopt::Mode::Triangles;
        else if (mode_name == "INDICES") mode = meshopt::Mode::Indices;
        else if (mode_name != "ATTRIBUTES")
            fail(what + ": mode '" + cut(mode_name) + "' is not ATTRIBUTES, TRIANGLES or INDICES");
        meshopt::Filter filter = meshopt::Filter::None;
        if (filter_name == "OCTAHEDRAL") filter = meshopt::Filter::Octahedral;
        else if (filter_name == "QUATERNION") filter = meshopt::Filter::Quaternion;
        else if (filter_name == "EXPONENTIAL") filter = meshopt::Filter::Exponential;
        else if (filter_name == "COLOR") fail(what + ": filter COLOR is not supported");
        else if (filter_name != "NONE")
            fail(what + ": filter '" + cut(filter_name) + "' is not NONE, OCTAHEDRAL, QUATERNION or EXPONENTIAL");
        // The extension's rules, which also keep count * stride from overflowing.
        if (count > kMaxAccessorCount) fail(what + ": absurd count " + std::to_string(count));
        if (mode == meshopt::Mode::Attributes) {
            if (stride == 0 || stride % 4 != 0 || stride > 256)
                fail(what + ": byteStride " + std::to_string(stride) + " (ATTRIBUTES need a multiple of 4 up to 256)");
        } else {
            if (stride != 2 && stride != 4)
                fail(what + ": byteStride " + std::to_string(stride) + " (" + mode_name + " need 2 or 4)");
            if (filter != meshopt::Filter::None) fail(what + ": a filter on " + mode_name);
            if (mode == meshopt::Mode::Triangles && count % 3 != 0)
                fail(what + ": count " + std::to_string(count) + " is not a multiple of 3 (TRIANGLES)");
        }
        if ((filter == meshopt::Filter::Octahedral && stride != 4 && stride != 8) ||
            (filter == meshopt::Filter::Quaternion && stride != 8))
            fail(what + ": byteStride " + std::to_string(stride) + " does not suit filter " + filter_name);
        if (bv.byteStride != 0 && bv.byteStride != stride)
            fail(what + ": byteStride " + std::to_string(stride) + " differs from the bufferView's " +
                 std::to_string(bv.byteStride));
        if (std::uint64_t(bv.byteLength) != count * stride)
            fail(what + ": count " + std::to_string(count) + " times byteStride " + std::to_string(stride) +
                 " is not the bufferView's byteLength " + std::to_string(bv.byteLength));
        if (buffer >= original_buffers || stand_ins.count(std::size_t(buffer)))
            fail(what + ": buffer " + std::to_string(buffer) + (buffer >= original_buffers ? " out of range" : " has no data"));
        const std::vector<unsigned char>& src = model_.buffers[std::size_t(buffer)].data;
        if (offset > src.size() || length > src.size() - offset)
            fail(what + ": byteOffset " + std::to_string(offset) + " + byteLength " + std::to_string(length) +
                 " exceeds buffer " + std::to_string(buffer) + " (" + std::to_string(src.size()) + " bytes)");
        // Before allocating: can these bytes hold what the file claims?
        const std::size_t least = meshopt::min_encoded_size(mode, std::size_t(count), std::size_t(stride));
        std::string why;
        tinygltf::Buffer decoded;
        if (length < least) {
            why = std::to_string(length) + " compressed bytes cannot hold " + std::to_string(count) +
                  " elements of " + std::to_string(stride) + " bytes (at least " + std::to_string(least) + " needed)";
        } else {
            decoded_bytes_ += bv.byteLength;
            if (decoded_bytes_ > kMaxDecodedBytes)
                fail(what + ": decoding brings the model's decompressed data to " + std::to_string(decoded_bytes_) +
                     " bytes, more than the limit of " + std::to_string(kMaxDecodedBytes) + " (2 GiB)");
            decoded.data.resize(bv.byteLength);
            why = meshopt::decode(mode, filter, src.data() + offset, std::size_t(length), std::size_t(count),
                                  std::size_t(stride), decoded.data.data());
        }
        if (!why.empty()) {
            const bool has_fallback = bv.buffer >= 0 && std::size_t(bv.buffer) < original_buffers &&
                                      !stand_ins.count(std::size_t(bv.buffer)) &&
                                      bv.byteOffset <= model_.buffers[std::size_t(bv.buffer)].data.size() &&
                                      bv.byteLength <= model_.buffers[std::size_t(bv.buffer)].data.size() - bv.byteOffset;
            if (!has_fallback) fail(what + ": cannot decode: " + why);
            warn(what + ": cannot decode (" + why + "), its uncompressed fallback data used");
            return;
        }
        model_.buffers.push_back(std::move(decoded));
        bv.buffer = int(model_.buffers.size()) - 1;
        bv.byteOffset = 0;
    }

    // ---- KHR_draco_mesh_compression

    // Each primitive with the extension decoded once (however many nodes
    // draw its mesh) into a buffer of its own: its accessors and indices then
    // point at views of it, and are read as any other. Before libdraco sees
    // the stream, its header's face and vertex counts are held to the
    // indices' and POSITION accessors' counts (each within kMaxSceneElements),
    // so that a hostile count is refused before anything is allocated for it;
    // after decoding, every accessor's count, type and componentType must be
    // the decoded attribute's. A primitive that does not decode is refused
    // naming the extension, unless all its accessors have uncompressed data.
    void decode_draco_primitives() {
        for (std::size_t a : draco_stand_ins_)
            if (a < model_.accessors.size()) model_.accessors[a].bufferView = -1;
        for (std::size_t m = 0; m < model_.meshes.size(); ++m)
            for (std::size_t p = 0; p < model_.meshes[m].primitives.size(); ++p) {
                tinygltf::Primitive& prim = model_.meshes[m].primitives[p];
                const auto ext = prim.extensions.find("KHR_draco_mesh_compression");
                if (ext == prim.extensions.end()) continue;
                const std::string what = "mesh " + std::to_string(m) + " primitive " + std::to_string(p) +
                                         ": KHR_draco_mesh_compression";
                std::string why;
                if (decode_draco(prim, ext->second, what, why)) continue;
                bool fallback = prim.indices >= 0;
                for (const auto& [name, index] : prim.attributes) {
                    (void)name;
                    fallback = fallback && index >= 0 && std::size_t(index) < model_.accessors.size() &&
                               model_.accessors[std::size_t(index)].bufferView >= 0;
                }
                if (prim.indices >= 0 && std::size_t(prim.indices) < model_.accessors.size())
                    fallback = fallback && model_.accessors[std::size_t(prim.indices)].bufferView >= 0;
                if (!fallback) fail(what + ": " + why);
                warn(what + ": " + why + "; its uncompressed accessors used");
            }
    }

    // False with `why` when the primitive cannot be decoded; a JSON error fails.
    bool decode_draco(tinygltf::Primitive& prim, const tinygltf::Value& e, const std::string& what, std::string& why) {
        if (!e.IsObject() || !e.Get("bufferView").IsNumber() || !e.Get("attributes").IsObject())
            fail(what + ": needs a bufferView and an attributes object");
        const double view_number = e.Get("bufferView").GetNumberAsDouble();
        if (!(view_number >= 0.0 && view_number < double(model_.bufferViews.size()) && view_number == std::floor(view_number)))
            fail(what + ": bufferView " +
                 (std::fabs(view_number) < 1e15 && view_number == std::floor(view_number)
                      ? std::to_string(std::int64_t(view_number)) : std::to_string(view_number)) +
                 " out of range (" + std::to_string(model_.bufferViews.size()) + " bufferViews)");
        const tinygltf::BufferView& bv = model_.bufferViews[std::size_t(view_number)];
        if (bv.buffer < 0 || std::size_t(bv.buffer) >= model_.buffers.size() ||
            bv.byteOffset > model_.buffers[std::size_t(bv.buffer)].data.size() ||
            bv.byteLength > model_.buffers[std::size_t(bv.buffer)].data.size() - bv.byteOffset)
            fail(what + ": bufferView " + std::to_string(std::size_t(view_number)) + " exceeds its buffer");
        const unsigned char* data = model_.buffers[std::size_t(bv.buffer)].data.data() + bv.byteOffset;
        // The attributes it decodes: glTF name -> Draco unique id, each with its accessor.
        struct Wanted {
            std::string name;
            int id = -1, accessor = -1;
        };
        std::vector<Wanted> wanted;
        const tinygltf::Value& attrs = e.Get("attributes");
        for (const std::string& key : attrs.Keys()) {
            const tinygltf::Value& id = attrs.Get(key);
            const double d = id.IsNumber() ? id.GetNumberAsDouble() : -1.0;
            if (!(d >= 0.0 && d <= 2147483647.0 && d == std::floor(d)))
                fail(what + ": attribute " + cut(key) + " has no Draco id (a non-negative integer)");
            const auto it = prim.attributes.find(key);
            if (it == prim.attributes.end() || it->second < 0 || std::size_t(it->second) >= model_.accessors.size())
                fail(what + ": attribute " + cut(key) + " has no accessor in the primitive");
            wanted.push_back({key, int(d), it->second});
        }
        const auto position = std::find_if(wanted.begin(), wanted.end(), [](const Wanted& w) { return w.name == "POSITION"; });
        if (position == wanted.end()) fail(what + ": no POSITION among its attributes");
        if (prim.indices < 0 || std::size_t(prim.indices) >= model_.accessors.size())
            fail(what + ": the primitive needs an indices accessor");
        const int mode = prim.mode == -1 ? TINYGLTF_MODE_TRIANGLES : prim.mode;
        if (mode != TINYGLTF_MODE_TRIANGLES) fail(what + ": only TRIANGLES primitives (mode 4) are supported");
        tinygltf::Accessor& indices = model_.accessors[std::size_t(prim.indices)];
        const std::uint64_t points = model_.accessors[std::size_t(position->accessor)].count;
        if (points > scene_detail::kMaxSceneElements || indices.count > scene_detail::kMaxSceneElements)
            fail(what + ": accessor counts " + std::to_string(points) + " and " + std::to_string(indices.count) +
                 " exceed the limit of " + std::to_string(scene_detail::kMaxSceneElements) + " (2^27)");
        // The stream's own claims, before libdraco allocates for them.
        draco_gltf::Counts counts;
        why = draco_gltf::read_counts(data, bv.byteLength, counts);
        if (!why.empty()) return false;
        if (counts.faces * 3 != indices.count) {
            why = "the stream has " + std::to_string(counts.faces) + " faces, the indices accessor " +
                  std::to_string(indices.count) + " indices";
            return false;
        }
        if (counts.vertices > points) {
            why = "the stream has " + std::to_string(counts.vertices) + " vertices, POSITION " + std::to_string(points);
            return false;
        }
        why = draco_gltf::check_density(counts, bv.byteLength);
        if (!why.empty()) return false;
        // What the decoded data will take, against the model's decoding budget.
        std::uint64_t bytes = indices.count * 4;
        for (const Wanted& w : wanted) {
            const tinygltf::Accessor& a = model_.accessors[std::size_t(w.accessor)];
            bytes += a.count * std::uint64_t(std::max(1, type_components(a.type))) *
                     std::uint64_t(std::max<std::size_t>(1, component_size(a.componentType)));
        }
        decoded_bytes_ += bytes;
        if (decoded_bytes_ > kMaxDecodedBytes)
            fail(what + ": decoding brings the model's decompressed data to " + std::to_string(decoded_bytes_) +
                 " bytes, more than the limit of " + std::to_string(kMaxDecodedBytes) + " (2 GiB)");
        std::vector<int> ids;
        for (const Wanted& w : wanted) ids.push_back(w.id);
        draco_gltf::Mesh mesh;
        why = draco_gltf::decode(data, bv.byteLength, ids, mesh);
        if (!why.empty()) return false;
        // Everything checked against the accessors before any is changed.
        if (mesh.indices.size() != indices.count) {
            why = "decoded " + std::to_string(mesh.indices.size()) + " indices, the accessor has " +
                  std::to_string(indices.count);
            return false;
        }
        const int ict = indices.componentType;
        const std::uint64_t index_limit = ict == TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE ? 0xff
                                          : ict == TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT ? 0xffff
                                          : ict == TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT ? 0xffffffffu : 0;
        if (index_limit == 0) fail(what + ": indices componentType " + std::to_string(ict) + " (must be an unsigned integer)");
        if (mesh.points - (mesh.points ? 1 : 0) > index_limit) {
            why = std::to_string(mesh.points) + " points do not fit the indices' componentType";
            return false;
        }
        for (const Wanted& w : wanted) {
            const tinygltf::Accessor& a = model_.accessors[std::size_t(w.accessor)];
            const draco_gltf::Attribute& d = mesh.attributes.at(w.id);
            const std::string name = "attribute " + cut(w.name) + " (Draco id " + std::to_string(w.id) + ")";
            if (a.count != mesh.points) {
                why = name + ": accessor count " + std::to_string(a.count) + ", decoded " + std::to_string(mesh.points) + " points";
                return false;
            }
            if (d.components != type_components(a.type) || d.component_type != a.componentType) {
                why = name + ": decoded " + std::to_string(d.components) + " components of componentType " +
                      std::to_string(d.component_type) + ", the accessor has " + std::to_string(type_components(a.type)) +
                      " of " + std::to_string(a.componentType);
                return false;
            }
            if (a.sparse.isSparse) fail(what + ": " + name + ": a sparse accessor cannot be Draco-compressed");
        }
        // The decoded data in one new buffer, a view per accessor.
        tinygltf::Buffer out;
        const auto add_view = [&](const std::vector<unsigned char>& b, tinygltf::Accessor& a) {
            while (out.data.size() % 4) out.data.push_back(0);
            tinygltf::BufferView view;
            view.buffer = int(model_.buffers.size());
            view.byteOffset = out.data.size();
            view.byteLength = b.size();
            out.data.insert(out.data.end(), b.begin(), b.end());
            model_.bufferViews.push_back(view);
            a.bufferView = int(model_.bufferViews.size()) - 1;
            a.byteOffset = 0;
        };
        std::vector<unsigned char> packed(mesh.indices.size() * component_size(ict));
        for (std::size_t i = 0; i < mesh.indices.size(); ++i)
            for (std::size_t k = 0; k < component_size(ict); ++k)
                packed[i * component_size(ict) + k] = static_cast<unsigned char>(mesh.indices[i] >> (8 * k));
        add_view(packed, indices);
        for (const Wanted& w : wanted)
            add_view(mesh.attributes.at(w.id).bytes, model_.accessors[std::size_t(w.accessor)]);
        model_.buffers.push_back(std::move(out));
        return true;
    }

    void check_required_extensions() {
        for (const std::string& ext : model_.extensionsRequired)
            if (!implemented_extension(ext)) fail("required extension " + cut(ext) + " is not supported");
    }

    // ---- Accessors: every offset, stride and count checked before reading

    // The first byte of `count` elements of `elem` bytes starting at `offset`
    // in bufferView `view`, and the stride between them.
    const unsigned char* view_window(int view, std::size_t offset, std::size_t count,
                                     std::size_t elem, bool strided, std::size_t& stride,
                                     const std::string& what) const {
        if (view < 0 || std::size_t(view) >= model_.bufferViews.size())
            fail(what + ": bufferView " + std::to_string(view) + " out of range (" +
                 std::to_string(model_.bufferViews.size()) + " bufferViews)");
        const tinygltf::BufferView& bv = model_.bufferViews[std::size_t(view)];
        if (bv.buffer < 0 || std::size_t(bv.buffer) >= model_.buffers.size())
            fail(what + ": bufferView " + std::to_string(view) + ": buffer " +
                 std::to_string(bv.buffer) + " out of range");
        const std::vector<unsigned char>& data = model_.buffers[std::size_t(bv.buffer)].data;
        if (bv.byteOffset > data.size() || bv.byteLength > data.size() - bv.byteOffset)
            fail(what + ": bufferView " + std::to_string(view) + " exceeds its buffer");
        stride = strided && bv.byteStride != 0 ? bv.byteStride : elem;
        if (stride < elem) fail(what + ": byteStride smaller than an element");
        if (count == 0) return nullptr;
        // offset + (count - 1) * stride + elem <= byteLength, without overflow
        if (offset > bv.byteLength || elem > bv.byteLength - offset ||
            count - 1 > (bv.byteLength - offset - elem) / stride)
            fail(what + ": accessor exceeds bufferView " + std::to_string(view));
        return data.data() + bv.byteOffset + offset;
    }

    // Accessor `index` as count * components values of T; `type` is the
    // required glTF type (TINYGLTF_TYPE_VEC3, ...). Sparse accessors included.
    template <class T>
    std::vector<T> read_accessor(int index, int type, const std::string& context) {
        const std::string what = context + ": accessor " + std::to_string(index);
        if (index < 0 || std::size_t(index) >= model_.accessors.size())
            fail(context + ": accessor " + std::to_string(index) + " out of range (" +
                 std::to_string(model_.accessors.size()) + " accessors)");
        const tinygltf::Accessor& a = model_.accessors[std::size_t(index)];
        const int ncomp = type_components(a.type);
        const std::size_t csize = component_size(a.componentType);
        if (a.type != type || ncomp == 0) fail(what + ": wrong type");
        if (csize == 0) fail(what + ": unsupported componentType " + std::to_string(a.componentType));
        if (a.count > kMaxAccessorCount) fail(what + ": absurd count " + std::to_string(a.count));
        // Budgets first, before anything is allocated or looped over.
        if (a.bufferView < 0) {
            zero_filled_ += a.count;
            if (zero_filled_ > scene_detail::kMaxZeroFilledElements)
                fail(what + ": " + std::to_string(a.count) + " elements without a bufferView bring the zero-filled "
                     "elements to " + std::to_string(zero_filled_) + ", more than the limit of " +
                     std::to_string(scene_detail::kMaxZeroFilledElements) + " (2^22)");
        }
        charge(a.count, what);
        const std::size_t elem = csize * std::size_t(ncomp);
        // `normalized` means nothing for indices.
        const bool normalized = a.normalized && std::is_floating_point_v<T>;

        std::vector<T> out;
        if (a.bufferView >= 0) {
            std::size_t stride = 0;
            const unsigned char* p =
                view_window(a.bufferView, a.byteOffset, a.count, elem, true, stride, what);
            out.resize(a.count * std::size_t(ncomp));
            for (std::size_t i = 0; i < a.count; ++i)
                for (int c = 0; c < ncomp; ++c)
                    out[i * std::size_t(ncomp) + std::size_t(c)] =
                        T(component(p + i * stride + std::size_t(c) * csize, a.componentType,
                                    normalized));
        } else {
            // No bufferView: zeros (glTF 2.0), which only sparse values may replace.
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
            const unsigned char* ip = view_window(s.indices.bufferView, std::size_t(s.indices.byteOffset),
                                                  n, isize, false, istride, what + " sparse indices");
            const unsigned char* vp = view_window(s.values.bufferView, std::size_t(s.values.byteOffset),
                                                  n, elem, false, vstride, what + " sparse values");
            for (std::size_t j = 0; j < n; ++j) {
                const double target = component(ip + j * istride, s.indices.componentType, false);
                if (target >= double(a.count)) fail(what + ": sparse index out of range");
                for (int c = 0; c < ncomp; ++c)
                    out[std::size_t(target) * std::size_t(ncomp) + std::size_t(c)] =
                        T(component(vp + j * vstride + std::size_t(c) * csize, a.componentType,
                                    normalized));
            }
        }
        return out;
    }

    // ---- Images, textures, materials

    // Scene image for glTF image i, or -1 (warned) when it cannot be used.
    int image_for(int i) {
        if (i < 0 || std::size_t(i) >= model_.images.size()) return -1;
        int& mapped = image_map_[std::size_t(i)];
        if (mapped != kNotYet) return mapped;
        mapped = -1;
        const tinygltf::Image& img = model_.images[std::size_t(i)];
        ImageSource src;
        src.name = fs::path(path_).filename().string() + "#image" + std::to_string(i);
        if (img.bufferView >= 0) {
            // Bounds-checked here: tinygltf does not (see the file comment).
            const auto& views = model_.bufferViews;
            bool ok = std::size_t(img.bufferView) < views.size();
            if (ok) {
                const tinygltf::BufferView& bv = views[std::size_t(img.bufferView)];
                ok = bv.buffer >= 0 && std::size_t(bv.buffer) < model_.buffers.size();
                if (ok) {
                    const auto& data = model_.buffers[std::size_t(bv.buffer)].data;
                    ok = bv.byteOffset <= data.size() && bv.byteLength <= data.size() - bv.byteOffset &&
                         bv.byteLength > 0;
                    if (ok)
                        src.bytes.assign(data.begin() + std::ptrdiff_t(bv.byteOffset),
                                         data.begin() + std::ptrdiff_t(bv.byteOffset + bv.byteLength));
                }
            }
            if (!ok) {
                warn("image " + std::to_string(i) + ": bad bufferView, texture ignored");
                return -1;
            }
        } else if (img.image.empty() && img.uri.compare(0, 5, "data:") == 0) {
            // A data URI whose type tinygltf does not decode (image/webp, EXT_texture_webp).
            const std::size_t marker = img.uri.find(";base64,");
            const std::string decoded =
                marker == std::string::npos ? std::string() : base64_bytes(img.uri, marker + 8);
            if (decoded.empty()) {
                warn("image " + std::to_string(i) + ": data URI without base64 data, texture ignored");
                return -1;
            }
            src.bytes.assign(decoded.begin(), decoded.end());
        } else if (!img.uri.empty()) {
            const FileScope::Resolved where = scope_.resolve(scope_.root(), decode_uri(img.uri));
            if (!where.ok()) {
                if (where.missing) warn("image " + std::to_string(i) + " '" + cut(img.uri) + "' not found, texture ignored");
                else log_.add(scope_.refusal("image " + std::to_string(i), img.uri, where) + ", texture ignored");
                return -1;
            }
            // One Scene image per file, however many images or spellings name it.
            const auto known = image_by_path_.find(where.path);
            if (known != image_by_path_.end()) return mapped = known->second;
            src.path = where.path;
            src.name = src.path;
            scene_.images.push_back(std::move(src));
            mapped = int(scene_.images.size()) - 1;
            image_by_path_.emplace(where.path, mapped);
            return mapped;
        } else if (!img.image.empty()) {
            src.bytes = img.image; // data URI
        } else {
            warn("image " + std::to_string(i) + " has no data, texture ignored");
            return -1;
        }
        scene_.images.push_back(std::move(src));
        mapped = int(scene_.images.size()) - 1;
        return mapped;
    }

    // The integer at materials[material].{parent.}key.texCoord as the file
    // writes it: tinygltf keeps the low 32 bits of an integer as an int, so
    // 2^31 would print as -2^31. The model's JSON is read and parsed again
    // for it, only for this warning and once: every material's values are
    // kept as text and the parsed document dropped. `fallback` when it cannot
    // be read.
    std::string file_texcoord(std::size_t material, const char* parent, const char* key, int fallback) {
        if (!texcoords_read_) {
            texcoords_read_ = true;
            try {
                read_texcoords();
            } catch (const std::exception&) {
                texcoords_.clear();
            }
        }
        const auto it = texcoords_.find(std::to_string(material) + "/" + (parent ? parent : "") + "/" + key);
        return it != texcoords_.end() ? it->second : std::to_string(fallback);
    }

    // The model's JSON parsed again, by nlohmann::json (for what tinygltf
    // does not keep as the file writes it); null when it cannot be read.
    nlohmann::json raw_document() const {
        std::uint64_t size = 0;
        const int fd = open_regular_file(path_, "", size);
        struct Closer {
            int fd;
            ~Closer() { ::close(fd); }
        } closer{fd};
        const auto read_at = [&](std::uint64_t offset, std::size_t n) {
            std::string out(n, '\0');
            std::size_t got = 0;
            while (got < n) {
                const ssize_t r = ::pread(fd, &out[got], n - got, off_t(offset + got));
                if (r < 0 && errno == EINTR) continue;
                if (r <= 0) break;
                got += std::size_t(r);
            }
            out.resize(got);
            return out;
        };
        if (size > scene_detail::kMaxFileBytes) return nlohmann::json();
        // Of a .glb only its JSON chunk (checked when the model was parsed).
        std::string text = read_at(0, std::size_t(std::min<std::uint64_t>(size, 20)));
        if (text.size() == 20 && text.compare(0, 4, "glTF") == 0)
            text = read_at(20, std::size_t(std::min<std::uint64_t>(
                                   le32(reinterpret_cast<const unsigned char*>(&text[12])), size - 20)));
        else
            text = read_at(0, std::size_t(size));
        return nlohmann::json::parse(text, nullptr, false);
    }

    void read_texcoords() {
        const nlohmann::json doc = raw_document();
        const auto materials = doc.is_object() ? doc.find("materials") : doc.end();
        if (!doc.is_object() || materials == doc.end() || !materials->is_array()) return;
        const auto integer = [](const nlohmann::json& v) -> std::string {
            if (v.is_number_unsigned()) return std::to_string(v.get<std::uint64_t>());
            if (v.is_number_integer()) return std::to_string(v.get<std::int64_t>());
            return "";
        };
        const auto member = [](const nlohmann::json& v, const char* name) -> const nlohmann::json* {
            if (!v.is_object()) return nullptr;
            const auto it = v.find(name);
            return it != v.end() ? &*it : nullptr;
        };
        for (std::size_t i = 0; i < materials->size(); ++i) {
            const nlohmann::json& m = (*materials)[i];
            for (const char* parent : {"", "pbrMetallicRoughness"}) {
                const nlohmann::json* base = *parent ? member(m, parent) : &m;
                if (!base) continue;
                for (const char* key : {"baseColorTexture", "metallicRoughnessTexture", "normalTexture",
                                        "occlusionTexture", "emissiveTexture"}) {
                    const nlohmann::json* info = member(*base, key);
                    const nlohmann::json* tc = info ? member(*info, "texCoord") : nullptr;
                    const std::string value = tc ? integer(*tc) : "";
                    if (!value.empty()) texcoords_[std::to_string(i) + "/" + parent + "/" + key] = value;
                }
            }
        }
    }

    TextureRef texture(int index, int texcoord, const tinygltf::ExtensionMap& extensions,
                       const std::string& what, std::size_t material, const char* parent, const char* key) {
        TextureRef ref;
        if (index < 0) return ref;
        if (std::size_t(index) >= model_.textures.size()) {
            warn(what + ": texture " + std::to_string(index) + " out of range, ignored");
            return ref;
        }
        // KHR_texture_transform's texCoord overrides the textureInfo's (when it is a set prast reads).
        const auto xt = extensions.find("KHR_texture_transform");
        const int override_set = xt != extensions.end() ? texcoord_override(xt->second) : -1;
        if (override_set >= 0) texcoord = override_set;
        // tinygltf keeps the low 32 bits: a set it reads as 1 is taken only when the file says 1.
        if (override_set < 0 && (texcoord < 0 || texcoord >= kMaxUvSets ||
            (texcoord != 0 && file_texcoord(material, parent, key, texcoord) != std::to_string(texcoord)))) {
            warn(what + " uses TEXCOORD_" + file_texcoord(material, parent, key, texcoord) +
                 " (only TEXCOORD_0 and TEXCOORD_1 are supported), ignored");
            return ref;
        }
        ref.texcoord = texcoord;
        if (xt != extensions.end()) texture_transform(xt->second, what, ref);
        const tinygltf::Texture& tex = model_.textures[std::size_t(index)];
        const int source = texture_source(tex, index);
        if (source < 0 || std::size_t(source) >= model_.images.size()) {
            warn(what + ": texture " + std::to_string(index) + " has no usable image source, ignored");
            return ref;
        }
        ref.image = image_for(source);
        if (tex.sampler >= 0) {
            if (std::size_t(tex.sampler) >= model_.samplers.size()) {
                warn(what + ": sampler " + std::to_string(tex.sampler) + " out of range, REPEAT used");
            } else {
                const std::size_t si = std::size_t(tex.sampler);
                const tinygltf::Sampler& s = model_.samplers[si];
                const nlohmann::json* raw = raw_sampler(si);
                bool known_s = true, known_t = true;
                ref.wrap_s = wrap_mode(s.wrapS, known_s);
                ref.wrap_t = wrap_mode(s.wrapT, known_t);
                known_s = known_s && as_written(raw, "wrapS", s.wrapS);
                known_t = known_t && as_written(raw, "wrapT", s.wrapT);
                if (!known_s || !known_t) warn(what + ": unknown wrap mode, REPEAT used");
                ref.mag_filter = mag_filter(si, s.magFilter, raw);
                ref.min_filter = min_filter(si, s.minFilter, raw);
            }
        }
        return ref;
    }

    // The image a texture draws: EXT_texture_webp's source when it names an
    // image (WebP preferred; the texture's own source is the PNG/JPEG
    // fallback), else the texture's source. KHR_texture_basisu (KTX2) has no
    // decoder here: its fallback source is used, with one warning (a file
    // requiring it was refused by check_required_extensions).
    int texture_source(const tinygltf::Texture& tex, int index) {
        const auto webp = tex.extensions.find("EXT_texture_webp");
        if (webp != tex.extensions.end()) {
            const tinygltf::Value& s = webp->second.IsObject() ? webp->second.Get("source") : tinygltf::Value();
            const double d = s.IsNumber() ? s.GetNumberAsDouble() : -1.0;
            if (d >= 0.0 && d < double(model_.images.size()) && d == std::floor(d)) return int(d);
            warn("texture " + std::to_string(index) + ": EXT_texture_webp source is not an image index, " +
                 (tex.source >= 0 ? "its fallback source used" : "no image"));
        }
        if (tex.extensions.count("KHR_texture_basisu"))
            warn_once(std::string("KHR_texture_basisu (KTX2) textures are not decoded (no decoder in Debian 12): ") +
                      "their PNG/JPEG source images are used where present");
        return tex.source;
    }

    // ---- KHR_texture_transform

    // The extension's texCoord when it is a set prast reads (0 .. kMaxUvSets - 1), else -1.
    static int texcoord_override(const tinygltf::Value& v) {
        if (!v.IsObject()) return -1;
        const tinygltf::Value& tc = v.Get("texCoord");
        const double d = tc.IsNumber() ? tc.GetNumberAsDouble() : -1.0;
        return d >= 0.0 && d < double(kMaxUvSets) && d == std::floor(d) ? int(d) : -1;
    }

    // A textureInfo's transform into ref: offset, rotation and scale (each
    // finite, else one warning and its default), and the texCoord override
    // (0 .. kMaxUvSets - 1, else one warning and the textureInfo's set). An
    // identity transform is no transform (the same bytes as without it).
    void texture_transform(const tinygltf::Value& v, const std::string& what_texture, TextureRef& ref) {
        const std::string what = what_texture + " KHR_texture_transform";
        if (!v.IsObject()) {
            warn(what + ": not an object, ignored");
            return;
        }
        const auto in_float = [](double d) { return std::isfinite(d) && std::fabs(d) <= 3.0e38; };
        const auto pair = [&](const char* key, glm::vec2 fallback) {
            const tinygltf::Value& x = v.Get(key);
            if (x.Type() == tinygltf::NULL_TYPE) return fallback;
            if (x.IsArray() && x.ArrayLen() == 2 && x.Get(0).IsNumber() && x.Get(1).IsNumber() &&
                in_float(x.Get(0).GetNumberAsDouble()) && in_float(x.Get(1).GetNumberAsDouble()))
                return glm::vec2(float(x.Get(0).GetNumberAsDouble()), float(x.Get(1).GetNumberAsDouble()));
            warn(what + ": bad " + key + " (not two finite numbers), [" + std::to_string(int(fallback.x)) + ", " +
                 std::to_string(int(fallback.y)) + "] used");
            return fallback;
        };
        TextureTransform t;
        t.offset = pair("offset", glm::vec2(0.0f));
        t.scale = pair("scale", glm::vec2(1.0f));
        const tinygltf::Value& r = v.Get("rotation");
        if (r.Type() != tinygltf::NULL_TYPE) {
            if (r.IsNumber() && in_float(r.GetNumberAsDouble())) t.rotation = float(r.GetNumberAsDouble());
            else warn(what + ": bad rotation (not a finite number), 0 used");
        }
        if (v.Get("texCoord").Type() != tinygltf::NULL_TYPE && texcoord_override(v) < 0)
            warn(what + ": texCoord override not 0 or 1, TEXCOORD_" + std::to_string(ref.texcoord) + " used");
        t.present = t.offset != glm::vec2(0.0f) || t.rotation != 0.0f || t.scale != glm::vec2(1.0f);
        ref.transform = t;
    }

    // ---- Samplers

    // Sampler i as the file writes it (check_json kept the array's text), or
    // null when that text is not the array tinygltf read.
    const nlohmann::json* raw_sampler(std::size_t i) {
        if (!samplers_parsed_) {
            samplers_parsed_ = true;
            if (!samplers_json_.empty()) raw_samplers_ = nlohmann::json::parse(samplers_json_, nullptr, false);
            samplers_json_ = {};
            if (!raw_samplers_.is_array() || raw_samplers_.size() != model_.samplers.size()) raw_samplers_ = {};
        }
        if (!raw_samplers_.is_array() || i >= raw_samplers_.size() || !raw_samplers_[i].is_object()) return nullptr;
        return &raw_samplers_[i];
    }

    // False when the file's `key` is an integer tinygltf wrapped into `value`.
    static bool as_written(const nlohmann::json* raw, const char* key, int value) {
        if (!raw) return true;
        const auto it = raw->find(key);
        if (it == raw->end() || !(it->is_number_integer() || it->is_number_unsigned())) return true;
        if (it->is_number_unsigned()) return it->get<std::uint64_t>() == std::uint64_t(std::int64_t(value));
        return it->get<std::int64_t>() == value;
    }

    // A filter enum: tinygltf's `value` (-1: absent) checked against what
    // the file writes (`raw`, when known); -1 when absent, kBadEnum when the
    // file's value is no integer tinygltf read as it is. `shown`: the value
    // as the file writes it, for the warning.
    static constexpr int kBadEnum = -2;
    static int filter_enum(const char* key, int value, const nlohmann::json* raw, std::string& shown) {
        shown = std::to_string(value);
        if (!raw) return value;
        const auto it = raw->find(key);
        if (it == raw->end()) return -1;
        shown = cut(it->dump(), 40);
        if (!(it->is_number_integer() || it->is_number_unsigned()) || !as_written(raw, key, value) || value < 0)
            return kBadEnum;
        return value;
    }

    Filter mag_filter(std::size_t si, int value, const nlohmann::json* raw) {
        std::string shown;
        const int v = filter_enum("magFilter", value, raw, shown);
        if (v == TINYGLTF_TEXTURE_FILTER_NEAREST) return Filter::Nearest;
        if (v == -1 || v == TINYGLTF_TEXTURE_FILTER_LINEAR) return Filter::Linear;
        warn_once("sampler " + std::to_string(si) + ": magFilter " + shown +
                  " is not NEAREST (9728) or LINEAR (9729), LINEAR used");
        return Filter::Linear;
    }

    MinFilter min_filter(std::size_t si, int value, const nlohmann::json* raw) {
        std::string shown;
        switch (filter_enum("minFilter", value, raw, shown)) {
        case -1: return MinFilter::LinearMipmapLinear;
        case TINYGLTF_TEXTURE_FILTER_NEAREST: return MinFilter::Nearest;
        case TINYGLTF_TEXTURE_FILTER_LINEAR: return MinFilter::Linear;
        case TINYGLTF_TEXTURE_FILTER_NEAREST_MIPMAP_NEAREST: return MinFilter::NearestMipmapNearest;
        case TINYGLTF_TEXTURE_FILTER_LINEAR_MIPMAP_NEAREST: return MinFilter::LinearMipmapNearest;
        case TINYGLTF_TEXTURE_FILTER_NEAREST_MIPMAP_LINEAR: return MinFilter::NearestMipmapLinear;
        case TINYGLTF_TEXTURE_FILTER_LINEAR_MIPMAP_LINEAR: return MinFilter::LinearMipmapLinear;
        default: break;
        }
        warn_once("sampler " + std::to_string(si) + ": minFilter " + shown +
                  " is not a glTF minification filter (9728, 9729, 9984 to 9987), LINEAR_MIPMAP_LINEAR used");
        return MinFilter::LinearMipmapLinear;
    }

    Material convert_material(const tinygltf::Material& g, std::size_t index) {
        Material m;
        m.name = g.name.empty() ? "material" + std::to_string(index) : g.name;
        const std::string what = "material '" + cut(m.name) + "'";
        const tinygltf::PbrMetallicRoughness& pbr = g.pbrMetallicRoughness;

        m.base_color_factor = glm::vec4(1.0f);
        if (pbr.baseColorFactor.size() == 4 && finite_values(pbr.baseColorFactor))
            m.base_color_factor = glm::vec4(pbr.baseColorFactor[0], pbr.baseColorFactor[1],
                                            pbr.baseColorFactor[2], pbr.baseColorFactor[3]);
        else warn(what + ": bad baseColorFactor, white used");
        auto unit = [](double v, float fallback) {
            return std::isfinite(v) ? std::clamp(float(v), 0.0f, 1.0f) : fallback;
        };
        m.metallic_factor = unit(pbr.metallicFactor, 1.0f);
        m.roughness_factor = unit(pbr.roughnessFactor, 1.0f);
        const char* const kPbr = "pbrMetallicRoughness";
        m.base_color = texture(pbr.baseColorTexture.index, pbr.baseColorTexture.texCoord,
                               pbr.baseColorTexture.extensions, what + " baseColorTexture", index, kPbr,
                               "baseColorTexture");
        m.metallic_roughness =
            texture(pbr.metallicRoughnessTexture.index, pbr.metallicRoughnessTexture.texCoord,
                    pbr.metallicRoughnessTexture.extensions, what + " metallicRoughnessTexture", index, kPbr,
                    "metallicRoughnessTexture");
        m.normal = texture(g.normalTexture.index, g.normalTexture.texCoord,
                           g.normalTexture.extensions, what + " normalTexture", index, nullptr, "normalTexture");
        m.normal_scale = std::isfinite(g.normalTexture.scale) ? float(g.normalTexture.scale) : 1.0f;
        m.occlusion = texture(g.occlusionTexture.index, g.occlusionTexture.texCoord,
                              g.occlusionTexture.extensions, what + " occlusionTexture", index, nullptr,
                              "occlusionTexture");
        m.occlusion_strength = unit(g.occlusionTexture.strength, 1.0f);
        m.emissive = texture(g.emissiveTexture.index, g.emissiveTexture.texCoord,
                             g.emissiveTexture.extensions, what + " emissiveTexture", index, nullptr,
                             "emissiveTexture");
        m.emissive_factor = glm::vec3(0.0f);
        if (g.emissiveFactor.size() == 3 && finite_values(g.emissiveFactor))
            m.emissive_factor = glm::vec3(g.emissiveFactor[0], g.emissiveFactor[1], g.emissiveFactor[2]);
        else if (!g.emissiveFactor.empty()) warn(what + ": bad emissiveFactor, black used");

        if (g.alphaMode == "MASK") {
            m.alpha_mode = AlphaMode::Mask;
        } else if (g.alphaMode == "BLEND") {
            m.alpha_mode = AlphaMode::Blend;
        } else if (g.alphaMode != "OPAQUE") {
            warn(what + ": unknown alphaMode '" + cut(g.alphaMode) + "', drawn opaque");
        }
        m.alpha_cutoff = std::isfinite(g.alphaCutoff) ? float(g.alphaCutoff) : 0.5f;
        m.double_sided = g.doubleSided;

        for (const auto& [name, value] : g.extensions) {
            if (name == "KHR_materials_emissive_strength") {
                if (value.IsObject() && value.Get("emissiveStrength").IsNumber()) {
                    const double s = value.Get("emissiveStrength").GetNumberAsDouble();
                    if (std::isfinite(s) && s >= 0.0) m.emissive_factor *= float(s);
                }
            } else if (name == "KHR_materials_ior") {
                if (value.IsObject() && value.Get("ior").IsNumber()) {
                    const double ior = value.Get("ior").GetNumberAsDouble();
                    if (std::isfinite(ior) && ior >= 1.0) m.ior = float(ior);
                }
            } else if (name == "KHR_materials_unlit") {
                // A flag: its object's members (none are defined) are not read.
                m.unlit = true;
            } else if (name == "KHR_materials_specular") {
                specular_extension(value, m, what, index);
            } else if (name == "KHR_materials_clearcoat") {
                clearcoat_extension(value, m, what, index);
            } else if (name == "KHR_materials_sheen") {
                sheen_extension(value, m, what, index);
            } else if (name == "KHR_materials_transmission") {
                transmission_extension(value, m, what, index);
            } else if (name == "KHR_materials_volume") {
                volume_extension(value, m, what, index);
            } else if (name != "KHR_materials_pbrSpecularGlossiness") {
                warn(what + ": extension " + cut(name) + " ignored");
            }
        }
        const auto sg = g.extensions.find("KHR_materials_pbrSpecularGlossiness");
        if (sg != g.extensions.end()) specular_glossiness(sg->second, m, what);
        return m;
    }

    // ---- KHR_materials_specular and KHR_materials_clearcoat

    // A number member of a material extension: `fallback` when absent or not
    // a finite number (warned), clamped to [lo, hi] (warned when outside).
    float extension_number(const tinygltf::Value& v, const char* key, float fallback, float lo, float hi,
                           const std::string& what) {
        const auto shown = [](double d) {
            char b[32];
            std::snprintf(b, sizeof b, "%g", d);
            return std::string(b);
        };
        const tinygltf::Value& x = v.Get(key);
        if (x.Type() == tinygltf::NULL_TYPE) return fallback;
        const double d = x.IsNumber() ? x.GetNumberAsDouble() : std::nan("");
        if (!std::isfinite(d)) {
            warn(what + ": bad " + key + " (not a finite number), " + shown(fallback) + " used");
            return fallback;
        }
        if (d < double(lo) || d > double(hi)) {
            const float c = float(std::clamp(d, double(lo), double(hi)));
            warn(what + ": " + key + " " + shown(d) + " outside [" + shown(lo) + ", " + shown(hi) + "], clamped to " +
                 shown(c));
            return c;
        }
        return float(d);
    }

    // A textureInfo member of a material extension, with its own
    // KHR_texture_transform, as texture() reads the core ones.
    TextureRef material_extension_texture(const tinygltf::Value& v, const char* key, const std::string& what,
                                          std::size_t material, float* scale = nullptr) {
        const tinygltf::Value& t = v.Get(key);
        if (t.Type() == tinygltf::NULL_TYPE) return {};
        if (!t.IsObject() || !t.Get("index").IsNumber()) {
            warn(what + " " + key + ": not a textureInfo, ignored");
            return {};
        }
        const double index = t.Get("index").GetNumberAsDouble();
        const tinygltf::Value& tc = t.Get("texCoord");
        const double texcoord = tc.IsNumber() ? tc.GetNumberAsDouble() : 0.0;
        tinygltf::ExtensionMap extensions;
        const tinygltf::Value& ext = t.Get("extensions");
        if (ext.IsObject())
            for (const std::string& k : ext.Keys()) extensions[k] = ext.Get(k);
        if (scale) *scale = extension_number(t, "scale", 1.0f, -3.0e38f, 3.0e38f, what + " " + key);
        // Out-of-int indices and sets are refused by texture() as out of range.
        const int ii = index >= 0.0 && index < 2.0e9 ? int(index) : -2;
        if (ii == -2 || index != std::floor(index)) {
            warn(what + " " + key + ": texture index not a non-negative integer, ignored");
            return {};
        }
        const int set = texcoord >= 0.0 && texcoord < 2.0e9 && texcoord == std::floor(texcoord) ? int(texcoord) : -1;
        return texture(ii, set, extensions, what + " " + key, material, "", "");
    }

    void specular_extension(const tinygltf::Value& v, Material& m, const std::string& what_material,
                            std::size_t index) {
        const std::string what = what_material + " KHR_materials_specular";
        if (!v.IsObject()) {
            warn(what + ": not an object, ignored");
            return;
        }
        m.has_specular = true;
        m.specular_factor = extension_number(v, "specularFactor", 1.0f, 0.0f, 1.0f, what);
        const tinygltf::Value& c = v.Get("specularColorFactor");
        if (c.Type() != tinygltf::NULL_TYPE) {
            bool ok = c.IsArray() && c.ArrayLen() == 3;
            for (int i = 0; ok && i < 3; ++i)
                ok = c.Get(i).IsNumber() && std::isfinite(c.Get(i).GetNumberAsDouble()) &&
                     std::fabs(c.Get(i).GetNumberAsDouble()) <= 3.0e38;
            if (!ok) {
                warn(what + ": bad specularColorFactor (not three finite numbers), [1, 1, 1] used");
            } else {
                bool negative = false;
                for (int i = 0; i < 3; ++i) {
                    const double d = c.Get(i).GetNumberAsDouble();
                    negative = negative || d < 0.0;
                    m.specular_color_factor[i] = float(std::max(d, 0.0));
                }
                if (negative) warn(what + ": negative specularColorFactor, clamped to 0");
            }
        }
        m.specular_texture = material_extension_texture(v, "specularTexture", what, index);
        m.specular_color_texture = material_extension_texture(v, "specularColorTexture", what, index);
    }

    void clearcoat_extension(const tinygltf::Value& v, Material& m, const std::string& what_material,
                             std::size_t index) {
        const std::string what = what_material + " KHR_materials_clearcoat";
        if (!v.IsObject()) {
            warn(what + ": not an object, ignored");
            return;
        }
        m.clearcoat_factor = extension_number(v, "clearcoatFactor", 0.0f, 0.0f, 1.0f, what);
        m.clearcoat_roughness_factor = extension_number(v, "clearcoatRoughnessFactor", 0.0f, 0.0f, 1.0f, what);
        m.clearcoat_texture = material_extension_texture(v, "clearcoatTexture", what, index);
        m.clearcoat_roughness_texture = material_extension_texture(v, "clearcoatRoughnessTexture", what, index);
        m.clearcoat_normal_texture =
            material_extension_texture(v, "clearcoatNormalTexture", what, index, &m.clearcoat_normal_scale);
        // clearcoatFactor 0 is no coat (the extension: the layer is off):
        // the material keeps the bytes it has without the extension.
        m.has_clearcoat = m.clearcoat_factor > 0.0f;
    }

    void sheen_extension(const tinygltf::Value& v, Material& m, const std::string& what_material, std::size_t index) {
        const std::string what = what_material + " KHR_materials_sheen";
        if (!v.IsObject()) {
            warn(what + ": not an object, ignored");
            return;
        }
        const tinygltf::Value& c = v.Get("sheenColorFactor");
        if (c.Type() != tinygltf::NULL_TYPE) {
            bool ok = c.IsArray() && c.ArrayLen() == 3;
            for (int i = 0; ok && i < 3; ++i) ok = c.Get(i).IsNumber() && std::isfinite(c.Get(i).GetNumberAsDouble());
            if (!ok) {
                warn(what + ": bad sheenColorFactor (not three finite numbers), [0, 0, 0] used");
            } else {
                bool outside = false;
                for (int i = 0; i < 3; ++i) {
                    const double d = c.Get(i).GetNumberAsDouble();
                    outside = outside || d < 0.0 || d > 1.0;
                    m.sheen_color_factor[i] = float(std::clamp(d, 0.0, 1.0));
                }
                if (outside) warn(what + ": sheenColorFactor outside [0, 1], clamped");
            }
        }
        m.sheen_roughness_factor = extension_number(v, "sheenRoughnessFactor", 0.0f, 0.0f, 1.0f, what);
        m.sheen_color_texture = material_extension_texture(v, "sheenColorTexture", what, index);
        m.sheen_roughness_texture = material_extension_texture(v, "sheenRoughnessTexture", what, index);
        // A black sheen colour disables the layer (the extension): the bytes of the file without it.
        m.has_sheen = m.sheen_color_factor != glm::vec3(0.0f);
    }

    // ---- KHR_materials_transmission and KHR_materials_volume

    void transmission_extension(const tinygltf::Value& v, Material& m, const std::string& what_material,
                                std::size_t index) {
        const std::string what = what_material + " KHR_materials_transmission";
        if (!v.IsObject()) {
            warn(what + ": not an object, ignored");
            return;
        }
        m.transmission_factor = extension_number(v, "transmissionFactor", 0.0f, 0.0f, 1.0f, what);
        m.transmission_texture = material_extension_texture(v, "transmissionTexture", what, index);
        // transmissionFactor 0 transmits nothing: the material keeps the
        // bytes it has without the extension.
        m.has_transmission = m.transmission_factor > 0.0f;
    }

    void volume_extension(const tinygltf::Value& v, Material& m, const std::string& what_material, std::size_t index) {
        const std::string what = what_material + " KHR_materials_volume";
        if (!v.IsObject()) {
            warn(what + ": not an object, ignored");
            return;
        }
        m.has_volume = true;
        m.thickness_factor = extension_number(v, "thicknessFactor", 0.0f, 0.0f, 3.0e38f, what);
        m.thickness_texture = material_extension_texture(v, "thicknessTexture", what, index);
        // attenuationDistance: > 0, absent = infinite (stored as 0: no attenuation).
        const tinygltf::Value& d = v.Get("attenuationDistance");
        if (d.Type() != tinygltf::NULL_TYPE) {
            const double x = d.IsNumber() ? d.GetNumberAsDouble() : std::nan("");
            if (!(x > 0.0) || !std::isfinite(x) || x > 3.0e38)
                warn(what + ": bad attenuationDistance (not a positive finite number), infinite used");
            else
                m.attenuation_distance = float(x);
        }
        const tinygltf::Value& c = v.Get("attenuationColor");
        if (c.Type() != tinygltf::NULL_TYPE) {
            bool ok = c.IsArray() && c.ArrayLen() == 3;
            for (int i = 0; ok && i < 3; ++i) ok = c.Get(i).IsNumber() && std::isfinite(c.Get(i).GetNumberAsDouble());
            if (!ok) {
                warn(what + ": bad attenuationColor (not three finite numbers), [1, 1, 1] used");
            } else {
                bool outside = false;
                for (int i = 0; i < 3; ++i) {
                    const double x = c.Get(i).GetNumberAsDouble();
                    outside = outside || x < 0.0 || x > 1.0;
                    m.attenuation_color[i] = float(std::clamp(x, 0.0, 1.0));
                }
                if (outside) warn(what + ": attenuationColor outside [0, 1], clamped");
            }
        }
        // A volume without transmission has no effect (the extension): it is kept, unused.
    }

    // ---- KHR_materials_pbrSpecularGlossiness, converted to metal-rough

    // A number array member of the extension: `fallback` when absent, warned
    // and `fallback` when not `n` finite numbers in [0, 1].
    std::vector<double> unit_numbers(const tinygltf::Value& v, const char* key, std::size_t n,
                                     std::vector<double> fallback, const std::string& what) {
        const tinygltf::Value& x = v.Get(key);
        if (x.Type() == tinygltf::NULL_TYPE) return fallback;
        std::vector<double> out;
        if (x.IsNumber() && n == 1) out.push_back(x.GetNumberAsDouble());
        if (x.IsArray() && x.ArrayLen() == n)
            for (std::size_t i = 0; i < n; ++i)
                if (x.Get(int(i)).IsNumber()) out.push_back(x.Get(int(i)).GetNumberAsDouble());
        if (out.size() != n || !finite_values(out)) {
            warn(what + ": bad " + key + ", default used");
            return fallback;
        }
        for (double& d : out) d = std::clamp(d, 0.0, 1.0);
        return out;
    }

    // A textureInfo member of the extension, as texture() reads the core ones.
    TextureRef extension_texture(const tinygltf::Value& v, const char* key, const std::string& what) {
        const tinygltf::Value& t = v.Get(key);
        if (t.Type() == tinygltf::NULL_TYPE) return {};
        if (!t.IsObject() || !t.Get("index").IsNumber()) {
            warn(what + " " + key + ": not a textureInfo, ignored");
            return {};
        }
        const tinygltf::Value& tc = t.Get("texCoord");
        const int texcoord = tc.IsNumber() ? tc.GetNumberAsInt() : 0;
        return texture(t.Get("index").GetNumberAsInt(), texcoord, {}, what + " " + key, 0, "", "");
    }

    // The material from the specular-glossiness parameters (see
    // specular_glossiness_to_metal_rough for the formulas). Textures are
    // converted texel by texel into two new images (base colour and
    // metallic-roughness) unless the diffuse texture can serve as the base
    // colour texture unchanged.
    void specular_glossiness(const tinygltf::Value& v, Material& m, const std::string& what_material) {
        const std::string what = what_material + " KHR_materials_pbrSpecularGlossiness";
        if (!v.IsObject()) {
            warn(what + ": not an object, ignored");
            return;
        }
        const std::vector<double> d = unit_numbers(v, "diffuseFactor", 4, {1, 1, 1, 1}, what);
        const std::vector<double> sp = unit_numbers(v, "specularFactor", 3, {1, 1, 1}, what);
        const double gloss = unit_numbers(v, "glossinessFactor", 1, {1}, what)[0];
        const glm::dvec4 diffuse(d[0], d[1], d[2], d[3]);
        const glm::dvec3 specular(sp[0], sp[1], sp[2]);
        const TextureRef diffuse_tex = extension_texture(v, "diffuseTexture", what);
        const TextureRef sg_tex = extension_texture(v, "specularGlossinessTexture", what);

        const MetalRough f = specular_glossiness_to_metal_rough(glm::dvec3(diffuse), specular, gloss, true);
        m.base_color_factor = glm::vec4(glm::vec3(f.base), float(diffuse.a));
        m.metallic_factor = float(f.metallic);
        m.roughness_factor = float(f.roughness);
        m.ior = float(f.ior);
        m.metallic_roughness = {};
        m.base_color = {};
        if (!diffuse_tex.valid() && !sg_tex.valid()) return;
        // A dielectric whose diffuse colour is the base colour: the diffuse
        // texture is the base colour texture, scaled by the factor above.
        const bool plain = !sg_tex.valid() && f.metallic == 0.0 && glm::dvec3(diffuse) != glm::dvec3(0.0);
        if (plain) {
            m.base_color = diffuse_tex;  // base = c_diff = diffuse (1 - max(specular)), times the texture
            return;
        }
        bake_specular_glossiness(diffuse, specular, gloss, diffuse_tex, sg_tex, m, what);
    }

    void bake_specular_glossiness(const glm::dvec4& diffuse, const glm::dvec3& specular, double gloss,
                                  const TextureRef& diffuse_tex, const TextureRef& sg_tex, Material& m,
                                  const std::string& what) {
        Image dimg, simg;
        try {
            if (diffuse_tex.valid()) dimg = decode_image(scene_.images[std::size_t(diffuse_tex.image)], true);
            if (sg_tex.valid()) simg = decode_image(scene_.images[std::size_t(sg_tex.image)], true);
        } catch (const LoadError& e) {
            warn(what + ": textures not converted (" + e.what() + "), factors used");
            return;
        }
        const Image& grid = dimg.texel_count() >= simg.texel_count() ? dimg : simg;
        if (grid.empty() || std::int64_t(grid.texel_count()) > kMaxBakeTexels) {
            warn(what + ": textures larger than " + std::to_string(kMaxBakeTexels) +
                 " texels are not converted, factors used");
            return;
        }
        if (diffuse_tex.valid() && sg_tex.valid() && diffuse_tex.texcoord != sg_tex.texcoord)
            warn_once(what + ": diffuse and specular-glossiness textures on different UV sets are combined "
                             "texel by texel (approximate)");
        // The other image at the grid texel's centre, nearest texel.
        const auto at = [&](const Image& img, int x, int y, const glm::vec4& none) {
            if (img.empty()) return none;
            const int ix = std::min(img.width - 1, int((x + 0.5) * img.width / grid.width));
            const int iy = std::min(img.height - 1, int((y + 0.5) * img.height / grid.height));
            return img.at(ix, iy);
        };
        const int w = grid.width, h = grid.height;
        // Factor times texel: diffuse RGBA, and specular RGB with glossiness.
        const auto dif = [&](int x, int y) { return diffuse * glm::dvec4(at(dimg, x, y, glm::vec4(1.0f))); };
        const auto sgl = [&](int x, int y) {
            return glm::dvec4(specular, gloss) * glm::dvec4(at(simg, x, y, glm::vec4(1.0f)));
        };
        const glm::dvec3 first_specular(sgl(0, 0));
        bool one_specular = true;
        for (int y = 0; y < h && one_specular; ++y)
            for (int x = 0; x < w && one_specular; ++x) one_specular = glm::dvec3(sgl(x, y)) == first_specular;
        // One specular colour over the whole texture: the exact per-material
        // conversion holds texel by texel (its ior is per material).
        const bool grey = one_specular && first_specular.r == first_specular.g && first_specular.g == first_specular.b;
        auto base = std::make_shared<Image>(), mr = std::make_shared<Image>();
        for (Image* img : {base.get(), mr.get()}) {
            img->width = w;
            img->height = h;
            img->rgba.assign(grid.texel_count() * 4, 0.0f);
        }
        double ior = 1.5;
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) {
                const glm::dvec4 d = dif(x, y), sg = sgl(x, y);
                const MetalRough t = specular_glossiness_to_metal_rough(glm::dvec3(d), glm::dvec3(sg), sg.a, grey);
                if (grey && t.ior != 1.5) ior = t.ior;
                base->set(x, y, glm::vec4(glm::vec3(t.base), float(d.a)));
                mr->set(x, y, glm::vec4(1.0f, float(t.roughness), float(t.metallic), 1.0f));
            }
        const TextureRef& first = diffuse_tex.valid() ? diffuse_tex : sg_tex;
        const TextureRef& second = sg_tex.valid() ? sg_tex : diffuse_tex;
        m.base_color = first;
        m.base_color.image = add_decoded(std::move(base), first.image, "base colour");
        m.metallic_roughness = second;
        m.metallic_roughness.image = add_decoded(std::move(mr), second.image, "metallic-roughness");
        m.base_color_factor = glm::vec4(1.0f);
        m.metallic_factor = 1.0f;
        m.roughness_factor = 1.0f;
        m.ior = float(ior);
    }

    int add_decoded(std::shared_ptr<Image> img, int from, const char* what) {
        ImageSource src;
        src.name = scene_.images[std::size_t(from)].name + " (" + what + " from specular-glossiness)";
        src.decoded = std::move(img);
        scene_.images.push_back(std::move(src));
        return int(scene_.images.size()) - 1;
    }

    // ---- Nodes

    glm::dmat4 local_transform(const tinygltf::Node& n, std::size_t index) {
        const std::string what = "node " + std::to_string(index);
        if (!n.matrix.empty()) {
            if (n.matrix.size() == 16) {
                glm::dmat4 m(1.0);
                for (int c = 0; c < 4; ++c)
                    for (int r = 0; r < 4; ++r) m[c][r] = n.matrix[std::size_t(c * 4 + r)];
                return m;
            }
            warn(what + ": matrix with " + std::to_string(n.matrix.size()) + " values ignored");
        }
        glm::dvec3 t(0.0), s(1.0);
        glm::dquat r(1.0, 0.0, 0.0, 0.0);
        if (n.translation.size() == 3) t = glm::dvec3(n.translation[0], n.translation[1], n.translation[2]);
        else if (!n.translation.empty()) warn(what + ": bad translation ignored");
        if (n.scale.size() == 3) s = glm::dvec3(n.scale[0], n.scale[1], n.scale[2]);
        else if (!n.scale.empty()) warn(what + ": bad scale ignored");
        if (n.rotation.size() == 4) {
            // glTF stores (x, y, z, w); glm::dquat's constructor takes w first.
            const glm::dquat q(n.rotation[3], n.rotation[0], n.rotation[1], n.rotation[2]);
            const double len = glm::length(q);
            if (len > 0.0 && std::isfinite(len)) r = q / len;
            else warn(what + ": bad rotation ignored");
        } else if (!n.rotation.empty()) {
            warn(what + ": bad rotation ignored");
        }
        return glm::translate(glm::dmat4(1.0), t) * glm::mat4_cast(r) * glm::scale(glm::dmat4(1.0), s);
    }

    // Nodes must form trees (glTF 2.0, "Nodes and Hierarchy"): one parent at
    // most and no cycles. Checked for the whole graph so traversal cannot loop.
    void check_node_graph() {
        const std::size_t n = model_.nodes.size();
        std::vector<int> parents(n, 0);
        for (std::size_t i = 0; i < n; ++i) {
            for (int c : model_.nodes[i].children) {
                if (c < 0 || std::size_t(c) >= n)
                    fail("node " + std::to_string(i) + ": child " + std::to_string(c) +
                         " out of range (" + std::to_string(n) + " nodes)");
                if (++parents[std::size_t(c)] > 1)
                    fail("node " + std::to_string(c) + " has more than one parent (node graph is not a tree)");
            }
        }
        // With at most one parent each, the nodes not reachable from a parentless
        // node are exactly those on or under a cycle.
        std::vector<char> seen(n, 0);
        std::vector<std::size_t> stack;
        for (std::size_t i = 0; i < n; ++i)
            if (parents[i] == 0) stack.push_back(i);
        while (!stack.empty()) {
            const std::size_t i = stack.back();
            stack.pop_back();
            seen[i] = 1;
            for (int c : model_.nodes[i].children) stack.push_back(std::size_t(c));
        }
        for (std::size_t i = 0; i < n; ++i)
            if (!seen[i]) fail("node " + std::to_string(i) + " is part of a cycle in the node graph");
        parentless_.clear();
        for (std::size_t i = 0; i < n; ++i)
            if (parents[i] == 0) parentless_.push_back(int(i));
    }

    void traverse_scene() {
        check_node_graph();
        std::vector<int> roots;
        if (!model_.scenes.empty()) {
            int s = model_.defaultScene;
            if (s < 0 || std::size_t(s) >= model_.scenes.size()) {
                if (s >= 0) warn("default scene " + std::to_string(s) + " out of range, scene 0 used");
                s = 0;
            }
            roots = model_.scenes[std::size_t(s)].nodes;
        } else {
            roots = parentless_;
        }

        struct Item {
            int node;
            glm::dmat4 parent;
        };
        std::vector<Item> stack;
        for (auto it = roots.rbegin(); it != roots.rend(); ++it) {
            if (*it < 0 || std::size_t(*it) >= model_.nodes.size())
                fail("scene node " + std::to_string(*it) + " out of range (" +
                     std::to_string(model_.nodes.size()) + " nodes)");
            stack.push_back({*it, glm::dmat4(1.0)});
        }
        std::vector<char> visited(model_.nodes.size(), 0);
        while (!stack.empty()) {
            const Item item = stack.back();
            stack.pop_back();
            const std::size_t i = std::size_t(item.node);
            if (visited[i]) {
                warn("node " + std::to_string(i) + " is reached twice, drawn once");
                continue;
            }
            visited[i] = 1;
            const tinygltf::Node& node = model_.nodes[i];
            const glm::dmat4 world = item.parent * local_transform(node, i);
            if (node.mesh >= 0) {
                if (std::size_t(node.mesh) >= model_.meshes.size())
                    fail("node " + std::to_string(i) + ": mesh " + std::to_string(node.mesh) +
                         " out of range (" + std::to_string(model_.meshes.size()) + " meshes)");
                add_mesh(node, std::size_t(node.mesh), world);
            }
            add_light(node, i, world);
            for (auto c = node.children.rbegin(); c != node.children.rend(); ++c)
                stack.push_back({*c, world});
        }
    }

    // ---- Meshes

    void add_mesh(const tinygltf::Node& node, std::size_t mesh_index, const glm::dmat4& world) {
        const tinygltf::Mesh& gmesh = model_.meshes[mesh_index];
        for (std::size_t p = 0; p < gmesh.primitives.size(); ++p) {
            const tinygltf::Primitive& prim = gmesh.primitives[p];
            const std::string what = "mesh " + std::to_string(mesh_index) + " primitive " + std::to_string(p);
            if (prim.mode < -1 || prim.mode > TINYGLTF_MODE_TRIANGLE_FAN) {
                warn(what + ": mode " + std::to_string(prim.mode) + " is not a glTF primitive mode, skipped");
                continue;
            }
            Mesh mesh;
            mesh.name = !gmesh.name.empty() ? gmesh.name : node.name;
            mesh.variant_materials = variant_mappings(prim, what);  // before: its materials may read TEXCOORD_1
            if (!read_primitive(prim, what, world, mesh)) continue;
            if (prim.material >= 0 && std::size_t(prim.material) >= model_.materials.size()) {
                warn(what + ": material " + std::to_string(prim.material) + " out of range, default used");
                mesh.material = -1;
            } else {
                mesh.material = prim.material; // -1: finish_scene's default material
            }
            mesh.source_node = int(&node - model_.nodes.data());  // for posing (scene/gltf_graph.h)
            mesh.source_primitive = int(p);
            scene_.meshes.push_back(std::move(mesh));
        }
    }

    // Fills mesh with the primitive's world-space vertices and triangles;
    // false when there is nothing to draw.
    bool read_primitive(const tinygltf::Primitive& prim, const std::string& what,
                        const glm::dmat4& world, Mesh& mesh) {
        const auto attribute = [&](const char* name) {
            const auto it = prim.attributes.find(name);
            return it == prim.attributes.end() ? -1 : it->second;
        };
        const int position = attribute("POSITION");
        if (position < 0) {
            warn(what + ": no POSITION, skipped");
            return false;
        }
        for (const auto& [name, index] : prim.attributes) {
            (void)index;
            if (name.rfind("COLOR_", 0) == 0 && name != "COLOR_0") warn_once("vertex colour sets other than COLOR_0 ignored");
        }
        const int mode = prim.mode == -1 ? TINYGLTF_MODE_TRIANGLES : prim.mode;
        const bool triangles = mode == TINYGLTF_MODE_TRIANGLES || mode == TINYGLTF_MODE_TRIANGLE_STRIP ||
                               mode == TINYGLTF_MODE_TRIANGLE_FAN;

        // Read
        const std::vector<float> pos = read_accessor<float>(position, TINYGLTF_TYPE_VEC3, what + " POSITION");
        const std::size_t n = pos.size() / 3;
        if (n == 0) return false;
        std::vector<float> nrm, uv, uv1, tan;
        const int normal = attribute("NORMAL"), texcoord = attribute("TEXCOORD_0"),
                  texcoord1 = attribute("TEXCOORD_1"), tangent = attribute("TANGENT");
        if (normal >= 0) nrm = read_accessor<float>(normal, TINYGLTF_TYPE_VEC3, what + " NORMAL");
        if (texcoord >= 0) uv = read_accessor<float>(texcoord, TINYGLTF_TYPE_VEC2, what + " TEXCOORD_0");
        // TEXCOORD_1 only for a material that samples it: other files read what they always did.
        bool wants_uv1 = reads_uv1(prim.material);
        for (int vm : mesh.variant_materials) wants_uv1 = wants_uv1 || reads_uv1(vm);
        if (texcoord1 >= 0 && wants_uv1)
            uv1 = read_accessor<float>(texcoord1, TINYGLTF_TYPE_VEC2, what + " TEXCOORD_1");
        else if (wants_uv1)
            warn(what + ": its material reads TEXCOORD_1, which it lacks (sampled at 0, 0)");
        if (tangent >= 0) tan = read_accessor<float>(tangent, TINYGLTF_TYPE_VEC4, what + " TANGENT");
        int color_components = 0;
        std::vector<float> rgba = read_colors(attribute("COLOR_0"), what, color_components);
        auto same_count = [&](std::vector<float>& v, std::size_t ncomp, const char* name) {
            if (!v.empty() && v.size() != n * ncomp) {
                warn(what + ": " + name + " count differs from POSITION, ignored");
                v.clear();
            }
        };
        same_count(nrm, 3, "NORMAL");
        same_count(uv, 2, "TEXCOORD_0");
        same_count(uv1, 2, "TEXCOORD_1");
        same_count(tan, 4, "TANGENT");
        same_count(rgba, std::size_t(color_components), "COLOR_0");

        std::vector<std::uint32_t> indices;
        if (prim.indices >= 0) {
            const std::size_t ai = std::size_t(prim.indices);
            if (ai < model_.accessors.size()) {
                const int ct = model_.accessors[ai].componentType;
                if (ct != TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE && ct != TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT &&
                    ct != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT)
                    fail(what + " indices: componentType " + std::to_string(ct) +
                         " (must be an unsigned integer)");
            }
            indices = read_accessor<std::uint32_t>(prim.indices, TINYGLTF_TYPE_SCALAR, what + " indices");
            for (std::uint32_t i : indices)
                if (i >= n)
                    fail(what + ": index " + std::to_string(i) + " out of range (" + std::to_string(n) +
                         " vertices)");
        } else {
            indices.resize(n);
            for (std::size_t i = 0; i < n; ++i) indices[i] = std::uint32_t(i);
        }
        if (!assemble(mode, what, indices)) return false;

        // Transform to world space. A mirroring transform (negative determinant)
        // turns the winding and the tangent handedness around.
        const glm::dmat3 linear(world);
        const glm::dmat3 normal_matrix = glm::transpose(glm::inverse(linear));
        const bool mirrored = glm::determinant(linear) < 0.0;
        mesh.positions.resize(n);
        for (std::size_t i = 0; i < n; ++i)
            mesh.positions[i] = glm::vec3(world * glm::dvec4(pos[3 * i], pos[3 * i + 1], pos[3 * i + 2], 1.0));
        if (!nrm.empty()) {
            mesh.normals.resize(n);
            for (std::size_t i = 0; i < n; ++i)
                mesh.normals[i] = glm::vec3(glm::normalize(normal_matrix * glm::dvec3(nrm[3 * i], nrm[3 * i + 1], nrm[3 * i + 2])));
        }
        // glTF's UV convention is the project's (v = 0 is the top row): kept as they are.
        if (!uv.empty()) {
            mesh.uvs.resize(n);
            for (std::size_t i = 0; i < n; ++i) mesh.uvs[i] = glm::vec2(uv[2 * i], uv[2 * i + 1]);
        }
        if (!uv1.empty()) {
            mesh.uvs1.resize(n);
            for (std::size_t i = 0; i < n; ++i) mesh.uvs1[i] = glm::vec2(uv1[2 * i], uv1[2 * i + 1]);
        }
        if (!rgba.empty()) {
            // glTF 2.0, "Meshes": an RGB colour's alpha is 1.
            const std::size_t c = std::size_t(color_components);
            mesh.colors.resize(n);
            for (std::size_t i = 0; i < n; ++i)
                mesh.colors[i] = glm::vec4(rgba[c * i], rgba[c * i + 1], rgba[c * i + 2], c == 4 ? rgba[c * i + 3] : 1.0f);
        }
        if (!tan.empty() && (!uv.empty() || !uv1.empty())) {
            mesh.tangents.resize(n);
            for (std::size_t i = 0; i < n; ++i) {
                const glm::dvec3 t = glm::normalize(linear * glm::dvec3(tan[4 * i], tan[4 * i + 1], tan[4 * i + 2]));
                const float w = tan[4 * i + 3] < 0.0f ? -1.0f : 1.0f;
                mesh.tangents[i] = glm::vec4(glm::vec3(t), mirrored ? -w : w);
            }
        }
        mesh.mirrored = mirrored;
        if (triangles) {
            if (mirrored)
                for (std::size_t t = 0; t < indices.size(); t += 3) std::swap(indices[t + 1], indices[t + 2]);
        } else {
            mesh.topology = mode == TINYGLTF_MODE_POINTS ? Mesh::Topology::Points : Mesh::Topology::Lines;
        }
        mesh.indices = std::move(indices);
        return true;
    }

    // ---- KHR_materials_variants

    // A JSON number that is a whole number in [0, limit): it; else -1.
    static long whole_index(const tinygltf::Value& v, std::size_t limit) {
        if (!v.IsNumber()) return -1;
        const double d = v.GetNumberAsDouble();
        if (!(d >= 0.0) || d != std::floor(d) || d >= double(limit)) return -1;
        return long(d);
    }

    // The root's variants: names, in order. A malformed entry keeps its
    // index (the mappings count by it) with the name "variant N".
    void read_variants() {
        const auto ext = model_.extensions.find("KHR_materials_variants");
        if (ext == model_.extensions.end()) return;
        const std::string what = "KHR_materials_variants";
        const tinygltf::Value& root = ext->second;
        const tinygltf::Value& list = root.IsObject() ? root.Get("variants") : root;
        if (!root.IsObject() || !list.IsArray()) {
            warn(what + ": no 'variants' array, no variants");
            return;
        }
        // The index a mapping names is an int: a longer list is not a real file.
        constexpr std::size_t kMaxVariants = 1u << 16;
        if (list.ArrayLen() > kMaxVariants) {
            warn(what + ": " + std::to_string(list.ArrayLen()) + " variants, more than " +
                 std::to_string(kMaxVariants) + ", no variants");
            return;
        }
        // tinygltf drops an empty object ({}) from an array, which would move
        // every later variant to the index before its own: the file's JSON
        // read again gives the list as written (tinygltf's when it cannot).
        std::vector<std::optional<std::string>> names;
        try {
            const nlohmann::json doc = raw_document();
            const nlohmann::json* raw = &doc;
            for (const char* key : {"extensions", "KHR_materials_variants", "variants"}) {
                const auto it = raw->is_object() ? raw->find(key) : raw->end();
                raw = raw->is_object() && it != raw->end() ? &*it : nullptr;
                if (!raw) break;
            }
            if (raw && raw->is_array() && raw->size() <= kMaxVariants)
                for (const nlohmann::json& v : *raw) {
                    const auto name = v.is_object() ? v.find("name") : v.end();
                    names.push_back(v.is_object() && name != v.end() && name->is_string()
                                        ? std::optional<std::string>(name->get<std::string>())
                                        : std::nullopt);
                }
        } catch (const std::exception&) {
            names.clear();
        }
        if (names.empty())
            for (std::size_t i = 0; i < list.ArrayLen(); ++i) {
                const tinygltf::Value& v = list.Get(int(i));
                const tinygltf::Value& name = v.IsObject() ? v.Get("name") : v;
                names.push_back(v.IsObject() && name.IsString() ? std::optional<std::string>(name.Get<std::string>())
                                                                 : std::nullopt);
            }
        std::set<std::string> seen;
        for (std::size_t i = 0; i < names.size(); ++i) {
            std::string n = "variant " + std::to_string(i);
            if (!names[i])
                warn(what + ": variant " + std::to_string(i) + " has no name string, called '" + n + "'");
            else
                n = *names[i];
            if (!seen.insert(n).second)
                warn(what + ": variant " + std::to_string(i) + " repeats the name '" + cut(n) +
                     "' (that name selects the first; the index selects this one)");
            scene_.variants.push_back(n);
        }
    }

    // The primitive's mappings as one material per variant (-1: none).
    // Problems are one warning each (once per primitive, however many nodes
    // instance it), and never drop more than the entry at fault.
    std::vector<int> variant_mappings(const tinygltf::Primitive& prim, const std::string& what_primitive) {
        const auto ext = prim.extensions.find("KHR_materials_variants");
        if (ext == prim.extensions.end()) return {};
        const std::string what = what_primitive + " KHR_materials_variants";
        const tinygltf::Value& v = ext->second;
        const tinygltf::Value& mappings = v.IsObject() ? v.Get("mappings") : v;
        if (!v.IsObject() || !mappings.IsArray()) {
            warn_once(what + ": no 'mappings' array, ignored");
            return {};
        }
        if (scene_.variants.empty()) {
            warn_once(what + ": the file defines no variants, mappings ignored");
            return {};
        }
        std::vector<int> out(scene_.variants.size(), -1);
        for (std::size_t k = 0; k < mappings.ArrayLen(); ++k) {
            const tinygltf::Value& m = mappings.Get(int(k));
            const std::string at = what + " mapping " + std::to_string(k);
            if (!m.IsObject()) {
                warn_once(at + ": not an object, ignored");
                continue;
            }
            const long material = whole_index(m.Get("material"), model_.materials.size());
            if (material < 0) {
                warn_once(at + ": material is not an index of the file's " + std::to_string(model_.materials.size()) +
                          " materials, ignored");
                continue;
            }
            const tinygltf::Value& variants = m.Get("variants");
            if (!variants.IsArray() || variants.ArrayLen() == 0) {
                warn_once(at + ": 'variants' is not a non-empty array, ignored");
                continue;
            }
            for (std::size_t j = 0; j < variants.ArrayLen(); ++j) {
                const long vi = whole_index(variants.Get(int(j)), scene_.variants.size());
                if (vi < 0) {
                    warn_once(at + ": variant entry " + std::to_string(j) + " is not an index of the " +
                              std::to_string(scene_.variants.size()) + " variants, ignored");
                } else if (out[std::size_t(vi)] >= 0) {
                    // The extension: a variant appears in at most one mapping of a primitive.
                    warn_once(at + ": variant " + std::to_string(vi) + " is mapped already, material " +
                              std::to_string(out[std::size_t(vi)]) + " kept");
                } else {
                    out[std::size_t(vi)] = int(material);
                }
            }
        }
        return out;
    }

    // True when material `index` (a glTF index, converted already) has a texture on TEXCOORD_1.
    bool reads_uv1(int index) const {
        if (index < 0 || std::size_t(index) >= scene_.materials.size()) return false;
        const Material& m = scene_.materials[std::size_t(index)];
        for (const TextureRef* t : {&m.base_color, &m.metallic_roughness, &m.roughness, &m.metallic, &m.normal,
                                    &m.occlusion, &m.emissive})
            if (t->valid() && t->texcoord == 1) return true;
        for (const TextureRef* t : m.extension_textures())
            if (t->valid() && t->texcoord == 1) return true;
        return false;
    }

    // COLOR_0 (glTF 2.0, "Meshes": VEC3 or VEC4 of float, or of normalized
    // unsigned bytes or shorts, mapped to [0, 1] as c / 255 and c / 65535):
    // `components` values per vertex; none (warned) when the accessor has
    // another form.
    std::vector<float> read_colors(int index, const std::string& what, int& components) {
        components = 0;
        if (index < 0) return {};
        if (std::size_t(index) >= model_.accessors.size())
            fail(what + " COLOR_0: accessor " + std::to_string(index) + " out of range (" +
                 std::to_string(model_.accessors.size()) + " accessors)");
        const tinygltf::Accessor& a = model_.accessors[std::size_t(index)];
        const bool unorm = a.normalized && (a.componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE ||
                                            a.componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT);
        if ((a.type != TINYGLTF_TYPE_VEC3 && a.type != TINYGLTF_TYPE_VEC4) ||
            (a.componentType != TINYGLTF_COMPONENT_TYPE_FLOAT && !unorm)) {
            warn(what + " COLOR_0: accessor " + std::to_string(index) +
                 " is not a VEC3/VEC4 of float or normalized unsigned byte/short, ignored");
            return {};
        }
        components = a.type == TINYGLTF_TYPE_VEC3 ? 3 : 4;
        return read_accessor<float>(index, a.type, what + " COLOR_0");
    }

    // Turns the index list of a glTF topology into the Mesh's list: triangle
    // triples, line pairs or points (glTF 2.0, "Meshes", the topology
    // equations). Strip triangle i is (i, i+1, i+2) for even i and
    // (i, i+2, i+1) for odd i, keeping every triangle's winding; fan
    // triangle i is (i+1, i+2, 0); a line strip's segment i is (i, i+1) and a
    // loop adds (last, 0). A count the topology cannot use is warned about:
    // a partial last primitive is dropped, too few indices skip the
    // primitive (false). The expanded list is charged to the element budget
    // before it is allocated.
    bool assemble(int mode, const std::string& what, std::vector<std::uint32_t>& indices) {
        const std::size_t c = indices.size();
        const auto too_few = [&](const char* topology, std::size_t least) {
            if (c >= least) return false;
            warn(what + ": " + std::to_string(c) + " indices, too few for " + topology + " (at least " +
                 std::to_string(least) + "), skipped");
            return true;
        };
        const auto expand = [&](std::size_t size) {
            charge(size, what + " " + std::to_string(c) + " indices expanded to " + std::to_string(size));
            std::vector<std::uint32_t> out;
            out.reserve(size);
            return out;
        };
        switch (mode) {
        case TINYGLTF_MODE_POINTS: return c > 0;
        case TINYGLTF_MODE_LINE: {
            if (c % 2 != 0) {
                warn(what + ": index count " + std::to_string(c) + " not a multiple of 2, truncated");
                indices.resize(c / 2 * 2);
            }
            return !indices.empty();
        }
        case TINYGLTF_MODE_LINE_STRIP:
        case TINYGLTF_MODE_LINE_LOOP: {
            const bool loop = mode == TINYGLTF_MODE_LINE_LOOP;
            if (too_few(loop ? "a line loop" : "a line strip", 2)) return false;
            std::vector<std::uint32_t> out = expand(2 * (c - 1) + (loop ? 2 : 0));
            for (std::size_t i = 0; i + 1 < c; ++i) out.insert(out.end(), {indices[i], indices[i + 1]});
            if (loop) out.insert(out.end(), {indices[c - 1], indices[0]});
            indices = std::move(out);
            return true;
        }
        case TINYGLTF_MODE_TRIANGLE_STRIP:
        case TINYGLTF_MODE_TRIANGLE_FAN: {
            const bool strip = mode == TINYGLTF_MODE_TRIANGLE_STRIP;
            if (too_few(strip ? "a triangle strip" : "a triangle fan", 3)) return false;
            std::vector<std::uint32_t> out = expand(3 * (c - 2));
            for (std::size_t i = 0; i + 2 < c; ++i) {
                if (!strip) out.insert(out.end(), {indices[i + 1], indices[i + 2], indices[0]});
                else if (i % 2 == 0) out.insert(out.end(), {indices[i], indices[i + 1], indices[i + 2]});
                else out.insert(out.end(), {indices[i], indices[i + 2], indices[i + 1]});
            }
            indices = std::move(out);
            return true;
        }
        default: {
            if (c % 3 != 0) {
                warn(what + ": index count " + std::to_string(c) + " not a multiple of 3, truncated");
                indices.resize(c / 3 * 3);
            }
            return !indices.empty();
        }
        }
    }

    // Keeps what the flattened scene reads (meshes instanced by many nodes
    // are read once per instance) within kMaxSceneElements accessor elements,
    // checked before each accessor is allocated.
    void charge(std::size_t elements, const std::string& what) {
        elements_ += elements;
        if (elements_ > scene_detail::kMaxSceneElements)
            fail(what + ": " + std::to_string(elements) + " elements bring the scene to " + std::to_string(elements_) +
                 " accessor elements, more than the limit of " + std::to_string(scene_detail::kMaxSceneElements) +
                 " (2^27)");
    }

    // ---- Lights (KHR_lights_punctual)

    void add_light(const tinygltf::Node& node, std::size_t index, const glm::dmat4& world) {
        const auto ext = node.extensions.find("KHR_lights_punctual");
        if (ext == node.extensions.end()) return;
        const tinygltf::Value& v = ext->second;
        const std::string what = "node " + std::to_string(index);
        if (!v.IsObject() || !v.Get("light").IsNumber()) {
            warn(what + ": bad KHR_lights_punctual, ignored");
            return;
        }
        const int li = v.Get("light").GetNumberAsInt();
        if (li < 0 || std::size_t(li) >= model_.lights.size()) {
            warn(what + ": light " + std::to_string(li) + " out of range, ignored");
            return;
        }
        const tinygltf::Light& gl = model_.lights[std::size_t(li)];
        Light light;
        light.source_node = int(index);
        if (gl.color.size() == 3 && finite_values(gl.color))
            light.color = glm::vec3(gl.color[0], gl.color[1], gl.color[2]);
        light.intensity = std::isfinite(gl.intensity) ? float(gl.intensity) : 1.0f;
        if (gl.type == "directional") {
            // The light shines along its node's -Z; we store the way back to it.
            const glm::dvec3 towards = glm::dmat3(world) * glm::dvec3(0.0, 0.0, 1.0);
            const double len = glm::length(towards);
            if (!(len > 0.0) || !std::isfinite(len)) {
                warn(what + ": directional light with a degenerate transform, ignored");
                return;
            }
            light.type = Light::Type::Directional;
            light.direction = glm::vec3(towards / len);
            if (gl.range != 0.0) warn(what + ": range of directional light " + std::to_string(li) + " ignored");
        } else if (gl.type == "point" || gl.type == "spot") {
            light.type = gl.type == "spot" ? Light::Type::Spot : Light::Type::Point;
            light.position = glm::vec3(world * glm::dvec4(0.0, 0.0, 0.0, 1.0));
            if (!std::isfinite(light.position.x) || !std::isfinite(light.position.y) ||
                !std::isfinite(light.position.z)) {
                warn(what + ": " + gl.type + " light with a non-finite position, ignored");
                return;
            }
            // range: > 0 a cut-off; absent (tinygltf's 0) infinite; anything else warned, infinite.
            if (gl.range != 0.0) {
                if (std::isfinite(gl.range) && gl.range > 0.0 && gl.range <= 3.0e38) light.range = float(gl.range);
                else warn(what + ": light " + std::to_string(li) + " range is not a positive number, infinite used");
            }
            if (light.type == Light::Type::Spot) {
                // It shines along its node's -Z; we store the way back to it, as for directional lights.
                const glm::dvec3 towards = glm::dmat3(world) * glm::dvec3(0.0, 0.0, 1.0);
                const double len = glm::length(towards);
                if (!(len > 0.0) || !std::isfinite(len)) {
                    warn(what + ": spot light with a degenerate transform, ignored");
                    return;
                }
                light.direction = glm::vec3(towards / len);
                spot_angles(gl.spot.innerConeAngle, gl.spot.outerConeAngle, what, li, light);
            }
        } else {
            warn(what + ": light type '" + cut(gl.type) + "' unknown, ignored");
            return;
        }
        scene_.lights.push_back(light);
    }

    // The spec's 0 <= inner < outer <= pi / 2. A non-finite angle is its
    // default (inner 0, outer pi / 4); outer is clamped to (0, pi / 2]; an
    // inner angle not below outer becomes 0 (the spec's fallback for one
    // angle); each with one warning.
    void spot_angles(double inner, double outer, const std::string& what, int li, Light& light) {
        const std::string name = what + ": spot light " + std::to_string(li);
        constexpr double kHalfPi = 1.5707963267948966, kDefaultOuter = 0.7853981633974483;
        if (!std::isfinite(inner)) {
            warn(name + " innerConeAngle is not a number, 0 used");
            inner = 0.0;
        }
        if (!std::isfinite(outer)) {
            warn(name + " outerConeAngle is not a number, pi/4 used");
            outer = kDefaultOuter;
        }
        if (outer > kHalfPi) {
            warn(name + " outerConeAngle above pi/2, pi/2 used");
            outer = kHalfPi;
        } else if (!(outer > 0.0)) {
            warn(name + " outerConeAngle not above 0, pi/4 used");
            outer = kDefaultOuter;
        }
        if (inner < 0.0 || !(inner < outer)) {
            warn(name + " innerConeAngle not in [0, outerConeAngle), 0 used");
            inner = 0.0;
        }
        light.inner_cone = float(inner);
        light.outer_cone = float(outer);
    }

    const std::string& path_;
    const std::string shown_;  // path_, printable
    FileScope scope_;
    WarningLog log_;
    std::string base_dir_;
    tinygltf::Model model_;
    Scene scene_;
    std::vector<int> image_map_; // glTF image -> Scene image, kNotYet or -1
    std::vector<int> parentless_;
    std::set<std::string> warned_;
    std::size_t elements_ = 0;     // accessor elements read
    std::size_t zero_filled_ = 0;  // of which made up (no bufferView)
    std::map<std::size_t, std::uint64_t> fallback_lengths_;  // stood-in meshopt fallback buffers: byteLength
    std::uint64_t decoded_bytes_ = 0;                         // by decode_meshopt_views
    std::set<std::size_t> draco_stand_ins_;                   // indices accessors given a bufferView to parse
    std::map<std::string, int> image_by_path_;
};

} // namespace

Scene load_gltf(const std::string& path, const LoadOptions& options) {
    try {
        return GltfLoader(path, options).load();
    } catch (const LoadError&) {
        throw;
    } catch (const std::bad_alloc&) {
        throw LoadError(printable(path) + ": out of memory while loading the model");
    } catch (const std::length_error&) {
        throw LoadError(printable(path) + ": too large to load (a size exceeds what memory can hold)");
    } catch (const std::exception& e) {
        // tinygltf and nlohmann::json may throw (out_of_range, type_error, ...).
        throw LoadError(printable(path) + ": cannot load: " + printable(e.what()));
    }
}

} // namespace prast

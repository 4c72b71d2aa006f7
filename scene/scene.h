// The scene as loaders produce it and renderers consume it: world-space meshes
// (node transforms already applied), metal-roughness materials, image sources
// (decoded later by image.h) and punctual lights.
//
// UV convention inside the project: glTF's, v = 0 is the TOP row of an image.
// The OBJ loader converts (v_internal = 1 - v_obj), so samplers and tangent
// generation follow one rule: T runs along +u, and the normal-map bitangent
// B = cross(N, T) * w points towards -v (up the image), see docs/conventions.md.
#pragma once

#include <cstdint>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include <glm/glm.hpp>

namespace prast {

struct Image;  // image.h

// A bad input file: what() is one line, "FILE: problem".
struct LoadError : std::runtime_error {
    using std::runtime_error::runtime_error;
};

// Where an image's bytes come from: a file on disk, or bytes embedded in a
// .glb / data URI. Decoding happens in image.h.
struct ImageSource {
    std::string path;                 // file path, empty when embedded
    std::vector<unsigned char> bytes; // embedded encoded bytes (PNG/JPEG)
    std::string name;                 // for messages: path or "file.glb#image3"
    // Procedural images (the built-in scene) arrive decoded, already linear.
    std::shared_ptr<const Image> decoded;
};

enum class Wrap { Repeat, ClampToEdge, MirroredRepeat };
// glTF's sampler filters. An absent minFilter is LinearMipmapLinear and an
// absent magFilter Linear: trilinear, what every texture had before samplers.
enum class Filter { Nearest, Linear };
enum class MinFilter {
    Nearest, Linear, NearestMipmapNearest, LinearMipmapNearest, NearestMipmapLinear, LinearMipmapLinear
};

// The UV sets a mesh carries: TEXCOORD_0 (Mesh::uvs) and TEXCOORD_1 (Mesh::uvs1).
constexpr int kMaxUvSets = 2;

// KHR_texture_transform on one texture reference: uv' = T R S uv, T the
// offset, S the scale and R the rotation by `rotation` radians, counter-
// clockwise in UV space (u right, v down; docs/shading.md has the matrix).
struct TextureTransform {
    bool present = false;        // false: the UVs as they are, no float operation added
    glm::vec2 offset{0.0f};
    float rotation = 0.0f;
    glm::vec2 scale{1.0f};
    bool operator==(const TextureTransform& o) const {
        return present == o.present && offset == o.offset && rotation == o.rotation && scale == o.scale;
    }
};

struct TextureRef {
    int image = -1;              // index into Scene::images; -1 = none
    Wrap wrap_s = Wrap::Repeat;  // the texture's own sampler: two textures of
    Wrap wrap_t = Wrap::Repeat;  // one image may sample it differently
    Filter mag_filter = Filter::Linear;
    MinFilter min_filter = MinFilter::LinearMipmapLinear;
    int texcoord = 0;            // UV set, 0 .. kMaxUvSets - 1 (the transform's override applied)
    TextureTransform transform;
    bool valid() const { return image >= 0; }
};

enum class AlphaMode { Opaque, Mask, Blend };

// Measured metals for the conductor (complex index) Fresnel; None = Schlick
// with F0 from ior and albedo as the conventions say.
enum class Conductor { None, Gold, Copper, Aluminium, Silver };

struct Material {
    std::string name = "default";
    glm::vec4 base_color_factor{0.8f, 0.8f, 0.8f, 1.0f};
    float metallic_factor = 0.0f;
    float roughness_factor = 0.5f;
    glm::vec3 emissive_factor{0.0f};
    float normal_scale = 1.0f;
    float occlusion_strength = 1.0f;
    float ior = 1.5f;

    TextureRef base_color;          // sRGB, RGBA
    TextureRef metallic_roughness;  // glTF packed: roughness G, metallic B
    TextureRef roughness;           // separate map (OBJ map_Pr): R
    TextureRef metallic;            // separate map (OBJ map_Pm): R
    TextureRef normal;              // tangent space, OpenGL convention
    TextureRef occlusion;           // R
    TextureRef emissive;            // sRGB

    AlphaMode alpha_mode = AlphaMode::Opaque;
    float alpha_cutoff = 0.5f;
    bool double_sided = false;
    Conductor conductor = Conductor::None;
    // KHR_materials_unlit: the colour is the base colour term (factor x
    // texture x vertex colour), no light, environment or emissive.
    bool unlit = false;

    // KHR_materials_specular: the dielectric's F0 = min(F0(ior) x colour, 1)
    // x specular and F90 = specular (docs/shading.md). Off: F0(ior) and 1,
    // the arithmetic of files without it unchanged.
    bool has_specular = false;
    float specular_factor = 1.0f;              // [0, 1]
    glm::vec3 specular_color_factor{1.0f};     // >= 0 (the product is clamped to 1)
    TextureRef specular_texture;               // A
    TextureRef specular_color_texture;         // sRGB, RGB

    // KHR_materials_clearcoat: a second GGX lobe (F0 0.04) over the base,
    // which it attenuates by 1 - clearcoat F_coat(n_c.v). Off (or factor 0):
    // no coat at all.
    bool has_clearcoat = false;
    float clearcoat_factor = 0.0f;             // [0, 1]
    float clearcoat_roughness_factor = 0.0f;   // [0, 1]
    float clearcoat_normal_scale = 1.0f;
    TextureRef clearcoat_texture;              // R
    TextureRef clearcoat_roughness_texture;    // G
    TextureRef clearcoat_normal_texture;       // tangent space; none: the geometric normal

    // KHR_materials_sheen: a Charlie lobe over the base, which keeps what it
    // leaves (albedo scaling). Off (or colour 0): no sheen at all.
    bool has_sheen = false;
    glm::vec3 sheen_color_factor{0.0f};        // [0, 1]
    float sheen_roughness_factor = 0.0f;       // [0, 1]
    TextureRef sheen_color_texture;            // sRGB, RGB
    TextureRef sheen_roughness_texture;        // A

    // KHR_materials_transmission: the share of the dielectric's diffuse that
    // is transmitted instead (docs/shading.md, "Transmission"). Off (or
    // factor 0): no transmission at all. KHR_materials_volume gives the
    // transmitting surface a thickness (0: thin-walled) and Beer-Lambert
    // attenuation; it does nothing without transmission.
    bool has_transmission = false;
    float transmission_factor = 0.0f;          // [0, 1]
    TextureRef transmission_texture;           // R
    bool has_volume = false;
    float thickness_factor = 0.0f;             // >= 0, world units
    TextureRef thickness_texture;              // G
    float attenuation_distance = 0.0f;         // > 0; 0: infinite (no attenuation)
    glm::vec3 attenuation_color{1.0f};         // [0, 1]

    // The extension textures above, for code that walks every map (in
    // BoundMaterial::ExtMap's order).
    std::vector<const TextureRef*> extension_textures() const {
        return {&specular_texture, &specular_color_texture, &clearcoat_texture, &clearcoat_roughness_texture,
                &clearcoat_normal_texture, &sheen_color_texture, &sheen_roughness_texture, &transmission_texture,
                &thickness_texture};
    }
    // Which of them hold sRGB colour (the others are linear data).
    bool extension_texture_srgb(const TextureRef* r) const {
        return r == &specular_color_texture || r == &sheen_color_texture;
    }
    bool layered() const { return has_specular || has_clearcoat || has_sheen || has_transmission; }
};

struct Mesh {
    std::string name;
    std::vector<glm::vec3> positions;  // world space
    std::vector<glm::vec3> normals;    // world space, unit; always filled by loaders
    std::vector<glm::vec2> uvs;        // internal (v = 0 top) convention; may be empty
    std::vector<glm::vec4> tangents;   // xyz + handedness w; filled when uvs exist
    std::vector<glm::vec2> uvs1;       // TEXCOORD_1, same convention; may be empty
    std::vector<glm::vec4> colors;     // COLOR_0, linear RGBA (RGB files: a = 1); empty = white
    std::vector<std::uint32_t> indices; // by topology: triangles, line pairs or points
    int material = 0;                  // index into Scene::materials
    // Strips, fans and loops are turned into these lists by the loaders.
    enum class Topology { Triangles, Lines, Points };
    Topology topology = Topology::Triangles;
    // Placed by a mirroring transform (negative determinant): the loader
    // reversed the triangles' winding and the tangents' handedness.
    bool mirrored = false;
    // Where a glTF mesh came from, for posing (scene/animation.h): the node
    // that instances it and the primitive's index in its mesh; -1 elsewhere.
    int source_node = -1, source_primitive = -1;
    // The primitive's vertex of each vertex here, once the loader has dropped
    // unused ones; filled only when the scene has a SceneSource.
    std::vector<std::uint32_t> source_vertex;
    // KHR_materials_variants: the material of each of Scene::variants on
    // this primitive, -1 where its mappings name none (the default, `material`,
    // is drawn); empty when the primitive has no mappings.
    std::vector<int> variant_materials;
};

struct Light {
    enum class Type { Directional, Point, Spot };
    Type type = Type::Directional;
    // Directional and spot: unit vector TOWARDS the light (a spot shines along -direction).
    glm::vec3 direction{0.0f, 1.0f, 0.0f};
    glm::vec3 position{0.0f};              // point and spot
    glm::vec3 color{1.0f};
    float intensity = 1.0f;                // radiance = color * intensity (/ d^2 for points and spots)
    float range = 0.0f;                    // point and spot: > 0 a cut-off distance, 0 infinite
    float inner_cone = 0.0f;               // spot: radians from the axis, 0 <= inner < outer <= pi/2
    float outer_cone = 0.78539816f;
    int source_node = -1;                  // the glTF node that places it (posed by scene/animation.h)
};

struct Bounds {
    glm::vec3 lo{1e30f}, hi{-1e30f};
    bool empty() const { return lo.x > hi.x; }
    void add(const glm::vec3& p) { lo = glm::min(lo, p); hi = glm::max(hi, p); }
    glm::vec3 center() const { return (lo + hi) * 0.5f; }
    float radius() const { return empty() ? 0.0f : glm::length(hi - lo) * 0.5f; }
};

struct SceneSource;  // scene/animation.h: nodes, skins, morph targets, animations

// A camera of the file (glTF "cameras"), placed by the node `node`.
struct SceneCamera {
    std::string name;
    int node = -1;
    bool orthographic = false;
    double yfov = 0.8;          // perspective: vertical field of view, radians
    double aspect_ratio = 0.0;  // perspective: 0 when the file gives none
    double xmag = 1.0, ymag = 1.0;  // orthographic: half width and height
    double znear = 0.1;
    double zfar = 0.0;          // 0: infinite (perspective without zfar)
};

struct Scene {
    std::vector<Mesh> meshes;
    std::vector<Material> materials;     // never empty after loading
    std::vector<ImageSource> images;
    std::vector<Light> lights;           // from the file (KHR_lights_punctual)
    // An equirect environment (linear radiance) that comes with the scene:
    // the built-in scene's sky; null = none. `render --env` overrides it.
    std::shared_ptr<const Image> environment;
    std::vector<std::string> warnings;   // one line each: "FILE: what was ignored/fallen back"
    // What posing needs (skins, morph targets, animations; scene/animation.h);
    // null for a static file, whose meshes never change.
    std::shared_ptr<const SceneSource> source;
    std::vector<SceneCamera> cameras;          // the file's, in node order
    std::vector<std::string> animation_names;  // one per animation ("animation N" when unnamed)
    std::vector<std::string> extensions_used, extensions_required;  // glTF's lists, for render --list
    // KHR_materials_variants: the variants' names, in the file's order (an
    // unnamed or malformed entry keeps its place as "variant N"); `render
    // --variant` picks one, Mesh::variant_materials maps it.
    std::vector<std::string> variants;
    // Counts the poses applied, so that what is drawn from the meshes
    // (shadow maps) is redrawn when they change.
    std::uint64_t pose_serial = 0;

    Bounds bounds() const {
        Bounds b;
        for (const Mesh& m : meshes)
            for (const glm::vec3& p : m.positions) b.add(p);
        return b;
    }
    std::size_t triangle_count() const {
        std::size_t n = 0;
        for (const Mesh& m : meshes)
            if (m.topology == Mesh::Topology::Triangles) n += m.indices.size() / 3;
        return n;
    }
};

} // namespace prast

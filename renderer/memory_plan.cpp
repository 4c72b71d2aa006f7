#include "renderer/memory_plan.h"

#include <algorithm>
#include <set>
#include <utility>

#include <unistd.h>

#include "scene/image.h"
#include "scene/messages.h"
#include "shading/ibl/environment.h"

namespace prast {

namespace {

constexpr std::uint64_t kPipelineBytesPerVertex = 96;    // clip position and varyings
constexpr std::uint64_t kPipelineBytesPerTriangle = 96;  // set-up edges and bin entries
constexpr std::uint64_t kShadowBytesPerTexel = 8;        // the drawn depth and the stored distance
// step's record: a triangle's set-up, pieces and tiles; a covered sample's
// depth, and its 4x4 block's share of a block record.
constexpr std::uint64_t kRecordBytesPerTriangle = 320;
constexpr std::uint64_t kRecordBytesPerSample = 8;
constexpr std::uint64_t kRecordDepthComplexity = 2;

std::string n(std::uint64_t v) { return std::to_string(v); }

} // namespace

std::string MemoryPlan::describe() const {
    std::string s = "about " + n(total()) + " bytes (scene " + n(scene) + ", textures " + n(textures) + " for " +
                    n(texels) + " texels in " + std::to_string(images) + " images, drawing " + n(pipeline) +
                    ", image " + n(image);
    if (environment)
        s += ", environment " + n(environment) + (environment_name.empty() ? "" : " for " + printable(environment_name));
    if (shadows) s += ", shadow maps " + n(shadows);
    if (recording) s += ", recording " + n(recording);
    return s + ")";
}

std::uint64_t memory_budget() {
    const long pages = sysconf(_SC_PHYS_PAGES), page = sysconf(_SC_PAGE_SIZE);
    if (pages <= 0 || page <= 0) return std::uint64_t(4) << 30;  // unknown: assume 8 GiB of RAM
    return std::uint64_t(pages) * std::uint64_t(page) / 2;
}

MemoryPlan plan_memory(const Scene& scene, int width, int height, std::uint64_t bytes_per_pixel) {
    MemoryPlan plan;
    std::size_t max_vertices = 0, max_triangles = 0;
    for (const Mesh& m : scene.meshes) {
        plan.scene += m.positions.size() * sizeof(glm::vec3) + m.normals.size() * sizeof(glm::vec3) +
                      m.uvs.size() * sizeof(glm::vec2) + m.tangents.size() * sizeof(glm::vec4) +
                      m.indices.size() * sizeof(std::uint32_t);
        max_vertices = std::max(max_vertices, m.positions.size());
        max_triangles = std::max(max_triangles, m.indices.size() / 3);
    }
    plan.pipeline = max_vertices * kPipelineBytesPerVertex + max_triangles * kPipelineBytesPerTriangle;
    // Each (image, colour space) a material uses is one texture.
    std::set<std::pair<int, bool>> used;
    for (const Material& m : scene.materials) {
        for (const TextureRef* r : {&m.base_color, &m.emissive}) used.insert({r->image, true});
        for (const TextureRef* r : {&m.metallic_roughness, &m.roughness, &m.metallic, &m.normal, &m.occlusion})
            used.insert({r->image, false});
        for (const TextureRef* r : m.extension_textures()) used.insert({r->image, m.extension_texture_srgb(r)});
    }
    std::vector<int> per_image(scene.images.size(), 0);
    for (const auto& u : used)
        if (u.first >= 0 && std::size_t(u.first) < scene.images.size()) ++per_image[std::size_t(u.first)];
    for (std::size_t i = 0; i < scene.images.size(); ++i) {
        if (per_image[i] == 0) continue;
        int w = 0, h = 0, texel_bytes = 16;
        const ImageSource& src = scene.images[i];
        if (src.decoded) {
            w = src.decoded->width;
            h = src.decoded->height;
            texel_bytes = src.decoded->is_8bit() ? src.decoded->channels : 16;
        } else if (!image_dimensions(src, w, h, &texel_bytes)) {
            continue;  // decoding will fail and say why
        }
        const std::uint64_t texels = std::uint64_t(w) * std::uint64_t(h) * std::uint64_t(per_image[i]);
        plan.texels += texels;
        plan.textures += texels * std::uint64_t(texel_bytes) * 4 / 3;
        ++plan.images;
    }
    plan.image = std::uint64_t(width) * std::uint64_t(height) * bytes_per_pixel;
    return plan;
}

void plan_environment(MemoryPlan& plan, const Scene& scene, const std::string& env_path) {
    int width = scene.environment ? scene.environment->width : 0;
    int height = scene.environment ? scene.environment->height : 0;
    if (!env_path.empty()) {
        ImageSource src;
        src.path = src.name = env_path;
        if (!image_dimensions(src, width, height)) return;
    }
    if (width <= 0 || height <= 0 || std::int64_t(width) * std::int64_t(height) > kMaxImageTexels) return;
    plan.environment_name = env_path;
    // The decoded file (float RGBA); the source resampled to at most kMaxWidth
    // with its mip chain, and its sampling tables (a float per texel); the
    // prefiltered levels are at most a third of level 0 again.
    const std::uint64_t decoded = std::uint64_t(width) * std::uint64_t(height) * 16;
    const std::uint64_t w = std::uint64_t(std::min(width, Environment::kMaxWidth));
    const std::uint64_t h = std::max<std::uint64_t>(1, std::uint64_t(height) * w / std::uint64_t(width));
    plan.environment += decoded + w * h * (16 * 4 / 3 + 4) + w * h * 16 / 3;
}

void plan_shadows(MemoryPlan& plan, const std::vector<ShadingLight>& lights, const ShadowSettings& settings) {
    if (!settings.enabled) return;
    const std::uint64_t side = std::uint64_t(settings.size) + 2 * kShadowPad;
    const std::uint64_t face = std::uint64_t(std::max(8, settings.size / 2)) + 2 * kShadowPad;
    for (const ShadingLight& l : lights)
        plan.shadows += (l.point ? 6 * face * face : side * side) * kShadowBytesPerTexel;
}

void plan_recording(MemoryPlan& plan, const Scene& scene, int width, int height, int samples) {
    std::uint64_t triangles = 0;
    for (const Mesh& m : scene.meshes) triangles += m.indices.size() / 3;
    plan.recording += triangles * kRecordBytesPerTriangle + std::uint64_t(width) * std::uint64_t(height) *
                                                                std::uint64_t(std::max(1, samples)) *
                                                                kRecordBytesPerSample * kRecordDepthComplexity;
}

} // namespace prast

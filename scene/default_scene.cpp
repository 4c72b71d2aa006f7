// The built-in scene; see default_scene.h.
#include "scene/default_scene.h"

#include <memory>

#include "scene/mesh_gen.h"
#include "scene/procedural_images.h"

namespace prast {

namespace {
constexpr int kColumns = 6;  // roughness 0 .. 1
constexpr int kRows = 4;     // metallic 0 .. 1 (bottom to top)
constexpr float kSpacing = 1.0f;
constexpr float kRadius = 0.4f;
constexpr int kTextureSize = 512;
} // namespace

DefaultScene make_default_scene() {
    DefaultScene d;
    Scene& s = d.scene;

    // Procedural tile textures, already linear.
    auto add_image = [&](Image img, const char* name) {
        ImageSource src;
        src.name = name;
        src.decoded = std::make_shared<const Image>(std::move(img));
        s.images.push_back(std::move(src));
        return int(s.images.size() - 1);
    };
    int albedo = add_image(make_tiles_albedo(kTextureSize), "builtin:tiles_albedo");
    int normal = add_image(make_tiles_normal(kTextureSize), "builtin:tiles_normal");
    int rm = add_image(make_tiles_roughness_metal(kTextureSize), "builtin:tiles_roughness_metal");

    // One material per sphere: a warm gold-white base colour.
    for (int row = 0; row < kRows; ++row)
        for (int col = 0; col < kColumns; ++col) {
            Material m;
            m.name = "sphere_m" + std::to_string(row) + "_r" + std::to_string(col);
            m.base_color_factor = glm::vec4(0.95f, 0.64f, 0.54f, 1.0f);  // copper-ish
            m.metallic_factor = float(row) / float(kRows - 1);
            m.roughness_factor = float(col) / float(kColumns - 1);
            s.materials.push_back(m);
            glm::vec3 c((float(col) - 0.5f * float(kColumns - 1)) * kSpacing,
                        0.9f + float(row) * kSpacing, 0.0f);
            s.meshes.push_back(make_uv_sphere(c, kRadius, 64, 32, int(s.materials.size() - 1)));
        }

    Material floor;
    floor.name = "tiles";
    floor.base_color_factor = glm::vec4(1.0f);
    floor.metallic_factor = 1.0f;
    floor.roughness_factor = 1.0f;
    floor.base_color.image = albedo;
    floor.normal.image = normal;
    floor.metallic_roughness.image = rm;
    s.materials.push_back(floor);
    s.meshes.push_back(make_floor(glm::vec3(0.0f, 0.5f, 1.0f), 4.5f, 8, 6.0f, int(s.materials.size() - 1)));

    Light sun;
    sun.type = Light::Type::Directional;
    sun.direction = glm::normalize(glm::vec3(-0.4f, 0.7f, 0.6f));
    sun.color = glm::vec3(1.0f, 0.96f, 0.9f);
    sun.intensity = 3.0f;
    Light lamp;
    lamp.type = Light::Type::Point;
    lamp.position = glm::vec3(2.5f, 2.0f, 3.0f);
    lamp.color = glm::vec3(0.6f, 0.75f, 1.0f);
    lamp.intensity = 12.0f;
    s.lights = {sun, lamp};

    d.camera.eye = glm::vec3(0.0f, 3.2f, 7.6f);
    d.camera.target = glm::vec3(0.0f, 1.9f, 0.0f);
    d.camera.fov_y_deg = 45.0f;
    fit_clip_planes(d.camera, s.bounds());
    return d;
}

} // namespace prast

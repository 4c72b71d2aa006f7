// The built-in scene; see default_scene.h.
#include "scene/default_scene.h"

#include <algorithm>
#include <cmath>
#include <memory>
#include <thread>
#include <vector>

#include "scene/det_math.h"
#include "scene/mesh_gen.h"
#include "scene/parallel.h"
#include "scene/procedural_images.h"

namespace prast {

namespace {
constexpr int kColumns = 6;  // roughness 0 .. 1
constexpr int kRows = 4;     // metallic 0 .. 1 (bottom to top)
constexpr float kSpacing = 1.0f;
constexpr float kRadius = 0.4f;
constexpr int kTextureSize = 512;
constexpr int kSkyWidth = 512;
// Towards the sun: the sun light's direction and the sky's sun disc.
const glm::vec3 kSunDirection = glm::normalize(glm::vec3(-0.4f, 0.7f, 0.6f));

float smoothstep(float e0, float e1, float x) {
    const float t = std::clamp((x - e0) / (e1 - e0), 0.0f, 1.0f);
    return t * t * (3.0f - 2.0f * t);
}
} // namespace

Image make_default_sky(int width) {
    Image img;
    img.width = width;
    img.height = std::max(1, width / 2);
    img.rgba.assign(std::size_t(img.width) * std::size_t(img.height) * 4, 0.0f);
    const glm::vec3 zenith(0.06f, 0.12f, 0.32f), horizon(0.32f, 0.36f, 0.42f);
    const glm::vec3 ground(0.07f, 0.06f, 0.05f), sun(60.0f, 55.0f, 48.0f);
    const float sun_radius = 0.03f;  // radians, about 1.7 degrees
    const float texel = 3.14159265f / float(img.height);
    // The direction of a texel centre (docs/conventions.md "Environment maps"):
    // its sines and cosines of phi per column and of theta per row.
    std::vector<float> sin_phi(std::size_t(img.width)), cos_phi(std::size_t(img.width));
    for (int x = 0; x < img.width; ++x) {
        const float phi = ((float(x) + 0.5f) / float(img.width) - 0.5f) * 6.28318531f;
        sin_phi[std::size_t(x)] = det::sin(phi);
        cos_phi[std::size_t(x)] = det::cos(phi);
    }
    for (int y = 0; y < img.height; ++y) {
        const float theta = (float(y) + 0.5f) / float(img.height) * 3.14159265f;
        const float sin_theta = det::sin(theta), cos_theta = det::cos(theta);
        for (int x = 0; x < img.width; ++x) {
            const glm::vec3 d(sin_theta * sin_phi[std::size_t(x)], cos_theta, -sin_theta * cos_phi[std::size_t(x)]);
            const float up = std::max(d.y, 0.0f);
            glm::vec3 sky = glm::mix(horizon, zenith, std::sqrt(up));
            // The ground darkens towards the nadir; one texel of blend at the horizon.
            const glm::vec3 below = ground * (0.6f + 0.4f * (1.0f + d.y));
            glm::vec3 c = glm::mix(below, sky, smoothstep(-texel, texel, d.y));
            // Sun disc with an anti-aliased rim and a faint glow.
            const float angle = det::acos(std::clamp(glm::dot(d, kSunDirection), -1.0f, 1.0f));
            c += sun * (1.0f - smoothstep(sun_radius - texel, sun_radius + texel, angle));
            c += glm::vec3(1.0f, 0.9f, 0.7f) * (0.6f * det::exp(-angle / 0.12f));
            img.set(x, y, glm::vec4(c, 1.0f));
        }
    }
    return img;
}

DefaultScene make_default_scene(int threads) {
    DefaultScene d;
    Scene& s = d.scene;

    // The images take most of the build: the sky, and the tile maps in bands
    // of rows.
    TileMaps maps = tile_maps_storage(kTextureSize);
    Image sky_img;
    constexpr int kBand = 32;
    const int bands = (kTextureSize + kBand - 1) / kBand;
    if (threads <= 0) threads = int(std::max(1u, std::thread::hardware_concurrency()));
    run_on_threads(threads, 1 + bands, [&](int task) {
        if (task == 0) {
            sky_img = make_default_sky(kSkyWidth);
        } else {
            const int y = (task - 1) * kBand;
            fill_tile_map_rows(maps, y, std::min(y + kBand, kTextureSize));
        }
    });

    // Procedural tile textures, already linear.
    auto add_image = [&](Image img, const char* name) {
        ImageSource src;
        src.name = name;
        src.decoded = std::make_shared<const Image>(std::move(img));
        s.images.push_back(std::move(src));
        return int(s.images.size() - 1);
    };
    int albedo = add_image(std::move(maps.albedo), "builtin:tiles_albedo");
    int normal = add_image(std::move(maps.normal), "builtin:tiles_normal");
    int rm = add_image(std::move(maps.roughness_metal), "builtin:tiles_roughness_metal");

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
    sun.direction = kSunDirection;
    sun.color = glm::vec3(1.0f, 0.96f, 0.9f);
    sun.intensity = 3.0f;
    Light lamp;
    lamp.type = Light::Type::Point;
    lamp.position = glm::vec3(2.5f, 2.0f, 3.0f);
    lamp.color = glm::vec3(0.6f, 0.75f, 1.0f);
    lamp.intensity = 12.0f;
    s.lights = {sun, lamp};
    s.environment = std::make_shared<const Image>(std::move(sky_img));

    d.camera.eye = glm::vec3(0.0f, 3.2f, 7.6f);
    d.camera.target = glm::vec3(0.0f, 1.9f, 0.0f);
    d.camera.fov_y_deg = 45.0f;
    fit_clip_planes(d.camera, s.bounds());
    return d;
}

} // namespace prast

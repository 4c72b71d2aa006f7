// Drawing order of blended meshes; see transparency.h.
#include "renderer/draw_order.h"

#include <algorithm>
#include <cmath>

namespace prast {

glm::vec3 mesh_centre(const Mesh& mesh) {
    Bounds b;
    for (const glm::vec3& p : mesh.positions)
        if (std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z)) b.add(p);
    return b.empty() ? glm::vec3(0.0f) : b.center();
}

bool mesh_blended(const Scene& scene, std::size_t i) {
    const int m = scene.meshes[i].material;
    return m >= 0 && std::size_t(m) < scene.materials.size() &&
           scene.materials[std::size_t(m)].alpha_mode == AlphaMode::Blend;
}

std::vector<std::size_t> draw_order(const Scene& scene, const glm::vec3& eye) {
    std::vector<std::size_t> order, blended;
    std::vector<float> distance(scene.meshes.size(), 0.0f);
    for (std::size_t i = 0; i < scene.meshes.size(); ++i) {
        if (!mesh_blended(scene, i)) {
            order.push_back(i);
            continue;
        }
        blended.push_back(i);
        // In double, so that the order does not hang on float rounding of
        // nearly equal distances more than it must.
        const glm::dvec3 d = glm::dvec3(mesh_centre(scene.meshes[i])) - glm::dvec3(eye);
        distance[i] = float(std::sqrt(glm::dot(d, d)));
    }
    std::stable_sort(blended.begin(), blended.end(),
                     [&](std::size_t a, std::size_t b) { return distance[a] > distance[b]; });
    order.insert(order.end(), blended.begin(), blended.end());
    return order;
}

} // namespace prast

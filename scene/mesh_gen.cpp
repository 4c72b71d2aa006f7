// Procedural meshes; see mesh_gen.h.
#include "scene/mesh_gen.h"

#include <cmath>

#include <glm/gtc/constants.hpp>

#include "scene/det_math.h"

namespace prast {

namespace {
// Two triangles per grid cell, counter-clockwise for a viewer on the side the
// grid's (row down, column right) layout is seen from.
void grid_indices(Mesh& m, int rows, int cols) {
    for (int i = 0; i < rows; ++i)
        for (int j = 0; j < cols; ++j) {
            std::uint32_t a = std::uint32_t(i * (cols + 1) + j), b = a + std::uint32_t(cols + 1);
            m.indices.insert(m.indices.end(), {a, b, b + 1, a, b + 1, a + 1});
        }
}
} // namespace

Mesh make_uv_sphere(glm::vec3 center, float radius, int segments, int rings, int material) {
    Mesh m;
    m.name = "sphere";
    m.material = material;
    const float pi = glm::pi<float>();
    for (int i = 0; i <= rings; ++i) {
        float theta = pi * float(i) / float(rings);
        for (int j = 0; j <= segments; ++j) {
            float phi = 2.0f * pi * float(j) / float(segments);
            glm::vec3 n(det::sin(theta) * det::cos(phi), det::cos(theta), -det::sin(theta) * det::sin(phi));
            m.positions.push_back(center + radius * n);
            m.normals.push_back(n);
            m.uvs.push_back({float(j) / float(segments), float(i) / float(rings)});
            // dP/dphi; B = cross(N, T) points to the north pole (-v): w = +1.
            glm::vec3 t(-det::sin(phi), 0.0f, -det::cos(phi));
            m.tangents.push_back(glm::vec4(t, 1.0f));
        }
    }
    grid_indices(m, rings, segments);
    return m;
}

Mesh make_floor(glm::vec3 center, float half_size, int cells, float uv_repeat, int material) {
    Mesh m;
    m.name = "floor";
    m.material = material;
    for (int i = 0; i <= cells; ++i)
        for (int j = 0; j <= cells; ++j) {
            float s = float(j) / float(cells), t = float(i) / float(cells);
            m.positions.push_back(center + glm::vec3((2.0f * s - 1.0f) * half_size, 0.0f,
                                                     (2.0f * t - 1.0f) * half_size));
            m.normals.push_back({0.0f, 1.0f, 0.0f});
            m.uvs.push_back({s * uv_repeat, t * uv_repeat});
            // T = +x; B = cross(+y, +x) = -z, which is -v: w = +1.
            m.tangents.push_back({1.0f, 0.0f, 0.0f, 1.0f});
        }
    grid_indices(m, cells, cells);
    return m;
}

} // namespace prast

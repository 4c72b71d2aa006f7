// Smooth normals and UV-derived tangent frames (see tangents.h). Sums are kept
// in double so that millimetre-sized triangles of a scanned mesh do not lose
// their direction to rounding.
#include "scene/tangents.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "scene/det_math.h"

namespace prast {

namespace {

bool finite(const glm::dvec3& v) {
    return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

// The angle between two edges leaving a corner; 0 when one of them is empty.
double corner_angle(const glm::dvec3& a, const glm::dvec3& b) {
    const double la = glm::length(a), lb = glm::length(b);
    if (!(la > 0.0) || !(lb > 0.0)) return 0.0;
    return det::acos(std::clamp(glm::dot(a, b) / (la * lb), -1.0, 1.0));
}

// The three corner indices of triangle t, or false when one is out of range.
bool triangle(const Mesh& mesh, std::size_t t, std::uint32_t (&v)[3]) {
    for (int k = 0; k < 3; ++k) {
        v[k] = mesh.indices[3 * t + std::size_t(k)];
        if (v[k] >= mesh.positions.size()) return false;
    }
    return true;
}

// Lines and points carry no surface: no triangle contributes to their frames.
std::size_t triangle_count(const Mesh& mesh) {
    return mesh.topology == Mesh::Topology::Triangles ? mesh.indices.size() / 3 : 0;
}

} // namespace

glm::vec3 any_perpendicular(const glm::vec3& n) {
    const glm::vec3 axis = std::abs(n.x) < 0.9f ? glm::vec3(1, 0, 0) : glm::vec3(0, 1, 0);
    const glm::vec3 p = glm::cross(n, axis);
    const float len = glm::length(p);
    return len > 0.0f && std::isfinite(len) ? p / len : glm::vec3(1, 0, 0); // n was zero or NaN
}

void compute_normals(Mesh& mesh) {
    std::vector<glm::dvec3> sum(mesh.positions.size(), glm::dvec3(0.0));
    const std::size_t triangles = triangle_count(mesh);
    for (std::size_t t = 0; t < triangles; ++t) {
        std::uint32_t v[3];
        if (!triangle(mesh, t, v)) continue;
        const glm::dvec3 p0(mesh.positions[v[0]]), p1(mesh.positions[v[1]]),
            p2(mesh.positions[v[2]]);
        // |cross| is twice the area: the sum is area-weighted.
        const glm::dvec3 n = glm::cross(p1 - p0, p2 - p0);
        if (!finite(n)) continue;
        for (std::uint32_t i : v) sum[i] += n;
    }
    mesh.normals.resize(mesh.positions.size());
    for (std::size_t i = 0; i < sum.size(); ++i) {
        const double len = glm::length(sum[i]);
        mesh.normals[i] = len > 0.0 && std::isfinite(len) ? glm::vec3(sum[i] / len)
                                                           : glm::vec3(0, 0, 1);
    }
}

void compute_tangents(Mesh& mesh) { compute_tangents(mesh, mesh.uvs); }

void compute_tangents(Mesh& mesh, const std::vector<glm::vec2>& uvs) {
    const std::size_t n = mesh.positions.size();
    if (uvs.size() != n || n == 0) {
        mesh.tangents.clear();
        return;
    }
    if (mesh.normals.size() != n) compute_normals(mesh);

    // Accumulate T = dP/du and B = -dP/dv per corner
    std::vector<glm::dvec3> sum_t(n, glm::dvec3(0.0)), sum_b(n, glm::dvec3(0.0));
    const std::size_t triangles = triangle_count(mesh);
    for (std::size_t t = 0; t < triangles; ++t) {
        std::uint32_t v[3];
        if (!triangle(mesh, t, v)) continue;
        const glm::dvec3 p[3] = {glm::dvec3(mesh.positions[v[0]]), glm::dvec3(mesh.positions[v[1]]),
                                 glm::dvec3(mesh.positions[v[2]])};
        const glm::dvec2 uv[3] = {glm::dvec2(uvs[v[0]]), glm::dvec2(uvs[v[1]]), glm::dvec2(uvs[v[2]])};
        const glm::dvec3 e1 = p[1] - p[0], e2 = p[2] - p[0];
        const glm::dvec2 d1 = uv[1] - uv[0], d2 = uv[2] - uv[0];
        const double r = d1.x * d2.y - d2.x * d1.y;
        if (r == 0.0 || !std::isfinite(r)) continue; // degenerate UVs: no information
        const glm::dvec3 dp_du = (e1 * d2.y - e2 * d1.y) / r;
        const glm::dvec3 dp_dv = (e2 * d1.x - e1 * d2.x) / r;
        const double lt = glm::length(dp_du), lb = glm::length(dp_dv);
        if (!(lt > 0.0) || !(lb > 0.0) || !std::isfinite(lt) || !std::isfinite(lb)) continue;
        const glm::dvec3 tangent = dp_du / lt;
        const glm::dvec3 bitangent = -dp_dv / lb; // up the image = -v internally
        for (int k = 0; k < 3; ++k) {
            const double w = corner_angle(p[(k + 1) % 3] - p[k], p[(k + 2) % 3] - p[k]);
            sum_t[v[k]] += tangent * w;
            sum_b[v[k]] += bitangent * w;
        }
    }

    // Gram-Schmidt against N, handedness from the accumulated bitangent. A
    // direction within 0.06 degrees of N (relative residual 1e-3) is taken as
    // no direction: what is left of it is rounding noise.
    mesh.tangents.resize(n);
    for (std::size_t i = 0; i < n; ++i) {
        // Renormalised in double: a float "unit" normal is off by ~1e-7, which
        // would leave that much of N in a short residual.
        const glm::dvec3 nrm = glm::normalize(glm::dvec3(mesh.normals[i]));
        glm::dvec3 t = sum_t[i] - nrm * glm::dot(nrm, sum_t[i]);
        double len = glm::length(t);
        if (!(len > 1e-3 * glm::length(sum_t[i])) || !std::isfinite(len)) {
            // No usable u direction: fall back on the bitangent (B = N x T for w = 1).
            t = glm::cross(sum_b[i], nrm);
            len = glm::length(t);
            if (!(len > 1e-3 * glm::length(sum_b[i]))) len = 0.0;
        }
        if (!(len > 0.0) || !std::isfinite(len)) {
            mesh.tangents[i] = glm::vec4(any_perpendicular(mesh.normals[i]), 1.0f);
            continue;
        }
        t /= len;
        const float w = glm::dot(glm::cross(nrm, t), sum_b[i]) < 0.0 ? -1.0f : 1.0f;
        mesh.tangents[i] = glm::vec4(glm::vec3(t), w);
    }
}

} // namespace prast

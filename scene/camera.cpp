// Camera matrices and framing; see camera.h.
#include "scene/camera.h"

#include <algorithm>
#include <cmath>

#include <glm/gtc/matrix_transform.hpp>

#include "scene/det_math.h"

namespace prast {

glm::mat4 Camera::view() const { return glm::lookAt(eye, target, up); }

glm::mat4 Camera::projection(float aspect) const {
    if (orthographic) {
        const float x = ortho_ymag * aspect;
        return glm::ortho(-x, x, -ortho_ymag, ortho_ymag, near_plane, far_plane);
    }
    // glm::perspective's and glm::infinitePerspective's matrices (right-handed,
    // depth -1 to 1), the same float expressions, with det::tan for the C
    // library's tanf, which rounds differently on x86-64 and aarch64.
    const float fovy = glm::radians(fov_y_deg);
    const float tan_half = det::tan(fovy / 2.0f);
    glm::mat4 m(0.0f);
    if (infinite_far) {
        const float range = tan_half * near_plane;
        const float left = -range * aspect, right = range * aspect, bottom = -range, top = range;
        m[0][0] = (2.0f * near_plane) / (right - left);
        m[1][1] = (2.0f * near_plane) / (top - bottom);
        m[2][2] = -1.0f;
        m[2][3] = -1.0f;
        m[3][2] = -2.0f * near_plane;
        return m;
    }
    m[0][0] = 1.0f / (aspect * tan_half);
    m[1][1] = 1.0f / tan_half;
    m[2][2] = -(far_plane + near_plane) / (far_plane - near_plane);
    m[2][3] = -1.0f;
    m[3][2] = -(2.0f * far_plane * near_plane) / (far_plane - near_plane);
    return m;
}

void fit_clip_planes(Camera& cam, const Bounds& b) {
    float r = std::max(b.radius(), 1e-4f);
    float d = glm::length(cam.eye - b.center());
    // Far encloses the sphere; near stays a sane fraction of it so depth keeps
    // its precision when the eye is inside the bounds.
    cam.far_plane = d + r * 1.05f;
    cam.near_plane = std::max(d - r * 1.05f, cam.far_plane * 1e-4f);
}

Camera frame_bounds(const Bounds& b, float fov_y_deg, float aspect) {
    Camera cam;
    cam.fov_y_deg = fov_y_deg;
    float r = std::max(b.radius(), 1e-4f);
    // The tighter of the vertical and horizontal half-angles must hold the sphere.
    float half_v = glm::radians(fov_y_deg) * 0.5f;
    float half_h = det::atan(det::tan(half_v) * aspect);
    float half = std::min(half_v, half_h);
    float dist = r / det::sin(half) * 1.02f;
    glm::vec3 dir = glm::normalize(glm::vec3(0.0f, 0.35f, 1.0f));
    cam.target = b.center();
    cam.eye = cam.target + dir * dist;
    fit_clip_planes(cam, b);
    return cam;
}

namespace {

// The framing's view basis for a direction `dir` (target to eye, unit):
// right, up, forward (eye to target).
struct ViewBasis {
    glm::dvec3 r, u, f;
};

ViewBasis view_basis(const glm::dvec3& dir) {
    ViewBasis b;
    b.f = -dir;
    b.r = glm::normalize(glm::cross(b.f, glm::dvec3(0.0, 1.0, 0.0)));
    b.u = glm::cross(b.r, b.f);
    return b;
}

} // namespace

Camera frame_scene(const Scene& scene, float fov_y_deg, float aspect, double orbit_deg) {
    const Bounds bounds = scene.bounds();
    Camera fallback = frame_bounds(bounds, fov_y_deg, aspect);
    if (bounds.empty()) return fallback;
    // In double: the planes below subtract nearly equal depths.
    const double ky = det::tan(double(glm::radians(fov_y_deg)) * 0.5) * kFrameFill;
    const double kx = ky * double(aspect);
    const glm::dvec3 c(bounds.center());
    const glm::dvec3 dir = glm::normalize(glm::dvec3(0.0, 0.35, 1.0));
    const ViewBasis v = view_basis(dir);
    // A vertex at (x, y, z) in the basis, relative to c, is inside the
    // frustum of an eye at (ex, ey, ez) when |x - ex| <= kx (z - ez) and
    // |y - ey| <= ky (z - ez). For each axis the two tightest planes meet
    // at the eye that is centred on the vertices and closest to them.
    double a = INFINITY, b = INFINITY, cc = INFINITY, d = INFINITY, zmin = INFINITY;
    for (const Mesh& m : scene.meshes)
        for (const glm::vec3& p : m.positions) {
            const glm::dvec3 q = glm::dvec3(p) - c;
            const double x = glm::dot(q, v.r), y = glm::dot(q, v.u), z = glm::dot(q, v.f);
            a = std::min(a, z - x / kx);
            b = std::min(b, z + x / kx);
            cc = std::min(cc, z - y / ky);
            d = std::min(d, z + y / ky);
            zmin = std::min(zmin, z);
        }
    double ex = kx * (b - a) * 0.5, ey = ky * (d - cc) * 0.5;
    const bool x_tight = (a + b) * 0.5 <= (cc + d) * 0.5;
    const double ez = std::min((a + b) * 0.5, (cc + d) * 0.5);
    const double radius = std::max(double(bounds.radius()), 1e-4);
    // Vertices on one line along the view span nothing to fit.
    if (!(ez < zmin - 1e-3 * radius) || !std::isfinite(ez)) return fallback;
    // The looser axis, seen from ez rather than from its own closest eye,
    // is centred again: the offset s where the largest and the smallest of
    // (w_i - s) / (z_i - ez) cancel, by bisection (their sum falls with s).
    {
        const bool along_x = !x_tight;
        double lo = INFINITY, hi = -INFINITY;
        for (const Mesh& m : scene.meshes)
            for (const glm::vec3& p : m.positions) {
                const double w = glm::dot(glm::dvec3(p) - c, along_x ? v.r : v.u);
                lo = std::min(lo, w), hi = std::max(hi, w);
            }
        for (int it = 0; it < 48; ++it) {
            const double s = (lo + hi) * 0.5;
            double gmax = -INFINITY, gmin = INFINITY;
            for (const Mesh& m : scene.meshes)
                for (const glm::vec3& p : m.positions) {
                    const glm::dvec3 q = glm::dvec3(p) - c;
                    const double g = (glm::dot(q, along_x ? v.r : v.u) - s) / (glm::dot(q, v.f) - ez);
                    gmax = std::max(gmax, g), gmin = std::min(gmin, g);
                }
            if (gmax + gmin > 0.0) lo = s;
            else hi = s;
        }
        (along_x ? ex : ey) = (lo + hi) * 0.5;
    }
    const glm::dvec3 target = c + v.r * ex + v.u * ey;
    double dist = -ez;
    if (orbit_deg > 0.0) {
        // Turning the eye by t around the vertical axis through the target:
        // the centred target stays, the distance grows to what every sampled
        // angle needs.
        constexpr int kOrbitSamples = 72;
        for (int k = 1; k <= kOrbitSamples; ++k) {
            const double t = glm::radians(orbit_deg) * double(k) / double(kOrbitSamples);
            const double ct = det::cos(t), st = det::sin(t);
            const glm::dvec3 dk(dir.x * ct + dir.z * st, dir.y, -dir.x * st + dir.z * ct);
            const ViewBasis w = view_basis(dk);
            for (const Mesh& m : scene.meshes)
                for (const glm::vec3& p : m.positions) {
                    const glm::dvec3 q = glm::dvec3(p) - target;
                    const double x = glm::dot(q, w.r), y = glm::dot(q, w.u), z = glm::dot(q, w.f);
                    dist = std::max(dist, std::max(std::fabs(x) / kx, std::fabs(y) / ky) - z);
                }
        }
    }
    Camera cam;
    cam.fov_y_deg = fov_y_deg;
    cam.target = glm::vec3(target);
    cam.eye = glm::vec3(target + dir * dist);
    fit_clip_planes(cam, bounds);
    return cam;
}

} // namespace prast

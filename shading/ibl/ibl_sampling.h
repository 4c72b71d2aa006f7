// Deterministic low-discrepancy sampling of the sphere for the image-based
// lighting precomputations (DFG table, prefiltered radiance) and the reference
// integrator: radical inverses (Hammersley / Halton points) and the three
// hemisphere distributions they are warped into (GGX normals, cosine, uniform),
// each with its pdf. Double precision: these run once per table texel or per
// reference sample, never in the per-pixel split-sum path, and double keeps
// sums of thousands of terms accurate.
#pragma once

#include <cmath>
#include <cstdint>

#include <glm/glm.hpp>

#include "scene/det_math.h"

namespace prast {

// Van der Corput radical inverse in base 2: the bits of i mirrored about the
// binary point, in [0, 1).
inline double radical_inverse2(std::uint32_t i) {
    i = (i << 16) | (i >> 16);
    i = ((i & 0x00ff00ffu) << 8) | ((i & 0xff00ff00u) >> 8);
    i = ((i & 0x0f0f0f0fu) << 4) | ((i & 0xf0f0f0f0u) >> 4);
    i = ((i & 0x33333333u) << 2) | ((i & 0xccccccccu) >> 2);
    i = ((i & 0x55555555u) << 1) | ((i & 0xaaaaaaaau) >> 1);
    return double(i) * (1.0 / 4294967296.0);
}

// Radical inverse in base 3 (the Halton sequence's second prime).
inline double radical_inverse3(std::uint32_t i) {
    double inv = 1.0 / 3.0, f = inv, r = 0.0;
    while (i > 0) {
        r += f * double(i % 3u);
        i /= 3u;
        f *= inv;
    }
    return r;
}

// x^5 as a multiply chain (std::pow is not guaranteed to round the same everywhere).
inline double pow5d(double x) {
    const double x2 = x * x;
    return x2 * x2 * x;
}

// Point i of the n-point Hammersley set in [0, 1)^2.
inline glm::dvec2 hammersley(std::uint32_t i, std::uint32_t n) {
    return {(double(i) + 0.5) / double(n), radical_inverse2(i)};
}

// GGX (Trowbridge-Reitz) half vector about +Z with pdf D(h) (n.h), from
// u in [0, 1)^2 (Walter et al. 2007, eq. 35-36); alpha = r^2.
inline glm::dvec3 sample_ggx_half(glm::dvec2 u, double alpha) {
    const double phi = 2.0 * M_PI * u.x;
    // (a^2 - 1) written (a - 1)(a + 1) for accuracy near a = 1.
    const double cos2 = (1.0 - u.y) / (1.0 + (alpha - 1.0) * (alpha + 1.0) * u.y);
    const double c = std::sqrt(cos2), s = std::sqrt(std::max(0.0, 1.0 - cos2));
    return {s * det::cos(phi), s * det::sin(phi), c};
}

// GGX D in double, for the pdfs of the precomputations.
inline double D_GGX_d(double NoH, double alpha) {
    const double a2 = alpha * alpha;
    const double d = NoH * NoH * (a2 - 1.0) + 1.0;
    return a2 / (M_PI * d * d);
}

// Cosine-weighted direction about +Z, pdf = cos / pi (Malley's method).
inline glm::dvec3 sample_cosine(glm::dvec2 u) {
    const double phi = 2.0 * M_PI * u.x;
    const double s = std::sqrt(u.y), c = std::sqrt(std::max(0.0, 1.0 - u.y));
    return {s * det::cos(phi), s * det::sin(phi), c};
}

// An orthonormal frame (t, b, n) around the unit vector n (Duff et al. 2017,
// "Building an orthonormal basis, revisited"): no branch on a threshold, so
// neighbouring normals get neighbouring frames.
struct Frame {
    glm::dvec3 t, b, n;
    explicit Frame(const glm::dvec3& nn) : n(nn) {
        const double sign = std::copysign(1.0, n.z);
        const double a = -1.0 / (sign + n.z);
        const double bb = n.x * n.y * a;
        t = {1.0 + sign * n.x * n.x * a, sign * bb, -sign * n.x};
        b = {bb, sign + n.y * n.y * a, -n.y};
    }
    glm::dvec3 to_world(const glm::dvec3& local) const { return t * local.x + b * local.y + n * local.z; }
};

} // namespace prast

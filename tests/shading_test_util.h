// Helpers shared by the tests that hold a block (16-lane) shading path to its
// scalar reference bit for bit.
#pragma once

#include <cmath>
#include <cstdint>
#include <cstring>
#include <random>

#include <glm/glm.hpp>

#include "shading/surface.h"

namespace prast::test {

// The bit pattern of a float: equal bits, not merely equal values (tells
// -0 from +0 and one NaN from another).
inline std::uint32_t bits(float f) {
    std::uint32_t u;
    std::memcpy(&u, &f, 4);
    return u;
}

// A sun from a random upper direction and a point light at (1, 2, 3): one
// light of each kind, so both light paths are exercised.
inline void add_test_lights(ShadingContext& ctx, std::mt19937& rng) {
    std::uniform_real_distribution<float> sym(-1.0f, 1.0f);
    ShadingLight sun, lamp;
    sun.direction = glm::normalize(glm::vec3(sym(rng), 1.0f, sym(rng)));
    sun.radiance = {3.0f, 2.5f, 2.0f};
    lamp.point = true;
    lamp.position = {1.0f, 2.0f, 3.0f};
    lamp.radiance = {10.0f, 12.0f, 14.0f};
    ctx.lights = {sun, lamp};
}

// The 15-bit code of an 8-bit texel's byte in the fixed-point filter
// (docs/conventions.md, "Precision of the weights"), written apart from the
// texture's tables: b * 128 when linear, else round(decode(b / 255) * 32640),
// the decode in long double.
inline int reference_code(int b, bool srgb) {
    if (!srgb) return b * 128;
    const long double c = (long double)b / 255.0L;
    const long double lin = c <= 0.04045L ? c / 12.92L : std::pow((c + 0.055L) / 1.055L, 2.4L);
    return int(std::floor(lin * 32640.0L + 0.5L));
}

} // namespace prast::test

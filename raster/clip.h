// Clipping in homogeneous clip space. Near and far are real clip planes (a
// triangle crossing the camera plane must not wrap around); x and y only need
// clipping beyond the guard band, so ordinary off-screen triangles skip it.
#pragma once

#include <cstdint>

#include "raster/limits.h"

namespace prast {

enum ClipBits : std::uint32_t {
    // Outside the view frustum: used only to reject whole triangles.
    kOutLeft = 1u << 0, kOutRight = 1u << 1, kOutBottom = 1u << 2, kOutTop = 1u << 3,
    kOutNear = 1u << 4, kOutFar = 1u << 5,
    // Outside the guard band: these planes must be clipped against.
    kOutGuardLeft = 1u << 6, kOutGuardRight = 1u << 7,
    kOutGuardBottom = 1u << 8, kOutGuardTop = 1u << 9,
};
constexpr std::uint32_t kFrustumBits = 0x3Fu;
constexpr std::uint32_t kClipNeededBits = kOutNear | kOutFar | kOutGuardLeft | kOutGuardRight |
                                          kOutGuardBottom | kOutGuardTop;

struct GuardBand {
    float x = 1.0f, y = 1.0f;  // |x_ndc| <= x keeps window x within +-kGuardBandPixels
    static GuardBand for_viewport(int width, int height);
};

std::uint32_t outcode(const float* clip, const GuardBand& gb);

// Clips triangle (v[0], v[1], v[2]) -- each `stride` floats: xyzw then varyings --
// against the planes named in `planes` (kClipNeededBits). Writes the convex
// result polygon into out (kMaxClippedVertices * stride floats) and returns its
// vertex count (0 when nothing is left). An edge is always cut from its inside
// end, so neighbours sharing an edge get bit-identical new vertices.
int clip_triangle(const float* const v[3], int stride, std::uint32_t planes,
                  const GuardBand& gb, float* out);

// Clips segment (a, b) against the planes named in `planes`: writes the
// remaining segment's two vertices into out (2 * stride floats) and returns
// true, or false when nothing is left. Each new end is cut along a -> b and
// put exactly on its plane.
bool clip_line(const float* a, const float* b, int stride, std::uint32_t planes, const GuardBand& gb,
               float* out);

} // namespace prast

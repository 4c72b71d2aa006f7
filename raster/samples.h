// Multisampling: the standard sample positions of Direct3D 11 / Vulkan for 1,
// 2, 4 and 8 samples per pixel (docs/conventions.md, "Multisampling and blending"),
// in 1/16 pixel from the pixel centre, y down. With 8 sub-pixel bits a 1/16
// step is 16 fixed-point units, so every sample lies exactly on the snapping
// grid and the edge functions stay exact integers at every sample.
#pragma once

#include <cstdint>

#include "raster/limits.h"

namespace prast {

struct SamplePattern {
    int count = 1;
    std::int8_t x[kMaxSamples] = {}, y[kMaxSamples] = {};  // 1/16 pixel from the centre

    // Offsets in fixed point (1/256 pixel) and in pixels.
    std::int64_t fixed_x(int s) const { return std::int64_t(x[s]) * (kSubPixelScale / 16); }
    std::int64_t fixed_y(int s) const { return std::int64_t(y[s]) * (kSubPixelScale / 16); }
    float pixel_x(int s) const { return float(x[s]) * (1.0f / 16.0f); }
    float pixel_y(int s) const { return float(y[s]) * (1.0f / 16.0f); }
};

constexpr bool valid_sample_count(int n) { return n == 1 || n == 2 || n == 4 || n == 8; }

// The pattern for 1, 2, 4 or 8 samples (anything else: the 1-sample pattern).
inline const SamplePattern& sample_pattern(int count) {
    static const SamplePattern kOne{1, {0}, {0}};
    static const SamplePattern kTwo{2, {4, -4}, {4, -4}};
    static const SamplePattern kFour{4, {-2, 6, -6, 2}, {-6, -2, 2, 6}};
    static const SamplePattern kEight{8, {1, -1, 5, -3, -5, -7, 3, 7}, {-3, 3, 1, -5, 5, -1, 7, -7}};
    switch (count) {
    case 2: return kTwo;
    case 4: return kFour;
    case 8: return kEight;
    default: return kOne;
    }
}

// The box the samples of a pixel span, in fixed point from the pixel centre:
// setup and binning use it so that a triangle reaching only some samples of a
// pixel still gets that pixel. All zero for one sample.
struct SampleExtent {
    std::int64_t lo_x = 0, hi_x = 0, lo_y = 0, hi_y = 0;
};

inline SampleExtent sample_extent(const SamplePattern& p) {
    SampleExtent e;
    e.lo_x = e.hi_x = p.fixed_x(0);
    e.lo_y = e.hi_y = p.fixed_y(0);
    for (int s = 1; s < p.count; ++s) {
        e.lo_x = p.fixed_x(s) < e.lo_x ? p.fixed_x(s) : e.lo_x;
        e.hi_x = p.fixed_x(s) > e.hi_x ? p.fixed_x(s) : e.hi_x;
        e.lo_y = p.fixed_y(s) < e.lo_y ? p.fixed_y(s) : e.lo_y;
        e.hi_y = p.fixed_y(s) > e.hi_y ? p.fixed_y(s) : e.hi_y;
    }
    return e;
}

} // namespace prast

// Stage observers: the stepper and tests attach one to watch each stage. The
// pipeline calls them under `if constexpr (Observer::enabled)`, so the default
// NullObserver costs nothing. Calls come from worker threads concurrently
// (render with one thread for an ordered trace).
#pragma once

#include <cstdint>

#include "raster/fragment.h"

namespace prast {

struct TriangleSetup;

enum class TriangleFate : std::uint8_t {
    Invalid,        // non-finite position
    CulledFrustum,  // entirely outside a frustum plane
    CulledBack,     // back face of a single-sided draw
    Degenerate,     // zero area, or covers no pixel centre
    SetUp,          // reached the bins (one call per post-clip piece)
};

struct NullObserver {
    static constexpr bool enabled = false;
    void vertex(std::uint32_t, const float*, const float*, int) {}
    void triangle(std::uint32_t, TriangleFate, bool /*clipped*/, const TriangleSetup*) {}
    void binned(std::uint32_t, int /*tile*/) {}
    // A 4x4 block of a triangle: coverage mask, depth-pass mask, window depth.
    void fragments(std::uint32_t, int, int, std::uint32_t, std::uint32_t, const float*) {}
    // After the shader: which lanes were written, with what input and output.
    template <int NV>
    void shaded(const FragmentBlock<NV>&, const FragmentOut&, std::uint32_t) {}
};

} // namespace prast

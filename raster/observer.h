// Stage observers: the stepper and tests attach one to a draw to watch each
// stage. The pipeline calls them under `if constexpr (Observer::enabled)`, so
// the default NullObserver costs nothing. Calls come from worker threads
// concurrently (render with one thread for an ordered trace); within a tile
// they come in submission order.
//
// Fragments. fragments() reports every 4x4 block a triangle covers, in
// submission order per tile, with the depth test's result at that point of
// the sequence: the result drawing one draw at a time would give, whether the draw is
// shaded in order or through the visibility pass. shaded() reports what the
// fragment program was run for and wrote:
//  - draws shaded in order (blending, alpha MASK, depth test or write off):
//    right after the block's fragments() call, `live` = lanes written;
//  - every other draw goes through the visibility pass: only the winners are
//    shaded, later, when the tile (or a blending draw) needs their colour;
//    then shaded() comes once per (winning triangle, block), in.mask = the
//    lanes where the triangle won at least one sample, `live` = lanes written.
//    The winner of a sample is the last fragment whose depth test passed
//    there, which fragments()/samples() tell in order.
// Draws without a fragment program (depth only) report fragments() only.
//
// Samples (multisampling, FrameOptions::samples > 1). In fragments() a lane
// counts as covered when any of its samples is, and as passed when any
// passed. An observer that also defines
//   void samples(std::uint32_t prim, int bx, int by, const SampleCoverage&)
// gets each block's per-sample coverage, depth results and depths right after
// fragments(); with one sample the single sample is the pixel centre. (The
// method is optional: observers without it compile as before.)
#pragma once

#include <cstdint>
#include <type_traits>
#include <utility>

#include "raster/fragment.h"
#include "raster/limits.h"

namespace prast {

struct TriangleSetup;

enum class TriangleFate : std::uint8_t {
    Invalid,        // non-finite position
    CulledFrustum,  // entirely outside a frustum plane
    CulledBack,     // back face of a single-sided draw
    Degenerate,     // zero area, or covers no sample
    SetUp,          // reached the bins (one call per post-clip piece)
};

// One block of one triangle, sample by sample (bit l of a mask: lane l).
struct SampleCoverage {
    int count = 1;                       // samples per pixel
    std::uint32_t cover[kMaxSamples];    // sample s of lane l inside the triangle
    std::uint32_t pass[kMaxSamples];     // ... and passed the depth test (then written)
    const float* z[kMaxSamples];         // window depth of sample s, 16 lanes
};

struct NullObserver {
    static constexpr bool enabled = false;
    void vertex(std::uint32_t, const float*, const float*, int) {}
    void triangle(std::uint32_t, TriangleFate, bool /*clipped*/, const TriangleSetup*) {}
    void binned(std::uint32_t, int /*tile*/) {}
    // A 4x4 block of a triangle: coverage mask, depth-pass mask, window depth
    // of sample 0 per lane (the pixel centre with one sample).
    void fragments(std::uint32_t, int, int, std::uint32_t, std::uint32_t, const float*) {}
    // After the shader: which lanes were written, with what input and output.
    template <int NV>
    void shaded(const FragmentBlock<NV>&, const FragmentOut&, std::uint32_t) {}
    void samples(std::uint32_t, int, int, const SampleCoverage&) {}
};

namespace raster_detail {
template <class O, class = void>
struct has_samples_event : std::false_type {};
template <class O>
struct has_samples_event<O, std::void_t<decltype(std::declval<O&>().samples(
                                std::uint32_t(), 0, 0, std::declval<const SampleCoverage&>()))>>
    : std::true_type {};
} // namespace raster_detail

template <class Observer>
constexpr bool observes_samples = Observer::enabled && raster_detail::has_samples_event<Observer>::value;

} // namespace prast

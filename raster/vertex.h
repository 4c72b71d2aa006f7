// The vertex stage: a draw's program turns each vertex into a clip-space
// position and its varyings. Run in chunks of vertices on the pool, so each
// vertex is shaded once however many triangles share it; the output array
// (`4 + kVaryings` floats per vertex) lives until the frame's tile pass.
#pragma once

#include <cstdint>

#include "raster/clip.h"
#include "raster/observer.h"
#include "raster/setup.h"

namespace prast {

// Vertices per task of the vertex pass.
constexpr std::uint32_t kVertexChunk = 4096;

template <class Program, class Observer>
void shade_vertices(const Program& program, std::uint32_t begin, std::uint32_t end, float* out, Observer& obs) {
    constexpr int stride = 4 + Program::kVaryings;
    for (std::uint32_t v = begin; v < end; ++v) {
        float* o = out + std::size_t(v) * stride;
        program.vertex(v, o, o + 4);
        if constexpr (Observer::enabled) obs.vertex(v, o, o + 4, Program::kVaryings);
    }
}

// A vertex with a non-finite coordinate: its triangles are dropped (invalid).
constexpr std::uint32_t kVertexNotFinite = 1u << 15;

// What binning and setup need of each shaded vertex, once per vertex rather
// than once per triangle corner: for vertices [begin, end) (`stride` floats
// each, clip xyzw first), codes[v] = outcode() or kVertexNotFinite, and
// window[v] = window_vertex() (used by triangles that need no clipping).
void project_vertices(const float* vertices, int stride, std::uint32_t begin, std::uint32_t end,
                      const GuardBand& gb, int width, int height, std::uint16_t* codes, WindowVertex* window);

} // namespace prast

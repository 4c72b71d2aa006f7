// The vertex stage: a draw's program turns each vertex into a clip-space
// position and its varyings. Run in chunks of vertices on the pool, so each
// vertex is shaded once however many triangles share it; the output array
// (`4 + kVaryings` floats per vertex) lives until the frame's tile pass.
#pragma once

#include <cstdint>

#include "raster/observer.h"

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

} // namespace prast

// Small programs and helpers shared by the raster tests: vertex shaders that
// take window or clip coordinates directly, counting and varying-echo shaders.
#pragma once

#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "raster/pipeline.h"

namespace prast::test {

// Positions given in clip space, NV varyings per vertex copied through.
template <int NV>
struct ClipProgram {
    static constexpr int kVaryings = NV;
    const glm::vec4* clip = nullptr;
    const float* varyings = nullptr;  // NV per vertex
    void vertex(std::uint32_t i, float out[4], float* var) const {
        out[0] = clip[i].x; out[1] = clip[i].y; out[2] = clip[i].z; out[3] = clip[i].w;
        for (int k = 0; k < NV; ++k) var[k] = varyings[i * NV + k];
    }
    // Writes varyings 0..2 as colour (alpha 1); with NV == 0 writes 1.
    void fragment(const FragmentBlock<NV>& in, FragmentOut& out) const {
        for (int l = 0; l < kBlockLanes; ++l) {
            out.r[l] = NV > 0 ? in.var[0][l] : 1.0f;
            out.g[l] = NV > 1 ? in.var[NV > 1 ? 1 : 0][l] : 1.0f;
            out.b[l] = NV > 2 ? in.var[NV > 2 ? 2 : 0][l] : 1.0f;
            out.a[l] = 1.0f;
        }
    }
};

// Window coordinates (pixels, y down) to clip space with w = 1.
inline glm::vec4 window_to_clip(float x, float y, float z_ndc, int w, int h) {
    return {x / float(w) * 2.0f - 1.0f, 1.0f - y / float(h) * 2.0f, z_ndc, 1.0f};
}

// Additive counter: each written fragment adds 1 to red.
struct CountProgram {
    static constexpr int kVaryings = 0;
    const glm::vec4* clip = nullptr;
    void vertex(std::uint32_t i, float out[4], float*) const {
        out[0] = clip[i].x; out[1] = clip[i].y; out[2] = clip[i].z; out[3] = clip[i].w;
    }
    void fragment(const FragmentBlock<0>&, FragmentOut& out) const {
        for (int l = 0; l < kBlockLanes; ++l) { out.r[l] = 1; out.g[l] = 0; out.b[l] = 0; out.a[l] = 0; }
    }
};

inline std::uint64_t fnv1a(const void* data, std::size_t n, std::uint64_t h = 1469598103934665603ull) {
    const unsigned char* p = static_cast<const unsigned char*>(data);
    for (std::size_t i = 0; i < n; ++i) { h ^= p[i]; h *= 1099511628211ull; }
    return h;
}

inline std::uint64_t hash_framebuffer(const Framebuffer& fb) {
    std::uint64_t h = fnv1a(fb.color.data(), fb.color.size() * sizeof(float));
    return fnv1a(fb.depth.data(), fb.depth.size() * sizeof(float), h);
}

} // namespace prast::test

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

// splitmix64: the same numbers on every platform.
struct Random {
    std::uint64_t s;
    explicit Random(std::uint64_t seed) : s(seed) {}
    std::uint64_t next() {
        std::uint64_t z = (s += 0x9E3779B97F4A7C15ull);
        z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
        z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
        return z ^ (z >> 31);
    }
    double uniform() { return double(next() >> 11) * (1.0 / 9007199254740992.0); }
    double range(double a, double b) { return a + (b - a) * uniform(); }
    int below(int n) { return int(next() % std::uint64_t(n)); }
};

// Clip-space position of window point (x, y) of a W x H target (y down), at
// NDC depth z_ndc, scaled by w.
inline glm::vec4 at(double x, double y, int W, int H, double z_ndc = 0.0, double w = 1.0) {
    return {float((x / W * 2.0 - 1.0) * w), float((1.0 - y / H * 2.0) * w), float(z_ndc * w), float(w)};
}

} // namespace prast::test

// Tile storage at the start and the end of a tile pass; see resolve.h.
#include "raster/tile_storage.h"

#include <algorithm>
#include <cstring>

#include "raster/stream_fill.h"

namespace prast {

void clear_tile(Framebuffer& fb, const TileRect& r, const float rgba[4], float depth) {
    const std::size_t w = std::size_t(r.width());
    for (int y = r.y0; y <= r.y1; ++y) {
        const std::size_t row = std::size_t(y) * std::size_t(fb.width) + std::size_t(r.x0);
        std::fill(fb.depth.begin() + std::ptrdiff_t(row), fb.depth.begin() + std::ptrdiff_t(row + w), depth);
        if (!fb.has_color()) continue;
        float* c = &fb.color[row * 4];
        for (std::size_t i = 0; i < w; ++i, c += 4) std::memcpy(c, rgba, 4 * sizeof(float));
    }
}

void clear_tile_streaming(Framebuffer& fb, const TileRect& r, const float rgba[4], float depth) {
    const std::size_t w = std::size_t(r.width());
    const StreamPattern z(&depth, sizeof(float)), c(rgba, 4 * sizeof(float));
    for (int y = r.y0; y <= r.y1; ++y) {
        const std::size_t row = std::size_t(y) * std::size_t(fb.width) + std::size_t(r.x0);
        stream_fill(&fb.depth[row], w * sizeof(float), z);
        if (fb.has_color()) stream_fill(&fb.color[row * 4], w * 4 * sizeof(float), c);
    }
    stream_fence();
}

void clear_samples(float* color, float* depth, int size, int samples, const float rgba[4], float z) {
    const std::size_t n = std::size_t(size) * std::size_t(size) * std::size_t(samples);
    std::fill(depth, depth + n, z);
    if (!color) return;
    // Eight floats (two pixels) at a time, held in one register; n is even
    // (size is a multiple of 4).
    typedef float Pair __attribute__((vector_size(32)));
    const Pair pair = {rgba[0], rgba[1], rgba[2], rgba[3], rgba[0], rgba[1], rgba[2], rgba[3]};
    for (std::size_t i = 0; i < n * 4; i += 8) std::memcpy(color + i, &pair, sizeof pair);
}

void load_samples(const Framebuffer& fb, const TileRect& r, float* color, float* depth, int size, int samples) {
    const std::size_t plane = std::size_t(size) * std::size_t(size);
    for (int y = r.y0; y <= r.y1; ++y)
        for (int x = r.x0; x <= r.x1; ++x) {
            const std::size_t src = std::size_t(y) * std::size_t(fb.width) + std::size_t(x);
            const std::size_t dst = std::size_t(y - r.y0) * std::size_t(size) + std::size_t(x - r.x0);
            for (int s = 0; s < samples; ++s) {
                depth[dst + s * plane] = fb.depth[src];
                if (color) std::memcpy(color + (dst + s * plane) * 4, &fb.color[src * 4], 4 * sizeof(float));
            }
        }
}

namespace {

// Pairwise sums: ((s0 + s1) + (s2 + s3)) + ... so that n equal values sum to
// exactly n times the value (n a power of two), and their mean is the value.
// Eight floats (two pixels' RGBA, or eight depths) at a time.
typedef float Floats8 __attribute__((vector_size(32)));

// One unaligned 32-byte load. Copying into an element of an array of
// Floats8 inside a loop compiled to two 16-byte stores read back as one
// 32-byte load, which stalls on store forwarding.
inline Floats8 load8(const float* p) {
    Floats8 v;
    std::memcpy(&v, p, sizeof v);
    return v;
}

template <int S>
inline void resolve_row(const float* color, const float* depth, std::size_t plane, int width, float* out_color,
                        float* out_depth) {
    constexpr float kInv = 1.0f / float(S);
    int x = 0;
    if (!out_depth) x = width;  // colour only
    for (; x + 8 <= width; x += 8) {
        Floats8 z = load8(depth + x);
#pragma GCC unroll 8
        for (int s = 1; s < S; ++s) {
            const Floats8 v = load8(depth + x + s * plane);
            z = v < z ? v : z;  // std::min(z, v)
        }
        std::memcpy(out_depth + x, &z, sizeof z);
    }
    for (; x < width; ++x) {
        float z = depth[x];
        for (int s = 1; s < S; ++s) z = std::min(z, depth[x + s * plane]);
        out_depth[x] = z;
    }
    if (!color) return;
    const std::size_t n = std::size_t(width) * 4, cplane = plane * 4;
    std::size_t i = 0;
    for (; i + 8 <= n; i += 8) {
        Floats8 v[S];
#pragma GCC unroll 8
        for (int s = 0; s < S; ++s) v[s] = load8(color + i + s * cplane);
        for (int k = S; k > 1; k /= 2)
            for (int j = 0; j < k / 2; ++j) v[j] = v[2 * j] + v[2 * j + 1];
        v[0] = v[0] * kInv;
        std::memcpy(out_color + i, &v[0], sizeof v[0]);
    }
    for (; i < n; ++i) {
        float v[S];
        for (int s = 0; s < S; ++s) v[s] = color[i + s * cplane];
        for (int k = S; k > 1; k /= 2)
            for (int j = 0; j < k / 2; ++j) v[j] = v[2 * j] + v[2 * j + 1];
        out_color[i] = v[0] * kInv;
    }
}

// resolve_row for the frame's sample count.
inline void resolve_row_of(int samples, const float* color, const float* depth, std::size_t plane, int width,
                           float* out_color, float* out_depth) {
    switch (samples) {
    case 2: resolve_row<2>(color, depth, plane, width, out_color, out_depth); break;
    case 4: resolve_row<4>(color, depth, plane, width, out_color, out_depth); break;
    case 8: resolve_row<8>(color, depth, plane, width, out_color, out_depth); break;
    default: resolve_row<1>(color, depth, plane, width, out_color, out_depth); break;
    }
}

} // namespace

void resolve_samples(const float* color, const float* depth, int size, int samples, const TileRect& r,
                     Framebuffer& fb) {
    const std::size_t plane = std::size_t(size) * std::size_t(size);
    for (int y = r.y0; y <= r.y1; ++y) {
        const std::size_t src = std::size_t(y - r.y0) * std::size_t(size);
        const std::size_t dst = std::size_t(y) * std::size_t(fb.width) + std::size_t(r.x0);
        const float* c = color ? color + src * 4 : nullptr;
        float* oc = fb.has_color() ? &fb.color[dst * 4] : nullptr;
        if (!oc) c = nullptr;
        resolve_row_of(samples, c, depth + src, plane, r.width(), oc, &fb.depth[dst]);
    }
}

void resolve_samples_local(const float* color, int size, int samples, int width, int height, float* out) {
    const std::size_t plane = std::size_t(size) * std::size_t(size);
    for (int y = 0; y < height; ++y) {
        const std::size_t at = std::size_t(y) * std::size_t(size) * 4;
        resolve_row_of(samples, color + at, nullptr, plane, width, out + at, nullptr);
    }
}

} // namespace prast

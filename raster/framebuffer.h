// The render target: linear float RGBA colour and float depth, row-major, row 0
// at the top. Depth is 32-bit float window z in [0, 1], cleared to 1, test LESS.
// A depth target (shadow maps) has no colour: depth_only(w, h), color empty.
// A deferred target (deferred(w, h)) has a size and no storage until a frame
// keeps its pixels.
// A multisampled frame keeps its samples in tile-local buffers and leaves here
// the resolved colour and each pixel's nearest sample depth (docs/pipeline.md "Anti-aliasing").
#pragma once

#include <algorithm>
#include <cstddef>
#include <vector>

namespace prast {

struct Framebuffer {
    int width = 0, height = 0;
    std::vector<float> color;  // 4 floats per pixel; empty for a depth target
    std::vector<float> depth;  // 1 float per pixel

    Framebuffer() = default;
    Framebuffer(int w, int h) { resize(w, h); }

    static Framebuffer depth_only(int w, int h) {
        Framebuffer fb;
        fb.width = w;
        fb.height = h;
        fb.depth.assign(std::size_t(w) * h, 1.0f);
        return fb;
    }

    // A colour target of w x h pixels that holds no storage yet: the first
    // frame that keeps its pixels (Renderer::begin of a frame that is not
    // transient, or Renderer::clear) allocates it as resize() does. A
    // transient frame never reads or writes the framebuffer, so a caller that
    // only wants the 8-bit image skips 20 bytes a pixel of allocation and
    // fill (41 MB at 1920x1080). Until then color and depth are empty: a
    // size without depth storage is what marks it.
    static Framebuffer deferred(int w, int h) {
        Framebuffer fb;
        fb.width = w;
        fb.height = h;
        return fb;
    }
    bool is_deferred() const { return width > 0 && height > 0 && depth.empty(); }
    // Allocates a deferred framebuffer's storage; nothing otherwise.
    void allocate() {
        if (is_deferred()) resize(width, height);
    }

    bool has_color() const { return !color.empty() || is_deferred(); }

    void resize(int w, int h) {
        width = w;
        height = h;
        color.assign(std::size_t(w) * h * 4, 0.0f);
        depth.assign(std::size_t(w) * h, 1.0f);
    }
    void clear(float r, float g, float b, float a, float z = 1.0f) {
        for (std::size_t i = 0; i < color.size(); i += 4) {
            color[i] = r; color[i + 1] = g; color[i + 2] = b; color[i + 3] = a;
        }
        std::fill(depth.begin(), depth.end(), z);
    }
    float* pixel(int x, int y) { return &color[(std::size_t(y) * width + x) * 4]; }
    const float* pixel(int x, int y) const { return &color[(std::size_t(y) * width + x) * 4]; }
};

} // namespace prast

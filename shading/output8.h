// The resolve stage: linear HDR radiance to the 8-bit output image, the last
// step of docs/conventions.md's "Output" (exposure, tone map, sRGB, rounding). It
// runs vectorised (eight pixels at a time with AVX2) and, as a frame's tile
// hook (TileResolve), on every thread inside the tile pass. Byte-identical to
// the per-pixel reference (tonemap() then linear_to_srgb8()); tested.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <memory>
#include <vector>

#include "raster/frame.h"
#include "raster/stream_fill.h"
#include "shading/tonemap.h"

namespace prast {

// `count` RGBA pixels: rgb * exposure, tone map, sRGB encode, round to 8
// bits; alpha floor(clamp(a, 0, 1) * 255 + 0.5), neither exposed nor encoded.
void resolve_pixels_srgb8(const float* rgba, std::size_t count, float exposure, ToneMap tm, std::uint8_t* out);

// Data (debug views) as is: clamp to [0, 1], * 255, round; alpha 255.
void resolve_pixels_raw8(const float* rgba, std::size_t count, std::uint8_t* out);

// Memory for an 8-bit RGBA image of `pixels` pixels whose first byte starts a
// cache line: then, when the width is a multiple of 16 pixels, TileResolve
// streams whole lines (a partly streamed line is flushed in pieces).
class Rgba8Buffer {
public:
    // Zeroed; on huge pages where large (scene/huge_pages.h): an image of
    // 1920x1080 is otherwise some 2,000 page faults before the first pixel.
    explicit Rgba8Buffer(std::size_t pixels);
    Rgba8Buffer(Rgba8Buffer&& o) noexcept : store_(std::move(o.store_)), data_(o.data_) { o.data_ = nullptr; }
    Rgba8Buffer& operator=(Rgba8Buffer&& o) noexcept {
        store_ = std::move(o.store_);
        data_ = o.data_;
        o.data_ = nullptr;
        return *this;
    }

    std::uint8_t* data() { return data_; }  // null for 0 pixels
    const std::uint8_t* data() const { return data_; }

private:
    struct Free {
        void operator()(std::uint8_t* p) const noexcept;
    };
    std::unique_ptr<std::uint8_t[], Free> store_;
    std::uint8_t* data_ = nullptr;
};

// A frame's tile hook writing the 8-bit image (rows of `width` pixels) from
// each finished tile.
struct TileResolve {
    std::uint8_t* rgba8 = nullptr;
    int width = 0;
    float exposure = 1.0f;
    ToneMap tonemap = ToneMap::Aces;
    bool raw = false;  // data views: resolve_pixels_raw8

    void operator()(const TileView& v) const {
        if (v.uniform) {  // one pixel converted, copied to the whole tile
            std::uint8_t px[4];
            if (raw) resolve_pixels_raw8(v.rgba, 1, px);
            else resolve_pixels_srgb8(v.rgba, 1, exposure, tonemap, px);
            const StreamPattern pattern(px, 4);
            for (int y = 0; y < v.height; ++y)  // not read again this frame: streamed
                stream_fill(rgba8 + (std::size_t(v.y0 + y) * std::size_t(width) + std::size_t(v.x0)) * 4,
                            std::size_t(v.width) * 4, pattern);
            stream_fence();
            return;
        }
        for (int y = 0; y < v.height; ++y) {
            const float* in = v.rgba + std::size_t(y) * v.row;
            std::uint8_t* out = rgba8 + (std::size_t(v.y0 + y) * std::size_t(width) + std::size_t(v.x0)) * 4;
            if (raw) resolve_pixels_raw8(in, std::size_t(v.width), out);
            else resolve_pixels_srgb8(in, std::size_t(v.width), exposure, tonemap, out);
        }
    }
};

} // namespace prast

// The end of a tile's life in a frame: its samples resolved into the
// framebuffer (colour: the average of the samples' linear radiance, summed
// pairwise so that equal samples give back their value exactly; depth: the
// nearest sample), and, at its start, its storage cleared or loaded.
#pragma once

#include <cstddef>

#include "raster/framebuffer.h"

namespace prast {

// The tile's pixels [x0, x1] x [y0, y1] (inclusive).
struct TileRect {
    int x0 = 0, y0 = 0, x1 = 0, y1 = 0;
    int width() const { return x1 - x0 + 1; }
    int height() const { return y1 - y0 + 1; }
};

// One sample: fill the framebuffer's pixels of the tile.
void clear_tile(Framebuffer& fb, const TileRect& r, const float rgba[4], float depth);
// The same bytes with non-temporal stores (stream_fill.h), for a tile no draw
// reaches: nothing reads its pixels again in the frame.
void clear_tile_streaming(Framebuffer& fb, const TileRect& r, const float rgba[4], float depth);

// Several samples in tile-local planes (`size` x `size` pixels each, colour
// RGBA; color may be null for a depth target): fill every plane, or load
// every sample from the framebuffer's pixel.
void clear_samples(float* color, float* depth, int size, int samples, const float rgba[4], float z);
void load_samples(const Framebuffer& fb, const TileRect& r, float* color, float* depth, int size, int samples);

// Averages the samples into the framebuffer's colour and writes each pixel's
// nearest sample depth.
void resolve_samples(const float* color, const float* depth, int size, int samples, const TileRect& r,
                     Framebuffer& fb);
// The same averages of the colour samples into tile-local storage (`size`
// pixels a row, the first width x height pixels), for a transient frame
// (FrameOptions::transient); no depth.
void resolve_samples_local(const float* color, int size, int samples, int width, int height, float* out);

} // namespace prast

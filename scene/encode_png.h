// PNG encoding with zlib (linked statically): 8-bit grey, grey+alpha, RGB or
// RGBA. Every row is filtered with the PNG "Paeth" predictor, or "Sub" for the
// first row (Paeth needs the row above), and the filtered rows are deflated at
// a low level in horizontal bands, each band its own run of the compressor
// ended at a byte boundary (a full flush), so that bands compress in parallel
// and still join into one valid zlib stream (the Adler-32 sums are combined).
// The output is a standard PNG (IHDR, one IDAT per band, IEND) that any
// decoder reads; the bytes do not depend on the thread count.
#pragma once

#include <cstdint>
#include <functional>
#include <vector>

namespace prast {

struct PngOptions {
    int zlib_level = 1;          // 1 (fastest) .. 9 (smallest): 1 already beats stb_image_write's size
    int band_rows = 64;          // rows per independently deflated band
    // Runs fn(band) for band in [0, count), possibly in parallel; null: in order.
    std::function<void(int count, const std::function<void(int)>& fn)> parallel_for;
};

// Options whose parallel_for runs the bands on `threads` std::threads (the
// caller among them); 0 = the hardware's thread count, at most 8.
PngOptions png_options_threads(int threads = 0);

// `pixels` holds height rows of width * channels bytes (channels 1 to 4).
// Throws std::invalid_argument for a bad size or channel count, and
// std::runtime_error if zlib fails.
std::vector<std::uint8_t> encode_png_pixels(const std::uint8_t* pixels, int width, int height, int channels,
                                            const PngOptions& options = {});

} // namespace prast

// Comparing two 8-bit images the way a pixel test needs it, in the style of
// Filament's renderdiff: a per-channel tolerance T (in 8-bit units) that may
// be exceeded on at most a fraction F of the pixels, the numbers that say how
// far apart the images are (PSNR, the largest difference and where, how many
// pixels differ and their bounding box) and a heat map of where they differ.
// `prast-diff` is a thin front end; the tests and examples call it directly.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace prast {

// 8 bits per channel, 4 bytes per pixel (RGBA), row 0 on top. Images without
// alpha carry 255 there and have has_alpha false: alpha is compared only when
// one of the two images has it.
struct Image8 {
    int width = 0, height = 0;
    bool has_alpha = false;
    std::vector<std::uint8_t> rgba;

    static Image8 from_rgb(int width, int height, const std::uint8_t* rgb);
    static Image8 from_rgba(int width, int height, const std::uint8_t* rgba, bool has_alpha);
    const std::uint8_t* at(int x, int y) const { return &rgba[(std::size_t(y) * std::size_t(width) + x) * 4]; }
};

// Reads a PNG (or any 8- or 16-bit format stb_image reads: JPEG, BMP, TGA,
// ...; 16-bit channels keep their high byte). Throws LoadError "PATH: reason"
// for a missing, empty, unreadable, corrupt or oversized file and for Radiance
// HDR (float data has no 8-bit difference to measure).
Image8 read_image8(const std::string& path);

struct DiffTolerance {
    int channel = 0;        // T: a channel differing by at most T counts as equal
    double fraction = 0.0;  // F: at most floor(F * pixels) pixels may exceed T
};

struct DiffResult {
    int width = 0, height = 0;
    int channels = 3;               // 3 (RGB) or 4 (RGBA, when either image has alpha)
    double mse = 0.0;               // mean of squared differences over every compared channel
    double psnr_db = 0.0;           // 10 log10(255^2 / mse); +infinity when mse == 0
    int max_diff = 0;               // largest channel difference, 0..255
    int max_x = -1, max_y = -1;     // first pixel (row-major) where it occurs; -1 when equal
    std::int64_t differing = 0;     // pixels with some channel difference > T
    double differing_fraction = 0;  // differing / pixels
    std::int64_t allowed = 0;       // floor(F * pixels)
    int box_x0 = -1, box_y0 = -1;   // inclusive bounding box of the differing
    int box_x1 = -1, box_y1 = -1;   // pixels; all -1 when there are none
    bool match = true;              // differing <= allowed
};

// The two images must be the same size (std::invalid_argument otherwise).
DiffResult diff_images(const Image8& a, const Image8& b, const DiffTolerance& tol);

// A heat map of the same size, RGBA8 (alpha 255). With d the pixel's largest
// channel difference:
//   d == 0       grey (r + g + b) / 12 of image a: the picture, dimmed to <= 63
//   0 < d <= T   (0, d, 255): blue, within tolerance
//   d > T        (255, d, 0): red, turning yellow as d grows
// so the green channel of every differing pixel is its difference.
std::vector<std::uint8_t> diff_heatmap(const Image8& a, const Image8& b, const DiffTolerance& tol);

// The report prast-diff prints, one "name: value" per line:
//   size: 64x48, RGB
//   psnr: 43.32 dB                      ("inf dB" when equal)
//   max difference: 10 at 2,2           ("0" when equal)
//   differing pixels: 2 of 12 (fraction 0.166667) above tolerance 0
//   bounding box: 1,0 to 2,2 (2x3)      ("none")
//   result: differ (at most 0 pixels may exceed tolerance 0)   or "result: match (...)"
std::string format_diff(const DiffResult& r, const DiffTolerance& tol);

} // namespace prast

// Writing images atomically: encode in memory, write a temporary file next to
// the target, then rename it over the target, so a failed or killed render
// never leaves a truncated file behind.
#pragma once

#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

namespace prast {

struct WriteError : std::runtime_error {
    using std::runtime_error::runtime_error;
};

// 8-bit RGBA (alpha dropped: the output is RGB).
void write_png_atomic(const std::string& path, int width, int height, const std::uint8_t* rgba8);
// Linear float RGBA as Radiance .hdr (RGB).
void write_hdr_atomic(const std::string& path, int width, int height, const float* rgba);

// The bytes of the PNG that write_png_atomic would write (for hashing in tests).
std::vector<std::uint8_t> encode_png(int width, int height, const std::uint8_t* rgba8);

} // namespace prast

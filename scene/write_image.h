// Writing images atomically: encode in memory, write a temporary file next to
// the target, then rename it over the target, so a failed or killed render
// never leaves a truncated file behind. The temporary name is short (".NAME.PID.tmp"
// with NAME cut to 64 bytes), so any output name the file system takes works.
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

// Removes the temporary file being written right now, if any. Only
// async-signal-safe calls: for a SIGINT/SIGTERM handler (render's), so that a
// killed render leaves nothing behind. One write at a time per process.
void remove_temporary_output() noexcept;

// The bytes of the PNG that write_png_atomic would write (for hashing in tests).
std::vector<std::uint8_t> encode_png(int width, int height, const std::uint8_t* rgba8);

} // namespace prast

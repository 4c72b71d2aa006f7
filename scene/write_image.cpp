// Atomic PNG/HDR output; see image_write.h.
#include "scene/write_image.h"

#include <cerrno>
#include <cstdio>
#include <cstring>

#include <unistd.h>

#include <stb_image_write.h>

#include "scene/encode_png.h"

namespace prast {

namespace {

void append_bytes(void* ctx, void* data, int size) {
    auto* out = static_cast<std::vector<std::uint8_t>*>(ctx);
    const auto* p = static_cast<const std::uint8_t*>(data);
    out->insert(out->end(), p, p + size);
}

void write_file_atomic(const std::string& path, const std::vector<std::uint8_t>& bytes) {
    std::string tmp = path + ".tmp" + std::to_string(long(getpid()));
    std::FILE* f = std::fopen(tmp.c_str(), "wb");
    if (!f) throw WriteError(path + ": cannot write (" + std::strerror(errno) + ")");
    bool ok = std::fwrite(bytes.data(), 1, bytes.size(), f) == bytes.size();
    ok &= std::fflush(f) == 0;
    ok &= fsync(fileno(f)) == 0;
    int err = errno;
    ok &= std::fclose(f) == 0;
    if (!ok) {
        std::remove(tmp.c_str());
        throw WriteError(path + ": write failed (" + std::strerror(err) + ")");
    }
    if (std::rename(tmp.c_str(), path.c_str()) != 0) {
        err = errno;
        std::remove(tmp.c_str());
        throw WriteError(path + ": cannot replace (" + std::strerror(err) + ")");
    }
}

} // namespace

std::vector<std::uint8_t> encode_png(int width, int height, const std::uint8_t* rgba8) {
    std::vector<std::uint8_t> rgb(std::size_t(width) * height * 3);
    for (std::size_t i = 0, n = std::size_t(width) * height; i < n; ++i) {
        rgb[i * 3] = rgba8[i * 4];
        rgb[i * 3 + 1] = rgba8[i * 4 + 1];
        rgb[i * 3 + 2] = rgba8[i * 4 + 2];
    }
    try {
        return encode_png_pixels(rgb.data(), width, height, 3, png_options_threads());
    } catch (const std::exception& e) {
        throw WriteError(std::string("PNG encoding failed: ") + e.what());
    }
}

void write_png_atomic(const std::string& path, int width, int height, const std::uint8_t* rgba8) {
    write_file_atomic(path, encode_png(width, height, rgba8));
}

void write_hdr_atomic(const std::string& path, int width, int height, const float* rgba) {
    std::vector<float> rgb(std::size_t(width) * height * 3);
    for (std::size_t i = 0, n = std::size_t(width) * height; i < n; ++i)
        for (int c = 0; c < 3; ++c) rgb[i * 3 + c] = rgba[i * 4 + c];
    std::vector<std::uint8_t> bytes;
    if (!stbi_write_hdr_to_func(append_bytes, &bytes, width, height, 3, rgb.data()))
        throw WriteError(path + ": HDR encoding failed");
    write_file_atomic(path, bytes);
}

} // namespace prast

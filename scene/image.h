// Decoded images, in their own format: 8-bit texels with the file's channel
// count (grey, grey+alpha, RGB, RGBA), colour channels still sRGB-encoded when
// the image is a colour map (base colour, emissive; docs/conventions.md
// "Textures"), or linear float RGBA for HDR files, 16-bit files and the
// procedural images of the built-in scene. Decoding PNG, JPEG and Radiance HDR
// files (or embedded bytes). Row 0 is the top row of the image as shown (a
// BMP's rows come out top first whichever way the file stores them). 8-bit
// values become linear floats only when sampled, through the 256-entry tables
// below, so that a texture costs its file's size in memory.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "scene/scene.h"

namespace prast {

// byte -> linear float: the sRGB decoding of byte / 255 (IEC 61966-2-1, exact
// form, computed once in float), and byte / 255.0f for linear data and alpha.
const float* srgb8_decode_table();
const float* unorm8_decode_table();

struct Image {
    int width = 0, height = 0;
    // Float storage (channels == 0): linear RGBA, 4 floats per texel, row-major.
    std::vector<float> rgba;
    // 8-bit storage (channels 1 to 4): `channels` bytes per texel, row-major:
    // grey, grey+alpha, RGB or RGBA. When `srgb`, the colour channels are
    // sRGB-encoded (alpha never is).
    std::vector<std::uint8_t> pixels;
    int channels = 0;
    bool srgb = false;

    bool empty() const { return width <= 0 || height <= 0; }
    bool is_8bit() const { return channels > 0; }
    std::size_t texel_count() const { return std::size_t(width) * std::size_t(height); }

    // Linear RGBA of one texel, whatever the storage: grey -> (g, g, g, 1),
    // grey+alpha -> (g, g, g, a), RGB -> (r, g, b, 1).
    glm::vec4 at(int x, int y) const {
        const std::size_t i = std::size_t(y) * std::size_t(width) + std::size_t(x);
        if (channels == 0) {
            const float* p = &rgba[i * 4];
            return {p[0], p[1], p[2], p[3]};
        }
        const std::uint8_t* p = &pixels[i * std::size_t(channels)];
        const float* colour = srgb ? srgb8_decode_table() : unorm8_decode_table();
        const float* alpha = unorm8_decode_table();
        switch (channels) {
        case 1: return {colour[p[0]], colour[p[0]], colour[p[0]], 1.0f};
        case 2: return {colour[p[0]], colour[p[0]], colour[p[0]], alpha[p[1]]};
        case 3: return {colour[p[0]], colour[p[1]], colour[p[2]], 1.0f};
        default: return {colour[p[0]], colour[p[1]], colour[p[2]], alpha[p[3]]};
        }
    }
    // Float storage only.
    void set(int x, int y, const glm::vec4& c) {
        float* p = &rgba[(std::size_t(y) * std::size_t(width) + std::size_t(x)) * 4];
        p[0] = c.r; p[1] = c.g; p[2] = c.b; p[3] = c.a;
    }
};

// Images larger than this are refused before anything is allocated: 2^28
// texels is 4 GiB as float RGBA, far beyond any sane texture.
constexpr std::int64_t kMaxImageTexels = std::int64_t(1) << 28;

// The longest side stb_image decodes (STBI_MAX_DIMENSIONS in
// third_party_impl/stb_impl.cpp). PNGs are decoded by libpng, which has no
// such limit: a PNG may have any shape within kMaxImageTexels.
constexpr int kMaxStbImageSide = 1 << 15;

// Decodes src.bytes when not empty, else the file src.path (PNG, JPEG, HDR and
// whatever else stb_image reads). 8-bit files keep their bytes and channel
// count, marked sRGB when `srgb` (Image::at() and the texture sampler decode
// them); 16-bit files become float RGBA, colour channels sRGB-decoded when
// `srgb` (alpha never is), else scaled to [0, 1]; HDR (Radiance) data is
// linear float and kept as is. Throws LoadError "NAME: reason" (NAME =
// src.name, or the path) for a missing, unreadable, empty, corrupt, zero-sized
// or oversized image.
//
// `capacity`, when given, says how many bytes an 8-bit image's pixel buffer
// should have room for (a texture's mip chain after level 0, so that the
// texture grows it in place instead of copying it): JPEG and PNG decodes
// reserve that much before writing the pixels.
using PixelCapacity = std::size_t (*)(int width, int height, int channels);
Image decode_image(const ImageSource& src, bool srgb, PixelCapacity capacity = nullptr);

// The width and height in an image's header, read without decoding (a file
// only as far as its header, through scene/file_access.h), and the bytes a
// decoded texel takes (the channel count for 8-bit files, 16 for float RGBA:
// HDR and 16-bit); false when the header cannot be read or gives a size that
// decode_image() refuses (zero, negative, beyond a side or texel limit), so
// that planning memory before decoding never counts an image that will not
// be decoded.
bool image_dimensions(const ImageSource& src, int& width, int& height, int* bytes_per_texel = nullptr);

} // namespace prast

// Decoded images: linear float RGBA in memory, and decoding PNG, JPEG and
// Radiance HDR files (or embedded bytes) into them with stb_image. Colour
// channels of 8- and 16-bit images are decoded from sRGB when asked (base
// colour and emissive maps, conventions.md "Textures"); alpha never is.
// Row 0 is the top row of the file; nothing is flipped.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "scene/scene.h"

namespace prast {

// Linear float RGBA, 4 floats per texel, row-major, row 0 = top row of the file.
struct Image {
    int width = 0, height = 0;
    std::vector<float> rgba;

    bool empty() const { return width <= 0 || height <= 0; }
    glm::vec4 at(int x, int y) const {
        const float* p = &rgba[(std::size_t(y) * std::size_t(width) + std::size_t(x)) * 4];
        return {p[0], p[1], p[2], p[3]};
    }
    void set(int x, int y, const glm::vec4& c) {
        float* p = &rgba[(std::size_t(y) * std::size_t(width) + std::size_t(x)) * 4];
        p[0] = c.r; p[1] = c.g; p[2] = c.b; p[3] = c.a;
    }
};

// Images larger than this are refused before anything is allocated: 2^28
// texels is 4 GiB as float RGBA, far beyond any sane texture.
constexpr std::int64_t kMaxImageTexels = std::int64_t(1) << 28;

// Decodes src.bytes when not empty, else the file src.path (PNG, JPEG, HDR and
// whatever else stb_image reads). 8-bit and 16-bit colour channels are sRGB-
// decoded when `srgb` (alpha never is), else scaled to [0, 1]; HDR (Radiance)
// data is linear and kept as is. Grey -> (g, g, g, 1), grey+alpha -> (g, g, g, a),
// RGB -> (r, g, b, 1). Throws LoadError "NAME: reason" (NAME = src.name, or the
// path) for a missing, unreadable, empty, corrupt, zero-sized or oversized image.
Image decode_image(const ImageSource& src, bool srgb);

// The width and height in an image's header, read without decoding (a file
// only as far as its header, through scene/file_access.h); false when the
// header cannot be read. For planning memory before decoding.
bool image_dimensions(const ImageSource& src, int& width, int& height);

} // namespace prast

// Image comparison for pixel tests; see image_diff.h.
#include "scene/image_diff.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <stdexcept>


#include "scene/hdr_guard.h"
#include "scene/image.h"
#include "scene/load_scene.h"

namespace prast {

Image8 Image8::from_rgb(int width, int height, const std::uint8_t* rgb) {
    Image8 img;
    img.width = width;
    img.height = height;
    img.rgba.resize(std::size_t(width) * std::size_t(height) * 4);
    for (std::size_t i = 0, n = std::size_t(width) * std::size_t(height); i < n; ++i) {
        img.rgba[i * 4] = rgb[i * 3];
        img.rgba[i * 4 + 1] = rgb[i * 3 + 1];
        img.rgba[i * 4 + 2] = rgb[i * 3 + 2];
        img.rgba[i * 4 + 3] = 255;
    }
    return img;
}

Image8 Image8::from_rgba(int width, int height, const std::uint8_t* rgba, bool has_alpha) {
    Image8 img;
    img.width = width;
    img.height = height;
    img.has_alpha = has_alpha;
    img.rgba.assign(rgba, rgba + std::size_t(width) * std::size_t(height) * 4);
    if (!has_alpha)
        for (std::size_t i = 3; i < img.rgba.size(); i += 4) img.rgba[i] = 255;
    return img;
}

Image8 read_image8(const std::string& path) {
    // Through the renderer's decoder (scene/image.h): the same file checks,
    // header limits and guards in front of stb_image, so an image from a
    // stranger is as safe to compare as to render.
    ImageSource src;
    src.name = path;
    src.bytes = scene_detail::read_file(path);
    if (src.bytes.empty()) throw LoadError(path + ": empty file");
    if (looks_like_hdr(src.bytes.data(), src.bytes.size()))
        throw LoadError(path + ": is a Radiance HDR image; only 8-bit images (PNG, ...) can be compared");
    const Image img = decode_image(src, false);
    const std::size_t n = img.texel_count();
    std::vector<std::uint8_t> rgba(n * 4);
    bool has_alpha = img.channels == 2 || img.channels == 4;
    if (img.is_8bit()) {
        const int c = img.channels;
        for (std::size_t i = 0; i < n; ++i) {
            const std::uint8_t* p = &img.pixels[i * std::size_t(c)];
            std::uint8_t* q = &rgba[i * 4];
            q[0] = p[0];
            q[1] = c >= 3 ? p[1] : p[0];
            q[2] = c >= 3 ? p[2] : p[0];
            q[3] = c == 2 ? p[1] : (c == 4 ? p[3] : 255);
        }
    } else {
        // 16-bit files, as linear v / 65535: back to v, then its high byte
        // (what stb_image's 8-bit load gives).
        for (std::size_t i = 0; i < n * 4; ++i)
            rgba[i] = std::uint8_t(long(std::lround(double(img.rgba[i]) * 65535.0)) >> 8);
        for (std::size_t i = 3; i < n * 4 && !has_alpha; i += 4) has_alpha = rgba[i] != 255;
    }
    return Image8::from_rgba(img.width, img.height, rgba.data(), has_alpha);
}

DiffResult diff_images(const Image8& a, const Image8& b, const DiffTolerance& tol) {
    if (a.width != b.width || a.height != b.height)
        throw std::invalid_argument("diff_images: sizes differ (" + std::to_string(a.width) + "x" +
                                    std::to_string(a.height) + " and " + std::to_string(b.width) + "x" +
                                    std::to_string(b.height) + ")");
    DiffResult r;
    r.width = a.width;
    r.height = a.height;
    r.channels = (a.has_alpha || b.has_alpha) ? 4 : 3;
    const std::int64_t pixels = std::int64_t(a.width) * a.height;
    // Squared differences are integers: their sum is exact in 64 bits for any
    // image under kMaxImageTexels (2^28 * 4 * 255^2 < 2^47).
    std::int64_t sum_sq = 0;
    for (int y = 0; y < a.height; ++y)
        for (int x = 0; x < a.width; ++x) {
            const std::uint8_t* pa = a.at(x, y);
            const std::uint8_t* pb = b.at(x, y);
            int d = 0;
            for (int c = 0; c < r.channels; ++c) {
                const int dc = std::abs(int(pa[c]) - int(pb[c]));
                sum_sq += std::int64_t(dc) * dc;
                d = std::max(d, dc);
            }
            if (d > r.max_diff) {
                r.max_diff = d;
                r.max_x = x;
                r.max_y = y;
            }
            if (d > tol.channel) {
                if (r.differing == 0) {
                    r.box_x0 = r.box_x1 = x;
                    r.box_y0 = r.box_y1 = y;
                }
                r.box_x0 = std::min(r.box_x0, x);
                r.box_x1 = std::max(r.box_x1, x);
                r.box_y1 = y;  // rows are visited in order
                ++r.differing;
            }
        }
    const double samples = double(pixels) * r.channels;
    r.mse = pixels > 0 ? double(sum_sq) / samples : 0.0;
    r.psnr_db = r.mse > 0.0 ? 10.0 * std::log10(255.0 * 255.0 / r.mse) : std::numeric_limits<double>::infinity();
    r.differing_fraction = pixels > 0 ? double(r.differing) / double(pixels) : 0.0;
    // A hair of slack so that F = 0.001 on 1000 pixels allows exactly 1.
    r.allowed = std::int64_t(std::floor(std::max(0.0, tol.fraction) * double(pixels) + 1e-9));
    r.match = r.differing <= r.allowed;
    return r;
}

std::vector<std::uint8_t> diff_heatmap(const Image8& a, const Image8& b, const DiffTolerance& tol) {
    if (a.width != b.width || a.height != b.height)
        throw std::invalid_argument("diff_heatmap: sizes differ");
    const int channels = (a.has_alpha || b.has_alpha) ? 4 : 3;
    std::vector<std::uint8_t> out(a.rgba.size());
    for (std::size_t i = 0; i < a.rgba.size(); i += 4) {
        int d = 0;
        for (int c = 0; c < channels; ++c) d = std::max(d, std::abs(int(a.rgba[i + c]) - int(b.rgba[i + c])));
        std::uint8_t* o = &out[i];
        if (d == 0) {
            const auto grey = std::uint8_t((int(a.rgba[i]) + a.rgba[i + 1] + a.rgba[i + 2]) / 12);
            o[0] = o[1] = o[2] = grey;
        } else if (d <= tol.channel) {
            o[0] = 0;
            o[1] = std::uint8_t(d);
            o[2] = 255;
        } else {
            o[0] = 255;
            o[1] = std::uint8_t(d);
            o[2] = 0;
        }
        o[3] = 255;
    }
    return out;
}

std::string format_diff(const DiffResult& r, const DiffTolerance& tol) {
    char buf[256];
    std::string s;
    std::snprintf(buf, sizeof buf, "size: %dx%d, %s\n", r.width, r.height, r.channels == 4 ? "RGBA" : "RGB");
    s += buf;
    if (std::isinf(r.psnr_db)) s += "psnr: inf dB\n";
    else {
        std::snprintf(buf, sizeof buf, "psnr: %.2f dB\n", r.psnr_db);
        s += buf;
    }
    if (r.max_diff == 0) s += "max difference: 0\n";
    else {
        std::snprintf(buf, sizeof buf, "max difference: %d at %d,%d\n", r.max_diff, r.max_x, r.max_y);
        s += buf;
    }
    std::snprintf(buf, sizeof buf, "differing pixels: %lld of %lld (fraction %.6f) above tolerance %d\n",
                  static_cast<long long>(r.differing), static_cast<long long>(std::int64_t(r.width) * r.height),
                  r.differing_fraction, tol.channel);
    s += buf;
    if (r.differing == 0) s += "bounding box: none\n";
    else {
        std::snprintf(buf, sizeof buf, "bounding box: %d,%d to %d,%d (%dx%d)\n", r.box_x0, r.box_y0, r.box_x1,
                      r.box_y1, r.box_x1 - r.box_x0 + 1, r.box_y1 - r.box_y0 + 1);
        s += buf;
    }
    std::snprintf(buf, sizeof buf, "result: %s (at most %lld pixels may exceed tolerance %d)\n",
                  r.match ? "match" : "differ", static_cast<long long>(r.allowed), tol.channel);
    s += buf;
    return s;
}

} // namespace prast

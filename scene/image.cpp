// Image decoding: stb_image (PNG, JPEG, HDR, ...) to linear float RGBA, with
// sRGB colour channels decoded first; see image.h.
#include "scene/image.h"

#include <array>
#include <cerrno>
#include <climits>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <memory>
#include <string>

#include <stb_image.h>
#include <unistd.h>

#include "scene/file_access.h"
#include "scene/hdr_guard.h"
#include "scene/messages.h"

namespace prast {

namespace {

// The sRGB electro-optical transfer function (IEC 61966-2-1), exact form.
float srgb_to_linear(float c) {
    return c <= 0.04045f ? c / 12.92f : std::pow((c + 0.055f) / 1.055f, 2.4f);
}

const std::array<float, 256>& srgb_table() {
    static const std::array<float, 256> table = [] {
        std::array<float, 256> t{};
        for (int i = 0; i < 256; ++i) t[i] = srgb_to_linear(float(i) / 255.0f);
        return t;
    }();
    return table;
}

std::string stbi_reason() {
    const char* r = stbi_failure_reason();
    return r ? r : "unknown error";
}

// The container format by its signature, for messages: when its header is
// bad, stb_image tries every other format and reports only the last failure
// ("unknown image type").
const char* sniff_format(const unsigned char* p, std::size_t n) {
    auto starts = [&](const char* sig, std::size_t len) { return n >= len && std::memcmp(p, sig, len) == 0; };
    if (starts("\x89PNG\r\n\x1a\n", 8)) return "PNG";
    if (starts("\xff\xd8\xff", 3)) return "JPEG";
    if (starts("#?RADIANCE", 10) || starts("#?RGBE", 6)) return "HDR";
    if (starts("GIF8", 4)) return "GIF";
    if (starts("8BPS", 4)) return "PSD";
    if (starts("BM", 2)) return "BMP";
    return nullptr;
}

// Expands `comp` channels per texel to RGBA, decoding colour channels with
// `colour` and alpha with `alpha`.
template <class T, class ColourFn, class AlphaFn>
void expand_to_rgba(const T* src, int comp, std::size_t count, float* dst, ColourFn colour,
                    AlphaFn alpha) {
    for (std::size_t i = 0; i < count; ++i, src += comp, dst += 4) {
        if (comp <= 2) {
            const float g = colour(src[0]);
            dst[0] = dst[1] = dst[2] = g;
            dst[3] = comp == 2 ? alpha(src[1]) : 1.0f;
        } else {
            dst[0] = colour(src[0]);
            dst[1] = colour(src[1]);
            dst[2] = colour(src[2]);
            dst[3] = comp == 4 ? alpha(src[3]) : 1.0f;
        }
    }
}

} // namespace

Image decode_image(const ImageSource& src, bool srgb) {
    const std::string name = printable(!src.name.empty()   ? src.name
                                       : !src.path.empty() ? src.path
                                                           : std::string("<embedded image>"));
    // Get the encoded bytes: embedded ones win over the path.
    std::vector<unsigned char> file_bytes;
    const std::vector<unsigned char>* bytes = &src.bytes;
    if (src.bytes.empty()) {
        if (src.path.empty()) throw LoadError(name + ": no image data (no path, no bytes)");
        // Only a regular file, never past what stb_image's int length takes.
        file_bytes = read_regular_file(src.path, std::uint64_t(INT_MAX), name);
        bytes = &file_bytes;
    }
    if (bytes->size() > std::size_t(INT_MAX)) throw LoadError(name + ": image data too large");
    const stbi_uc* data = bytes->data();
    const int len = int(bytes->size());

    // Radiance data goes through the guard first: stb_image 2.27 can hang on it.
    if (looks_like_hdr(data, bytes->size())) {
        int hw = 0, hh = 0;
        const std::string bad = check_hdr_data(data, bytes->size(), hw, hh);
        if (!bad.empty()) throw LoadError(name + ": cannot decode HDR image: " + bad);
    }

    // Check the header before decoding anything: refuse absurd sizes up front.
    int w = 0, h = 0, comp = 0;
    if (!stbi_info_from_memory(data, len, &w, &h, &comp)) {
        const char* format = sniff_format(data, bytes->size());
        const std::string reason = stbi_reason();
        if (!format) throw LoadError(name + ": not an image file stb_image can read (" + reason + ")");
        throw LoadError(name + ": cannot decode " + format + " image: " +
                        (reason == "unknown image type" ? "corrupt or truncated header" : reason));
    }
    if (w <= 0 || h <= 0)
        throw LoadError(name + ": image has zero size (" + std::to_string(w) + "x" +
                        std::to_string(h) + ")");
    const std::int64_t texels = std::int64_t(w) * std::int64_t(h);
    if (texels > kMaxImageTexels)
        throw LoadError(name + ": image too large: " + std::to_string(w) + "x" +
                        std::to_string(h) + " = " + std::to_string(texels) +
                        " texels, more than the limit of " + std::to_string(kMaxImageTexels) +
                        " (2^28)");

    // Decode with the file's own channel count.
    struct StbiFree {
        void operator()(void* p) const { stbi_image_free(p); }
    };
    Image img;
    int dw = 0, dh = 0, dcomp = 0;
    auto check = [&](const void* pixels) {
        if (!pixels) throw LoadError(name + ": cannot decode image: " + stbi_reason());
        if (dw != w || dh != h || dcomp < 1 || dcomp > 4)
            throw LoadError(name + ": inconsistent image header");
        img.width = w;
        img.height = h;
        img.rgba.resize(std::size_t(texels) * 4);
    };
    const std::size_t count = std::size_t(texels);
    const auto unit = [](float c) { return c; };
    if (stbi_is_hdr_from_memory(data, len)) {
        // Radiance HDR: linear floats, kept as is whatever `srgb` says.
        std::unique_ptr<float, StbiFree> px(stbi_loadf_from_memory(data, len, &dw, &dh, &dcomp, 0));
        check(px.get());
        expand_to_rgba(px.get(), dcomp, count, img.rgba.data(), unit, unit);
    } else if (stbi_is_16_bit_from_memory(data, len)) {
        std::unique_ptr<stbi_us, StbiFree> px(stbi_load_16_from_memory(data, len, &dw, &dh, &dcomp, 0));
        check(px.get());
        const auto linear = [](stbi_us c) { return float(c) / 65535.0f; };
        const auto decode = [](stbi_us c) { return srgb_to_linear(float(c) / 65535.0f); };
        if (srgb) expand_to_rgba(px.get(), dcomp, count, img.rgba.data(), decode, linear);
        else expand_to_rgba(px.get(), dcomp, count, img.rgba.data(), linear, linear);
    } else {
        std::unique_ptr<stbi_uc, StbiFree> px(stbi_load_from_memory(data, len, &dw, &dh, &dcomp, 0));
        check(px.get());
        const std::array<float, 256>& table = srgb_table();
        const auto linear = [](stbi_uc c) { return float(c) / 255.0f; };
        const auto decode = [&table](stbi_uc c) { return table[c]; };
        if (srgb) expand_to_rgba(px.get(), dcomp, count, img.rgba.data(), decode, linear);
        else expand_to_rgba(px.get(), dcomp, count, img.rgba.data(), linear, linear);
    }
    return img;
}

namespace {

// stb_image's callbacks over a file descriptor, for reading headers only.
int fd_read(void* user, char* data, int size) {
    for (;;) {
        const ssize_t n = ::read(*static_cast<int*>(user), data, std::size_t(size));
        if (n < 0 && errno == EINTR) continue;
        return n < 0 ? 0 : int(n);
    }
}
void fd_skip(void* user, int n) { ::lseek(*static_cast<int*>(user), n, SEEK_CUR); }
int fd_eof(void* user) {
    const int fd = *static_cast<int*>(user);
    const off_t here = ::lseek(fd, 0, SEEK_CUR), end = ::lseek(fd, 0, SEEK_END);
    ::lseek(fd, here, SEEK_SET);
    return here >= end;
}

} // namespace

bool image_dimensions(const ImageSource& src, int& width, int& height) {
    int comp = 0;
    width = height = 0;
    if (!src.bytes.empty()) {
        if (src.bytes.size() > std::size_t(INT_MAX)) return false;
        return stbi_info_from_memory(src.bytes.data(), int(src.bytes.size()), &width, &height, &comp) != 0;
    }
    if (src.path.empty()) return false;
    std::uint64_t size = 0;
    int fd = -1;
    try {
        fd = open_regular_file(src.path, src.name, size);
    } catch (const LoadError&) {
        return false;
    }
    const stbi_io_callbacks io{fd_read, fd_skip, fd_eof};
    const int ok = stbi_info_from_callbacks(&io, &fd, &width, &height, &comp);
    ::close(fd);
    return ok != 0;
}

} // namespace prast

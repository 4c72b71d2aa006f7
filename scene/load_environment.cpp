// Environment map reading; see load_environment.h.
#include "scene/load_environment.h"

#include <cstring>
#include <filesystem>

#include "scene/file_access.h"
#include "scene/messages.h"

namespace prast {

Image load_environment_hdr(const std::string& path) {
    // decode_image() reads any format stb_image knows; an 8-bit PNG renamed
    // .hdr would light the scene with radiance at most 1, so check the
    // Radiance signature first ("#?RADIANCE" or "#?RGBE").
    std::error_code ec;
    if (!std::filesystem::exists(path, ec)) throw LoadError(printable(path) + ": no such file");
    if (std::filesystem::is_directory(path, ec))
        throw LoadError(printable(path) + ": is a directory, not an .hdr file");
    // Only a regular file, read once, at most kMaxReadBytes: a FIFO or a
    // device named by --env cannot hang or flood the render.
    ImageSource src;
    src.name = path;
    src.bytes = read_regular_file(path, kMaxReadBytes, path);
    const std::vector<unsigned char>& b = src.bytes;
    if (b.empty()) throw LoadError(printable(path) + ": empty file");
    const auto starts_with = [&](const char* sig) {
        const std::size_t n = std::strlen(sig);
        return b.size() >= n && std::memcmp(b.data(), sig, n) == 0;
    };
    if (!starts_with("#?RADIANCE") && !starts_with("#?RGBE"))
        throw LoadError(printable(path) + ": not a Radiance HDR file (no #?RADIANCE or #?RGBE header)");
    return decode_image(src, false);
}

} // namespace prast

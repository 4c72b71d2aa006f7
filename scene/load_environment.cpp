// Environment map reading; see load_environment.h.
#include "scene/load_environment.h"

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>

namespace prast {

Image load_environment_hdr(const std::string& path) {
    // decode_image() reads any format stb_image knows; an 8-bit PNG renamed
    // .hdr would light the scene with radiance at most 1, so check the
    // Radiance signature first ("#?RADIANCE" or "#?RGBE").
    std::error_code ec;
    if (!std::filesystem::exists(path, ec)) throw LoadError(path + ": no such file");
    if (std::filesystem::is_directory(path, ec)) throw LoadError(path + ": is a directory, not an .hdr file");
    char head[10] = {};
    std::size_t got = 0;
    if (std::FILE* f = std::fopen(path.c_str(), "rb")) {
        got = std::fread(head, 1, sizeof head, f);
        std::fclose(f);
    } else {
        throw LoadError(path + ": cannot open (" + std::strerror(errno) + ")");
    }
    if (got == 0) throw LoadError(path + ": empty file");
    if (!(got >= 10 && std::memcmp(head, "#?RADIANCE", 10) == 0) && !(got >= 6 && std::memcmp(head, "#?RGBE", 6) == 0))
        throw LoadError(path + ": not a Radiance HDR file (no #?RADIANCE or #?RGBE header)");
    ImageSource src;
    src.path = path;
    src.name = path;
    return decode_image(src, false);
}

} // namespace prast

// The web page's files (stepper/web/), built into the program by
// stepper/embed_web.cmake: the server needs no file and no network.
#pragma once

#include <cstddef>
#include <string>

namespace prast::stepper {

struct WebAsset {
    const char* path;   // "/index.html"
    const char* mime;
    const unsigned char* data;
    std::size_t size;
};

// nullptr when there is no such file.
const WebAsset* find_web_asset(const std::string& path);

} // namespace prast::stepper

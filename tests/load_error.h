// The one-line message the loader refuses a file with, for tests of bad input.
#pragma once

#include <string>

#include "scene/load_scene.h"

namespace prast::test {

// The LoadError message for path, or "" when it loads.
inline std::string load_error(const std::string& path) {
    try {
        load_scene(path);
    } catch (const LoadError& e) {
        return e.what();
    }
    return "";
}

} // namespace prast::test

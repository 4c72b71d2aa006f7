// Reading an environment map (render --env): an equirectangular Radiance
// .hdr (docs/conventions.md "Environment maps"), decoded by decode_image() to
// linear float RGBA as stored (the map's own exposure). Anything that is not a
// Radiance file, or that fails to decode, is a LoadError "FILE: problem".
#pragma once

#include <string>

#include "scene/image.h"

namespace prast {

Image load_environment_hdr(const std::string& path);

} // namespace prast

// The built-in scene `render` draws with no arguments: a grid of spheres that
// sweeps roughness (columns, 0 to 1) against metallic (rows, 0 to 1), standing
// on a floor of tiles whose albedo, normal and roughness/metal maps are made by
// code here (procedural_images.h), lit by a sun and a point light. No
// third-party file is involved.
#pragma once

#include "scene/camera.h"
#include "scene/scene.h"

namespace prast {

struct DefaultScene {
    Scene scene;
    Camera camera;  // the framing the README image uses (for 16:9)
};

DefaultScene make_default_scene();

} // namespace prast

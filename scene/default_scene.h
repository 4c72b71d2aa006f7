// The built-in scene `render` draws with no arguments: a grid of spheres that
// sweeps roughness (columns, 0 to 1) against metallic (rows, 0 to 1), standing
// on a floor of tiles whose albedo, normal and roughness/metal maps are made by
// code here (procedural_images.h), lit by a sun and a point light and by a
// procedural sky (make_default_sky) that the metal spheres reflect. No
// third-party file is involved.
#pragma once

#include "scene/camera.h"
#include "scene/image.h"
#include "scene/scene.h"

namespace prast {

struct DefaultScene {
    Scene scene;
    Camera camera;  // the framing the README image uses (for 16:9)
};

// Its images (the three tile maps and the sky) are made on up to `threads`
// threads (0: all hardware threads); each image is the same either way.
DefaultScene make_default_scene(int threads = 1);

// The built-in scene's environment, an equirect map of `width` x width/2
// texels (linear radiance): a sky from a pale horizon to a blue zenith, a
// small sun disc where the scene's sun light comes from, and a dim ground.
Image make_default_sky(int width);

} // namespace prast

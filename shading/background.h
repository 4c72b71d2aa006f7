// What the image shows where no triangle was drawn (conventions.md "Output"):
// black, unless an environment map is shown (the map itself, or its
// prefiltered level of a medium roughness, `--background blur`), or a flat
// colour the user asked for.
#pragma once

#include <glm/glm.hpp>

#include "raster/framebuffer.h"
#include "raster/thread_pool.h"
#include "scene/camera.h"
#include "shading/environment.h"

namespace prast {

enum class Background { Env, Blur, Black, Color };

// The roughness whose prefiltered level `blur` shows.
constexpr float kBlurBackgroundRoughness = 0.5f;

// Every pixel whose depth is still the clear value (1) gets the background
// along its camera ray (through the pixel centre). env may be null only for
// Black and Color. One task per row: the same bytes for any thread count.
void draw_background(Framebuffer& fb, const Camera& cam, const Environment* env, Background mode,
                     const glm::vec3& color, ThreadPool& pool);

} // namespace prast

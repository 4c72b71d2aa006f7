// What the image shows where no triangle was drawn (docs/conventions.md "Output"):
// black, unless an environment map is shown (the map itself, or its
// prefiltered level of a medium roughness, `--background blur`), or a flat
// colour the user asked for. A frame clears each pixel to it (in the tile
// pass, FrameOptions::clear_fill), so that with several samples per pixel
// the samples no triangle covers resolve to it.
#pragma once

#include <cstddef>

#include <glm/glm.hpp>

#include "raster/frame.h"
#include "scene/camera.h"
#include "shading/ibl/environment.h"

namespace prast {

enum class Background { Env, Blur, Black, Color };

// The roughness whose prefiltered level `blur` shows.
constexpr float kBlurBackgroundRoughness = 0.5f;

// The background of one frame of width x height pixels seen through `cam`:
// each pixel's colour along its camera ray (through the pixel centre).
class BackgroundFill {
public:
    // env may be null only for Black and Color (Env and Blur without one are black).
    BackgroundFill(const Camera& cam, int width, int height, const Environment* env, Background mode,
                   const glm::vec3& color);

    // Black: the frame's plain clear colour does.
    bool black() const { return mode_ == Background::Black; }
    // Pixel (x, y)'s colour.
    glm::vec3 at(int x, int y) const;
    // Pixels [x0, x0 + w) x [y0, y0 + h): RGBA (alpha 1) of pixel (x0 + i,
    // y0 + j) at rgba[j * row + 4 i]; the same values as at().
    void fill(int x0, int y0, int w, int h, float* rgba, std::size_t row) const;
    // Sets `frame` to clear to this background (this must outlive the frame).
    void attach(FrameOptions& frame) const;

private:
    Background mode_;
    glm::vec3 color_;
    const Environment* env_;
    int width_, height_;
    glm::vec3 f_, s_, u_;      // the camera's basis, as glm::lookAt builds it
    float half_w_, half_h_;    // half extents of the image plane at distance 1
    float lod_;                // blur's level
    EquirectLevel level_;      // env's source level
};

} // namespace prast

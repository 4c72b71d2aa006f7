// Display transform: linear HDR -> tone map -> sRGB -> 8 bits, the last stage
// of docs/conventions.md's "Output". Exposure is NOT part of tonemap(): the caller
// multiplies by it first (resolve_to_srgb8 does so).
#pragma once

#include <cstdint>
#include <string>

#include <glm/glm.hpp>

namespace prast {

enum class ToneMap { None, Aces, Neutral };

// "none", "aces" or "neutral"; false (out untouched) for anything else.
bool parse_tonemap(const std::string& s, ToneMap& out);
const char* tonemap_name(ToneMap tm);

// Linear (already exposed) colour to linear display colour in [0, 1]:
// None clamps; Aces is Narkowicz's 2015 fit, per channel, clamped;
// Neutral is the Khronos PBR Neutral operator (negative input clamped to 0).
glm::vec3 tonemap(glm::vec3 linear, ToneMap tm);

// The whole-image resolve (resolve.h has the per-run and per-tile forms,
// vectorised; the bytes are the same).
// For each pixel: rgb * exposure, tonemap, sRGB encode, round to 8 bits
// (byte-identical to linear_to_srgb8); alpha is not exposed nor encoded:
// floor(clamp(a, 0, 1) * 255 + 0.5). Both buffers are width * height RGBA,
// rows in order; the colour is used as is (not divided by alpha).
void resolve_to_srgb8(const float* rgba_linear, int width, int height, float exposure,
                      ToneMap tm, std::uint8_t* rgba8_out);

// Data (debug views) to 8 bits as is: clamp to [0, 1], * 255, round; alpha 255.
void resolve_raw8(const float* rgba, int width, int height, std::uint8_t* rgba8_out);

} // namespace prast

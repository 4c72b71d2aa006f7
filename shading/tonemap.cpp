// Tone mapping operators and the final 8-bit resolve (see tonemap.h).
#include "shading/tonemap.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <cstddef>

#include "shading/color.h"
#include "shading/output8.h"

namespace prast {

namespace {

inline float clamp01(float x) {
    if (!(x > 0.0f)) return 0.0f;  // also NaN
    return x < 1.0f ? x : 1.0f;
}

// Narkowicz 2015, "ACES Filmic Tone Mapping Curve": a rational fit of the
// ACES RRT + ODT for sRGB. The post's 0.6 pre-scale is not applied: the
// conventions give the bare curve, and exposure is the caller's.
inline float aces_narkowicz(float x) {
    // Negative input would map to the fit's other branch (x = -1 gives 1.25).
    x = std::max(x, 0.0f);
    float num = x * (2.51f * x + 0.03f);
    float den = x * (2.43f * x + 0.59f) + 0.14f;
    return clamp01(num / den);
}

// Khronos PBR Neutral (KhronosGroup/ToneMapping, PBR_Neutral/README.md):
// identity up to a small toe offset until the brightest channel reaches
// Ks = 0.8 - 0.04, then a hue-preserving compression of the peak towards 1
// with desaturation speed Kd = 0.15.
inline glm::vec3 pbr_neutral(glm::vec3 c) {
    constexpr float kF90 = 0.04f;
    constexpr float kStartCompression = 0.8f - 0.04f;
    constexpr float kDesaturation = 0.15f;
    c = glm::max(c, glm::vec3(0.0f));
    // Toe: subtract f = x - x^2 / (4 F90) for x <= 2 F90, else F90 (x = min channel).
    float x = std::min(c.r, std::min(c.g, c.b));
    float offset = x < 2.0f * kF90 ? x - 6.25f * x * x : kF90;
    c -= offset;
    float peak = std::max(c.r, std::max(c.g, c.b));
    if (peak < kStartCompression) return c;
    // Compress the peak, then blend towards white as it is compressed.
    constexpr float d = 1.0f - kStartCompression;
    float new_peak = 1.0f - d * d / (peak + d - kStartCompression);
    c *= new_peak / peak;
    float g = 1.0f - 1.0f / (kDesaturation * (peak - new_peak) + 1.0f);
    return glm::mix(c, glm::vec3(new_peak), g);
}

template <ToneMap TM>
inline glm::vec3 tonemap_fixed(glm::vec3 c) {
    if constexpr (TM == ToneMap::Aces) {
        return glm::vec3(aces_narkowicz(c.r), aces_narkowicz(c.g), aces_narkowicz(c.b));
    } else if constexpr (TM == ToneMap::Neutral) {
        glm::vec3 m = pbr_neutral(c);
        return glm::vec3(clamp01(m.r), clamp01(m.g), clamp01(m.b));
    } else {
        return glm::vec3(clamp01(c.r), clamp01(c.g), clamp01(c.b));
    }
}

} // namespace

bool parse_tonemap(const std::string& s, ToneMap& out) {
    if (s == "none") { out = ToneMap::None; return true; }
    if (s == "aces") { out = ToneMap::Aces; return true; }
    if (s == "neutral") { out = ToneMap::Neutral; return true; }
    return false;
}

const char* tonemap_name(ToneMap tm) {
    switch (tm) {
    case ToneMap::None: return "none";
    case ToneMap::Aces: return "aces";
    case ToneMap::Neutral: return "neutral";
    }
    return "?";
}

glm::vec3 tonemap(glm::vec3 linear, ToneMap tm) {
    switch (tm) {
    case ToneMap::Aces: return tonemap_fixed<ToneMap::Aces>(linear);
    case ToneMap::Neutral: return tonemap_fixed<ToneMap::Neutral>(linear);
    case ToneMap::None: break;
    }
    return tonemap_fixed<ToneMap::None>(linear);
}

void resolve_to_srgb8(const float* rgba_linear, int width, int height, float exposure,
                      ToneMap tm, std::uint8_t* rgba8_out) {
    assert(width >= 0 && height >= 0);
    assert((rgba_linear && rgba8_out) || width == 0 || height == 0);
    resolve_pixels_srgb8(rgba_linear, std::size_t(width) * std::size_t(height), exposure, tm, rgba8_out);
}

void resolve_raw8(const float* rgba, int width, int height, std::uint8_t* out) {
    resolve_pixels_raw8(rgba, std::size_t(width) * std::size_t(height), out);
}

} // namespace prast

// The 2D (n.v, roughness) table of the split sum's BRDF half (Karis 2013):
// for Schlick's F = F0 + (1 - F0) Fc, Fc = (1 - v.h)^5, the specular
// reflectance of a material under uniform light is
//     E_spec(v) = integral of f_spec (n.l) dl = F0 A + B,
//     A = integral of (1 - Fc) f_spec/F (n.l),   B = integral of Fc f_spec/F (n.l),
// and the diffuse lobe with the conventions' kd = (1 - F)(1 - metallic) takes
//     (1 - F0)(1 - metallic) albedo Kd,   Kd = (1/pi) integral of (1 - Fc) (n.l) dl,
// which depends on n.v only. Each texel holds (A, B, Kd, 0).
//
// Three tables, one per geometry term: Schlick-GGX G with k = r^2 / 2 (image-
// based lighting), with k = (r + 1)^2 / 8 (analytic lights, for the energy
// compensation of --energy conserve), and the height-correlated V of --brdf
// gltf. The specular lobe includes the conventions' e = 1e-4 clamps exactly as
// evaluate_brdf() computes it.
//
// The energy terms of --energy conserve come from the same texel: E_ss = A + B
// is the single-scattering albedo of a white (F = 1) metal, so the multiple-
// scattering compensation is 1 + F0 (1 / E_ss - 1) (Fdez-Aguera 2019, as
// Filament writes it), and the diffuse keeps what the compensated specular
// lobe leaves, (1 - E_spec)(1 - metallic) (Kelemen & Szirmay-Kalos 2001).
//
// Built on the thread pool, one task per roughness row, each texel a fixed-
// order sum: the same bytes for any thread count.
#pragma once

#include <cmath>
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "raster/thread_pool.h"
#include "shading/ibl/equirect.h"

namespace prast {

enum class DfgModel { SchlickIbl, SchlickDirect, HeightCorrelated };

class DfgTable {
public:
    static constexpr int kSizeNoV = 64;     // texels along n.v (the terms change fast near grazing)
    static constexpr int kSizeRough = 32;   // texels along roughness
    static constexpr int kSamples = 2048;   // GGX half vectors per texel (Hammersley)

    // `Lanes` integrates four n.v columns at a time where the build has AVX2,
    // with the same bits as `Scalar`, one at a time (the test's reference).
    enum class Path { Lanes, Scalar };
    static DfgTable build(DfgModel model, ThreadPool& pool, Path path = Path::Lanes);

    DfgModel model() const { return model_; }
    // (A, B, Kd, 0) texels, row-major: row j is roughness j / (kSizeRough - 1)
    // (clamped to [0.045, 1]), column i is n.v = (i / (kSizeNoV - 1))^2: the
    // ends (n.v = 0 and 1, r = 1) are texels, not extrapolations, and the
    // columns crowd towards grazing views, where the terms change fastest.
    const glm::vec4* texels() const { return texels_.data(); }
    // Bilinear lookup at (n.v, r); r already clamped to [0.045, 1].
    glm::vec4 lookup(float NoV, float r) const;

private:
    DfgModel model_ = DfgModel::SchlickIbl;
    std::vector<glm::vec4> texels_;
};

// The table texels and weights at (n.v, r), shared by the scalar and the lane
// code: column sqrt(n.v) (kSizeNoV - 1), row r (kSizeRough - 1), clamped to
// the table; NaN reads at 0.
[[gnu::always_inline]] inline void dfg_taps(float NoV, float r, std::int32_t* idx, float& tx, float& ty) {
    constexpr int S = DfgTable::kSizeNoV, R = DfgTable::kSizeRough;
    const float right = float(S - 1), top = float(R - 1);
    float x = std::sqrt(NoV) * right, y = r * top;
    x = x > 0.0f ? x : 0.0f;  // also NaN -> 0
    y = y > 0.0f ? y : 0.0f;
    x = x < right ? x : right;
    y = y < top ? y : top;
    const std::int32_t xi = std::int32_t(x), yi = std::int32_t(y);
    const std::int32_t x0 = xi < S - 2 ? xi : S - 2, y0 = yi < R - 2 ? yi : R - 2;
    tx = x - float(x0);
    ty = y - float(y0);
    idx[0] = y0 * S + x0;
    idx[1] = y0 * S + x0 + 1;
    idx[2] = (y0 + 1) * S + x0;
    idx[3] = (y0 + 1) * S + x0 + 1;
}

inline glm::vec4 DfgTable::lookup(float NoV, float r) const {
    std::int32_t idx[4];
    float tx, ty;
    dfg_taps(NoV, r, idx, tx, ty);
    const Texel4 c = bilinear4(texels_.data(), idx, tx, ty);
    return {c[0], c[1], c[2], c[3]};
}

// The --energy conserve factors of one colour channel from a texel (A, B):
// the specular multiplier and the specular albedo it leads to. Shared by the
// scalar and the lane code (same operations, same order).
[[gnu::always_inline]] inline float energy_compensation(float F0, float A, float B) {
    const float Ess = A + B;
    return 1.0f + F0 * (1.0f / (Ess > 1e-4f ? Ess : 1e-4f) - 1.0f);
}

} // namespace prast

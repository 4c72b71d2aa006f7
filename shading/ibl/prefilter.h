// The two filters the environment's precomputation runs over equirect levels:
// an area-weighted resampler (each output texel the solid-angle-weighted mean
// of the source texels it covers, so every level keeps the map's integral
// of radiance) for the source's mip chain, and the GGX prefilter of the split
// sum's specular half (Karis 2013), with filtered importance sampling
// (Krivanek & Colbert 2008): each of the N GGX samples reads the source at the
// mip level whose texels have the solid angle the sample stands for,
// 1 / (N pdf), so a small bright source (a sun) is spread over the lobe
// instead of being hit by a few samples as fireflies.
//
// Both run one task per output row; every texel is a fixed-order sum, so the
// bytes do not depend on the thread count.
#pragma once

#include <glm/glm.hpp>

#include "raster/thread_pool.h"
#include "shading/ibl/equirect.h"

namespace prast {

// texels[out.offset ...] = the area-weighted resampling of texels[in.offset ...].
// Any sizes (up- or downsampling); rows are weighted by their solid angle.
void resample_equirect(glm::vec4* texels, const EquirectLevel& in, const EquirectLevel& out, ThreadPool& pool);

// texels[out.offset ...] = sum over samples of L(l) (n.l) / sum of (n.l), with
// n = v = the texel's direction and h GGX-distributed for roughness r (alpha =
// r^2); L read trilinearly from the `mip_count` source levels `mips` at the
// filtered-importance-sampling level, 0.5 log2(omega_sample / omega_texel) + 1.
// `Lanes` runs eight texels of a row at a time where the build has AVX2,
// with the same bits as `Scalar`, one texel at a time (the test's reference).
enum class PrefilterPath { Lanes, Scalar };
void prefilter_ggx(glm::vec4* texels, const EquirectLevel* mips, int mip_count, float roughness, int samples,
                   const EquirectLevel& out, ThreadPool& pool, PrefilterPath path = PrefilterPath::Lanes);

} // namespace prast

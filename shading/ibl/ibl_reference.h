// The ground truth the split sum is measured against (render --ibl
// reference): the reflectance equation at one shading point integrated
// directly over the environment,
//     Lo = sum over N incoming directions l of f(v, l) L(l) (n.l) dw(l),
// with the BRDF of brdf.h (the conventions' k = r^2 / 2 for image-based
// lighting; the energy terms when the inputs carry them) and L the source
// map, bilinear, with no prefiltering and no split.
//
// The N directions are deterministic: Hammersley points warped by three
// strategies, each given a fixed share of N (the GGX lobe, the cosine lobe,
// and the map's own luminance when the environment has a sampler), combined
// with the balance heuristic (Veach 1997, multi-sample MIS): each sample
// weighs f L (n.l) / sum_s N_s pdf_s(l), so dw is exact for the mixture and
// the sum is an unbiased estimate whatever the shares. Map sampling is what
// makes a small sun converge.
#pragma once

#include <glm/glm.hpp>

#include "shading/brdf.h"
#include "shading/ibl/environment.h"

namespace prast {

// Lo at a point with inputs `in` (n, v and the material; in.l is ignored),
// not yet times occlusion.
glm::vec3 integrate_environment(const Environment& env, const BrdfInputs& in, BrdfModel model, int samples);

} // namespace prast

// Procedural images for the built-in scene (linear values, deterministic,
// seamless under Repeat): made by code, so no third-party file is involved.
#pragma once

#include <cstdint>

#include <glm/glm.hpp>

#include "scene/image.h"

namespace prast {

// Which integer hash picks the noise lattice's values: Mixed (the built-in
// scene's images) or Linear (x * 73856093 ^ y * 19349663 ^ seed, then mixed:
// the maps of bench's synthetic workloads). Each keeps its images' bytes.
enum class NoiseLattice { Mixed, Linear };

// The lattice value at integer point (x, y), in [0, 1).
float lattice_value(int x, int y, std::uint32_t seed, NoiseLattice lattice = NoiseLattice::Mixed);
// Smooth value noise in [0, 1) with `period` lattice cells across [0, 1)
// (smoothstep between the four lattice values), so it tiles seamlessly.
float value_noise(glm::vec2 uv, int period, std::uint32_t seed, NoiseLattice lattice = NoiseLattice::Mixed);

// size x size, cells x cells squares; the top-left cell is `a`.
Image make_checker(int size, int cells, glm::vec4 a, glm::vec4 b);
// Running-bond bricks (4 across, 8 rows per tile of the texture) in a palette
// of ceramic colours, a few of them gold, with grey grout. Linear colour.
Image make_tiles_albedo(int size);
// The matching tangent-space normal map (OpenGL convention: green points up
// the image, towards -v), encoded 0.5 * n + 0.5: bevelled brick edges,
// concave grout grooves, each brick slightly tilted.
Image make_tiles_normal(int size);
// ORM packing: R = ambient occlusion (grout darker), G = roughness (glazed
// bricks smooth-ish, grout rough), B = metallic (1 on the gold bricks).
Image make_tiles_roughness_metal(int size);

// The three maps above, the same texels, made together: each sub-sample's
// brick is worked out once for all three. tile_maps_storage() allocates
// them; fill_tile_map_rows() makes rows [y0, y1) of each, so that bands of
// rows can be made on different threads.
struct TileMaps {
    Image albedo, normal, roughness_metal;
};
TileMaps tile_maps_storage(int size);
void fill_tile_map_rows(TileMaps& maps, int y0, int y1);
TileMaps make_tile_maps(int size);

} // namespace prast

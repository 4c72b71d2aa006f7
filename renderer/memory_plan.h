// The bytes a render holds at its peak, estimated before anything big is
// allocated: before the textures and the environment map are decoded, the
// shadow maps drawn or a frame started. render and step refuse a job whose
// plan exceeds the budget (half the physical memory) with the plan in the
// message, rather than being killed half-way (docs/security.md).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "scene/scene.h"
#include "shading/shadow/shadow_map.h"
#include "shading/surface.h"

namespace prast {

struct MemoryPlan {
    std::uint64_t scene = 0;        // meshes as loaded
    std::uint64_t textures = 0;     // decoded textures with their mip chains
    std::uint64_t texels = 0;       // their level-0 texels
    std::size_t images = 0;         // how many
    std::uint64_t pipeline = 0;     // per-vertex and per-triangle work of the largest mesh
    std::uint64_t image = 0;        // framebuffer and output image
    std::uint64_t environment = 0;  // the decoded map and its prefiltered levels
    std::string environment_name;   // its file, for the message
    std::uint64_t shadows = 0;      // shadow maps
    std::uint64_t recording = 0;    // step's record of the frame
    std::uint64_t total() const { return scene + textures + pipeline + image + environment + shadows + recording; }
    // "about N bytes (scene N, textures N for N texels in N images, ...)"
    std::string describe() const;
};

// Half the physical memory: the most a render may plan to use.
std::uint64_t memory_budget();

// The scene, its textures (only the images a material uses, at the file's
// bytes per texel, read from the headers), the pipeline and a width x height
// image of `bytes_per_pixel`.
MemoryPlan plan_memory(const Scene& scene, int width, int height, std::uint64_t bytes_per_pixel);

// The environment a render prefilters, decoded and with its levels
// (shading/environment.h): the --env file `env_path` (its size read from the
// header), else the scene's own map, else none. A map whose header cannot be
// read, or beyond kMaxImageTexels, is left to the decoder, which refuses it
// with its own message.
void plan_environment(MemoryPlan& plan, const Scene& scene, const std::string& env_path);

// One shadow map per light when shadows are on (shading/shadow_pass.h).
void plan_shadows(MemoryPlan& plan, const std::vector<ShadingLight>& lights, const ShadowSettings& settings);

// step's recording (stepper/recording.h): per triangle, and per sample for
// an average depth complexity of 2.
void plan_recording(MemoryPlan& plan, const Scene& scene, int width, int height, int samples);

} // namespace prast

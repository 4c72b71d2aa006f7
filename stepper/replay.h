// Recomputing what the recording left out, with the pipeline's own data and
// functions: a triangle's outcodes and clipped polygon (raster/clip.h), the
// vertices of each set-up piece, the barycentrics, depth and varyings of a
// 4x4 block exactly as rasterize.h's shade_block() computes them (the same
// float operations in the same order), and the shading of one lane with
// shading/surface.h's scalar path, which is bit-identical to the lane path
// `render` uses. Each draw is replayed with the program it was drawn with:
// PbrProgram, PbrProgramExt (vertex colours, a second UV set) or, for lines
// and points without normals, UnlitProgram. Lines and points, which the
// pipeline's observers do not follow past their vertices, are set up again
// with raster/line.h's own functions (bin.h's bin_lines() order: clip, snap,
// set up) and their pixels found by its exact diamond-exit test. The
// `verify` command re-renders the frame and compares all of it with the
// pipeline's own values.
#pragma once

#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "raster/clip.h"
#include "raster/fragment.h"
#include "raster/line.h"
#include "renderer/scene_renderer.h"
#include "shading/surface.h"
#include "stepper/recording.h"

namespace prast::stepper {

// Clipping of one triangle, recomputed from the recorded vertices.
struct ClipReplay {
    bool valid = false;                 // finite positions, indices in range
    std::uint32_t index[3] = {0, 0, 0}; // vertex indices in the mesh
    std::uint32_t outcode[3] = {0, 0, 0};
    std::uint32_t planes = 0;           // planes clipped against (kClipNeededBits)
    int count = 0;                      // polygon vertices after clipping (3 when not clipped)
    int stride = kStride;               // floats of each polygon vertex (the draw's)
    float polygon[kMaxClippedVertices][kMaxStride] = {};
};
ClipReplay replay_clip(const FrameSetup& s, const Recording& rec, std::uint32_t tri);

// The three vertices of a set-up piece in TriangleSetup order (vtx[0..2]):
// clip xyzw and the first kPbrVaryings varyings, or every varying the draw has.
void piece_vertices(const FrameSetup& s, const Recording& rec, std::uint32_t piece, float out[3][kStride]);
void piece_vertices_full(const FrameSetup& s, const Recording& rec, std::uint32_t piece, float out[3][kMaxStride]);

// Window position of a vertex, snapped to 1/256 pixel as setup_triangle() does.
struct SnappedVertex {
    double x_win = 0, y_win = 0;
    std::int64_t fx = 0, fy = 0;        // 1/256-pixel units
    float z = 0, inv_w = 0;
};
SnappedVertex snap_vertex(const float* clip, int width, int height);

// The fragment block of a recorded block as the shader received it (filled
// by the rasterizer's own interpolate_block()), and for display where each
// lane was interpolated: at its pixel centre, or with several samples, for a
// shaded lane whose centre is outside the triangle, at the centroid of its
// covered samples.
struct ReplayedBlock {
    int varyings = kPbrVaryings;        // the draw's program: kPbrVaryings, kPbrVaryingsExt or UnlitProgram's
    bool has_color = false;             // the wide layout with the mesh's vertex colours
    bool line = false;                  // a line or point fragment (zero derivatives)
    FragmentBlock<kPbrVaryings> in;     // the first kPbrVaryings varyings (PBR programs)
    FragmentBlock<kPbrVaryingsExt> ext; // all of them when varyings == kPbrVaryingsExt
    FragmentBlock<UnlitProgram::kVaryings> unlit;  // when varyings == UnlitProgram::kVaryings
    float bary[3][kBlockLanes];         // screen-space barycentrics at that point
    float persp[3][kBlockLanes];        // perspective-correct weights (w0 = q0 / sum, shown only)
    float at_x[kBlockLanes], at_y[kBlockLanes];  // the point, in pixels from the pixel centre
    std::uint8_t centroid_of[kBlockLanes];       // bit s: sample s in the centroid; 0: the centre
};
void replay_block(const FrameSetup& s, const Recording& rec, const BlockRecord& b, ReplayedBlock& out);

// The block of the draw's program type (NV its varyings) in a replayed block.
template <int NV>
const FragmentBlock<NV>& program_block(const ReplayedBlock& rb) {
    if constexpr (NV == kPbrVaryingsExt) return rb.ext;
    else if constexpr (NV == UnlitProgram::kVaryings) return rb.unlit;
    else return rb.in;
}

// One line or point of a draw, set up again as bin_lines() sets it up.
struct LineReplay {
    bool valid = false;                 // indices in range, finite positions
    bool drawn = false;                 // survived clipping and set-up (line.h)
    bool point = false;
    std::uint32_t index[2] = {0, 0};    // vertex indices in the mesh (a point: both the same)
    std::uint32_t planes = 0;           // planes clipped against (kClipNeededBits); 0: not clipped
    float v[2][kMaxStride] = {};        // the segment's ends after clipping (the draw's stride)
    LineSetup setup;
};
LineReplay replay_line(const FrameSetup& s, const Recording& rec, std::size_t draw, std::uint32_t prim);

// A line or point fragment at pixel (x, y), which it covers, as line_raster.h's
// line_block() hands it to the program: depth and varyings at the projection
// t of the centre onto the segment (w1 the perspective weight of the end),
// every lane of the pixel's quad holding them (zero derivatives), the
// pixel's lane live. The block's x, y are the 4x4 block's.
struct LineFragment {
    float t = 0.0f, w1 = 0.0f, z = 0.0f;
    ReplayedBlock block;
};
void replay_line_fragment(const FrameSetup& s, const Recording& rec, std::size_t draw, const LineReplay& l, int x,
                          int y, LineFragment& out);

// One lane's shading, step by step, as shade_surface() computes it.
struct LightStep {
    glm::vec3 l{0.0f}, h{0.0f}, radiance{0.0f};  // radiance after the shadow's visibility
    bool shadowed = false;              // the light has a shadow map: `shadow` holds its lookup
    ShadowProbe shadow;
    BrdfTerms terms;
    glm::vec3 contribution{0.0f};       // f * radiance * n.l
};
struct LaneShading {
    bool unlit = false;                 // UnlitProgram: Lo = base colour factor x texture x vertex colour
    glm::vec4 unlit_texture{1.0f};      // its texture's sample (finest level), 1 without one
    glm::vec4 unlit_color{1.0f};        // its interpolated vertex colour
    SurfacePoint sp;
    MaterialLods lods;
    MaterialSample ms;
    bool killed = false;                // alpha MASK discarded it
    BrdfInputs inputs;
    std::vector<LightStep> lights;
    glm::vec3 ambient{0.0f};            // ambient * albedo * occlusion, or the environment's split sum
    bool ibl = false;                   // lit by an environment: ambient = ibl_terms.diffuse + .specular
    IblTerms ibl_terms;
    glm::vec3 Lo{0.0f};                 // the colour the shader wrote
    bool matches_shade_surface = true;  // Lo == shade_surface(): always, or the stepper is wrong
};
LaneShading shade_lane(const ShadingContext& ctx, const BoundMaterial& bm, const ReplayedBlock& rb, int lane);

// The surface point a lane's PBR program builds (either layout).
SurfacePoint replay_surface_point(const ReplayedBlock& rb, int lane);

// The material a triangle's draw uses, or a draw's.
const BoundMaterial& material_of(const FrameSetup& s, const Recording& rec, std::uint32_t tri);
const BoundMaterial& draw_material(const FrameSetup& s, const DrawRecord& d);

} // namespace prast::stepper

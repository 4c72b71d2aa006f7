// Fixed-function state of one draw call.
#pragma once

namespace prast {

enum class CullMode { Back, None };   // None = double-sided

// How a fragment's colour meets the target's, per sample, in linear radiance:
// Replace: dst = src. Add: dst += src (counting, glow). Alpha: dst = src * a +
// dst * (1 - a), every channel alike (alpha too), as glBlendFunc(SRC_ALPHA,
// ONE_MINUS_SRC_ALPHA) does (transparency; usually with depth_write off).
enum class Blend { Replace, Add, Alpha };

// What a draw's indices list: triangles (3 each), line segments (2 each) or
// points (1 each). Lines and points are 1 pixel wide; their rules (the
// diamond-exit rule, the pixel a point lies in, every sample of a covered
// pixel) are in raster/line.h. `cull` does not apply to them.
enum class Topology : unsigned char { Triangles, Lines, Points };

struct DrawState {
    CullMode cull = CullMode::Back;
    Blend blend = Blend::Replace;
    bool depth_test = true;   // LESS against the buffer
    bool depth_write = true;
    // The fragment program may set FragmentOut::kill (alpha MASK). Such draws
    // are shaded in submission order, like blending draws and draws without
    // depth test or write; every other draw gets the visibility pass (each
    // sample's winner shaded once, see docs/pipeline.md). A program that
    // kills without this flag set breaks that contract: its kills are honoured
    // only as "colour not written" after the depth was already written.
    bool may_discard = false;
    Topology topology = Topology::Triangles;
};

} // namespace prast

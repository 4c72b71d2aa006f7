// Fixed-function state of one draw call.
#pragma once

namespace prast {

enum class CullMode { Back, None };   // None = double-sided

// How a fragment's colour meets the target's, per sample, in linear radiance:
// Replace: dst = src. Add: dst += src (counting, glow). Alpha: dst = src * a +
// dst * (1 - a), every channel alike (alpha too), as glBlendFunc(SRC_ALPHA,
// ONE_MINUS_SRC_ALPHA) does (transparency; usually with depth_write off).
enum class Blend { Replace, Add, Alpha };

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
};

} // namespace prast

// Fixed-function state of one draw call.
#pragma once

namespace prast {

enum class CullMode { Back, None };   // None = double-sided
enum class Blend { Replace, Add };    // Add: colour += shader output (counting, glow)

struct DrawState {
    CullMode cull = CullMode::Back;
    Blend blend = Blend::Replace;
    bool depth_test = true;   // LESS against the buffer
    bool depth_write = true;
};

} // namespace prast

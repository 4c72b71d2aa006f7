// write_avx512.h's colour write, the one function an x86-64-v3 build compiles
// with AVX-512 here (raster/CMakeLists.txt) and calls where the CPU has it.
// Everything else it uses is inlined (the `isa` test lists its symbols).
#include "raster/write_avx512.h"

#if !defined(__AVX512F__) || !defined(__AVX512VL__)
#error "write_avx512.cpp needs AVX-512 F and VL (see raster/CMakeLists.txt)"
#endif

namespace prast::raster_detail {

void write_planes_avx512(float* color, std::size_t row, std::size_t plane, const std::uint32_t* masks, int samples,
                         const FragmentOut& out) {
    switch (samples) {  // the loops over samples unrolled
    case 1: write_planes_avx512_inline<1>(color, row, plane, masks, 1, out); break;
    case 2: write_planes_avx512_inline<2>(color, row, plane, masks, 2, out); break;
    case 4: write_planes_avx512_inline<4>(color, row, plane, masks, 4, out); break;
    case 8: write_planes_avx512_inline<8>(color, row, plane, masks, 8, out); break;
    default: write_planes_avx512_inline<0>(color, row, plane, masks, samples, out); break;
    }
}

} // namespace prast::raster_detail

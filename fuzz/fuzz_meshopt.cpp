// libFuzzer harness: the EXT_meshopt_compression decoder alone
// (scene/meshopt_decode.cpp), thousands of times faster than through a glTF
// file, and, where libmeshoptimizer is installed, against the reference
// decoder: a stream one decoder accepts and the other refuses, or that
// decodes to different bytes, is a finding too (the filters, specified to
// one unit in the last place, are run but not compared).
//
// The input: byte 0 the mode (bits 0-1: 0 ATTRIBUTES, 1 TRIANGLES, 2
// INDICES, 3 ATTRIBUTES) and the filter (bits 2-3: NONE, OCTAHEDRAL,
// QUATERNION, EXPONENTIAL, where the stride allows it), byte 1 the stride
// (ATTRIBUTES: 4 (1 + b % 64); else 2 or 4 by its low bit), bytes 2-3 the
// element count (little-endian; TRIANGLES: rounded down to a multiple of
// 3), then the stream. fuzz_make_seeds writes seeds of this layout.
#include <cstdint>
#include <cstring>
#include <vector>

#include "scene/meshopt_decode.h"

#if defined(PRAST_HAVE_MESHOPT_DECODER)
#include <meshoptimizer.h>
#endif

namespace meshopt = prast::meshopt;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    if (size < 4) return 0;
    const unsigned m = data[0] & 3, f = (data[0] >> 2) & 3;
    const meshopt::Mode mode = m == 1 ? meshopt::Mode::Triangles : m == 2 ? meshopt::Mode::Indices : meshopt::Mode::Attributes;
    const bool attributes = mode == meshopt::Mode::Attributes;
    const std::size_t stride = attributes ? 4 * (1 + std::size_t(data[1] % 64)) : (data[1] & 1) ? 4 : 2;
    std::size_t count = std::size_t(data[2]) | std::size_t(data[3]) << 8;
    if (mode == meshopt::Mode::Triangles) count -= count % 3;
    // The loader's rules for filters (scene/load_gltf.cpp decode_meshopt_view).
    meshopt::Filter filter = meshopt::Filter::None;
    if (attributes) {
        if (f == 1 && (stride == 4 || stride == 8)) filter = meshopt::Filter::Octahedral;
        if (f == 2 && stride == 8) filter = meshopt::Filter::Quaternion;
        if (f == 3) filter = meshopt::Filter::Exponential;
    }
    const std::uint8_t* src = data + 4;
    const std::size_t n = size - 4;
    // As the loader does: a stream shorter than its least size is refused
    // before the output is allocated.
    const bool long_enough = n >= meshopt::min_encoded_size(mode, count, stride);
    std::vector<unsigned char> ours(count * stride, 0xcd);
    const bool ok = long_enough && meshopt::decode(mode, filter, src, n, count, stride, ours.data()).empty();
#if defined(PRAST_HAVE_MESHOPT_DECODER)
    // The reference, unfiltered; its version-0 index and triangle streams
    // (0xd0, 0xe0) are outside the extension, which names 0xd1 and 0xe1.
    if (filter == meshopt::Filter::None && (attributes || (n > 0 && (src[0] == 0xd1 || src[0] == 0xe1)))) {
        std::vector<unsigned char> ref(count * stride, 0xcd);
        int rc = -1;
        if (attributes) rc = meshopt_decodeVertexBuffer(ref.data(), count, stride, src, n);
        else if (mode == meshopt::Mode::Triangles) rc = meshopt_decodeIndexBuffer(ref.data(), count, stride, src, n);
        else rc = meshopt_decodeIndexSequence(ref.data(), count, stride, src, n);
        if ((rc == 0) != ok) __builtin_trap();                 // one accepts what the other refuses
        if (ok && ref != ours) __builtin_trap();               // or they disagree on the bytes
    }
#endif
    return 0;
}

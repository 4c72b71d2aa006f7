// Decoder of the EXT_meshopt_compression bitstream (also KHR_meshopt_compression's
// version-0 streams, which are the same): written from the extension's
// specification (Appendix A, bitstream; Appendix B, filters). Debian ships the
// reference library only as a shared object, and render links statically.
#pragma once

#include <cstddef>
#include <string>

namespace prast::meshopt {

enum class Mode { Attributes, Triangles, Indices };
enum class Filter { None, Octahedral, Quaternion, Exponential };

// The fewest encoded bytes that can hold `count` elements of `stride` bytes in
// `mode` (headers, one code per triangle, one byte per index, the tails): a
// stream shorter than this is refused before the output is allocated, which
// bounds the output by a fixed multiple of the input (64 for attributes).
std::size_t min_encoded_size(Mode mode, std::size_t count, std::size_t stride);

// Decodes `count` elements of `stride` bytes from src[0, size) into out
// (count * stride bytes), then applies `filter` in place. Returns "" or why
// the stream is not a valid one of its mode: a bad header byte, a read past
// the stream, bytes left over. The caller has checked the extension's rules
// (stride per mode and filter, count % 3 for triangles).
std::string decode(Mode mode, Filter filter, const unsigned char* src, std::size_t size, std::size_t count,
                   std::size_t stride, unsigned char* out);

} // namespace prast::meshopt

// A guard for JPEG data before stb_image reads it. Debian 12's stb_image 2.27
// builds a Huffman table from the 16 code counts of a DHT segment without
// checking that they add up to at most 256: a crafted file writes past the
// table's 257-byte size array and 256-byte value array into the decoder's
// other fields (stb issue #1289, fixed upstream in 2.28; the heap
// use-after-free reported against stbi__jpeg_huff_decode comes from it), and
// stbi_info() already does so while looking for the frame header. So every
// DHT segment is checked here first; found by our libFuzzer harness
// (tests/fuzz-regressions/jpeg/).
#pragma once

#include <cstddef>
#include <string>

namespace prast {

// True when stb_image takes the bytes for a JPEG: 0xFF, any fill 0xFFs, 0xD8.
bool looks_like_jpeg(const unsigned char* data, std::size_t size);

// "" when no DHT segment that stb_image 2.27 could reach declares more than
// 256 codes; otherwise the reason. The segments are walked as stb walks them
// (by their lengths; junk skipped up to the next 0xFF; after a scan, the
// entropy-coded bytes skipped up to a marker other than a stuffed 0xFF00 or a
// restart marker; the walk ends at EOI or at a marker stb refuses), and where
// stb's own position depends on its Huffman decoding, every place it could
// stop is covered: stb either reaches the same marker or fails first.
std::string check_jpeg_data(const unsigned char* data, std::size_t size);

} // namespace prast

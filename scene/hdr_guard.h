// A guard for Radiance .hdr data before stb_image decodes it. Debian 12 ships
// stb_image 2.27, whose run-length decoder never advances on a run of length
// 0 and, at the end of truncated data, reads 0 forever: a 60-byte file spins
// the CPU for good (CVE-2021-42715, fixed upstream in 2.28). It also decodes
// a flat scanline after run-length ones from the wrong place and fills
// truncated flat data with uninitialised bytes. So every scanline is walked
// here first, with stb's own reading of the header, and anything stb would
// not decode correctly and in bounded time is refused. Used for textures and
// environment maps alike (scene/image.cpp decodes both).
#pragma once

#include <cstddef>
#include <string>

namespace prast {

// True when the bytes start like a Radiance file ("#?RADIANCE\n" or "#?RGBE\n").
bool looks_like_hdr(const unsigned char* data, std::size_t size);

// "" when stb_image 2.27 decodes these Radiance bytes completely and in time;
// otherwise the reason, e.g. "run of length 0 in scanline 3 (stb_image 2.27
// would loop forever, CVE-2021-42715)". `width`/`height` receive the size the
// header gives (0 when it has none).
std::string check_hdr_data(const unsigned char* data, std::size_t size, int& width, int& height);

} // namespace prast

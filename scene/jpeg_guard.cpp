// The DHT check; see jpeg_guard.h. Markers and tables are read the way
// stb_image 2.27 reads them (stbi__get_marker, stbi__process_marker,
// stbi__decode_jpeg_image; bytes past the end read as 0).
#include "scene/jpeg_guard.h"

namespace prast {

namespace {

// The markers stb reads a length-prefixed segment for: SOF0-2, DHT, SOS,
// DQT, DNL, DRI, APP0-15, COM. Any other marker makes stb fail.
bool has_length(int m) {
    return m == 0xC0 || m == 0xC1 || m == 0xC2 || m == 0xC4 || m == 0xDA || m == 0xDB || m == 0xDC || m == 0xDD ||
           (m >= 0xE0 && m <= 0xEF) || m == 0xFE;
}

} // namespace

bool looks_like_jpeg(const unsigned char* data, std::size_t size) {
    std::size_t i = 0;
    if (size == 0 || data[0] != 0xFF) return false;
    while (i < size && data[i] == 0xFF) ++i;
    return i < size && data[i] == 0xD8;
}

std::string check_jpeg_data(const unsigned char* data, std::size_t size) {
    if (!looks_like_jpeg(data, size)) return "";
    const auto byte = [&](std::size_t i) -> int { return i < size ? data[i] : 0; };
    std::size_t pos = 0;
    while (pos < size && data[pos] == 0xFF) ++pos;
    ++pos;  // past SOI
    for (;;) {
        // The next marker: junk up to an 0xFF, fill 0xFFs, then the code.
        while (pos < size && data[pos] != 0xFF) ++pos;
        while (pos < size && data[pos] == 0xFF) ++pos;
        if (pos >= size) return "";
        const int m = data[pos++];
        if (m == 0xD9 || !has_length(m)) return "";  // end of image, or stb fails here
        const long length = long(byte(pos) << 8 | byte(pos + 1));
        if (length < 2) return "";  // stb fails
        const std::size_t end = pos + std::size_t(length);
        if (m == 0xC4) {
            // Tables: a byte with class and id, 16 code counts, the values.
            long left = length - 2;
            std::size_t t = pos + 2;
            while (left > 0 && t < size) {
                const int q = byte(t);
                if ((q >> 4) > 1 || (q & 15) > 3) return "";  // stb refuses it itself
                long codes = 0;
                for (int i = 0; i < 16; ++i) codes += byte(t + 1 + std::size_t(i));
                if (codes > 256)
                    return "Huffman table with " + std::to_string(codes) +
                           " codes, more than 256 (stb_image 2.27 would write past its tables)";
                t += 17 + std::size_t(codes);
                left -= 17 + codes;
            }
        }
        pos = end;
        if (m == 0xDA) {
            // Entropy-coded data: up to a marker that is neither a stuffed
            // 0xFF00 nor a restart marker (stb stops there or fails earlier).
            while (pos + 1 < size) {
                if (data[pos] == 0xFF && data[pos + 1] != 0x00 && !(data[pos + 1] >= 0xD0 && data[pos + 1] <= 0xD7))
                    break;
                ++pos;
            }
        }
    }
}

} // namespace prast

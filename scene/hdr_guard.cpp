// The Radiance scanline walk; see hdr_guard.h. The header is read the way
// stb_image 2.27's stbi__hdr_load reads it (tokens up to '\n', at most 1023
// characters, strtol for the sizes), so both agree on the layout.
#include "scene/hdr_guard.h"

#include <cstdlib>
#include <cstring>
#include <string>

namespace prast {

namespace {

// stb's largest side (STBI_MAX_DIMENSIONS in third_party_impl/stb_impl.cpp).
constexpr long kMaxSide = 1 << 15;

// One header token as stbi__hdr_gettoken returns it.
struct TokenReader {
    const unsigned char* p;
    std::size_t n, pos = 0;

    std::string next() {
        std::string token;
        while (pos < n) {
            const char c = char(p[pos++]);
            if (c == '\n') break;
            token += c;
            if (token.size() == 1023) {  // stb flushes the rest of the line
                while (pos < n && p[pos++] != '\n') {}
                break;
            }
        }
        // stb stops a token at a NUL when it compares or parses it.
        return std::string(token.c_str());
    }
};

bool starts(const unsigned char* data, std::size_t size, const char* sig) {
    const std::size_t len = std::strlen(sig);
    return size >= len && std::memcmp(data, sig, len) == 0;
}

} // namespace

bool looks_like_hdr(const unsigned char* data, std::size_t size) {
    return starts(data, size, "#?RADIANCE\n") || starts(data, size, "#?RGBE\n");
}

std::string check_hdr_data(const unsigned char* data, std::size_t size, int& width, int& height) {
    width = height = 0;
    TokenReader in{data, size};
    const std::string magic = in.next();
    if (magic != "#?RADIANCE" && magic != "#?RGBE") return "not a Radiance file";

    // Header lines up to an empty one; the format must be RGBE.
    bool rgbe = false;
    for (;;) {
        if (in.pos >= size) return "truncated header";
        const std::string token = in.next();
        if (token.empty()) break;
        if (token == "FORMAT=32-bit_rle_rgbe") rgbe = true;
    }
    if (!rgbe) return "unsupported format (no FORMAT=32-bit_rle_rgbe)";

    // "-Y H +X W", parsed as stb does.
    const std::string res = in.next();
    if (res.compare(0, 3, "-Y ") != 0) return "unsupported data layout (expected -Y H +X W)";
    const char* s = res.c_str() + 3;
    char* end = nullptr;
    const long h = std::strtol(s, &end, 10);
    s = end;
    while (*s == ' ') ++s;
    if (std::strncmp(s, "+X ", 3) != 0) return "unsupported data layout (expected -Y H +X W)";
    const long w = std::strtol(s + 3, nullptr, 10);
    if (w < 1 || h < 1 || w > kMaxSide || h > kMaxSide)
        return "bad size " + std::to_string(w) + "x" + std::to_string(h) + " (each side 1 to " +
               std::to_string(kMaxSide) + ")";
    width = int(w);
    height = int(h);

    const unsigned char* p = data + in.pos;
    const std::size_t left = size - in.pos;
    const std::size_t flat_bytes = std::size_t(w) * std::size_t(h) * 4;
    const std::string truncated = "truncated pixel data";
    // Flat (uncompressed) RGBE: stb reads w*h*4 bytes and would make up the
    // missing ones.
    if (w < 8 || w >= kMaxSide) return left >= flat_bytes ? "" : truncated;

    std::size_t pos = 0;
    for (long y = 0; y < h; ++y) {
        if (left - pos < 4) return truncated + " (scanline " + std::to_string(y) + ")";
        const unsigned char c1 = p[pos], c2 = p[pos + 1], hi = p[pos + 2], lo = p[pos + 3];
        if (c1 != 2 || c2 != 2 || (hi & 0x80)) {
            // Not run-length encoded: stb reads the whole image flat from here,
            // which is only right for the first scanline.
            if (y != 0) return "scanline " + std::to_string(y) + " is flat after run-length ones";
            return left >= flat_bytes ? "" : truncated;
        }
        if ((long(hi) << 8 | long(lo)) != w)
            return "scanline " + std::to_string(y) + " has length " + std::to_string(long(hi) << 8 | long(lo)) +
                   ", not the width " + std::to_string(w);
        pos += 4;
        for (int channel = 0; channel < 4; ++channel) {
            long x = 0;
            while (x < w) {
                if (pos >= left) return truncated + " (scanline " + std::to_string(y) + ")";
                long count = p[pos++];
                if (count > 128) {
                    count -= 128;
                    if (pos >= left) return truncated + " (scanline " + std::to_string(y) + ")";
                    ++pos;  // the repeated value
                } else {
                    if (count == 0)
                        return "run of length 0 in scanline " + std::to_string(y) +
                               " (stb_image 2.27 would loop forever, CVE-2021-42715)";
                    if (left - pos < std::size_t(count)) return truncated + " (scanline " + std::to_string(y) + ")";
                    pos += std::size_t(count);
                }
                if (count > w - x) return "run past the end of scanline " + std::to_string(y);
                x += count;
            }
        }
    }
    return "";
}

} // namespace prast

// PNG files made byte by byte, for the PNG fuzzer's seeds (fuzz/make_seeds.cpp)
// and the hostile PNG tests (tests/test_hostile.cpp): chunks with their CRCs,
// pixel rows (Adam7 interlaced or not) in stored, uncompressed deflate
// blocks, so every field can be set, right or wrong, on purpose.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace prast::png_craft {

inline const std::string kSignature = "\x89PNG\r\n\x1a\n";

inline std::uint32_t crc32(const std::string& bytes) {
    std::uint32_t c = 0xFFFFFFFFu;
    for (unsigned char b : bytes) {
        c ^= b;
        for (int k = 0; k < 8; ++k) c = (c >> 1) ^ (0xEDB88320u & (0u - (c & 1u)));
    }
    return c ^ 0xFFFFFFFFu;
}

inline std::string be32(std::uint32_t v) { return {char(v >> 24), char(v >> 16), char(v >> 8), char(v)}; }

inline std::string chunk(const std::string& type, const std::string& data) {
    return be32(std::uint32_t(data.size())) + type + data + be32(crc32(type + data));
}

inline std::string ihdr(std::uint32_t w, std::uint32_t h, int depth, int colour, int interlace = 0) {
    return chunk("IHDR", be32(w) + be32(h) + char(depth) + char(colour) + '\0' + '\0' + char(interlace));
}

// A zlib stream (RFC 1950) of stored deflate blocks holding `raw`.
inline std::string zlib_stored(const std::string& raw) {
    std::string z = "\x78\x01";
    std::size_t at = 0;
    do {
        const std::size_t n = std::min<std::size_t>(raw.size() - at, 65535);
        z += char(at + n == raw.size() ? 1 : 0);
        z += char(n & 0xFF);
        z += char(n >> 8);
        z += char(~n & 0xFF);
        z += char((~n >> 8) & 0xFF);
        z += raw.substr(at, n);
        at += n;
    } while (at < raw.size());
    std::uint32_t a = 1, b = 0;
    for (unsigned char c : raw) {
        a = (a + c) % 65521;
        b = (b + a) % 65521;
    }
    return z + be32(b << 16 | a);
}

// The filtered rows (filter type 0) of a w x h image of `bits`-bit pixels,
// pixel (x, y) being the low `bits` bits of sample(x, y), Adam7 interlaced
// (ISO 15948 8.2) or not.
inline std::string rows(int w, int h, int bits, bool interlaced, const std::function<std::uint64_t(int, int)>& sample) {
    struct Pass {
        int x0, y0, dx, dy;
    };
    const std::vector<Pass> passes = interlaced ? std::vector<Pass>{{0, 0, 8, 8}, {4, 0, 8, 8}, {0, 4, 4, 8},
                                                                    {2, 0, 4, 4}, {0, 2, 2, 4}, {1, 0, 2, 2},
                                                                    {0, 1, 1, 2}}
                                                : std::vector<Pass>{{0, 0, 1, 1}};
    std::string raw;
    for (const Pass& p : passes) {
        if (p.x0 >= w || p.y0 >= h) continue;  // an empty pass has no rows
        for (int y = p.y0; y < h; y += p.dy) {
            raw += '\0';
            std::string row;
            int used = 0;  // bits filled in the last byte of `row`
            for (int x = p.x0; x < w; x += p.dx) {
                const std::uint64_t v = sample(x, y);
                for (int k = bits - 1; k >= 0; --k) {
                    if (used == 0) row += '\0';
                    row.back() = char(row.back() | (((v >> k) & 1u) << (7 - used)));
                    used = (used + 1) % 8;
                }
            }
            raw += row;
        }
    }
    return raw;
}

// A whole file: signature, IHDR, `extra` chunks (PLTE, tRNS, ...), one IDAT, IEND.
inline std::string file(int w, int h, int depth, int colour, int interlace, int bits,
                        const std::function<std::uint64_t(int, int)>& sample, const std::string& extra = "") {
    return kSignature + ihdr(std::uint32_t(w), std::uint32_t(h), depth, colour, interlace) + extra +
           chunk("IDAT", zlib_stored(rows(w, h, bits, interlace == 1, sample))) + chunk("IEND", "");
}

} // namespace prast::png_craft

// EXT_meshopt_compression decoding, from the extension's specification: the
// attribute codec (byte deltas per 16-element group, zigzag coded in 0, 2, 4
// or 8 bits with sentinels), the triangle codec (edge and vertex FIFOs), the
// index codec (two baselines), and the octahedral, quaternion and exponential
// filters in float32 as the specification writes them (their results are
// specified to one unit in the last place; ours are exactly these formulas,
// evaluated without FMA, so they do not vary by compiler or CPU).
#include "scene/meshopt_decode.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>

namespace prast::meshopt {

namespace {

constexpr unsigned char kAttributeHeader = 0xa0, kTriangleHeader = 0xe1, kIndexHeader = 0xd1;
constexpr std::size_t kAttributeTail = 32;  // the baseline element, padded to at least this
constexpr std::size_t kTriangleTail = 16;   // codeaux
constexpr std::size_t kIndexTail = 4;

std::string hex_byte(unsigned v) {
    static const char* digits = "0123456789abcdef";
    return std::string("0x") + digits[(v >> 4) & 15] + digits[v & 15];
}

std::size_t max_block_elements(std::size_t stride) {
    return std::min<std::size_t>((8192 / stride) & ~std::size_t(15), 256);
}

// Header bytes of one data block of n elements: 2 bits per group of 16.
std::size_t header_bytes(std::size_t n) { return ((n + 15) / 16 + 3) / 4; }

unsigned char unzigzag8(unsigned char v) { return (v & 1) ? static_cast<unsigned char>(~(v >> 1)) : (v >> 1); }

std::string decode_attributes(const unsigned char* src, std::size_t size, std::size_t count, std::size_t stride,
                              unsigned char* out) {
    if (size < 1) return "empty stream";
    if (src[0] != kAttributeHeader) {
        if ((src[0] & 0xf0) == 0xa0)
            return "attribute stream version " + std::to_string(src[0] & 15) + " is not supported (only 0)";
        return "bad header byte " + hex_byte(src[0]) + " (an attribute stream starts with 0xa0)";
    }
    const std::size_t tail = std::max(stride, kAttributeTail);
    if (size < 1 + tail) return "truncated stream (" + std::to_string(size) + " bytes, shorter than its tail)";
    const unsigned char* p = src + 1;
    const unsigned char* const end = src + size - tail;
    unsigned char last[256];
    std::memcpy(last, src + size - stride, stride);  // the baseline element ends the stream
    const std::size_t block = max_block_elements(stride);
    unsigned char deltas[256];
    const std::string truncated = "truncated stream (a group reads past its end)";
    for (std::size_t base = 0; base < count; base += block) {
        const std::size_t n = std::min(count - base, block), groups = (n + 15) / 16, hbytes = header_bytes(n);
        for (std::size_t k = 0; k < stride; ++k) {
            if (std::size_t(end - p) < hbytes) return truncated;
            const unsigned char* header = p;
            p += hbytes;
            for (std::size_t g = 0; g < groups; ++g) {
                const unsigned bits = (header[g / 4] >> ((g % 4) * 2)) & 3;
                unsigned char* d = deltas + g * 16;
                if (bits == 0) {
                    std::memset(d, 0, 16);
                } else if (bits == 3) {
                    if (end - p < 16) return truncated;
                    std::memcpy(d, p, 16);
                    p += 16;
                } else {
                    // 2 or 4 bits a delta, first delta in the high bits; the
                    // all-ones value says the delta is the next extra byte.
                    const unsigned width = bits == 1 ? 2 : 4, per_byte = 8 / width, sentinel = (1u << width) - 1;
                    const std::size_t packed = 16 / per_byte;
                    if (std::size_t(end - p) < packed) return truncated;
                    const unsigned char* extra = p + packed;
                    for (unsigned i = 0; i < 16; ++i) {
                        const unsigned shift = 8 - width * (i % per_byte + 1);
                        const unsigned v = (p[i / per_byte] >> shift) & sentinel;
                        if (v == sentinel) {
                            if (extra >= end) return truncated;
                            d[i] = *extra++;
                        } else {
                            d[i] = static_cast<unsigned char>(v);
                        }
                    }
                    p = extra;
                }
            }
            unsigned char v = last[k];
            for (std::size_t i = 0; i < n; ++i) {
                v = static_cast<unsigned char>(v + unzigzag8(deltas[i]));
                out[(base + i) * stride + k] = v;
            }
            last[k] = v;
        }
    }
    if (p != end) return std::to_string(end - p) + " bytes left over before the tail";
    return "";
}

void put_index(unsigned char* out, std::size_t stride, std::size_t i, std::uint32_t v) {
    unsigned char* o = out + i * stride;
    o[0] = static_cast<unsigned char>(v);
    o[1] = static_cast<unsigned char>(v >> 8);
    if (stride == 4) {
        o[2] = static_cast<unsigned char>(v >> 16);
        o[3] = static_cast<unsigned char>(v >> 24);
    }
}

// Unsigned LEB128 of at most 5 bytes (32 bits); false past `end`.
bool read_varint(const unsigned char*& p, const unsigned char* end, std::uint32_t& v) {
    v = 0;
    for (int i = 0; i < 5; ++i) {
        if (p >= end) return false;
        const unsigned char b = *p++;
        v |= std::uint32_t(b & 127) << (7 * i);
        if (!(b & 128)) break;
    }
    return true;
}

std::string decode_triangles(const unsigned char* src, std::size_t size, std::size_t count, std::size_t stride,
                             unsigned char* out) {
    const std::size_t triangles = count / 3;
    if (size < 1 + triangles + kTriangleTail)
        return "truncated stream (" + std::to_string(size) + " bytes for " + std::to_string(triangles) +
               " triangle codes and the tail)";
    if (src[0] != kTriangleHeader) return "bad header byte " + hex_byte(src[0]) + " (a triangle stream starts with 0xe1)";
    const unsigned char* codes = src + 1;
    const unsigned char* data = codes + triangles;
    const unsigned char* const data_end = src + size - kTriangleTail;
    const unsigned char* const codeaux = data_end;
    // The specification leaves the FIFOs' first contents undefined; they
    // start as the reference decoder's (every index ~0), so that a stream
    // reading them decodes to what every other decoder gives (indices the
    // loader then refuses as out of range) rather than to vertex 0.
    std::uint32_t edges[16][2], vertices[16];
    std::fill(&edges[0][0], &edges[0][0] + 32, ~std::uint32_t(0));
    std::fill(vertices, vertices + 16, ~std::uint32_t(0));
    unsigned edge_at = 0, vertex_at = 0;  // where the next push goes
    std::uint32_t next = 0, last = 0;
    const auto edge = [&](unsigned x, std::uint32_t& a, std::uint32_t& b) {
        const unsigned i = (edge_at - 1 - x) & 15;
        a = edges[i][0];
        b = edges[i][1];
    };
    const auto vertex = [&](unsigned y) { return vertices[(vertex_at - 1 - y) & 15]; };
    const auto push_edge = [&](std::uint32_t a, std::uint32_t b) {
        edges[edge_at][0] = a;
        edges[edge_at][1] = b;
        edge_at = (edge_at + 1) & 15;
    };
    const auto push_vertex = [&](std::uint32_t v) {
        vertices[vertex_at] = v;
        vertex_at = (vertex_at + 1) & 15;
    };
    bool ok = true;
    const auto index = [&]() {
        std::uint32_t v = 0;
        if (!read_varint(data, data_end, v)) ok = false;
        last += (v & 1) ? ~(v >> 1) : (v >> 1);  // a zigzag delta, in wrapping 32-bit arithmetic
        return last;
    };
    const std::string truncated = "truncated stream (a triangle reads past its data)";
    for (std::size_t t = 0; t < triangles; ++t) {
        const unsigned code = codes[t], hi = code >> 4, lo = code & 15;
        std::uint32_t a = 0, b = 0, c = 0;
        if (hi < 15) {
            edge(hi, a, b);
            if (lo == 0) {
                c = next++;
                push_vertex(c);
            } else if (lo < 13) {
                c = vertex(lo);
            } else if (lo < 15) {
                c = last = lo == 13 ? last - 1 : last + 1;
                push_vertex(c);
            } else {
                c = index();
                if (!ok) return truncated;
                push_vertex(c);
            }
            push_edge(c, b);
            push_edge(a, c);
        } else {
            unsigned z = 0, w = 0;
            bool explicit_z = false, explicit_w = false;
            if (lo < 14) {
                const unsigned aux = codeaux[lo];
                z = aux >> 4;
                w = aux & 15;
                a = next++;
                b = z == 0 ? next++ : vertex(z - 1);
                c = w == 0 ? next++ : vertex(w - 1);
            } else {
                if (data >= data_end) return truncated;
                const unsigned zw = *data++;
                if (zw == 0) next = 0;
                z = zw >> 4;
                w = zw & 15;
                explicit_z = z == 15;
                explicit_w = w == 15;
                a = lo == 14 ? next++ : index();
                b = z == 0 ? next++ : z < 15 ? vertex(z - 1) : index();
                c = w == 0 ? next++ : w < 15 ? vertex(w - 1) : index();
                if (!ok) return truncated;
            }
            push_edge(b, a);
            push_edge(c, b);
            push_edge(a, c);
            push_vertex(a);
            if (z == 0 || explicit_z) push_vertex(b);
            if (w == 0 || explicit_w) push_vertex(c);
        }
        put_index(out, stride, 3 * t, a);
        put_index(out, stride, 3 * t + 1, b);
        put_index(out, stride, 3 * t + 2, c);
    }
    if (data != data_end) return std::to_string(data_end - data) + " bytes of triangle data left over";
    return "";
}

std::string decode_indices(const unsigned char* src, std::size_t size, std::size_t count, std::size_t stride,
                           unsigned char* out) {
    if (size < 1 + count + kIndexTail)
        return "truncated stream (" + std::to_string(size) + " bytes for " + std::to_string(count) + " indices)";
    if (src[0] != kIndexHeader) return "bad header byte " + hex_byte(src[0]) + " (an index stream starts with 0xd1)";
    const unsigned char* p = src + 1;
    const unsigned char* const end = src + size - kIndexTail;
    std::uint32_t last[2] = {0, 0};
    for (std::size_t i = 0; i < count; ++i) {
        std::uint32_t v = 0;
        if (!read_varint(p, end, v)) return "truncated stream (an index reads past its end)";
        const unsigned baseline = v & 1;
        last[baseline] += (v & 2) ? ~(v >> 2) : (v >> 2);
        put_index(out, stride, i, last[baseline]);
    }
    if (p != end) return std::to_string(end - p) + " bytes of index data left over";
    return "";
}

// ---- Filters (Appendix B), in place

std::int32_t get_signed(const unsigned char* p, std::size_t bytes) {
    if (bytes == 1) return std::int8_t(p[0]);
    return std::int16_t(std::uint16_t(p[0] | p[1] << 8));
}

void put_signed(unsigned char* p, std::size_t bytes, std::int32_t v) {
    p[0] = static_cast<unsigned char>(v);
    if (bytes == 2) p[1] = static_cast<unsigned char>(v >> 8);
}

// round(v * max) into [-max, max]; 0 for a NaN (an invalid input, whose
// result the specification leaves open: defined here, never undefined behaviour).
std::int32_t snorm(float v, float max) {
    const float r = std::round(v * max);
    if (!(r == r)) return 0;
    return std::int32_t(std::clamp(r, -max, max));
}

void filter_octahedral(unsigned char* data, std::size_t count, std::size_t stride) {
    const std::size_t c = stride / 4;  // bytes a component: 1 or 2
    const float max = c == 1 ? 127.0f : 32767.0f;
    for (std::size_t i = 0; i < count; ++i) {
        unsigned char* e = data + i * stride;
        const float one = float(get_signed(e + 2 * c, c));
        float x = float(get_signed(e, c)) / one;
        float y = float(get_signed(e + c, c)) / one;
        const float z = 1.0f - std::fabs(x) - std::fabs(y);
        const float t = std::min(z, 0.0f);
        x -= std::copysign(t, x);
        y -= std::copysign(t, y);
        const float len = std::sqrt(x * x + y * y + z * z);
        put_signed(e, c, snorm(x / len, max));
        put_signed(e + c, c, snorm(y / len, max));
        put_signed(e + 2 * c, c, snorm(z / len, max));
    }
}

void filter_quaternion(unsigned char* data, std::size_t count) {
    const float range = 1.0f / std::sqrt(2.0f);
    for (std::size_t i = 0; i < count; ++i) {
        unsigned char* e = data + i * 8;
        const std::int32_t last = get_signed(e + 6, 2);
        const float one = float(last | 3);
        const float x = float(get_signed(e, 2)) / one * range;
        const float y = float(get_signed(e + 2, 2)) / one * range;
        const float z = float(get_signed(e + 4, 2)) / one * range;
        const float w = std::sqrt(std::max(0.0f, 1.0f - x * x - y * y - z * z));
        const unsigned maxcomp = unsigned(last) & 3;
        put_signed(e + 2 * ((maxcomp + 1) % 4), 2, snorm(x, 32767.0f));
        put_signed(e + 2 * ((maxcomp + 2) % 4), 2, snorm(y, 32767.0f));
        put_signed(e + 2 * ((maxcomp + 3) % 4), 2, snorm(z, 32767.0f));
        put_signed(e + 2 * ((maxcomp + 0) % 4), 2, snorm(w, 32767.0f));
    }
}

void filter_exponential(unsigned char* data, std::size_t values) {
    for (std::size_t i = 0; i < values; ++i) {
        unsigned char* e = data + i * 4;
        const std::uint32_t u = std::uint32_t(e[0]) | std::uint32_t(e[1]) << 8 | std::uint32_t(e[2]) << 16 |
                                std::uint32_t(e[3]) << 24;
        const std::int32_t exponent = std::int32_t(u) >> 24;
        const std::int32_t mantissa = std::int32_t(u << 8) >> 8;
        // 2^e * m is exact in float for the valid exponents [-100, 100].
        const float f = std::ldexp(float(mantissa), exponent);
        std::uint32_t bits = 0;
        std::memcpy(&bits, &f, 4);
        for (int b = 0; b < 4; ++b) e[b] = static_cast<unsigned char>(bits >> (8 * b));
    }
}

} // namespace

std::size_t min_encoded_size(Mode mode, std::size_t count, std::size_t stride) {
    switch (mode) {
    case Mode::Triangles: return 1 + count / 3 + kTriangleTail;
    case Mode::Indices: return 1 + count + kIndexTail;
    case Mode::Attributes: break;
    }
    if (stride == 0) return 1 + kAttributeTail;
    const std::size_t block = max_block_elements(stride);
    const std::size_t full = count / block, rest = count % block;
    return 1 + std::max(stride, kAttributeTail) +
           stride * (full * header_bytes(block) + (rest ? header_bytes(rest) : 0));
}

std::string decode(Mode mode, Filter filter, const unsigned char* src, std::size_t size, std::size_t count,
                   std::size_t stride, unsigned char* out) {
    std::string why;
    switch (mode) {
    case Mode::Attributes: why = decode_attributes(src, size, count, stride, out); break;
    case Mode::Triangles: why = decode_triangles(src, size, count, stride, out); break;
    case Mode::Indices: why = decode_indices(src, size, count, stride, out); break;
    }
    if (!why.empty()) return why;
    switch (filter) {
    case Filter::None: break;
    case Filter::Octahedral: filter_octahedral(out, count, stride); break;
    case Filter::Quaternion: filter_quaternion(out, count); break;
    case Filter::Exponential: filter_exponential(out, count * stride / 4); break;
    }
    return "";
}

} // namespace prast::meshopt

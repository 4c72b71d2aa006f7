// Filling memory that nothing reads again this frame (the pixels of a tile no
// draw reaches, and their 8-bit output) with non-temporal stores: they skip
// the read of each line before it is written and do not evict the caches.
// Such a fill is bound by memory bandwidth, which two threads share, so with
// plain stores it scaled from 1 to 2 threads by about 1.1x (bench --alternate,
// the bottle workload: 88% of its frame is untouched tiles). The bytes written
// are those of a plain fill.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstring>

#if defined(__AVX2__)
#include <immintrin.h>
#endif

namespace prast {

// A pattern of `size` bytes (size divides 32: 4 for a depth or an 8-bit
// pixel, 16 for a float RGBA pixel) repeated over 64 bytes, built once for
// many fills.
struct StreamPattern {
    alignas(32) unsigned char rep[64];
    std::size_t size;
    StreamPattern(const void* pattern, std::size_t bytes) : size(bytes) {
        for (std::size_t i = 0; i < sizeof rep; i += bytes) std::memcpy(rep + i, pattern, bytes);
    }
};

// The 4 pattern bytes at offset i from the fill's start (i a multiple of 4).
inline int pattern_word(const StreamPattern& p, std::size_t i) {
    int w;
    std::memcpy(&w, p.rep + i % p.size, sizeof w);
    return w;
}

// Writes `bytes` bytes at dst, the pattern repeated from dst on. Call
// stream_fence() before other threads read the memory.
inline void stream_fill(void* dst, std::size_t bytes, const StreamPattern& p) {
    if (bytes == 0) return;  // dst may then be null (memcpy's arguments may not)
    auto* out = static_cast<unsigned char*>(dst);
#if defined(__AVX2__)
    // Up to a 32-byte boundary, whole 32-byte stores, the rest: all streamed,
    // 4 bytes at a time at the ends. A plain store into a line that streamed
    // stores also write reads the line first and waits for it: with a 16-byte
    // head and tail per row such stores took a third of the bottle's tile pass.
    const std::uintptr_t at = reinterpret_cast<std::uintptr_t>(out);
    if ((at | bytes) & 3) {  // not in 4-byte units: plain stores
        for (std::size_t i = 0; i < bytes; i += 32)
            std::memcpy(out + i, p.rep, bytes - i < 32 ? bytes - i : 32);
        return;
    }
    std::size_t head = (32 - (at & 31)) & 31;
    if (head > bytes) head = bytes;
    std::size_t i = 0;
    for (; i < head; i += 4) _mm_stream_si32(reinterpret_cast<int*>(out + i), pattern_word(p, i));
    const __m256i v = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(p.rep + head % p.size));
    for (; i + 32 <= bytes; i += 32) _mm256_stream_si256(reinterpret_cast<__m256i*>(out + i), v);
    for (; i < bytes; i += 4) _mm_stream_si32(reinterpret_cast<int*>(out + i), pattern_word(p, i));
#else
    for (std::size_t i = 0; i < bytes; i += 32)
        std::memcpy(out + i, p.rep, bytes - i < 32 ? bytes - i : 32);
#endif
}

// Orders the non-temporal stores before any later store (the pool's hand-over).
inline void stream_fence() {
#if defined(__AVX2__)
    _mm_sfence();
#endif
}

} // namespace prast

// Memory for large buffers that are filled at once (file contents, decoded
// images, the 8-bit output image): on the virtual machines prast is measured
// on, the first touch of fresh memory costs about 1 ms per MiB in 4 KiB pages
// and 0.1-0.2 ms in 2 MiB ones (docs/performance.md). Internal, not installed.
#pragma once

#include <cstddef>
#include <cstdint>
#include <new>
#include <vector>

namespace prast {

// Uninitialised memory for `bytes` bytes (at least 1), to be freed with
// free_huge(): from 2 MiB up it is 2 MiB aligned, its size rounded up to
// whole 2 MiB, and advised as transparent huge pages (which the kernel then
// gives where it offers them on request). Throws std::bad_alloc.
void* allocate_huge(std::size_t bytes);
void free_huge(void* p) noexcept;

// Reserves n bytes for v (a vector whose type is public, so its allocator
// is the standard one) and advises the whole 2 MiB pages inside that
// reservation as transparent huge pages: a 2048x2048 RGB map's buffer is
// otherwise about 3,000 page faults, which cost more than inflating it.
void reserve_huge(std::vector<std::uint8_t>& v, std::size_t n);

// A std::allocator on allocate_huge(), for vectors of such buffers.
template <class T>
struct HugeAllocator {
    using value_type = T;
    HugeAllocator() = default;
    template <class U>
    HugeAllocator(const HugeAllocator<U>&) noexcept {}
    T* allocate(std::size_t n) {
        if (n > SIZE_MAX / sizeof(T)) throw std::bad_alloc();
        return static_cast<T*>(allocate_huge(n * sizeof(T)));
    }
    void deallocate(T* p, std::size_t) noexcept { free_huge(p); }
    template <class U>
    bool operator==(const HugeAllocator<U>&) const noexcept { return true; }
    template <class U>
    bool operator!=(const HugeAllocator<U>&) const noexcept { return false; }
};

using HugeBytes = std::vector<unsigned char, HugeAllocator<unsigned char>>;

} // namespace prast

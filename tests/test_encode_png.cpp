// The zlib PNG encoder (scene/encode_png.h): what it writes decodes, with
// stb_image, to exactly the pixels it was given, for every channel count,
// odd sizes, one-row and one-column images, bands of any height and any
// thread count; the bytes do not depend on the thread count.
#include <doctest/doctest.h>

#include <atomic>
#include <cstdint>
#include <functional>
#include <new>
#include <random>
#include <vector>

#include <stb_image.h>

#include "scene/encode_png.h"
#include "scene/write_image.h"

using namespace prast;

namespace {

std::vector<std::uint8_t> decode_exact(const std::vector<std::uint8_t>& png, int w, int h, int channels) {
    int dw = 0, dh = 0, dc = 0;
    stbi_uc* px = stbi_load_from_memory(png.data(), int(png.size()), &dw, &dh, &dc, 0);
    REQUIRE(px != nullptr);
    CHECK(dw == w);
    CHECK(dh == h);
    CHECK(dc == channels);
    std::vector<std::uint8_t> out(px, px + std::size_t(w) * std::size_t(h) * std::size_t(channels));
    stbi_image_free(px);
    return out;
}

// Smooth gradients, flat areas and noise: every Paeth branch gets taken.
std::vector<std::uint8_t> test_pixels(int w, int h, int channels, std::uint32_t seed) {
    std::mt19937 rng(seed);
    std::vector<std::uint8_t> p(std::size_t(w) * std::size_t(h) * std::size_t(channels));
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            for (int c = 0; c < channels; ++c) {
                const std::size_t i = (std::size_t(y) * std::size_t(w) + std::size_t(x)) * std::size_t(channels) +
                                      std::size_t(c);
                const int region = (x * 4 / w) + 4 * (y * 2 / h);
                p[i] = region % 3 == 0 ? std::uint8_t(x + 3 * y + 50 * c)
                       : region % 3 == 1 ? std::uint8_t(200)
                                         : std::uint8_t(rng());
            }
    return p;
}

} // namespace

TEST_SUITE("encode_png") {

TEST_CASE("encoded PNGs decode to exactly the input pixels") {
    const int sizes[][2] = {{1, 1}, {7, 5}, {1, 300}, {300, 1}, {129, 65}, {640, 360}};
    std::uint32_t seed = 1;
    for (const auto& s : sizes)
        for (int channels = 1; channels <= 4; ++channels) {
            INFO("size ", s[0], "x", s[1], " channels ", channels);
            const std::vector<std::uint8_t> px = test_pixels(s[0], s[1], channels, seed++);
            for (int level : {1, 2, 6, 9})
                for (int rows : {1, 3, 64, 1000}) {
                    PngOptions o = png_options_threads(1);
                    o.zlib_level = level;
                    o.band_rows = rows;
                    const std::vector<std::uint8_t> png = encode_png_pixels(px.data(), s[0], s[1], channels, o);
                    REQUIRE(decode_exact(png, s[0], s[1], channels) == px);
                    CHECK(png.capacity() == png.size());  // the file's size worked out exactly, one allocation
                }
        }
}

TEST_CASE("PNG bytes do not depend on the thread count") {
    const std::vector<std::uint8_t> px = test_pixels(333, 517, 3, 42);
    const std::vector<std::uint8_t> one = encode_png_pixels(px.data(), 333, 517, 3, png_options_threads(1));
    for (int threads : {2, 3, 8})
        CHECK(encode_png_pixels(px.data(), 333, 517, 3, png_options_threads(threads)) == one);
    CHECK(decode_exact(one, 333, 517, 3) == px);
    // It compresses: these pixels are a third noise.
    CHECK(one.size() < px.size());
}

TEST_CASE("a band that throws on a worker thread reaches the caller after every thread has joined") {
    // Out of memory inside a band: the exception must come out of
    // parallel_for, not terminate the process, and no band may run after it
    // returns (the bands' data is gone then).
    for (int threads : {2, 3, 8})
        for (int bad : {0, 5, 19}) {
            CAPTURE(threads);
            CAPTURE(bad);
            std::atomic<int> running{0}, after{0};
            std::atomic<bool> returned{false};
            const PngOptions o = png_options_threads(threads);
            REQUIRE(o.parallel_for);
            CHECK_THROWS_AS(o.parallel_for(20,
                                           [&](int b) {
                                               ++running;
                                               after += returned.load();
                                               if (b == bad) {
                                                   --running;
                                                   throw std::bad_alloc();
                                               }
                                               --running;
                                           }),
                            std::bad_alloc);
            returned = true;
            CHECK(running == 0);
            CHECK(after == 0);
        }
    // And through encode_png_pixels: no band's result is used.
    const std::vector<std::uint8_t> px = test_pixels(64, 64, 3, 3);
    PngOptions o = png_options_threads(2);
    const auto inner = o.parallel_for;
    o.parallel_for = [&](int count, const std::function<void(int)>& fn) {
        inner(count, [&](int b) {
            if (b == count / 2) throw std::bad_alloc();
            fn(b);
        });
    };
    o.band_rows = 4;
    CHECK_THROWS_AS(encode_png_pixels(px.data(), 64, 64, 3, o), std::bad_alloc);
}

TEST_CASE("write_image's encode_png drops alpha and keeps RGB exactly") {
    const int w = 97, h = 31;
    const std::vector<std::uint8_t> rgba = test_pixels(w, h, 4, 7);
    const std::vector<std::uint8_t> png = encode_png(w, h, rgba.data());
    const std::vector<std::uint8_t> rgb = decode_exact(png, w, h, 3);
    for (std::size_t i = 0; i < std::size_t(w) * h; ++i)
        for (int c = 0; c < 3; ++c) REQUIRE(rgb[i * 3 + std::size_t(c)] == rgba[i * 4 + std::size_t(c)]);
}

TEST_CASE("bad sizes are refused") {
    const std::uint8_t px[4] = {0, 0, 0, 0};
    CHECK_THROWS_AS(encode_png_pixels(px, 0, 1, 3), std::invalid_argument);
    CHECK_THROWS_AS(encode_png_pixels(px, 1, 1, 5), std::invalid_argument);
    CHECK_THROWS_AS(encode_png_pixels(px, 1, -1, 1), std::invalid_argument);
}

} // TEST_SUITE

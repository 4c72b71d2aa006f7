// 8-bit textures: level 0 samples exactly the floats of the decoded image,
// every stored mip texel is the correctly rounded byte of the exact
// area-weighted box filter of the level above (in linear space for sRGB
// channels), the memory a texture takes, packed roughness + metal maps, and
// mip chains independent of the thread count.
#include <doctest/doctest.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <random>
#include <vector>

#include "raster/thread_pool.h"
#include "scene/image.h"
#include "shading/texture.h"
#include "tests/shading_test_util.h"

using namespace prast;
using prast::test::bits;

namespace {

Image random_unorm8(std::mt19937& rng, int w, int h, int channels, bool srgb) {
    std::uniform_int_distribution<int> byte(0, 255);
    Image img;
    img.width = w;
    img.height = h;
    img.channels = channels;
    img.srgb = srgb;
    img.pixels.resize(img.texel_count() * std::size_t(channels));
    for (std::uint8_t& c : img.pixels) c = std::uint8_t(byte(rng));
    return img;
}

// The same image as linear float RGBA (what the float textures hold).
Image to_float(const Image& img) {
    Image f;
    f.width = img.width;
    f.height = img.height;
    f.rgba.resize(img.texel_count() * 4);
    for (int y = 0; y < img.height; ++y)
        for (int x = 0; x < img.width; ++x) f.set(x, y, img.at(x, y));
    return f;
}

// Overlap, in units of 1/m of a source texel, of source texel k with output
// texel i when n texels become m: output i covers [i n / m, (i + 1) n / m).
// The weight of source texel k is overlap / n.
long long overlap(int n, int m, int i, int k) {
    const long long lo = std::max<long long>(1LL * i * n, 1LL * k * m);
    const long long hi = std::min<long long>(1LL * (i + 1) * n, 1LL * (k + 1) * m);
    return hi > lo ? hi - lo : 0;
}

long double srgb_encode(long double x) {
    return x <= 0.0031308L ? 12.92L * x : 1.055L * std::pow(x, 1.0L / 2.4L) - 0.055L;
}

// Checks every texel of every level >= 1 of an 8-bit texture against the
// exact box filter of the stored level above; returns the number of texels
// that sit so close to a rounding tie (within 1e-6 of a byte step) that the
// long double reference itself cannot decide them.
int check_unorm8_chain(const Texture& tex, bool srgb) {
    const int C = tex.channels();
    const std::uint8_t* data = tex.unorm8_data();
    const float* srgb_table = srgb8_decode_table();
    int near_ties = 0;
    for (int l = 1; l < tex.levels(); ++l) {
        const int sw = tex.width(l - 1), sh = tex.height(l - 1), dw = tex.width(l), dh = tex.height(l);
        const std::uint8_t* src = data + tex.level_offset(l - 1) * std::size_t(C);
        const std::uint8_t* dst = data + tex.level_offset(l) * std::size_t(C);
        const long long denom = 1LL * sw * sh;  // weights are overlap_x * overlap_y / (sw * sh)
        for (int j = 0; j < dh; ++j)
            for (int i = 0; i < dw; ++i)
                for (int c = 0; c < C; ++c) {
                    const bool alpha = C == 2 ? c == 1 : (C == 4 && c == 3);
                    const bool decode = srgb && !alpha;
                    long long sum = 0;
                    long double lsum = 0.0L;
                    for (int y = 0; y < sh; ++y) {
                        const long long oy = overlap(sh, dh, j, y);
                        if (!oy) continue;
                        for (int x = 0; x < sw; ++x) {
                            const long long ox = overlap(sw, dw, i, x);
                            if (!ox) continue;
                            const int b = src[(std::size_t(y) * std::size_t(sw) + std::size_t(x)) * std::size_t(C) +
                                              std::size_t(c)];
                            sum += ox * oy * b;
                            lsum += (long double)(ox * oy) * (long double)srgb_table[b];
                        }
                    }
                    const int got = dst[(std::size_t(j) * std::size_t(dw) + std::size_t(i)) * std::size_t(C) +
                                        std::size_t(c)];
                    if (!decode) {
                        // Exact in integers: round(sum / denom), ties up.
                        const long long want = (2 * sum + denom) / (2 * denom);
                        INFO("level ", l, " texel ", i, ",", j, " channel ", c, " linear");
                        REQUIRE(got == want);
                        continue;
                    }
                    const long double e = 255.0L * srgb_encode(lsum / (long double)denom);
                    const long double want = std::floor(e + 0.5L);
                    if (got != int(want)) {
                        // Only a value within a hair of k + 0.5 may go either way.
                        INFO("level ", l, " texel ", i, ",", j, " channel ", c, " sRGB value ", double(e));
                        REQUIRE(std::fabs(double(e - std::floor(e) - 0.5L)) < 1e-6);
                        REQUIRE(std::abs(got - int(want)) == 1);
                        ++near_ties;
                    }
                }
    }
    return near_ties;
}

} // namespace

TEST_SUITE("texture") {

TEST_CASE("8-bit mips: each texel is the correctly rounded exact box filter of the level above") {
    std::mt19937 rng(8u);
    const int sizes[][2] = {{8, 8}, {5, 3}, {17, 1}, {1, 9}, {7, 7}, {64, 32}, {33, 20}, {3, 130}};
    int near_ties = 0, checked = 0;
    for (const auto& size : sizes)
        for (int channels = 1; channels <= 4; ++channels)
            for (bool srgb : {false, true}) {
                INFO("size ", size[0], "x", size[1], " channels ", channels, " srgb ", srgb);
                const Texture tex =
                    Texture::from_image(random_unorm8(rng, size[0], size[1], channels, srgb), Wrap::Repeat, Wrap::Repeat);
                REQUIRE(tex.is_unorm8());
                REQUIRE(tex.channels() == channels);
                near_ties += check_unorm8_chain(tex, srgb);
                ++checked;
            }
    // A smooth sRGB ramp has many texels near mid-grey steps: the same rule.
    Image ramp;
    ramp.width = 256;
    ramp.height = 2;
    ramp.channels = 1;
    ramp.srgb = true;
    for (int y = 0; y < 2; ++y)
        for (int x = 0; x < 256; ++x) ramp.pixels.push_back(std::uint8_t(x ^ (y * 3)));
    near_ties += check_unorm8_chain(Texture::from_image(ramp, Wrap::Repeat, Wrap::Repeat), true);
    MESSAGE((checked + 1) << " chains checked, " << near_ties << " texels within 1e-6 of a rounding tie");
    CHECK(near_ties <= 2);
}

TEST_CASE("8-bit level 0 samples exactly the floats of the decoded image") {
    std::mt19937 rng(80u);
    std::uniform_real_distribution<float> uni(-2.0f, 2.0f);
    for (int channels = 1; channels <= 4; ++channels)
        for (bool srgb : {false, true}) {
            const Image img = random_unorm8(rng, 19, 12, channels, srgb);
            const Texture t8 = Texture::from_image(img, Wrap::Repeat, Wrap::MirroredRepeat);
            const Texture tf = Texture::from_image(to_float(img), Wrap::Repeat, Wrap::MirroredRepeat);
            CHECK(!tf.is_unorm8());
            for (int y = 0; y < 12; ++y)
                for (int x = 0; x < 19; ++x) REQUIRE(t8.texel(0, x, y) == tf.texel(0, x, y));
            for (int k = 0; k < 2000; ++k) {
                const float u = uni(rng), v = uni(rng);
                const glm::vec4 a = t8.sample_bilinear(u, v, 0), b = tf.sample_bilinear(u, v, 0);
                for (int c = 0; c < 4; ++c) REQUIRE(bits(a[c]) == bits(b[c]));
                // Magnification (lambda <= 0) reads level 0 only: identical too.
                const glm::vec4 m = t8.sample_trilinear(u, v, -1.5f);
                for (int c = 0; c < 4; ++c) REQUIRE(bits(m[c]) == bits(b[c]));
            }
            // Grey replicates to r, g, b; no alpha channel reads 1.
            const glm::vec4 t = t8.texel(0, 3, 4);
            if (channels <= 2) CHECK((t.r == t.g && t.g == t.b));
            if (channels % 2 == 1) CHECK(t.a == 1.0f);
        }
}

TEST_CASE("8-bit storage: a texture takes its 8-bit size plus a third for the mips") {
    Image rgba;
    rgba.width = rgba.height = 2048;
    rgba.channels = 4;
    rgba.pixels.assign(rgba.texel_count() * 4, 128);
    const Texture tex = Texture::from_image(std::move(rgba), Wrap::Repeat, Wrap::Repeat);
    std::size_t texels = 0;
    for (int l = 0; l < tex.levels(); ++l) texels += std::size_t(tex.width(l)) * std::size_t(tex.height(l));
    CHECK(tex.memory_bytes() == texels * 4);
    const std::size_t level0 = std::size_t(2048) * 2048 * 4;
    CHECK(tex.memory_bytes() <= level0 + level0 / 3 + 1);  // 22,369,620 bytes (21.3 MiB); float RGBA took 89.5 MB
    MESSAGE("2048x2048 RGBA with mips: " << tex.memory_bytes() << " bytes");
    // The constant image stays constant at every level.
    CHECK(tex.texel(tex.levels() - 1, 0, 0) == tex.texel(0, 7, 9));

    Image grey;
    grey.width = grey.height = 1024;
    grey.channels = 1;
    grey.pixels.assign(grey.texel_count(), 7);
    const Texture g = Texture::from_image(std::move(grey), Wrap::Repeat, Wrap::Repeat);
    CHECK(g.memory_bytes() <= std::size_t(1024) * 1024 * 4 / 3 + 1);
}

TEST_CASE("roughness and metal maps packed into one texture sample as the two apart") {
    std::mt19937 rng(81u);
    std::uniform_real_distribution<float> uni(-2.0f, 2.0f), lam(-1.0f, 8.0f);
    const int sizes[][2] = {{13, 7}, {64, 64}, {1, 5}};
    for (const auto& size : sizes) {
        const Image rough = random_unorm8(rng, size[0], size[1], 1, false);
        const Image metal = random_unorm8(rng, size[0], size[1], 1, false);
        const Texture tr = Texture::from_image(rough, Wrap::Repeat, Wrap::ClampToEdge);
        const Texture tm = Texture::from_image(metal, Wrap::Repeat, Wrap::ClampToEdge);
        const Texture packed = Texture::pack_roughness_metal(rough, metal, Wrap::Repeat, Wrap::ClampToEdge);
        CHECK(packed.channels() == 2);
        CHECK(packed.memory_bytes() == tr.memory_bytes() + tm.memory_bytes());
        for (int k = 0; k < 3000; ++k) {
            const float u = uni(rng), v = uni(rng), lambda = k % 7 == 0 ? float(k % 5) : lam(rng);
            const glm::vec4 p = packed.sample_trilinear(u, v, lambda);
            REQUIRE(bits(p.g) == bits(tr.sample_trilinear(u, v, lambda).r));
            REQUIRE(bits(p.b) == bits(tm.sample_trilinear(u, v, lambda).r));
            REQUIRE(bits(p.r) == bits(p.g));
            REQUIRE(p.a == 1.0f);
        }
    }
    // What cannot be packed is refused.
    const Image a = random_unorm8(rng, 4, 4, 1, false), b = random_unorm8(rng, 4, 2, 1, false);
    CHECK_THROWS_AS(Texture::pack_roughness_metal(a, b), std::invalid_argument);
    CHECK_THROWS_AS(Texture::pack_roughness_metal(a, random_unorm8(rng, 4, 4, 1, true)), std::invalid_argument);
    CHECK_THROWS_AS(Texture::pack_roughness_metal(a, to_float(a)), std::invalid_argument);
}

TEST_CASE("mip chains are the same bytes on any thread count") {
    std::mt19937 rng(82u);
    ThreadPool one(1), three(3);
    for (int channels : {1, 3, 4}) {
        const Image img = random_unorm8(rng, 515, 387, channels, channels != 1);
        const Texture serial = Texture::from_image(img, Wrap::Repeat, Wrap::Repeat);
        const Texture a = Texture::from_image(img, Wrap::Repeat, Wrap::Repeat, &one);
        const Texture b = Texture::from_image(img, Wrap::Repeat, Wrap::Repeat, &three);
        REQUIRE(serial.memory_bytes() == b.memory_bytes());
        CHECK(std::memcmp(serial.unorm8_data(), a.unorm8_data(), serial.memory_bytes()) == 0);
        CHECK(std::memcmp(serial.unorm8_data(), b.unorm8_data(), serial.memory_bytes()) == 0);
    }
    const Image f = to_float(random_unorm8(rng, 301, 517, 4, true));
    const Texture fs = Texture::from_image(f, Wrap::Repeat, Wrap::Repeat);
    const Texture fp = Texture::from_image(f, Wrap::Repeat, Wrap::Repeat, &three);
    CHECK(std::memcmp(fs.texel_data(), fp.texel_data(), fs.memory_bytes()) == 0);
}

} // TEST_SUITE

// 8-bit textures: the fixed-point filter (shading/texture.h) against a
// reference written from docs/conventions.md and against the float filter of
// the same image, every stored mip texel is the correctly rounded byte of the exact
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
using prast::test::reference_code;

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
    // 44x10 and 2x6: even widths whose halves are no multiple of 4 (the SSE blocks and a scalar tail).
    const int sizes[][2] = {{8, 8}, {5, 3}, {17, 1}, {1, 9}, {7, 7}, {64, 32}, {33, 20}, {3, 130}, {44, 10}, {2, 6}};
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

namespace {

// The conventions' bilinear filter of one level of an 8-bit texture that
// repeats in both axes, per stored channel, as an integer over 32640 * 256.
std::vector<long long> reference_bilinear(const Image& img, float u, float v) {
    const int w = img.width, h = img.height, C = img.channels;
    const float ur = u - std::floor(u), vr = v - std::floor(v);
    const float x = ur * float(w) - 0.5f, y = vr * float(h) - 0.5f;
    const float fx = std::floor(x), fy = std::floor(y);
    const long long wx = (long long)((x - fx) * 256.0f + 0.5f), wy = (long long)((y - fy) * 256.0f + 0.5f);
    auto wrap = [](int i, int n) { return ((i % n) + n) % n; };
    const int x0 = wrap(int(fx), w), x1 = wrap(int(fx) + 1, w), y0 = wrap(int(fy), h), y1 = wrap(int(fy) + 1, h);
    std::vector<long long> out;
    for (int c = 0; c < C; ++c) {
        const bool srgb = img.srgb && !(c == C - 1 && (C == 2 || C == 4));
        auto code = [&](int xx, int yy) {
            return (long long)reference_code(img.pixels[(std::size_t(yy) * std::size_t(w) + std::size_t(xx)) * std::size_t(C) + std::size_t(c)], srgb);
        };
        const long long top = (code(x0, y0) * (256 - wx) + code(x1, y0) * wx + 128) / 256;
        const long long bottom = (code(x0, y1) * (256 - wx) + code(x1, y1) * wx + 128) / 256;
        out.push_back(top * (256 - wy) + bottom * wy);
    }
    return out;
}

} // namespace

TEST_CASE("8-bit textures filter in fixed point as the conventions define it") {
    std::mt19937 rng(80u);
    std::uniform_real_distribution<float> uni(-2.0f, 2.0f);
    double worst_float = 0.0;
    for (int channels = 1; channels <= 4; ++channels)
        for (bool srgb : {false, true}) {
            const Image img = random_unorm8(rng, 19, 12, channels, srgb);
            const Texture t8 = Texture::from_image(img, Wrap::Repeat, Wrap::Repeat);
            const Texture tf = Texture::from_image(to_float(img), Wrap::Repeat, Wrap::Repeat);
            CHECK(!tf.is_unorm8());
            // Texels: linear bytes exactly b / 255; sRGB ones the code / 32640,
            // within half a code of the float decode.
            for (int y = 0; y < 12; ++y)
                for (int x = 0; x < 19; ++x) {
                    const glm::vec4 a = t8.texel(0, x, y), b = tf.texel(0, x, y);
                    for (int c = 0; c < 4; ++c) {
                        if (!srgb || c == 3) REQUIRE(a[c] == b[c]);
                        else REQUIRE(std::fabs(a[c] - b[c]) <= 0.5f / 32640.0f + 1e-7f);
                    }
                }
            const int n_out = channels <= 2 ? 1 : 3;  // stored channels that reach r (g, b)
            for (int k = 0; k < 2000; ++k) {
                const float u = uni(rng), v = uni(rng);
                const glm::vec4 a = t8.sample_bilinear(u, v, 0), f = tf.sample_bilinear(u, v, 0);
                const std::vector<long long> ref = reference_bilinear(img, u, v);
                for (int c = 0; c < n_out; ++c) {
                    REQUIRE(bits(a[c]) == bits(float(double(ref[std::size_t(c)])) / 8355840.0f));
                    // Against float filtering: each 8-bit weight moves a result by
                    // at most 1/512 of a step, plus the codes' roundings.
                    worst_float = std::max(worst_float, double(std::fabs(a[c] - f[c])));
                    REQUIRE(std::fabs(a[c] - f[c]) <= 2.0f / 512.0f + 3.0f / 32640.0f);
                }
                if (channels == 2 || channels == 4)
                    REQUIRE(bits(a.a) == bits(float(double(ref[std::size_t(channels - 1)])) / 8355840.0f));
                // Magnification (lambda <= 0) reads level 0 only.
                const glm::vec4 m = t8.sample_trilinear(u, v, -1.5f);
                for (int c = 0; c < 4; ++c) REQUIRE(bits(m[c]) == bits(a[c]));
            }
            // Grey replicates to r, g, b; no alpha channel reads 1.
            const glm::vec4 t = t8.texel(0, 3, 4);
            if (channels <= 2) CHECK((t.r == t.g && t.g == t.b));
            if (channels % 2 == 1) CHECK(t.a == 1.0f);
        }
    MESSAGE("largest difference from float filtering: " << worst_float);
}

TEST_CASE("fixed-point filtering: analytic cases") {
    // Two linear texels 0 and 255, repeating: x = u * 2 - 0.5. Half way
    // between the centres (u = 0.5) the weight is 128/256 and the result
    // exactly 0.5; a texel centre returns the texel exactly.
    Image img;
    img.width = 2;
    img.height = 1;
    img.channels = 1;
    img.pixels = {0, 255};
    const Texture t = Texture::from_image(img, Wrap::ClampToEdge, Wrap::ClampToEdge);
    CHECK(t.sample_bilinear(0.5f, 0.5f, 0).r == 0.5f);
    CHECK(t.sample_bilinear(0.25f, 0.5f, 0).r == 0.0f);
    CHECK(t.sample_bilinear(0.75f, 0.5f, 0).r == 1.0f);
    // A weight of 1/3 rounds to 85/256: (32640 * 85 + 128) >> 8 = 10838.
    const float u = (0.5f + 1.0f / 3.0f) / 2.0f;
    CHECK(t.sample_bilinear(u, 0.5f, 0).r == float(10838 * 256) / 8355840.0f);
    // Every 8-bit byte of a constant texture, linear or sRGB, samples to its
    // own texel value at any position and level.
    for (bool srgb : {false, true})
        for (int b = 0; b < 256; b += 17) {
            Image c;
            c.width = 5;
            c.height = 3;
            c.channels = 3;
            c.srgb = srgb;
            c.pixels.assign(15 * 3, std::uint8_t(b));
            const Texture ct = Texture::from_image(c);
            const float want = ct.texel(0, 0, 0).r;
            for (float lambda : {-1.0f, 0.3f, 1.7f, 5.0f}) CHECK(ct.sample_trilinear(0.37f, 0.81f, lambda).r == want);
        }
    // The level blend: t = 0.25 is 64/256 between two constant levels.
    Image g;
    g.width = 2;
    g.height = 2;
    g.channels = 1;
    g.pixels = {0, 255, 255, 0};  // level 1 is the mean, 128
    const Texture gt = Texture::from_image(g);
    const float l0 = gt.sample_bilinear(0.25f, 0.25f, 0).r;  // texel 0: 0
    CHECK(l0 == 0.0f);
    const int code1 = 128 * 128;
    CHECK(gt.sample_trilinear(0.25f, 0.25f, 0.25f).r == float(code1 * 64) / 8355840.0f);
}

TEST_CASE("the level of detail's log2 is within 4e-6 of log2 and exact at powers of two") {
    for (int e = -60; e <= 60; ++e) CHECK(texture_detail::lod_log2(std::ldexp(1.0f, e)) == float(e));
    std::mt19937 rng(7u);
    std::uniform_real_distribution<float> mant(1.0f, 2.0f);
    double worst = 0.0;
    for (int k = 0; k < 100000; ++k) {
        const float x = std::ldexp(mant(rng), int(k % 40) - 20);
        worst = std::max(worst, std::fabs(double(texture_detail::lod_log2(x)) - std::log2(double(x))));
    }
    MESSAGE("largest error of lod_log2: " << worst);
    CHECK(worst < 4e-6);  // 2.8e-6 from the table, the rest the sum's rounding
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

TEST_CASE("unorm8_codes holds each stored byte's code, built per level on first use") {
    std::mt19937 rng(83u);
    for (int channels : {1, 2, 3, 4}) {
        for (bool srgb : {false, true}) {
            const Image img = random_unorm8(rng, 77, 45, channels, srgb);
            const Texture tex = Texture::from_image(img, Wrap::Repeat, Wrap::Repeat);
            const std::uint16_t* codes = tex.unorm8_codes(0u);
            if (channels < 3 || !srgb) {
                // Those fetch through shifts or one gather per tap, not the copy.
                CHECK(codes == nullptr);
                CHECK(tex.code_bytes() == 0);
                continue;
            }
            if (!codes) {
                MESSAGE("no 16-bit codes in this process (the AVX-512 fetch runs, or no AVX2)");
                continue;
            }
            CHECK(tex.code_bytes() == 0);
            // Levels 1 and 3 first, then all: each level's codes are code_table(c)[byte].
            const std::uint32_t some = 0xAu, all = (1u << tex.levels()) - 1u;
            for (std::uint32_t levels : {some, all}) {
                codes = tex.unorm8_codes(levels);
                std::size_t texels = 0;
                for (int l = 0; l < tex.levels(); ++l) {
                    if (!((levels >> l) & 1u)) continue;
                    const std::size_t n = std::size_t(tex.width(l)) * std::size_t(tex.height(l));
                    texels += n;
                    const std::size_t first = tex.level_offset(l) * std::size_t(channels);
                    for (std::size_t i = first; i < first + n * std::size_t(channels); ++i) {
                        const int c = int(i % std::size_t(channels));
                        REQUIRE(codes[i] == tex.code_table(c)[tex.unorm8_data()[i]]);
                    }
                }
                CHECK(tex.code_bytes() == texels * std::size_t(channels) * 2);
            }
            // A view through another sampler shares them.
            SamplerState clamp;
            clamp.wrap_s = clamp.wrap_t = Wrap::ClampToEdge;
            CHECK(tex.with_sampler(clamp).unorm8_codes(all) == codes);
        }
    }
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

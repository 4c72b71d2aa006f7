// 8-bit PNGs are decoded by libpng (scene/image.cpp); stb_image remains the
// reference for what an image holds. Every PNG flavour (palette with and
// without transparency, grey at 1, 2, 4 and 8 bits, grey and RGB with a tRNS
// colour key, grey+alpha, RGB, RGBA, Adam7 interlacing) decodes to exactly
// stb_image's channels and bytes.
#include <doctest/doctest.h>

#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include <png.h>
#include <zlib.h>
#include <stb_image.h>

#include "fuzz/png_craft.h"
#include "scene/image.h"

using namespace prast;

namespace {

void append_png(png_structp png, png_bytep data, png_size_t n) {
    auto* out = static_cast<std::vector<unsigned char>*>(png_get_io_ptr(png));
    out->insert(out->end(), data, data + n);
}

struct Flavour {
    const char* name;
    int colour_type, bit_depth;
    bool trns, interlace;
};

// Writes a w x h PNG of one flavour, with packed samples from `rng`; with
// `filters` >= 0 (PNG_FILTER_NONE ... PNG_FILTER_PAETH, or several) libpng
// filters its rows with those only, and the samples are gradients, flat runs
// and noise by turns (so that Paeth picks each of its three neighbours).
std::vector<unsigned char> write_flavour(const Flavour& f, int w, int h, std::mt19937& rng, int filters = -1) {
    std::vector<unsigned char> out;
    png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
    png_infop info = png_create_info_struct(png);
    REQUIRE(png);
    REQUIRE(info);
    png_set_write_fn(png, &out, append_png, nullptr);
    png_set_IHDR(png, info, png_uint_32(w), png_uint_32(h), f.bit_depth, f.colour_type,
                 f.interlace ? PNG_INTERLACE_ADAM7 : PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT,
                 PNG_FILTER_TYPE_DEFAULT);
    if (f.colour_type == PNG_COLOR_TYPE_PALETTE) {
        png_color palette[16];
        for (int i = 0; i < 16; ++i) palette[i] = {png_byte(i * 16), png_byte(255 - i * 9), png_byte(i * 5)};
        png_set_PLTE(png, info, palette, 16);
        if (f.trns) {
            png_byte alpha[5] = {0, 50, 100, 150, 200};
            png_set_tRNS(png, info, alpha, 5, nullptr);
        }
    } else if (f.trns) {
        png_color_16 key{};
        key.gray = 1;
        key.red = 3; key.green = 5; key.blue = 7;
        png_set_tRNS(png, info, nullptr, 0, &key);
    }
    if (filters >= 0) png_set_filter(png, PNG_FILTER_TYPE_BASE, filters);
    png_write_info(png, info);
    const int channels = f.colour_type == PNG_COLOR_TYPE_RGB ? 3 : f.colour_type == PNG_COLOR_TYPE_RGBA ? 4
                         : f.colour_type == PNG_COLOR_TYPE_GRAY_ALPHA ? 2 : 1;
    const std::size_t row_bytes = (std::size_t(w) * std::size_t(channels) * std::size_t(f.bit_depth) + 7) / 8;
    std::vector<std::vector<png_byte>> rows;
    rows.assign(static_cast<std::size_t>(h), std::vector<png_byte>(row_bytes));
    const int max_index = f.colour_type == PNG_COLOR_TYPE_PALETTE ? 15 : (1 << f.bit_depth) - 1;
    for (std::size_t y = 0; y < rows.size(); ++y) {
        std::vector<png_byte>& row = rows[y];
        // Small values often, so that the tRNS keys are hit.
        for (png_byte& b : row) b = png_byte(rng() % 4 == 0 ? 0x13 : rng());
        if (filters >= 0)
            for (std::size_t i = 0; i < row.size(); ++i) {
                const std::size_t part = (i * 5 / row.size() + y) % 3;
                if (part == 0) row[i] = png_byte(3 * i + 7 * y);  // gradients across and down
                else if (part == 1) row[i] = png_byte(200 - (i % 3) * 40);
            }
        // 4-bit palette indices are all below 16, the palette's size; 8-bit ones are folded.
        if (f.bit_depth == 8 && f.colour_type == PNG_COLOR_TYPE_PALETTE)
            for (png_byte& b : row) b = png_byte(b % (max_index + 1));
    }
    std::vector<png_bytep> pointers;
    for (auto& row : rows) pointers.push_back(row.data());
    png_write_image(png, pointers.data());
    png_write_end(png, nullptr);
    png_destroy_write_struct(&png, &info);
    return out;
}

std::uint32_t be32(const unsigned char* p) {
    return std::uint32_t(p[0]) << 24 | std::uint32_t(p[1]) << 16 | std::uint32_t(p[2]) << 8 | std::uint32_t(p[3]);
}
// The PNG with its IDAT data (the zlib stream) replaced by edit(stream),
// written as IDAT chunks of `piece` bytes.
template <class Edit>
std::vector<unsigned char> restream(const std::vector<unsigned char>& png, std::size_t piece, Edit edit) {
    std::vector<unsigned char> stream;
    std::string out(png.begin(), png.begin() + 8);
    std::size_t pos = 8;
    bool written = false;
    while (pos + 12 <= png.size()) {
        const std::uint32_t len = be32(&png[pos]);
        const std::string type(reinterpret_cast<const char*>(&png[pos + 4]), 4);
        const auto data = png.begin() + std::ptrdiff_t(pos + 8);
        if (type == "IDAT") {
            stream.insert(stream.end(), data, data + len);
        } else {
            if (!stream.empty() && !written) {
                const std::vector<unsigned char> s = edit(stream);
                for (std::size_t at = 0; at < s.size(); at += piece)
                    out += png_craft::chunk("IDAT", std::string(s.begin() + std::ptrdiff_t(at),
                                                                s.begin() + std::ptrdiff_t(std::min(at + piece, s.size()))));
                written = true;
            }
            out += png_craft::chunk(type, std::string(data, data + len));
        }
        pos += 12 + len;
    }
    return std::vector<unsigned char>(out.begin(), out.end());
}

} // namespace

TEST_SUITE("texture") {

TEST_CASE("PNG image data: libdeflate's whole-image inflate and zlib's rows give the same image and errors") {
    std::mt19937 rng(9u);
    for (const Flavour& f : {Flavour{"RGB", PNG_COLOR_TYPE_RGB, 8, false, false},
                             Flavour{"RGBA", PNG_COLOR_TYPE_RGBA, 8, false, false},
                             Flavour{"grey", PNG_COLOR_TYPE_GRAY, 8, false, false}}) {
        INFO(f.name);
        const std::vector<unsigned char> png = write_flavour(f, 61, 37, rng);
        int w = 0, h = 0, comp = 0;
        stbi_uc* ref = stbi_load_from_memory(png.data(), int(png.size()), &w, &h, &comp, 0);
        REQUIRE(ref != nullptr);
        const std::vector<std::uint8_t> want(ref, ref + std::size_t(w) * std::size_t(h) * std::size_t(comp));
        stbi_image_free(ref);
        auto decode = [](const std::vector<unsigned char>& bytes) {
            ImageSource src;
            src.bytes = bytes;
            src.name = "p.png";
            return decode_image(src, false);
        };
        const auto same = [](const std::vector<unsigned char>& s) { return s; };
        // One IDAT or many small ones.
        for (std::size_t piece : {std::size_t(1) << 20, std::size_t(7), std::size_t(1)})
            CHECK(decode(restream(png, piece, same)).pixels == want);
        // Bytes after the end of the deflate stream: ignored by both.
        const std::vector<unsigned char> trailing = restream(png, 100, [](std::vector<unsigned char> s) {
            s.insert(s.end(), {1, 2, 3, 4, 5});
            return s;
        });
        CHECK(decode(trailing).pixels == want);
        // A stream cut short, or damaged: refused, with the zlib path's words.
        const std::vector<unsigned char> cut = restream(png, 100, [](std::vector<unsigned char> s) {
            s.resize(s.size() / 2);
            return s;
        });
        CHECK_THROWS_WITH(decode(cut), doctest::Contains("p.png: cannot decode PNG image: truncated image data"));
        const std::vector<unsigned char> damaged = restream(png, 100, [](std::vector<unsigned char> s) {
            for (std::size_t i = 2; i < s.size(); i += 3) s[i] = static_cast<unsigned char>(s[i] ^ 0x5A);
            return s;
        });
        CHECK_THROWS_WITH(decode(damaged), doctest::Contains("p.png: cannot decode PNG image: corrupt image data"));
    }
}

TEST_CASE("every row filter, at 1 to 4 bytes a pixel, unfilters exactly as stb_image does") {
    const Flavour flavours[] = {{"grey", PNG_COLOR_TYPE_GRAY, 8, false, false},
                                {"grey+alpha", PNG_COLOR_TYPE_GRAY_ALPHA, 8, false, false},
                                {"RGB", PNG_COLOR_TYPE_RGB, 8, false, false},
                                {"RGBA", PNG_COLOR_TYPE_RGBA, 8, false, false}};
    const int filters[] = {PNG_FILTER_NONE, PNG_FILTER_SUB, PNG_FILTER_UP, PNG_FILTER_AVG, PNG_FILTER_PAETH,
                           PNG_ALL_FILTERS};
    std::mt19937 rng(17u);
    int paeth_rows = 0;
    for (const Flavour& f : flavours)
        for (int filter : filters)
            for (int size : {1, 2, 5, 64, 301}) {
                INFO(std::string(f.name), " filters ", filter, " ", size, "x", size / 2 + 3);
                const std::vector<unsigned char> png = write_flavour(f, size, size / 2 + 3, rng, filter);
                // The rows carry the filter asked for (libpng may write None on the first row).
                const std::vector<unsigned char> stream = [&] {
                    std::vector<unsigned char> s;
                    restream(png, 1u << 20, [&](const std::vector<unsigned char>& z) {
                        s = z;
                        return z;
                    });
                    return s;
                }();
                int w = 0, h = 0, comp = 0;
                stbi_uc* ref = stbi_load_from_memory(png.data(), int(png.size()), &w, &h, &comp, 0);
                REQUIRE(ref != nullptr);
                if (filter == PNG_FILTER_PAETH && h > 1) {
                    std::vector<unsigned char> raw(std::size_t(w * comp + 1) * std::size_t(h));
                    uLongf raw_size = uLongf(raw.size());
                    REQUIRE(uncompress(raw.data(), &raw_size, stream.data(), uLong(stream.size())) == Z_OK);
                    for (int y = 1; y < h; ++y) paeth_rows += raw[std::size_t(y) * std::size_t(w * comp + 1)] == 4;
                }
                ImageSource src;
                src.bytes = png;
                src.name = f.name;
                const Image img = decode_image(src, false);
                REQUIRE(img.width == w);
                REQUIRE(img.height == h);
                CHECK(img.channels == comp);
                CHECK(img.pixels == std::vector<std::uint8_t>(ref, ref + std::size_t(w) * std::size_t(h) * std::size_t(comp)));
                stbi_image_free(ref);
            }
    CHECK(paeth_rows > 100);  // the Paeth rows were written as Paeth
}

TEST_CASE("libpng decodes every 8-bit PNG flavour exactly as stb_image does") {
    const Flavour flavours[] = {
        {"palette", PNG_COLOR_TYPE_PALETTE, 8, false, false},
        {"palette+tRNS", PNG_COLOR_TYPE_PALETTE, 8, true, false},
        {"palette 4-bit", PNG_COLOR_TYPE_PALETTE, 4, false, false},
        {"grey 1-bit", PNG_COLOR_TYPE_GRAY, 1, false, false},
        {"grey 2-bit", PNG_COLOR_TYPE_GRAY, 2, false, false},
        {"grey 4-bit", PNG_COLOR_TYPE_GRAY, 4, false, false},
        {"grey", PNG_COLOR_TYPE_GRAY, 8, false, false},
        {"grey+tRNS", PNG_COLOR_TYPE_GRAY, 8, true, false},
        {"grey+alpha", PNG_COLOR_TYPE_GRAY_ALPHA, 8, false, false},
        {"RGB", PNG_COLOR_TYPE_RGB, 8, false, false},
        {"RGB+tRNS", PNG_COLOR_TYPE_RGB, 8, true, false},
        {"RGBA", PNG_COLOR_TYPE_RGBA, 8, false, false},
        {"RGB interlaced", PNG_COLOR_TYPE_RGB, 8, false, true},
        {"grey 2-bit interlaced", PNG_COLOR_TYPE_GRAY, 2, false, true},
    };
    std::mt19937 rng(5u);
    for (const Flavour& f : flavours)
        for (int size : {1, 7, 33, 200}) {
            INFO(f.name, " ", size, "x", size + 2);
            const std::vector<unsigned char> png = write_flavour(f, size, size + 2, rng);
            int w = 0, h = 0, comp = 0;
            stbi_uc* ref = stbi_load_from_memory(png.data(), int(png.size()), &w, &h, &comp, 0);
            REQUIRE(ref != nullptr);
            ImageSource src;
            src.bytes = png;
            src.name = f.name;
            const Image img = decode_image(src, true);
            CHECK(img.channels == comp);
            CHECK(img.srgb);
            REQUIRE(img.width == w);
            REQUIRE(img.height == h);
            CHECK(img.pixels == std::vector<std::uint8_t>(ref, ref + std::size_t(w) * std::size_t(h) * std::size_t(comp)));
            stbi_image_free(ref);
        }
}

} // TEST_SUITE

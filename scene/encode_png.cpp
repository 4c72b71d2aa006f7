// PNG encoding with zlib in parallel bands; see encode_png.h.
#include "scene/encode_png.h"

#include <algorithm>
#include <cstdlib>
#include <stdexcept>
#include <string>
#include <thread>

#include <zlib.h>

#include "scene/parallel.h"

namespace prast {

namespace {

void put_u32(std::vector<std::uint8_t>& out, std::uint32_t v) {
    for (int s = 24; s >= 0; s -= 8) out.push_back(std::uint8_t(v >> s));
}

void put_chunk(std::vector<std::uint8_t>& out, const char* type, const std::uint8_t* data, std::size_t n) {
    put_u32(out, std::uint32_t(n));
    const std::size_t start = out.size();
    out.insert(out.end(), type, type + 4);
    if (n) out.insert(out.end(), data, data + n);
    put_u32(out, std::uint32_t(crc32(0L, out.data() + start, uInt(n + 4))));
}

// PNG filter type 4 (Paeth, ISO 15948 9.4): predict each byte from the left
// (a), above (b) and upper-left (c) bytes, whichever is closest to a + b - c.
inline std::uint8_t paeth(int a, int b, int c) {
    const int p = a + b - c;
    const int pa = std::abs(p - a), pb = std::abs(p - b), pc = std::abs(p - c);
    if (pa <= pb && pa <= pc) return std::uint8_t(a);
    return std::uint8_t(pb <= pc ? b : c);
}

void filter_row(const std::uint8_t* row, const std::uint8_t* above, std::size_t bytes, int bpp,
                std::uint8_t* out) {
    out[0] = 4;  // Paeth
    for (std::size_t i = 0; i < bytes; ++i) {
        const int a = i >= std::size_t(bpp) ? row[i - std::size_t(bpp)] : 0;
        const int b = above ? above[i] : 0;
        const int c = above && i >= std::size_t(bpp) ? above[i - std::size_t(bpp)] : 0;
        out[i + 1] = std::uint8_t(row[i] - paeth(a, b, c));
    }
}

struct Band {
    std::vector<std::uint8_t> deflated;
    uLong adler = 1;
    uLong filtered_bytes = 0;
    std::string error;
};

// Filters and deflates rows [y0, y1) as raw deflate data ending on a byte
// boundary (the last band with the final block).
void encode_band(const std::uint8_t* pixels, int width, int channels, int y0, int y1, bool last, int level,
                 Band& band) {
    const std::size_t row_bytes = std::size_t(width) * std::size_t(channels);
    std::vector<std::uint8_t> filtered((row_bytes + 1) * std::size_t(y1 - y0));
    for (int y = y0; y < y1; ++y) {
        const std::uint8_t* row = pixels + std::size_t(y) * row_bytes;
        filter_row(row, y > 0 ? row - row_bytes : nullptr, row_bytes, channels,
                   filtered.data() + std::size_t(y - y0) * (row_bytes + 1));
    }
    band.filtered_bytes = uLong(filtered.size());
    band.adler = adler32(1L, filtered.data(), uInt(filtered.size()));

    z_stream z{};
    // Raw deflate (negative window bits): the zlib header and the Adler-32 of
    // the whole stream are written once around the bands.
    if (deflateInit2(&z, level, Z_DEFLATED, -15, 8, Z_DEFAULT_STRATEGY) != Z_OK) {
        band.error = "deflateInit2 failed";
        return;
    }
    try {
        band.deflated.resize(deflateBound(&z, uLong(filtered.size())) + 16);
    } catch (...) {
        deflateEnd(&z);
        throw;
    }
    z.next_in = filtered.data();
    z.avail_in = uInt(filtered.size());
    z.next_out = band.deflated.data();
    z.avail_out = uInt(band.deflated.size());
    const int rc = deflate(&z, last ? Z_FINISH : Z_FULL_FLUSH);
    if ((last && rc != Z_STREAM_END) || (!last && (rc != Z_OK || z.avail_in != 0)))
        band.error = "deflate failed";
    band.deflated.resize(band.deflated.size() - z.avail_out);
    deflateEnd(&z);
}

} // namespace

PngOptions png_options_threads(int threads) {
    if (threads <= 0) threads = int(std::min(8u, std::max(1u, std::thread::hardware_concurrency())));
    PngOptions o;
    if (threads == 1) return o;
    o.parallel_for = [threads](int count, const std::function<void(int)>& fn) {
        run_on_threads(threads, count, fn);  // the first band that throws (out of memory): rethrown
    };
    return o;
}

std::vector<std::uint8_t> encode_png_pixels(const std::uint8_t* pixels, int width, int height, int channels,
                                            const PngOptions& options) {
    if (width <= 0 || height <= 0 || channels < 1 || channels > 4)
        throw std::invalid_argument("encode_png: bad image (" + std::to_string(width) + "x" + std::to_string(height) +
                                    ", " + std::to_string(channels) + " channels)");
    if (std::size_t(width) * std::size_t(channels) + 1 > std::size_t(1) << 30)
        throw std::invalid_argument("encode_png: rows too long");
    const int rows = options.band_rows > 0 ? options.band_rows : 64;
    const int level = options.zlib_level < 1 ? 1 : (options.zlib_level > 9 ? 9 : options.zlib_level);
    const int count = (height + rows - 1) / rows;
    std::vector<Band> bands(static_cast<std::size_t>(count));
    auto run = [&](int b) {
        const int y0 = b * rows, y1 = y0 + rows < height ? y0 + rows : height;
        encode_band(pixels, width, channels, y0, y1, b == count - 1, level, bands[std::size_t(b)]);
    };
    if (options.parallel_for) {
        options.parallel_for(count, run);
    } else {
        for (int b = 0; b < count; ++b) run(b);
    }

    // The file's size first (signature, IHDR, the IDATs, IEND): one
    // allocation, not a growing vector's copies of the bands.
    std::size_t file_bytes = 8 + 25 + 14 + 16 + 12;
    for (const Band& band : bands) file_bytes += 12 + band.deflated.size();
    std::vector<std::uint8_t> png;
    png.reserve(file_bytes);
    png.insert(png.end(), {0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'});
    std::vector<std::uint8_t> ihdr;
    put_u32(ihdr, std::uint32_t(width));
    put_u32(ihdr, std::uint32_t(height));
    static const std::uint8_t kColourType[5] = {0, 0, 4, 2, 6};  // grey, grey+alpha, RGB, RGBA
    ihdr.insert(ihdr.end(), {8, kColourType[channels], 0, 0, 0});  // 8 bits, deflate, adaptive filters, no interlace
    put_chunk(png, "IHDR", ihdr.data(), ihdr.size());

    // The zlib stream: header (deflate, 32 KiB window; 0x78 0x5E passes the
    // FCHECK test), the bands, the Adler-32 of all filtered bytes.
    uLong adler = 1;
    for (std::size_t b = 0; b < bands.size(); ++b) {
        if (!bands[b].error.empty()) throw std::runtime_error("encode_png: zlib " + bands[b].error);
        adler = b == 0 ? bands[b].adler : adler32_combine(adler, bands[b].adler, z_off_t(bands[b].filtered_bytes));
    }
    const std::uint8_t header[2] = {0x78, 0x5E};
    put_chunk(png, "IDAT", header, 2);
    for (const Band& band : bands) {
        // Chunks hold at most 2^31 - 1 bytes; a band never comes near.
        put_chunk(png, "IDAT", band.deflated.data(), band.deflated.size());
    }
    std::uint8_t trailer[4];
    for (int i = 0; i < 4; ++i) trailer[i] = std::uint8_t(adler >> (24 - 8 * i));
    put_chunk(png, "IDAT", trailer, 4);
    put_chunk(png, "IEND", nullptr, 0);
    return png;
}

} // namespace prast

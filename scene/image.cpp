// Image decoding: 8-bit PNG through libpng and zlib (linked statically: their
// inflate and row filters are several times faster than stb_image's), JPEG
// through libjpeg-turbo's TurboJPEG API (static; its SIMD inverse DCT,
// upsampling and colour conversion give the bytes of its C code on every
// CPU), WebP through libwebp (static too; EXT_texture_webp), every other
// format (HDR, 16-bit PNG, BMP, ...) through stb_image. 8-bit files keep their
// bytes, 16-bit and HDR files become linear float RGBA; see image.h.
#include "scene/image.h"

#include <array>
#include <cerrno>
#include <climits>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <memory>
#include <string>

#include <algorithm>
#include <csetjmp>
#include <cstdlib>

#if defined(__SSE2__)
#include <immintrin.h>
#endif
#include <libdeflate.h>
#include <png.h>
#include <zlib.h>
#include <stb_image.h>
#include <turbojpeg.h>
#include <webp/decode.h>
#include <unistd.h>

#include "scene/det_math.h"
#include "scene/file_access.h"
#include "scene/hdr_guard.h"
#include "scene/huge_pages.h"
#include "scene/messages.h"

namespace prast {

namespace {

// The sRGB electro-optical transfer function (IEC 61966-2-1), exact form.
float srgb_to_linear(float c) {
    return c <= 0.04045f ? c / 12.92f : det::pow((c + 0.055f) / 1.055f, 2.4f);
}


std::string stbi_reason() {
    const char* r = stbi_failure_reason();
    if (r && std::string(r) == "outofmem") return "out of memory";
    if (r && std::string(r) == "outofdata") return "truncated image data";
    return r ? r : "unknown error";
}

// The container format by its signature, for messages: when its header is
// bad, stb_image tries every other format and reports only the last failure
// ("unknown image type").
const char* sniff_format(const unsigned char* p, std::size_t n) {
    auto starts = [&](const char* sig, std::size_t len) { return n >= len && std::memcmp(p, sig, len) == 0; };
    if (starts("\x89PNG\r\n\x1a\n", 8)) return "PNG";
    if (starts("\xff\xd8\xff", 3)) return "JPEG";
    if (starts("#?RADIANCE", 10) || starts("#?RGBE", 6)) return "HDR";
    if (starts("GIF8", 4)) return "GIF";
    if (starts("8BPS", 4)) return "PSD";
    if (starts("BM", 2)) return "BMP";
    return nullptr;
}

// A WebP file (RIFF container, EXT_texture_webp): decoded by libwebp.
bool is_webp(const unsigned char* p, std::size_t n) {
    return n >= 12 && std::memcmp(p, "RIFF", 4) == 0 && std::memcmp(p + 8, "WEBP", 4) == 0;
}

// A WebP (lossless or lossy) can code a flat image in almost no bits, so its
// size alone bounds nothing: above kWebpFreeTexels, a file must bring a byte
// per kMaxWebpTexelsPerByte texels (a flat 4096x4096 lossless texture is
// about 100 bytes: such a file is refused; real textures are far denser),
// so that a small file cannot make prast allocate a gigabyte for pixels.
constexpr std::int64_t kWebpFreeTexels = std::int64_t(1) << 20;
constexpr std::int64_t kMaxWebpTexelsPerByte = 4096;

// "" with the size and channel count (3, or 4 with alpha) from a WebP's
// header, checked against kMaxImageTexels and the bound above (`file_size`:
// the whole file's); else why not.
std::string webp_header(const unsigned char* data, std::size_t size, std::uint64_t file_size, int& w, int& h,
                        int& channels) {
    WebPBitstreamFeatures f;
    if (WebPGetFeatures(data, size, &f) != VP8_STATUS_OK) return "cannot decode WebP image: corrupt or truncated header";
    if (f.has_animation) return "cannot decode WebP image: animated WebP is not supported";
    if (f.width <= 0 || f.height <= 0) return "image has zero size";
    const std::int64_t texels = std::int64_t(f.width) * std::int64_t(f.height);
    if (texels > kMaxImageTexels)
        return "image too large: " + std::to_string(f.width) + "x" + std::to_string(f.height) + " = " +
               std::to_string(texels) + " texels, more than the limit of " + std::to_string(kMaxImageTexels) +
               " (2^28)";
    if (texels > kWebpFreeTexels && std::uint64_t(texels) > std::uint64_t(kMaxWebpTexelsPerByte) * file_size)
        return "cannot decode WebP image: " + std::to_string(f.width) + "x" + std::to_string(f.height) +
               " texels from only " + std::to_string(file_size) + " bytes (more than " +
               std::to_string(kMaxWebpTexelsPerByte) + " texels a byte are refused)";
    w = f.width;
    h = f.height;
    channels = f.has_alpha ? 4 : 3;
    return "";
}

bool is_png(const unsigned char* p, std::size_t n) {
    const char* format = sniff_format(p, n);
    return format && std::strcmp(format, "PNG") == 0;
}

// Expands `comp` channels per texel to RGBA, decoding colour channels with
// `colour` and alpha with `alpha`.
template <class T, class ColourFn, class AlphaFn>
void expand_to_rgba(const T* src, int comp, std::size_t count, float* dst, ColourFn colour,
                    AlphaFn alpha) {
    for (std::size_t i = 0; i < count; ++i, src += comp, dst += 4) {
        if (comp <= 2) {
            const float g = colour(src[0]);
            dst[0] = dst[1] = dst[2] = g;
            dst[3] = comp == 2 ? alpha(src[1]) : 1.0f;
        } else {
            dst[0] = colour(src[0]);
            dst[1] = colour(src[1]);
            dst[2] = colour(src[2]);
            dst[3] = comp == 4 ? alpha(src[3]) : 1.0f;
        }
    }
}

// ---- The common PNGs (8-bit grey, grey+alpha, RGB, RGBA, not interlaced, no
// tRNS) decoded here: chunks walked with their lengths and CRCs checked, the
// IDAT data inflated by zlib one row at a time, and the rows unfiltered with
// SSE2 for the Paeth filter (3 or 4 bytes a pixel), which libpng as Debian
// builds it does a byte at a time. Everything else goes to libpng below.

std::uint32_t be32(const unsigned char* p) {
    return std::uint32_t(p[0]) << 24 | std::uint32_t(p[1]) << 16 | std::uint32_t(p[2]) << 8 | std::uint32_t(p[3]);
}

enum class FastPng { Done, NotMine, Failed };

// Paeth predictor (ISO 15948 9.4) of one byte.
inline int paeth_predict(int a, int b, int c) {
    const int pa = std::abs(b - c), pb = std::abs(a - c), pc = std::abs(a + b - 2 * c);
    return pa <= pb && pa <= pc ? a : (pb <= pc ? b : c);
}

#if defined(__SSE2__)
// Rows of BPP-byte pixels (3 or 4), one pixel per step in 16-bit lanes: a
// (left), b (above), c (upper left), x (the filtered bytes). Each step waits
// for the one before (a), so what counts is the chain from a to the result.
inline __m128i load_pixel16(const unsigned char* p) {
    std::int32_t word;
    std::memcpy(&word, p, 4);
    return _mm_unpacklo_epi8(_mm_cvtsi32_si128(word), _mm_setzero_si128());
}
template <int BPP> inline void store_pixel16(unsigned char* p, __m128i v) {
    const std::int32_t word = _mm_cvtsi128_si32(_mm_packus_epi16(v, v));
    std::memcpy(p, &word, BPP);
}
inline __m128i abs16(__m128i v) {
#if defined(__SSSE3__)
    return _mm_abs_epi16(v);
#else
    return _mm_max_epi16(v, _mm_sub_epi16(_mm_setzero_si128(), v));
#endif
}
// mask ? t : f, the mask's lanes all ones or all zeros.
inline __m128i select16(__m128i mask, __m128i t, __m128i f) {
#if defined(__SSE4_1__)
    return _mm_blendv_epi8(f, t, mask);
#else
    return _mm_or_si128(_mm_and_si128(mask, t), _mm_andnot_si128(mask, f));
#endif
}
// Bytes in the low halves of 16-bit lanes (the high halves 0): x + p mod 256
// in one add of bytes, whose carries stay inside each byte.
inline __m128i add_mod256(__m128i x, __m128i p) { return _mm_add_epi8(x, p); }

// x + Paeth's prediction (paeth_predict): a unless pa > min(pb, pc); then c
// if pb > pc, else b. pa = |b - c| does not depend on a; from a the chain is
// a - c, the absolute values, min, compare, select and the add: seven steps.
inline __m128i paeth_step(__m128i a, __m128i b, __m128i c, __m128i x) {
    const __m128i bc = _mm_sub_epi16(b, c), pa = abs16(bc);
    const __m128i ac = _mm_sub_epi16(a, c);
    const __m128i pb = abs16(ac), pc = abs16(_mm_add_epi16(ac, bc));  // |a + b - 2c|
    const __m128i not_a = _mm_cmpgt_epi16(pa, _mm_min_epi16(pb, pc));
    const __m128i b_or_c = select16(_mm_cmpgt_epi16(pb, pc), c, b);
    return add_mod256(x, select16(not_a, b_or_c, a));
}

template <int BPP>
void paeth_sse2(const unsigned char* raw, const unsigned char* above, unsigned char* out, std::size_t n) {
    __m128i a = _mm_setzero_si128(), c = a;
    for (std::size_t i = 0; i < n; i += BPP) {
        const __m128i b = load_pixel16(above + i);
        a = paeth_step(a, b, c, load_pixel16(raw + i));
        store_pixel16<BPP>(out + i, a);
        c = b;
    }
}

// Two Paeth rows at once, each step one pixel of each: lanes 0-3 hold pixel
// p of the first row, lanes 4-7 pixel p - 1 of the second, whose pixel above
// is the step before's low half. The two chains share one run of seven
// steps (and the move of that half), so a pixel costs half as long.
// raw0 and above are read 4 bytes past their row (n) and raw1 up to there.
template <int BPP>
void paeth_two_rows_sse2(const unsigned char* raw0, const unsigned char* raw1, const unsigned char* above,
                         unsigned char* out0, unsigned char* out1, std::size_t n) {
    const __m128i zero = _mm_setzero_si128();
    const std::size_t pixels = n / BPP;
    // The step before (a) and its b (now c). At p = 0 the second row's lanes
    // see only zeros and give 0: the left of its pixel 0.
    __m128i v = zero, c = zero;
    for (std::size_t p = 0; p <= pixels; ++p) {
        const std::size_t i = p * BPP;
        const __m128i x = _mm_unpacklo_epi64(load_pixel16(raw0 + i), p > 0 ? load_pixel16(raw1 + i - BPP) : zero);
        const __m128i b = _mm_unpacklo_epi64(load_pixel16(above + i), v);
        const __m128i next = paeth_step(v, b, c, x);
        if (p < pixels) store_pixel16<BPP>(out0 + i, next);
        if (p > 0) store_pixel16<BPP>(out1 + i - BPP, _mm_srli_si128(next, 8));
        v = next;
        c = b;
    }
}

// Sub (x + a) and Average (x + (a + b) / 2, b = 0 without a row above).
template <int BPP>
void sub_sse2(const unsigned char* raw, unsigned char* out, std::size_t n) {
    __m128i a = _mm_setzero_si128();
    for (std::size_t i = 0; i < n; i += BPP) {
        a = add_mod256(load_pixel16(raw + i), a);
        store_pixel16<BPP>(out + i, a);
    }
}
template <int BPP>
void average_sse2(const unsigned char* raw, const unsigned char* above, unsigned char* out, std::size_t n) {
    __m128i a = _mm_setzero_si128();
    for (std::size_t i = 0; i < n; i += BPP) {
        const __m128i b = above ? load_pixel16(above + i) : _mm_setzero_si128();
        a = add_mod256(load_pixel16(raw + i), _mm_srli_epi16(_mm_add_epi16(a, b), 1));
        store_pixel16<BPP>(out + i, a);
    }
}
#endif

// Reconstructs one row (filter byte already read) from the filtered bytes
// `raw` (4 readable bytes past the row) and the row above (null for row 0,
// else 4 readable bytes past it: the row below follows it in memory).
bool unfilter_row(int filter, const unsigned char* raw, const unsigned char* above, unsigned char* out,
                  std::size_t n, int bpp) {
    const std::size_t b = std::size_t(bpp);
    switch (filter) {
    case 0: std::memcpy(out, raw, n); return true;
    case 1:
#if defined(__SSE2__)
        if (bpp == 3) return sub_sse2<3>(raw, out, n), true;
        if (bpp == 4) return sub_sse2<4>(raw, out, n), true;
#endif
        for (std::size_t i = 0; i < n; ++i) out[i] = (unsigned char)(raw[i] + (i >= b ? out[i - b] : 0));
        return true;
    case 2:
        if (!above) std::memcpy(out, raw, n);
        else for (std::size_t i = 0; i < n; ++i) out[i] = (unsigned char)(raw[i] + above[i]);
        return true;
    case 3:
#if defined(__SSE2__)
        if (bpp == 3) return average_sse2<3>(raw, above, out, n), true;
        if (bpp == 4) return average_sse2<4>(raw, above, out, n), true;
#endif
        for (std::size_t i = 0; i < n; ++i)
            out[i] = (unsigned char)(raw[i] + (((i >= b ? out[i - b] : 0) + (above ? above[i] : 0)) >> 1));
        return true;
    case 4:
        if (!above) {  // Paeth with no row above is Sub
            for (std::size_t i = 0; i < n; ++i) out[i] = (unsigned char)(raw[i] + (i >= b ? out[i - b] : 0));
            return true;
        }
#if defined(__SSE2__)
        if (bpp == 3) return paeth_sse2<3>(raw, above, out, n), true;
        if (bpp == 4) return paeth_sse2<4>(raw, above, out, n), true;
#endif
        for (std::size_t i = 0; i < n; ++i) {
            const int left = i >= b ? out[i - b] : 0, up_left = i >= b ? above[i - b] : 0;
            out[i] = (unsigned char)(raw[i] + paeth_predict(left, above[i], up_left));
        }
        return true;
    default: return false;
    }
}

// Rows [y0, y1) of an image n bytes a row: filtered row y (its filter byte
// first) at raw + (y - y0) * (n + 1), with 4 readable bytes after the last;
// row y of the result at pixels + y * n (rows before y0 already there, and 4
// readable bytes after row y1 - 1). Returns the first row with an unknown
// filter type, or -1.
int unfilter_rows(const unsigned char* raw, unsigned char* pixels, std::size_t n, int y0, int y1, int bpp) {
    for (int y = y0; y < y1;) {
        const unsigned char* r = raw + std::size_t(y - y0) * (n + 1);
        unsigned char* out = pixels + std::size_t(y) * n;
        const unsigned char* above = y > 0 ? out - n : nullptr;
#if defined(__SSE2__)
        if (r[0] == 4 && above && y + 1 < y1 && r[n + 1] == 4 && (bpp == 3 || bpp == 4)) {
            if (bpp == 3) paeth_two_rows_sse2<3>(r + 1, r + n + 2, above, out, out + n, n);
            else paeth_two_rows_sse2<4>(r + 1, r + n + 2, above, out, out + n, n);
            y += 2;
            continue;
        }
#endif
        if (!unfilter_row(r[0], r + 1, above, out, n, bpp)) return y;
        ++y;
    }
    return -1;
}

// The zlib header (RFC 1950) of a PNG's image data: deflate, a window of at
// most 32 KiB, no preset dictionary, its check bits right.
bool png_zlib_header_ok(unsigned char cmf, unsigned char flg) {
    return (cmf & 0x0F) == 8 && (cmf >> 4) <= 7 && !(flg & 0x20) && (unsigned(cmf) * 256u + flg) % 31u == 0;
}

// decode_png_fast's first try: true when libdeflate inflated the whole
// image and every row unfiltered into img.pixels (sized by the caller);
// false for anything else (and for images over 128 MiB of rows), which the
// zlib path then reads and reports.
bool inflate_png_whole(const unsigned char* data, std::size_t size, int w, int h, int channels, Image& img) {
    const std::size_t stride = std::size_t(w) * std::size_t(channels);
    const std::size_t raw_size = (stride + 1) * std::size_t(h);
    // The image's filtered rows are held whole (in its pixels' buffer, with
    // the compressed data beside them): beyond 128 MiB (a 5,792-texel RGBA
    // square) the zlib path's 256 KiB at a time keeps a huge texture's
    // decode within what the memory plan counted.
    if (raw_size > (std::size_t(128) << 20)) return false;
    // The IDAT data's size first, so that it is gathered into one buffer
    // of its size (growing one would copy and fault in about twice that).
    std::size_t idat_bytes = 0;
    for (std::size_t pos = 8; pos + 12 <= size;) {
        const std::uint32_t len = be32(data + pos);
        if (len > size - pos - 12) return false;
        if (std::memcmp(data + pos + 4, "IDAT", 4) == 0) idat_bytes += len;
        pos += 12 + std::size_t(len);
    }
    HugeBytes compressed;
    compressed.reserve(idat_bytes);
    for (std::size_t pos = 8; pos + 12 <= size;) {
        const std::uint32_t len = be32(data + pos);
        if (len > size - pos - 12) return false;
        const unsigned char* type = data + pos + 4;
        if (std::uint32_t(libdeflate_crc32(0, type, len + 4)) != be32(data + pos + 8 + len)) return false;
        if (std::memcmp(type, "IDAT", 4) == 0) compressed.insert(compressed.end(), type + 4, type + 4 + len);
        else if (!compressed.empty() || std::memcmp(type, "IEND", 4) == 0) break;  // IDATs are consecutive
        pos += 12 + std::size_t(len);
    }
    if (compressed.size() < 2 || !png_zlib_header_ok(compressed[0], compressed[1])) return false;
    struct Free {
        void operator()(libdeflate_decompressor* d) const { libdeflate_free_decompressor(d); }
    };
    const std::unique_ptr<libdeflate_decompressor, Free> inflater(libdeflate_alloc_decompressor());
    if (!inflater) return false;
    // One buffer: the filtered rows are inflated two rows of pixels past its
    // start and unfiltered in place. Pixel row y (and y + 1, which the Paeth
    // pair writes while still reading filtered row y) then ends before
    // filtered row y begins: no write reaches a byte still to be read.
    const std::size_t lead = 2 * stride;
    reserve_huge(img.pixels, lead + raw_size + 4);  // 4 spare bytes for unfilter_row's 4-byte reads
    img.pixels.resize(lead + raw_size + 4);
    unsigned char* raw = img.pixels.data() + lead;
    std::size_t in_used = 0, out_made = 0;
    // The raw deflate stream after the header; its Adler-32 is not checked
    // (the chunk CRCs guard the bytes), as on the zlib path.
    if (libdeflate_deflate_decompress_ex(inflater.get(), compressed.data() + 2, compressed.size() - 2, raw,
                                         raw_size, &in_used, &out_made) != LIBDEFLATE_SUCCESS ||
        out_made != raw_size)
        return false;
    compressed = HugeBytes();
    return unfilter_rows(raw, img.pixels.data(), stride, 0, h, channels) < 0;
}

FastPng decode_png_fast(const unsigned char* data, std::size_t size, int w, int h, Image& img, std::string& error) {
    // Walk the chunk headers first: is this a PNG of the common kind?
    if (size < 8 + 25) return FastPng::NotMine;
    std::size_t pos = 8;
    int channels = 0;
    bool seen_idat = false;
    while (pos + 12 <= size) {
        const std::uint32_t len = be32(data + pos);
        if (len > size - pos - 12) return FastPng::NotMine;  // libpng names the problem
        const unsigned char* type = data + pos + 4;
        if (pos == 8) {
            if (std::memcmp(type, "IHDR", 4) != 0 || len != 13) return FastPng::NotMine;
            const unsigned char* d = data + pos + 8;
            if (int(be32(d)) != w || int(be32(d + 4)) != h || d[8] != 8 || d[10] != 0 || d[11] != 0 || d[12] != 0)
                return FastPng::NotMine;
            static const int kChannels[7] = {1, 0, 3, 0, 2, 0, 4};
            if (d[9] > 6 || !kChannels[d[9]]) return FastPng::NotMine;
            channels = kChannels[d[9]];
        }
        if (std::memcmp(type, "tRNS", 4) == 0) return FastPng::NotMine;
        if (std::memcmp(type, "IDAT", 4) == 0) seen_idat = true;
        if (std::memcmp(type, "IEND", 4) == 0) break;
        pos += 12 + std::size_t(len);
    }
    if (!channels || !seen_idat) return FastPng::NotMine;

    const std::size_t stride = std::size_t(w) * std::size_t(channels);
    // First libdeflate, in one call over the whole image (2 to 3 times zlib's
    // speed): the IDAT data gathered, every CRC checked, the zlib header
    // checked, the rows inflated into one buffer of exactly the image's size
    // (more data, or less, is refused there) and unfiltered. Whatever it does
    // not take (a damaged stream, data past the pixels) goes on to zlib below,
    // which names the problem as it always has.
    if (inflate_png_whole(data, size, w, h, channels, img)) {
        img.pixels.resize(stride * std::size_t(h));
        img.width = w;
        img.height = h;
        img.channels = channels;
        return FastPng::Done;
    }
    img.pixels.resize(stride * std::size_t(h) + 4);  // 4 spare bytes for the 4-byte reads

    // Inflate the IDAT chunks into `raw`, many rows at a time (zlib copies
    // what each call writes into its 32 KiB window: calls of a few hundred KiB
    // keep that copy small), and unfilter them. The zlib header is read here
    // and the data inflated raw: the chunk CRCs already guard the bytes, so
    // the Adler-32 of the pixels (7% of the decode) is not computed.
    const std::size_t rows_per_call = std::max<std::size_t>(1, (std::size_t(256) << 10) / (stride + 1));
    std::vector<unsigned char> raw((stride + 1) * std::min<std::size_t>(rows_per_call, std::size_t(h)) + 4, 0);
    z_stream z{};
    if (inflateInit2(&z, -15) != Z_OK) {
        error = "zlib: cannot start";
        return FastPng::Failed;
    }
    struct EndInflate {
        z_stream* z;
        ~EndInflate() { inflateEnd(z); }
    } end_inflate{&z};
    pos = 8;
    std::size_t idat_left = 0;
    const unsigned char* idat = nullptr;
    auto next_idat = [&]() -> bool {  // the next IDAT chunk's data, CRC checked
        while (pos + 12 <= size) {
            const std::uint32_t len = be32(data + pos);
            if (len > size - pos - 12) return false;
            const unsigned char* type = data + pos + 4;
            if (std::uint32_t(libdeflate_crc32(0, type, len + 4)) != be32(data + pos + 8 + len)) {
                error = std::string("CRC error in the ") + std::string(reinterpret_cast<const char*>(type), 4) +
                        " chunk";
                return false;
            }
            const std::size_t at = pos;
            pos += 12 + std::size_t(len);
            if (std::memcmp(type, "IDAT", 4) == 0) {
                idat = data + at + 8;
                idat_left = len;
                return true;
            }
            if (std::memcmp(type, "IEND", 4) == 0) return false;
        }
        return false;
    };
    // The zlib header's two bytes, which may straddle IDAT chunks.
    unsigned char header[2];
    for (int i = 0; i < 2; ++i) {
        while (idat_left == 0)
            if (!next_idat()) {
                if (error.empty()) error = "truncated image data";
                return FastPng::Failed;
            }
        header[i] = *idat++;
        --idat_left;
    }
    if (!png_zlib_header_ok(header[0], header[1])) {
        error = "corrupt image data (bad zlib header)";
        return FastPng::Failed;
    }
    for (int y0 = 0; y0 < h; y0 += int(rows_per_call)) {
        const int y1 = std::min(h, y0 + int(rows_per_call));
        z.next_out = raw.data();
        z.avail_out = uInt((stride + 1) * std::size_t(y1 - y0));
        while (z.avail_out > 0) {
            if (z.avail_in == 0) {
                if (idat_left == 0 && !next_idat()) {
                    if (error.empty()) error = "truncated image data";
                    return FastPng::Failed;
                }
                const std::size_t take = std::min<std::size_t>(idat_left, 1u << 30);
                z.next_in = const_cast<unsigned char*>(idat);
                z.avail_in = uInt(take);
                idat += take;
                idat_left -= take;
            }
            const int rc = inflate(&z, Z_NO_FLUSH);
            if (rc == Z_STREAM_END && z.avail_out > 0) {
                error = "not enough image data";
                return FastPng::Failed;
            }
            if (rc != Z_OK && rc != Z_STREAM_END && !(rc == Z_BUF_ERROR && z.avail_in == 0)) {
                error = std::string("corrupt image data (zlib: ") + (z.msg ? z.msg : "error") + ")";
                return FastPng::Failed;
            }
        }
        const int bad = unfilter_rows(raw.data(), img.pixels.data(), stride, y0, y1, channels);
        if (bad >= 0) {
            error = "bad row filter type " + std::to_string(int(raw[std::size_t(bad - y0) * (stride + 1)]));
            return FastPng::Failed;
        }
    }
    // Later chunks (after the pixels) are not needed; stb_image and libpng
    // read no further either.
    img.pixels.resize(stride * std::size_t(h));
    img.width = w;
    img.height = h;
    img.channels = channels;
    return FastPng::Done;
}

// ---- 8-bit PNG through libpng. libpng reports errors by longjmp: no object
// with a destructor is created between the setjmp and the end of the decode
// (the output vector belongs to the caller).

struct PngSource {
    const unsigned char* data;
    std::size_t size, pos;
    char error[160];
};

void png_read_memory(png_structp png, png_bytep out, png_size_t n) {
    PngSource* s = static_cast<PngSource*>(png_get_io_ptr(png));
    if (n > s->size - s->pos) png_error(png, "truncated file");
    std::memcpy(out, s->data + s->pos, n);
    s->pos += n;
}

[[noreturn]] void png_on_error(png_structp png, png_const_charp message) {
    PngSource* s = static_cast<PngSource*>(png_get_error_ptr(png));
    std::snprintf(s->error, sizeof s->error, "%s", message ? message : "unknown error");
    png_longjmp(png, 1);
}

void png_on_warning(png_structp, png_const_charp) {}

// Decodes into img (channels as the file has them, palettes and tRNS expanded
// as stb_image does); false with src.error set on failure.
bool decode_png8(PngSource& src, int w, int h, Image& img) {
    png_structp png = png_create_read_struct(PNG_LIBPNG_VER_STRING, &src, png_on_error, png_on_warning);
    if (!png) {
        std::snprintf(src.error, sizeof src.error, "out of memory");
        return false;
    }
    png_infop info = png_create_info_struct(png);
    if (!info || setjmp(png_jmpbuf(png))) {
        png_destroy_read_struct(&png, info ? &info : nullptr, nullptr);
        if (!src.error[0]) std::snprintf(src.error, sizeof src.error, "out of memory");
        return false;
    }
    png_set_read_fn(png, &src, png_read_memory);
    // The header was checked already (sizes, the texel limit); keep libpng's
    // own limits from refusing what stb_image accepts.
    png_set_user_limits(png, 0x7FFFFFFF, 0x7FFFFFFF);
    png_read_info(png, info);
    if (int(png_get_image_width(png, info)) != w || int(png_get_image_height(png, info)) != h)
        png_error(png, "inconsistent image header");
    png_set_expand(png);  // palette -> RGB, grey < 8 bits -> 8, tRNS -> alpha
    png_set_strip_16(png);
    const int passes = png_set_interlace_handling(png);
    png_read_update_info(png, info);
    const int channels = png_get_channels(png, info);
    if (channels < 1 || channels > 4 || png_get_rowbytes(png, info) != std::size_t(w) * std::size_t(channels))
        png_error(png, "unsupported pixel layout");
    img.pixels.resize(std::size_t(w) * std::size_t(h) * std::size_t(channels));
    const std::size_t stride = std::size_t(w) * std::size_t(channels);
    for (int pass = 0; pass < passes; ++pass)
        for (int y = 0; y < h; ++y) png_read_row(png, img.pixels.data() + std::size_t(y) * stride, nullptr);
    png_destroy_read_struct(&png, &info, nullptr);
    img.width = w;
    img.height = h;
    img.channels = channels;
    return true;
}

// Decodes a 16-bit PNG into `samples` (tRNS expanded to an alpha channel, as
// stb_image does), and its channel count; false with src.error set on
// failure. For the PNGs stb_image refuses by size.
bool decode_png16(PngSource& src, int w, int h, std::vector<std::uint16_t>& samples, int& channels) {
    png_structp png = png_create_read_struct(PNG_LIBPNG_VER_STRING, &src, png_on_error, png_on_warning);
    if (!png) {
        std::snprintf(src.error, sizeof src.error, "out of memory");
        return false;
    }
    png_infop info = png_create_info_struct(png);
    if (!info || setjmp(png_jmpbuf(png))) {
        png_destroy_read_struct(&png, info ? &info : nullptr, nullptr);
        if (!src.error[0]) std::snprintf(src.error, sizeof src.error, "out of memory");
        return false;
    }
    png_set_read_fn(png, &src, png_read_memory);
    png_set_user_limits(png, 0x7FFFFFFF, 0x7FFFFFFF);
    png_read_info(png, info);
    if (int(png_get_image_width(png, info)) != w || int(png_get_image_height(png, info)) != h ||
        png_get_bit_depth(png, info) != 16)
        png_error(png, "inconsistent image header");
    png_set_expand(png);  // tRNS -> alpha
    const std::uint16_t probe = 1;
    unsigned char first = 0;
    std::memcpy(&first, &probe, 1);
    if (first == 1) png_set_swap(png);  // the file's big-endian samples in host order
    const int passes = png_set_interlace_handling(png);
    png_read_update_info(png, info);
    channels = png_get_channels(png, info);
    const std::size_t stride = std::size_t(w) * std::size_t(channels) * 2;
    if (channels < 1 || channels > 4 || png_get_rowbytes(png, info) != stride)
        png_error(png, "unsupported pixel layout");
    samples.resize(stride / 2 * std::size_t(h));
    png_bytep rows = reinterpret_cast<png_bytep>(samples.data());
    for (int pass = 0; pass < passes; ++pass)
        for (int y = 0; y < h; ++y) png_read_row(png, rows + std::size_t(y) * stride, nullptr);
    png_destroy_read_struct(&png, &info, nullptr);
    return true;
}

} // namespace

const float* srgb8_decode_table() {
    static const std::array<float, 256> table = [] {
        std::array<float, 256> t{};
        for (int i = 0; i < 256; ++i) t[i] = srgb_to_linear(float(i) / 255.0f);
        return t;
    }();
    return table.data();
}

const float* unorm8_decode_table() {
    static const std::array<float, 256> table = [] {
        std::array<float, 256> t{};
        for (int i = 0; i < 256; ++i) t[i] = float(i) / 255.0f;
        return t;
    }();
    return table.data();
}

namespace {

// Twice the densest JPEG possible (512 texels a byte, see decode_image).
constexpr std::int64_t kMaxJpegTexelsPerByte = 1024;

// Deflate's densest output: a 258-byte match costs at least 2 bits (a
// length and a distance code), so 1032 bytes per compressed byte.
constexpr std::int64_t kMaxDeflateRatio = 1032;

// "" when every chunk of a PNG lies within the file and its IDAT chunks can
// hold the pixels its header claims; else why not. Checked before any decoder allocates the image: a 100-byte file
// claiming 16384x16384 texels would otherwise cost a gigabyte of zeroed
// memory before failing as truncated. The filtered rows hold at least
// w * h * bits / 8 bytes (interlaced or not), and no more than
// kMaxDeflateRatio bytes come from each compressed one.
std::string png_data_shortfall(const unsigned char* data, std::size_t size, int w, int h) {
    if (size < 8 + 25) return "";  // the decoders name a short file
    const unsigned char* ihdr = data + 16;
    static const int kSamples[7] = {1, 0, 3, 1, 2, 0, 4};
    const int depth = ihdr[8], colour = ihdr[9];
    if (colour > 6 || !kSamples[colour] || depth < 1 || depth > 16) return "";  // refused by the decoders
    const std::int64_t bits = std::int64_t(kSamples[colour]) * depth;
    const std::int64_t need = std::int64_t(w) * std::int64_t(h) * bits / 8;
    std::int64_t idat = 0;
    // A chunk header (length and type) is 8 bytes: stb_image reads those and
    // grows its buffer before it looks for the data and CRC, so a header that
    // fits with its data cut off is refused as well.
    for (std::size_t pos = 8; pos + 8 <= size;) {
        const std::uint32_t len = be32(data + pos);
        const std::string type = printable(std::string(reinterpret_cast<const char*>(data + pos + 4), 4));
        // A chunk past the end of the file: stb_image 2.27 grows its buffer
        // to the claimed length first (up to 4 GiB for one 16-bit file).
        const std::size_t left = size - pos - 8;  // after the header
        if (left < 4 || len > left - 4)
            return "truncated: the " + type + " chunk at byte " + std::to_string(pos) + " claims " +
                   std::to_string(len) + " bytes, " + std::to_string(left < 4 ? 0 : left - 4) + " are left";
        if (type == "IDAT") idat += len;
        if (type == "IEND") break;
        pos += 12 + std::size_t(len);
    }
    if (need <= kMaxDeflateRatio * idat + 1024) return "";
    return std::to_string(w) + "x" + std::to_string(h) + " texels need at least " + std::to_string(need) +
           " bytes of pixel data, and " + std::to_string(idat) + " compressed bytes hold at most " +
           std::to_string(kMaxDeflateRatio * idat + 1024);
}

// "" when stb_image 2.27 may see these bytes; else "cannot decode FORMAT
// image: why".
std::string stb_unsafe(const unsigned char* data, std::size_t size) {
    if (!looks_like_hdr(data, size)) return "";
    int w = 0, h = 0;
    const std::string why = check_hdr_data(data, size, w, h);
    return why.empty() ? why : "cannot decode HDR image: " + why;
}

// A PNG's IHDR (ISO 15948 11.2.2), when it is the first chunk and its fields
// are a valid combination; `channels` counts the alpha a tRNS chunk before the
// pixel data adds (a palette's entries are RGB).
struct PngHeader {
    std::uint32_t width = 0, height = 0;
    int depth = 0, colour = 0, channels = 0;
};

bool read_png_ihdr(const unsigned char* data, std::size_t size, PngHeader& out) {
    if (!is_png(data, size) || size < 8 + 25 || be32(data + 8) != 13 || std::memcmp(data + 12, "IHDR", 4) != 0)
        return false;
    const unsigned char* d = data + 16;
    PngHeader p;
    p.width = be32(d);
    p.height = be32(d + 4);
    p.depth = d[8];
    p.colour = d[9];
    if (p.width == 0 || p.height == 0 || p.width > 0x7FFFFFFFu || p.height > 0x7FFFFFFFu) return false;
    if (d[10] != 0 || d[11] != 0 || d[12] > 1) return false;  // compression, filter, interlace methods
    const bool small_depth = p.depth == 1 || p.depth == 2 || p.depth == 4;
    switch (p.colour) {
    case 0: p.channels = 1; if (!small_depth && p.depth != 8 && p.depth != 16) return false; break;
    case 3: p.channels = 3; if (!small_depth && p.depth != 8) return false; break;
    case 2: case 4: case 6:
        p.channels = p.colour == 2 ? 3 : p.colour == 4 ? 2 : 4;
        if (p.depth != 8 && p.depth != 16) return false;
        break;
    default: return false;
    }
    for (std::size_t pos = 33; pos + 12 <= size;) {
        const std::uint32_t len = be32(data + pos);
        const unsigned char* type = data + pos + 4;
        if (std::memcmp(type, "IDAT", 4) == 0) break;
        if (std::memcmp(type, "tRNS", 4) == 0 && (p.colour == 0 || p.colour == 2 || p.colour == 3)) {
            ++p.channels;
            break;
        }
        if (len > size - pos - 12) break;
        pos += 12 + std::size_t(len);
    }
    out = p;
    return true;
}

// True when stb_image 2.27's header scan refuses this PNG by its size alone:
// a side beyond kMaxStbImageSide, or more than 2^30 samples (a palette
// counted as 4).
bool stb_refuses_png_size(const PngHeader& p) {
    if (p.width > std::uint32_t(kMaxStbImageSide) || p.height > std::uint32_t(kMaxStbImageSide)) return true;
    const std::uint32_t samples = p.colour == 3 ? 4 : std::uint32_t(p.colour & 2 ? 3 : 1) + (p.colour & 4 ? 1 : 0);
    return (std::uint32_t(1) << 30) / p.width / samples < p.height;
}

// What an image's header says, checked as decode_image() needs it.
struct ImageHeader {
    int width = 0, height = 0, channels = 0;
    bool hdr = false, sixteen_bit = false;
    bool jpeg = false;         // read by libjpeg-turbo, which decodes it
    int jpeg_colorspace = -1;  // TJCS_*
    bool png_by_ihdr = false;  // read from the IHDR: stb_image refuses its size, libpng decodes it
};

// True when the bytes start like a JPEG as stb_image tells one (0xFF, any fill
// 0xFFs, 0xD8): such data goes to libjpeg-turbo, never to stb_image.
bool looks_like_jpeg(const unsigned char* data, std::size_t size) {
    std::size_t i = 0;
    if (size == 0 || data[0] != 0xFF) return false;
    while (i < size && data[i] == 0xFF) ++i;
    return i < size && data[i] == 0xD8;
}

// A TurboJPEG decompressor, destroyed on every path out.
struct TjHandle {
    tjhandle h = tjInitDecompress();
    ~TjHandle() {
        if (h) tjDestroy(h);
    }
};

// "" with the size, channels (1 grey, else 3: RGB, CMYK and YCCK files become
// RGB) and colour space of a JPEG filled in; else the decoder's reason.
std::string read_jpeg_header(const unsigned char* data, std::size_t size, ImageHeader& hd) {
    TjHandle tj;
    if (!tj.h) return "cannot start the decoder";
    if (size > std::size_t(ULONG_MAX)) return "too large";
    int w = 0, h = 0, subsamp = 0, colorspace = 0;
    if (tjDecompressHeader3(tj.h, data, static_cast<unsigned long>(size), &w, &h, &subsamp, &colorspace) != 0)
        return printable(tjGetErrorStr2(tj.h));
    if (w <= 0 || h <= 0) return "bad image size (" + std::to_string(w) + "x" + std::to_string(h) + ") in the header";
    hd.width = w;
    hd.height = h;
    hd.channels = colorspace == TJCS_GRAY ? 1 : 3;
    hd.jpeg = true;
    hd.jpeg_colorspace = colorspace;
    return "";
}

// Decodes a JPEG whose header `hd` read, into img's bytes; "" or the reason.
// The inverse DCT is the accurate integer one (libjpeg's default, as
// stb_image's was). Progressive files are limited to 500 scans (a file of
// thousands of tiny scans costs minutes). A warning (corrupt or truncated
// entropy-coded data) still leaves a whole image, which is kept, as stb_image
// and browsers keep it.
std::string decode_jpeg(const unsigned char* data, std::size_t size, const ImageHeader& hd, Image& img) {
    TjHandle tj;
    if (!tj.h) return "cannot start the decoder";
    const bool cmyk = hd.jpeg_colorspace == TJCS_CMYK || hd.jpeg_colorspace == TJCS_YCCK;
    const int format = hd.channels == 1 ? TJPF_GRAY : cmyk ? TJPF_CMYK : TJPF_RGB;
    const std::size_t out_channels = cmyk ? 4 : std::size_t(hd.channels);
    const std::size_t count = std::size_t(hd.width) * std::size_t(hd.height);
    // Into img's own buffer (and the room it has reserved) unless CMYK.
    std::vector<std::uint8_t> cmyk_px;
    std::vector<std::uint8_t>& px = cmyk ? cmyk_px : img.pixels;
    px.resize(count * out_channels);
    if (tjDecompress2(tj.h, data, static_cast<unsigned long>(size), px.data(), hd.width,
                      int(std::size_t(hd.width) * out_channels), hd.height, format,
                      TJFLAG_ACCURATEDCT | TJFLAG_LIMITSCANS) != 0 &&
        tjGetErrorCode(tj.h) != TJERR_WARNING)
        return printable(tjGetErrorStr2(tj.h));
    img.width = hd.width;
    img.height = hd.height;
    img.channels = hd.channels;
    if (!cmyk) return "";
    // Adobe's CMYK is stored inverted (255 = no ink): each colour is its
    // value scaled by K, x * k / 255 rounded.
    img.pixels.resize(count * 3);
    for (std::size_t i = 0; i < count; ++i) {
        const unsigned k = px[i * 4 + 3];
        for (std::size_t c = 0; c < 3; ++c) {
            const unsigned t = unsigned(px[i * 4 + c]) * k + 128u;
            img.pixels[i * 3 + c] = std::uint8_t((t + (t >> 8)) >> 8);
        }
    }
    return "";
}

// "" with `hd` filled when the bytes (all of a file of `file_size` bytes, or
// its first ones) have a header that decode_image() goes on to decode; else
// the reason, the message after "NAME: ". Every value stbi_info() gives is
// checked before use: stb 2.27 returns a top-down BMP's height negative, and
// a Radiance or PNM size as whatever its integer parse made of the text.
std::string read_image_header(const unsigned char* data, std::size_t size, std::uint64_t file_size,
                              ImageHeader& hd) {
    const int len = int(std::min<std::size_t>(size, std::size_t(INT_MAX)));
    const char* format = sniff_format(data, size);
    int w = 0, h = 0, comp = 0;
    if (looks_like_jpeg(data, size)) {
        const std::string why = read_jpeg_header(data, size, hd);
        if (!why.empty()) return "cannot decode JPEG image: " + why;
    } else if (!stbi_info_from_memory(data, len, &w, &h, &comp)) {
        const std::string reason = stbi_reason();
        PngHeader png;
        if (read_png_ihdr(data, size, png) && stb_refuses_png_size(png)) {
            const std::int64_t texels = std::int64_t(png.width) * std::int64_t(png.height);
            if (texels > kMaxImageTexels)
                return "image too large: " + std::to_string(png.width) + "x" + std::to_string(png.height) + " = " +
                       std::to_string(texels) + " texels, more than the limit of " + std::to_string(kMaxImageTexels) +
                       " (2^28)";
            hd.width = int(png.width);
            hd.height = int(png.height);
            hd.channels = png.channels;
            hd.sixteen_bit = png.depth == 16;
            hd.png_by_ihdr = true;
        } else {
            if (!format) return "not an image file stb_image can read (" + reason + ")";
            return std::string("cannot decode ") + format + " image: " +
                   (reason == "unknown image type" ? "corrupt or truncated header" : reason);
        }
    } else {
        // A BMP with a negative height stores its rows top-down; stbi_load
        // puts row 0 on top for either order.
        if (format && std::strcmp(format, "BMP") == 0 && h < 0 && h != INT_MIN) h = -h;
        if (w <= 0 || h <= 0) {
            const std::string size_text = "(" + std::to_string(w) + "x" + std::to_string(h) + ")";
            if (w == 0 || h == 0) return "image has zero size " + size_text;
            return "bad image size " + size_text + " in the header";
        }
        if (comp < 1 || comp > 4) return "unsupported channel count " + std::to_string(comp) + " in the header";
        hd.width = w;
        hd.height = h;
        hd.channels = comp;
        hd.hdr = stbi_is_hdr_from_memory(data, len) != 0;
        hd.sixteen_bit = stbi_is_16_bit_from_memory(data, len) != 0;
    }
    w = hd.width;
    h = hd.height;
    const std::int64_t texels = std::int64_t(w) * std::int64_t(h);
    if (texels > kMaxImageTexels)
        return "image too large: " + std::to_string(w) + "x" + std::to_string(h) + " = " + std::to_string(texels) +
               " texels, more than the limit of " + std::to_string(kMaxImageTexels) + " (2^28)";
    if (!hd.png_by_ihdr && !hd.jpeg && (w > kMaxStbImageSide || h > kMaxStbImageSide))
        return std::string("image too large: ") + std::to_string(w) + "x" + std::to_string(h) + ", more than " +
               std::to_string(kMaxStbImageSide) + " pixels a side (" + (format ? format : "this format") +
               " images are decoded by stb_image)";
    // A JPEG needs at least a bit per 8x8 block (a progressive DC scan), so
    // no file holds more than 512 texels a byte; a small file that claims
    // more would keep the decoder filling made-up data for seconds.
    if (looks_like_jpeg(data, size) && std::uint64_t(texels) > std::uint64_t(kMaxJpegTexelsPerByte) * file_size)
        return "cannot decode JPEG image: " + std::to_string(w) + "x" + std::to_string(h) + " texels from only " +
               std::to_string(file_size) + " bytes (a JPEG holds at most " + std::to_string(kMaxJpegTexelsPerByte) +
               " texels a byte)";
    return "";
}

} // namespace

Image decode_image(const ImageSource& src, bool srgb, PixelCapacity capacity) {
    const std::string name = printable(!src.name.empty()   ? src.name
                                       : !src.path.empty() ? src.path
                                                           : std::string("<embedded image>"));
    // Get the encoded bytes: embedded ones win over the path.
    HugeBytes file_bytes;
    const stbi_uc* data = src.bytes.data();
    std::size_t size = src.bytes.size();
    if (src.bytes.empty()) {
        if (src.path.empty()) throw LoadError(name + ": no image data (no path, no bytes)");
        // Only a regular file, never past what stb_image's int length takes.
        read_regular_file(src.path, std::uint64_t(INT_MAX), name, file_bytes);
        data = file_bytes.data();
        size = file_bytes.size();
    }
    if (size > std::size_t(INT_MAX)) throw LoadError(name + ": image data too large");
    const int len = int(size);

    if (is_webp(data, size)) {
        // Its header's size is checked before libwebp allocates anything.
        Image img;
        const std::string refused = webp_header(data, size, size, img.width, img.height, img.channels);
        if (!refused.empty()) throw LoadError(name + ": " + refused);
        const std::size_t row = std::size_t(img.width) * std::size_t(img.channels);
        img.pixels.resize(row * std::size_t(img.height));
        const std::uint8_t* ok = img.channels == 4
            ? WebPDecodeRGBAInto(data, size, img.pixels.data(), img.pixels.size(), int(row))
            : WebPDecodeRGBInto(data, size, img.pixels.data(), img.pixels.size(), int(row));
        if (!ok) throw LoadError(name + ": cannot decode WebP image: corrupt or truncated data");
        img.srgb = srgb;
        return img;
    }

    // Through the guard first: stb_image 2.27 can hang on Radiance data
    // (scene/hdr_guard.h).
    const std::string unsafe = stb_unsafe(data, size);
    if (!unsafe.empty()) throw LoadError(name + ": " + unsafe);

    // Check the header before decoding anything: refuse absurd sizes up front.
    ImageHeader header;
    const std::string refused = read_image_header(data, size, size, header);
    if (!refused.empty()) throw LoadError(name + ": " + refused);
    const int w = header.width, h = header.height;
    const std::int64_t texels = std::int64_t(w) * std::int64_t(h);

    if (is_png(data, size)) {
        const std::string shortfall = png_data_shortfall(data, size, w, h);
        if (!shortfall.empty()) throw LoadError(name + ": cannot decode PNG image: " + shortfall);
    }

    // Decode with the file's own channel count.
    struct StbiFree {
        void operator()(void* p) const { stbi_image_free(p); }
    };
    Image img;
    int dw = 0, dh = 0, dcomp = 0;
    auto check = [&](const void* pixels) {
        if (!pixels) {
            const char* format = sniff_format(data, size);
            throw LoadError(name + ": cannot decode " + (format ? format : "") + (format ? " " : "") +
                            "image: " + stbi_reason());
        }
        if (dw != w || dh != h || dcomp < 1 || dcomp > 4)
            throw LoadError(name + ": inconsistent image header");
        img.width = w;
        img.height = h;
    };
    const std::size_t count = std::size_t(texels);
    const auto unit = [](float c) { return c; };
    if (header.png_by_ihdr && header.sixteen_bit) {
        std::vector<std::uint16_t> values;
        int channels = 0;
        PngSource png{data, size, 0, {0}};
        if (!decode_png16(png, w, h, values, channels))
            throw LoadError(name + ": cannot decode PNG image: " + png.error);
        img.width = w;
        img.height = h;
        img.rgba.resize(count * 4);
        const auto linear = [](stbi_us c) { return float(c) / 65535.0f; };
        const auto decode = [](stbi_us c) { return srgb_to_linear(float(c) / 65535.0f); };
        if (srgb) expand_to_rgba(values.data(), channels, count, img.rgba.data(), decode, linear);
        else expand_to_rgba(values.data(), channels, count, img.rgba.data(), linear, linear);
    } else if (header.hdr) {
        // Radiance HDR: linear floats, kept as is whatever `srgb` says.
        std::unique_ptr<float, StbiFree> px(stbi_loadf_from_memory(data, len, &dw, &dh, &dcomp, 0));
        check(px.get());
        img.rgba.resize(count * 4);
        expand_to_rgba(px.get(), dcomp, count, img.rgba.data(), unit, unit);
    } else if (header.sixteen_bit) {
        std::unique_ptr<stbi_us, StbiFree> px(stbi_load_16_from_memory(data, len, &dw, &dh, &dcomp, 0));
        check(px.get());
        img.rgba.resize(count * 4);
        const auto linear = [](stbi_us c) { return float(c) / 65535.0f; };
        const auto decode = [](stbi_us c) { return srgb_to_linear(float(c) / 65535.0f); };
        if (srgb) expand_to_rgba(px.get(), dcomp, count, img.rgba.data(), decode, linear);
        else expand_to_rgba(px.get(), dcomp, count, img.rgba.data(), linear, linear);
    } else if (header.jpeg) {
        if (capacity) reserve_huge(img.pixels, capacity(w, h, header.channels));
        const std::string why = decode_jpeg(data, size, header, img);
        if (!why.empty()) throw LoadError(name + ": cannot decode JPEG image: " + why);
        img.srgb = srgb;
    } else if (is_png(data, size)) {
        // 8-bit PNG: the bytes as the file has them; sampling decodes them.
        std::string error;
        if (capacity) reserve_huge(img.pixels, capacity(w, h, header.channels));
        const FastPng fast = decode_png_fast(data, size, w, h, img, error);
        if (fast == FastPng::Failed) throw LoadError(name + ": cannot decode PNG image: " + error);
        if (fast == FastPng::NotMine) {
            img = Image();
            PngSource png{data, size, 0, {0}};
            if (!decode_png8(png, w, h, img)) throw LoadError(name + ": cannot decode PNG image: " + png.error);
        }
        img.srgb = srgb;
    } else {
        // 8-bit: the bytes as the file has them; sampling decodes them.
        std::unique_ptr<stbi_uc, StbiFree> px(stbi_load_from_memory(data, len, &dw, &dh, &dcomp, 0));
        check(px.get());
        img.channels = dcomp;
        img.srgb = srgb;
        img.pixels.assign(px.get(), px.get() + count * std::size_t(dcomp));
    }
    return img;
}

bool image_dimensions(const ImageSource& src, int& width, int& height, int* bytes_per_texel) {
    width = height = 0;
    // The header is within the first MiB of any file the project reads (a
    // JPEG's frame header follows its EXIF and ICC segments, 64 KiB each).
    constexpr std::size_t kHeaderBytes = std::size_t(1) << 20;
    std::vector<unsigned char> head;
    const std::vector<unsigned char>* bytes = &src.bytes;
    std::uint64_t file_size = src.bytes.size();
    if (src.bytes.empty()) {
        if (src.path.empty()) return false;
        std::uint64_t size = 0;
        int fd = -1;
        try {
            fd = open_regular_file(src.path, src.name, size);
        } catch (const LoadError&) {
            return false;
        }
        file_size = size;
        head.resize(std::size_t(std::min<std::uint64_t>(size, kHeaderBytes)));
        std::size_t got = 0;
        while (got < head.size()) {
            const ssize_t n = ::read(fd, head.data() + got, head.size() - got);
            if (n < 0 && errno == EINTR) continue;
            if (n <= 0) break;
            got += std::size_t(n);
        }
        ::close(fd);
        head.resize(got);
        bytes = &head;
    }
    if (bytes->empty() || bytes->size() > std::size_t(INT_MAX)) return false;
    const stbi_uc* data = bytes->data();
    if (is_webp(data, bytes->size())) {
        int w = 0, h = 0, channels = 0;
        if (!webp_header(data, bytes->size(), file_size, w, h, channels).empty()) return false;
        width = w;
        height = h;
        if (bytes_per_texel) *bytes_per_texel = channels;
        return true;
    }
    // A Radiance header alone is safe for stbi_info, and its pixels are
    // beyond the prefix read here: no guard needed.
    // Only a size the decoder goes on to decode: one it refuses is a warning
    // when decoded, never part of the plan.
    ImageHeader header;
    if (!read_image_header(data, bytes->size(), file_size, header).empty()) return false;
    // A small PNG whose header claims more pixels than its data can hold is
    // refused as well (a model may name many); a large one is only read here
    // as far as its header.
    if (bytes->size() == file_size && is_png(data, bytes->size()) &&
        !png_data_shortfall(data, bytes->size(), header.width, header.height).empty())
        return false;
    width = header.width;
    height = header.height;
    if (bytes_per_texel) *bytes_per_texel = header.hdr || header.sixteen_bit ? 16 : header.channels;
    return true;
}

} // namespace prast

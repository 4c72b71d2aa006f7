// prast-diff: compares two 8-bit images for pixel tests (issue 7). Parses the
// command line, reads both images and prints scene/image_diff.h's report;
// the comparison itself lives in the library.
//
// Exit codes: 0 the images match within the tolerance, 1 they differ (also
// when their sizes differ: a test that suddenly renders at another size has
// failed, it was not called wrongly), 2 usage and I/O errors (bad flags, an
// image that cannot be read, a heat map that cannot be written).
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <string>
#include <vector>

#include "scene/image_diff.h"
#include "scene/scene.h"
#include "scene/write_image.h"

using namespace prast;

namespace {

constexpr int kExitMatch = 0;
constexpr int kExitDiffer = 1;
constexpr int kExitUsage = 2;

#ifndef PRAST_VERSION
#define PRAST_VERSION "unknown"
#endif

const char* kUsage =
    "usage: prast-diff A.png B.png [--tolerance T] [--max-fraction F] [--heatmap OUT.png]\n"
    "  --tolerance T      a channel may differ by up to T (8-bit units, 0..255; default 0)\n"
    "  --max-fraction F   at most floor(F * pixels) pixels may exceed T (0..1; default 0)\n"
    "  --heatmap OUT.png  write where the images differ: grey = equal (image A dimmed),\n"
    "                     blue = within T, red to yellow = beyond T; green = the difference\n"
    "  --help, --version\n"
    "prints psnr, the largest difference, the differing pixels and their bounding box\n"
    "exit codes: 0 match, 1 differ (or sizes differ), 2 bad usage or unreadable image\n";

int usage_error(const std::string& message) {
    std::fprintf(stderr, "prast-diff: %s (see prast-diff --help)\n", message.c_str());
    return kExitUsage;
}

bool parse_int(const std::string& s, int lo, int hi, int& out) {
    if (s.empty()) return false;
    char* end = nullptr;
    errno = 0;
    const long v = std::strtol(s.c_str(), &end, 10);
    if (errno || *end || v < lo || v > hi) return false;
    out = int(v);
    return true;
}

bool parse_fraction(const std::string& s, double& out) {
    if (s.empty()) return false;
    char* end = nullptr;
    errno = 0;
    const double v = std::strtod(s.c_str(), &end);
    if (errno || *end || !std::isfinite(v) || v < 0.0 || v > 1.0) return false;
    out = v;
    return true;
}

} // namespace

int main(int argc, char** argv) {
    std::vector<std::string> files;
    DiffTolerance tol;
    std::string heatmap;
    bool options_done = false;  // after "--" every argument is a file
    for (int i = 1; i < argc; ++i) {
        const std::string arg = argv[i];
        if (options_done) {
            files.push_back(arg);
            continue;
        }
        if (arg == "--") {
            options_done = true;
            continue;
        }
        if (arg == "--help" || arg == "-h") {
            std::fputs(kUsage, stdout);
            return kExitMatch;
        }
        if (arg == "--version") {
            std::printf("prast-diff %s\n", PRAST_VERSION);
            return kExitMatch;
        }
        if (arg == "--tolerance" || arg == "--max-fraction" || arg == "--heatmap") {
            if (i + 1 >= argc) return usage_error(arg + " needs a value");
            const std::string value = argv[++i];
            if (arg == "--tolerance" && !parse_int(value, 0, 255, tol.channel))
                return usage_error("--tolerance '" + value + "': expected an integer from 0 to 255");
            if (arg == "--max-fraction" && !parse_fraction(value, tol.fraction))
                return usage_error("--max-fraction '" + value + "': expected a number from 0 to 1");
            if (arg == "--heatmap") {
                if (value.empty()) return usage_error("--heatmap needs a file name");
                heatmap = value;
            }
            continue;
        }
        if (arg.size() > 1 && arg[0] == '-') return usage_error("unknown option '" + arg + "'");
        files.push_back(arg);
    }
    if (files.size() != 2)
        return usage_error("expected two images, got " + std::to_string(files.size()));

    Image8 a, b;
    try {
        a = read_image8(files[0]);
        b = read_image8(files[1]);
    } catch (const LoadError& e) {
        std::fprintf(stderr, "prast-diff: %s\n", e.what());
        return kExitUsage;
    }
    if (a.width != b.width || a.height != b.height) {
        std::fprintf(stderr, "prast-diff: sizes differ: %s is %dx%d, %s is %dx%d%s\n", files[0].c_str(), a.width,
                     a.height, files[1].c_str(), b.width, b.height, heatmap.empty() ? "" : " (no heat map written)");
        std::printf("result: differ (sizes differ)\n");
        return kExitDiffer;
    }

    const DiffResult r = diff_images(a, b, tol);
    std::printf("%s vs %s\n%s", files[0].c_str(), files[1].c_str(), format_diff(r, tol).c_str());
    if (!heatmap.empty()) {
        try {
            const std::vector<std::uint8_t> heat = diff_heatmap(a, b, tol);
            write_png_atomic(heatmap, a.width, a.height, heat.data());
        } catch (const std::exception& e) {
            std::fprintf(stderr, "prast-diff: %s\n", e.what());
            return kExitUsage;
        }
    }
    return r.match ? kExitMatch : kExitDiffer;
}

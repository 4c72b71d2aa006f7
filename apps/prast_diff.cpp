// prast-diff: compares two 8-bit images for pixel tests. Parses the command
// line (apps/cli/diff_flags.h), reads both images and prints
// scene/image_diff.h's report; the comparison itself lives in the library.
//
// Exit codes: 0 the images match within the tolerance, 1 they differ (also
// when their sizes differ: a test that suddenly renders at another size has
// failed, it was not called wrongly), 2 usage and I/O errors (bad flags, an
// image that cannot be read, a heat map that cannot be written).
#include <cstdio>
#include <exception>
#include <string>
#include <vector>

#include "apps/cli/diff_flags.h"
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

} // namespace

int main(int argc, char** argv) {
    cli::DiffOptions opt;
    const std::string err = cli::parse_diff_args(argc, argv, opt);
    if (!err.empty()) {
        std::fprintf(stderr, "prast-diff: %s (see prast-diff --help)\n", err.c_str());
        return kExitUsage;
    }
    if (opt.help) {
        std::fputs(cli::diff_usage(), stdout);
        return kExitMatch;
    }
    if (opt.version) {
        std::printf("prast-diff %s\n", PRAST_VERSION);
        return kExitMatch;
    }
    const std::vector<std::string>& files = opt.files;
    const DiffTolerance& tol = opt.tol;
    const std::string& heatmap = opt.heatmap;

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

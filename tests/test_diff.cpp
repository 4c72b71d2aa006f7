// The pixel-test kit: scene/image_diff.h and the prast-diff executable on
// crafted images whose every number is worked out by hand (PSNR, largest
// difference, differing pixels, bounding box, the match decision, the heat
// map), and prast-diff's exit codes and one-line errors.
#include <doctest/doctest.h>

#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include <stb_image.h>
#include <stb_image_write.h>

#include "cli_util.h"
#include "scene/image_diff.h"
#include "scene/scene.h"

using namespace prast;
using prast::cli_test::CliRun;
using prast::cli_test::CliSandbox;

namespace {

// 4 x 3 RGB, every pixel (10, 20, 30).
std::vector<std::uint8_t> flat_rgb() {
    std::vector<std::uint8_t> rgb;
    for (int i = 0; i < 12; ++i) rgb.insert(rgb.end(), {10, 20, 30});
    return rgb;
}

// The same with pixel (1, 0) red +3 and pixel (2, 2) blue -10. By hand:
// squared differences 9 + 100 = 109 over 12 * 3 = 36 samples, mse 3.02778,
// PSNR 10 log10(255^2 / 3.02778) = 43.32 dB; largest difference 10 at (2, 2).
std::vector<std::uint8_t> crafted_rgb() {
    std::vector<std::uint8_t> rgb = flat_rgb();
    rgb[(0 * 4 + 1) * 3 + 0] = 13;
    rgb[(2 * 4 + 2) * 3 + 2] = 20;
    return rgb;
}

void write_png(const std::string& path, int w, int h, int comp, const std::vector<std::uint8_t>& px) {
    REQUIRE(stbi_write_png(path.c_str(), w, h, comp, px.data(), w * comp) != 0);
}

std::string line_starting(const std::string& text, const std::string& prefix) {
    for (const std::string& l : cli_test::lines_of(text))
        if (l.compare(0, prefix.size(), prefix) == 0) return l;
    return "";
}

// Writes a.png (flat) and b.png (crafted) into the sandbox.
void write_pair(const CliSandbox& box) {
    write_png(box.path("a.png"), 4, 3, 3, flat_rgb());
    write_png(box.path("b.png"), 4, 3, 3, crafted_rgb());
}

CliRun diff(const CliSandbox& box, const std::vector<std::string>& args) {
    return box.run_exe(PRAST_DIFF_EXE, args);
}

} // namespace

TEST_SUITE("diff") {

TEST_CASE("identical images: psnr inf, nothing differs, match") {
    const std::vector<std::uint8_t> px = flat_rgb();
    const Image8 a = Image8::from_rgb(4, 3, px.data());
    const DiffResult r = diff_images(a, a, {});
    CHECK(std::isinf(r.psnr_db));
    CHECK(r.mse == 0.0);
    CHECK(r.max_diff == 0);
    CHECK(r.max_x == -1);
    CHECK(r.differing == 0);
    CHECK(r.box_x0 == -1);
    CHECK(r.match);
    CHECK(format_diff(r, {}) ==
          "size: 4x3, RGB\n"
          "psnr: inf dB\n"
          "max difference: 0\n"
          "differing pixels: 0 of 12 (fraction 0.000000) above tolerance 0\n"
          "bounding box: none\n"
          "result: match (at most 0 pixels may exceed tolerance 0)\n");
}

TEST_CASE("crafted images: every number worked out by hand") {
    const std::vector<std::uint8_t> pa = flat_rgb(), pb = crafted_rgb();
    const Image8 a = Image8::from_rgb(4, 3, pa.data()), b = Image8::from_rgb(4, 3, pb.data());

    SUBCASE("tolerance 0: both changed pixels differ") {
        const DiffResult r = diff_images(a, b, {0, 0.0});
        CHECK(r.channels == 3);
        CHECK(r.mse == doctest::Approx(109.0 / 36.0).epsilon(1e-12));
        CHECK(r.psnr_db == doctest::Approx(10.0 * std::log10(65025.0 * 36.0 / 109.0)).epsilon(1e-12));
        CHECK(r.max_diff == 10);
        CHECK(r.max_x == 2);
        CHECK(r.max_y == 2);
        CHECK(r.differing == 2);
        CHECK(r.differing_fraction == doctest::Approx(2.0 / 12.0));
        CHECK(r.box_x0 == 1);
        CHECK(r.box_y0 == 0);
        CHECK(r.box_x1 == 2);
        CHECK(r.box_y1 == 2);
        CHECK(r.allowed == 0);
        CHECK_FALSE(r.match);
        CHECK(format_diff(r, {0, 0.0}) ==
              "size: 4x3, RGB\n"
              "psnr: 43.32 dB\n"
              "max difference: 10 at 2,2\n"
              "differing pixels: 2 of 12 (fraction 0.166667) above tolerance 0\n"
              "bounding box: 1,0 to 2,2 (2x3)\n"
              "result: differ (at most 0 pixels may exceed tolerance 0)\n");
    }
    SUBCASE("tolerance 3: the +3 pixel is equal, the -10 one differs") {
        const DiffResult r = diff_images(a, b, {3, 0.0});
        CHECK(r.differing == 1);
        CHECK(r.box_x0 == 2);
        CHECK(r.box_y0 == 2);
        CHECK(r.box_x1 == 2);
        CHECK(r.box_y1 == 2);
        CHECK(r.max_diff == 10);  // the numbers do not depend on the tolerance
        CHECK_FALSE(r.match);
        // floor(0.1 * 12) = 1 pixel may exceed: match; floor(0.05 * 12) = 0: differ.
        CHECK(diff_images(a, b, {3, 0.1}).match);
        CHECK(diff_images(a, b, {3, 0.1}).allowed == 1);
        CHECK_FALSE(diff_images(a, b, {3, 0.05}).match);
    }
    SUBCASE("tolerance 10: nothing exceeds it") {
        const DiffResult r = diff_images(a, b, {10, 0.0});
        CHECK(r.differing == 0);
        CHECK(r.box_x0 == -1);
        CHECK(r.match);
        CHECK(r.max_diff == 10);
    }
    SUBCASE("a fraction F of N pixels allows floor(F N), with F N exact at integers") {
        std::vector<std::uint8_t> big_a(1000 * 3, 0), big_b(1000 * 3, 0);
        big_b[0] = 1;
        const Image8 x = Image8::from_rgb(1000, 1, big_a.data()), y = Image8::from_rgb(1000, 1, big_b.data());
        CHECK(diff_images(x, y, {0, 0.001}).allowed == 1);
        CHECK(diff_images(x, y, {0, 0.001}).match);
        CHECK_FALSE(diff_images(x, y, {0, 0.000999}).match);
    }
    SUBCASE("sizes must agree") {
        const Image8 c = Image8::from_rgb(3, 4, pa.data());
        CHECK_THROWS_AS(diff_images(a, c, {}), std::invalid_argument);
    }
}

TEST_CASE("alpha is compared when either image has it") {
    const std::vector<std::uint8_t> pa = {0, 0, 0, 255, 100, 100, 100, 255};
    const std::vector<std::uint8_t> pb = {0, 0, 0, 255, 100, 100, 100, 200};
    const Image8 a = Image8::from_rgba(2, 1, pa.data(), true), b = Image8::from_rgba(2, 1, pb.data(), true);
    const DiffResult r = diff_images(a, b, {});
    // 55^2 over 2 * 4 samples: mse 378.125, PSNR 10 log10(65025 / 378.125) = 22.35 dB.
    CHECK(r.channels == 4);
    CHECK(r.mse == doctest::Approx(378.125));
    CHECK(line_starting(format_diff(r, {}), "psnr:") == "psnr: 22.35 dB");
    CHECK(r.max_diff == 55);
    CHECK(r.max_x == 1);
    // Without alpha the same pixels are equal (alpha is forced to 255 and not compared).
    const Image8 a3 = Image8::from_rgba(2, 1, pa.data(), false), b3 = Image8::from_rgba(2, 1, pb.data(), false);
    CHECK(diff_images(a3, b3, {}).channels == 3);
    CHECK(diff_images(a3, b3, {}).match);
}

TEST_CASE("heat map: grey where equal, blue within tolerance, red beyond; green is the difference") {
    const std::vector<std::uint8_t> pa = flat_rgb(), pb = crafted_rgb();
    const Image8 a = Image8::from_rgb(4, 3, pa.data()), b = Image8::from_rgb(4, 3, pb.data());
    const std::vector<std::uint8_t> heat = diff_heatmap(a, b, {3, 0.0});
    REQUIRE(heat.size() == 4u * 3u * 4u);
    auto px = [&](int x, int y) {
        const std::uint8_t* p = &heat[std::size_t(y * 4 + x) * 4];
        return std::vector<int>{p[0], p[1], p[2], p[3]};
    };
    CHECK(px(1, 0) == std::vector<int>{0, 3, 255, 255});   // 3 <= T: blue
    CHECK(px(2, 2) == std::vector<int>{255, 10, 0, 255});  // 10 > T: red
    // Equal pixels: (10 + 20 + 30) / 12 = 5.
    CHECK(px(0, 0) == std::vector<int>{5, 5, 5, 255});
    CHECK(px(3, 2) == std::vector<int>{5, 5, 5, 255});
}

TEST_CASE("read_image8 reads RGB and RGBA PNGs and refuses what it cannot compare") {
    CliSandbox box;
    write_png(box.path("rgb.png"), 4, 3, 3, crafted_rgb());
    const Image8 img = read_image8(box.path("rgb.png"));
    CHECK(img.width == 4);
    CHECK(img.height == 3);
    CHECK_FALSE(img.has_alpha);
    CHECK(int(img.at(1, 0)[0]) == 13);
    CHECK(int(img.at(2, 2)[2]) == 20);
    CHECK(int(img.at(2, 2)[3]) == 255);
    write_png(box.path("rgba.png"), 2, 1, 4, {1, 2, 3, 4, 5, 6, 7, 8});
    const Image8 rgba = read_image8(box.path("rgba.png"));
    CHECK(rgba.has_alpha);
    CHECK(int(rgba.at(1, 0)[3]) == 8);
    CHECK_THROWS_AS(read_image8(box.path("missing.png")), LoadError);
    cli_test::write_text(box.path("junk.png"), "not a png");
    CHECK_THROWS_AS(read_image8(box.path("junk.png")), LoadError);
}

TEST_CASE("prast-diff: exit 0 on a match, 1 on a difference, and the report on stdout") {
    CliSandbox box;
    write_pair(box);

    CliRun same = diff(box, {"a.png", "a.png"});
    CHECK(same.code == 0);
    CHECK(line_starting(same.out, "psnr:") == "psnr: inf dB");
    CHECK(line_starting(same.out, "result:") == "result: match (at most 0 pixels may exceed tolerance 0)");
    CHECK(same.err.empty());

    CliRun differ = diff(box, {"a.png", "b.png"});
    CHECK(differ.code == 1);
    CHECK(differ.out ==
          "a.png vs b.png\n"
          "size: 4x3, RGB\n"
          "psnr: 43.32 dB\n"
          "max difference: 10 at 2,2\n"
          "differing pixels: 2 of 12 (fraction 0.166667) above tolerance 0\n"
          "bounding box: 1,0 to 2,2 (2x3)\n"
          "result: differ (at most 0 pixels may exceed tolerance 0)\n");

    CliRun tolerant = diff(box, {"a.png", "b.png", "--tolerance", "3", "--max-fraction", "0.1"});
    CHECK(tolerant.code == 0);
    CHECK(line_starting(tolerant.out, "differing pixels:") ==
          "differing pixels: 1 of 12 (fraction 0.083333) above tolerance 3");
    CHECK(line_starting(tolerant.out, "bounding box:") == "bounding box: 2,2 to 2,2 (1x1)");
    CHECK(line_starting(tolerant.out, "result:") == "result: match (at most 1 pixels may exceed tolerance 3)");

    CHECK(diff(box, {"a.png", "b.png", "--tolerance", "3", "--max-fraction", "0.05"}).code == 1);
    CHECK(diff(box, {"a.png", "b.png", "--tolerance", "10"}).code == 0);
    CHECK(diff(box, {"--tolerance", "10", "a.png", "b.png"}).code == 0);  // flags anywhere
}

TEST_CASE("prast-diff: different sizes differ (exit 1) with a one-line message") {
    CliSandbox box;
    write_pair(box);
    write_png(box.path("c.png"), 3, 4, 3, flat_rgb());
    CliRun r = diff(box, {"a.png", "c.png", "--heatmap", "heat.png"});
    CHECK(r.code == 1);
    CHECK(r.err == "prast-diff: sizes differ: a.png is 4x3, c.png is 3x4 (no heat map written)\n");
    CHECK(r.out == "result: differ (sizes differ)\n");
    CHECK_FALSE(cli_test::fs::exists(box.path("heat.png")));
}

TEST_CASE("prast-diff: usage and I/O errors exit 2 with one line naming the problem") {
    CliSandbox box;
    write_pair(box);
    cli_test::write_text(box.path("junk.png"), "not a png at all");
    cli_test::fs::create_directories(box.path("dir"));
    {
        // A tiny valid Radiance HDR: refused, it has no 8-bit values.
        const float hdr[3] = {1.0f, 0.5f, 0.25f};
        REQUIRE(stbi_write_hdr(box.path("img.hdr").c_str(), 1, 1, 3, hdr) != 0);
    }
    struct Case {
        std::vector<std::string> args;
        std::string message;  // how stderr's one line starts
    };
    const std::vector<Case> cases = {
        {{}, "prast-diff: expected two images, got 0 (see prast-diff --help)"},
        {{"a.png"}, "prast-diff: expected two images, got 1 (see prast-diff --help)"},
        {{"a.png", "b.png", "a.png"}, "prast-diff: expected two images, got 3 (see prast-diff --help)"},
        {{"a.png", "b.png", "--tolerance"}, "prast-diff: --tolerance needs a value (see prast-diff --help)"},
        {{"a.png", "b.png", "--tolerance", "256"},
         "prast-diff: --tolerance '256': expected an integer from 0 to 255 (see prast-diff --help)"},
        {{"a.png", "b.png", "--tolerance", "-1"},
         "prast-diff: --tolerance '-1': expected an integer from 0 to 255 (see prast-diff --help)"},
        {{"a.png", "b.png", "--tolerance", "1.5"},
         "prast-diff: --tolerance '1.5': expected an integer from 0 to 255 (see prast-diff --help)"},
        {{"a.png", "b.png", "--max-fraction", "1.5"},
         "prast-diff: --max-fraction '1.5': expected a number from 0 to 1 (see prast-diff --help)"},
        {{"a.png", "b.png", "--max-fraction", "nan"},
         "prast-diff: --max-fraction 'nan': expected a number from 0 to 1 (see prast-diff --help)"},
        {{"a.png", "b.png", "--max-fraction", ""},
         "prast-diff: --max-fraction '': expected a number from 0 to 1 (see prast-diff --help)"},
        {{"a.png", "b.png", "--bogus"}, "prast-diff: unknown option '--bogus' (see prast-diff --help)"},
        {{"a.png", "missing.png"}, "prast-diff: missing.png: cannot open file"},
        {{"dir", "a.png"}, "prast-diff: dir: is a directory"},
        {{"a.png", "img.hdr"},
         "prast-diff: img.hdr: is a Radiance HDR image; only 8-bit images (PNG, ...) can be compared"},
    };
    for (const Case& c : cases) {
        std::string joined;
        for (const std::string& a : c.args) joined += " '" + a + "'";
        CAPTURE(joined);
        CliRun r = diff(box, c.args);
        CHECK(r.code == 2);
        CHECK(r.err.rfind(c.message, 0) == 0);
        CHECK(cli_test::lines_of(r.err).size() == 1u);
        CHECK(r.out.empty());
    }
    // Corrupt input: one line naming the file, whatever stb_image's reason.
    CliRun junk = diff(box, {"junk.png", "a.png"});
    CHECK(junk.code == 2);
    CHECK(junk.err.rfind("prast-diff: junk.png: ", 0) == 0);
    CHECK(cli_test::lines_of(junk.err).size() == 1u);
    // A heat map that cannot be written.
    CliRun unwritable = diff(box, {"a.png", "b.png", "--heatmap", "no/such/dir/heat.png"});
    CHECK(unwritable.code == 2);
    CHECK(unwritable.err.rfind("prast-diff: no/such/dir/heat.png: cannot write", 0) == 0);
    // --help is not an error.
    CliRun help = diff(box, {"--help"});
    CHECK(help.code == 0);
    CHECK(help.out.rfind("usage: prast-diff A.png B.png", 0) == 0);
}

TEST_CASE("prast-diff --heatmap writes the heat map, on a match and on a difference") {
    CliSandbox box;
    write_pair(box);
    CliRun r = diff(box, {"a.png", "b.png", "--tolerance", "3", "--heatmap", "heat.png"});
    CHECK(r.code == 1);  // the -10 pixel exceeds 3, and F = 0
    const cli_test::Rgb8 heat = cli_test::load_rgb8(box.path("heat.png"));
    REQUIRE(heat.width == 4);
    REQUIRE(heat.height == 3);
    CHECK(std::vector<int>(heat.at(1, 0), heat.at(1, 0) + 3) == std::vector<int>{0, 3, 255});
    CHECK(std::vector<int>(heat.at(2, 2), heat.at(2, 2) + 3) == std::vector<int>{255, 10, 0});
    CHECK(std::vector<int>(heat.at(0, 1), heat.at(0, 1) + 3) == std::vector<int>{5, 5, 5});
    CHECK(diff(box, {"a.png", "a.png", "--heatmap", "same.png"}).code == 0);
    const cli_test::Rgb8 same = cli_test::load_rgb8(box.path("same.png"));
    REQUIRE_FALSE(same.empty());
    CHECK(same.mean() == doctest::Approx(5.0));
}

} // TEST_SUITE

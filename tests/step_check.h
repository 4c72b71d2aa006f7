// One check that the suites of new shading features share: `step` explains
// pixels of the frame `render` draws with the same flags, each answer's
// srgb8 line equal to render's PNG there, and its `verify` passes.
#pragma once

#include <cstdio>
#include <string>
#include <utility>
#include <vector>

#include <doctest/doctest.h>

#include "tests/cli_util.h"

namespace prast::cli_test {

struct StepAgainstRender {
    CliRun render, step;  // render's run (-o r.png) and step's transcript
    int lit = 0;          // compared pixels the PNG has not black
};

// The pixels (x, y) for x, y = first, first + every, ... inside the frame.
inline StepAgainstRender step_pixels_match_render(const CliSandbox& box, const std::vector<std::string>& flags, int first,
                                                  int every) {
    StepAgainstRender r;
    std::vector<std::string> png_args = flags;
    png_args.insert(png_args.end(), {"-o", "r.png"});
    r.render = box.run_exe(PRAST_RENDER_EXE, png_args);
    INFO(r.render.err);
    REQUIRE(r.render.code == 0);
    const Rgb8 png = load_rgb8(box.path("r.png"));
    REQUIRE(!png.empty());
    std::string commands;
    std::vector<std::pair<int, int>> pixels;
    for (int y = first; y < png.height; y += every)
        for (int x = first; x < png.width; x += every) {
            pixels.push_back({x, y});
            commands += "pixel " + std::to_string(x) + " " + std::to_string(y) + "\n";
        }
    commands += "verify\n";
    r.step = box.run_exe_with_input(PRAST_STEP_EXE, flags, commands);
    const std::string& out = r.step.out;
    INFO(out.substr(0, 4000) << r.step.err);
    REQUIRE(r.step.code == 0);
    CHECK(out.find("verify: ok, all identical") != std::string::npos);
    std::size_t at = 0;
    for (const auto& [x, y] : pixels) {
        at = out.find("srgb8 ", at);
        REQUIRE(at != std::string::npos);
        int c[3] = {-1, -1, -1};
        std::sscanf(out.c_str() + at, "srgb8 %d %d %d", &c[0], &c[1], &c[2]);
        ++at;
        const std::uint8_t* p = png.at(x, y);
        CAPTURE(x);
        CAPTURE(y);
        CHECK(c[0] == int(p[0]));
        CHECK(c[1] == int(p[1]));
        CHECK(c[2] == int(p[2]));
        r.lit += p[0] + p[1] + p[2] > 0;
    }
    return r;
}

} // namespace prast::cli_test

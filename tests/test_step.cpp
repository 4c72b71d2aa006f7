// The `step` executable end to end, through the built binary:
// every explained pixel equals render's output (the 8-bit PNG exactly, the
// linear colour as render's .hdr stores it) over grids of pixels on the
// built-in scene, the tea set and NormalTangentTest; `verify` finds every
// recomputed number equal to the pipeline's; scripted sessions against the
// expected transcripts in tests/step/ (the same for 1 and 2 threads); bad
// commands and bad flags. Core glTF on models the tests write
// (tests/gltf_writer.h): vertex colours, UV set 1 through a NEAREST sampler,
// a skinned model posed at a time, lines and points, each explained, equal to
// render's bytes and verified; render --pixel naming step's winner; the
// frame's environment, ambient and shadows. The views (stepper/views.h):
// draws, draw N, textures, texture ID LEVEL (an 8-bit level's PNG holds the
// image's bytes), vertices N (clip coordinates recomputed from the camera),
// the tile filters and the views' JSON, on the built-in scene and a glTF the
// test writes, with bad input.
//
// Regenerate the transcripts only deliberately, after reading the diff:
//   PRAST_STEP_REGENERATE=1 build/prast_tests -ts=step
#include <doctest/doctest.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <set>
#include <string>
#include <vector>

#include <regex>

#include <nlohmann/json.hpp>

#include "scene/camera.h"
#include "scene/write_image.h"
#include "tests/cli_util.h"
#include "tests/gltf_writer.h"

using namespace prast::cli_test;
using prast::gltf_test::GltfWriter;
using nlohmann::json;

namespace {

const std::string kStep = PRAST_STEP_EXE;
const std::string kRender = PRAST_RENDER_EXE;
const std::string kAssets = PRAST_SHARED_ASSETS;
const std::string kTranscripts = std::string(PRAST_SOURCE_DIR) + "/tests/step/";

// Runs step in the sandbox with `commands` on standard input.
CliRun run_step(CliSandbox& box, const std::vector<std::string>& args, const std::string& commands) {
    return box.run_exe_with_input(kStep, args, commands);
}

// stb_image_write's RGBE encoding and stb_image's decoding of it: what a
// linear colour becomes in render's .hdr.
void rgbe_round_trip(const float in[3], float out[3]) {
    float maxcomp = std::max(in[0], std::max(in[1], in[2]));
    if (maxcomp < 1e-32f) {
        out[0] = out[1] = out[2] = 0.0f;
        return;
    }
    int exponent;
    const float normalize = float(std::frexp(maxcomp, &exponent)) * 256.0f / maxcomp;
    unsigned char rgbe[4] = {(unsigned char)(in[0] * normalize), (unsigned char)(in[1] * normalize),
                             (unsigned char)(in[2] * normalize), (unsigned char)(exponent + 128)};
    const float f1 = float(std::ldexp(1.0f, rgbe[3] - (128 + 8)));
    for (int k = 0; k < 3; ++k) out[k] = float(rgbe[k]) * f1;
}

struct PixelAnswer {
    int srgb[3] = {-1, -1, -1};
    float linear[3] = {0, 0, 0};
    bool background = false;
};

// The answers of a transcript of `pixel` commands, in order.
std::vector<PixelAnswer> pixel_answers(const std::string& out) {
    std::vector<PixelAnswer> answers;
    PixelAnswer cur;
    for (const std::string& l : lines_of(out)) {
        if (l.rfind("no fragment was written", 0) == 0) cur.background = true;
        if (l.rfind("linear (", 0) == 0)
            std::sscanf(l.c_str(), "linear (%f, %f, %f)", &cur.linear[0], &cur.linear[1], &cur.linear[2]);
        if (l.rfind("srgb8 ", 0) == 0) {
            std::sscanf(l.c_str(), "srgb8 %d %d %d", &cur.srgb[0], &cur.srgb[1], &cur.srgb[2]);
            answers.push_back(cur);
            cur = PixelAnswer{};
        }
    }
    return answers;
}

// A grid of pixels over a render: step's srgb8 equals the PNG, its linear
// colour the .hdr (after the same RGBE encoding). Returns the pixels that
// a fragment reached.
int check_pixels_against_render(const std::vector<std::string>& flags, int cols, int rows) {
    CliSandbox box;
    std::vector<std::string> png_args = flags, hdr_args = flags;
    png_args.insert(png_args.end(), {"-o", "r.png"});
    hdr_args.insert(hdr_args.end(), {"-o", "r.hdr"});
    REQUIRE(box.run_exe(kRender, png_args).code == 0);
    REQUIRE(box.run_exe(kRender, hdr_args).code == 0);
    const Rgb8 png = load_rgb8(box.path("r.png"));
    const RgbFloat hdr = load_hdr(box.path("r.hdr"));
    REQUIRE(!png.empty());
    REQUIRE(hdr.width == png.width);
    std::string commands;
    std::vector<std::pair<int, int>> pixels;
    for (int j = 0; j < rows; ++j)
        for (int i = 0; i < cols; ++i) {
            const int x = int((i + 0.5) * png.width / cols) + (j % 3), y = int((j + 0.5) * png.height / rows) + (i % 2);
            pixels.push_back({x, y});
            commands += "pixel " + std::to_string(x) + " " + std::to_string(y) + "\n";
        }
    const CliRun r = run_step(box, flags, commands);
    REQUIRE(r.code == 0);
    const std::vector<PixelAnswer> answers = pixel_answers(r.out);
    REQUIRE(answers.size() == pixels.size());
    int reached = 0;
    for (std::size_t i = 0; i < pixels.size(); ++i) {
        const auto [x, y] = pixels[i];
        const PixelAnswer& a = answers[i];
        const std::uint8_t* p = png.at(x, y);
        INFO("pixel " << x << " " << y);
        CHECK(a.srgb[0] == p[0]);
        CHECK(a.srgb[1] == p[1]);
        CHECK(a.srgb[2] == p[2]);
        float rt[3];
        rgbe_round_trip(a.linear, rt);
        const float* h = &hdr.rgb[(std::size_t(y) * hdr.width + x) * 3];
        CHECK(rt[0] == h[0]);
        CHECK(rt[1] == h[1]);
        CHECK(rt[2] == h[2]);
        reached += !a.background;
    }
    return reached;
}

bool have_asset(const std::string& path) {
    if (std::FILE* f = std::fopen(path.c_str(), "rb")) {
        std::fclose(f);
        return true;
    }
    MESSAGE("skipped: " << path << " is absent (PRAST_SHARED_ASSETS)");
    return false;
}

const std::string kTea = kAssets + "/tea-set-01/gltf/tea_set_01_1k.gltf";
const std::string kNormalTangent = kAssets + "/normal-tangent-test/NormalTangentTest.glb";
const std::vector<std::string> kTeaFlags = {kTea, "--eye", "-0.20,0.20,0.42", "--target", "-0.347,0.065,0.061",
                                            "--fov", "35"};
const std::vector<std::string> kNormalTangentFlags = {kNormalTangent, "--eye", "0,-0.125,3.9", "--target",
                                                      "0,-0.125,0", "--size", "640x480"};

// A scripted session against its expected transcript.
void check_transcript(const std::string& name, const std::vector<std::string>& flags) {
    const std::string commands = read_text(kTranscripts + name + ".cmd");
    REQUIRE(!commands.empty());
    std::string first;
    for (const char* threads : {"1", "2"}) {
        CliSandbox box;
        std::vector<std::string> args = flags;
        args.insert(args.end(), {"--threads", threads});
        const CliRun r = run_step(box, args, commands);
        INFO("stderr: " << r.err);
        if (first.empty()) {
            first = r.out;
        } else {
            CHECK(r.out == first);  // any thread count: the same transcript
        }
    }
    const std::string expected_path = kTranscripts + name + ".txt";
    if (std::getenv("PRAST_STEP_REGENERATE")) write_text(expected_path, first);
    const std::string expected = read_text(expected_path);
    REQUIRE_MESSAGE(!expected.empty(), "missing " << expected_path << " (PRAST_STEP_REGENERATE=1 writes it)");
    const std::vector<std::string> got = lines_of(first), want = lines_of(expected);
    for (std::size_t i = 0; i < std::min(got.size(), want.size()); ++i) {
        INFO("line " << i + 1 << " of " << expected_path);
        REQUIRE(got[i] == want[i]);
    }
    CHECK(got.size() == want.size());
}


// ---- Small glTF models for the core glTF features (tests/gltf_writer.h).

// A quad x, y in [-1, 1] at z = 0 facing +z (two triangles, counter-clockwise
// seen from +z), with normals, UV set 0 over [0, 1]^2 and `extra` attributes.
int add_quad(GltfWriter& g, float z, const json& extra_attributes, int material, bool with_normals = true) {
    const int pos = g.floats({-1, -1, z, 1, -1, z, 1, 1, z, -1, 1, z}, "VEC3", 3);
    json attrs = {{"POSITION", pos}};
    if (with_normals) attrs["NORMAL"] = g.floats({0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1}, "VEC3", 3);
    attrs["TEXCOORD_0"] = g.floats({0, 1, 1, 1, 1, 0, 0, 0}, "VEC2", 2);
    for (auto it = extra_attributes.begin(); it != extra_attributes.end(); ++it) attrs[it.key()] = it.value();
    const int ind = g.u16({0, 1, 2, 0, 2, 3}, "SCALAR", 1);
    g.doc["meshes"].push_back({{"name", "quad" + std::to_string(g.doc["meshes"].size())},
                               {"primitives", json::array({{{"attributes", attrs}, {"indices", ind}, {"material", material}}})}});
    return int(g.doc["meshes"].size()) - 1;
}


std::string write_gltf(CliSandbox& box, const GltfWriter& g, const std::string& name) {
    write_text(box.path(name), g.text());
    return box.path(name);
}

// A 4x4 RGBA checker of four colours (2x2 texels each) as PNG bytes.
std::vector<unsigned char> checker_png() {
    std::vector<std::uint8_t> rgba(4 * 4 * 4);
    const std::uint8_t colours[4][3] = {{255, 0, 0}, {0, 255, 0}, {0, 0, 255}, {255, 255, 0}};
    for (int y = 0; y < 4; ++y)
        for (int x = 0; x < 4; ++x) {
            const std::uint8_t* c = colours[(y / 2) * 2 + x / 2];
            std::uint8_t* p = &rgba[std::size_t(y * 4 + x) * 4];
            p[0] = c[0]; p[1] = c[1]; p[2] = c[2]; p[3] = 255;
        }
    const std::vector<std::uint8_t> png = prast::encode_png(4, 4, rgba.data());
    return std::vector<unsigned char>(png.begin(), png.end());
}

const std::vector<std::string> kQuadView = {"--eye", "0,0,3", "--target", "0,0,0", "--size", "48x36", "--msaa", "1",
                                            "--sun", "0,0,1:1,1,1"};

// Every pixel of `pixels`: step's explanation against render's PNG bytes; the
// step transcript for the caller.
std::string check_listed_pixels(CliSandbox& box, const std::vector<std::string>& flags,
                                const std::vector<std::pair<int, int>>& pixels) {
    std::vector<std::string> png_args = flags;
    png_args.insert(png_args.end(), {"-o", "r.png"});
    REQUIRE(box.run_exe(kRender, png_args).code == 0);
    const Rgb8 png = load_rgb8(box.path("r.png"));
    REQUIRE(!png.empty());
    std::string commands;
    for (const auto& [x, y] : pixels) commands += "pixel " + std::to_string(x) + " " + std::to_string(y) + "\n";
    const CliRun r = run_step(box, flags, commands);
    INFO(r.err);
    REQUIRE(r.code == 0);
    const std::vector<PixelAnswer> answers = pixel_answers(r.out);
    REQUIRE(answers.size() == pixels.size());
    for (std::size_t i = 0; i < pixels.size(); ++i) {
        const std::uint8_t* p = png.at(pixels[i].first, pixels[i].second);
        INFO("pixel " << pixels[i].first << " " << pixels[i].second);
        CHECK(answers[i].srgb[0] == p[0]);
        CHECK(answers[i].srgb[1] == p[1]);
        CHECK(answers[i].srgb[2] == p[2]);
    }
    return r.out;
}

std::vector<std::pair<int, int>> grid(int w, int h, int step) {
    std::vector<std::pair<int, int>> out;
    for (int y = step / 2; y < h; y += step)
        for (int x = step / 2; x < w; x += step) out.push_back({x, y});
    return out;
}

void check_verify(CliSandbox& box, const std::vector<std::string>& flags, const char* expect = nullptr) {
    const CliRun r = run_step(box, flags, "verify\n");
    INFO(r.out << r.err);
    CHECK(r.code == 0);
    CHECK(r.out.find("verify: ok, all identical") != std::string::npos);
    if (expect) CHECK(r.out.find(expect) != std::string::npos);
}

// The answer blocks of a transcript of `pixel` commands, one string each.
std::vector<std::string> pixel_blocks(const std::string& out) {
    std::vector<std::string> blocks;
    std::string cur;
    for (const std::string& l : lines_of(out)) {
        cur += l + "\n";
        if (l.rfind("srgb8 ", 0) == 0) {
            blocks.push_back(cur);
            cur.clear();
        }
    }
    return blocks;
}

// The name of the fragment step's pixel explanation shades first (the
// winner): "draw D (mesh 'M') triangle P (frame triangle N)", or "" when none.
std::string step_winner(const std::string& block) {
    std::smatch m;
    if (!std::regex_search(block, m, std::regex("\nshading of #([0-9]+) "))) return "";
    const std::string entry = "\n  #" + m[1].str() + " ";
    const std::size_t at = block.find(entry);
    if (at == std::string::npos) return "";
    const std::string line = block.substr(at + entry.size(), block.find('\n', at + 1) - at - entry.size());
    if (!std::regex_search(line, m, std::regex("draw [0-9]+ \\(mesh '[^']*'\\) triangle [0-9]+ \\(frame triangle [0-9]+\\)")))
        return "";
    return m[0].str();
}

std::string render_winner(const std::string& out) {
    std::smatch m;
    if (!std::regex_search(out, m, std::regex("draw [0-9]+ \\(mesh '[^']*'\\) triangle [0-9]+ \\(frame triangle [0-9]+\\)")))
        return "";
    return m[0].str();
}

} // namespace

TEST_SUITE("step") {

TEST_CASE("pixel: the built-in scene's explained pixels are render's, byte for byte") {
    const int reached = check_pixels_against_render({}, 16, 9);
    CHECK(reached > 60);  // most of the grid lands on the spheres and the floor
}

TEST_CASE("pixel: the tea set's explained pixels are render's") {
    if (!have_asset(kTea)) return;
    CHECK(check_pixels_against_render(kTeaFlags, 12, 8) > 15);  // the teapot fills the middle
}

TEST_CASE("pixel: NormalTangentTest's explained pixels are render's") {
    if (!have_asset(kNormalTangent)) return;
    CHECK(check_pixels_against_render(kNormalTangentFlags, 10, 8) > 30);
}

TEST_CASE("pixel: under an --env map with --energy conserve, the explained pixels are render's") {
    const std::string venice = kAssets + "/venice-sunset-1k/venice_sunset_1k.hdr";
    if (!have_asset(venice)) return;
    const std::vector<std::string> flags = {"--size", "160x90", "--env", venice, "--env-rotate", "40",
                                            "--energy", "conserve", "--brdf", "gltf"};
    CHECK(check_pixels_against_render(flags, 12, 6) > 20);  // --msaa 4: edge samples resolve to the sky
    std::vector<std::string> one = flags;
    for (const char* f : {"--msaa", "1", "--background", "blur"}) one.push_back(f);
    CHECK(check_pixels_against_render(one, 12, 6) > 20);
}

TEST_CASE("pixel: with shadows on and blended glass, the explained pixels are render's, with the shadow lookups and the blend order") {
    CHECK(check_pixels_against_render({"--size", "320x180", "--shadows", "on", "--shadow-size", "512",
                                       "--point", "0.5,2.5,1.5:4,4,4"}, 12, 7) > 40);
    const std::string glass = std::string(PRAST_SOURCE_DIR) + "/docs/glass.obj";
    const std::vector<std::string> flags = {glass, "--size", "320x180", "--shadows", "on", "--shadow-size", "512",
                                            "--eye", "0.6,2.4,4.4", "--target", "0,0.5,-0.3"};
    CHECK(check_pixels_against_render(flags, 12, 7) > 40);
    // The green pane over the floor: one blended fragment over the floor,
    // whose sun is looked up in its shadow map.
    CliSandbox box;
    const CliRun r = run_step(box, flags, "pixel 160 125\n");
    REQUIRE(r.code == 0);
    CHECK(r.out.find("blend #1, shader out") != std::string::npos);
    CHECK(r.out.find("out * alpha + previous * (1 - alpha) = ") != std::string::npos);
    CHECK(r.out.find("shadow map: texel (") != std::string::npos);
    CHECK(r.out.find("PCF: 3x3 bilinear taps") != std::string::npos);
}

TEST_CASE("pixel: with 1 and 8 samples per pixel too, the explained pixels are render's") {
    for (const char* msaa : {"1", "8"}) {
        INFO("--msaa " << msaa);
        CHECK(check_pixels_against_render({"--size", "480x270", "--msaa", msaa}, 16, 9) > 60);
    }
}

TEST_CASE("verify: every recomputed number equals the pipeline's") {
    // The built-in scene as render draws it by default, then smaller frames
    // for the variations (the size changes no code path verify checks).
    std::vector<std::vector<std::string>> scenes = {{}, {"--near", "6.5", "--far", "20", "--size", "480x270"},
                                                    {"--msaa", "1", "--size", "480x270"},
                                                    {"--msaa", "8", "--size", "480x270"}};
    if (have_asset(kTea)) scenes.push_back(kTeaFlags);
    if (have_asset(kNormalTangent)) scenes.push_back(kNormalTangentFlags);
    for (const auto& flags : scenes) {
        CliSandbox box;
        const CliRun r = run_step(box, flags, "verify\n");
        INFO(r.out << r.err);
        CHECK(r.code == 0);
        CHECK(r.out.find("verify: ok, all identical") != std::string::npos);
    }
}

TEST_CASE("upto: all triangles give render's image, none the cleared frame") {
    CliSandbox box;
    // With a black background (the built-in sky otherwise), no triangle is a black frame.
    REQUIRE(box.run_exe(kRender, {"--size", "320x180", "--background", "black", "-o", "r.png"}).code == 0);
    const CliRun r = run_step(box, {"--size", "320x180", "--background", "black"},
                              "upto 98432 all.png\nupto 0 none.png\nupto 50000\n");
    REQUIRE(r.code == 0);
    CHECK(r.out.find("upto 50000: wrote upto-50000.png") != std::string::npos);
    const Rgb8 want = load_rgb8(box.path("r.png")), all = load_rgb8(box.path("all.png"));
    const Rgb8 none = load_rgb8(box.path("none.png")), half = load_rgb8(box.path("upto-50000.png"));
    REQUIRE(!all.empty());
    CHECK(all.rgb == want.rgb);
    CHECK(none.mean() == 0.0);
    CHECK(half.mean() > 0.0);
    CHECK(half.rgb != want.rgb);
}

TEST_CASE("upto N, then pixel: the pixel as it stands after N triangles, equal to upto's image") {
    // The sky's clear colour, 4 samples (the visibility pass decides which
    // fragments are shaded: at a point part way, others than at the end).
    const std::vector<std::string> flags = {"--size", "160x90"};
    const std::vector<std::pair<int, int>> pixels = grid(160, 90, 18);
    std::string ask;
    for (const auto& [x, y] : pixels) ask += "pixel " + std::to_string(x) + " " + std::to_string(y) + "\n";
    CliSandbox box;
    const CliRun end = run_step(box, flags, ask);
    REQUIRE(end.code == 0);
    const std::vector<std::string> at_end = pixel_blocks(end.out);
    REQUIRE(at_end.size() == pixels.size());
    const long kPoints[] = {0, 20000, 50000, 98432};
    std::string commands;
    for (long n : kPoints) commands += "upto " + std::to_string(n) + " u" + std::to_string(n) + ".png\n" + ask;
    commands += "upto all\n" + ask;
    const CliRun r = run_step(box, flags, commands);
    INFO(r.err);
    REQUIRE(r.code == 0);
    CHECK(r.out.find("pixel X Y now explains a pixel as it stands after these 20000 triangles") != std::string::npos);
    CHECK(r.out.find("upto all: pixel explains a pixel at the frame's end") != std::string::npos);
    std::vector<std::string> blocks = pixel_blocks(r.out);
    REQUIRE(blocks.size() == pixels.size() * 5);
    // Each answer from its "pixel X Y:" line (the first after an upto follows upto's reply).
    for (std::string& b : blocks) {
        std::smatch m;
        REQUIRE(std::regex_search(b, m, std::regex("(^|\n)pixel [0-9]")));
        b = b.substr(std::size_t(m.position(0)) + (b[std::size_t(m.position(0))] == '\n'));
    }
    int differ_from_end = 0;
    for (std::size_t k = 0; k < 4; ++k) {
        const long n = kPoints[k];
        const Rgb8 img = load_rgb8(box.path("u" + std::to_string(n) + ".png"));
        REQUIRE(!img.empty());
        for (std::size_t i = 0; i < pixels.size(); ++i) {
            const std::string& b = blocks[k * pixels.size() + i];
            const auto [x, y] = pixels[i];
            INFO("upto " << n << " pixel " << x << " " << y << "\n" << b);
            // The framebuffer at that point is what the explanation computes (no NOTE).
            CHECK(b.find("NOTE") == std::string::npos);
            const std::vector<PixelAnswer> a = pixel_answers(b);
            REQUIRE(a.size() == 1);
            const std::uint8_t* p = img.at(x, y);
            CHECK(a[0].srgb[0] == p[0]);
            CHECK(a[0].srgb[1] == p[1]);
            CHECK(a[0].srgb[2] == p[2]);
            if (n == 98432) {
                CHECK(b == at_end[i]);  // all of them: the frame's end
                continue;
            }
            CHECK(b.find("as the frame stands after the first " + std::to_string(n) + " of 98432 triangles") !=
                  std::string::npos);
            if (n == 0) {
                CHECK(b.find("then 0 fragments") != std::string::npos);
                CHECK(b.find("no fragment was written in the first 0 triangles: the pixel holds the clear colour") !=
                      std::string::npos);
            }
            differ_from_end += pixel_answers(at_end[i])[0].srgb[0] != a[0].srgb[0];
        }
    }
    CHECK(differ_from_end > 10);  // the points part way are not the frame's end
    // upto all: the frame's end again, word for word.
    for (std::size_t i = 0; i < pixels.size(); ++i) CHECK(blocks[4 * pixels.size() + i] == at_end[i]);
    // A bad upto leaves the point where it was.
    const CliRun bad = run_step(box, flags, "upto 0 z.png\nupto 98433\nupto all extra\npixel 80 45\n");
    CHECK(bad.out.find("the pixel holds the clear colour") != std::string::npos);
}

TEST_CASE("texel: stored and linear values of a texel, sRGB bytes decoded, for every kind of texture") {
    CliSandbox box;
    // The checker as an sRGB base colour map: texel (2, 0) is green (0, 255, 0, 255).
    GltfWriter g;
    const int tex = g.texture(g.image_png(checker_png()), 9728 /*NEAREST*/, 9987 /*LINEAR_MIPMAP_LINEAR*/);
    const int m = add_material(g, {{"pbrMetallicRoughness", {{"baseColorTexture", {{"index", tex}}}}}});
    add_quad(g, 0.0f, json::object(), m);
    g.scene_of_meshes();
    const std::string file = write_gltf(box, g, "checker.gltf");
    std::vector<std::string> flags = {file};
    flags.insert(flags.end(), kQuadView.begin(), kQuadView.end());
    const CliRun r = run_step(box, flags, "texel 0 0 2 0\ntexel 0 0 0 3\njson texel 0 1 1 1\ntexel 0 0 4 0\n"
                                          "texel 0 3 0 0\ntexel nope 0 0 0\ntexel 0 0 x 0\n");
    INFO(r.out << r.err);
    CHECK(r.out.find("texel 2 0 of texture 0 level 0 (4x4, RGB 8-bit sRGB)\n"
                     "  stored (8-bit): R 0, G 255, B 0\n") != std::string::npos);
    // The fixed-point filter's 15-bit code of the byte (docs/conventions.md).
    CHECK(r.out.find("    G = sRGB decode of G 255 = code 32640 / 32640\n") != std::string::npos);
    CHECK(r.out.find("  linear (what the samplers read): R 0, G 1, B 0, A 1\n") != std::string::npos);
    CHECK(r.out.find("    A = 1 (not stored)\n") != std::string::npos);
    CHECK(r.out.find("  shown in the PNG: 0 255 0 (") != std::string::npos);
    // Texel (0, 3): the blue quarter.
    CHECK(r.out.find("texel 0 3 of texture 0 level 0 (4x4, RGB 8-bit sRGB)\n"
                     "  stored (8-bit): R 0, G 0, B 255\n") != std::string::npos);
    // Level 1 is 2x2, one texel per colour, (1, 1) the yellow one: the JSON's values.
    const std::size_t j = r.out.find("{\"decode\"");
    REQUIRE(j != std::string::npos);
    const json v = json::parse(r.out.substr(j, r.out.find('\n', j) - j));
    CHECK(v["width"] == 2);
    CHECK(v["stored"] == json::array({255, 255, 0}));  // opaque: stored without alpha
    CHECK(v["linear"][0] == 1.0);
    CHECK(v["stored_type"] == "8-bit");
    CHECK(r.out.find("error: texel '4 0' of texture 0 level 0: outside its 4x4 texels (x 0..3, y 0..3)") !=
          std::string::npos);
    CHECK(r.out.find("error: texture 0 level '3': no such level (levels 0..2)") != std::string::npos);
    CHECK(r.out.find("error: texture 'nope': no such texture") != std::string::npos);
    CHECK(r.out.find("error: texel 'x 0' of texture 0") != std::string::npos);
    // The built-in scene's float maps, its sky and its shadow map.
    const CliRun b = run_step(box, {"--size", "160x90", "--shadows", "on", "--shadow-size", "256"},
                              "texel 0 0 10 10\ntexel env 0 0 0\ntexel shadow0 0 128 128\n");
    INFO(b.out << b.err);
    CHECK(b.code == 0);
    CHECK(b.out.find("  stored (float32): R ") != std::string::npos);
    CHECK(b.out.find("    stored linear: read as it is\n") != std::string::npos);
    CHECK(b.out.find("    stored linear radiance: read as it is\n") != std::string::npos);
    CHECK(b.out.find("  stored (float32): distance ") != std::string::npos);
}

TEST_CASE("--out: every stage as a PNG and an index.html; the final stage is render's image") {
    CliSandbox box;
    // A magenta background (the built-in sky otherwise), so that render's
    // empty pixels can be told from drawn ones below (a metal seen exactly
    // edge-on under the sky alone is black).
    REQUIRE(box.run_exe(kRender, {"--size", "320x180", "--background", "1,0,1", "-o", "r.png"}).code == 0);
    const CliRun r = box.run_exe(kStep, {"--size", "320x180", "--background", "1,0,1", "--out", "stages"});
    REQUIRE(r.code == 0);
    const std::string index = read_text(box.work() / "stages" / "index.html");
    const char* kStages[] = {"vertices", "wireframe", "bins", "depth", "overdraw", "shaded", "msaa", "quad_overdraw",
                             "triangle_size",
                             "nan", "albedo", "normal", "roughness", "metallic", "occlusion", "mip", "D", "F", "G",
                             "diffuse", "specular", "final"};
    for (const char* name : kStages) {
        INFO(name);
        const Rgb8 img = load_rgb8(box.path(std::string("stages/") + name + ".png"));
        CHECK(img.width == 320);
        CHECK(img.height == 180);
        CHECK(index.find(std::string("src=\"") + name + ".png\"") != std::string::npos);
    }
    CHECK(index.find("http") == std::string::npos);  // nothing to fetch: opens offline
    const Rgb8 want = load_rgb8(box.path("r.png")), final = load_rgb8(box.path("stages/final.png"));
    CHECK(final.rgb == want.rgb);
    // No NaN, infinity or negative value in the built-in frame: all grey.
    const Rgb8 nan = load_rgb8(box.path("stages/nan.png"));
    for (std::size_t i = 0; i < nan.rgb.size(); ++i) REQUIRE(nan.rgb[i] == 64);
    // Depth and albedo are black exactly where render drew the background.
    const Rgb8 depth = load_rgb8(box.path("stages/depth.png")), albedo = load_rgb8(box.path("stages/albedo.png"));
    int background = 0;
    for (int y = 0; y < 180; ++y)
        for (int x = 0; x < 320; ++x) {
            const std::uint8_t* bg = want.at(0, 0);  // the top-left corner shows the background
            const bool empty = want.at(x, y)[0] == bg[0] && want.at(x, y)[1] == bg[1] && want.at(x, y)[2] == bg[2];
            background += empty;
            if (empty) CHECK(albedo.at(x, y)[0] + albedo.at(x, y)[1] + albedo.at(x, y)[2] == 0);
            else CHECK(albedo.at(x, y)[0] + albedo.at(x, y)[1] + albedo.at(x, y)[2] > 0);
            if (empty) CHECK(depth.at(x, y)[0] == 0);
        }
    CHECK(background > 1000);
    // A file where the directory should be: one line, exit 1.
    write_text(box.work() / "afile", "x");
    const CliRun bad = box.run_exe(kStep, {"--size", "32x18", "--out", "afile"});
    CHECK(bad.code == 1);
    CHECK(bad.err.find("afile") != std::string::npos);
}

TEST_CASE("stage wireframe: set-up triangles white, clipped pieces orange, culled dark blue, degenerate magenta") {
    // The colours as stepper/stages.cpp writes them (linear * 255, no sRGB).
    const std::uint8_t kWhite[3] = {255, 255, 255}, kOrange[3] = {255, 140, 26}, kBlue[3] = {38, 51, 153},
                       kMagenta[3] = {255, 0, 255};
    auto count = [](const Rgb8& img, const std::uint8_t* c) {
        int n = 0;
        for (std::size_t i = 0; i < img.rgb.size(); i += 3) n += std::memcmp(&img.rgb[i], c, 3) == 0;
        return n;
    };
    CliSandbox box;
    REQUIRE(run_step(box, {"--size", "320x180"}, "stage wireframe whole.png\n").code == 0);
    REQUIRE(run_step(box, {"--size", "320x180", "--near", "6.5", "--far", "20"}, "stage wireframe cut.png\n").code == 0);
    const Rgb8 whole = load_rgb8(box.path("whole.png")), cut = load_rgb8(box.path("cut.png"));
    REQUIRE(!whole.empty());
    REQUIRE(!cut.empty());
    // Nothing is clipped in the built-in frame; the near plane through the
    // floor clips some triangles, drawn in their own colour.
    CHECK(count(whole, kOrange) == 0);
    CHECK(count(cut, kOrange) > 100);
    for (const Rgb8* img : {&whole, &cut}) {
        CHECK(count(*img, kWhite) > 1000);
        CHECK(count(*img, kBlue) > 0);     // back faces seen past the silhouettes
        CHECK(count(*img, kMagenta) > 0);  // the scene's degenerate triangles
    }
}

TEST_CASE("--out: names from the model reach index.html escaped") {
    CliSandbox box;
    write_text(box.work() / "<i>&x.obj", "o <script>alert(1)</script>\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
    const CliRun r = box.run_exe(kStep, {"--size", "32x18", "<i>&x.obj", "--out", "o"});
    REQUIRE(r.code == 0);
    const std::string index = read_text(box.work() / "o" / "index.html");
    CHECK(index.find("<i>") == std::string::npos);
    CHECK(index.find("&lt;i&gt;&amp;x.obj") != std::string::npos);
}

TEST_CASE("sessions: the built-in scene, step by step") {
    check_transcript("builtin", {});
}

TEST_CASE("sessions: a near plane through the scene clips triangles") {
    check_transcript("clipped", {"--near", "6.5", "--far", "20"});
}

TEST_CASE("sessions: spheres in front of spheres, the visibility pass and the samples") {
    check_transcript("side", {"--size", "320x180", "--eye", "8,2.2,0.6", "--target", "0,1.9,0"});
}

TEST_CASE("sessions: bad commands get one line each and the session goes on") {
    CliSandbox box;
    const std::string long_word(5000, 'x');
    const CliRun r = run_step(box, {"--size", "160x90"},
                              "bogus\npixel\npixel 1\npixel -1 0\npixel 160 0\npixel 0 90\npixel a b\n"
                              "pixel 99999999999999999999 0\ntri\ntri 1e3\ntri -5\ntri 98432\ntile 3 0\n"
                              "upto 98433\nupto 5 /nonexistent-dir/x.png\nstage nope\nframe extra\n" +
                                  long_word + "\n\n   \n# a comment\npixel 80 45\n");
    CHECK(r.code == 1);
    const std::vector<std::string> lines = lines_of(r.out);
    int errors = 0;
    for (const std::string& l : lines)
        if (l.rfind("error: ", 0) == 0) {
            ++errors;
            CHECK(l.size() < 200);
        }
    CHECK(errors == 18);
    CHECK(r.out.find("srgb8 ") != std::string::npos);  // the last command still ran
    CHECK(r.err.empty());
}

TEST_CASE("flags: step takes every flag of render's --help, or refuses it") {
    // A render flag step neither lists nor refuses would be parsed and then
    // ignored, and step would explain a frame render does not draw: a new
    // flag must reach FrameRequest (apps/frame_request.h) and step's --help,
    // or join kNotForStep in apps/step.cpp.
    auto flags = [](const std::string& help) {
        std::vector<std::string> out;
        for (std::size_t i = help.find("--"); i != std::string::npos; i = help.find("--", i + 2)) {
            std::size_t e = i + 2;
            while (e < help.size() && (std::isalnum(static_cast<unsigned char>(help[e])) || help[e] == '-')) ++e;
            if (e > i + 2) out.push_back(help.substr(i, e - i));
        }
        return out;
    };
    CliSandbox box;
    const CliRun render_help = box.run_exe(kRender, {"--help"}), step_help = box.run_exe(kStep, {"--help"});
    REQUIRE(render_help.code == 0);
    REQUIRE(step_help.code == 0);
    const std::vector<std::string> listed = flags(step_help.out);
    // render-only: one frame has no turntable, output file, repeat, stats or
    // debug view; --samples belongs to --ibl reference, which step refuses;
    // step never reads outside the model's folder (it may serve what it reads).
    const std::vector<std::string> refused = {"--output", "--frames", "--orbit", "--frame-range", "--repeat",
                                              "--view", "--stats", "--allow-outside-paths", "--fps", "--list"};
    for (const std::string& f : flags(render_help.out)) {
        INFO("render flag " << f);
        if (std::find(listed.begin(), listed.end(), f) != listed.end() || f == "--samples") continue;
        REQUIRE(std::find(refused.begin(), refused.end(), f) != refused.end());
        const CliRun r = box.run_exe(kStep, {f, "1"});
        CHECK(r.code == 2);
        CHECK(r.err.find("not a step option") != std::string::npos);
    }
}

TEST_CASE("flags: render's flags that make no sense for one frame, and bad files") {
    CliSandbox box;
    for (const char* flag : {"--frames", "--view", "-o", "--repeat", "--stats"}) {
        const CliRun r = box.run_exe(kStep, {flag, "2"});
        CHECK(r.code == 2);
        CHECK(r.err.find("not a step option") != std::string::npos);
    }
    CHECK(box.run_exe(kStep, {"--port", "80"}).code == 2);
    CHECK(box.run_exe(kStep, {"--size", "0x5"}).code == 2);
    const CliRun missing = box.run_exe(kStep, {"no-such-file.glb"});
    CHECK(missing.code == 1);
    CHECK(missing.err.find("no-such-file.glb") != std::string::npos);
    const CliRun help = box.run_exe(kStep, {"--help"});
    CHECK(help.code == 0);
    CHECK(help.out.find("usage: step") == 0);
    const CliRun pixel = box.run_exe(kStep, {"--size", "160x90", "--pixel", "80,60"});
    CHECK(pixel.code == 0);
    CHECK(pixel_answers(pixel.out).size() == 1);
}


TEST_CASE("core glTF: vertex colours, the base colour term and the exact interpolated colour") {
    CliSandbox box;
    GltfWriter g;
    const int mat = add_material(g, {{"pbrMetallicRoughness", {{"baseColorFactor", {0.5, 1, 1, 1}}, {"metallicFactor", 0}}}});
    // Quad 0: red grows with x (r = (x + 1) / 2), green and blue constant.
    const int colors = g.floats({0, 0.25f, 0.75f, 1, 1, 0.25f, 0.75f, 1, 1, 0.25f, 0.75f, 1, 0, 0.25f, 0.75f, 1}, "VEC4", 4);
    add_quad(g, 0.0f, {{"COLOR_0", colors}}, mat);
    g.scene_of_meshes();
    const std::string file = write_gltf(box, g, "colours.gltf");
    std::vector<std::string> flags = kQuadView;
    flags.insert(flags.begin(), file);
    const std::string out = check_listed_pixels(box, flags, grid(48, 36, 5));
    check_verify(box, flags);
    // Every explained fragment shows its colour and the base colour product.
    const std::regex colour("vertex colour \\(COLOR_0, interpolated\\) \\(([-0-9.e]+), ([-0-9.e]+), ([-0-9.e]+), ([-0-9.e]+)\\)");
    const std::regex P("\n     P \\(([-0-9.e]+), ([-0-9.e]+), ([-0-9.e]+)\\)");
    int seen = 0;
    for (const std::string& b : pixel_blocks(out)) {
        std::smatch m, p;
        if (!std::regex_search(b, m, colour)) continue;
        REQUIRE(std::regex_search(b, p, P));
        ++seen;
        const float r = std::stof(m[1]), px = std::stof(p[1]);
        INFO(b);
        CHECK(std::fabs(r - (px + 1.0f) / 2.0f) <= 2e-6f);  // interpolated like P: exact up to float rounding
        CHECK(m[2].str() == "0.25");                        // constant across the quad: exactly
        CHECK(m[3].str() == "0.75");
        CHECK(m[4].str() == "1");
        CHECK(b.find("base colour = factor (0.5, 1, 1, 1) x vertex colour (" + m[1].str() + ", 0.25, 0.75, 1) = (") !=
              std::string::npos);
        CHECK(b.find(" colour (" + m[1].str() + ", 0.25, 0.75, 1)\n") != std::string::npos);  // the history line
    }
    CHECK(seen > 20);
}

TEST_CASE("core glTF: a texture on UV set 1 through a NEAREST sampler, explained and equal to render") {
    CliSandbox box;
    GltfWriter g;
    const int img = g.image_png(checker_png());
    const int tex = g.texture(img, 9728 /*NEAREST*/, 9729 /*LINEAR*/, 33071 /*CLAMP*/, 10497);
    const int mat = add_material(g, {{"pbrMetallicRoughness",
                                      {{"baseColorTexture", {{"index", tex}, {"texCoord", 1}}}, {"metallicFactor", 0}}}});
    // UV set 1 is UV set 0 mirrored in u: the explanation must read set 1.
    const int uv1 = g.floats({1, 1, 0, 1, 0, 0, 1, 0}, "VEC2", 2);
    add_quad(g, 0.0f, {{"TEXCOORD_1", uv1}}, mat);
    g.scene_of_meshes();
    const std::string file = write_gltf(box, g, "uv1.gltf");
    std::vector<std::string> flags = kQuadView;
    flags.insert(flags.begin(), file);
    const std::string out = check_listed_pixels(box, flags, grid(48, 36, 5));
    check_verify(box, flags);
    CHECK(out.find("map base_color: 4x4, 3 levels, UV set 1 (") != std::string::npos);
    CHECK(out.find("sampler: mag NEAREST, min LINEAR, wrap clamp/repeat") != std::string::npos);
    CHECK(out.find("(magnification: nearest on level 0)") != std::string::npos);
    CHECK(out.find("nearest texel x ") != std::string::npos);
    CHECK(out.find("base colour = factor (1, 1, 1, 1) x texture(UV set 1, sampler: mag NEAREST") != std::string::npos);
    CHECK(out.find(" uv1 (") != std::string::npos);
    const CliRun t = run_step(box, flags, "tri 0\n");
    CHECK(t.out.find("18 varyings (vertex colours or UV set 1)") != std::string::npos);
}

TEST_CASE("core glTF: a skinned, animated model posed at a time: step equals render and verify passes") {
    CliSandbox box;
    GltfWriter g;
    // A strip of two quads (rows y = 0, 1, 2) on two joints; joint 1 turns about z over [0, 1].
    const int pos = g.floats({-0.5f, 0, 0, 0.5f, 0, 0, -0.5f, 1, 0, 0.5f, 1, 0, -0.5f, 2, 0, 0.5f, 2, 0}, "VEC3", 3);
    const int nrm = g.floats({0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1}, "VEC3", 3);
    const int col = g.floats({1, 0, 0, 1, 1, 0, 0, 1, 0, 1, 0, 1, 0, 1, 0, 1, 0, 0, 1, 1, 0, 0, 1, 1}, "VEC4", 4);
    const int joints = g.u16({0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0}, "VEC4", 4);
    const int weights = g.floats({1, 0, 0, 0, 1, 0, 0, 0, 0.5f, 0.5f, 0, 0, 0.5f, 0.5f, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0},
                                 "VEC4", 4);
    const int ind = g.u16({0, 1, 3, 0, 3, 2, 2, 3, 5, 2, 5, 4}, "SCALAR", 1);
    const int ibm = g.floats({1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, -1, 0, 1},
                             "MAT4", 16);
    const int mat = add_material(g, {{"pbrMetallicRoughness", {{"metallicFactor", 0}}}, {"doubleSided", true}});
    g.doc["meshes"].push_back(
        {{"name", "strip"},
         {"primitives", json::array({{{"attributes", {{"POSITION", pos}, {"NORMAL", nrm}, {"COLOR_0", col},
                                                      {"JOINTS_0", joints}, {"WEIGHTS_0", weights}}},
                                      {"indices", ind},
                                      {"material", mat}}})}});
    g.doc["nodes"] = json::array({{{"name", "root"}, {"children", {1}}},
                                  {{"name", "bone"}, {"translation", {0, 1, 0}}},
                                  {{"name", "strip"}, {"mesh", 0}, {"skin", 0}}});
    g.doc["skins"] = json::array({{{"joints", {0, 1}}, {"inverseBindMatrices", ibm}}});
    g.doc["scenes"] = json::array({{{"nodes", {0, 2}}}});
    g.doc["scene"] = 0;
    const double h = std::sqrt(0.5);
    const int in = g.floats({0, 1}, "SCALAR", 1);
    const int out = g.floats({0, 0, 0, 1, 0, 0, float(h), float(h)}, "VEC4", 4);
    g.doc["animations"] = json::array(
        {{{"name", "bend"},
          {"samplers", json::array({{{"input", in}, {"output", out}}})},
          {"channels", json::array({{{"sampler", 0}, {"target", {{"node", 1}, {"path", "rotation"}}}}})}}});
    const std::string file = write_gltf(box, g, "skinned.gltf");
    const std::vector<std::string> flags = {file, "--size", "40x40", "--time", "0.5", "--msaa", "1"};
    const std::string t = check_listed_pixels(box, flags, grid(40, 40, 4));
    CHECK(t.find("vertex colour (COLOR_0, interpolated) (") != std::string::npos);
    check_verify(box, flags);
    check_verify(box, {file, "--size", "40x40", "--time", "0.5"});  // 4 samples
}

TEST_CASE("core glTF: lines and points, unlit, explained by the diamond-exit rule and equal to render") {
    CliSandbox box;
    GltfWriter g;
    const int grey = add_material(g, {{"pbrMetallicRoughness", {{"baseColorFactor", {0.2, 0.2, 0.2, 1}}, {"metallicFactor", 0}}}});
    const int white = add_material(g, {{"pbrMetallicRoughness", {{"baseColorFactor", {1, 0.5, 1, 1}}}}});
    add_quad(g, -0.5f, json::object(), grey);
    // Lines (mode 1): a horizontal one through the middle and a diagonal, with colours; no normals.
    const int lpos = g.floats({-2, 0.1f, 0, 2, 0.1f, 0, -1, -1, 0.2f, 1, 1, 0.2f}, "VEC3", 3);
    const int lcol = g.floats({1, 0, 0, 1, 0, 0, 1, 1, 0, 1, 0, 1, 1, 1, 0, 1}, "VEC4", 4);
    const int lind = g.u16({0, 1, 2, 3}, "SCALAR", 1);
    g.doc["meshes"].push_back({{"name", "lines"},
                               {"primitives", json::array({{{"attributes", {{"POSITION", lpos}, {"COLOR_0", lcol}}},
                                                            {"indices", lind}, {"mode", 1}, {"material", white}}})}});
    // Points (mode 0) in front of everything.
    const int ppos = g.floats({-0.6f, -0.6f, 0.5f, 0.6f, -0.6f, 0.5f}, "VEC3", 3);
    g.doc["meshes"].push_back({{"name", "points"},
                               {"primitives", json::array({{{"attributes", {{"POSITION", ppos}}}, {"mode", 0},
                                                            {"material", white}}})}});
    g.scene_of_meshes();
    const std::string file = write_gltf(box, g, "lines.gltf");
    for (const char* msaa : {"1", "4"}) {
        INFO("--msaa " << msaa);
        const std::vector<std::string> flags = {file, "--eye", "0,0,3", "--target", "0,0,0", "--size", "48x36",
                                                "--msaa", msaa, "--sun", "0,0,1:1,1,1"};
        check_verify(box, flags, " lines and points set up again, ");
        // Every pixel of the image: the lines' and points' pixels among them.
        const std::string out = check_listed_pixels(box, flags, grid(48, 36, 1));
        CHECK(out.find("line fragment: segment from (") != std::string::npos);
        CHECK(out.find("coverage rule (diamond exit): the segment meets the pixel's diamond") != std::string::npos);
        CHECK(out.find("point fragment: at (") != std::string::npos);
        CHECK(out.find("unlit (a line or point without normals") != std::string::npos);
        CHECK(out.find("base colour = factor (1, 0.5, 1, 1) x vertex colour (") != std::string::npos);
        CHECK(out.find("shaded in order (lines and points always are): unlit, shader out") != std::string::npos);
        CHECK(out.find("base colour = factor (1, 0.5, 1, 1) x vertex colour (1, 1, 1, 1) = (1, 0.5, 1, 1)") !=
              std::string::npos);  // the points: no COLOR_0, white
    }
}

TEST_CASE("render --pixel names step's winner: a back face behind a front face, a coincident double-sided pair") {
    CliSandbox box;
    GltfWriter g;
    const int front = add_material(g, {{"name", "front"}, {"pbrMetallicRoughness", {{"baseColorFactor", {1, 0, 0, 1}}}}});
    const int twosided = add_material(g, {{"name", "twosided"}, {"doubleSided", true},
                                          {"pbrMetallicRoughness", {{"baseColorFactor", {0, 1, 0, 1}}}}});
    const int twin = add_material(g, {{"name", "twin"}, {"doubleSided", true},
                                      {"pbrMetallicRoughness", {{"baseColorFactor", {0, 0, 1, 1}}}}});
    // Mesh 0: a small front-facing quad in front (x, y in [-0.4, 0.4] at z = 0.5).
    {
        const int pos = g.floats({-0.4f, -0.4f, 0.5f, 0.4f, -0.4f, 0.5f, 0.4f, 0.4f, 0.5f, -0.4f, 0.4f, 0.5f}, "VEC3", 3);
        const int nrm = g.floats({0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1}, "VEC3", 3);
        const int ind = g.u16({0, 1, 2, 0, 2, 3}, "SCALAR", 1);
        g.doc["meshes"].push_back({{"name", "front"}, {"primitives", json::array({{{"attributes", {{"POSITION", pos}, {"NORMAL", nrm}}},
                                                                                   {"indices", ind}, {"material", front}}})}});
    }
    // Mesh 1: a double-sided quad behind it wound the other way (a back face to the camera).
    {
        const int pos = g.floats({-1, -1, 0, 1, -1, 0, 1, 1, 0, -1, 1, 0}, "VEC3", 3);
        const int nrm = g.floats({0, 0, -1, 0, 0, -1, 0, 0, -1, 0, 0, -1}, "VEC3", 3);
        const int ind = g.u16({0, 2, 1, 0, 3, 2}, "SCALAR", 1);
        g.doc["meshes"].push_back({{"name", "back"}, {"primitives", json::array({{{"attributes", {{"POSITION", pos}, {"NORMAL", nrm}}},
                                                                                  {"indices", ind}, {"material", twosided}}})}});
    }
    // Meshes 2 and 3: two coincident double-sided quads further back, wider: the first drawn keeps the ties.
    for (int k = 0; k < 2; ++k) {
        const int pos = g.floats({-2, -2, -0.5f, 2, -2, -0.5f, 2, 2, -0.5f, -2, 2, -0.5f}, "VEC3", 3);
        const int nrm = g.floats({0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1}, "VEC3", 3);
        const int ind = g.u16({0, 1, 2, 0, 2, 3}, "SCALAR", 1);
        g.doc["meshes"].push_back({{"name", k ? "pair1" : "pair0"},
                                   {"primitives", json::array({{{"attributes", {{"POSITION", pos}, {"NORMAL", nrm}}},
                                                                {"indices", ind}, {"material", twin}}})}});
    }
    g.scene_of_meshes();
    const std::string file = write_gltf(box, g, "faces.gltf");
    for (const char* msaa : {"1", "4"}) {
        const std::vector<std::string> flags = {file, "--eye", "0,0,3", "--target", "0,0,0", "--size", "48x36",
                                                "--msaa", msaa, "--sun", "0,0,1:1,1,1"};
        std::string commands;
        // Every 5th pixel: a render process each, enough for each kind of winner several times.
        const std::vector<std::pair<int, int>> pixels = grid(48, 36, 5);
        for (const auto& [x, y] : pixels) commands += "pixel " + std::to_string(x) + " " + std::to_string(y) + "\n";
        const std::vector<std::string> blocks = pixel_blocks(run_step(box, flags, commands).out);
        REQUIRE(blocks.size() == pixels.size());
        int back = 0, pair = 0, fronts = 0;
        std::set<std::string> asked;
        for (std::size_t i = 0; i < pixels.size(); ++i) {
            std::vector<std::string> args = flags;
            args.insert(args.end(), {"--pixel", std::to_string(pixels[i].first) + "," + std::to_string(pixels[i].second),
                                     "-o", "p.png"});
            const CliRun r = box.run_exe(kRender, args);
            REQUIRE(r.code == 0);
            const std::string want = step_winner(blocks[i]);
            INFO("--msaa " << msaa << " pixel " << pixels[i].first << " " << pixels[i].second << "\n" << r.out << blocks[i]);
            CHECK(render_winner(r.out) == want);
            back += want.find("(mesh 'back')") != std::string::npos && r.out.find(", back face") != std::string::npos;
            pair += want.find("(mesh 'pair0')") != std::string::npos;
            fronts += want.find("(mesh 'front')") != std::string::npos;
            CHECK(want.find("(mesh 'pair1')") == std::string::npos);  // ties keep the first drawn
            if (!want.empty() && asked.insert(want).second) {
                // step's tri takes the name as printed (once a triangle).
                std::smatch m;
                REQUIRE(std::regex_search(want, m, std::regex("draw ([0-9]+) .* triangle ([0-9]+) \\(frame triangle ([0-9]+)\\)")));
                const CliRun t = run_step(box, flags, "tri draw " + m[1].str() + " triangle " + m[2].str() + "\n");
                CHECK(t.out.rfind("tri " + m[3].str() + ": " + want, 0) == 0);
            }
        }
        CHECK(back > 5);
        CHECK(pair > 5);
        CHECK(fronts > 5);
    }
}

TEST_CASE("render --pixel on the tea set names step's winner (a back face of 'Circle.001')") {
    const std::string venice = kAssets + "/venice-sunset-1k/venice_sunset_1k.hdr";
    if (!have_asset(kTea) || !have_asset(venice)) return;
    CliSandbox box;
    std::vector<std::string> flags = kTeaFlags;
    flags.insert(flags.end(), {"--size", "640x480", "--msaa", "1", "--env", venice});
    std::vector<std::string> args = flags;
    args.insert(args.end(), {"--pixel", "273,169", "-o", "t.png"});
    const CliRun r = box.run_exe(kRender, args);
    REQUIRE(r.code == 0);
    const CliRun s = run_step(box, flags, "pixel 273 169\n");
    REQUIRE(s.code == 0);
    const std::string want = step_winner(s.out);
    INFO(r.out << s.out);
    CHECK(!want.empty());
    CHECK(render_winner(r.out) == want);
    CHECK(want.find("(mesh 'Circle.001')") != std::string::npos);
    CHECK(r.out.find(", back face") != std::string::npos);
}

TEST_CASE("frame: names the environment that lights the frame, the ambient only when it does, and the shadows") {
    CliSandbox box;
    // The built-in scene: its own sky lights it.
    CliRun r = run_step(box, {"--size", "160x90"}, "frame\n");
    REQUIRE(r.code == 0);
    CHECK(r.out.find("environment built-in sky, ") != std::string::npos);
    CHECK(r.out.find("in place of the ambient term") != std::string::npos);
    CHECK(r.out.find("\nambient (") == std::string::npos);
    CHECK(r.out.find("\nshadows off\n") != std::string::npos);
    // Shadows on: which lights cast, the map sizes, bias and filter.
    r = run_step(box, {"--size", "160x90", "--shadows", "on", "--shadow-size", "512"}, "frame\n");
    CHECK(r.out.find("shadows on: light 0 directional map 512x512; light 1 cube map, 6 faces of 256x256; bias 1 + 3 "
                     "tan(theta) texels, PCF 3x3 bilinear taps") != std::string::npos);
    // A model without an environment: the ambient lights it.
    GltfWriter g;
    add_quad(g, 0.0f, json::object(), add_material(g, {{"pbrMetallicRoughness", {{"metallicFactor", 0}}}}));
    g.scene_of_meshes();
    const std::string file = write_gltf(box, g, "quad.gltf");
    r = run_step(box, {file, "--size", "48x36", "--ambient", "0.1,0.2,0.3"}, "frame\n");
    CHECK(r.out.find("\nambient (0.1, 0.2, 0.3), brdf default") != std::string::npos);
    CHECK(r.out.find("\nenvironment ") == std::string::npos);
    // An --env file: named, with its size.
    const std::string venice = kAssets + "/venice-sunset-1k/venice_sunset_1k.hdr";
    if (have_asset(venice)) {
        r = run_step(box, {file, "--size", "48x36", "--env", venice}, "frame\n");
        CHECK(r.out.find("environment file '" + venice + "', 1024x512, intensity 1, rotated 0 degrees: split sum") !=
              std::string::npos);
        CHECK(r.out.find("\nambient (") == std::string::npos);
    }
}


// ---- The views: draws, draw N, textures, texture ID [LEVEL], vertices, tile filters.

// The PNG at `path` as stb_image reads it: size, channels as stored, bytes.
struct PngFile {
    int width = 0, height = 0, channels = 0;
    std::vector<std::uint8_t> bytes;
};
PngFile load_png(const std::string& path) {
    PngFile p;
    unsigned char* data = stbi_load(path.c_str(), &p.width, &p.height, &p.channels, 0);
    if (data) p.bytes.assign(data, data + std::size_t(p.width) * std::size_t(p.height) * std::size_t(p.channels));
    stbi_image_free(data);
    return p;
}

// The floats of "(a, b, c)" after `key` in `text`.
std::vector<float> floats_after(const std::string& text, const std::string& key) {
    std::vector<float> out;
    const std::size_t at = text.find(key);
    if (at == std::string::npos) return out;
    const std::size_t open = text.find('(', at + key.size()), close = text.find(')', open);
    std::string inside = text.substr(open + 1, close - open - 1);
    for (std::size_t p = 0; p < inside.size();) {
        std::size_t used = 0;
        out.push_back(std::stof(inside.substr(p), &used));
        p += used;
        while (p < inside.size() && (inside[p] == ',' || inside[p] == ' ')) ++p;
    }
    return out;
}

TEST_CASE("views: draws, draw, textures, texture and vertices on a small glTF, with exact values") {
    CliSandbox box;
    GltfWriter g;
    const int img = g.image_png(checker_png());
    const int tex = g.texture(img, 9728 /*NEAREST*/, 9729 /*LINEAR*/, 33071 /*CLAMP*/, 10497);
    const int mat = add_material(g, {{"name", "checker"},
                                     {"pbrMetallicRoughness",
                                      {{"baseColorFactor", {0.5, 0.25, 1, 1}},
                                       {"baseColorTexture", {{"index", tex}}},
                                       {"metallicFactor", 0.25},
                                       {"roughnessFactor", 0.75}}},
                                     {"emissiveFactor", {0.125, 0.25, 0.5}},
                                     {"alphaMode", "MASK"},
                                     {"alphaCutoff", 0.375},
                                     {"doubleSided", true}});
    add_quad(g, 0.0f, json::object(), mat);
    g.scene_of_meshes();
    const std::string file = write_gltf(box, g, "views.gltf");
    std::vector<std::string> flags = kQuadView;
    flags.insert(flags.begin(), file);
    const CliRun r = run_step(box, flags, "frame\ndraws\ndraw 0\ntextures\ntexture 0\ntexture 0 2\nvertices 0\n");
    INFO(r.out << r.err);
    REQUIRE(r.code == 0);
    CHECK(r.out.find("1 draw, in submission order:\n  draw 0: mesh 0 'quad0', material 0 'checker', 2 triangles, "
                     "visible (2 set up, 0 culled or degenerate), MASK 0.375, double-sided, PBR narrow (12 varyings)\n") !=
          std::string::npos);
    CHECK(r.out.find("  material: base colour (0.5, 0.25, 1, 1), metallic 0.25, roughness 0.75, emissive (0.125, 0.25, "
                     "0.5)\n    normal scale 1, occlusion strength 1, ior 1.5, alpha MASK 0.375, double-sided\n") !=
          std::string::npos);
    CHECK(r.out.find("  map base_color: texture 0, image 0 ") != std::string::npos);
    CHECK(r.out.find(", 4x4, RGB 8-bit sRGB, 3 mip levels, sampler: mag NEAREST, min LINEAR, wrap clamp/repeat, UV set "
                     "0\n") != std::string::npos);
    CHECK(r.out.find("  state: cull none, depth test LESS, depth write on, blend replace, may discard (alpha MASK); "
                     "shaded in submission order\n") != std::string::npos);
    CHECK(r.out.find("  light 0: sun towards (0, 0, 1), radiance (1, 1, 1)\n") != std::string::npos);
    CHECK(r.out.find("  shadows off\n") != std::string::npos);
    CHECK(r.out.find("1 texture (texture ID [LEVEL] writes a level as a PNG):\n  texture 0: 4x4, 3 levels, RGB 8-bit "
                     "sRGB\n") != std::string::npos);
    CHECK(r.out.find("  levels: 0 4x4, 1 2x2, 2 1x1\n") != std::string::npos);
    CHECK(r.out.find("texture 0 0 -> wrote texture-0-level-0.png\n") != std::string::npos);
    CHECK(r.out.find("texture 0 2 -> wrote texture-0-level-2.png\n") != std::string::npos);
    // Level 0's PNG holds the image's own bytes; level 2 is one texel.
    const PngFile l0 = load_png(box.path("texture-0-level-0.png"));
    std::vector<std::uint8_t> src;  // checker_png()'s texels, as the decoder gives them
    const std::uint8_t colours[4][3] = {{255, 0, 0}, {0, 255, 0}, {0, 0, 255}, {255, 255, 0}};
    for (int y = 0; y < 4; ++y)
        for (int x = 0; x < 4; ++x) {
            const std::uint8_t* c = colours[(y / 2) * 2 + x / 2];
            src.insert(src.end(), {c[0], c[1], c[2]});
        }
    CHECK(l0.width == 4);
    CHECK(l0.height == 4);
    CHECK(l0.channels == 3);  // encode_png() writes RGB
    CHECK(l0.bytes == src);
    const PngFile l2 = load_png(box.path("texture-0-level-2.png"));
    CHECK(l2.width == 1);
    CHECK(l2.height == 1);
    // The first vertex: its position, and clip coordinates the test recomputes
    // from the camera `frame` prints (its numbers read back as the same floats).
    CHECK(r.out.find("vertices of draw 0 (mesh 'quad0'): 4 of 4 vertices from 0\n") != std::string::npos);
    CHECK(r.out.find("  v0 in: position (-1, -1, 0) normal (0, 0, 1) uv0 (0, 1) tangent (") != std::string::npos);
    prast::Camera cam;
    const std::vector<float> eye = floats_after(r.out, "camera eye "), target = floats_after(r.out, " target "),
                             up = floats_after(r.out, " up ");
    REQUIRE(eye.size() == 3);
    cam.eye = {eye[0], eye[1], eye[2]};
    cam.target = {target[0], target[1], target[2]};
    cam.up = {up[0], up[1], up[2]};
    std::smatch m;
    const std::regex planes("fov ([-0-9.e]+) near ([-0-9.e]+) far ([-0-9.e]+)");
    REQUIRE(std::regex_search(r.out, m, planes));
    cam.fov_y_deg = std::stof(m[1]);
    cam.near_plane = std::stof(m[2]);
    cam.far_plane = std::stof(m[3]);
    const glm::vec4 clip = cam.view_projection(48.0f / 36.0f) * glm::vec4(-1.0f, -1.0f, 0.0f, 1.0f);
    const std::vector<float> got = floats_after(r.out.substr(r.out.find("  v0 in:")), "out: clip ");
    REQUIRE(got.size() == 4);
    for (int k = 0; k < 4; ++k) CHECK(got[std::size_t(k)] == clip[k]);
    const double wx = (double(clip.x) / clip.w + 1.0) * 0.5 * 48, wy = (1.0 - double(clip.y) / clip.w) * 0.5 * 36;
    const std::vector<float> win = floats_after(r.out.substr(r.out.find("  v0 in:")), " window ");
    REQUIRE(win.size() == 2);
    CHECK(std::fabs(win[0] - wx) < 1e-4);
    CHECK(std::fabs(win[1] - wy) < 1e-4);
    // The JSON of each view: the same values, and the text under "text".
    const CliRun js = run_step(box, flags,
                               "json draws\njson draw 0\njson textures\njson texture 0 1\njson vertices 0 1 2\n"
                               "json tile 0 0 --summary\n");
    REQUIRE(js.code == 0);
    const std::vector<std::string> jl = lines_of(js.out);
    REQUIRE(jl.size() == 6);
    const json draws = json::parse(jl[0]), draw = json::parse(jl[1]), textures = json::parse(jl[2]),
               texture = json::parse(jl[3]), vertices = json::parse(jl[4]), tile = json::parse(jl[5]);
    CHECK(draws["draws"].size() == 1);
    CHECK(draws["draws"][0]["material_name"] == "checker");
    CHECK(draws["draws"][0]["drawn"] == 2);
    CHECK(draws["draws"][0]["alpha"] == "MASK 0.375");
    CHECK(draws["text"].get<std::string>().find("1 draw, in submission order:\n") == 0);
    CHECK(draw["state"]["material"]["metallic"] == 0.25);
    CHECK(draw["state"]["material"]["alpha_cutoff"] == 0.375);
    CHECK(draw["state"]["material"]["base_color"] == json::array({0.5, 0.25, 1, 1}));
    CHECK(draw["state"]["maps"][0]["texture"] == "0");
    CHECK(draw["state"]["maps"][0]["uv_set"] == 0);
    CHECK(draw["state"]["cull"] == "none");
    CHECK(textures["textures"][0]["levels"] == 3);
    CHECK(texture["level"] == 1);
    CHECK(texture["level_sizes"][1]["width"] == 2);
    CHECK(texture["colour_space"] == "sRGB");
    CHECK(texture["png"] == json({{"endpoint", "/api/texture.png"}, {"id", "0"}, {"level", 1}}));
    CHECK(vertices["vertices"].size() == 2);
    CHECK(vertices["vertices"][0]["index"] == 1);
    CHECK(vertices["vertices"][0]["position"] == json::array({1, -1, 0}));
    CHECK(tile["summary"]["bin_entries"] == 2);
    CHECK(tile["bins"].empty());
    // Bad input: one line each, naming the range.
    const CliRun bad = run_step(box, flags,
                                "draw 1\ndraw x\ntexture 1\ntexture 0 3\nvertices 1\nvertices 0 4\nvertices 0 0 0\n"
                                "draw\ntexture\nvertices\ndraws 1\njson frame\njson draw 7\n");
    CHECK(bad.code == 1);
    CHECK(bad.out == "error: draw '1': no such draw (draws 0..0)\n"
                     "error: draw 'x': no such draw (draws 0..0)\n"
                     "error: texture '1': no such texture (textures 0..0; `textures` lists them)\n"
                     "error: texture 0 level '3': no such level (levels 0..2)\n"
                     "error: vertices '1': no such draw (draws 0..0)\n"
                     "error: vertices 0 '4': no such vertex (draw 0 has vertices 0..3)\n"
                     "error: vertices 0 0 '0': not a count (1 or more)\n"
                     "error: usage: draw N (draws lists them)\n"
                     "error: usage: texture ID [LEVEL [FILE]] (textures lists the IDs)\n"
                     "error: usage: vertices N [FIRST [COUNT]] (draw N; FIRST 0 and COUNT 16 by default)\n"
                     "error: draws takes no arguments\n"
                     "error: usage: json draws | draw N | textures | texture ID [LEVEL] | texel ID LEVEL X Y | "
                     "vertices N [FIRST [COUNT]] | tile X Y [FILTER]\n"
                     "error: draw '7': no such draw (draws 0..0)\n");
}

TEST_CASE("views: the built-in scene's draws and maps, its shadow maps and sky as textures, tile filters") {
    CliSandbox box;
    const CliRun r = run_step(box, {"--size", "160x90", "--shadows", "on", "--shadow-size", "256"},
                              "draws\ndraw 24\ntextures\ntexture 0 9\ntexture shadow0\ntexture shadow1\ntexture env 3\n"
                              "vertices 24 70 1000000\nvertices 0 0 5000\ntile 1 0\ntile 1 0 --summary\n");
    INFO(r.out << r.err);
    REQUIRE(r.code == 0);
    CHECK(r.out.find("25 draws, in submission order:\n  draw 0: mesh 0 'sphere', material 0 'sphere_m0_r0', 4096 "
                     "triangles, visible (") != std::string::npos);
    CHECK(r.out.find("  draw 24: mesh 24 'floor', material 24 'tiles', 128 triangles, ") != std::string::npos);
    // The floor's maps: procedural, float, 512x512 with 10 levels.
    CHECK(r.out.find("  map base_color: texture 0, image 0 'builtin:tiles_albedo', 512x512, RGBA float32 linear, 10 mip levels, "
                     "sampler: mag LINEAR, min LINEAR_MIPMAP_LINEAR, wrap repeat/repeat, UV set 0\n") != std::string::npos);
    CHECK(r.out.find("  shadows on, maps of 256 texels a side (cube faces half that)\n") != std::string::npos);
    CHECK(r.out.find("shadow map shadow0 (directional, 256x256)") != std::string::npos);
    CHECK(r.out.find("shadow map shadow1 (cube, 6 faces of 128x128)") != std::string::npos);
    CHECK(r.out.find("  environment: texture env, 512x256, intensity 1, rotated 0 degrees") != std::string::npos);
    CHECK(r.out.find("  texture shadow0: 256x256, 1 level, distance float32, directional\n") != std::string::npos);
    CHECK(r.out.find("  texture shadow1: 128x768, 1 level, distance float32, a cube of 6 faces of 128x128") !=
          std::string::npos);
    CHECK(r.out.find("  texture env: 512x256, 8 levels, RGB float32 linear radiance") != std::string::npos);
    CHECK(r.out.find("texture 0 9 -> wrote texture-0-level-9.png\n") != std::string::npos);
    CHECK(r.out.find("texture env 3 -> wrote texture-env-level-3.png\n") != std::string::npos);
    const PngFile floor9 = load_png(box.path("texture-0-level-9.png"));
    CHECK(floor9.width == 1);
    CHECK(floor9.channels == 4);
    const PngFile sun = load_png(box.path("texture-shadow0-level-0.png"));
    CHECK(sun.width == 256);
    CHECK(sun.height == 256);
    CHECK(sun.channels == 1);
    CHECK(std::count(sun.bytes.begin(), sun.bytes.end(), 0) > 0);  // the ramp reaches black at the nearest caster
    const std::regex ramp("  distance ([-0-9.e]+) \\(black\\) \\.\\. ([-0-9.e]+) \\(grey 254\\)");
    std::smatch m;
    REQUIRE(std::regex_search(r.out, m, ramp));
    CHECK(std::stof(m[1]) < std::stof(m[2]));
    const PngFile cube = load_png(box.path("texture-shadow1-level-0.png"));
    CHECK(cube.width == 128);
    CHECK(cube.height == 768);
    const PngFile env3 = load_png(box.path("texture-env-level-3.png"));
    CHECK(env3.width > 0);
    CHECK(r.out.find("  levels: 0 512x256, 1 256x128, 2 128x64, 3 64x32,") != std::string::npos);
    CHECK(env3.width == 64);
    CHECK(env3.height == 32);
    // Vertices: from 70 the floor's 81 leave 11 rows; 5000 of a sphere's are capped at 1000, with a note.
    CHECK(r.out.find("vertices of draw 24 (mesh 'floor'): 11 of 81 vertices from 70\n") != std::string::npos);
    CHECK(r.out.find("vertices of draw 0 (mesh 'sphere'): 1000 of 2145 vertices from 0 (5000 asked, capped at 1000 "
                     "rows: ask again with FIRST 1000 for more)\n") != std::string::npos);
    CHECK(r.out.find("  v999 in: ") != std::string::npos);
    CHECK(r.out.find("  v1000 in: ") == std::string::npos);
    // Tiles: the summary first, then the bins; --summary alone.
    const std::size_t t0 = r.out.find("tile 1 0: pixels x 64..127 y 0..63\n");
    REQUIRE(t0 != std::string::npos);
    CHECK(r.out.find("triangles binned (", t0) != std::string::npos);
    CHECK(r.out.find(" bin entries in the order the tile ran them:\n", t0) != std::string::npos);
    const std::regex one_plural("[^0-9.]1 (blocks|fragments|triangles|pixels|bin entries|levels)[^a-z]");
    CHECK(!std::regex_search(r.out, one_plural));
    CHECK(r.out.find(": 1 block, 1 fragment, ") != std::string::npos);
    // Bad input.
    const CliRun bad = run_step(box, {"--size", "160x90"},
                                "draw 25\ntexture nope\ntexture shadow0\ntexture env 8\ntile 0 0 tri 98432\n"
                                "tile 0 0 pixel 64 0\ntile 0 0 bogus\ntile 3 0\n");
    CHECK(bad.code == 1);
    CHECK(bad.out == "error: draw '25': no such draw (draws 0..24)\n"
                     "error: texture 'nope': no such texture (textures 0..2, env; `textures` lists them)\n"
                     "error: texture 'shadow0': no such texture (textures 0..2, env; `textures` lists them)\n"
                     "error: texture env level '8': no such level (levels 0..7)\n"
                     "error: tile 0 0 tri '98432': not a triangle number (0..98431)\n"
                     "error: tile 0 0 pixel '64 0': not in the tile (x 0..63, y 0..63)\n"
                     "error: usage: tile X Y [tri N | pixel X Y | --summary] (tile column and row)\n"
                     "error: tile '3 0': outside the 3x2 tiles (columns 0..2, rows 0..1)\n");
}

TEST_CASE("tile: the filters pick the bins of one triangle and of one pixel, which add up to the summary") {
    CliSandbox box;
    const CliRun r = run_step(box, {"--size", "640x360"}, "tile 6 2\npixel 390 190\n");
    INFO(r.out);
    REQUIRE(r.code == 0);
    // The pixel's winning triangle, from pixel's history.
    const std::regex winner("  #[0-9]+ draw [0-9]+ \\(mesh '[^']*'\\) triangle [0-9]+ \\(frame triangle ([0-9]+)\\)");
    std::smatch m;
    REQUIRE(std::regex_search(r.out, m, winner));
    const std::string tri = m[1];
    const CliRun f = run_step(box, {"--size", "640x360"}, "tile 6 2 tri " + tri + "\ntile 6 2 pixel 390 190\n");
    INFO(f.out);
    REQUIRE(f.code == 0);
    CHECK(f.out.find(" of tri " + tri + ", in the order the tile ran them:\n  tri " + tri) != std::string::npos);
    CHECK(f.out.find("    block ") != std::string::npos);
    CHECK(f.out.find(" of pixel 390 190, in the order the tile ran them:\n") != std::string::npos);
    CHECK(f.out.find("    block 388 188 lane ") != std::string::npos);
    CHECK(f.out.find("  tri " + tri) != f.out.rfind("  tri " + tri));  // in both filters
    // The summary's counts are the sums of the bins' lines.
    const std::string all = r.out.substr(0, r.out.find("pixel 390 190:"));
    const std::regex summary("  ([0-9]+) triangles? binned \\(([0-9]+) bin entr(y|ies)\\), ([0-9]+) 4x4 blocks?, ([0-9]+) "
                             "fragments? covered: ([0-9]+) passed the depth test, ([0-9]+) failed; ([0-9]+) shaded, "
                             "([0-9]+) written to ([0-9]+) pixels?");
    REQUIRE(std::regex_search(all, m, summary));
    const long blocks = std::stol(m[4]), covered = std::stol(m[5]), passed = std::stol(m[6]), failed = std::stol(m[7]);
    CHECK(covered == passed + failed);
    CHECK(std::stol(m[10]) <= 64 * 64);
    long sum_blocks = 0, sum_covered = 0;
    const std::regex bin("  tri [0-9]+( piece [0-9]+)? \\('[^']*'\\): ([0-9]+) blocks?, ([0-9]+) fragments?,");
    for (std::sregex_iterator it(all.begin(), all.end(), bin), end; it != end; ++it) {
        sum_blocks += std::stol((*it)[2]);
        sum_covered += std::stol((*it)[3]);
    }
    CHECK(sum_blocks == blocks);
    CHECK(sum_covered == covered);
}

TEST_CASE("frame names a spot light's cone and range as light_at() applies them") {
    CliSandbox box;
    GltfWriter g;
    const int pos = g.floats({-1, -1, 0, 1, -1, 0, 0, 1, 0}, "VEC3", 3);
    g.doc["meshes"].push_back({{"primitives", json::array({{{"attributes", {{"POSITION", pos}}}}})}});
    g.doc["extensionsUsed"] = {"KHR_lights_punctual"};
    g.doc["extensions"]["KHR_lights_punctual"]["lights"] = json::array(
        {{{"type", "spot"}, {"intensity", 5}, {"range", 4}, {"spot", {{"innerConeAngle", 0.2}, {"outerConeAngle", 0.5}}}}});
    g.doc["nodes"] = json::array({{{"mesh", 0}}, {{"translation", {0, 0, 2}}, {"extensions", {{"KHR_lights_punctual", {{"light", 0}}}}}}});
    g.doc["scenes"] = json::array({{{"nodes", {0, 1}}}});
    write_text(box.path("spot.gltf"), g.text());
    const CliRun r = run_step(box, {box.path("spot.gltf"), "--size", "32x32"}, "frame\n");
    REQUIRE(r.code == 0);
    // scale = 1 / (cos 0.2 - cos 0.5), offset = -cos 0.5 scale (KHR_lights_punctual).
    const double scale = 1.0 / (std::cos(0.2) - std::cos(0.5)), offset = -std::cos(0.5) * scale;
    const std::string head = "light 0: spot at (0, 0, 2) shining along (0, 0, -1) radiance (5, 5, 5) cone clamp(-l.axis * ";
    const std::size_t at = r.out.find(head);
    REQUIRE(at != std::string::npos);
    double got_scale = 0, got_offset = 0;
    REQUIRE(std::sscanf(r.out.c_str() + at + head.size(), "%lf + %lf, 0, 1)^2 range 4", &got_scale, &got_offset) == 2);
    CHECK(got_scale == doctest::Approx(scale).epsilon(1e-6));
    CHECK(got_offset == doctest::Approx(offset).epsilon(1e-6));
    CHECK(r.out.find(", 0, 1)^2 range 4\n", at) != std::string::npos);
}

} // TEST_SUITE

TEST_SUITE("readme") {

// The README's first paragraph names what scripts/install-deps.sh installs:
// the same packages, so a reader who installs by hand gets a working build.
TEST_CASE("README: the install paragraph lists exactly the packages of scripts/install-deps.sh") {
    const std::string readme = read_text(std::string(PRAST_SOURCE_DIR) + "/README.md");
    const std::string script = read_text(std::string(PRAST_SOURCE_DIR) + "/scripts/install-deps.sh");
    auto words = [](const std::string& text) {
        std::vector<std::string> out;
        std::string w;
        for (char c : text + " ") {
            if (c == ' ' || c == '\n' || c == '`' || c == '\t') {
                if (!w.empty()) out.push_back(w);
                w.clear();
            } else {
                w += c;
            }
        }
        return out;
    };
    // The script: the words between PACKAGES=" and the closing quote.
    const std::size_t a = script.find("PACKAGES=\"");
    REQUIRE(a != std::string::npos);
    const std::size_t b = script.find('"', a + 10);
    REQUIRE(b != std::string::npos);
    std::vector<std::string> want = words(script.substr(a + 10, b - a - 10));
    // The README: the words after "it installs" up to the sentence's end.
    const std::size_t c = readme.find("it installs ");
    REQUIRE(c != std::string::npos);
    const std::size_t d = readme.find('.', c);
    std::vector<std::string> got = words(readme.substr(c + 12, d - c - 12));
    std::sort(want.begin(), want.end());
    std::sort(got.begin(), got.end());
    CHECK(want.size() >= 12);
    CHECK(got == want);
}


} // TEST_SUITE

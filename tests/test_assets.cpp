// The project's own assets (assets/, made by assets/make_assets.py): the
// script reproduces the committed files byte for byte (suite "assets"), the
// loaders read each with the counts and materials the script writes (suite
// "load"), and `render` draws them (suite "cli").
#include <doctest/doctest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "cli_util.h"
#include "scene/image.h"
#include "scene/load_scene.h"
#include "scene/tangents.h"
#include "tests/scratch.h"

namespace fs = std::filesystem;
using namespace prast;

namespace {

const std::string kAssets = std::string(PRAST_SOURCE_DIR) + "/assets";

// The files make_assets.py writes, relative to assets/.
const std::vector<std::string> kGenerated = {
    "cornell/cornell.obj",        "cornell/cornell.mtl",        "textured-sphere/sphere.gltf",
    "textured-sphere/sphere.bin", "textured-sphere/albedo.png", "textured-sphere/normal.png",
    "textured-sphere/orm.png",    "env/studio_small.hdr"};

const Material* find_material(const Scene& s, const std::string& name) {
    for (const Material& m : s.materials)
        if (m.name == name) return &m;
    return nullptr;
}

bool near3(const glm::vec3& a, const glm::vec3& b, float eps = 1e-6f) {
    return std::fabs(a.x - b.x) <= eps && std::fabs(a.y - b.y) <= eps && std::fabs(a.z - b.z) <= eps;
}

} // namespace

TEST_SUITE("assets") {

TEST_CASE("assets/make_assets.py reproduces the committed files byte for byte") {
    if (std::system("command -v python3 >/dev/null 2>&1") != 0) {
        MESSAGE("skipped: python3 is not installed, the assets cannot be regenerated here");
        return;
    }
    test::TempDir out("assets");
    const std::string cmd = "python3 " + cli_test::shell_quote(kAssets + "/make_assets.py") + " --out " +
                            cli_test::shell_quote(out.path.string()) + " >/dev/null";
    REQUIRE(std::system(cmd.c_str()) == 0);
    std::size_t generated = 0;
    for (const auto& e : fs::recursive_directory_iterator(out.path))
        if (e.is_regular_file()) ++generated;
    CHECK(generated == kGenerated.size());  // the list above is complete
    for (const std::string& name : kGenerated) {
        CAPTURE(name);
        const std::vector<unsigned char> fresh = test::read_bytes(out.file(name));
        const std::vector<unsigned char> committed = test::read_bytes(kAssets + "/" + name);
        REQUIRE_FALSE(fresh.empty());
        CHECK(fresh == committed);
    }
}

TEST_CASE("the generated assets stay small: under 256 KB together") {
    std::uintmax_t generated = 0, folder = 0;
    for (const std::string& name : kGenerated) generated += fs::file_size(kAssets + "/" + name);
    for (const auto& e : fs::recursive_directory_iterator(kAssets))
        if (e.is_regular_file()) folder += e.file_size();
    MESSAGE("assets/: " << generated << " bytes from make_assets.py, " << folder << " bytes in the folder");
    CHECK(generated < 256u * 1024u);
}

} // TEST_SUITE("assets")

TEST_SUITE("load") {

TEST_CASE("assets/cornell: eight objects, four materials, the room's bounds and inward walls") {
    const Scene s = load_scene(kAssets + "/cornell/cornell.obj");
    CHECK(s.warnings.empty());
    // Walls, floor, ceiling and the light panel are one quad each; the two
    // boxes have five faces each (no bottom): 6 * 2 + 10 * 2 triangles.
    CHECK(s.meshes.size() == 8u);
    CHECK(s.triangle_count() == 32u);
    const Bounds b = s.bounds();
    CHECK(near3(b.lo, glm::vec3(-1.0f, 0.0f, -1.0f)));
    CHECK(near3(b.hi, glm::vec3(1.0f, 2.0f, 1.0f)));
    const Material* red = find_material(s, "red");
    const Material* green = find_material(s, "green");
    const Material* white = find_material(s, "white");
    const Material* light = find_material(s, "light");
    REQUIRE(red);
    REQUIRE(green);
    REQUIRE(white);
    REQUIRE(light);
    CHECK(near3(glm::vec3(red->base_color_factor), glm::vec3(0.63f, 0.065f, 0.05f)));
    CHECK(near3(glm::vec3(green->base_color_factor), glm::vec3(0.14f, 0.45f, 0.091f)));
    CHECK(white->roughness_factor == doctest::Approx(0.9f));
    CHECK(white->metallic_factor == 0.0f);
    CHECK(near3(light->emissive_factor, glm::vec3(1.0f, 0.85f, 0.6f)));
    CHECK(near3(white->emissive_factor, glm::vec3(0.0f)));
    // Every wall faces the inside: its normal points towards the room's centre.
    for (const Mesh& m : s.meshes) {
        if (m.name == "short_box" || m.name == "tall_box") continue;
        CAPTURE(m.name);
        REQUIRE_FALSE(m.normals.empty());
        const glm::vec3 to_centre = glm::vec3(0.0f, 1.0f, 0.0f) - m.positions[0];
        CHECK(glm::dot(m.normals[0], to_centre) > 0.0f);
    }
}

TEST_CASE("assets/textured-sphere: one UV sphere, its maps, and tangents that agree with its UVs") {
    const Scene s = load_scene(kAssets + "/textured-sphere/sphere.gltf");
    CHECK(s.warnings.empty());
    REQUIRE(s.meshes.size() == 1u);
    const Mesh& m = s.meshes[0];
    // 32 segments x 16 rings, one triangle per segment at each pole; the two
    // pole vertices no triangle uses (first and last of a pole row) are dropped.
    CHECK(s.triangle_count() == 32u * 16u * 2u - 2u * 32u);
    CHECK(m.positions.size() == 33u * 17u - 2u);
    REQUIRE(m.uvs.size() == m.positions.size());
    REQUIRE(m.tangents.size() == m.positions.size());
    for (const glm::vec3& p : m.positions) CHECK(glm::length(p) == doctest::Approx(1.0f).epsilon(1e-6));
    REQUIRE(s.materials.size() == 1u);
    const Material& mat = s.materials[0];
    CHECK(mat.base_color.valid());
    CHECK(mat.normal.valid());
    CHECK(mat.metallic_roughness.valid());
    CHECK(mat.occlusion.valid());
    CHECK(mat.occlusion.image == mat.metallic_roughness.image);  // one ORM map
    CHECK(s.images.size() == 3u);
    for (const ImageSource& src : s.images) {
        const Image img = decode_image(src, false);
        CHECK(img.width == 128);
        CHECK(img.height == 64);
    }
    // The file's tangents are the ones the project would compute from the UVs
    // (docs/conventions.md, "Normal mapping": T along +u, cross(N, T) w up the
    // image), away from the poles where dP/du vanishes.
    Mesh computed = m;
    computed.tangents.clear();
    compute_tangents(computed);
    int compared = 0;
    for (std::size_t i = 0; i < m.positions.size(); ++i) {
        if (std::fabs(m.positions[i].y) > 0.95f) continue;
        const glm::vec4 t = m.tangents[i], c = computed.tangents[i];
        CHECK(glm::dot(glm::vec3(t), glm::vec3(c)) > 0.99f);
        CHECK(t.w == c.w);
        ++compared;
    }
    CHECK(compared > 400);
}

TEST_CASE("assets/env/studio_small.hdr: 128x64, the key light front left and up, the floor dim") {
    ImageSource src;
    src.path = kAssets + "/env/studio_small.hdr";
    const Image env = decode_image(src, false);
    REQUIRE(env.width == 128);
    REQUIRE(env.height == 64);
    // The key soft box: the texels brighter than anything else in the map
    // (radiance sum over 40; the rim and fill lights stay below 25).
    glm::dvec3 sum(0.0);
    int count = 0;
    for (int y = 0; y < env.height; ++y)
        for (int x = 0; x < env.width; ++x) {
            const glm::vec4 c = env.at(x, y);
            if (c.r + c.g + c.b <= 40.0f) continue;
            // Its direction (docs/conventions.md, "Environment maps"): u = 0.5 + atan2(x, -z) / 2 pi,
            // v = acos(y) / pi.
            const double u = (x + 0.5) / env.width, v = (y + 0.5) / env.height;
            const double phi = (u - 0.5) * 2.0 * M_PI, theta = v * M_PI;
            sum += glm::dvec3(std::sin(theta) * std::sin(phi), std::cos(theta), -std::sin(theta) * std::cos(phi));
            ++count;
        }
    REQUIRE(count > 20);
    // The script centres it at u = 0.125, v = 0.306: 35 degrees up, towards -X
    // (left) and +Z (the camera's side): (-0.58, 0.57, 0.58).
    const glm::dvec3 d = glm::normalize(sum);
    CHECK(d.x == doctest::Approx(-0.58).epsilon(0.1));
    CHECK(d.y == doctest::Approx(0.57).epsilon(0.1));
    CHECK(d.z == doctest::Approx(0.58).epsilon(0.1));
    // The zenith row is the dome's brightest grey (0.59 * (0.9, 0.95, 1.1) by
    // the script), within RGBE's 8-bit mantissa; the bottom row is the floor.
    const glm::vec4 top = env.at(0, 0), bottom = env.at(0, env.height - 1);
    const double k = 0.25 + 0.35 * (1.0 - 2.0 * (0.5 / 64.0));
    CHECK(top.r == doctest::Approx(k * 0.9).epsilon(0.01));
    CHECK(top.b == doctest::Approx(k * 1.1).epsilon(0.01));
    CHECK(bottom.r < 0.1f);
    CHECK(bottom.r > 0.0f);
}

} // TEST_SUITE("load")

TEST_SUITE("cli") {

TEST_CASE("render draws assets/cornell: red wall left, green wall right, lit floor") {
    cli_test::CliSandbox box;
    const cli_test::CliRun r =
        box.run_exe(PRAST_RENDER_EXE, {kAssets + "/cornell/cornell.obj", "--eye", "0,1,3.9", "--target", "0,1,0",
                                       "--fov", "38", "--point", "0,1.9,0.6:3,2.8,2.3", "--size", "96x96", "-o",
                                       "cornell.png"});
    REQUIRE_MESSAGE(r.code == 0, r.err);
    const cli_test::Rgb8 img = cli_test::load_rgb8(box.path("cornell.png"));
    REQUIRE(img.width == 96);
    const std::uint8_t* left = img.at(6, 48);
    const std::uint8_t* right = img.at(89, 48);
    const std::uint8_t* floor = img.at(48, 92);
    CAPTURE(int(left[0]));
    CAPTURE(int(left[1]));
    CAPTURE(int(right[0]));
    CAPTURE(int(right[1]));
    CHECK(left[0] > left[1] + 60);
    CHECK(right[1] > right[0] + 40);
    CHECK(int(floor[0]) > 40);
}

TEST_CASE("render draws assets/textured-sphere with its textures") {
    cli_test::CliSandbox box;
    const cli_test::CliRun r = box.run_exe(
        PRAST_RENDER_EXE, {kAssets + "/textured-sphere/sphere.gltf", "--size", "64x64", "-o", "sphere.png"});
    REQUIRE_MESSAGE(r.code == 0, r.err);
    const cli_test::Rgb8 img = cli_test::load_rgb8(box.path("sphere.png"));
    REQUIRE(img.width == 64);
    CHECK(img.mean() > 20.0);
    // Corners are background, the centre is the sphere.
    CHECK(int(img.at(0, 0)[0]) + img.at(0, 0)[1] + img.at(0, 0)[2] == 0);
    CHECK(int(img.at(32, 32)[0]) + img.at(32, 32)[1] + img.at(32, 32)[2] > 0);
    // The albedo's hues differ across the sphere (the texture is used, not a flat factor).
    const std::uint8_t* a = img.at(24, 28);
    const std::uint8_t* b = img.at(40, 28);
    CHECK(std::abs(int(a[0]) - int(b[0])) + std::abs(int(a[1]) - int(b[1])) + std::abs(int(a[2]) - int(b[2])) > 30);
}

} // TEST_SUITE("cli")

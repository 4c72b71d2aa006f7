// Skins, morph targets, animations sampled at a time and the file's cameras
// (scene/animation.h, scene/gltf_graph.h), on small glTF files written here:
// exact vertex positions of a bent two-bone strip, a morph at weight 0.5,
// keyframes halfway against hand values and the spline formula, clamping,
// cameras through `render --camera` against exact pixel ranges, `render
// --list`, a sequence (`--frames --fps`), thread-count independence,
// `step pixel` == `render`, and hostile files.
#include <doctest/doctest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "tests/cli_util.h"
#include "tests/gltf_writer.h"

#include "scene/animation.h"
#include "scene/load_scene.h"

using namespace prast;
using namespace prast::cli_test;
using nlohmann::json;

namespace {

const std::string kRender = PRAST_RENDER_EXE;
const std::string kStep = PRAST_STEP_EXE;
const double kPi = 3.14159265358979323846;

// The tests' glTF writer (tests/gltf_writer.h), written into a sandbox.
// Hostile files write NaN: their float accessors carry no min and max.
struct Gltf : prast::gltf_test::GltfWriter {
    int floats(const std::vector<float>& v, const char* type, int per) {
        if (std::all_of(v.begin(), v.end(), [](float x) { return std::isfinite(x); }))
            return GltfWriter::floats(v, type, per);
        return add_raw(v.data(), v.size() * 4, 5126, type, v.size() / std::size_t(per));
    }
    std::string write(const CliSandbox& box, const std::string& name) const {
        write_text(box.path(name), text());
        return box.path(name);
    }
};

// An emissive white, black-based material: pixels are bright where drawn.
json glowing_material() {
    return {{"pbrMetallicRoughness", {{"baseColorFactor", {0, 0, 0, 1}}, {"metallicFactor", 0}}},
            {"emissiveFactor", {1, 1, 1}}};
}

// The strip x in [-0.5, 0.5], y in 0..2 (rows at y = 0, 1, 2), two joints:
// joint 0 at the origin, joint 1 at y = 1 (its child), rotated by
// `rotation` (x, y, z, w). Row 0 follows joint 0, row 2 joint 1, row 1 both
// half and half. The mesh's own node is moved by 5 in x, which skinning ignores.
Gltf bent_strip(const std::vector<double>& rotation) {
    Gltf g;
    const int pos = g.floats({-0.5f, 0, 0, 0.5f, 0, 0, -0.5f, 1, 0, 0.5f, 1, 0, -0.5f, 2, 0, 0.5f, 2, 0}, "VEC3", 3);
    const int nrm = g.floats({0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1}, "VEC3", 3);
    const int uv = g.floats({0, 1, 1, 1, 0, 0.5f, 1, 0.5f, 0, 0, 1, 0}, "VEC2", 2);
    const int tan = g.floats({1, 0, 0, 1, 1, 0, 0, 1, 1, 0, 0, 1, 1, 0, 0, 1, 1, 0, 0, 1, 1, 0, 0, 1}, "VEC4", 4);
    const int joints = g.u16({0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0}, "VEC4", 4);
    const int weights = g.floats({1, 0, 0, 0, 1, 0, 0, 0, 0.5f, 0.5f, 0, 0, 0.5f, 0.5f, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0},
                                 "VEC4", 4);
    const std::vector<std::uint16_t> idx = {0, 1, 3, 0, 3, 2, 2, 3, 5, 2, 5, 4};
    const int ind = g.u16(idx, "SCALAR", 1);
    // Inverse bind matrices: identity, and translate(0, -1, 0) (column-major).
    const int ibm = g.floats({1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1,  //
                              1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, -1, 0, 1},
                             "MAT4", 16);
    g.doc["materials"] = json::array({glowing_material()});
    g.doc["materials"][0]["doubleSided"] = true;
    g.doc["meshes"].push_back(
        {{"primitives",
          json::array({{{"attributes",
                         {{"POSITION", pos}, {"NORMAL", nrm}, {"TEXCOORD_0", uv}, {"TANGENT", tan},
                          {"JOINTS_0", joints}, {"WEIGHTS_0", weights}}},
                        {"indices", ind},
                        {"material", 0}}})}});
    g.doc["nodes"] = json::array({{{"name", "root"}, {"children", {1}}},
                                  {{"name", "bone"}, {"translation", {0, 1, 0}}, {"rotation", rotation}},
                                  {{"name", "strip"}, {"mesh", 0}, {"skin", 0}, {"translation", {5, 0, 0}}}});
    g.doc["skins"] = json::array({{{"joints", {0, 1}}, {"inverseBindMatrices", ibm}}});
    g.doc["scenes"] = json::array({{{"nodes", {0, 2}}}});
    g.doc["scene"] = 0;
    return g;
}

void check_vec(const glm::vec3& got, const glm::vec3& want, float tol = 1e-6f) {
    INFO("got " << got.x << " " << got.y << " " << got.z << " want " << want.x << " " << want.y << " " << want.z);
    CHECK(std::fabs(got.x - want.x) <= tol);
    CHECK(std::fabs(got.y - want.y) <= tol);
    CHECK(std::fabs(got.z - want.z) <= tol);
}

// A unit-ish triangle facing +z under node 1 (child of node 0), animated by
// one channel of `path` with `interp`, key times `times`, values `values`.
Gltf animated_triangle(const char* path, const char* interp, const std::vector<float>& times,
                       const std::vector<float>& values, const char* type, int per) {
    Gltf g;
    const int pos = g.floats({0, 0, 0, 1, 0, 0, 0, 1, 0}, "VEC3", 3);
    g.doc["meshes"].push_back({{"primitives", json::array({{{"attributes", {{"POSITION", pos}}}}})}});
    g.doc["nodes"] = json::array({{{"children", {1}}}, {{"mesh", 0}}});
    const int in = g.floats(times, "SCALAR", 1);
    const int out = g.floats(values, type, per);
    g.doc["animations"] = json::array(
        {{{"name", "move"},
          {"samplers", json::array({{{"input", in}, {"output", out}, {"interpolation", interp}}})},
          {"channels", json::array({{{"sampler", 0}, {"target", {{"node", 1}, {"path", path}}}}})}}});
    return g;
}

// The triangle's vertex 1 ((1, 0, 0) in its node) at time t.
glm::vec3 vertex1_at(const std::string& file, double t) {
    Scene s = load_scene(file);
    REQUIRE(s.source);
    pose_scene(s, t, kAllAnimations);
    REQUIRE(s.meshes.size() == 1);
    return s.meshes[0].positions[1];
}

// A quad x, y in [-0.5, 0.5] at z = 0 facing +z, glowing, and cameras.
Gltf quad_with_cameras() {
    Gltf g;
    const int pos = g.floats({-0.5f, -0.5f, 0, 0.5f, -0.5f, 0, 0.5f, 0.5f, 0, -0.5f, 0.5f, 0}, "VEC3", 3);
    const int ind = g.u16({0, 1, 2, 0, 2, 3}, "SCALAR", 1);
    g.doc["materials"] = json::array({glowing_material()});
    g.doc["meshes"].push_back(
        {{"primitives", json::array({{{"attributes", {{"POSITION", pos}}}, {"indices", ind}, {"material", 0}}})}});
    // Perspective: half height tan(yfov / 2) = 0.5 at distance 1 per unit, so at
    // distance 2 the view is 2 high and the quad fills the middle half.
    g.doc["cameras"] = json::array(
        {{{"type", "perspective"}, {"name", "persp"}, {"perspective", {{"yfov", 2 * std::atan(0.5)}, {"znear", 0.1}}}},
         {{"type", "orthographic"},
          {"name", "ortho"},
          {"orthographic", {{"xmag", 1}, {"ymag", 1}, {"znear", 0.1}, {"zfar", 100}}}}});
    g.doc["nodes"] = json::array({{{"mesh", 0}},
                                  {{"translation", {0, 0, 1}}, {"children", {2}}},
                                  {{"camera", 0}, {"translation", {0, 0, 1}}},
                                  {{"camera", 1}, {"translation", {0, 0, 5}}}});
    // The perspective camera's parent moves from z = 1 to z = 3 over one second.
    const int in = g.floats({0, 1}, "SCALAR", 1);
    const int out = g.floats({0, 0, 1, 0, 0, 3}, "VEC3", 3);
    g.doc["animations"] = json::array(
        {{{"name", "dolly"},
          {"samplers", json::array({{{"input", in}, {"output", out}}})},
          {"channels", json::array({{{"sampler", 0}, {"target", {{"node", 1}, {"path", "translation"}}}}})}}});
    g.doc["scenes"] = json::array({{{"nodes", {0, 1, 3}}}});
    return g;
}

// The pixels brighter than the black background: the bounding box
// [x0, x1) x [y0, y1), and whether every pixel inside is lit.
struct Lit {
    int x0 = 1 << 30, y0 = 1 << 30, x1 = -1, y1 = -1;
    bool solid = true;
};
Lit lit_box(const Rgb8& img) {
    Lit b;
    for (int y = 0; y < img.height; ++y)
        for (int x = 0; x < img.width; ++x)
            if (img.at(x, y)[0] > 0) {
                b.x0 = std::min(b.x0, x), b.y0 = std::min(b.y0, y);
                b.x1 = std::max(b.x1, x + 1), b.y1 = std::max(b.y1, y + 1);
            }
    for (int y = b.y0; y < b.y1; ++y)
        for (int x = b.x0; x < b.x1; ++x) b.solid = b.solid && img.at(x, y)[0] > 0;
    return b;
}

bool has_warning(const Scene& s, const std::string& part) {
    for (const std::string& w : s.warnings)
        if (w.find(part) != std::string::npos) return true;
    return false;
}

} // namespace

TEST_SUITE("animation") {

TEST_CASE("a two-bone strip bent 90 degrees: exact skinned positions, normals and tangents") {
    CliSandbox box;
    const double h = std::sqrt(0.5);
    // 90 degrees about +z.
    const std::string file = bent_strip({0, 0, h, h}).write(box, "bent.gltf");
    const Scene s = load_scene(file);
    REQUIRE(s.source);
    REQUIRE(s.meshes.size() == 1);
    const Mesh& m = s.meshes[0];
    REQUIRE(m.positions.size() == 6);
    // Row 0: joint 0 (identity); the node's own x + 5 is not applied.
    check_vec(m.positions[0], {-0.5f, 0, 0});
    check_vec(m.positions[1], {0.5f, 0, 0});
    // Row 2: about (0, 1, 0) by 90 degrees: (x, 2) -> (-1, 1 + x).
    check_vec(m.positions[4], {-1, 0.5f, 0});
    check_vec(m.positions[5], {-1, 1.5f, 0});
    // Row 1: half of (x, 1) and half of (0, 1 + x).
    check_vec(m.positions[2], {-0.25f, 0.75f, 0});
    check_vec(m.positions[3], {0.25f, 1.25f, 0});
    // The normal stays +z; the tangent (+x) of row 2 turns to +y, of row 1 halfway.
    for (const glm::vec3& n : m.normals) check_vec(n, {0, 0, 1});
    check_vec(glm::vec3(m.tangents[5]), {0, 1, 0});
    check_vec(glm::vec3(m.tangents[3]), {float(h), float(h), 0});
    CHECK(m.tangents[5].w == 1.0f);
    CHECK(s.warnings.empty());

    // About +x instead: the normal of row 2 turns from +z to -y.
    const Scene x = load_scene(bent_strip({h, 0, 0, h}).write(box, "bent_x.gltf"));
    check_vec(x.meshes[0].positions[5], {0.5f, 1, 1});
    check_vec(x.meshes[0].normals[5], {0, -1, 0});
}

TEST_CASE("a skinned model is drawn skinned without --time, on any thread count") {
    CliSandbox box;
    const double h = std::sqrt(0.5);
    const std::string file = bent_strip({0, 0, h, h}).write(box, "bent.gltf");
    const CliRun a = box.run_exe(kRender, {file, "--size", "48x48", "--threads", "1", "-o", "a.png"});
    const CliRun b = box.run_exe(kRender, {file, "--size", "48x48", "--threads", "2", "--tile", "16", "-o", "b.png"});
    REQUIRE(a.code == 0);
    REQUIRE(b.code == 0);
    CHECK(a.err.find("warning") == std::string::npos);
    CHECK(read_bytes(box.path("a.png")) == read_bytes(box.path("b.png")));
    const Lit lit = lit_box(load_rgb8(box.path("a.png")));
    CHECK(lit.x1 > lit.x0);  // something is drawn
}

TEST_CASE("morph targets: base + weight * delta, from the mesh weights and a weights channel") {
    CliSandbox box;
    Gltf g;
    const int pos = g.floats({0, 0, 0, 1, 0, 0, 0, 1, 0}, "VEC3", 3);
    const int delta = g.floats({0, 0, 2, 0, 0, 2, 0, 0, 0}, "VEC3", 3);
    g.doc["meshes"].push_back({{"primitives", json::array({{{"attributes", {{"POSITION", pos}}},
                                                            {"targets", json::array({{{"POSITION", delta}}})}}})},
                               {"weights", {0.5}}});
    g.doc["nodes"] = json::array({{{"mesh", 0}}});
    const std::string file = g.write(box, "morph.gltf");
    const Scene s = load_scene(file);
    REQUIRE(s.source);
    check_vec(s.meshes[0].positions[0], {0, 0, 1});
    check_vec(s.meshes[0].positions[1], {1, 0, 1});
    check_vec(s.meshes[0].positions[2], {0, 1, 0});
    // The normal is computed from the morphed triangle: (1,0,1)-(0,0,1) x (0,1,0)-(0,0,1).
    check_vec(s.meshes[0].normals[2], glm::normalize(glm::cross(glm::vec3(1, 0, 0), glm::vec3(0, 1, -1))), 1e-6f);

    // A weights channel from 0 to 1 over a second: 0.25 at t = 0.25.
    const int in = g.floats({0, 1}, "SCALAR", 1);
    const int out = g.floats({0, 1}, "SCALAR", 1);
    g.doc["animations"] = json::array(
        {{{"samplers", json::array({{{"input", in}, {"output", out}}})},
          {"channels", json::array({{{"sampler", 0}, {"target", {{"node", 0}, {"path", "weights"}}}}})}}});
    Scene a = load_scene(g.write(box, "morph_anim.gltf"));
    check_vec(a.meshes[0].positions[0], {0, 0, 1});  // the rest pose: the mesh weights
    pose_scene(a, 0.25, kAllAnimations);
    check_vec(a.meshes[0].positions[0], {0, 0, 0.5f});
    pose_scene(a, 0.0, kNoAnimation);
    check_vec(a.meshes[0].positions[0], {0, 0, 1});
    CHECK(a.animation_names == std::vector<std::string>{"animation 0"});
}

TEST_CASE("keyframes: LINEAR, slerp, STEP and CUBICSPLINE halfway; clamped before the first and after the last") {
    CliSandbox box;
    // LINEAR translation 0 -> 4 in x over [0, 2]: exactly 2 at t = 1.
    const std::string lin = animated_triangle("translation", "LINEAR", {0, 2}, {0, 0, 0, 4, 0, 0}, "VEC3", 3)
                                .write(box, "lin.gltf");
    check_vec(vertex1_at(lin, 1.0), {3, 0, 0}, 0.0f);
    check_vec(vertex1_at(lin, 0.5), {2, 0, 0}, 0.0f);
    check_vec(vertex1_at(lin, -1.0), {1, 0, 0}, 0.0f);  // before the first key: the first value
    check_vec(vertex1_at(lin, 7.0), {5, 0, 0}, 0.0f);   // after the last: the last
    // At load (no time given): the rest pose, as the loader flattens it.
    CHECK(load_scene(lin).meshes[0].positions[1] == glm::vec3(1, 0, 0));

    // STEP: the value of the key at or before t.
    const std::string step = animated_triangle("translation", "STEP", {0, 1, 2}, {0, 0, 0, 4, 0, 0, 8, 0, 0}, "VEC3", 3)
                                 .write(box, "step.gltf");
    check_vec(vertex1_at(step, 0.99), {1, 0, 0}, 0.0f);
    check_vec(vertex1_at(step, 1.0), {5, 0, 0}, 0.0f);
    check_vec(vertex1_at(step, 1.5), {5, 0, 0}, 0.0f);

    // Rotation 0 -> 90 degrees about z over [0, 1]; halfway is 45 degrees
    // (slerp), also when the second key is written as its negative (the
    // shorter arc).
    const double h = std::sqrt(0.5), c = std::cos(kPi / 8), s = std::sin(kPi / 8);
    for (float sign : {1.0f, -1.0f}) {
        const std::string rot = animated_triangle("rotation", "LINEAR", {0, 1},
                                                  {0, 0, 0, 1, 0, 0, sign * float(h), sign * float(h)}, "VEC4", 4)
                                    .write(box, "rot.gltf");
        Scene sc = load_scene(rot);
        const NodePose p = pose_nodes(*sc.source, 0.5, kAllAnimations);
        // cos 45 = 1 - 2 s^2 and sin 45 = 2 s c of the hand quaternion (0, 0, s, c).
        CHECK(p.world[1][0][0] == doctest::Approx(1 - 2 * s * s).epsilon(1e-7));
        CHECK(p.world[1][0][1] == doctest::Approx(2 * s * c).epsilon(1e-7));
        check_vec(vertex1_at(rot, 0.25), {float(std::cos(kPi / 8)), float(std::sin(kPi / 8)), 0}, 1e-6f);
    }

    // CUBICSPLINE: in-tangent, value, out-tangent per key. Times 0 and 2
    // (td = 2); at t = 0.5, u = 0.25: the Hermite formula by hand.
    const float v0 = 1, b0 = 3, a1 = -2, v1 = 5;
    const std::string cub =
        animated_triangle("translation", "CUBICSPLINE", {0, 2},
                          {9, 9, 9, v0, 0, 0, b0, 0, 0, a1, 0, 0, v1, 0, 0, 9, 9, 9}, "VEC3", 3)
            .write(box, "cubic.gltf");
    const double u = 0.25, td = 2.0;
    const double want = (2 * u * u * u - 3 * u * u + 1) * v0 + td * (u * u * u - 2 * u * u + u) * b0 +
                        (-2 * u * u * u + 3 * u * u) * v1 + td * (u * u * u - u * u) * a1;
    CHECK(vertex1_at(cub, 0.5).x == doctest::Approx(1.0 + want).epsilon(1e-6));
    CHECK(vertex1_at(cub, 0.0).x == doctest::Approx(1.0 + v0));
    CHECK(vertex1_at(cub, 3.0).x == doctest::Approx(1.0 + v1));
}

TEST_CASE("the rest pose of moving meshes has the loader's bytes; static files carry no source") {
    CliSandbox box;
    Gltf g = animated_triangle("translation", "LINEAR", {0, 1}, {0, 0, 0, 1, 0, 0}, "VEC3", 3);
    g.doc["nodes"][0]["rotation"] = {0.1, 0.2, 0.3, 0.9};
    g.doc["nodes"][1]["scale"] = {1.5, -2, 0.7};
    g.doc["nodes"][1]["translation"] = {0.3, -0.1, 2};
    Scene s = load_scene(g.write(box, "rest.gltf"));
    const Mesh before = s.meshes[0];
    pose_scene(s, 0.7, kAllAnimations);
    CHECK(s.meshes[0].positions != before.positions);
    pose_scene(s, 0.0, kNoAnimation);
    CHECK(s.meshes[0].positions == before.positions);
    CHECK(s.meshes[0].normals == before.normals);
    CHECK(s.meshes[0].indices == before.indices);

    Gltf plain;
    const int pos = plain.floats({0, 0, 0, 1, 0, 0, 0, 1, 0}, "VEC3", 3);
    plain.doc["meshes"].push_back({{"primitives", json::array({{{"attributes", {{"POSITION", pos}}}}})}});
    plain.doc["nodes"] = json::array({{{"mesh", 0}}});
    const Scene p = load_scene(plain.write(box, "plain.gltf"));
    CHECK(!p.source);
    CHECK(p.meshes[0].source_vertex.empty());
}

TEST_CASE("render --camera: perspective, orthographic and animated file cameras fill exact pixel ranges") {
    CliSandbox box;
    const std::string file = quad_with_cameras().write(box, "cams.gltf");
    auto render_box = [&](const std::vector<std::string>& extra) {
        std::vector<std::string> args = {file, "--size", "32x32", "--msaa", "1", "-o", "c.png"};
        args.insert(args.end(), extra.begin(), extra.end());
        const CliRun r = box.run_exe(kRender, args);
        INFO(r.err);
        REQUIRE(r.code == 0);
        return lit_box(load_rgb8(box.path("c.png")));
    };
    for (const char* cam : {"persp", "0", "ortho", "1"}) {
        INFO(cam);
        const Lit b = render_box({"--camera", cam});
        CHECK(b.x0 == 8);
        CHECK(b.x1 == 24);
        CHECK(b.y0 == 8);
        CHECK(b.y1 == 24);
        CHECK(b.solid);
    }
    // At t = 1 the perspective camera is at z = 4: the quad fills a quarter.
    const Lit far = render_box({"--camera", "persp", "--time", "1"});
    CHECK(far.x0 == 12);
    CHECK(far.x1 == 20);
    CHECK(far.y0 == 12);
    CHECK(far.y1 == 20);
    CHECK(far.solid);
    // A wide image keeps the vertical extent (the image's aspect is used).
    const CliRun wide = box.run_exe(kRender, {file, "--size", "64x32", "--msaa", "1", "--camera", "ortho", "-o", "w.png"});
    REQUIRE(wide.code == 0);
    const Lit w = lit_box(load_rgb8(box.path("w.png")));
    CHECK(w.x0 == 24);
    CHECK(w.x1 == 40);
    CHECK(w.y0 == 8);
    CHECK(w.y1 == 24);

    // Unknown names and numbers, and conflicting flags: one line, exit 2.
    const CliRun bad = box.run_exe(kRender, {file, "--camera", "nope"});
    CHECK(bad.code == 2);
    CHECK(bad.err.find("--camera 'nope': ") != std::string::npos);
    CHECK(bad.err.find("0 'persp', 1 'ortho'") != std::string::npos);
    CHECK(lines_of(bad.err).size() == 1);
    CHECK(box.run_exe(kRender, {file, "--camera", "2"}).code == 2);
    CHECK(box.run_exe(kRender, {file, "--animation", "walk"}).code == 2);
    const CliRun both = box.run_exe(kRender, {file, "--camera", "0", "--eye", "1,2,3"});
    CHECK(both.code == 2);
    CHECK(both.err == "render: --camera: the file's camera places the view; it cannot be combined with --eye\n");
}

TEST_CASE("render --list prints meshes, materials, cameras, animations, skins and extensions") {
    CliSandbox box;
    Gltf g = quad_with_cameras();
    g.doc["extensionsUsed"] = {"KHR_lights_punctual"};
    const std::string file = g.write(box, "cams.gltf");
    const CliRun r = box.run_exe(kRender, {"--list", file});
    INFO(r.out << r.err);
    REQUIRE(r.code == 0);
    const std::vector<std::string> lines = lines_of(r.out);
    auto has = [&](const std::string& line) { return std::find(lines.begin(), lines.end(), line) != lines.end(); };
    CHECK(has("meshes 1 (2 triangles)"));
    CHECK(has("  mesh 0 '': 2 triangles, 4 vertices, material 0, node 0"));
    CHECK(has("cameras 2"));
    CHECK(has("  camera 0 'persp': perspective, yfov 53.1301 degrees, znear 0.1 zfar infinite, node 2"));
    CHECK(has("  camera 1 'ortho': orthographic, xmag 1 ymag 1, znear 0.1 zfar 100, node 3"));
    CHECK(has("animations 1"));
    CHECK(has("  animation 0 'dolly': 1 s (keys 0 to 1 s), 1 channels: 1 translation, 0 rotation, 0 scale, 0 weights"));
    CHECK(has("skins 0"));
    CHECK(has("extensions used: KHR_lights_punctual"));
    CHECK(has("extensions required: none"));
    CHECK(box.work_files() == std::vector<std::string>{"cams.gltf"});  // nothing rendered
    const double h = std::sqrt(0.5);
    const CliRun s = box.run_exe(kRender, {"--list", bent_strip({0, 0, h, h}).write(box, "bent.gltf")});
    CHECK(s.out.find("skins 1\n  skin 0: 2 joints\n") != std::string::npos);
    CHECK(s.out.find(", node 2, skin 0\n") != std::string::npos);
    CHECK(box.run_exe(kRender, {"--list"}).code == 2);
}

TEST_CASE("--frames 3 --fps 2 renders frames at 0, 0.5 and 1 s; --frame-range splits it") {
    CliSandbox box;
    const std::string file = quad_with_cameras().write(box, "cams.gltf");
    const std::vector<std::string> common = {file, "--size", "32x32", "--camera", "persp"};
    auto with = [&](std::vector<std::string> extra) {
        std::vector<std::string> a = common;
        a.insert(a.end(), extra.begin(), extra.end());
        return a;
    };
    REQUIRE(box.run_exe(kRender, with({"--frames", "3", "--fps", "2", "-o", "f%04d.png"})).code == 0);
    for (int i = 0; i < 3; ++i) {
        const std::string t = i == 0 ? "0" : i == 1 ? "0.5" : "1";
        REQUIRE(box.run_exe(kRender, with({"--time", t, "-o", "t.png"})).code == 0);
        const std::string name = "f000" + std::to_string(i) + ".png";
        INFO(name);
        CHECK(read_bytes(box.path(name)) == read_bytes(box.path("t.png")));
    }
    CHECK(read_bytes(box.path("f0000.png")) != read_bytes(box.path("f0002.png")));
    REQUIRE(box.run_exe(kRender, with({"--frames", "3", "--fps", "2", "--frame-range", "2-2", "-o", "g%04d.png"})).code == 0);
    CHECK(read_bytes(box.path("g0002.png")) == read_bytes(box.path("f0002.png")));
    // --fps needs --frames; a file camera does not orbit.
    CHECK(box.run_exe(kRender, with({"--fps", "2"})).code == 2);
    CHECK(box.run_exe(kRender, with({"--frames", "2", "-o", "o%d.png"})).code == 2);
}

TEST_CASE("step pixel equals render on a skinned, animated model") {
    CliSandbox box;
    const double h = std::sqrt(0.5);
    Gltf g = bent_strip({0, 0, 0, 1});
    const int in = g.floats({0, 1}, "SCALAR", 1);
    const int out = g.floats({0, 0, 0, 1, 0, 0, float(h), float(h)}, "VEC4", 4);
    g.doc["animations"] = json::array(
        {{{"name", "bend"},
          {"samplers", json::array({{{"input", in}, {"output", out}}})},
          {"channels", json::array({{{"sampler", 0}, {"target", {{"node", 1}, {"path", "rotation"}}}}})}}});
    const std::string file = g.write(box, "bend.gltf");
    const std::vector<std::string> flags = {file, "--size", "40x40", "--time", "0.6", "--animation", "bend"};
    std::vector<std::string> png_args = flags;
    png_args.insert(png_args.end(), {"-o", "r.png"});
    REQUIRE(box.run_exe(kRender, png_args).code == 0);
    const Rgb8 png = load_rgb8(box.path("r.png"));
    REQUIRE(!png.empty());
    std::string commands;
    std::vector<std::pair<int, int>> pixels;
    for (int y = 3; y < 40; y += 6)
        for (int x = 2; x < 40; x += 5) {
            pixels.push_back({x, y});
            commands += "pixel " + std::to_string(x) + " " + std::to_string(y) + "\n";
        }
    const fs::path dir = box.work().parent_path();
    write_text(dir / "stdin.txt", commands);
    std::string cmd = "cd " + shell_quote(box.work().string()) + " && " + shell_quote(kStep);
    for (const std::string& a : flags) cmd += " " + shell_quote(a);
    cmd += " <" + shell_quote((dir / "stdin.txt").string()) + " >" + shell_quote((dir / "step.txt").string()) + " 2>&1";
    REQUIRE(std::system(cmd.c_str()) == 0);
    std::vector<std::array<int, 3>> answers;
    for (const std::string& l : lines_of(read_text(dir / "step.txt"))) {
        std::array<int, 3> c{};
        if (l.rfind("srgb8 ", 0) == 0 && std::sscanf(l.c_str(), "srgb8 %d %d %d", &c[0], &c[1], &c[2]) == 3)
            answers.push_back(c);
    }
    REQUIRE(answers.size() == pixels.size());
    int lit = 0;
    for (std::size_t i = 0; i < pixels.size(); ++i) {
        const std::uint8_t* p = png.at(pixels[i].first, pixels[i].second);
        INFO("pixel " << pixels[i].first << " " << pixels[i].second);
        CHECK(answers[i][0] == p[0]);
        CHECK(answers[i][1] == p[1]);
        CHECK(answers[i][2] == p[2]);
        lit += p[0] > 0;
    }
    CHECK(lit > 3);
    // And the pose differs from t = 0's.
    std::vector<std::string> t0 = {file, "--size", "40x40", "-o", "t0.png"};
    REQUIRE(box.run_exe(kRender, t0).code == 0);
    CHECK(read_bytes(box.path("t0.png")) != read_bytes(box.path("r.png")));
}

TEST_CASE("hostile skins and animations: warnings or one-line errors, never a crash") {
    CliSandbox box;
    const double h = std::sqrt(0.5);
    {
        // Joint index 7 of a two-joint skin: that influence counts for nothing.
        Gltf g = bent_strip({0, 0, h, h});
        const int joints = g.u16({7, 0, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0}, "VEC4", 4);
        g.doc["meshes"][0]["primitives"][0]["attributes"]["JOINTS_0"] = joints;
        const Scene s = load_scene(g.write(box, "badjoint.gltf"));
        CHECK(has_warning(s, "1 skin influences with a joint out of range"));
        check_vec(s.meshes[0].positions[5], {-1, 1.5f, 0});
    }
    {
        // A joint node out of range: the skin is dropped, the mesh drawn unskinned.
        Gltf g = bent_strip({0, 0, h, h});
        g.doc["skins"][0]["joints"] = {0, 99};
        const Scene s = load_scene(g.write(box, "badskin.gltf"));
        CHECK(has_warning(s, "skin 0: joint node 99 out of range"));
        check_vec(s.meshes[0].positions[5], {5.5f, 2, 0});
    }
    {
        // NaN key values, non-increasing times, an unknown path and interpolation.
        Gltf g = animated_triangle("translation", "LINEAR", {0, 1}, {0, 0, 0, NAN, 0, 0}, "VEC3", 3);
        Scene s = load_scene(g.write(box, "nan.gltf"));
        CHECK(has_warning(s, "non-finite output values"));
        pose_scene(s, 0.5, kAllAnimations);
        CHECK(s.meshes[0].positions[1] == glm::vec3(1, 0, 0));
        const Scene t = load_scene(
            animated_triangle("translation", "LINEAR", {0, 1, 1}, {0, 0, 0, 1, 0, 0, 2, 0, 0}, "VEC3", 3)
                .write(box, "times.gltf"));
        CHECK(has_warning(t, "strictly increasing (key 2)"));
        const Scene p = load_scene(
            animated_triangle("pointer", "LINEAR", {0, 1}, {0, 0, 0, 1, 0, 0}, "VEC3", 3).write(box, "path.gltf"));
        CHECK(has_warning(p, "path 'pointer' not supported"));
        const Scene q = load_scene(
            animated_triangle("translation", "SMOOTH", {0, 1}, {0, 0, 0, 1, 0, 0}, "VEC3", 3).write(box, "interp.gltf"));
        CHECK(has_warning(q, "interpolation 'SMOOTH' unknown"));
        // Output count not matching the key times.
        const Scene c = load_scene(
            animated_triangle("translation", "CUBICSPLINE", {0, 1}, {0, 0, 0, 1, 0, 0}, "VEC3", 3).write(box, "count.gltf"));
        CHECK(has_warning(c, "2 output values for 2 key times"));
    }
    {
        // A huge count: refused by the bufferView check before anything is allocated.
        Gltf g = animated_triangle("translation", "LINEAR", {0, 1}, {0, 0, 0, 1, 0, 0}, "VEC3", 3);
        g.doc["accessors"][1]["count"] = 2000000000;
        const std::string file = g.write(box, "huge.gltf");
        CHECK_THROWS_WITH_AS(load_scene(file), doctest::Contains("animation 0 sampler 0 input: accessor 1"), LoadError);
        const CliRun r = box.run_exe(kRender, {file, "--size", "16x16"});
        CHECK(r.code == 1);
        CHECK(lines_of(r.err).size() == 1);
    }
    {
        // A cycle among the joints' nodes: the loader's one-line error.
        Gltf g = bent_strip({0, 0, h, h});
        g.doc["nodes"][1]["children"] = {0};
        g.doc["scenes"][0]["nodes"] = {2};
        const CliRun r = box.run_exe(kRender, {g.write(box, "cycle.gltf"), "--size", "16x16"});
        CHECK(r.code == 1);
        CHECK(r.err.find("cycle") != std::string::npos);
        CHECK(lines_of(r.err).size() == 1);
    }
    {
        // A camera with a bad field of view is dropped with a warning.
        Gltf g = quad_with_cameras();
        g.doc["cameras"][0]["perspective"]["yfov"] = -1;
        const Scene s = load_scene(g.write(box, "badcam.gltf"));
        CHECK(has_warning(s, "camera 0: bad perspective values"));
        CHECK(s.cameras.size() == 1);
    }
}

TEST_CASE("an animated scale that turns mirrored turns the winding; lights follow their animated nodes") {
    CliSandbox box;
    // Scale x from 1 to -1 (STEP at t = 1): the triangle (0,0,0) (1,0,0)
    // (0,1,0) becomes (0,0,0) (-1,0,0) (0,1,0). glTF's determinant rule keeps
    // it counter-clockwise seen from +z, so its front still faces +z.
    Gltf g = animated_triangle("scale", "STEP", {0, 1}, {1, 1, 1, -1, 1, 1}, "VEC3", 3);
    Scene s = load_scene(g.write(box, "mirror.gltf"));
    auto facing_z = [](const Mesh& m) {
        REQUIRE(m.indices.size() == 3);
        const glm::vec3 a = m.positions[m.indices[0]], b = m.positions[m.indices[1]], c = m.positions[m.indices[2]];
        return glm::cross(b - a, c - a).z;
    };
    CHECK(facing_z(s.meshes[0]) > 0.0f);
    pose_scene(s, 1.0, kAllAnimations);
    check_vec(s.meshes[0].positions[1], {-1, 0, 0});
    CHECK(s.meshes[0].mirrored);
    CHECK(facing_z(s.meshes[0]) > 0.0f);
    pose_scene(s, 0.0, kAllAnimations);
    CHECK(!s.meshes[0].mirrored);
    CHECK(facing_z(s.meshes[0]) > 0.0f);

    // A point light and a sun under an animated rig node, translated from
    // (0, 0, 0) to (0, 0, 2) over a second; the triangle stays.
    Gltf l = animated_triangle("translation", "LINEAR", {0, 1}, {0, 0, 0, 0, 0, 2}, "VEC3", 3);
    l.doc["animations"][0]["channels"][0]["target"]["node"] = 2;
    l.doc["extensionsUsed"] = {"KHR_lights_punctual"};
    l.doc["extensions"]["KHR_lights_punctual"]["lights"] = json::array(
        {{{"type", "point"}, {"intensity", 5}}, {{"type", "directional"}, {"intensity", 2}}});
    const double h = std::sqrt(0.5);
    l.doc["nodes"].push_back({{"name", "rig"}, {"children", {3, 4}}});
    l.doc["nodes"].push_back({{"translation", {0, 1, 0}}, {"extensions", {{"KHR_lights_punctual", {{"light", 0}}}}}});
    l.doc["nodes"].push_back({{"rotation", {0, h, 0, h}}, {"extensions", {{"KHR_lights_punctual", {{"light", 1}}}}}});
    l.doc["scenes"] = json::array({{{"nodes", {0, 2}}}});
    l.doc["scene"] = 0;
    const std::string lf = l.write(box, "lights.gltf");
    Scene ls = load_scene(lf);
    REQUIRE(ls.lights.size() == 2);
    check_vec(ls.lights[0].position, {0, 1, 0});
    check_vec(ls.lights[1].direction, {1, 0, 0});  // the node's +z turned about y
    pose_scene(ls, 1.0, kAllAnimations);
    check_vec(ls.lights[0].position, {0, 1, 2});
    check_vec(ls.lights[1].direction, {1, 0, 0});
    pose_scene(ls, 0.5, kAllAnimations);
    check_vec(ls.lights[0].position, {0, 1, 1});
    // Through render: only the light moves, and the pixels change with it;
    // a sequence's frame 1 equals a still at its time.
    const std::vector<std::string> common = {lf, "--size", "64x64", "--eye", "0.3,0.3,4", "--target", "0.3,0.3,0"};
    auto with = [&](std::vector<std::string> extra) {
        std::vector<std::string> v = common;
        v.insert(v.end(), extra.begin(), extra.end());
        return v;
    };
    REQUIRE(box.run_exe(kRender, with({"--time", "0", "-o", "l0.png"})).code == 0);
    REQUIRE(box.run_exe(kRender, with({"--time", "1", "-o", "l1.png"})).code == 0);
    CHECK(read_bytes(box.path("l0.png")) != read_bytes(box.path("l1.png")));
    REQUIRE(box.run_exe(kRender, with({"--frames", "2", "--fps", "1", "-o", "s%d.png"})).code == 0);
    CHECK(read_bytes(box.path("s1.png")) == read_bytes(box.path("l1.png")));
}

TEST_CASE("step's frame names an orthographic file camera's half height, and a perspective one's infinite far") {
    CliSandbox box;
    const std::string file = quad_with_cameras().write(box, "cams.gltf");
    const fs::path dir = box.work().parent_path();
    write_text(dir / "stdin.txt", "frame\n");
    auto frame_text = [&](const std::string& camera) {
        const std::string cmd = "cd " + shell_quote(box.work().string()) + " && " + shell_quote(kStep) + " " +
                                shell_quote(file) + " --size 32x32 --camera " + camera + " <" +
                                shell_quote((dir / "stdin.txt").string()) + " >" +
                                shell_quote((dir / "step.txt").string()) + " 2>&1";
        REQUIRE(std::system(cmd.c_str()) == 0);
        for (const std::string& l : lines_of(read_text(dir / "step.txt")))
            if (l.rfind("camera eye ", 0) == 0) return l;
        return std::string();
    };
    const std::string ortho = frame_text("ortho");
    CHECK(ortho.find(" orthographic, half height 1 near 0.1 far 100") != std::string::npos);
    CHECK(ortho.find(" fov ") == std::string::npos);
    const std::string persp = frame_text("persp");
    CHECK(persp.find(" fov ") != std::string::npos);
    CHECK(persp.find(" far infinite") != std::string::npos);  // the file gives no zfar
}

} // TEST_SUITE

// KHR_materials_variants on small files the test writes (tests/gltf_writer.h),
// through the built `render` and `step`: each variant draws the exact colour
// of the unlit material its mapping names, primitives without a mapping keep
// their own, a variant equals a file with those materials written in directly
// (lit, textured, a normal map on TEXCOORD_1), `--list` counts the primitives
// each variant remaps, and hostile mappings are one warning each.
#include <doctest/doctest.h>

#include <algorithm>
#include <string>
#include <vector>

#include "scene/load_scene.h"
#include "scene/write_image.h"
#include "shading/color.h"
#include "tests/cli_util.h"
#include "tests/gltf_writer.h"
#include "tests/scratch.h"

using namespace prast;
using namespace prast::cli_test;
using prast::gltf_test::GltfWriter;
using json = nlohmann::json;

namespace {

const std::string kRender = PRAST_RENDER_EXE;
const std::string kStep = PRAST_STEP_EXE;

// A quad x in [cx - 0.4, cx + 0.4], y in [-0.4, 0.4] at z 0 facing +z, with
// two UV sets; `ext` is the primitive's extensions object (null: none).
int add_quad(GltfWriter& g, float cx, int material, const json& ext = nullptr) {
    const float a = cx - 0.4f, b = cx + 0.4f, h = 0.4f;
    const int pos = g.floats({a, -h, 0, b, -h, 0, b, h, 0, a, h, 0}, "VEC3", 3);
    json attrs = {{"POSITION", pos},
                  {"NORMAL", g.floats({0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1}, "VEC3", 3)},
                  {"TEXCOORD_0", g.floats({0, 1, 1, 1, 1, 0, 0, 0}, "VEC2", 2)},
                  {"TEXCOORD_1", g.floats({1, 1, 1, 0, 0, 0, 0, 1}, "VEC2", 2)}};
    json prim = {{"attributes", attrs}, {"indices", g.u16({0, 1, 2, 0, 2, 3}, "SCALAR", 1)}, {"material", material}};
    if (!ext.is_null()) prim["extensions"] = ext;
    g.doc["meshes"].push_back({{"primitives", json::array({prim})}});
    return int(g.doc["meshes"].size()) - 1;
}

json unlit(double r, double g, double b) {
    return {{"pbrMetallicRoughness", {{"baseColorFactor", {r, g, b, 1.0}}}},
            {"extensions", {{"KHR_materials_unlit", json::object()}}}};
}

json mappings(const json& list) { return {{"KHR_materials_variants", {{"mappings", list}}}}; }

void set_variants(GltfWriter& g, const json& names) {
    json v = json::array();
    for (const auto& n : names) v.push_back({{"name", n}});
    g.doc["extensions"]["KHR_materials_variants"] = {{"variants", v}};
    g.doc["extensionsUsed"] = {"KHR_materials_unlit", "KHR_materials_variants"};
}

// Four unlit materials (red, green, blue, white); a left quad (red) and a
// right quad (green); variants midnight, sunrise, noon: midnight maps the
// left quad to blue and the right one to white, sunrise the left one to
// white, noon nothing.
GltfWriter two_quads(bool with_variants = true) {
    GltfWriter g;
    for (const json& m : {unlit(0.8, 0.1, 0.1), unlit(0.1, 0.6, 0.2), unlit(0.05, 0.2, 0.9), unlit(1, 1, 1)})
        g.doc["materials"].push_back(m);
    if (with_variants) {
        add_quad(g, -0.5f, 0, mappings({{{"material", 2}, {"variants", {0}}}, {{"material", 3}, {"variants", {1}}, {"name", "w"}}}));
        add_quad(g, 0.5f, 1, mappings({{{"material", 3}, {"variants", {0}}}}));
        set_variants(g, {"midnight", "sunrise", "noon"});
    } else {
        add_quad(g, -0.5f, 0);
        add_quad(g, 0.5f, 1);
        g.doc["extensionsUsed"] = {"KHR_materials_unlit"};
    }
    g.scene_of_meshes();
    return g;
}

std::string write(CliSandbox& box, const GltfWriter& g, const std::string& name) {
    write_text(box.work() / name, g.text());
    return name;
}

// A look at the quads down -z: 64x32, a field of view that shows y in
// [-0.5, 0.5] (tan(fov / 2) = 0.5 / 3), so the left quad covers pixels
// 3.2 to 28.8 in x and y, the right one 35.2 to 60.8 in x.
std::vector<std::string> view(const std::string& file, const std::string& out) {
    return {file, "--size", "64x32", "--eye", "0,0,3", "--target", "0,0,0", "--fov", "18.92464", "--tonemap", "none",
            "--no-default-lights", "--threads", "1", "-o", out};
}

std::vector<std::string> with(std::vector<std::string> args, const std::vector<std::string>& more) {
    args.insert(args.end(), more.begin(), more.end());
    return args;
}

// The bytes an unlit factor writes (the pixel is the factor, sRGB-encoded).
std::vector<int> srgb(double r, double g, double b) {
    return {int(linear_to_srgb8(float(r))), int(linear_to_srgb8(float(g))), int(linear_to_srgb8(float(b)))};
}

std::vector<int> at(const Rgb8& img, int x, int y) {
    const std::uint8_t* p = img.at(x, y);
    return {p[0], p[1], p[2]};
}

std::size_t count_with(const std::vector<std::string>& lines, const std::string& part) {
    return std::size_t(std::count_if(lines.begin(), lines.end(),
                                     [&](const std::string& l) { return l.find(part) != std::string::npos; }));
}

} // namespace

TEST_SUITE("variants") {

TEST_CASE("each variant draws its mapped materials' exact colours, unmapped primitives their own") {
    CliSandbox box;
    const std::string file = write(box, two_quads(), "v.gltf");
    const auto red = srgb(0.8, 0.1, 0.1), green = srgb(0.1, 0.6, 0.2), blue = srgb(0.05, 0.2, 0.9),
               white = srgb(1, 1, 1);
    struct Case {
        std::vector<std::string> flag;
        std::vector<int> left, right;
    };
    const Case cases[] = {{{}, red, green},
                          {{"--variant", "midnight"}, blue, white},
                          {{"--variant", "0"}, blue, white},
                          {{"--variant", "sunrise"}, white, green},
                          {{"--variant", "1"}, white, green},
                          {{"--variant", "noon"}, red, green}};
    int k = 0;
    for (const Case& c : cases) {
        const std::string out = "c" + std::to_string(k++) + ".png";
        const CliRun r = box.run_exe(kRender, with(view(file, out), c.flag));
        INFO(r.err);
        REQUIRE(r.code == 0);
        CHECK(r.err.empty());
        const Rgb8 img = load_rgb8(box.path(out));
        REQUIRE(img.width == 64);
        // The quads' inner pixels (no edge in them, so MSAA keeps them exact).
        for (int y = 12; y < 20; ++y)
            for (int x = 10; x < 22; ++x) {
                CHECK(at(img, x, y) == c.left);
                CHECK(at(img, x + 32, y) == c.right);
            }
        CHECK(at(img, 32, 2) == std::vector<int>{0, 0, 0});  // the background between and above
    }
    // A variant nothing maps, and the default, are the default's bytes; so is
    // the same file without the extension.
    const std::string plain = write(box, two_quads(false), "plain.gltf");
    REQUIRE(box.run_exe(kRender, view(plain, "plain.png")).code == 0);
    CHECK(read_bytes(box.path("c0.png")) == read_bytes(box.path("plain.png")));
    CHECK(read_bytes(box.path("c5.png")) == read_bytes(box.path("plain.png")));
    CHECK(read_bytes(box.path("c1.png")) == read_bytes(box.path("c2.png")));  // name and index agree
    CHECK(read_bytes(box.path("c3.png")) == read_bytes(box.path("c4.png")));
}

TEST_CASE("a lit, textured variant equals the file with its materials written in; step agrees with render") {
    CliSandbox box;
    // Material 1 only a variant uses: a base colour texture and a normal map
    // on TEXCOORD_1 (so the loader must read that set and the tangents
    // follow it, as they would for a file drawing it by default).
    std::vector<std::uint8_t> rgba(8 * 8 * 4), bump(8 * 8 * 4);
    for (int i = 0; i < 64; ++i) {
        rgba[std::size_t(i * 4 + 0)] = std::uint8_t(30 * (i % 8));
        rgba[std::size_t(i * 4 + 1)] = std::uint8_t(30 * (i / 8));
        rgba[std::size_t(i * 4 + 2)] = 200;
        rgba[std::size_t(i * 4 + 3)] = 255;
        bump[std::size_t(i * 4 + 0)] = std::uint8_t(100 + 7 * (i % 8));
        bump[std::size_t(i * 4 + 1)] = std::uint8_t(160 - 5 * (i / 8));
        bump[std::size_t(i * 4 + 2)] = 230;
        bump[std::size_t(i * 4 + 3)] = 255;
    }
    auto make = [&](bool variant) {
        GltfWriter g;
        const int tex = g.texture(g.image_png(encode_png(8, 8, rgba.data())), 9729, 9987);
        const int nrm = g.texture(g.image_png(encode_png(8, 8, bump.data())), 9729, 9987);
        g.doc["materials"].push_back({{"pbrMetallicRoughness", {{"baseColorFactor", {0.7, 0.7, 0.7, 1}}, {"roughnessFactor", 0.4}}}});
        g.doc["materials"].push_back({{"pbrMetallicRoughness",
                                       {{"baseColorTexture", {{"index", tex}}}, {"metallicFactor", 0.3}, {"roughnessFactor", 0.6}}},
                                      {"normalTexture", {{"index", nrm}, {"texCoord", 1}}}});
        if (variant) {
            add_quad(g, -0.5f, 0, mappings({{{"material", 1}, {"variants", {0}}}}));
            add_quad(g, 0.5f, 0);
            set_variants(g, {"textured"});
        } else {
            add_quad(g, -0.5f, 1);
            add_quad(g, 0.5f, 0);
        }
        g.doc["extensions"]["KHR_lights_punctual"] = {{"lights", json::array({{{"type", "directional"}, {"intensity", 3}}})}};
        g.scene_of_meshes();
        g.doc["nodes"].push_back({{"rotation", {-0.2588190451, 0.0, 0.0, 0.9659258263}},
                                  {"extensions", {{"KHR_lights_punctual", {{"light", 0}}}}}});
        g.doc["scenes"][0]["nodes"].push_back(2);
        return g;
    };
    const std::string file = write(box, make(true), "v.gltf"), direct = write(box, make(false), "d.gltf");
    std::vector<std::string> lit = {"--size", "64x32", "--eye", "0.3,0.2,3", "--target", "0,0,0", "--fov", "18.92464", "--threads", "1"};
    CliRun a = box.run_exe(kRender, with({file, "--variant", "textured", "-o", "a.png"}, lit));
    CliRun b = box.run_exe(kRender, with({direct, "-o", "b.png"}, lit));
    CliRun c = box.run_exe(kRender, with({file, "-o", "c.png"}, lit));
    INFO(a.err << b.err << c.err);
    REQUIRE(a.code == 0);
    REQUIRE(b.code == 0);
    CHECK(a.err.empty());
    CHECK(read_bytes(box.path("a.png")) == read_bytes(box.path("b.png")));
    CHECK(read_bytes(box.path("a.png")) != read_bytes(box.path("c.png")));  // the variant did change something
    const Rgb8 img = load_rgb8(box.path("a.png"));
    // step takes the flag and its srgb8 is render's PNG, over the textured quad and the other.
    for (auto [x, y] : {std::pair<int, int>{14, 15}, {19, 18}, {47, 16}}) {
        const CliRun s = box.run_exe(kStep, with({file, "--variant", "textured", "--pixel",
                                                  std::to_string(x) + "," + std::to_string(y)}, lit));
        REQUIRE(s.code == 0);
        const std::string want = "srgb8 " + std::to_string(img.at(x, y)[0]) + " " + std::to_string(img.at(x, y)[1]) +
                                 " " + std::to_string(img.at(x, y)[2]) + "\n";
        CHECK(s.out.find(want) != std::string::npos);
    }
    // verify: every recomputed number is the pipeline's, with the variant's materials.
    const fs::path in = box.work().parent_path() / "verify.txt";
    write_text(in, "verify\n");
    std::string cmd = "cd " + shell_quote(box.work().string()) + " && " + shell_quote(kStep) + " " + file +
                      " --variant textured --size 64x32 --eye 0.3,0.2,3 --target 0,0,0 --fov 18.92464 --threads 1 <" +
                      shell_quote(in.string()) + " >" + shell_quote((box.work().parent_path() / "vout.txt").string());
    REQUIRE(std::system(cmd.c_str()) == 0);
    CHECK(read_text(box.work().parent_path() / "vout.txt").find("verify: ok, all identical") != std::string::npos);
}

TEST_CASE("render --list shows the variants and how many primitives each remaps") {
    CliSandbox box;
    const std::string file = write(box, two_quads(), "v.gltf");
    const CliRun r = box.run_exe(kRender, {"--list", file});
    INFO(r.out << r.err);
    REQUIRE(r.code == 0);
    CHECK(r.err.empty());
    CHECK(r.out.find("variants 3\n"
                     "  variant 0 'midnight': remaps 2 of 2 primitives\n"
                     "  variant 1 'sunrise': remaps 1 of 2 primitives\n"
                     "  variant 2 'noon': remaps 0 of 2 primitives\n") != std::string::npos);
    CHECK(r.out.find("extensions used: KHR_materials_unlit, KHR_materials_variants\n") != std::string::npos);
    const CliRun p = box.run_exe(kRender, {"--list", write(box, two_quads(false), "plain.gltf")});
    CHECK(p.out.find("variants 0\n") != std::string::npos);
    CHECK(box.work_files() == std::vector<std::string>{"plain.gltf", "v.gltf"});  // nothing rendered
}

TEST_CASE("an unknown variant is one line listing the variants and exit 2, in render and step") {
    CliSandbox box;
    const std::string file = write(box, two_quads(), "v.gltf");
    const std::string listed = "(it has 0 'midnight', 1 'sunrise', 2 'noon')\n";
    const CliRun r = box.run_exe(kRender, with(view(file, "x.png"), {"--variant", "dusk"}));
    CHECK(r.code == 2);
    CHECK(r.err == "render: --variant 'dusk': v.gltf has no variant of that name or index " + listed);
    const CliRun i = box.run_exe(kRender, with(view(file, "x.png"), {"--variant", "3"}));
    CHECK(i.code == 2);
    CHECK(i.err == "render: --variant '3': v.gltf has no variant of that name or index " + listed);
    const CliRun s = box.run_exe(kStep, {file, "--variant", "Midnight", "--pixel", "1,1"});
    CHECK(s.code == 2);
    CHECK(lines_of(s.err).size() == 1);
    CHECK(s.err.find("--variant 'Midnight': v.gltf has no variant of that name or index " + listed) != std::string::npos);
    const CliRun none = box.run_exe(kRender, with(view(write(box, two_quads(false), "p.gltf"), "x.png"), {"--variant", "a"}));
    CHECK(none.code == 2);
    CHECK(none.err == "render: --variant 'a': p.gltf has no variant of that name or index (it has none)\n");
    const CliRun builtin = box.run_exe(kRender, {"--variant", "a", "--size", "8x8", "-o", "x.png"});
    CHECK(builtin.code == 2);
    CHECK(lines_of(builtin.err).size() == 1);
    const CliRun empty = box.run_exe(kRender, {file, "--variant", ""});
    CHECK(empty.code == 2);
    CHECK(lines_of(empty.err).size() == 1);
    std::vector<std::string> files = box.work_files();
    CHECK(std::find(files.begin(), files.end(), "x.png") == files.end());
}

TEST_CASE("hostile variants and mappings: one warning each, the rest kept, never a crash") {
    test::TempDir dir("variants");
    auto load = [&](const GltfWriter& g) {
        const std::string path = dir.file("h.gltf");
        test::write_text(path, g.text());
        return load_scene(path);
    };
    auto only = [](const Scene& s, const std::string& part) { return count_with(s.warnings, part); };

    SUBCASE("bad entries of the mappings") {
        GltfWriter g;
        for (int i = 0; i < 4; ++i) g.doc["materials"].push_back(unlit(0.1 * i, 0.5, 0.5));
        add_quad(g, 0.0f, 0,
                 mappings({{{"material", 99}, {"variants", {0}}},              // material out of range
                           {{"material", -1}, {"variants", {0}}},              // negative
                           {{"material", 1.5}, {"variants", {0}}},             // not whole
                           {{"material", "two"}, {"variants", {0}}},           // not a number
                           {{"material", 1}, {"variants", {7, -1, "x", 0.5, 1}}},  // four bad indices, 1 kept
                           {{"material", 2}, {"variants", json::array()}},     // empty
                           {{"material", 2}, {"variants", "all"}},             // not an array
                           {{"material", 3}, {"variants", {1, 0}}},            // 1 mapped already; 0 kept
                           {{"variants", {2}}},                                // no material
                           42}));                                              // not an object
        set_variants(g, {"a", "b", "c"});
        g.scene_of_meshes();
        // A second node instancing the same mesh: its problems are not told twice.
        g.doc["nodes"].push_back({{"mesh", 0}, {"translation", {0, 0, -1}}});
        g.doc["scenes"][0]["nodes"].push_back(1);
        const Scene s = load(g);
        for (const std::string& w : s.warnings) MESSAGE(w);
        CHECK(s.warnings.size() == 13);
        CHECK(only(s, "mesh 0 primitive 0 KHR_materials_variants mapping 0: material is not an index of the file's 4 materials, ignored") == 1);
        CHECK(only(s, "mapping 1: material is not an index") == 1);
        CHECK(only(s, "mapping 2: material is not an index") == 1);
        CHECK(only(s, "mapping 3: material is not an index") == 1);
        CHECK(only(s, "mapping 4: variant entry ") == 4);
        CHECK(only(s, "mapping 4: variant entry 0 is not an index of the 3 variants, ignored") == 1);
        CHECK(only(s, "mapping 5: 'variants' is not a non-empty array, ignored") == 1);
        CHECK(only(s, "mapping 6: 'variants' is not a non-empty array, ignored") == 1);
        CHECK(only(s, "mapping 7: variant 1 is mapped already, material 1 kept") == 1);
        CHECK(only(s, "mapping 8: material is not an index") == 1);
        CHECK(only(s, "mapping 9: not an object, ignored") == 1);
        REQUIRE(s.meshes.size() == 2);
        for (const Mesh& m : s.meshes) CHECK(m.variant_materials == std::vector<int>{3, 1, -1});
    }
    SUBCASE("bad variants lists") {
        GltfWriter g;
        g.doc["materials"].push_back(unlit(1, 0, 0));
        g.doc["materials"].push_back(unlit(0, 1, 0));
        add_quad(g, 0.0f, 0, mappings({{{"material", 1}, {"variants", {0, 1, 2}}}}));
        g.scene_of_meshes();
        g.doc["extensions"]["KHR_materials_variants"] = {
            {"variants", json::array({{{"name", "x"}}, {{"name", 5}}, json("bare"), {{"name", "x"}}})}};
        Scene s = load(g);
        CHECK(s.warnings.size() == 3);
        CHECK(only(s, "KHR_materials_variants: variant 1 has no name string, called 'variant 1'") == 1);
        CHECK(only(s, "KHR_materials_variants: variant 2 has no name string, called 'variant 2'") == 1);
        CHECK(only(s, "KHR_materials_variants: variant 3 repeats the name 'x'") == 1);
        CHECK(s.variants == std::vector<std::string>{"x", "variant 1", "variant 2", "x"});
        CHECK(s.meshes[0].variant_materials == std::vector<int>{1, 1, 1, -1});

        // An empty object keeps its index: tinygltf drops {} from arrays,
        // which moved "late" to index 1 before the loader read the JSON itself.
        g.doc["extensions"]["KHR_materials_variants"] = {
            {"variants", json::array({{{"name", "early"}}, json::object(), {{"name", "late"}}})}};
        g.doc["meshes"][0]["primitives"][0]["extensions"] = mappings({{{"material", 1}, {"variants", {2}}}});
        s = load(g);
        CHECK(s.variants == std::vector<std::string>{"early", "variant 1", "late"});
        CHECK(only(s, "KHR_materials_variants: variant 1 has no name string, called 'variant 1'") == 1);
        CHECK(s.meshes[0].variant_materials == std::vector<int>{-1, -1, 1});
        CliSandbox box;
        const std::string file = write(box, g, "empty.gltf");
        for (const auto& [variant, out] : {std::pair{"late", "late.png"}, {"2", "two.png"}, {"0", "early.png"}})
            REQUIRE(box.run_exe(kRender, {file, "--variant", variant, "--size", "16x16", "-o", out}).code == 0);
        CHECK(read_bytes(box.work() / "late.png") == read_bytes(box.work() / "two.png"));
        CHECK(read_bytes(box.work() / "late.png") != read_bytes(box.work() / "early.png"));

        g.doc["meshes"][0]["primitives"][0]["extensions"] = mappings({{{"material", 1}, {"variants", {0, 1, 2}}}});
        g.doc["extensions"]["KHR_materials_variants"] = {{"variants", json::object({{"name", "x"}})}};
        s = load(g);
        CHECK(s.variants.empty());
        CHECK(only(s, "KHR_materials_variants: no 'variants' array, no variants") == 1);
        CHECK(only(s, "mesh 0 primitive 0 KHR_materials_variants: the file defines no variants, mappings ignored") == 1);
        CHECK(s.warnings.size() == 2);
        CHECK(s.meshes[0].variant_materials.empty());
        // An extension value that is not an object never reaches the loader
        // (tinygltf drops it): no variants, and the mappings say so.
        g.doc["extensions"]["KHR_materials_variants"] = "none";
        s = load(g);
        CHECK(s.variants.empty());
        CHECK(s.warnings == std::vector<std::string>{dir.file("h.gltf") + ": mesh 0 primitive 0 KHR_materials_variants: "
                                                     "the file defines no variants, mappings ignored"});

        // More variants than an index can sensibly name: refused in one line, not allocated per primitive.
        json many = json::array();
        for (int i = 0; i < 70000; ++i) many.push_back({{"name", "v"}});
        g.doc["extensions"]["KHR_materials_variants"] = {{"variants", many}};
        s = load(g);
        CHECK(s.variants.empty());
        CHECK(only(s, "KHR_materials_variants: 70000 variants, more than 65536, no variants") == 1);
    }
    SUBCASE("bad mappings objects") {
        GltfWriter g;
        g.doc["materials"].push_back(unlit(1, 0, 0));
        add_quad(g, -0.5f, 0, mappings({{"material", 0}}));  // mappings an object
        add_quad(g, 0.5f, 0, mappings(nullptr));              // mappings null
        add_quad(g, 0.0f, 0, {{"KHR_materials_variants", json::object()}});  // none
        set_variants(g, {"a"});
        g.scene_of_meshes();
        const Scene s = load(g);
        CHECK(s.warnings.size() == 3);
        for (int m = 0; m < 3; ++m)
            CHECK(only(s, "mesh " + std::to_string(m) + " primitive 0 KHR_materials_variants: no 'mappings' array, ignored") == 1);
        for (const Mesh& m : s.meshes) CHECK(m.variant_materials.empty());
    }
    SUBCASE("a file requiring the extension loads; the renders of hostile files exit 0") {
        CliSandbox box;
        GltfWriter g = two_quads();
        g.doc["extensionsRequired"] = {"KHR_materials_variants"};
        g.doc["meshes"][0]["primitives"][0]["extensions"]["KHR_materials_variants"]["mappings"].push_back(
            {{"material", 1e300}, {"variants", {1e300, -1e300, nullptr}}});
        const std::string file = write(box, g, "h.gltf");
        const CliRun r = box.run_exe(kRender, with(view(file, "h.png"), {"--variant", "midnight"}));
        CHECK(r.code == 0);
        CHECK(lines_of(r.err).size() == 1);
        CHECK(r.err.find("mapping 2: material is not an index") != std::string::npos);
    }
}

} // TEST_SUITE

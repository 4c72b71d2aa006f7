// prast._prast: the Python module's native half (pybind11). python/prast/
// __init__.py turns keyword arguments into render's flags; here they are
// parsed by render's own parser (apps/render_options.h) and drawn through the
// same frame set-up (apps/frame_request.h, renderer/frame_setup.h), so that an
// image equals the PNG `render` writes with those flags, byte for byte. The
// GIL is released while a scene loads and a frame renders.
#include <cmath>
#include <cstdint>
#include <cstring>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "apps/frame_request.h"
#include "apps/render_options.h"
#include "renderer/frame_setup.h"
#include "renderer/scene_renderer.h"
#include "scene/image.h"
#include "scene/image_diff.h"
#include "scene/load_scene.h"
#include "scene/messages.h"
#include "scene/tangents.h"
#include "scene/write_image.h"
#include "shading/output8.h"

namespace py = pybind11;
using namespace prast;

namespace {

// A usage error (render's exit code 2) and a bad file or job (exit code 1).
struct UsageError : std::runtime_error {
    using std::runtime_error::runtime_error;
};
struct FileError : std::runtime_error {
    using std::runtime_error::runtime_error;
};

// A scene loaded once and drawn many times: its textures' decoded images
// are kept between renders.
struct LoadedScene {
    std::shared_ptr<const Scene> scene;
    std::shared_ptr<DecodedImages> decoded = std::make_shared<DecodedImages>();
    std::string name;        // the path, or "<mesh NAME>"
    std::vector<std::string> warnings;
};

using Uint8Array = py::array_t<std::uint8_t, py::array::c_style | py::array::forcecast>;
using FloatArray = py::array_t<float, py::array::c_style | py::array::forcecast>;

std::shared_ptr<LoadedScene> load(const std::string& path, bool allow_outside_paths) {
    auto out = std::make_shared<LoadedScene>();
    out->name = path;
    Scene scene;
    {
        py::gil_scoped_release unlocked;
        LoadOptions options;
        options.allow_outside_paths = allow_outside_paths;
        try {
            scene = load_scene(path, options);
        } catch (const LoadError& e) {
            throw FileError(e.what());
        }
    }
    out->warnings = cap_warnings(scene.warnings);
    scene.warnings.clear();  // said once, here, not on every render
    out->scene = std::make_shared<const Scene>(std::move(scene));
    return out;
}

// "NAME: what" for a mesh given as arrays.
[[noreturn]] void bad_mesh(const std::string& name, const std::string& what) {
    throw UsageError("mesh '" + name + "': " + what);
}

// An (n, width) float array of one value per vertex, or a UsageError
// "mesh 'NAME': WHAT must be an (N, width) float array, one per position".
FloatArray per_vertex(const py::object& obj, std::size_t n, int width, const std::string& name, const char* what) {
    const auto a = FloatArray::ensure(obj);
    if (!a || a.ndim() != 2 || a.shape(1) != width || std::size_t(a.shape(0)) != n)
        bad_mesh(name, std::string(what) + " must be an (N, " + std::to_string(width) +
                           ") float array, one per position");
    return a;
}

// A scene of one triangle mesh from arrays: positions (N, 3), indices (M, 3)
// or (3M,) (none: consecutive triangles), normals (N, 3) (none: smooth ones
// computed), uvs (N, 2) in glTF's convention (v = 0 the top of the image),
// a base colour (linear RGBA) and optionally an sRGB texture (H, W, 3|4).
std::shared_ptr<LoadedScene> mesh_scene(const std::string& name, const FloatArray& positions, py::object indices_obj,
                                        py::object normals_obj, py::object uvs_obj, std::vector<float> base_color,
                                        py::object texture_obj, float metallic, float roughness, bool double_sided) {
    constexpr std::size_t kMaxVertices = std::size_t(1) << 26, kMaxIndices = std::size_t(3) << 26;
    if (positions.ndim() != 2 || positions.shape(1) != 3) bad_mesh(name, "positions must be an (N, 3) array");
    const std::size_t n = std::size_t(positions.shape(0));
    if (n < 3 || n > kMaxVertices) bad_mesh(name, "positions: " + std::to_string(n) + " vertices (3 to 2^26)");
    Mesh mesh;
    mesh.name = name;
    mesh.positions.resize(n);
    const float* p = positions.data();
    for (std::size_t i = 0; i < n; ++i) {
        mesh.positions[i] = {p[i * 3], p[i * 3 + 1], p[i * 3 + 2]};
        if (!std::isfinite(p[i * 3]) || !std::isfinite(p[i * 3 + 1]) || !std::isfinite(p[i * 3 + 2]) ||
            std::fabs(p[i * 3]) > 1e18f || std::fabs(p[i * 3 + 1]) > 1e18f || std::fabs(p[i * 3 + 2]) > 1e18f)
            bad_mesh(name, "position " + std::to_string(i) + " is not a finite number of at most 1e18");
    }
    if (indices_obj.is_none()) {
        if (n % 3) bad_mesh(name, "without indices the vertex count must be a multiple of 3");
        mesh.indices.resize(n);
        for (std::size_t i = 0; i < n; ++i) mesh.indices[i] = std::uint32_t(i);
    } else {
        const auto idx = py::array_t<std::int64_t, py::array::c_style | py::array::forcecast>::ensure(indices_obj);
        if (!idx) bad_mesh(name, "indices must be an integer array");
        const std::size_t m = std::size_t(idx.size());
        if ((idx.ndim() != 1 && !(idx.ndim() == 2 && idx.shape(1) == 3)) || m % 3 || m == 0 || m > kMaxIndices)
            bad_mesh(name, "indices must be (M, 3) or (3M,), M from 1 to 2^26");
        mesh.indices.resize(m);
        const std::int64_t* q = idx.data();
        for (std::size_t i = 0; i < m; ++i) {
            if (q[i] < 0 || std::uint64_t(q[i]) >= n)
                bad_mesh(name, "index " + std::to_string(q[i]) + " at " + std::to_string(i) + " is outside the " +
                                   std::to_string(n) + " vertices");
            mesh.indices[i] = std::uint32_t(q[i]);
        }
    }
    if (!uvs_obj.is_none()) {
        const FloatArray uv = per_vertex(uvs_obj, n, 2, name, "uvs");
        mesh.uvs.resize(n);
        for (std::size_t i = 0; i < n; ++i) {
            mesh.uvs[i] = {uv.data()[i * 2], uv.data()[i * 2 + 1]};
            if (!std::isfinite(mesh.uvs[i].x) || !std::isfinite(mesh.uvs[i].y))
                bad_mesh(name, "uv " + std::to_string(i) + " is not finite");
        }
    }
    if (!normals_obj.is_none()) {
        const FloatArray nr = per_vertex(normals_obj, n, 3, name, "normals");
        mesh.normals.resize(n);
        for (std::size_t i = 0; i < n; ++i) {
            const glm::vec3 v{nr.data()[i * 3], nr.data()[i * 3 + 1], nr.data()[i * 3 + 2]};
            const float len = glm::length(v);
            if (!std::isfinite(len) || !(len > 0.0f)) bad_mesh(name, "normal " + std::to_string(i) + " is zero or not finite");
            mesh.normals[i] = v / len;
        }
    } else {
        compute_normals(mesh);
    }
    if (!mesh.uvs.empty()) compute_tangents(mesh, mesh.uvs);

    Scene scene;
    Material mat;
    mat.name = name;
    if (base_color.size() != 4) bad_mesh(name, "base_color must have 4 values (linear RGBA)");
    for (float c : base_color)
        if (!(c >= 0.0f && c <= 1.0f)) bad_mesh(name, "base_color values must be between 0 and 1");
    if (!(metallic >= 0.0f && metallic <= 1.0f)) bad_mesh(name, "metallic must be between 0 and 1");
    if (!(roughness >= 0.0f && roughness <= 1.0f)) bad_mesh(name, "roughness must be between 0 and 1");
    mat.base_color_factor = {base_color[0], base_color[1], base_color[2], base_color[3]};
    mat.metallic_factor = metallic;
    mat.roughness_factor = roughness;
    mat.double_sided = double_sided;
    if (!texture_obj.is_none()) {
        const auto tex = Uint8Array::ensure(texture_obj);
        if (!tex || tex.ndim() != 3 || (tex.shape(2) != 3 && tex.shape(2) != 4) || tex.shape(0) < 1 ||
            tex.shape(1) < 1 || tex.shape(0) > 16384 || tex.shape(1) > 16384)
            bad_mesh(name, "texture must be an (H, W, 3) or (H, W, 4) uint8 array, at most 16384 a side");
        if (mesh.uvs.empty()) bad_mesh(name, "a texture needs uvs");
        auto img = std::make_shared<Image>();
        img->height = int(tex.shape(0));
        img->width = int(tex.shape(1));
        img->channels = int(tex.shape(2));
        img->srgb = true;
        img->pixels.assign(tex.data(), tex.data() + tex.size());
        ImageSource src;
        src.name = name + "#texture";
        src.decoded = std::move(img);
        scene.images.push_back(std::move(src));
        mat.base_color.image = 0;
    }
    scene.materials.push_back(mat);
    scene.meshes.push_back(std::move(mesh));
    auto out = std::make_shared<LoadedScene>();
    out->name = "<mesh " + name + ">";
    out->scene = std::make_shared<const Scene>(std::move(scene));
    return out;
}

// render's command line (without the program name) drawn; with `scene`,
// that scene instead of loading one. Returns the (h, w, 4) image (alpha
// 255, as the PNG, which is RGB) and the warnings and notes render prints.
py::tuple render(const std::vector<std::string>& args, const std::shared_ptr<LoadedScene>& scene) {
    std::vector<const char*> argv{"render"};
    for (const std::string& a : args) argv.push_back(a.c_str());
    RenderOptions opt;
    const std::string err = parse_render_args(int(argv.size()), argv.data(), opt);
    if (!err.empty()) throw UsageError(err);
    if (opt.help || opt.version || opt.list || opt.pixel || opt.frames > 1 || opt.repeat_given || opt.hdr_output())
        throw UsageError("--help, --version, --list, --pixel, --frames, --repeat and .hdr output are render's, "
                         "not prast.render()'s");
    FrameRequest request = render_frame_request(opt);
    if (scene) {
        request.scene = scene->name;
        request.loaded = scene->scene;
        request.decoded = scene->decoded;
    }
    const std::size_t w = std::size_t(opt.width), h = std::size_t(opt.height);
    Uint8Array image({h, w, std::size_t(4)});
    std::vector<std::string> notes;
    {
        py::gil_scoped_release unlocked;
        FrameSetup frame;
        const FrameError setup_err = setup_frame(request, frame);
        notes = frame.notes;
        if (setup_err) {
            if (setup_err.code == kFrameExitUsage) throw UsageError(setup_err.message);
            throw FileError(setup_err.message);
        }
        if (CameraFault f = frame.set_frame(0, 0.0)) throw UsageError(f.message);
        Framebuffer fb = Framebuffer::deferred(opt.width, opt.height);
        Rgba8Buffer rgba8(w * h);
        const ImageOutput out8 = render_image_output(opt, rgba8.data());  // --pixel was refused above
        frame.scene_renderer->render(frame.settings, fb, &out8);
        std::uint8_t* dst = image.mutable_data();
        std::memcpy(dst, rgba8.data(), w * h * 4);
        for (std::size_t i = 0; i < w * h; ++i) dst[i * 4 + 3] = 255;
    }
    return py::make_tuple(image, notes);
}

Image8 image8(const Uint8Array& a, const char* which) {
    if (a.ndim() != 3 || (a.shape(2) != 3 && a.shape(2) != 4) || a.shape(0) < 1 || a.shape(1) < 1)
        throw UsageError(std::string(which) + ": an image is an (H, W, 3) or (H, W, 4) uint8 array");
    const int h = int(a.shape(0)), w = int(a.shape(1));
    return a.shape(2) == 4 ? Image8::from_rgba(w, h, a.data(), true) : Image8::from_rgb(w, h, a.data());
}

Uint8Array to_array(const Image8& im) {
    Uint8Array out({std::size_t(im.height), std::size_t(im.width), std::size_t(4)});
    std::memcpy(out.mutable_data(), im.rgba.data(), im.rgba.size());
    return out;
}

py::dict diff(const Uint8Array& a, const Uint8Array& b, int tolerance, double max_fraction) {
    if (tolerance < 0 || tolerance > 255) throw UsageError("tolerance must be 0 to 255");
    if (!(max_fraction >= 0.0 && max_fraction <= 1.0)) throw UsageError("max_fraction must be 0 to 1");
    Image8 ia = image8(a, "a"), ib = image8(b, "b");
    // Alpha only where an image has it: an RGBA array whose alpha is all 255
    // is an RGB image (what render writes and prast.render returns).
    auto opaque = [](const Image8& im) {
        for (std::size_t i = 3; i < im.rgba.size(); i += 4)
            if (im.rgba[i] != 255) return false;
        return true;
    };
    if (ia.has_alpha && opaque(ia)) ia.has_alpha = false;
    if (ib.has_alpha && opaque(ib)) ib.has_alpha = false;
    if (ia.width != ib.width || ia.height != ib.height)
        throw UsageError("the images differ in size: " + std::to_string(ia.width) + "x" + std::to_string(ia.height) +
                         " and " + std::to_string(ib.width) + "x" + std::to_string(ib.height));
    const DiffTolerance tol{tolerance, max_fraction};
    const DiffResult r = diff_images(ia, ib, tol);
    py::dict d;
    d["match"] = r.match;
    d["psnr"] = r.psnr_db;
    d["mse"] = r.mse;
    d["max_diff"] = r.max_diff;
    d["max_at"] = r.max_x < 0 ? py::object(py::none()) : py::object(py::make_tuple(r.max_x, r.max_y));
    d["differing"] = r.differing;
    d["differing_fraction"] = r.differing_fraction;
    d["allowed"] = r.allowed;
    d["box"] = r.box_x0 < 0 ? py::object(py::none()) : py::object(py::make_tuple(r.box_x0, r.box_y0, r.box_x1, r.box_y1));
    d["channels"] = r.channels;
    d["report"] = format_diff(r, tol);
    const std::vector<std::uint8_t> heat = diff_heatmap(ia, ib, tol);
    Uint8Array hm({std::size_t(ia.height), std::size_t(ia.width), std::size_t(4)});
    std::memcpy(hm.mutable_data(), heat.data(), heat.size());
    d["heatmap"] = hm;
    return d;
}

void write_png(const std::string& path, const Uint8Array& img) {
    Image8 im = image8(img, "image");
    try {
        write_png_atomic(path, im.width, im.height, im.rgba.data());
    } catch (const WriteError& e) {
        throw FileError(e.what());
    }
}

Uint8Array read_png(const std::string& path) {
    try {
        return to_array(read_image8(path));
    } catch (const LoadError& e) {
        throw FileError(e.what());
    }
}

py::dict describe(const LoadedScene& s) {
    const Scene& scene = *s.scene;
    py::list meshes, materials, cameras, variants, animations;
    for (const Mesh& m : scene.meshes) {
        py::dict d;
        d["name"] = m.name;
        d["vertices"] = m.positions.size();
        const char* kind = m.topology == Mesh::Topology::Lines    ? "lines"
                           : m.topology == Mesh::Topology::Points ? "points" : "triangles";
        d["topology"] = kind;
        d["primitives"] = m.indices.size() / (m.topology == Mesh::Topology::Lines ? 2 : m.topology == Mesh::Topology::Points ? 1 : 3);
        d["material"] = m.material;
        meshes.append(d);
    }
    for (const Material& m : scene.materials) materials.append(m.name);
    for (const SceneCamera& c : scene.cameras) {
        py::dict d;
        d["name"] = c.name;
        d["type"] = c.orthographic ? "orthographic" : "perspective";
        cameras.append(d);
    }
    for (const std::string& v : scene.variants) variants.append(v);
    for (const std::string& a : scene.animation_names) animations.append(a);
    const Bounds b = scene.bounds();
    py::dict d;
    d["name"] = s.name;
    d["meshes"] = meshes;
    d["materials"] = materials;
    d["cameras"] = cameras;
    d["animations"] = animations;
    d["variants"] = variants;
    d["triangles"] = scene.triangle_count();
    d["bounds"] = b.empty() ? py::object(py::none())
                            : py::object(py::make_tuple(py::make_tuple(b.lo.x, b.lo.y, b.lo.z),
                                                        py::make_tuple(b.hi.x, b.hi.y, b.hi.z)));
    d["extensions_used"] = scene.extensions_used;
    d["warnings"] = s.warnings;
    return d;
}

} // namespace

PYBIND11_MODULE(_prast, m) {
    m.doc() = "prast's native half; use the prast package";
    // Error, the base of both: UsageError (render's exit code 2) and FileError (1).
    py::handle error(PyErr_NewException("prast._prast.Error", PyExc_RuntimeError, nullptr));
    m.add_object("Error", error);
    py::register_exception<UsageError>(m, "UsageError", error);
    py::register_exception<FileError>(m, "FileError", error);

    py::class_<LoadedScene, std::shared_ptr<LoadedScene>>(m, "LoadedScene")
        .def_readonly("name", &LoadedScene::name)
        .def("describe", &describe);
    m.def("load", &load, py::arg("path"), py::arg("allow_outside_paths") = false);
    m.def("mesh_scene", &mesh_scene, py::arg("name"), py::arg("positions"), py::arg("indices"), py::arg("normals"),
          py::arg("uvs"), py::arg("base_color"), py::arg("texture"), py::arg("metallic"), py::arg("roughness"),
          py::arg("double_sided"));
    m.def("render", &render, py::arg("args"), py::arg("scene") = nullptr);
    m.def("diff", &diff, py::arg("a"), py::arg("b"), py::arg("tolerance") = 0, py::arg("max_fraction") = 0.0);
    m.def("write_png", &write_png, py::arg("path"), py::arg("image"));
    m.def("read_png", &read_png, py::arg("path"));
    m.attr("version") = PRAST_VERSION;
}

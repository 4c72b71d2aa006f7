// Draws a loaded Scene: decodes and binds its textures once (in parallel, on
// the renderer's threads), then renders frames of it with the PBR program into
// a linear HDR framebuffer. The render CLI, bench and stepper all go through it.
#pragma once

#include <algorithm>
#include <cstdint>
#include <limits>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <type_traits>
#include <vector>

#include "raster/pipeline.h"
#include "scene/camera.h"
#include "shading/ibl/background.h"
#include "shading/debug_view.h"
#include "shading/ibl/dfg.h"
#include "shading/ibl/environment.h"
#include "shading/pbr_program.h"
#include "scene/scene.h"
#include "shading/shadow/shadow_pass.h"
#include "shading/surface.h"
#include "shading/texture.h"
#include "shading/tonemap.h"

namespace prast {

struct FrameSettings {
    Camera camera;
    std::vector<ShadingLight> lights;
    glm::vec3 ambient{0.03f};
    BrdfModel model = BrdfModel::Default;
    DebugView view = DebugView::None;
    ShadowSettings shadows;  // shadow maps for the lights (docs/shadows-and-transparency.md); not for the environment
    // Image-based lighting: this environment, or when null the scene's own
    // (Scene::environment, prefiltered on first use) unless scene_environment
    // is false. With one, it replaces the ambient term.
    const Environment* environment = nullptr;
    bool scene_environment = true;
    IblMode ibl = IblMode::SplitSum;
    int ibl_samples = 256;
    bool energy = false;   // --energy conserve
    // Env and Blur need an environment (without one they draw black).
    Background background = Background::Env;
    glm::vec3 background_color{0.0f};
    int samples = 1;  // per pixel: 1, 2, 4 or 8 (docs/pipeline.md "Anti-aliasing")
    // Where the visibility pass runs (the bytes are the same either way).
    FrameOptions::Visibility visibility = FrameOptions::Visibility::Auto;
    // Draws that read no map run the position-and-normal varying layout
    // (narrow_varyings_suffice(); the bytes are the same either way). Frames
    // with stage observers always run the usual layout, which they record.
    bool narrow_varyings = true;
};

// The 8-bit image a frame writes from its tile pass (render's PNG): exposure,
// tone map, sRGB, 8 bits; or, for data views, the values as they are.
struct ImageOutput {
    std::uint8_t* rgba8 = nullptr;  // framebuffer width * height * 4 bytes
    float exposure = 1.0f;
    ToneMap tonemap = ToneMap::Aces;
    bool raw = false;               // resolve_raw8 instead (data debug views)
    // Also leave the linear colour and depth in the framebuffer. false: only
    // the 8-bit image is wanted (render without --pixel), and the frame keeps
    // its tiles in cache (FrameOptions::transient); the same 8-bit bytes.
    bool keep_framebuffer = true;
};

// Scene lights (KHR_lights_punctual) in shading form.
std::vector<ShadingLight> shading_lights(const Scene& scene);

// The documented default rig for scenes without lights: a key sun from the
// upper left front and a weaker, cooler fill from the right.
std::vector<ShadingLight> default_light_rig();

// The lights of a frame: the scene's (unless `file_lights` is false:
// --file-lights off), then the flags', and the default rig when neither has
// any, none was refused (--no-default-lights) and no environment lights the
// scene; `used_default_rig` says whether it was.
std::vector<ShadingLight> frame_lights(const Scene& scene, const std::vector<ShadingLight>& flag_lights,
                                       bool file_lights, bool no_default_lights, bool environment,
                                       bool& used_default_rig);

// One draw of a frame, as SceneRenderer::render submits it: what a tap
// factory is told before the frame runs.
struct SceneDraw {
    int mesh = -1;                      // index into the scene's meshes
    std::uint32_t first_triangle = 0;   // submission-order number of the draw's triangle 0
    std::uint32_t triangle_count = 0;   // the mesh's, also when a limit cuts the draw short
    std::uint32_t vertex_count = 0;
    DrawState state;
};

// Lines and points without normals, which glTF draws unlit: base colour
// factor x base colour texture x vertex colour (COLOR_0) as the radiance, its
// alpha blended (BLEND) or tested (MASK) as the PBR program does. Lines and
// points shade with zero derivatives, so the texture's finest level is read
// (at the UVs through the base colour's KHR_texture_transform, if any).
struct UnlitProgram {
    static constexpr int kVaryings = 6;  // uv, rgba
    const Mesh* mesh = nullptr;
    glm::mat4 view_proj{1.0f};
    const BoundMaterial* material = nullptr;

    void vertex(std::uint32_t i, float clip[4], float* var) const {
        const glm::vec4 c = view_proj * glm::vec4(mesh->positions[i], 1.0f);
        clip[0] = c.x; clip[1] = c.y; clip[2] = c.z; clip[3] = c.w;
        const std::vector<glm::vec2>& uvs = material->m->base_color.texcoord == 1 ? mesh->uvs1 : mesh->uvs;
        const glm::vec2 uv = i < uvs.size() ? uvs[i] : glm::vec2(0.0f);
        const glm::vec4 rgba = i < mesh->colors.size() ? mesh->colors[i] : glm::vec4(1.0f);
        var[0] = uv.x; var[1] = uv.y;
        var[2] = rgba.r; var[3] = rgba.g; var[4] = rgba.b; var[5] = rgba.a;
    }
    void fragment(const FragmentBlock<kVaryings>& in, FragmentOut& out) const {
        const Material& m = *material->m;
        out.kill = 0;
        for (int l = 0; l < kBlockLanes; ++l) {
            glm::vec4 c = m.base_color_factor * glm::vec4(in.var[2][l], in.var[3][l], in.var[4][l], in.var[5][l]);
            if (material->base_color) {
                glm::vec2 uv(in.var[0][l], in.var[1][l]);
                if (const UvTransform* x = material->transform_of(BoundMaterial::kBaseColor)) uv = x->apply(uv);
                c *= material->base_color->sample(uv.x, uv.y, 0.0f, 0.0f, 0.0f, 0.0f);
            }
            out.r[l] = c.r; out.g[l] = c.g; out.b[l] = c.b;
            out.a[l] = m.alpha_mode == AlphaMode::Blend ? c.a : 1.0f;
            if (m.alpha_mode == AlphaMode::Mask && !(c.a >= m.alpha_cutoff)) out.kill |= 1u << l;
        }
    }
};

// A tap factory that watches nothing.
struct NoTaps {
    NullObserver operator()(const SceneDraw&) const { return {}; }
};

// Decoded images kept between SceneRenderers of one scene (the Python
// module's loaded scenes): slot image * 2 + srgb, filled on first decode.
// Decoding is deterministic, so a kept image is the one decoding again gives.
struct DecodedImages {
    std::mutex mutex;
    std::vector<std::shared_ptr<const Image>> slots;
};

class SceneRenderer {
public:
    // Decodes every texture the materials use (or takes it from `kept`,
    // adding what it decodes there). A texture that cannot be decoded is
    // dropped with a warning (the factor alone is used).
    SceneRenderer(const Scene& scene, Renderer& renderer, DecodedImages* kept = nullptr);

    // Renders one frame into fb (resized by the caller): clears to the
    // background (frame_background), draws every mesh, and applies the
    // overdraw/tiles debug overlays. With `out`, also writes the 8-bit image
    // (in the tile pass, on every thread); out->keep_framebuffer false leaves
    // fb as it was.
    void render(const FrameSettings& settings, Framebuffer& fb, const ImageOutput* out = nullptr);
    // The same frame with a stage observer (raster/observer.h) on each draw:
    // make_tap(const SceneDraw&) gives it, before the frame runs, and the taps
    // live until the frame is done. Only the first `triangle_limit` triangles
    // in submission order are drawn ("the image after N triangles").
    template <class MakeTap>
    void render(const FrameSettings& settings, Framebuffer& fb, const ImageOutput* out, MakeTap&& make_tap,
                std::uint64_t triangle_limit = std::numeric_limits<std::uint64_t>::max());

    // The material a mesh draws with: its own, or the fallback.
    const BoundMaterial& material_of(const Mesh& mesh) const;
    // The state a draw of material `bm` runs with in a frame showing `view`.
    static DrawState draw_state(const BoundMaterial& bm, DebugView view);

    // The environment a frame with these settings is lit by (null: none).
    const Environment* environment(const FrameSettings& settings);
    // A DFG table, built on the renderer's pool on first use.
    const DfgTable& dfg_table(DfgModel model);
    // The context render() shades with (lights, eye, environment, tables).
    // With settings.shadows on and the aspect of the frame (width / height),
    // each light points at its shadow map, drawn for these settings unless
    // the last ones drawn are for the same camera, lights and size.
    ShadingContext shading_context(const FrameSettings& settings, float aspect = 0.0f);
    // The frame's lights, each pointing at its shadow map (valid until maps
    // for other settings are drawn); the lights as they are when shadows are
    // off, the aspect is 0 or the view shows no lighting.
    std::vector<ShadingLight> shadowed_lights(const FrameSettings& settings, float aspect);
    const ShadowMaps& shadow_maps() const { return shadow_maps_; }

    const std::vector<std::string>& warnings() const { return warnings_; }
    const std::vector<BoundMaterial>& materials() const { return bound_; }
    const Scene& scene() const { return scene_; }
    Renderer& renderer() { return renderer_; }

private:
    // A frame between begin_pass() and end_pass(): what its draws point to.
    struct Pass {
        ShadingContext ctx;
        glm::mat4 view_proj{1.0f};
        bool overlay = false;
        std::vector<std::size_t> order;
        std::optional<BackgroundFill> background;  // the frame's clear reads it until end()
        std::vector<LookupPlan> plans;  // of bound_[i], for the lane sampler
    };
    void begin_pass(const FrameSettings& settings, Framebuffer& fb, const ImageOutput* out, Pass& pass);
    PbrProgram program(const FrameSettings& settings, const Pass& pass, const Mesh& mesh,
                       const BoundMaterial& bm) const;
    // The wide varying layout: vertex colours, UV sets past 0 (needs_extended_varyings).
    PbrProgramExt program_ext(const FrameSettings& settings, const Pass& pass, const Mesh& mesh,
                              const BoundMaterial& bm) const;
    // The position-and-normal layout (narrow_varyings_suffice).
    PbrProgramLite program_lite(const FrameSettings& settings, const Pass& pass, const Mesh& mesh,
                                const BoundMaterial& bm) const;
    template <class P>
    P program_of(const FrameSettings& settings, const Pass& pass, const Mesh& mesh, const BoundMaterial& bm) const;
    // A mesh of lines or points: with its material, lit when it has normals.
    template <class Tap>
    void submit_lines(const FrameSettings& settings, const Pass& pass, const Mesh& mesh, const BoundMaterial& bm,
                      const SceneDraw& d, Tap& tap);
    void end_pass(const FrameSettings& settings, Framebuffer& fb, const ImageOutput* out, const Pass& pass);

    const Scene& scene_;
    Renderer& renderer_;
    std::vector<std::unique_ptr<Texture>> textures_;  // [image * 2 + srgb]
    std::vector<std::unique_ptr<Texture>> packed_;    // OBJ roughness + metal pairs
    std::vector<std::unique_ptr<Texture>> views_;     // textures_ through other samplers
    std::vector<BoundMaterial> bound_;
    std::vector<std::string> warnings_;
    ShadowMaps shadow_maps_;
    std::vector<float> shadow_key_;  // what the maps were drawn for (shadowed_lights)
    std::unique_ptr<Environment> scene_env_;   // from Scene::environment, on first use
    std::unique_ptr<DfgTable> dfg_[3];         // by DfgModel, on first use
};

template <class MakeTap>
void SceneRenderer::render(const FrameSettings& s, Framebuffer& fb, const ImageOutput* out, MakeTap&& make_tap,
                           std::uint64_t triangle_limit) {
    using Tap = decltype(make_tap(SceneDraw{}));
    Pass pass;
    begin_pass(s, fb, out, pass);
    std::vector<Tap> taps;
    taps.reserve(scene_.meshes.size());  // submit() keeps a pointer to each tap
    std::uint64_t first = 0;
    for (const std::size_t mi : pass.order) {
        const Mesh& mesh = scene_.meshes[mi];
        if (mesh.indices.empty()) continue;
        if (first >= triangle_limit) break;
        const BoundMaterial& bm = material_of(mesh);
        SceneDraw d;
        d.mesh = int(mi);
        d.first_triangle = std::uint32_t(first);
        if (mesh.topology != Mesh::Topology::Triangles) {  // no triangles: triangle_count 0
            d.vertex_count = std::uint32_t(mesh.positions.size());
            d.state = draw_state(bm, s.view);
            d.state.topology = mesh.topology == Mesh::Topology::Lines ? Topology::Lines : Topology::Points;
            taps.push_back(make_tap(d));
            submit_lines(s, pass, mesh, bm, d, taps.back());
            continue;
        }
        d.triangle_count = std::uint32_t(mesh.indices.size() / 3);
        d.vertex_count = std::uint32_t(mesh.positions.size());
        d.state = draw_state(bm, s.view);
        const std::uint64_t drawn = std::min<std::uint64_t>(d.triangle_count, triangle_limit - first);
        taps.push_back(make_tap(d));
        first += d.triangle_count;
        if constexpr (std::is_same_v<Tap, NullObserver>) {
            if (s.narrow_varyings && narrow_varyings_suffice(mesh, bm, s.view)) {
                renderer_.submit(program_lite(s, pass, mesh, bm), d.vertex_count, mesh.indices.data(),
                                 std::size_t(drawn) * 3, d.state, taps.back());
                continue;
            }
        }
        if (needs_extended_varyings(mesh, bm))
            renderer_.submit(program_ext(s, pass, mesh, bm), d.vertex_count, mesh.indices.data(),
                             std::size_t(drawn) * 3, d.state, taps.back());
        else
            renderer_.submit(program(s, pass, mesh, bm), d.vertex_count, mesh.indices.data(), std::size_t(drawn) * 3,
                             d.state, taps.back());
    }
    end_pass(s, fb, out, pass);
}

template <class Tap>
void SceneRenderer::submit_lines(const FrameSettings& s, const Pass& pass, const Mesh& mesh, const BoundMaterial& bm,
                                 const SceneDraw& d, Tap& tap) {
    const std::size_t n = d.state.topology == Topology::Lines ? mesh.indices.size() / 2 * 2 : mesh.indices.size();
    if (mesh.normals.empty() && (s.view == DebugView::None || s.view == DebugView::Tiles)) {
        UnlitProgram prog;
        prog.mesh = &mesh;
        prog.view_proj = pass.view_proj;
        prog.material = &bm;
        renderer_.submit(prog, d.vertex_count, mesh.indices.data(), n, d.state, tap);
    } else if (needs_extended_varyings(mesh, bm)) {
        renderer_.submit(program_ext(s, pass, mesh, bm), d.vertex_count, mesh.indices.data(), n, d.state, tap);
    } else {
        renderer_.submit(program(s, pass, mesh, bm), d.vertex_count, mesh.indices.data(), n, d.state, tap);
    }
}

// The background a frame with these settings clears to: settings.background
// for the lit image and the tiles view, black for the other debug views.
BackgroundFill frame_background(const FrameSettings& settings, const Environment* env, int width, int height);

// Debug-view post passes, exposed for tests.
void apply_overdraw_heat(Framebuffer& fb);
void apply_tile_overlay(Framebuffer& fb, const std::vector<std::uint32_t>& entries, int tile_size);

} // namespace prast

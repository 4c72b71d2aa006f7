// The frame, drawn the way SceneRenderer::render draws it (one frame: cleared
// to the background in the tile pass, one draw per mesh with the PBR program,
// in scene order, with render's samples per pixel), with two additions
// for the stepper: a stage observer (raster/observer.h) and a limit on the
// number of triangles, for "the image after the first N triangles".
// tests/test_step.cpp proves the result equal to `render`'s, byte for byte.
#pragma once

#include <cstddef>
#include <cstdint>
#include <limits>
#include <vector>

#include "raster/pipeline.h"
#include "shading/pbr_program.h"
#include "renderer/scene_renderer.h"
#include "renderer/draw_order.h"
#include "stepper/scene_setup.h"

namespace prast::stepper {

// The material a mesh draws with: its own, or the renderer's fallback.
inline const BoundMaterial& draw_material(const StepScene& s, const Mesh& mesh) {
    static const Material kFallback;
    static const BoundMaterial kFallbackBound{&kFallback};
    const auto& bound = s.scene_renderer->materials();
    return mesh.material >= 0 && std::size_t(mesh.material) < bound.size() ? bound[std::size_t(mesh.material)]
                                                                            : kFallbackBound;
}

// render's shading context: lights, eye, and the environment with its tables
// (SceneRenderer::shading_context, which builds them on first use).
// With shadows on, the lights point at the maps render draws (for a frame of
// the requested size; drawn once, then reused).
inline ShadingContext shading_context(const StepScene& s) {
    return s.scene_renderer->shading_context(s.settings, float(s.options.width) / float(s.options.height));
}

// render's background (what every sample clears to) for a frame of width x height.
inline BackgroundFill frame_background(const StepScene& s, int width, int height) {
    return prast::frame_background(s.settings, s.scene_renderer->environment(s.settings), width, height);
}

// The state a mesh draws with, as SceneRenderer::render sets it.
inline DrawState draw_state(const BoundMaterial& bm) {
    DrawState st;
    st.cull = bm.m->double_sided ? CullMode::None : CullMode::Back;
    st.may_discard = bm.m->alpha_mode == AlphaMode::Mask;
    if (bm.m->alpha_mode == AlphaMode::Blend) {  // README "Transparency"
        st.blend = Blend::Alpha;
        st.depth_write = false;
    }
    return st;
}

// How the tile pass runs a draw of state `st` (Renderer::submit's choice,
// for a colour target with a fragment program): its winners shaded once
// after the visibility pass, or shaded in submission order.
inline bool draws_visible(const DrawState& st, FrameOptions::Visibility v) {
    return v != FrameOptions::Visibility::Never && st.depth_test && st.depth_write && st.blend == Blend::Replace &&
           !st.may_discard;
}

// make_tap(mesh, first_triangle, triangles, vertices, state) gives the
// observer of each draw (raster/observer.h), created before the frame runs;
// the taps live until the frame is done. One frame: every mesh submitted,
// then one tile pass (raster/frame.h), with the samples per pixel and the
// visibility setting of s.settings; fb is resized by the caller.
template <class MakeTap>
void draw_frame(StepScene& s, Framebuffer& fb, MakeTap&& make_tap,
                std::uint64_t triangle_limit = std::numeric_limits<std::uint64_t>::max()) {
    using Tap = decltype(make_tap(0, 0u, 0u, 0u, DrawState{}));
    std::vector<Tap> taps;
    taps.reserve(s.scene.meshes.size());  // submit() keeps a pointer to each tap
    Renderer& renderer = *s.renderer;
    const ShadingContext ctx = shading_context(s);  // shadow maps first: not counted in the frame
    renderer.begin_frame();
    FrameOptions frame;  // cleared to the background, alpha 1, depth 1, in the tile pass
    frame.samples = s.settings.samples;
    frame.visibility = s.settings.visibility;
    const BackgroundFill background = frame_background(s, fb.width, fb.height);
    background.attach(frame);
    renderer.begin(fb, frame);
    const float aspect = float(fb.width) / float(fb.height);
    const glm::mat4 vp = s.settings.camera.view_projection(aspect);
    std::uint64_t first = 0;
    // Opaque and MASK meshes in file order, then BLEND ones back to front.
    for (const std::size_t m : draw_order(s.scene, s.settings.camera.eye)) {
        const Mesh& mesh = s.scene.meshes[m];
        if (mesh.indices.empty()) continue;
        if (first >= triangle_limit) break;
        const BoundMaterial& bm = draw_material(s, mesh);
        PbrProgram prog;
        prog.mesh = &mesh;
        prog.view_proj = vp;
        prog.material = &bm;
        prog.ctx = &ctx;
        prog.view = DebugView::None;
        prog.near_plane = s.settings.camera.near_plane;
        prog.far_plane = s.settings.camera.far_plane;
        const DrawState st = draw_state(bm);
        const std::uint64_t triangles = mesh.indices.size() / 3;
        const std::uint64_t drawn = std::min<std::uint64_t>(triangles, triangle_limit - first);
        taps.push_back(make_tap(int(m), std::uint32_t(first), std::uint32_t(triangles),
                                std::uint32_t(mesh.positions.size()), st));
        renderer.submit(prog, std::uint32_t(mesh.positions.size()), mesh.indices.data(), std::size_t(drawn) * 3, st,
                        taps.back());
        first += triangles;
    }
    renderer.end();
}

} // namespace prast::stepper

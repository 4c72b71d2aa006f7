// The frame, drawn the way SceneRenderer::render draws it (clear, then one
// draw per mesh with the PBR program, in scene order), with two additions
// for the stepper: a stage observer (raster/observer.h) and a limit on the
// number of triangles, for "the image after the first N triangles".
// tests/test_step.cpp proves the result equal to `render`'s, byte for byte.
#pragma once

#include <cstddef>
#include <cstdint>
#include <limits>

#include "raster/pipeline.h"
#include "shading/pbr_program.h"
#include "shading/scene_renderer.h"
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

inline ShadingContext shading_context(const FrameSettings& s) {
    ShadingContext ctx;
    ctx.eye = s.camera.eye;
    ctx.lights = s.lights;
    ctx.ambient = s.ambient;
    ctx.model = s.model;
    return ctx;
}

// An observer that also hears which draw comes next.
//   void begin_draw(int mesh, std::uint32_t first_triangle, std::uint32_t triangles,
//                   std::uint32_t vertices, const DrawState&);
template <class Observer>
void draw_frame(StepScene& s, Framebuffer& fb, Observer& obs,
                std::uint64_t triangle_limit = std::numeric_limits<std::uint64_t>::max()) {
    Renderer& renderer = *s.renderer;
    renderer.clear(fb, 0.0f, 0.0f, 0.0f, 1.0f);
    renderer.begin_frame();
    const ShadingContext ctx = shading_context(s.settings);
    const float aspect = float(fb.width) / float(fb.height);
    const glm::mat4 vp = s.settings.camera.view_projection(aspect);
    std::uint64_t first = 0;
    for (std::size_t m = 0; m < s.scene.meshes.size(); ++m) {
        const Mesh& mesh = s.scene.meshes[m];
        if (mesh.indices.empty()) continue;
        const BoundMaterial& bm = draw_material(s, mesh);
        PbrProgram prog;
        prog.mesh = &mesh;
        prog.view_proj = vp;
        prog.material = &bm;
        prog.ctx = &ctx;
        prog.view = DebugView::None;
        prog.near_plane = s.settings.camera.near_plane;
        prog.far_plane = s.settings.camera.far_plane;
        DrawState st;
        st.cull = bm.m->double_sided ? CullMode::None : CullMode::Back;
        const std::uint64_t triangles = mesh.indices.size() / 3;
        if (first >= triangle_limit) break;
        const std::uint64_t drawn = std::min<std::uint64_t>(triangles, triangle_limit - first);
        if constexpr (Observer::enabled)
            obs.begin_draw(int(m), std::uint32_t(first), std::uint32_t(triangles),
                           std::uint32_t(mesh.positions.size()), st);
        renderer.draw(fb, prog, std::uint32_t(mesh.positions.size()), mesh.indices.data(),
                      std::size_t(drawn) * 3, st, obs);
        first += triangles;
    }
}

} // namespace prast::stepper

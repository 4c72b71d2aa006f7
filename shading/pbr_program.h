// The rasterizer program for metal-roughness PBR: the vertex stage transforms
// world-space mesh vertices to clip space and passes position, normal, uv and
// tangent as varyings; the fragment stage builds a SurfacePoint per lane (uv
// derivatives from its 2x2 quad), samples the material and shades it, or
// writes one of the debug views.
#pragma once

#include <cstdint>

#include <glm/glm.hpp>

#include "raster/fragment.h"
#include "shading/debug_view.h"
#include "scene/scene.h"
#include "shading/surface.h"

namespace prast {

// Varying layout.
enum : int { kVarP = 0, kVarN = 3, kVarUV = 6, kVarT = 8, kPbrVaryings = 12 };

struct PbrProgram {
    static constexpr int kVaryings = kPbrVaryings;

    const Mesh* mesh = nullptr;
    glm::mat4 view_proj{1.0f};
    const BoundMaterial* material = nullptr;
    const ShadingContext* ctx = nullptr;
    DebugView view = DebugView::None;
    float near_plane = 0.1f, far_plane = 100.0f;  // for the depth view

    void vertex(std::uint32_t i, float clip[4], float* var) const {
        const glm::vec3& p = mesh->positions[i];
        glm::vec4 c = view_proj * glm::vec4(p, 1.0f);
        clip[0] = c.x; clip[1] = c.y; clip[2] = c.z; clip[3] = c.w;
        var[kVarP + 0] = p.x; var[kVarP + 1] = p.y; var[kVarP + 2] = p.z;
        glm::vec3 n = i < mesh->normals.size() ? mesh->normals[i] : glm::vec3(0.0f, 0.0f, 1.0f);
        var[kVarN + 0] = n.x; var[kVarN + 1] = n.y; var[kVarN + 2] = n.z;
        glm::vec2 uv = i < mesh->uvs.size() ? mesh->uvs[i] : glm::vec2(0.0f);
        var[kVarUV + 0] = uv.x; var[kVarUV + 1] = uv.y;
        glm::vec4 t = i < mesh->tangents.size() ? mesh->tangents[i] : glm::vec4(1.0f, 0.0f, 0.0f, 1.0f);
        var[kVarT + 0] = t.x; var[kVarT + 1] = t.y; var[kVarT + 2] = t.z; var[kVarT + 3] = t.w;
    }

    static SurfacePoint surface_point(const FragmentBlock<kVaryings>& in, int l) {
        SurfacePoint sp;
        sp.P = {in.var[kVarP][l], in.var[kVarP + 1][l], in.var[kVarP + 2][l]};
        sp.N = {in.var[kVarN][l], in.var[kVarN + 1][l], in.var[kVarN + 2][l]};
        sp.T = {in.var[kVarT][l], in.var[kVarT + 1][l], in.var[kVarT + 2][l], in.var[kVarT + 3][l]};
        sp.uv = {in.var[kVarUV][l], in.var[kVarUV + 1][l]};
        sp.duv_dx = {in.ddx(kVarUV, l), in.ddx(kVarUV + 1, l)};
        sp.duv_dy = {in.ddy(kVarUV, l), in.ddy(kVarUV + 1, l)};
        sp.front_facing = in.front_facing;
        return sp;
    }

    void fragment(const FragmentBlock<kVaryings>& in, FragmentOut& out) const;
    // Several sparse blocks at once (raster/fragment.h): the same bytes as
    // fragment() on each.
    void fragment_batch(const FragmentBlock<kVaryings>* const* in, FragmentOut* const* out, int count) const;

private:
    bool lit_lanes() const;
    void shade_block(const FragmentBlock<kVaryings>& in, FragmentOut& out) const;
    void shade_packed_lanes(const FragmentBlock<kVaryings>* const* in, FragmentOut* const* out, int count) const;
    template <int N>
    void shade_packed(const FragmentBlock<kVaryings>* const* in, FragmentOut* const* out, int count) const;
};

} // namespace prast

// The rasterizer program for metal-roughness PBR: the vertex stage transforms
// world-space mesh vertices to clip space and passes position, normal, uv and
// tangent as varyings; the fragment stage builds a SurfacePoint per lane (uv
// derivatives from its 2x2 quad), samples the material and shades it, or
// writes one of the debug views.
#pragma once

#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "raster/fragment.h"
#include "shading/debug_view.h"
#include "scene/scene.h"
#include "shading/surface.h"

namespace prast {

// Varying layout. A draw whose mesh has vertex colours, or whose material
// reads a UV set past TEXCOORD_0, runs the wider layout (PbrProgramExt):
// the first kPbrVaryings are the same, then UV sets 1 .. kMaxUvSets - 1 (two
// floats each) and the RGBA colour. A lit draw whose material reads no map
// at all runs the position-and-normal layout (PbrProgramLite,
// kPbrVaryingsLite): nothing in its shading reads a UV or a tangent, so it
// gives the same bytes with half the varyings to interpolate and pack
// (narrow_varyings_suffice()). Every other draw runs kPbrVaryings.
enum : int {
    kVarP = 0, kVarN = 3, kVarUV = 6, kVarT = 8, kPbrVaryings = 12,
    kPbrVaryingsLite = kVarUV,
    kVarUVMore = kPbrVaryings,
    kVarColor = kVarUVMore + 2 * (kMaxUvSets - 1),
    kPbrVaryingsExt = kVarColor + 4
};

// The first varying of UV set `set`.
constexpr int var_uv(int set) { return set == 0 ? kVarUV : kVarUVMore + 2 * (set - 1); }

template <int NV>
struct PbrProgramT {
    static constexpr int kVaryings = NV;
    static constexpr bool kExtended = NV == kPbrVaryingsExt;
    static constexpr bool kUvAndTangent = NV != kPbrVaryingsLite;
    static_assert(NV == kPbrVaryingsLite || NV == kPbrVaryings || NV == kPbrVaryingsExt, "the three layouts");

    const Mesh* mesh = nullptr;
    glm::mat4 view_proj{1.0f};
    const BoundMaterial* material = nullptr;
    const ShadingContext* ctx = nullptr;
    DebugView view = DebugView::None;
    float near_plane = 0.1f, far_plane = 100.0f;  // for the depth view
    // The lane sampler's plan of `material`'s lookups (surface.h), made once
    // per frame; without it (or with another binding's) blocks plan their own.
    const LookupPlan* plan = nullptr;

    void vertex(std::uint32_t i, float clip[4], float* var) const {
        const glm::vec3& p = mesh->positions[i];
        glm::vec4 c = view_proj * glm::vec4(p, 1.0f);
        clip[0] = c.x; clip[1] = c.y; clip[2] = c.z; clip[3] = c.w;
        var[kVarP + 0] = p.x; var[kVarP + 1] = p.y; var[kVarP + 2] = p.z;
        glm::vec3 n = i < mesh->normals.size() ? mesh->normals[i] : glm::vec3(0.0f, 0.0f, 1.0f);
        var[kVarN + 0] = n.x; var[kVarN + 1] = n.y; var[kVarN + 2] = n.z;
        if constexpr (kUvAndTangent) {
            glm::vec2 uv = i < mesh->uvs.size() ? mesh->uvs[i] : glm::vec2(0.0f);
            var[kVarUV + 0] = uv.x; var[kVarUV + 1] = uv.y;
            glm::vec4 t = i < mesh->tangents.size() ? mesh->tangents[i] : glm::vec4(1.0f, 0.0f, 0.0f, 1.0f);
            var[kVarT + 0] = t.x; var[kVarT + 1] = t.y; var[kVarT + 2] = t.z; var[kVarT + 3] = t.w;
        }
        if constexpr (kExtended) {
            for (int set = 1; set < kMaxUvSets; ++set) {
                const std::vector<glm::vec2>& uvs = uv_set(*mesh, set);
                const glm::vec2 st = i < uvs.size() ? uvs[i] : glm::vec2(0.0f);
                var[var_uv(set)] = st.x; var[var_uv(set) + 1] = st.y;
            }
            const glm::vec4 c = i < mesh->colors.size() ? mesh->colors[i] : glm::vec4(1.0f);
            var[kVarColor + 0] = c.r; var[kVarColor + 1] = c.g; var[kVarColor + 2] = c.b; var[kVarColor + 3] = c.a;
        }
    }

    // The mesh's UV set `set` (1 .. kMaxUvSets - 1).
    static const std::vector<glm::vec2>& uv_set(const Mesh& m, int set) {
        static_assert(kMaxUvSets == 2, "name the further UV sets of Mesh here");
        (void)set;
        return m.uvs1;
    }

    // has_color: the mesh has vertex colours (the wide layout only).
    static SurfacePoint surface_point(const FragmentBlock<kVaryings>& in, int l, bool has_color = false) {
        SurfacePoint sp;
        sp.P = {in.var[kVarP][l], in.var[kVarP + 1][l], in.var[kVarP + 2][l]};
        sp.N = {in.var[kVarN][l], in.var[kVarN + 1][l], in.var[kVarN + 2][l]};
        if constexpr (kUvAndTangent) {
            sp.T = {in.var[kVarT][l], in.var[kVarT + 1][l], in.var[kVarT + 2][l], in.var[kVarT + 3][l]};
            sp.uv = {in.var[kVarUV][l], in.var[kVarUV + 1][l]};
            sp.duv_dx = {in.ddx(kVarUV, l), in.ddx(kVarUV + 1, l)};
            sp.duv_dy = {in.ddy(kVarUV, l), in.ddy(kVarUV + 1, l)};
        } else {  // what a mesh without UVs and tangents gives; read by nothing
            sp.T = glm::vec4(1.0f, 0.0f, 0.0f, 1.0f);
            sp.uv = sp.duv_dx = sp.duv_dy = glm::vec2(0.0f);
        }
        sp.front_facing = in.front_facing;
        if constexpr (kExtended) {
            for (int set = 1; set < kMaxUvSets; ++set) {
                const int k = var_uv(set);
                sp.uv_more[set - 1] = {in.var[k][l], in.var[k + 1][l]};
                sp.duv_more_dx[set - 1] = {in.ddx(k, l), in.ddx(k + 1, l)};
                sp.duv_more_dy[set - 1] = {in.ddy(k, l), in.ddy(k + 1, l)};
            }
            if (has_color) {
                sp.has_color = true;
                sp.color = {in.var[kVarColor][l], in.var[kVarColor + 1][l], in.var[kVarColor + 2][l],
                            in.var[kVarColor + 3][l]};
            }
        } else {
            (void)has_color;
        }
        return sp;
    }
    bool has_color() const { return kExtended && !mesh->colors.empty(); }

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

using PbrProgram = PbrProgramT<kPbrVaryings>;
using PbrProgramExt = PbrProgramT<kPbrVaryingsExt>;
using PbrProgramLite = PbrProgramT<kPbrVaryingsLite>;
extern template struct PbrProgramT<kPbrVaryings>;
extern template struct PbrProgramT<kPbrVaryingsExt>;
extern template struct PbrProgramT<kPbrVaryingsLite>;

// Whether a draw of `mesh` with `bm` needs the wide layout.
inline bool needs_extended_varyings(const Mesh& mesh, const BoundMaterial& bm) {
    return !mesh.colors.empty() || bm.reads_extra_uv_sets();
}

// Whether a draw of `mesh` with `bm`, showing `view`, may run PbrProgramLite:
// the lit image (the UV view shows UVs), the usual layout otherwise, and no
// map bound (only maps read UVs, and only normal maps read tangents).
inline bool narrow_varyings_suffice(const Mesh& mesh, const BoundMaterial& bm, DebugView view) {
    return (view == DebugView::None || view == DebugView::Tiles) && !needs_extended_varyings(mesh, bm) &&
           !bm.reads_maps();
}

} // namespace prast

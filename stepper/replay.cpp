// Recomputation from the recording; see replay.h.
#include "stepper/replay.h"

#include <algorithm>
#include <cmath>
#include <cstring>

#include "stepper/frame_loop.h"

namespace prast::stepper {

const BoundMaterial& material_of(const StepScene& s, const Recording& rec, std::uint32_t tri) {
    return draw_material(s, s.scene.meshes[std::size_t(rec.draw_of(tri).mesh)]);
}

ClipReplay replay_clip(const StepScene& s, const Recording& rec, std::uint32_t tri) {
    ClipReplay c;
    const DrawRecord& d = rec.draw_of(tri);
    const Mesh& mesh = s.scene.meshes[std::size_t(d.mesh)];
    const std::uint32_t prim = tri - d.first_triangle;
    const float* v[3];
    c.valid = true;
    for (int i = 0; i < 3; ++i) {
        c.index[i] = mesh.indices[3 * std::size_t(prim) + std::size_t(i)];
        if (c.index[i] >= d.vertex_count) { c.valid = false; return c; }
        v[i] = &d.vertices[std::size_t(c.index[i]) * kStride];
        for (int k = 0; k < 4; ++k) c.valid &= std::isfinite(v[i][k]);
    }
    if (!c.valid) return c;
    const GuardBand gb = GuardBand::for_viewport(rec.width, rec.height);
    for (int i = 0; i < 3; ++i) c.outcode[i] = outcode(v[i], gb);
    c.planes = (c.outcode[0] | c.outcode[1] | c.outcode[2]) & kClipNeededBits;
    if ((c.outcode[0] & c.outcode[1] & c.outcode[2] & kFrustumBits) || !c.planes) {
        c.count = 3;
        for (int i = 0; i < 3; ++i) std::memcpy(c.polygon[i], v[i], sizeof(float) * kStride);
        return c;
    }
    float poly[kMaxClippedVertices * kStride];
    c.count = clip_triangle(v, kStride, c.planes, gb, poly);
    for (int i = 0; i < c.count; ++i) std::memcpy(c.polygon[i], &poly[i * kStride], sizeof(float) * kStride);
    return c;
}

void piece_vertices(const StepScene& s, const Recording& rec, std::uint32_t piece, float out[3][kStride]) {
    const PieceRecord& p = rec.pieces[piece];
    const TriangleSetup& t = rec.setups[p.setup];
    const DrawRecord& d = rec.draw_of(p.triangle);
    if (!(t.vtx[0] & kClippedVertexBit)) {
        for (int i = 0; i < 3; ++i)
            std::memcpy(out[i], &d.vertices[std::size_t(t.vtx[i]) * kStride], sizeof(float) * kStride);
        return;
    }
    // A clipped piece k of the fan uses polygon vertices 0, k + 1, k + 2;
    // the pipeline numbered them from a base in its clip pool, the smallest.
    const ClipReplay c = replay_clip(s, rec, p.triangle);
    const std::uint32_t base = std::min({t.vtx[0], t.vtx[1], t.vtx[2]}) & ~kClippedVertexBit;
    for (int i = 0; i < 3; ++i) {
        const std::uint32_t j = (t.vtx[i] & ~kClippedVertexBit) - base;
        std::memcpy(out[i], c.polygon[std::min<std::uint32_t>(j, std::uint32_t(c.count - 1))],
                    sizeof(float) * kStride);
    }
}

SnappedVertex snap_vertex(const float* clip, int width, int height) {
    // setup_triangle()'s projection and snap, in double.
    SnappedVertex v;
    const double w = clip[3];
    v.x_win = (double(clip[0]) / w + 1.0) * 0.5 * width;
    v.y_win = (1.0 - double(clip[1]) / w) * 0.5 * height;
    v.fx = std::llrint(v.x_win * double(kSubPixelScale));
    v.fy = std::llrint(v.y_win * double(kSubPixelScale));
    v.z = float((double(clip[2]) / w + 1.0) * 0.5);
    v.inv_w = float(1.0 / w);
    return v;
}

void replay_block(const StepScene& s, const Recording& rec, const BlockRecord& b, ReplayedBlock& out) {
    const PieceRecord& p = rec.pieces[b.piece];
    const TriangleSetup& t = rec.setups[p.setup];
    float v[3][kStride];
    piece_vertices(s, rec, b.piece, v);
    constexpr int NV = kPbrVaryings;
    float v0[NV], d1[NV], d2[NV];
    for (int k = 0; k < NV; ++k) {
        v0[k] = v[0][4 + k];
        d1[k] = v[1][4 + k] - v[0][4 + k];
        d2[k] = v[2][4 + k] - v[0][4 + k];
    }
    FragmentBlock<NV>& in = out.in;
    const float ox = float(int(b.bx) - t.minx), oy = float(int(b.by) - t.miny);
    for (int l = 0; l < kBlockLanes; ++l) {
        // Screen-space barycentrics from the anchored planes, then depth.
        const float dx = ox + float(lane_x(l)), dy = oy + float(lane_y(l));
        const float b0 = t.bary[0][0] + t.bary[0][1] * dx + t.bary[0][2] * dy;
        const float b1 = t.bary[1][0] + t.bary[1][1] * dx + t.bary[1][2] * dy;
        const float b2 = t.bary[2][0] + t.bary[2][1] * dx + t.bary[2][2] * dy;
        const float z = b0 * t.z[0] + b1 * t.z[1] + b2 * t.z[2];
        in.z[l] = std::min(std::max(z, 0.0f), 1.0f);
        out.bary[0][l] = b0; out.bary[1][l] = b1; out.bary[2][l] = b2;
        // Perspective-correct weights: over w, renormalised; then the varyings.
        const float q0 = b0 * t.inv_w[0], q1 = b1 * t.inv_w[1], q2 = b2 * t.inv_w[2];
        const float sum = 1.0f / (q0 + q1 + q2);
        const float w1 = q1 * sum, w2 = q2 * sum;
        out.persp[0][l] = q0 * sum; out.persp[1][l] = w1; out.persp[2][l] = w2;
        for (int k = 0; k < NV; ++k) in.var[k][l] = v0[k] + w1 * d1[k] + w2 * d2[k];
    }
    in.x = b.bx;
    in.y = b.by;
    in.mask = b.pass;
    in.prim_id = t.prim_id;
    in.front_facing = t.front_facing;
}

LaneShading shade_lane(const ShadingContext& ctx, const BoundMaterial& bm, const ReplayedBlock& rb, int lane) {
    LaneShading r;
    r.sp = PbrProgram::surface_point(rb.in, lane);
    // The quad's lanes share their derivatives, hence their levels of detail.
    r.lods = material_lods(bm, r.sp.duv_dx, r.sp.duv_dy);
    r.ms = sample_material(bm, r.sp, r.lods);
    r.killed = bm.m->alpha_mode == AlphaMode::Mask && !(r.ms.alpha >= bm.m->alpha_cutoff);
    // shade_surface(), one step at a time.
    r.inputs = brdf_inputs(r.ms, r.sp, ctx);
    BrdfInputs in = r.inputs;
    glm::vec3 Lo = r.ms.emissive;
    for (const ShadingLight& L : ctx.lights) {
        LightStep st;
        light_at(L, r.sp.P, in.l, st.radiance);
        st.l = in.l;
        const glm::vec3 sum = in.l + in.v;  // evaluate_brdf()'s half vector, for display
        const float len2 = glm::dot(sum, sum);
        st.h = len2 > 0.0f ? sum / std::sqrt(len2) : in.n;
        st.terms = evaluate_brdf(in, ctx.model);
        st.contribution = st.terms.f * st.radiance * st.terms.NoL;
        Lo += st.contribution;
        r.lights.push_back(st);
    }
    r.ambient = ctx.ambient * r.ms.albedo * r.ms.occlusion;
    Lo += r.ambient;
    r.Lo = Lo;
    const glm::vec3 ref = shade_surface(r.ms, r.sp, ctx);
    r.matches_shade_surface = std::memcmp(&ref, &Lo, sizeof Lo) == 0;
    return r;
}

} // namespace prast::stepper

// Recomputation from the recording; see replay.h.
#include "stepper/replay.h"

#include <algorithm>
#include <cmath>
#include <cstring>

#include "raster/samples.h"
#include "raster/shade.h"

namespace prast::stepper {

const BoundMaterial& material_of(const FrameSetup& s, const Recording& rec, std::uint32_t tri) {
    return s.scene_renderer->material_of(s.scene.meshes[std::size_t(rec.draw_of(tri).mesh)]);
}

ClipReplay replay_clip(const FrameSetup& s, const Recording& rec, std::uint32_t tri) {
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

void piece_vertices(const FrameSetup& s, const Recording& rec, std::uint32_t piece, float out[3][kStride]) {
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

void replay_block(const FrameSetup& s, const Recording& rec, const BlockRecord& b, ReplayedBlock& out) {
    const PieceRecord& p = rec.pieces[b.piece];
    const TriangleSetup& t = rec.setups[p.setup];
    float v[3][kStride];
    piece_vertices(s, rec, b.piece, v);
    constexpr int NV = kPbrVaryings;
    raster_detail::TriangleVaryings<NV> pv;  // as prepare_varyings() makes them
    for (int k = 0; k < NV; ++k) {
        pv.v0[k] = v[0][4 + k];
        pv.d1[k] = v[1][4 + k] - v[0][4 + k];
        pv.d2[k] = v[2][4 + k] - v[0][4 + k];
    }
    FragmentBlock<NV>& in = out.in;
    const SamplePattern& sp = sample_pattern(rec.samples);
    const std::uint32_t lanes = b.shaded ? b.shaded : b.pass;  // the lanes the shader ran for
    // The rasterizer's own interpolation (shade.h), centroids included.
    if (rec.samples > 1) raster_detail::interpolate_block<true, NV>(t, pv, sp, b.bx, b.by, lanes, nullptr, in);
    else raster_detail::interpolate_block<false, NV>(t, pv, sp, b.bx, b.by, lanes, nullptr, in);
    in.x = b.bx;
    in.y = b.by;
    in.mask = lanes;
    in.prim_id = t.prim_id;
    in.front_facing = t.front_facing;

    // For display: the point each lane was interpolated at, its barycentrics
    // and perspective weights, with interpolate_block()'s float operations.
    for (int l = 0; l < kBlockLanes; ++l) {
        const int x = b.bx + lane_x(l), y = b.by + lane_y(l);
        float dx = float(b.bx - t.ax) + float(lane_x(l)), dy = float(b.by - t.ay) + float(lane_y(l));
        out.at_x[l] = out.at_y[l] = 0.0f;
        out.centroid_of[l] = 0;
        if ((in.centroid_mask >> l) & 1u) {
            float sum_x = 0.0f, sum_y = 0.0f;
            int n = 0;
            for (int smp = 0; smp < sp.count; ++smp) {
                bool inside = true;
                for (int e = 0; e < 3; ++e)
                    inside &= edge_at_pixel(t, e, x, y) + std::int64_t(t.A[e]) * sp.fixed_x(smp) +
                                  std::int64_t(t.B[e]) * sp.fixed_y(smp) >= 0;
                if (!inside) continue;
                sum_x += sp.pixel_x(smp);
                sum_y += sp.pixel_y(smp);
                out.centroid_of[l] |= std::uint8_t(1u << smp);
                ++n;
            }
            if (n > 0) {
                out.at_x[l] = sum_x / float(n);
                out.at_y[l] = sum_y / float(n);
                dx = float(x - t.ax) + out.at_x[l];
                dy = float(y - t.ay) + out.at_y[l];
            }
        }
        const float b0 = t.bary[0][0] + t.bary[0][1] * dx + t.bary[0][2] * dy;
        const float b1 = t.bary[1][0] + t.bary[1][1] * dx + t.bary[1][2] * dy;
        const float b2 = t.bary[2][0] + t.bary[2][1] * dx + t.bary[2][2] * dy;
        out.bary[0][l] = b0; out.bary[1][l] = b1; out.bary[2][l] = b2;
        const float q0 = b0 * t.inv_w[0], q1 = b1 * t.inv_w[1], q2 = b2 * t.inv_w[2];
        const float sum = 1.0f / (q0 + q1 + q2);
        out.persp[0][l] = q0 * sum; out.persp[1][l] = q1 * sum; out.persp[2][l] = q2 * sum;
    }
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
        if (L.shadow) {
            st.shadowed = true;
            st.shadow = shadow_probe(*L.shadow, r.sp.P, r.ms.N_geom, L.direction);
        }
        st.radiance *= light_visibility(L, r.sp.P, r.ms.N_geom);
        st.l = in.l;
        const glm::vec3 sum = in.l + in.v;  // evaluate_brdf()'s half vector, for display
        const float len2 = glm::dot(sum, sum);
        st.h = len2 > 0.0f ? sum / std::sqrt(len2) : in.n;
        st.terms = evaluate_brdf(in, ctx.model);
        st.contribution = st.terms.f * st.radiance * st.terms.NoL;
        Lo += st.contribution;
        r.lights.push_back(st);
    }
    r.ibl = ctx.env != nullptr;
    if (r.ibl) {
        r.ibl_terms = ibl_terms(r.ms, r.sp, ctx);
        r.ambient = r.ibl_terms.diffuse + r.ibl_terms.specular;
    } else {
        r.ambient = ctx.ambient * r.ms.albedo * r.ms.occlusion;
    }
    Lo += r.ambient;
    r.Lo = Lo;
    const glm::vec3 ref = shade_surface(r.ms, r.sp, ctx);
    r.matches_shade_surface = std::memcmp(&ref, &Lo, sizeof Lo) == 0;
    return r;
}

} // namespace prast::stepper

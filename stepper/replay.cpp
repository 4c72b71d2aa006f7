// Recomputation from the recording; see replay.h.
#include "stepper/replay.h"

#include <algorithm>
#include <cmath>
#include <cstring>

#include "raster/samples.h"
#include "raster/shade.h"

namespace prast::stepper {

const BoundMaterial& material_of(const FrameSetup& s, const Recording& rec, std::uint32_t tri) {
    return draw_material(s, rec.draw_of(tri));
}

const BoundMaterial& draw_material(const FrameSetup& s, const DrawRecord& d) {
    return s.scene_renderer->material_of(s.scene.meshes[std::size_t(d.mesh)]);
}

ClipReplay replay_clip(const FrameSetup& s, const Recording& rec, std::uint32_t tri) {
    ClipReplay c;
    const DrawRecord& d = rec.draw_of(tri);
    const Mesh& mesh = s.scene.meshes[std::size_t(d.mesh)];
    const std::uint32_t prim = tri - d.first_triangle;
    const int stride = d.stride();
    c.stride = stride;
    float full[3][kMaxStride];
    const float* v[3];
    c.valid = true;
    for (int i = 0; i < 3; ++i) {
        c.index[i] = mesh.indices[3 * std::size_t(prim) + std::size_t(i)];
        if (c.index[i] >= d.vertex_count) { c.valid = false; return c; }
        d.full_vertex(c.index[i], full[i]);
        v[i] = full[i];
        for (int k = 0; k < 4; ++k) c.valid &= std::isfinite(v[i][k]);
    }
    if (!c.valid) return c;
    const GuardBand gb = GuardBand::for_viewport(rec.width, rec.height);
    for (int i = 0; i < 3; ++i) c.outcode[i] = outcode(v[i], gb);
    c.planes = (c.outcode[0] | c.outcode[1] | c.outcode[2]) & kClipNeededBits;
    if ((c.outcode[0] & c.outcode[1] & c.outcode[2] & kFrustumBits) || !c.planes) {
        c.count = 3;
        for (int i = 0; i < 3; ++i) std::memcpy(c.polygon[i], v[i], sizeof(float) * std::size_t(stride));
        return c;
    }
    float poly[kMaxClippedVertices * kMaxStride];
    c.count = clip_triangle(v, stride, c.planes, gb, poly);
    for (int i = 0; i < c.count; ++i)
        std::memcpy(c.polygon[i], &poly[std::size_t(i) * std::size_t(stride)], sizeof(float) * std::size_t(stride));
    return c;
}

void piece_vertices_full(const FrameSetup& s, const Recording& rec, std::uint32_t piece, float out[3][kMaxStride]) {
    const PieceRecord& p = rec.pieces[piece];
    const TriangleSetup& t = rec.setups[p.setup];
    const DrawRecord& d = rec.draw_of(p.triangle);
    const std::size_t bytes = sizeof(float) * std::size_t(d.stride());
    if (!(t.vtx[0] & kClippedVertexBit)) {
        for (int i = 0; i < 3; ++i) d.full_vertex(t.vtx[i], out[i]);
        return;
    }
    // A clipped piece k of the fan uses polygon vertices 0, k + 1, k + 2;
    // the pipeline numbered them from a base in its clip pool, the smallest.
    const ClipReplay c = replay_clip(s, rec, p.triangle);
    const std::uint32_t base = std::min({t.vtx[0], t.vtx[1], t.vtx[2]}) & ~kClippedVertexBit;
    for (int i = 0; i < 3; ++i) {
        const std::uint32_t j = (t.vtx[i] & ~kClippedVertexBit) - base;
        std::memcpy(out[i], c.polygon[std::min<std::uint32_t>(j, std::uint32_t(c.count - 1))], bytes);
    }
}

void piece_vertices(const FrameSetup& s, const Recording& rec, std::uint32_t piece, float out[3][kStride]) {
    float full[3][kMaxStride];
    piece_vertices_full(s, rec, piece, full);
    for (int i = 0; i < 3; ++i) std::memcpy(out[i], full[i], sizeof(float) * kStride);
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

namespace {

// interpolate_block() with the draw's own varying count.
template <int NV>
void interpolate_as(const Recording& rec, const TriangleSetup& t, const float v[3][kMaxStride], int bx, int by,
                    std::uint32_t lanes, FragmentBlock<NV>& in) {
    raster_detail::TriangleVaryings<NV> pv;  // as prepare_varyings() makes them
    for (int k = 0; k < NV; ++k) {
        pv.v0[k] = v[0][4 + k];
        pv.d1[k] = v[1][4 + k] - v[0][4 + k];
        pv.d2[k] = v[2][4 + k] - v[0][4 + k];
    }
    const SamplePattern& sp = sample_pattern(rec.samples);
    // The rasterizer's own interpolation (shade.h), centroids included.
    if (rec.samples > 1) raster_detail::interpolate_block<true, NV>(t, pv, sp, bx, by, lanes, nullptr, in);
    else raster_detail::interpolate_block<false, NV>(t, pv, sp, bx, by, lanes, nullptr, in);
    in.x = bx;
    in.y = by;
    in.mask = lanes;
    in.prim_id = t.prim_id;
    in.front_facing = t.front_facing;
}

// The narrow block's varyings from a wider one: the same values (each
// varying is interpolated on its own).
template <int NV, int NW>
void narrow_block(const FragmentBlock<NW>& w, FragmentBlock<NV>& n) {
    static_assert(NV <= NW, "narrowing");
    for (int k = 0; k < NV; ++k) {
        std::memcpy(n.var[k], w.var[k], sizeof n.var[k]);
        std::memcpy(n.centre_var[k], w.centre_var[k], sizeof n.centre_var[k]);
    }
    std::memcpy(n.z, w.z, sizeof n.z);
    n.x = w.x;
    n.y = w.y;
    n.mask = w.mask;
    n.prim_id = w.prim_id;
    n.front_facing = w.front_facing;
    n.centroid_mask = w.centroid_mask;
}

} // namespace

void replay_block(const FrameSetup& s, const Recording& rec, const BlockRecord& b, ReplayedBlock& out) {
    const PieceRecord& p = rec.pieces[b.piece];
    const TriangleSetup& t = rec.setups[p.setup];
    const DrawRecord& d = rec.draw_of(p.triangle);
    float v[3][kMaxStride];
    piece_vertices_full(s, rec, b.piece, v);
    const SamplePattern& sp = sample_pattern(rec.samples);
    const std::uint32_t lanes = b.shaded ? b.shaded : b.pass;  // the lanes the shader ran for
    out.varyings = d.varyings;
    out.line = false;
    out.has_color = d.varyings == kPbrVaryingsExt && !s.scene.meshes[std::size_t(d.mesh)].colors.empty();
    FragmentBlock<kPbrVaryings>& in = out.in;
    if (d.varyings == kPbrVaryingsExt) {
        interpolate_as<kPbrVaryingsExt>(rec, t, v, b.bx, b.by, lanes, out.ext);
        narrow_block(out.ext, in);
    } else {
        interpolate_as<kPbrVaryings>(rec, t, v, b.bx, b.by, lanes, in);
    }

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

SurfacePoint replay_surface_point(const ReplayedBlock& rb, int lane) {
    if (rb.varyings == kPbrVaryingsExt) return PbrProgramExt::surface_point(rb.ext, lane, rb.has_color);
    return PbrProgram::surface_point(rb.in, lane);
}

LaneShading shade_lane(const ShadingContext& ctx, const BoundMaterial& bm, const ReplayedBlock& rb, int lane) {
    LaneShading r;
    if (rb.varyings == UnlitProgram::kVaryings) {
        // UnlitProgram::fragment(), term by term; then the program itself on
        // the block, whose lane must give the same bytes.
        const FragmentBlock<UnlitProgram::kVaryings>& in = rb.unlit;
        const Material& m = *bm.m;
        r.unlit = true;
        r.unlit_color = glm::vec4(in.var[2][lane], in.var[3][lane], in.var[4][lane], in.var[5][lane]);
        glm::vec4 c = m.base_color_factor * r.unlit_color;
        if (bm.base_color) {
            r.unlit_texture = bm.base_color->sample(in.var[0][lane], in.var[1][lane], 0.0f, 0.0f, 0.0f, 0.0f);
            c *= r.unlit_texture;
        }
        r.sp.uv = {in.var[0][lane], in.var[1][lane]};
        r.sp.has_color = true;
        r.sp.color = r.unlit_color;
        r.ms.albedo = glm::vec3(c);
        r.ms.alpha = c.a;
        r.killed = m.alpha_mode == AlphaMode::Mask && !(c.a >= m.alpha_cutoff);
        r.Lo = glm::vec3(c);
        UnlitProgram prog;
        prog.material = &bm;
        FragmentOut out;
        prog.fragment(in, out);
        const glm::vec3 ref(out.r[lane], out.g[lane], out.b[lane]);
        r.matches_shade_surface = std::memcmp(&ref, &r.Lo, sizeof ref) == 0 && r.killed == (((out.kill >> lane) & 1u) != 0);
        return r;
    }
    r.sp = replay_surface_point(rb, lane);
    // The quad's lanes share their derivatives, hence their levels of detail
    // (each map's from the UV set it reads).
    r.lods = material_lods(bm, r.sp);
    r.ms = sample_material(bm, r.sp, r.lods);
    r.killed = bm.m->alpha_mode == AlphaMode::Mask && !(r.ms.alpha >= bm.m->alpha_cutoff);
    // shade_surface(), one step at a time.
    r.inputs = brdf_inputs(r.ms, r.sp, ctx);
    BrdfInputs in = r.inputs;
    glm::vec3 Lo = coated_emission(r.ms, in);  // the emission, under the clear coat if any
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
        st.contribution = brdf_light(st.terms, st.radiance);  // with the clear coat's lobe if any
        Lo += st.contribution;
        r.lights.push_back(st);
    }
    r.ibl = ctx.env != nullptr;
    if (r.ibl) {
        r.ibl_terms = ibl_terms(r.ms, r.sp, ctx);
        r.ambient = ibl_sum(r.ibl_terms);
    } else {
        r.ambient = ctx.ambient * r.ms.albedo * r.ms.occlusion;
    }
    Lo += r.ambient;
    r.Lo = Lo;
    const glm::vec3 ref = shade_surface(r.ms, r.sp, ctx);
    r.matches_shade_surface = std::memcmp(&ref, &Lo, sizeof Lo) == 0;
    return r;
}

LineReplay replay_line(const FrameSetup& s, const Recording& rec, std::size_t draw, std::uint32_t prim) {
    // bin.h's bin_lines(), with the recorded vertices.
    LineReplay r;
    const DrawRecord& d = rec.draws[draw];
    const Mesh& mesh = s.scene.meshes[std::size_t(d.mesh)];
    const int stride = d.stride();
    r.point = d.topology == Topology::Points;
    const std::size_t per = r.point ? 1 : 2;
    if (per * std::size_t(prim) + per > mesh.indices.size()) return r;
    r.index[0] = mesh.indices[per * prim];
    r.index[1] = mesh.indices[per * prim + per - 1];
    if (r.index[0] >= d.vertex_count || r.index[1] >= d.vertex_count) return r;
    float a[kMaxStride], b[kMaxStride];
    d.full_vertex(r.index[0], a);
    d.full_vertex(r.index[1], b);
    r.valid = true;
    for (int k = 0; k < 4; ++k) r.valid &= std::isfinite(a[k]) && std::isfinite(b[k]);
    if (!r.valid) return r;
    const GuardBand gb = GuardBand::for_viewport(rec.width, rec.height);
    const std::uint32_t oc0 = outcode(a, gb), oc1 = outcode(b, gb);
    std::memcpy(r.v[0], a, sizeof(float) * std::size_t(stride));
    std::memcpy(r.v[1], b, sizeof(float) * std::size_t(stride));
    if (r.point) {
        r.drawn = !(oc0 & (kOutNear | kOutFar)) &&
                  setup_point(window_vertex(a, rec.width, rec.height), r.index[0], rec.width, rec.height, r.setup);
    } else if (oc0 & oc1 & kFrustumBits) {
        r.drawn = false;
    } else if (const std::uint32_t planes = (oc0 | oc1) & kClipNeededBits) {
        r.planes = planes;
        float seg[2 * kMaxStride];
        r.drawn = clip_line(a, b, stride, planes, gb, seg);
        if (r.drawn) {
            std::memcpy(r.v[0], seg, sizeof(float) * std::size_t(stride));
            std::memcpy(r.v[1], seg + stride, sizeof(float) * std::size_t(stride));
            const std::uint32_t pref[2] = {kClippedVertexBit, 1u | kClippedVertexBit};
            r.drawn = setup_line(window_vertex(r.v[0], rec.width, rec.height),
                                 window_vertex(r.v[1], rec.width, rec.height), pref, rec.width, rec.height, r.setup);
        }
    } else {
        r.drawn = setup_line(window_vertex(a, rec.width, rec.height), window_vertex(b, rec.width, rec.height),
                             r.index, rec.width, rec.height, r.setup);
    }
    r.setup.prim_id = prim;
    return r;
}

namespace {

// line_block()'s values at one pixel, into every lane of its quad.
template <int NV>
void line_lanes(const LineReplay& l, float w1, float z, int lane, int bx, int by, FragmentBlock<NV>& in) {
    float var[NV];
    for (int k = 0; k < NV; ++k) {
        const float v0 = l.v[0][4 + k], dv = l.v[1][4 + k] - l.v[0][4 + k];  // prepare_line_varyings()
        var[k] = v0 + w1 * dv;
    }
    for (int j = 0; j < kBlockLanes; ++j) {
        in.z[j] = z;
        for (int k = 0; k < NV; ++k) in.var[k][j] = var[k];
    }
    in.x = bx;
    in.y = by;
    in.mask = 1u << lane;
    in.prim_id = l.setup.prim_id;
    in.front_facing = true;
    in.centroid_mask = 0;
}

} // namespace

void replay_line_fragment(const FrameSetup& s, const Recording& rec, std::size_t draw, const LineReplay& l, int x,
                          int y, LineFragment& out) {
    const DrawRecord& d = rec.draws[draw];
    const LineSetup& ls = l.setup;
    // line_block(): depth linear in window space, varyings perspective-correct.
    out.t = line_parameter(ls, x, y);
    const float zt = ls.z0 + out.t * (ls.z1 - ls.z0);
    out.z = std::min(std::max(zt, 0.0f), 1.0f);
    const float q0 = (1.0f - out.t) * ls.inv_w0, q1 = out.t * ls.inv_w1;
    out.w1 = out.t > 0.0f ? q1 / (q0 + q1) : 0.0f;
    const int bx = x & ~(kBlockSize - 1), by = y & ~(kBlockSize - 1);
    int lane = 0;
    for (int k = 0; k < kBlockLanes; ++k)
        if (lane_x(k) == x - bx && lane_y(k) == y - by) lane = k;
    ReplayedBlock& rb = out.block;
    rb.varyings = d.varyings;
    rb.line = true;
    rb.has_color = d.varyings == kPbrVaryingsExt && !s.scene.meshes[std::size_t(d.mesh)].colors.empty();
    if (d.varyings == UnlitProgram::kVaryings) {
        line_lanes(l, out.w1, out.z, lane, bx, by, rb.unlit);
    } else if (d.varyings == kPbrVaryingsExt) {
        line_lanes(l, out.w1, out.z, lane, bx, by, rb.ext);
        narrow_block(rb.ext, rb.in);
    } else {
        line_lanes(l, out.w1, out.z, lane, bx, by, rb.in);
    }
    for (int k = 0; k < kBlockLanes; ++k) {
        rb.at_x[k] = rb.at_y[k] = 0.0f;
        rb.centroid_of[k] = 0;
        rb.bary[0][k] = 1.0f - out.t; rb.bary[1][k] = out.t; rb.bary[2][k] = 0.0f;
        rb.persp[0][k] = 1.0f - out.w1; rb.persp[1][k] = out.w1; rb.persp[2][k] = 0.0f;
    }
}

} // namespace prast::stepper

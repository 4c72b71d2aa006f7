// Fitting and drawing the shadow maps of a frame; see shadow_pass.h.
#include "shading/shadow/shadow_pass.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <glm/gtc/matrix_transform.hpp>

#include "scene/det_math.h"

namespace prast {

namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();

// Opaque casters: position only, a depth-only program (no fragment stage).
struct ShadowCasterProgram {
    static constexpr int kVaryings = 0;
    const glm::vec3* positions = nullptr;
    glm::vec3 origin{0.0f};
    glm::mat4 view_proj{1.0f};

    void vertex(std::uint32_t i, float clip[4], float*) const {
        const glm::vec4 c = view_proj * glm::vec4(positions[i] - origin, 1.0f);
        clip[0] = c.x; clip[1] = c.y; clip[2] = c.z; clip[3] = c.w;
    }
};

// MASK and BLEND casters: the base colour's alpha against a cutoff, as the
// PBR program's MASK test does (factor times texture times vertex colour;
// the texture on its own UV set and sampler, level of detail from the
// quad's uv derivatives in the map's texels).
struct ShadowCutoutProgram {
    static constexpr int kVaryings = 3;  // u, v, the vertex colour's alpha
    const Mesh* mesh = nullptr;
    const std::vector<glm::vec2>* uvs = nullptr;  // the base colour map's set
    const BoundMaterial* material = nullptr;
    float cutoff = 0.5f;
    glm::vec3 origin{0.0f};
    glm::mat4 view_proj{1.0f};

    void vertex(std::uint32_t i, float clip[4], float* var) const {
        const glm::vec4 c = view_proj * glm::vec4(mesh->positions[i] - origin, 1.0f);
        clip[0] = c.x; clip[1] = c.y; clip[2] = c.z; clip[3] = c.w;
        const glm::vec2 uv = i < uvs->size() ? (*uvs)[i] : glm::vec2(0.0f);
        var[0] = uv.x;
        var[1] = uv.y;
        var[2] = i < mesh->colors.size() ? mesh->colors[i].a : 1.0f;
    }
    void fragment(const FragmentBlock<kVaryings>& in, FragmentOut& out) const {
        const float factor = material->m->base_color_factor.a;
        const Texture* tex = material->base_color;
        const bool colored = !mesh->colors.empty();
        float lod = 0.0f;
        for (int l = 0; l < kBlockLanes; ++l) {
            out.r[l] = out.g[l] = out.b[l] = out.a[l] = 0.0f;
            if (!(in.mask & (1u << l))) continue;
            float alpha = factor;
            if (tex) {
                if (!(in.mask & (0xFu << (l & ~3)) & ((1u << l) - 1)))  // first live lane of its quad
                    lod = tex->lod(in.ddx(0, l), in.ddx(1, l), in.ddy(0, l), in.ddy(1, l));
                alpha *= tex->sample_lod(in.var[0][l], in.var[1][l], lod).a;
            }
            if (colored) alpha *= in.var[2][l];
            if (!(alpha >= cutoff)) out.kill |= 1u << l;
        }
    }
};

// A matrix from its rows.
glm::mat4 from_rows(const glm::vec4& r0, const glm::vec4& r1, const glm::vec4& r2, const glm::vec4& r3) {
    return glm::transpose(glm::mat4(r0, r1, r2, r3));
}

bool finite(const glm::vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

// Whether a box (relative to `origin`) lies wholly outside one clip plane of
// view_proj, with a little slack for rounding.
bool box_outside(const Bounds& b, const glm::vec3& origin, const glm::mat4& view_proj) {
    bool outside[6] = {true, true, true, true, true, true};
    for (int c = 0; c < 8; ++c) {
        const glm::vec3 p((c & 1) ? b.hi.x : b.lo.x, (c & 2) ? b.hi.y : b.lo.y, (c & 4) ? b.hi.z : b.lo.z);
        const glm::vec4 q = view_proj * glm::vec4(p - origin, 1.0f);
        // Plane x + w >= 0 and the others; the slack grows with the values.
        auto out = [&](float a) { return a + q.w < -(1e-3f * (std::fabs(a) + std::fabs(q.w)) + 1e-6f); };
        outside[0] &= out(q.x); outside[1] &= out(-q.x);
        outside[2] &= out(q.y); outside[3] &= out(-q.y);
        outside[4] &= out(q.z); outside[5] &= out(-q.z);
    }
    return outside[0] || outside[1] || outside[2] || outside[3] || outside[4] || outside[5];
}

// The summary cells (shadow_map.h) of one face row: out[c] = the least (or
// greatest, Max) of texels [2 c, 2 c + 5] of d, clipped to its n texels;
// `pair` is scratch.
template <bool Max>
void cell_row(const float* __restrict d, int n, float* __restrict pair, float* __restrict out) {
    const int k = (n + 1) / 2;
    auto pick = [](float a, float b) { return Max ? std::max(a, b) : std::min(a, b); };
    for (int i = 0; i < k; ++i) pair[i] = pick(d[2 * i], d[std::min(2 * i + 1, n - 1)]);
    for (int c = 0; c < k; ++c)
        out[c] = pick(pick(pair[c], pair[std::min(c + 1, k - 1)]), pair[std::min(c + 2, k - 1)]);
}

// Then down: out[c] = the least (greatest) of six rows' cells, in a loop the
// compiler vectorises.
template <bool Max>
void cell_column(const float* __restrict r0, const float* __restrict r1, const float* __restrict r2,
                 const float* __restrict r3, const float* __restrict r4, const float* __restrict r5, int k,
                 float* __restrict out) {
    auto pick = [](float a, float b) { return Max ? std::max(a, b) : std::min(a, b); };
    for (int c = 0; c < k; ++c) out[c] = pick(pick(pick(r0[c], r1[c]), pick(r2[c], r3[c])), pick(r4[c], r5[c]));
}

// A directional map's row: window depth to distance from the near plane
// (nothing drawn: +inf).
void sun_distances(const float* __restrict z, float* __restrict d, int n, float range) {
    for (int i = 0; i < n; ++i) {
        const float zi = z[i];
        d[i] = zi < 1.0f ? zi * range : kInf;
    }
}

// A cube face's row: window depth to distance from the light: the depth
// along the face's axis, f n / (f - z (f - n)), times the length of the
// texel centre's ray (a, b, 1), a = (i + 0.5) step - e.
void cube_distances(const float* __restrict z, float* __restrict d, int n, float b, float e, float step,
                    float near_d, float far_d) {
    for (int i = 0; i < n; ++i) {
        const float zi = z[i];
        const float a = (float(i) + 0.5f) * step - e;
        const float depth = far_d * near_d / (far_d - zi * (far_d - near_d));
        d[i] = zi < 1.0f ? depth * std::sqrt(1.0f + a * a + b * b) : kInf;
    }
}

// Work split for the per-texel passes: rows in chunks, each chunk one task.
template <class Fn>
void for_rows(Renderer& renderer, int rows, Fn&& fn) {
    constexpr int kRows = 32;
    renderer.pool().run((rows + kRows - 1) / kRows, [&](int chunk, int) {
        const int end = std::min(rows, (chunk + 1) * kRows);
        for (int j = chunk * kRows; j < end; ++j) fn(j);
    });
}

} // namespace

ShadowMap fit_directional_shadow(const glm::vec3& toward_light, const Bounds& scene, const Camera& camera,
                                 float aspect, int size, glm::mat4& view_proj, float& range) {
    // Light space, in double: z towards the light, x and y across it,
    // centred on the scene.
    const glm::dvec3 z = glm::normalize(glm::dvec3(toward_light));
    const glm::dvec3 helper = std::fabs(z.y) < 0.99 ? glm::dvec3(0, 1, 0) : glm::dvec3(1, 0, 0);
    const glm::dvec3 x = glm::normalize(glm::cross(helper, z));
    const glm::dvec3 y = glm::cross(z, x);
    const glm::vec3 origin_f = scene.center();
    const glm::dvec3 origin(origin_f);
    auto to_light = [&](const glm::dvec3& p) {
        const glm::dvec3 q = p - origin;
        return glm::dvec3(glm::dot(q, x), glm::dot(q, y), glm::dot(q, z));
    };

    // The scene's box and the camera frustum in light space.
    glm::dvec3 slo(1e300), shi(-1e300);
    for (int c = 0; c < 8; ++c) {
        const glm::dvec3 p((c & 1) ? scene.hi.x : scene.lo.x, (c & 2) ? scene.hi.y : scene.lo.y,
                           (c & 4) ? scene.hi.z : scene.lo.z);
        const glm::dvec3 q = to_light(p);
        slo = glm::min(slo, q);
        shi = glm::max(shi, q);
    }
    const glm::dvec3 eye(camera.eye);
    const glm::dvec3 fwd = glm::normalize(glm::dvec3(camera.target) - eye);
    const glm::dvec3 right = glm::normalize(glm::cross(fwd, glm::dvec3(camera.up)));
    const glm::dvec3 up = glm::cross(right, fwd);
    const double tan_half = det::tan(glm::radians(double(camera.fov_y_deg)) * 0.5);
    glm::dvec2 flo(1e300), fhi(-1e300);
    for (int c = 0; c < 8; ++c) {
        const double d = (c & 4) ? double(camera.far_plane) : double(camera.near_plane);
        const double h = d * tan_half, w = h * double(aspect);
        const glm::dvec3 p = eye + fwd * d + right * ((c & 1) ? w : -w) + up * ((c & 2) ? h : -h);
        const glm::dvec3 q = to_light(p);
        flo = glm::min(flo, glm::dvec2(q));
        fhi = glm::max(fhi, glm::dvec2(q));
    }

    // The visible rectangle: the overlap, or the whole scene when the two do
    // not overlap or the frustum is not finite.
    glm::dvec2 lo = glm::max(glm::dvec2(slo), flo), hi = glm::min(glm::dvec2(shi), fhi);
    if (!(lo.x < hi.x && lo.y < hi.y)) {
        lo = glm::dvec2(slo);
        hi = glm::dvec2(shi);
    }
    // Side: the scene's, shrunk by whole quarter octaves while it still holds
    // the visible rectangle (at most 6 octaves).
    const double whole = std::max({shi.x - slo.x, shi.y - slo.y, 1e-6 * (1.0 + glm::length(origin))});
    const double needed = std::max({hi.x - lo.x, hi.y - lo.y, whole / 64.0});
    int steps = int(std::floor(4.0 * det::log2(whole / needed)));
    steps = std::clamp(steps, 0, 24);
    while (steps > 0 && whole * det::exp2(-steps / 4.0) < needed) --steps;
    const double side = whole * det::exp2(-steps / 4.0);
    // Three texels of margin each side for the PCF footprint; the centre
    // snapped to whole texels.
    const double texel = side / double(size - 6);
    const double ku = std::round((lo.x + hi.x) * 0.5 / texel), kv = std::round((lo.y + hi.y) * 0.5 / texel);
    const double half = double(size) * 0.5;

    // Depth: the whole scene's extent along the light (casters outside the
    // frustum still cast), with a margin so nothing touches the clip planes.
    const double depth_margin = 0.01 * (shi.z - slo.z) + 1e-4 * whole;
    const double near_z = shi.z + depth_margin;
    range = float((shi.z - slo.z) + 2.0 * depth_margin);

    ShadowMap m;
    m.cube = false;
    m.size = size;
    m.stride = size + 2 * kShadowPad;
    m.origin = origin_f;
    m.axis_u = glm::vec3(x / texel);
    m.axis_v = glm::vec3(-y / texel);
    m.offset_u = float(half - ku);
    m.offset_v = float(half + kv);
    m.toward_light = glm::vec3(z);
    m.distance0 = float(near_z);
    m.texel = float(texel);

    // clip x = 2 u / size - 1, y = 1 - 2 v / size (row 0 at the top), z =
    // 2 distance / range - 1, for P - origin.
    const float s = 2.0f / float(size), rz = 2.0f / range;
    view_proj = from_rows(glm::vec4(m.axis_u * s, m.offset_u * s - 1.0f),
                          glm::vec4(-m.axis_v * s, 1.0f - m.offset_v * s),
                          glm::vec4(-m.toward_light * rz, m.distance0 * rz - 1.0f), glm::vec4(0, 0, 0, 1));
    return m;
}

void ShadowMaps::draw_casters(const Scene& scene, const std::vector<BoundMaterial>& materials, Renderer& renderer,
                              const glm::mat4& view_proj, const glm::vec3& origin) {
    static const Material kFallback;
    static const BoundMaterial kFallbackBound{&kFallback};
    FrameOptions frame;  // depth cleared to 1 in the tile pass; one sample
    renderer.begin(*target_, frame);
    DrawState st;
    st.cull = CullMode::None;
    for (std::size_t mi = 0; mi < scene.meshes.size(); ++mi) {
        const Mesh& mesh = scene.meshes[mi];
        // Lines and points are 1 pixel wide in the image: they cast no shadow.
        if (mesh.topology != Mesh::Topology::Triangles || mesh.indices.empty() || mesh_bounds_[mi].empty() ||
            box_outside(mesh_bounds_[mi], origin, view_proj))
            continue;
        const BoundMaterial* bm = mesh.material >= 0 && std::size_t(mesh.material) < materials.size()
                                      ? &materials[std::size_t(mesh.material)] : &kFallbackBound;
        const std::uint32_t vertices = std::uint32_t(mesh.positions.size());
        const AlphaMode mode = bm->m->alpha_mode;
        if (mode == AlphaMode::Opaque) {
            ShadowCasterProgram prog;
            prog.positions = mesh.positions.data();
            prog.origin = origin;
            prog.view_proj = view_proj;
            renderer.submit(prog, vertices, mesh.indices.data(), mesh.indices.size(), st);
        } else {
            ShadowCutoutProgram prog;
            prog.mesh = &mesh;
            prog.uvs = bm->uv.base_color == 1 ? &mesh.uvs1 : &mesh.uvs;
            prog.material = bm;
            prog.cutoff = mode == AlphaMode::Mask ? bm->m->alpha_cutoff : kBlendShadowCutoff;
            prog.origin = origin;
            prog.view_proj = view_proj;
            DrawState cut = st;
            cut.may_discard = true;
            renderer.submit(prog, vertices, mesh.indices.data(), mesh.indices.size(), cut);
        }
    }
    renderer.end();
}

void ShadowMaps::summarise(Renderer& renderer, ShadowMap& map, int face) {
    // Rows of cells across the face, then six rows of those down.
    const int w = map.stride, k = map.cells;
    const std::size_t face0 = std::size_t(face) * std::size_t(w) * std::size_t(w);
    const std::size_t cell0 = std::size_t(face) * std::size_t(k) * std::size_t(k);
    row_min_.resize(std::size_t(w) * std::size_t(k));
    row_max_.resize(row_min_.size());
    pairs_.resize(std::size_t(w) * std::size_t(k));
    for_rows(renderer, w, [&](int j) {
        const float* d = &map.distance[face0 + std::size_t(j) * w];
        float* pair = &pairs_[std::size_t(j) * k];
        cell_row<false>(d, w, pair, &row_min_[std::size_t(j) * k]);
        cell_row<true>(d, w, pair, &row_max_[std::size_t(j) * k]);
    });
    for_rows(renderer, k, [&](int cj) {
        std::size_t r[6];
        for (int i = 0; i < 6; ++i) r[i] = std::size_t(std::min(2 * cj + i, w - 1)) * k;
        const float* mn = row_min_.data();
        const float* mx = row_max_.data();
        cell_column<false>(mn + r[0], mn + r[1], mn + r[2], mn + r[3], mn + r[4], mn + r[5], k,
                           &map.cell_min[cell0 + std::size_t(cj) * k]);
        cell_column<true>(mx + r[0], mx + r[1], mx + r[2], mx + r[3], mx + r[4], mx + r[5], k,
                          &map.cell_max[cell0 + std::size_t(cj) * k]);
    });
}

void ShadowMaps::draw(const Scene& scene, const std::vector<BoundMaterial>& materials, Renderer& renderer,
                      const ShadowSettings& settings, const Camera& camera, float aspect,
                      std::vector<ShadingLight>& lights) {
    if (!bounds_known_) {
        mesh_bounds_.assign(scene.meshes.size(), Bounds());
        for (std::size_t mi = 0; mi < scene.meshes.size(); ++mi) {
            for (const glm::vec3& p : scene.meshes[mi].positions)
                if (finite(p)) mesh_bounds_[mi].add(p);
            if (!mesh_bounds_[mi].empty()) {
                bounds_.add(mesh_bounds_[mi].lo);
                bounds_.add(mesh_bounds_[mi].hi);
            }
        }
        bounds_known_ = true;
    }
    if (bounds_.empty()) return;
    maps_.resize(lights.size());
    const int cube_size = std::max(8, settings.size / 2);

    for (std::size_t li = 0; li < lights.size(); ++li) {
        ShadingLight& L = lights[li];
        if (!maps_[li]) maps_[li] = std::make_unique<ShadowMap>();
        ShadowMap& map = *maps_[li];
        std::vector<float> storage = std::move(map.distance);
        std::vector<float> cell_min = std::move(map.cell_min), cell_max = std::move(map.cell_max);

        if (!L.point) {
            glm::mat4 vp;
            float range = 0.0f;
            map = fit_directional_shadow(L.direction, bounds_, camera, aspect, settings.size, vp, range);
            const std::size_t texels = std::size_t(map.stride) * std::size_t(map.stride);
            if (storage.size() != texels) storage.assign(texels, kInf);  // the padding stays +inf
            map.distance = std::move(storage);
            map.cells = (map.stride + 1) / 2;
            map.cell_min = std::move(cell_min);
            map.cell_max = std::move(cell_max);
            map.cell_min.resize(std::size_t(map.cells) * std::size_t(map.cells));
            map.cell_max.resize(map.cell_min.size());
            if (sun_target_.width != map.size) sun_target_ = Framebuffer::depth_only(map.size, map.size);
            target_ = &sun_target_;
            draw_casters(scene, materials, renderer, vp, map.origin);
            for_rows(renderer, map.size, [&](int j) {
                sun_distances(&sun_target_.depth[std::size_t(j) * std::size_t(map.size)],
                              &map.distance[std::size_t(j + kShadowPad) * map.stride + kShadowPad], map.size, range);
            });
            summarise(renderer, map, 0);
            L.shadow = &map;
            continue;
        }

        // Point light: six faces around its position, out to the farthest
        // corner of the scene; the near plane as far out as every caster
        // allows (at most the nearest point of the box over sqrt(3)).
        map = ShadowMap();
        map.cube = true;
        map.size = cube_size;
        map.stride = cube_size + 2 * kShadowPad;
        map.position = L.position;
        map.extent = float(double(cube_size) / double(cube_size - 6));
        map.texel_angle = 2.0f * map.extent / float(cube_size);
        const std::size_t face_texels = std::size_t(map.stride) * std::size_t(map.stride);
        if (storage.size() != 6 * face_texels) storage.assign(6 * face_texels, kInf);
        map.distance = std::move(storage);
        map.cells = (map.stride + 1) / 2;
        map.cell_min = std::move(cell_min);
        map.cell_max = std::move(cell_max);
        map.cell_min.resize(6 * std::size_t(map.cells) * std::size_t(map.cells));
        map.cell_max.resize(map.cell_min.size());
        const glm::dvec3 lp(L.position), blo(bounds_.lo), bhi(bounds_.hi);
        double far_d = 0.0;
        for (int c = 0; c < 8; ++c) {
            const glm::dvec3 p((c & 1) ? bhi.x : blo.x, (c & 2) ? bhi.y : blo.y, (c & 4) ? bhi.z : blo.z);
            far_d = std::max(far_d, glm::length(p - lp));
        }
        const double nearest = glm::length(glm::clamp(lp, blo, bhi) - lp);
        far_d = far_d * 1.01 + 1e-6;
        const double near_d = std::max(far_d * 1e-3, 0.5 * nearest);
        const float n = float(near_d), f = float(far_d), e = map.extent;
        const glm::mat4 proj = glm::frustum(-e * n, e * n, -e * n, e * n, n, f);
        if (cube_target_.width != cube_size) cube_target_ = Framebuffer::depth_only(cube_size, cube_size);
        target_ = &cube_target_;
        for (int face = 0; face < 6; ++face) {
            const ShadowCubeFace& cf = shadow_cube_face(face);
            const glm::mat4 vp = proj * glm::lookAt(glm::vec3(0.0f), cf.forward, cf.up);
            float* out = &map.distance[std::size_t(face) * face_texels];
            // A face whose frustum misses the scene's box keeps +inf.
            if (box_outside(bounds_, L.position, vp)) {
                for_rows(renderer, cube_size, [&](int j) {
                    std::fill_n(out + std::size_t(j + kShadowPad) * map.stride + kShadowPad, cube_size, kInf);
                });
                summarise(renderer, map, face);
                continue;
            }
            draw_casters(scene, materials, renderer, vp, L.position);
            const float step = 2.0f * e / float(cube_size);
            for_rows(renderer, cube_size, [&](int j) {
                cube_distances(&cube_target_.depth[std::size_t(j) * std::size_t(cube_size)],
                               out + std::size_t(j + kShadowPad) * map.stride + kShadowPad, cube_size,
                               e - (float(j) + 0.5f) * step, e, step, n, f);
            });
            summarise(renderer, map, face);
        }
        L.shadow = &map;
    }
}

} // namespace prast

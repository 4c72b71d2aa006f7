// Text and JSON explanations of the recorded frame; see explain.h.
#include "stepper/explain.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <sstream>

#include "scene/messages.h"
#include "shading/color.h"
#include "shading/tonemap.h"
#include "stepper/format.h"
#include "stepper/views.h"
#include "raster/samples.h"

namespace prast::stepper {

using nlohmann::json;

const char* fate_name(TriangleFate f) {
    switch (f) {
    case TriangleFate::Invalid: return "invalid (non-finite position or index out of range)";
    case TriangleFate::CulledFrustum: return "culled (outside the frustum)";
    case TriangleFate::CulledBack: return "culled (back face)";
    case TriangleFate::Degenerate: return "degenerate (zero area or no pixel centre)";
    case TriangleFate::SetUp: return "set up";
    }
    return "?";
}

std::string mesh_name(const FrameSetup& s, const Recording& rec, std::uint32_t tri) {
    return s.scene.meshes[std::size_t(rec.draw_of(tri).mesh)].name;
}

namespace {

// Names come from the model: escaped, so they cannot drive the terminal.
std::string quoted(const std::string& s) { return "'" + printable(s) + "'"; }

} // namespace

std::string triangle_name(const FrameSetup& s, const Recording& rec, std::uint32_t tri) {
    const DrawRecord& d = rec.draw_of(tri);
    return "draw " + std::to_string(rec.draw_index(tri)) + " (mesh " + quoted(s.scene.meshes[std::size_t(d.mesh)].name) +
           ") triangle " + std::to_string(tri - d.first_triangle) + " (frame triangle " + std::to_string(tri) + ")";
}

std::string line_name(const FrameSetup& s, const Recording& rec, std::size_t draw, std::uint32_t prim) {
    const DrawRecord& d = rec.draws[draw];
    return "draw " + std::to_string(draw) + " (mesh " + quoted(s.scene.meshes[std::size_t(d.mesh)].name) + ") " +
           (d.topology == Topology::Points ? "point " : "line ") + std::to_string(prim);
}

bool frame_triangle(const Recording& rec, long draw, long prim, std::uint32_t& tri) {
    if (draw < 0 || std::size_t(draw) >= rec.draws.size() || prim < 0) return false;
    const DrawRecord& d = rec.draws[std::size_t(draw)];
    if (d.topology != Topology::Triangles || std::uint64_t(prim) >= d.triangle_count) return false;
    tri = d.first_triangle + std::uint32_t(prim);
    return true;
}

namespace {

json j3(const glm::vec3& v) { return json::array({v.x, v.y, v.z}); }

std::string plane_names(std::uint32_t planes) {
    static const struct { std::uint32_t bit; const char* name; } kNames[] = {
        {kOutLeft, "left"}, {kOutRight, "right"}, {kOutBottom, "bottom"}, {kOutTop, "top"},
        {kOutNear, "near"}, {kOutFar, "far"}, {kOutGuardLeft, "guard-left"},
        {kOutGuardRight, "guard-right"}, {kOutGuardBottom, "guard-bottom"}, {kOutGuardTop, "guard-top"}};
    std::string out;
    for (const auto& n : kNames)
        if (planes & n.bit) out += (out.empty() ? "" : ",") + std::string(n.name);
    return out.empty() ? "inside" : out;
}

// ---- Texture footprints: which texels a trilinear sample blended.

float reduce_wrap(Wrap w, float c) {
    switch (w) {
    case Wrap::Repeat: return texture_detail::reduce<Wrap::Repeat>(c);
    case Wrap::MirroredRepeat: return texture_detail::reduce<Wrap::MirroredRepeat>(c);
    case Wrap::ClampToEdge: break;
    }
    return texture_detail::reduce<Wrap::ClampToEdge>(c);
}

int wrap_texel(Wrap w, int i, int n) {
    switch (w) {
    case Wrap::Repeat: return texture_detail::wrap_index<Wrap::Repeat>(i, n);
    case Wrap::MirroredRepeat: return texture_detail::wrap_index<Wrap::MirroredRepeat>(i, n);
    case Wrap::ClampToEdge: break;
    }
    return texture_detail::wrap_index<Wrap::ClampToEdge>(i, n);
}

const char* wrap_name(Wrap w) {
    return w == Wrap::Repeat ? "repeat" : w == Wrap::MirroredRepeat ? "mirror" : "clamp";
}

const char* const kChannelNames[4] = {"R", "G", "B", "A"};

// The stored 15-bit codes of one 8-bit texel, per stored channel.
std::array<int, 4> texel_codes(const Texture& tex, int level, int x, int y) {
    const std::size_t i = tex.level_offset(level) + std::size_t(y) * std::size_t(tex.width(level)) + std::size_t(x);
    const std::uint8_t* p = tex.unorm8_data() + i * std::size_t(tex.channels());
    std::array<int, 4> c = {0, 0, 0, 0};
    for (int k = 0; k < tex.channels(); ++k) c[std::size_t(k)] = tex.code_table(k)[p[k]];
    return c;
}

// One level's bilinear footprint. 8-bit textures: the fixed-point steps of
// Texture::fix_bilinear() (shading/texture.h), with their integers, into
// `fixed` when given.
std::string level_footprint(const Texture& tex, glm::vec2 uv, int level, Texture::Fix4* fixed = nullptr) {
    using namespace texture_detail;
    const int w = tex.width(level), h = tex.height(level);
    const float x = reduce_wrap(tex.wrap_s(), uv.x) * float(w) - 0.5f;
    const float y = reduce_wrap(tex.wrap_t(), uv.y) * float(h) - 0.5f;
    const float fx = std::floor(x), fy = std::floor(y);
    const int x0 = int(fx), y0 = int(fy);
    const int xa = wrap_texel(tex.wrap_s(), x0, w), xb = wrap_texel(tex.wrap_s(), x0 + 1, w);
    const int ya = wrap_texel(tex.wrap_t(), y0, h), yb = wrap_texel(tex.wrap_t(), y0 + 1, h);
    std::string s = "level " + std::to_string(level) + " (" + std::to_string(w) + "x" + std::to_string(h) +
                    "): texels x " + std::to_string(xa) + "," + std::to_string(xb) + " y " + std::to_string(ya) +
                    "," + std::to_string(yb) + " weights " + num(x - fx) + ", " + num(y - fy);
    if (!tex.is_unorm8())
        return s + ": " + vec(tex.texel(level, xa, ya)) + " " + vec(tex.texel(level, xb, ya)) + " " +
               vec(tex.texel(level, xa, yb)) + " " + vec(tex.texel(level, xb, yb));
    const int wx = weight8(x - fx), wy = weight8(y - fy);
    s += " = " + std::to_string(wx) + "/256, " + std::to_string(wy) + "/256";
    const std::array<int, 4> a = texel_codes(tex, level, xa, ya), b = texel_codes(tex, level, xb, ya);
    const std::array<int, 4> c = texel_codes(tex, level, xa, yb), d = texel_codes(tex, level, xb, yb);
    for (int k = 0; k < tex.channels(); ++k) {
        const std::size_t i = std::size_t(k);
        const int top = narrow8(lerp8(a[i], b[i], wx)), bottom = narrow8(lerp8(c[i], d[i], wx));
        const int v = lerp8(top, bottom, wy);
        if (fixed) fixed->c[k] = v;
        s += std::string("; ") + kChannelNames[k] + " codes " + std::to_string(a[i]) + " " + std::to_string(b[i]) +
             " / " + std::to_string(c[i]) + " " + std::to_string(d[i]) + ", top " + std::to_string(top) +
             ", bottom " + std::to_string(bottom) + ", " + std::to_string(v);
    }
    return s;
}

const char* filter_name(Filter f) { return f == Filter::Nearest ? "NEAREST" : "LINEAR"; }

const char* min_filter_name(MinFilter f) {
    switch (f) {
    case MinFilter::Nearest: return "NEAREST";
    case MinFilter::Linear: return "LINEAR";
    case MinFilter::NearestMipmapNearest: return "NEAREST_MIPMAP_NEAREST";
    case MinFilter::LinearMipmapNearest: return "LINEAR_MIPMAP_NEAREST";
    case MinFilter::NearestMipmapLinear: return "NEAREST_MIPMAP_LINEAR";
    case MinFilter::LinearMipmapLinear: break;
    }
    return "LINEAR_MIPMAP_LINEAR";
}

} // namespace

std::string sampler_text(const Texture& tex) {
    const SamplerState& st = tex.sampler();
    return std::string("sampler: mag ") + filter_name(st.mag) + ", min " + min_filter_name(st.min) + ", wrap " +
           wrap_name(st.wrap_s) + "/" + wrap_name(st.wrap_t);
}

namespace {

// The NEAREST texel of one level: floor(u w), floor(v h), wrapped.
std::string nearest_footprint(const Texture& tex, glm::vec2 uv, int level, Texture::Fix4* fixed = nullptr) {
    const int w = tex.width(level), h = tex.height(level);
    const int x = int(std::floor(reduce_wrap(tex.wrap_s(), uv.x) * float(w)));
    const int y = int(std::floor(reduce_wrap(tex.wrap_t(), uv.y) * float(h)));
    const int xi = wrap_texel(tex.wrap_s(), x, w), yi = wrap_texel(tex.wrap_t(), y, h);
    std::string s = "level " + std::to_string(level) + " (" + std::to_string(w) + "x" + std::to_string(h) +
                    "): nearest texel x " + std::to_string(xi) + " y " + std::to_string(yi) + ": " +
                    vec(tex.texel(level, xi, yi));
    if (tex.is_unorm8()) {
        const std::array<int, 4> a = texel_codes(tex, level, xi, yi);
        for (int k = 0; k < tex.channels(); ++k) {
            if (fixed) fixed->c[k] = a[std::size_t(k)] * 256;
            s += std::string("; ") + kChannelNames[k] + " code " + std::to_string(a[std::size_t(k)]) + ", " +
                 std::to_string(a[std::size_t(k)] * 256);
        }
    }
    return s;
}

// One map: its size, UV set, sampler, the level of detail, the levels and
// texels the sampler's filters read (Texture::choose_level), the value.
std::string map_text(const char* name, const Texture* tex, int uv_set, glm::vec2 uv, float lambda,
                     const char* indent) {
    if (!tex) return "";
    std::string s = std::string(indent) + "map " + name + ": " + std::to_string(tex->width(0)) + "x" +
                    std::to_string(tex->height(0)) + ", " + std::to_string(tex->levels()) + " levels, UV set " +
                    std::to_string(uv_set) + " " + vec(uv) + ", " + sampler_text(*tex) + ", lambda " + num(lambda);
    const LevelChoice c = tex->choose_level(lambda);
    const SamplerState& st = tex->sampler();
    const char* filter = c.nearest ? "nearest" : "bilinear";
    const int last = tex->levels() - 1;
    // OpenGL's switch-over point (texture.h): 0.5 for LINEAR magnification
    // with NEAREST_MIPMAP_* minification, else 0.
    const float switch_c = st.mag == Filter::Linear && (st.min == MinFilter::NearestMipmapNearest ||
                                                        st.min == MinFilter::NearestMipmapLinear) ? 0.5f : 0.0f;
    const bool mipmap_linear = st.min == MinFilter::LinearMipmapLinear || st.min == MinFilter::NearestMipmapLinear;
    std::vector<int> levels = {c.level};
    if (!(lambda > switch_c)) {
        s += std::string(" (magnification: ") + filter + " on level 0)";
    } else if (mipmap_linear && lambda >= float(last)) {
        s += std::string(" (past the last level: ") + filter + " on level " + std::to_string(last) + ")";
    } else if (mipmap_linear) {
        s += std::string(" (") + (c.nearest ? "nearest, mipmap linear" : "trilinear") + ": levels " +
             std::to_string(c.level) + " and " + std::to_string(c.level + 1) + ", blend " + num(c.t) + ")";
        if (c.blend) levels.push_back(c.level + 1);
    } else {
        s += std::string(" (") + filter + " on level " + std::to_string(c.level) + ")";
    }
    s += "\n";
    Texture::Fix4 fixed[2];
    for (std::size_t i = 0; i < levels.size(); ++i) {
        const int L = levels[i];
        s += std::string(indent) + "  " +
             (c.nearest ? nearest_footprint(*tex, uv, L, &fixed[i]) : level_footprint(*tex, uv, L, &fixed[i])) + "\n";
    }
    if (tex->is_unorm8()) {
        // The fixed-point finish (shading/texture.h): the levels' blend, then
        // each channel / (32640 * 256).
        Texture::Fix4 f = fixed[0];
        if (levels.size() == 2) {
            using namespace texture_detail;
            const int wt = weight8(c.t);
            f = Texture::fix_blend(fixed[0], fixed[1], c.t);
            s += std::string(indent) + "  blend " + std::to_string(wt) + "/256:";
            for (int k = 0; k < tex->channels(); ++k)
                s += std::string(" ") + kChannelNames[k] + " " + std::to_string(narrow8(fixed[0].c[k])) + ", " +
                     std::to_string(narrow8(fixed[1].c[k])) + " -> " + std::to_string(f.c[k]) + ";";
            s += "\n";
        }
        s += std::string(indent) + "  fixed point / 8355840: " + vec(tex->fix_value(f)) + "\n";
    }
    s += std::string(indent) + "  sample " + vec(tex->sample_lod(uv.x, uv.y, lambda)) + "\n";
    return s;
}

const char* conductor_name(Conductor c) {
    switch (c) {
    case Conductor::Gold: return "gold";
    case Conductor::Copper: return "copper";
    case Conductor::Aluminium: return "aluminium";
    case Conductor::Silver: return "silver";
    case Conductor::None: break;
    }
    return "none";
}

glm::vec3 color_of(const Framebuffer& fb, int x, int y) {
    const float* c = fb.pixel(x, y);
    return glm::vec3(c[0], c[1], c[2]);
}

} // namespace

// ---------------------------------------------------------------- tile walk

TileWalk walk_tile(const Recording& rec, std::uint32_t piece, int tile) {
    TileWalk w;
    w.tile = tile;
    const PieceRecord& p = rec.pieces[piece];
    if (p.setup == kNone) return w;
    const TriangleSetup& t = rec.setups[p.setup];
    const int ts = rec.tile_size;
    const int tx0 = (tile % rec.tiles_x) * ts, ty0 = (tile / rec.tiles_x) * ts;
    const int tx1 = std::min(tx0 + ts, rec.width) - 1, ty1 = std::min(ty0 + ts, rec.height) - 1;
    const int x0 = std::max(tx0, t.minx), x1 = std::min(tx1, t.maxx);
    const int y0 = std::max(ty0, t.miny), y1 = std::min(ty1, t.maxy);
    const SamplePattern& sp = sample_pattern(rec.samples);
    const SampleExtent ext = sample_extent(sp);
    auto count_coverage = [&](int bx, int by, unsigned partial) {
        // A lane is covered when any of its samples is inside the partial edges.
        std::uint32_t mask = 0;
        for (int l = 0; l < kBlockLanes; ++l) {
            const int x = bx + lane_x(l), y = by + lane_y(l);
            if (x >= rec.width || y >= rec.height) continue;
            for (int smp = 0; smp < sp.count; ++smp) {
                bool in = true;
                for (int e = 0; e < 3; ++e)
                    if ((partial & (1u << e)) && edge_at_pixel(t, e, x, y) + std::int64_t(t.A[e]) * sp.fixed_x(smp) +
                                                         std::int64_t(t.B[e]) * sp.fixed_y(smp) < 0)
                        in = false;
                if (in) mask |= 1u << l;
            }
        }
        if (mask) ++w.fine_with_coverage;
    };
    if (x0 <= x1 && y0 <= y1) {
        // for_each_block() (rasterize.h): 16x16 blocks, then 4x4 blocks of the partial ones.
        for (int cy = y0 & ~(kCoarseBlockSize - 1); cy <= y1; cy += kCoarseBlockSize)
            for (int cx = x0 & ~(kCoarseBlockSize - 1); cx <= x1; cx += kCoarseBlockSize) {
                unsigned partial = 0;
                bool out = false;
                for (int e = 0; e < 3 && !out; ++e) {
                    const EdgeClass c = classify_block(t, e, cx, cy, kCoarseBlockSize, ext);
                    if (c == kEdgeOut) out = true;
                    else if (c == kEdgePartial) partial |= 1u << e;
                }
                if (out) { ++w.coarse_rejected; continue; }
                if (partial == 0) ++w.coarse_accepted;
                else ++w.coarse_partial;
                const int bx_lo = std::max(cx, x0 & ~(kBlockSize - 1)), bx_hi = std::min(cx + kCoarseBlockSize - 1, x1);
                const int by_lo = std::max(cy, y0 & ~(kBlockSize - 1)), by_hi = std::min(cy + kCoarseBlockSize - 1, y1);
                for (int by = by_lo; by <= by_hi; by += kBlockSize)
                    for (int bx = bx_lo; bx <= bx_hi; bx += kBlockSize) {
                        if (partial == 0) {
                            ++w.fine_accepted;
                            count_coverage(bx, by, 0);
                            continue;
                        }
                        unsigned block_partial = 0;
                        bool block_out = false;
                        for (int e = 0; e < 3 && !block_out; ++e) {
                            if (!(partial & (1u << e))) continue;
                            const EdgeClass c = classify_block(t, e, bx, by, kBlockSize, ext);
                            if (c == kEdgeOut) block_out = true;
                            else if (c == kEdgePartial) block_partial |= 1u << e;
                        }
                        if (block_out) { ++w.fine_rejected; continue; }
                        if (block_partial) ++w.fine_walked;
                        else ++w.fine_accepted;
                        count_coverage(bx, by, block_partial);
                    }
            }
    }
    for (const BlockRecord& b : rec.tiles[std::size_t(tile)].blocks) {
        if (b.piece != piece) continue;
        ++w.recorded_blocks;
        w.covered += __builtin_popcount(b.mask);
        w.passed += __builtin_popcount(b.pass);
        w.written += __builtin_popcount(b.live);
    }
    return w;
}

// ---------------------------------------------------------------- frame

std::string frame_text(const FrameSetup& s, const Recording& rec) {
    std::ostringstream o;
    const Camera& c = s.settings.camera;
    o << "frame " << rec.width << "x" << rec.height << ", tiles of " << rec.tile_size << " (" << rec.tiles_x << "x"
      << rec.tiles_y << "), " << rec.samples << " sample" << (rec.samples == 1 ? "" : "s") << " per pixel\n";
    o << "scene " << (s.request.scene.empty() ? "built-in" : s.request.scene) << ": " << rec.triangle_count()
      << " triangles, " << s.scene.meshes.size() << " meshes, " << s.scene.materials.size() << " materials\n";
    o << "camera eye " << vec(c.eye) << " target " << vec(c.target) << " up " << vec(c.up)
      << (c.orthographic ? " orthographic, half height " + num(c.ortho_ymag) : " fov " + num(c.fov_y_deg)) << " near "
      << num(c.near_plane) << " far " << (c.infinite_far ? std::string("infinite") : num(c.far_plane)) << "\n";
    for (std::size_t i = 0; i < s.settings.lights.size(); ++i) {
        const ShadingLight& L = s.settings.lights[i];
        o << "light " << i << ": "
          << (L.spot    ? "spot at " + vec(L.position) + " shining along " + vec(glm::vec3(0.0f) - L.direction)
              : L.point ? "point at " + vec(L.position)
                        : "sun towards " + vec(L.direction))
          << " radiance " << vec(L.radiance);
        // KHR_lights_punctual's cone and range factors, which light_at() applies.
        if (L.spot)
            o << " cone clamp(-l.axis * " << num(L.cone_scale) << " + " << num(L.cone_offset) << ", 0, 1)^2";
        if (L.point && L.range_inv2 > 0.0f) o << " range " << num(1.0f / std::sqrt(L.range_inv2));
        o << "\n";
    }
    // What lights the frame besides the lights: an environment (then the
    // ambient term is not used) or the ambient colour.
    const Environment* env = s.scene_renderer->environment(s.settings);
    if (env) {
        const std::string source = !s.request.env.empty() ? "file " + quoted(s.request.env)
                                   : s.request.scene.empty() ? std::string("built-in sky")
                                                             : std::string("the scene's own");
        o << "environment " << source << ", " << env->width() << "x" << env->height() << ", intensity "
          << num(s.request.env_intensity) << ", rotated " << num(s.request.env_rotate_deg)
          << " degrees: split sum (SH irradiance, " << Environment::kSpecularLevels
          << " GGX-prefiltered levels, a DFG table) in place of the ambient term\n";
        o << "brdf ";
    } else {
        o << "ambient " << vec(s.settings.ambient) << ", brdf ";
    }
    o << brdf_model_name(s.settings.model) << ", exposure " << num(s.exposure()) << ", tone map "
      << tonemap_name(s.tonemap()) << "\n";
    // Shadows: which lights cast, through which maps (shading/shadow/).
    if (!s.settings.shadows.enabled) {
        o << "shadows off\n";
    } else {
        const ShadingContext ctx = s.shading_context();
        o << "shadows on:";
        bool any = false;
        for (std::size_t i = 0; i < ctx.lights.size(); ++i) {
            const ShadowMap* m = ctx.lights[i].shadow;
            if (!m) continue;
            o << (any ? ";" : "") << " light " << i << " "
              << (m->cube ? "cube map, 6 faces of " : "directional map ") << m->size << "x" << m->size;
            any = true;
        }
        if (!any) o << " no light has a map (nothing casts)";
        o << "; bias " << num(kShadowConstantBias) << " + " << num(kShadowSlopeBias)
          << " tan(theta) texels, PCF 3x3 bilinear taps\n";
    }
    // The counters, without the times (those are for `cost`).
    std::istringstream stats(rec.stats.to_string());
    for (std::string l; std::getline(stats, l);)
        if (l.compare(0, 4, "time") != 0) o << l << "\n";
    std::size_t blocks = 0, depths = 0, bins = 0;
    for (const TileRecord& t : rec.tiles) {
        blocks += t.blocks.size();
        depths += t.z.size();
        bins += t.pieces.size();
    }
    o << "recording " << rec.bytes() << " bytes: " << rec.draws.size() << " draws, " << rec.triangles.size()
      << " triangles, " << rec.pieces.size() << " pieces, " << rec.setups.size() << " setups, " << bins
      << " bin entries, " << blocks << " blocks, " << depths << " depths\n";
    return o.str();
}

json frame_json(const FrameSetup& s, const Recording& rec) {
    json j;
    j["width"] = rec.width;
    j["height"] = rec.height;
    j["tile_size"] = rec.tile_size;
    j["samples"] = rec.samples;
    j["tiles_x"] = rec.tiles_x;
    j["tiles_y"] = rec.tiles_y;
    j["triangles"] = rec.triangle_count();
    j["draws"] = rec.draws.size();
    j["recording_bytes"] = rec.bytes();
    j["text"] = frame_text(s, rec);
    return j;
}

// ---------------------------------------------------------------- triangle

std::string triangle_text(const FrameSetup& s, const Recording& rec, std::uint32_t tri) {
    std::ostringstream o;
    const DrawRecord& d = rec.draw_of(tri);
    const TriangleRecord& tr = rec.triangles[tri];
    const BoundMaterial& bm = material_of(s, rec, tri);
    o << "tri " << tri << ": " << triangle_name(s, rec, tri) << ", " << d.triangle_count << " in the draw, mesh "
      << d.mesh << ", material " << quoted(bm.m->name) << ", cull " << (d.state.cull == CullMode::Back ? "back" : "none")
      << (d.varyings == kPbrVaryingsExt ? ", " + std::to_string(d.varyings) + " varyings (vertex colours or UV set 1)"
                                        : std::string())
      << "\n";
    if (!tr.seen) {
        o << "  not submitted\n";
        return o.str();
    }
    const ClipReplay c = replay_clip(s, rec, tri);
    o << "  vertices " << c.index[0] << " " << c.index[1] << " " << c.index[2] << "\n";
    if (!c.valid) {
        o << "  fate: " << fate_name(tr.fate) << "\n";
        return o.str();
    }
    for (int i = 0; i < 3; ++i) {
        const float* v = &d.vertices[std::size_t(c.index[i]) * kStride];
        o << "  clip v" << i << " " << vec(glm::vec4(v[0], v[1], v[2], v[3])) << " outside: " << plane_names(c.outcode[i])
          << "\n";
    }
    if (tr.clipped) {
        o << "  clipping: against " << plane_names(c.planes) << " -> polygon of " << c.count << " vertices, "
          << std::max(0, c.count - 2) << " pieces (a fan from vertex 0)\n";
        for (int i = 0; i < c.count; ++i)
            o << "    p" << i << " " << vec(glm::vec4(c.polygon[i][0], c.polygon[i][1], c.polygon[i][2], c.polygon[i][3]))
              << "\n";
    } else {
        o << "  clipping: none needed" << ((c.outcode[0] & c.outcode[1] & c.outcode[2] & kFrustumBits)
                                               ? " (all three vertices outside one frustum plane)" : "")
          << "\n";
    }
    o << "  fate: " << fate_name(tr.fate) << "\n";
    for (std::uint32_t k = 0; k < tr.piece_count; ++k) {
        const std::uint32_t pi = tr.first_piece + k;
        const PieceRecord& p = rec.pieces[pi];
        o << "  piece " << k << ": " << fate_name(p.fate);
        if (p.setup == kNone) {
            o << "\n";
            continue;
        }
        const TriangleSetup& t = rec.setups[p.setup];
        o << ", " << (t.front_facing ? "front" : "back") << " face\n";
        float v[3][kStride];
        piece_vertices(s, rec, pi, v);
        SnappedVertex sv[3];
        o << "    window vertices (setup order, snapped to 1/256 px):\n";
        for (int i = 0; i < 3; ++i) {
            sv[i] = snap_vertex(v[i], rec.width, rec.height);
            o << "      v" << i << " (" << num(sv[i].x_win) << ", " << num(sv[i].y_win) << ") -> fixed (" << sv[i].fx
              << ", " << sv[i].fy << ") = (" << num(double(sv[i].fx) / 256.0) << ", " << num(double(sv[i].fy) / 256.0)
              << ") px, z " << num(t.z[i]) << ", 1/w " << num(t.inv_w[i]) << "\n";
        }
        o << "    edges E(x, y) = A x + B y + C at pixel centres (1/256 px), inside when E >= 0:\n";
        bool consistent = true;
        for (int e = 0; e < 3; ++e) {
            const int a = (e + 1) % 3, b = (e + 2) % 3;
            const bool top = t.A[e] == 0 && t.B[e] > 0, left = t.A[e] > 0;
            consistent &= std::int64_t(t.A[e]) == sv[a].fy - sv[b].fy && std::int64_t(t.B[e]) == sv[b].fx - sv[a].fx;
            o << "      e" << e << " (v" << a << " -> v" << b << "): A " << t.A[e] << " B " << t.B[e] << " C " << t.C[e]
              << (top ? "  top edge: no bias" : left ? "  left edge: no bias"
                                                     : "  neither top nor left: C includes the -1 bias")
              << "\n";
        }
        if (!consistent) o << "    NOTE: the snapped vertices above do not reproduce A and B\n";
        if (rec.samples > 1)
            o << "    " << rec.samples << " samples per pixel: sample s at (dx, dy) 1/256 px from the centre tests E + A dx + "
                 "B dy >= 0 (dx, dy multiples of 16)\n";
        const std::int64_t area2 = (sv[1].fx - sv[0].fx) * (sv[2].fy - sv[0].fy) - (sv[2].fx - sv[0].fx) * (sv[1].fy - sv[0].fy);
        o << "    area " << num(double(area2 < 0 ? -area2 : area2) / (2.0 * 65536.0)) << " px (2 x area = " << area2
          << " in 1/65536 px^2)\n";
        o << "    box x " << t.minx << ".." << t.maxx << " y " << t.miny << ".." << t.maxy << "\n";
        o << "    barycentric planes at the pixel centre (" << t.ax << ", " << t.ay << "): b0 " << num(t.bary[0][0]) << " + " << num(t.bary[0][1])
          << " dx + " << num(t.bary[0][2]) << " dy; b1 " << num(t.bary[1][0]) << " + " << num(t.bary[1][1]) << " dx + "
          << num(t.bary[1][2]) << " dy; b2 " << num(t.bary[2][0]) << " + " << num(t.bary[2][1]) << " dx + "
          << num(t.bary[2][2]) << " dy\n";
        o << "    binned to " << p.tile_count << " tile" << (p.tile_count == 1 ? "" : "s") << ":\n";
        for (std::uint32_t i = 0; i < p.tile_count; ++i) {
            const int tile = int(rec.piece_tiles[p.first_tile + i]);
            const TileWalk w = walk_tile(rec, pi, tile);
            o << "      tile " << tile % rec.tiles_x << " " << tile / rec.tiles_x << ": 16x16 blocks "
              << w.coarse_rejected << " rejected, " << w.coarse_accepted << " accepted, " << w.coarse_partial
              << " partial; 4x4 blocks " << w.fine_rejected << " rejected, " << w.fine_accepted << " accepted, "
              << w.fine_walked << " walked; " << w.recorded_blocks << " blocks with coverage, " << w.covered
              << " fragments, " << w.passed << " passed depth, " << w.written << " written\n";
            if (w.fine_with_coverage != w.recorded_blocks)
                o << "      NOTE: the walk finds " << w.fine_with_coverage << " covered blocks, the recording "
                  << w.recorded_blocks << "\n";
        }
    }
    return o.str();
}

json triangle_json(const FrameSetup& s, const Recording& rec, std::uint32_t tri) {
    json j;
    const TriangleRecord& tr = rec.triangles[tri];
    j["tri"] = tri;
    j["fate"] = fate_name(tr.fate);
    j["clipped"] = tr.clipped;
    json pieces = json::array();
    for (std::uint32_t k = 0; k < tr.piece_count; ++k) {
        const PieceRecord& p = rec.pieces[tr.first_piece + k];
        json pj;
        pj["fate"] = fate_name(p.fate);
        if (p.setup != kNone) {
            float v[3][kStride];
            piece_vertices(s, rec, tr.first_piece + k, v);
            json verts = json::array();
            for (int i = 0; i < 3; ++i) {
                const SnappedVertex sv = snap_vertex(v[i], rec.width, rec.height);
                verts.push_back(json::array({double(sv.fx) / 256.0, double(sv.fy) / 256.0}));
            }
            pj["window"] = verts;
            const TriangleSetup& t = rec.setups[p.setup];
            pj["box"] = json::array({t.minx, t.miny, t.maxx, t.maxy});
            json tiles = json::array();
            for (std::uint32_t i = 0; i < p.tile_count; ++i) tiles.push_back(rec.piece_tiles[p.first_tile + i]);
            pj["tiles"] = tiles;
        }
        pieces.push_back(pj);
    }
    j["pieces"] = pieces;
    j["text"] = triangle_text(s, rec, tri);
    return j;
}

// ---------------------------------------------------------------- tile

std::string tile_text(const FrameSetup& s, const Recording& rec, int tx, int ty) {
    TileView v;
    make_tile(s, rec, {std::to_string(tx), std::to_string(ty)}, v);
    return v.text();
}

json tile_json(const FrameSetup& s, const Recording& rec, int tx, int ty) {
    TileView v;
    make_tile(s, rec, {std::to_string(tx), std::to_string(ty)}, v);
    return v.json();
}

// ---------------------------------------------------------------- pixel

glm::vec3 resolve_average(const glm::vec3* colors, int samples) {
    glm::vec3 out(0.0f);
    const float inv = 1.0f / float(samples);
    for (int ch = 0; ch < 3; ++ch) {
        float v[kMaxSamples] = {};
        for (int i = 0; i < samples; ++i) v[i] = colors[i][ch];
        for (int n = samples; n > 1; n /= 2)
            for (int i = 0; i < n / 2; ++i) v[i] = v[2 * i] + v[2 * i + 1];
        out[ch] = v[0] * inv;
    }
    return out;
}

PixelExplanation explain_pixel(const FrameSetup& s, const Recording& rec, int x, int y, std::uint64_t upto,
                               const Framebuffer* frame) {
    PixelExplanation px;
    px.x = x;
    px.y = y;
    px.samples = rec.samples;
    px.upto = upto >= rec.triangle_count() ? kAllTriangles : upto;
    const bool all = px.upto == kAllTriangles;
    const int S = rec.samples;
    const ShadingContext ctx = s.shading_context();
    const TileRecord& tile = rec.tiles[std::size_t(rec.tile_of(x, y))];
    const int bx = x & ~(kBlockSize - 1), by = y & ~(kBlockSize - 1);
    for (int l = 0; l < kBlockLanes; ++l)
        if (lane_x(l) == x - bx && lane_y(l) == y - by) px.lane = l;
    const int lane = px.lane;
    // The tile pass, sample by sample: cleared (to the background), then each
    // fragment in the tile's order. A draw taking the visibility pass writes
    // depth and makes the fragment the sample's winner (`pending`), shaded
    // once later; a draw shaded in order writes its colour at once.
    px.background = s.background(rec.fb.width, rec.fb.height).at(x, y);
    for (int i = 0; i < S; ++i) {
        px.sample_depth[i] = 1.0f;
        px.sample_color[i] = px.background;
        px.sample_owner[i] = -1;
    }
    int pending[kMaxSamples];
    for (int i = 0; i < S; ++i) pending[i] = -1;
    int blends = 0;
    // A fragment's effect on the samples, once its tests and shading are known.
    auto account = [&](HistoryEntry& h, const DrawRecord& d) {
        const int index = int(px.history.size());
        const bool blend = d.state.blend == Blend::Alpha && h.written && h.pass;
        if (blend) {
            h.blend_order = ++blends;
            h.alpha = h.shading.ms.alpha;
            // A blending draw reads the colour: the visibility pass's winners
            // so far are shaded first (raster/frame.h).
            for (int i = 0; i < S; ++i) {
                if (pending[i] < 0 || !((h.pass >> i) & 1u)) continue;
                const HistoryEntry& w = px.history[std::size_t(pending[i])];
                px.sample_owner[i] = pending[i];
                px.sample_color[i] = w.written ? w.shading.Lo : glm::vec3(0.0f);
                pending[i] = -1;
            }
        }
        for (int i = 0; i < S; ++i) {
            if (!((h.pass >> i) & 1u)) continue;
            if (h.visible) {
                px.sample_depth[i] = h.z[i];
                pending[i] = index;
            } else if (h.written) {
                if (d.state.depth_write) px.sample_depth[i] = h.z[i];
                if (blend) {
                    // raster/shade.h write_color(), Blend::Alpha: out * a + dst * (1 - a).
                    const float a = h.alpha, keep = 1.0f - a;
                    const glm::vec3 src = h.shading.Lo, dst = px.sample_color[i];
                    px.sample_color[i] = glm::vec3(src.r * a + dst.r * keep, src.g * a + dst.g * keep,
                                                   src.b * a + dst.b * keep);
                    h.blended[i] = px.sample_color[i];
                } else {
                    px.sample_color[i] = h.shading.Lo;
                }
                px.sample_owner[i] = index;
                pending[i] = -1;
            }
        }
        px.history.push_back(std::move(h));
    };
    // The lines and points of draw `di` covering the pixel, in order
    // (line_raster.h: every sample covered at the pixel's depth, always
    // shaded in order).
    auto line_draw = [&](std::size_t di) {
        const DrawRecord& d = rec.draws[di];
        for (std::uint32_t prim = 0; prim < d.primitives; ++prim) {
            const LineReplay l = replay_line(s, rec, di, prim);
            if (!l.drawn || !line_covers(l.setup, x, y)) continue;
            HistoryEntry h;
            h.line_draw = int(di);
            h.line_prim = prim;
            h.line = l;
            h.lane = lane;
            LineFragment f;
            replay_line_fragment(s, rec, di, l, x, y, f);
            h.line_t = f.t;
            h.line_w1 = f.w1;
            h.replay = f.block;
            for (int i = 0; i < S; ++i) {
                h.cover |= 1u << i;
                h.z[i] = f.z;
                h.depth_before[i] = px.sample_depth[i];
                if (!d.state.depth_test || f.z < px.sample_depth[i]) h.pass |= 1u << i;
            }
            if (h.pass) {
                h.shaded = true;
                h.shading = shade_lane(ctx, draw_material(s, d), h.replay, lane);
                h.killed = h.shading.killed;
                h.written = !h.killed;
            }
            account(h, d);
        }
    };
    std::size_t next_draw = 0;  // line draws before it are done
    auto lines_before = [&](std::size_t di) {
        for (; next_draw < di && next_draw < rec.draws.size(); ++next_draw)
            if (rec.draws[next_draw].topology != Topology::Triangles &&
                (all || rec.draws[next_draw].first_triangle < px.upto))  // SceneRenderer's limit
                line_draw(next_draw);
    };
    for (const BlockRecord& b : tile.blocks) {
        if (b.bx != bx || b.by != by || !(b.mask & (1u << lane))) continue;
        const std::uint32_t tri = rec.pieces[b.piece].triangle;
        if (tri >= px.upto) continue;
        HistoryEntry h;
        h.piece = b.piece;
        h.lane = lane;
        h.block = &b;
        const DrawRecord& d = rec.draw_of(tri);
        lines_before(rec.draw_index(tri));
        h.visible = d.visible;
        for (int i = 0; i < S; ++i) {
            if (!((rec.cover(tile, b, i) >> lane) & 1u)) continue;
            h.cover |= 1u << i;
            h.z[i] = rec.depth(tile, b, i, lane);
            h.depth_before[i] = px.sample_depth[i];
            if ((rec.pass(tile, b, i) >> lane) & 1u) h.pass |= 1u << i;
        }
        h.shaded = (b.shaded >> lane) & 1u;
        h.written = (b.live >> lane) & 1u;
        h.killed = h.shaded && !h.written;
        replay_block(s, rec, b, h.replay);
        if (h.shaded) h.shading = shade_lane(ctx, material_of(s, rec, tri), h.replay, lane);
        account(h, d);
    }
    lines_before(rec.draws.size());
    // The visibility pass's winners, shaded once per pixel: their colour.
    for (int i = 0; i < S; ++i) {
        if (pending[i] < 0) continue;
        HistoryEntry& w = px.history[std::size_t(pending[i])];
        if (!all && !w.shaded) {
            // A winner at this point that a later triangle beat by the
            // frame's end: shaded here as draw_upto's frame shades it (the
            // lane among those the shader runs for, which decides its centroid).
            BlockRecord b = *w.block;
            b.shaded = std::uint16_t(b.shaded | (1u << lane));
            replay_block(s, rec, b, w.replay);
            w.shading = shade_lane(ctx, material_of(s, rec, rec.pieces[b.piece].triangle), w.replay, lane);
            w.shaded = true;
            w.killed = w.shading.killed;
            w.written = !w.killed;
        }
        px.sample_owner[i] = pending[i];
        px.sample_color[i] = w.written ? w.shading.Lo : glm::vec3(0.0f);
    }
    for (int i = 0; i < S; ++i)
        if (px.sample_owner[i] >= 0) px.history[std::size_t(px.sample_owner[i])].owns |= 1u << i;
    for (int k = 0; k < int(px.history.size()); ++k)
        if (px.history[std::size_t(k)].owns) px.contributors.push_back(k);
    std::stable_sort(px.contributors.begin(), px.contributors.end(), [&](int a, int b) {
        return __builtin_popcount(px.history[std::size_t(a)].owns) > __builtin_popcount(px.history[std::size_t(b)].owns);
    });

    // The resolve (the samples' average), then docs/conventions.md "Output".
    px.linear = resolve_average(px.sample_color, S);
    px.framebuffer = all || !frame ? color_of(rec.fb, x, y) : color_of(*frame, x, y);
    px.exposed = px.linear * s.exposure();
    px.toned = tonemap(px.exposed, s.tonemap());
    const float rgba[4] = {px.linear.r, px.linear.g, px.linear.b, 1.0f};
    std::uint8_t out[4];
    resolve_to_srgb8(rgba, 1, 1, s.exposure(), s.tonemap(), out);
    std::memcpy(px.srgb8, out, 3);
    return px;
}

namespace {

// "base colour = factor (..) x texture(UV set n, sampler: ...) (..) x vertex colour (..) = (..)"
std::string base_colour_text(const BoundMaterial& bm, const glm::vec4& texture, bool has_color, const glm::vec4& color,
                             const glm::vec4& result) {
    std::string t = "base colour = factor " + vec(bm.m->base_color_factor);
    if (bm.base_color)
        t += " x texture(UV set " + std::to_string(int(bm.uv.base_color)) + ", " + sampler_text(*bm.base_color) +
             ") " + vec(texture);
    if (has_color) t += " x vertex colour " + vec(color);
    return t + " = " + vec(result);
}

void shading_text(std::ostringstream& o, const FrameSetup& s, const Recording& rec, const HistoryEntry& h) {
    const BoundMaterial& bm = h.line_draw >= 0 ? draw_material(s, rec.draws[std::size_t(h.line_draw)])
                                               : material_of(s, rec, rec.pieces[h.piece].triangle);
    const Material& m = *bm.m;
    const LaneShading& sh = h.shading;
    const MaterialSample& ms = sh.ms;
    const SurfacePoint& sp = sh.sp;
    if (sh.unlit) {
        // UnlitProgram (renderer/scene_renderer.h): no lights, no environment.
        o << "  unlit (a line or point without normals, drawn as glTF asks): zero derivatives, textures read "
             "their finest level\n";
        o << "  uv " << vec(sp.uv) << " (UV set " << int(bm.uv.base_color) << ")\n";
        o << "  vertex colour " << vec(sh.unlit_color) << (s.scene.meshes[std::size_t(rec.draws[std::size_t(h.line_draw)].mesh)].colors.empty()
                                                                ? " (the mesh has none: white)" : " (COLOR_0, interpolated)")
          << "\n";
        o << map_text("base_color", bm.base_color, bm.uv.base_color, sp.uv, 0.0f, "  ");
        o << "  " << base_colour_text(bm, sh.unlit_texture, true, sh.unlit_color,
                                      m.base_color_factor * sh.unlit_color * sh.unlit_texture) << "\n";
        o << "  alpha " << num(ms.alpha);
        if (m.alpha_mode == AlphaMode::Mask) o << " (mask cutoff " << num(m.alpha_cutoff) << ")";
        else if (m.alpha_mode == AlphaMode::Blend) o << " (the blend weight)";
        o << "\n  shaded colour (unlit: the base colour's rgb) " << vec(sh.Lo) << "\n";
        if (!sh.matches_shade_surface) o << "  NOTE: UnlitProgram::fragment() gives a different value\n";
        return;
    }
    o << "  geometric normal " << vec(ms.N_geom) << (sp.front_facing ? "" : " (back face: flipped)") << "\n";
    o << "  uv " << vec(sp.uv) << ", d(uv)/dx " << vec(sp.duv_dx) << ", d(uv)/dy " << vec(sp.duv_dy)
      << (h.line_draw >= 0 ? " (a line or point: zero derivatives)" : " (per 2x2 quad)") << "\n";
    if (h.replay.varyings == kPbrVaryingsExt)
        for (int set = 1; set < kMaxUvSets; ++set)
            o << "  uv set " << set << " " << vec(sp.uv_of(set)) << ", d/dx " << vec(sp.duv_dx_of(set)) << ", d/dy "
              << vec(sp.duv_dy_of(set)) << "\n";
    if (sp.has_color) o << "  vertex colour (COLOR_0, interpolated) " << vec(sp.color) << "\n";
    if (bm.normal) {
        const glm::vec3 N = glm::normalize(sp.N);
        glm::vec3 T = glm::vec3(sp.T);
        T = T - N * glm::dot(N, T);
        const float len2 = glm::dot(T, T);
        if (len2 > 1e-20f) {
            T = T / std::sqrt(len2);
            const float w = sp.T.w < 0.0f ? -1.0f : 1.0f;
            const glm::vec3 B = glm::cross(N, T) * w;
            o << "  tangent T " << vec(T) << " (w " << num(w) << "), bitangent B = cross(N, T) w " << vec(B) << "\n";
        }
        const glm::vec2 nuv = sp.uv_of(bm.uv.normal);
        o << map_text("normal", bm.normal, bm.uv.normal, nuv, sh.lods.normal, "  ");
        const glm::vec4 tx = bm.normal->sample_lod(nuv.x, nuv.y, sh.lods.normal);
        o << "  normal-map texel " << vec(glm::vec3(tx)) << " -> tangent space " << vec(glm::vec3(tx) * 2.0f - 1.0f)
          << " (scale " << num(m.normal_scale) << ")\n";
    }
    o << "  mapped normal n " << vec(ms.N) << "\n";
    auto map = [&](const char* name, const Texture* tex, int set, float lambda) {
        o << map_text(name, tex, set, sp.uv_of(set), lambda, "  ");
    };
    map("base_color", bm.base_color, bm.uv.base_color, sh.lods.base_color);
    map("metallic_roughness", bm.metallic_roughness, bm.uv.metallic_roughness, sh.lods.metallic_roughness);
    map("roughness", bm.roughness, bm.uv.roughness, sh.lods.roughness);
    map("metallic", bm.metallic, bm.uv.metallic, sh.lods.metallic);
    map("occlusion", bm.occlusion, bm.uv.occlusion, sh.lods.occlusion);
    map("emissive", bm.emissive, bm.uv.emissive, sh.lods.emissive);
    {
        static const char* const kExtNames[BoundMaterial::kExtMaps] = {
            "specularTexture", "specularColorTexture", "clearcoatTexture", "clearcoatRoughnessTexture",
            "clearcoatNormalTexture", "sheenColorTexture", "sheenRoughnessTexture", "transmissionTexture",
            "thicknessTexture"};
        for (int i = 0; i < BoundMaterial::kExtMaps; ++i) {
            if (!bm.ext[i]) continue;
            glm::vec2 uv = sp.uv_of(bm.ext_uv[i]);
            if (const UvTransform* x = bm.ext_transform_of(i)) uv = x->apply(uv);
            o << map_text(kExtNames[i], bm.ext[i], bm.ext_uv[i], uv, sh.lods.ext[i], "  ");
        }
    }
    if (bm.base_color || sp.has_color) {
        const glm::vec2 buv = sp.uv_of(bm.uv.base_color);
        const glm::vec4 tex = bm.base_color ? bm.base_color->sample_lod(buv.x, buv.y, sh.lods.base_color) : glm::vec4(1.0f);
        o << "  " << base_colour_text(bm, tex, sp.has_color, sp.color, glm::vec4(ms.albedo, ms.alpha)) << "\n";
    }
    const float r = glm::clamp(ms.roughness, kMinPerceptualRoughness, 1.0f);
    o << "  albedo " << vec(ms.albedo) << ", alpha " << num(ms.alpha);
    if (m.alpha_mode == AlphaMode::Mask) o << " (mask cutoff " << num(m.alpha_cutoff) << ")";
    o << "\n  roughness " << num(ms.roughness) << " (clamped " << num(r) << ", alpha r^2 " << num(r * r)
      << "), metallic " << num(ms.metallic) << ", occlusion " << num(ms.occlusion) << "\n";
    if (ms.conductor != Conductor::None) {
        const ConductorIOR c = conductor_ior(ms.conductor);
        o << "  conductor " << conductor_name(ms.conductor) << ": eta " << vec(c.eta) << " k " << vec(c.k) << "\n";
    } else if (ms.has_specular) {
        o << "  KHR_materials_specular: specular " << num(ms.specular) << ", colour " << vec(ms.specular_color)
          << "; F0 = mix(min(F0(ior " << num(ms.ior) << ") " << num(f0_from_ior(ms.ior))
          << " x colour, 1) x specular, albedo, metallic) = " << vec(brdf_f0(sh.inputs))
          << ", F90 = mix(specular, 1, metallic) = " << num(brdf_f90(sh.inputs)) << "\n";
    } else {
        o << "  F0 " << vec(glm::mix(glm::vec3(f0_from_ior(ms.ior)), ms.albedo, ms.metallic)) << " (ior "
          << num(ms.ior) << ")\n";
    }
    if (sh.inputs.clearcoat > 0.0f) {
        const float rc = glm::clamp(ms.clearcoat_roughness, kMinPerceptualRoughness, 1.0f);
        o << "  KHR_materials_clearcoat: clearcoat " << num(ms.clearcoat) << ", roughness "
          << num(ms.clearcoat_roughness) << " (clamped " << num(rc) << ", alpha " << num(rc * rc)
          << "), coat normal n_c " << vec(sh.inputs.clearcoat_n)
          << (bm.ext[BoundMaterial::kClearcoatNormal] ? " (its own normal map, scale " + num(m.clearcoat_normal_scale) + ")"
                                                       : std::string(" (the geometric normal)"))
          << ", F0 0.04\n";
    }
    if (sh.inputs.has_sheen()) {
        const float rs = glm::clamp(ms.sheen_roughness, kMinPerceptualRoughness, 1.0f);
        o << "  KHR_materials_sheen: colour " << vec(ms.sheen_color) << ", roughness " << num(ms.sheen_roughness)
          << " (clamped " << num(rs) << ", alpha " << num(rs * rs) << "), Charlie D and V, albedo E(n.v) "
          << num(sheen_albedo(glm::clamp(glm::dot(sh.inputs.n, sh.inputs.v), 0.0f, 1.0f), rs)) << "\n";
    }
    if (sh.inputs.transmission > 0.0f) {
        const float rt = glm::clamp(sh.inputs.transmission_roughness, kMinPerceptualRoughness, 1.0f);
        o << "  KHR_materials_transmission: transmission " << num(ms.transmission)
          << " (the diffuse times 1 - transmission), roughness r clamp(2 ior - 2, 0, 1) "
          << num(sh.inputs.transmission_roughness) << " (clamped " << num(rt) << ")";
        if (ms.thickness > 0.0f)
            o << "; KHR_materials_volume: thickness " << num(ms.thickness) << ", attenuation colour "
              << vec(ms.attenuation_color) << " at distance "
              << (ms.attenuation_distance > 0.0f ? num(ms.attenuation_distance) : std::string("infinite"));
        else
            o << ", thin-walled";
        o << " -> transmittance colour^(thickness / distance) " << vec(sh.inputs.transmittance) << "\n";
    }
    o << "  v " << vec(sh.inputs.v) << " (towards the eye " << vec(s.settings.camera.eye) << " from P " << vec(sp.P)
      << ")\n";
    for (std::size_t i = 0; i < sh.lights.size(); ++i) {
        const LightStep& L = sh.lights[i];
        const ShadingLight& src = s.settings.lights[i];
        const BrdfTerms& t = L.terms;
        o << "  light " << i << " (" << (src.point ? "point" : "sun") << "): l " << vec(L.l) << " radiance "
          << vec(L.radiance) << (L.shadowed ? " (times the shadow's visibility)" : "") << "\n";
        if (L.shadowed) {
            const ShadowTap& tp = L.shadow.tap;
            o << "    shadow map: " << (src.point ? "cube face " + std::to_string(tp.face) + " " : std::string())
              << "texel (" << num(tp.u) << ", " << num(tp.v) << "), distance to the light " << num(tp.receiver)
              << ", map depth " << (tp.inside ? num(L.shadow.map_distance) : std::string("(outside the map: lit)"))
              << ", bias " << num(tp.bias) << "\n";
            o << "    PCF: 3x3 bilinear taps (4x4 texels, weights 1-f,1,1,f; f " << num(tp.fx) << ", " << num(tp.fy)
              << "), lit where depth >= " << num(tp.threshold) << ": visibility " << num(L.shadow.visibility) << "\n";
        }
        o << "    h " << vec(L.h) << "  n.l " << num(t.NoL) << "  n.v " << num(t.NoV) << "  n.h " << num(t.NoH)
          << "  v.h " << num(t.VoH) << "\n";
        o << "    D " << num(t.D) << "  " << (s.settings.model == BrdfModel::Gltf ? "V " : "G ") << num(t.G) << "  F "
          << vec(t.F) << "  kd " << vec(t.kd) << "\n";
        if (t.sheen)
            o << "    sheen: D " << num(t.sheen_D) << "  V " << num(t.sheen_V) << " -> colour D V " << vec(t.sheen_f)
              << (t.coat ? " (times the coat's attenuation)" : "") << "; the base beneath times min(1 - max(colour) "
              << "E(n.v), 1 - max(colour) E(n.l)) = " << num(t.sheen_scaling) << "\n";
        o << "    diffuse " << vec(t.diffuse) << "  specular " << vec(t.specular)
          << (t.coat ? "  (both times the coat's 1 - clearcoat F_coat = " + num(t.coat_attenuation) + ")" : std::string())
          << "\n";
        if (t.transmission)
            o << "    transmission: " << (t.tr_NoL > 0.0f ? std::string("the light is behind: l mirrored through the "
                                                                    "surface, n.l' ")
                                                      : std::string("the light is in front: n.l' "))
              << num(t.tr_NoL) << "  n.h_t " << num(t.tr_NoH) << "  v.h_t " << num(t.tr_VoH) << "  D " << num(t.tr_D)
              << "  " << (s.settings.model == BrdfModel::Gltf ? "V " : "G ") << num(t.tr_G) << "  F " << vec(t.tr_F)
              << " -> transmission (1 - metallic) (1 - F) albedo D " << (s.settings.model == BrdfModel::Gltf ? "V" : "G / (4 n.v n.l')")
              << " transmittance " << vec(t.tr_f) << ", times radiance * n.l'\n";
        if (t.coat) {
            o << "    clear coat: n_c.l " << num(t.coat_NoL) << "  n_c.v " << num(t.coat_NoV) << "  n_c.h "
              << num(t.coat_NoH) << "  D " << num(t.coat_D) << "  " << (s.settings.model == BrdfModel::Gltf ? "V " : "G ")
              << num(t.coat_G) << "  F_coat(n_c.v) " << num(t.coat_F) << " -> coat lobe clearcoat F_coat D "
              << (s.settings.model == BrdfModel::Gltf ? "V " : "G / (4 n_c.v n_c.l) ") << num(t.coat_specular) << "\n";
            o << "    contribution (diffuse + specular) * radiance * n.l + coat * radiance * n_c.l"
              << (t.transmission ? " + transmission * radiance * n.l'" : "") << " = " << vec(L.contribution) << "\n";
        } else {
            o << "    contribution (diffuse + specular) * radiance * n.l"
              << (t.transmission ? " + transmission * radiance * n.l'" : "") << " = " << vec(L.contribution) << "\n";
        }
    }
    o << "  emissive " << vec(ms.emissive);
    if (sh.inputs.clearcoat > 0.0f)
        o << " x (1 - clearcoat F_coat(n_c.v)) = " << vec(coated_emission(ms, sh.inputs)) << " (under the coat)";
    o << "\n";
    if (sh.ibl) {
        const IblTerms& t = sh.ibl_terms;
        o << "  environment (split sum): irradiance E(n)/pi " << vec(t.irradiance) << ", kd " << vec(t.kd)
          << " -> diffuse " << vec(t.diffuse) << "\n";
        o << "    prefiltered " << vec(t.prefiltered) << " along " << vec(t.R) << " at level " << num(t.level)
          << ", dfg scale " << num(t.dfg_scale) << " bias " << num(t.dfg_bias) << " (n.v " << num(t.NoV)
          << ") -> specular " << vec(t.specular) << "\n";
        if (ms.has_specular) o << "    KHR_materials_specular: specular albedo F0 A + F90 B with F90 " << num(t.F90) << "\n";
        if (t.transmission)
            o << "    transmission: prefiltered " << vec(t.tr_prefiltered) << " along " << vec(t.tr_dir)
              << (ms.thickness > 0.0f ? " (refracted through the volume)" : " (straight through, -v)") << " at level "
              << num(t.tr_level) << ", transmittance " << vec(t.tr_transmittance) << (s.settings.energy ? ", lobe albedo 1 - specular albedo " : ", lobe albedo (1 - F0) A + (1 - F90) B ")
              << vec(t.tr_albedo) << " -> transmission (1 - metallic) lobe albedo x albedo prefiltered transmittance occlusion "
              << vec(t.tr_specular) << "; diffuse above times 1 - transmission\n";
        if (t.sheen)
            o << "    sheen: irradiance E(n)/pi " << vec(t.sheen_irradiance) << ", E(n.v) " << num(t.sheen_E)
              << " -> colour E irradiance occlusion "
              << vec(t.sheen_specular) << "; diffuse and specular above times 1 - max(colour) E = "
              << num(t.sheen_scaling) << "\n";
        if (t.coat) {
            o << "    clear coat: prefiltered " << vec(t.coat_prefiltered) << " along " << vec(t.coat_R) << " at level "
              << num(t.coat_level) << ", dfg scale " << num(t.coat_dfg_scale) << " bias " << num(t.coat_dfg_bias)
              << " (n_c.v " << num(t.coat_NoV) << "), F_coat " << num(t.coat_F)
              << " -> coat clearcoat F_coat (A + B) prefiltered occlusion " << vec(t.coat_specular)
              << "; diffuse and specular above times 1 - clearcoat F_coat = " << num(t.coat_attenuation) << "\n";
            o << "    occlusion " << num(t.occlusion) << "; diffuse + specular" << (t.sheen ? " + sheen" : "")
              << " + coat" << (t.transmission ? " + transmission" : "") << " = " << vec(sh.ambient) << "\n";
        } else {
            o << "    occlusion " << num(t.occlusion) << "; diffuse + specular" << (t.sheen ? " + sheen" : "")
              << (t.transmission ? " + transmission" : "") << " = " << vec(sh.ambient) << "\n";
        }
    } else {
        o << "  ambient " << vec(s.settings.ambient) << " * albedo * occlusion = " << vec(sh.ambient) << "\n";
    }
    o << "  shaded colour (emissive + contributions + " << (sh.ibl ? "environment" : "ambient") << ") "
      << vec(sh.Lo) << "\n";
    if (!sh.matches_shade_surface) o << "  NOTE: shade_surface() gives a different value\n";
}

} // namespace

namespace {

std::string sample_list(std::uint32_t bits, int samples) {
    std::string out;
    for (int i = 0; i < samples; ++i)
        if ((bits >> i) & 1u) out += (out.empty() ? "" : ",") + std::to_string(i);
    return out.empty() ? "none" : out;
}

std::string entry_name(const Recording& rec, const PixelExplanation& px, int k) {
    const HistoryEntry& h = px.history[std::size_t(k)];
    if (h.line_draw >= 0)
        return "#" + std::to_string(k + 1) + " (draw " + std::to_string(h.line_draw) +
               (rec.draws[std::size_t(h.line_draw)].topology == Topology::Points ? " point " : " line ") +
               std::to_string(h.line_prim) + ")";
    return "#" + std::to_string(k + 1) + " (tri " + std::to_string(rec.pieces[h.piece].triangle) + ")";
}

// The history line of a line or point fragment and how line.h's rules gave it the pixel.
void line_entry_text(std::ostringstream& o, const FrameSetup& s, const Recording& rec, const PixelExplanation& px,
                     const HistoryEntry& h, std::size_t i) {
    const DrawRecord& d = rec.draws[std::size_t(h.line_draw)];
    const LineSetup& l = h.line.setup;
    o << "  #" << i + 1 << " " << line_name(s, rec, std::size_t(h.line_draw), h.line_prim) << ", material "
      << quoted(draw_material(s, d).m->name) << ", vertices " << h.line.index[0];
    if (!l.point) o << " " << h.line.index[1];
    o << (h.line.planes ? ", clipped against " + plane_names(h.line.planes) : std::string()) << "\n";
    auto px_of = [](std::int32_t v) { return num(double(v) / 256.0); };
    if (l.point) {
        o << "     point fragment: at (" << px_of(l.x0) << ", " << px_of(l.y0) << ") px (fixed " << l.x0 << ", " << l.y0
          << "), coverage rule: the pixel containing it, floor(x), floor(y) = " << px.x << " " << px.y
          << " (a point on a pixel edge belongs to the pixel right of or below it)\n";
    } else {
        o << "     line fragment: segment from (" << px_of(l.x0) << ", " << px_of(l.y0) << ") to (" << px_of(l.x1)
          << ", " << px_of(l.y1) << ") px (fixed " << l.x0 << "," << l.y0 << " -> " << l.x1 << "," << l.y1 << "), "
          << (l.x_major ? "x" : "y") << "-major\n";
        o << "     coverage rule (diamond exit): the segment meets the pixel's diamond |x - " << px.x << ".5| + |y - "
          << px.y << ".5| < 1/2 and its end is not inside it (ties: the segment moved by (+e, +e^2))\n";
        o << "     at t " << num(h.line_t) << " along it (the centre's projection): perspective weight of the end "
          << num(h.line_w1) << "\n";
    }
    const int S = px.samples;
    if (S > 1) o << "     covers all " << S << " samples (aliased: every sample at the pixel's depth)\n";
    for (int k = 0; k < S; ++k) {
        const bool passed = (h.pass >> k) & 1u;
        const std::string test = d.state.depth_test ? (passed ? "passed" : "failed the depth test (LESS)") : "no depth test";
        if (S == 1) o << "     depth " << num(h.z[k]) << " vs buffer " << num(h.depth_before[k]) << ": " << test << "\n";
        else o << "     sample " << k << ": depth " << num(h.z[k]) << " vs " << num(h.depth_before[k]) << ": " << test << "\n";
    }
    if (!h.pass) o << "     hidden: the depth test failed\n";
    else if (h.killed) o << "     shaded in order: discarded by the shader (alpha " << num(h.shading.ms.alpha)
                         << " below the cutoff)\n";
    else if (h.blend_order) {
        o << "     shaded in order (alpha blend; depth tested, not written): blend #" << h.blend_order << ", shader out "
          << vec(h.shading.Lo) << " alpha " << num(h.alpha) << "\n";
        for (int k = 0; k < S; ++k)
            if ((h.pass >> k) & 1u)
                o << "     " << (S > 1 ? "sample " + std::to_string(k) + ": " : std::string())
                  << "out * alpha + previous * (1 - alpha) = " << vec(h.blended[k]) << "\n";
    } else {
        o << "     shaded in order (lines and points always are): " << (h.shading.unlit ? "unlit, " : "")
          << "shader out " << vec(h.shading.Lo) << ", written to sample" << (__builtin_popcount(h.pass) > 1 ? "s " : " ")
          << sample_list(h.pass, S) << "\n";
    }
}

} // namespace

std::string pixel_text(const FrameSetup& s, const Recording& rec, const PixelExplanation& px) {
    std::ostringstream o;
    const int tile = rec.tile_of(px.x, px.y);
    const int S = px.samples;
    const SamplePattern& pattern = sample_pattern(S);
    o << "pixel " << px.x << " " << px.y << ": tile " << tile % rec.tiles_x << " " << tile / rec.tiles_x << ", block "
      << (px.x & ~3) << " " << (px.y & ~3) << " lane " << px.lane << "\n";
    if (S > 1) {
        o << S << " samples per pixel (MSAA), at the pixel centre plus (in pixels):";
        for (int i = 0; i < S; ++i)
            o << " s" << i << " (" << num(pattern.pixel_x(i)) << ", " << num(pattern.pixel_y(i)) << ")";
        o << "\n";
    }
    const bool partial = px.upto != kAllTriangles;
    const std::string point = partial ? "after " + std::to_string(px.upto) + " triangles" : "after the frame";
    if (partial)
        o << "as the frame stands after the first " << px.upto << " of " << rec.triangle_count()
          << " triangles (upto " << px.upto << "; `upto all` explains the frame's end)\n";
    o << "history: cleared to " << vec(px.background) << " depth 1, then " << px.history.size() << " fragment"
      << (px.history.size() == 1 ? "" : "s") << " in submission order\n";
    for (std::size_t i = 0; i < px.history.size(); ++i) {
        const HistoryEntry& h = px.history[i];
        if (h.line_draw >= 0) {
            line_entry_text(o, s, rec, px, h, i);
            continue;
        }
        const PieceRecord& p = rec.pieces[h.piece];
        const TriangleRecord& tr = rec.triangles[p.triangle];
        const DrawRecord& d = rec.draw_of(p.triangle);
        const TriangleSetup& t = rec.setups[p.setup];
        const SurfacePoint sp = replay_surface_point(h.replay, h.lane);
        o << "  #" << i + 1 << " " << triangle_name(s, rec, p.triangle);
        if (tr.piece_count > 1) o << " piece " << (h.piece - tr.first_piece);
        o << ", material " << quoted(material_of(s, rec, p.triangle).m->name) << ", "
          << (t.front_facing ? "front" : "back") << " face\n";
        const int l = h.lane;
        if (S > 1) o << "     covers samples " << sample_list(h.cover, S) << " of " << S << "\n";
        o << "     barycentrics screen (" << num(h.replay.bary[0][l]) << ", " << num(h.replay.bary[1][l]) << ", "
          << num(h.replay.bary[2][l]) << ") perspective (" << num(h.replay.persp[0][l]) << ", "
          << num(h.replay.persp[1][l]) << ", " << num(h.replay.persp[2][l]) << ")";
        if (h.replay.centroid_of[l])
            o << " at the centroid of samples " << sample_list(h.replay.centroid_of[l], S) << " ("
              << num(h.replay.at_x[l]) << ", " << num(h.replay.at_y[l]) << ") px: the centre is outside";
        o << "\n";
        o << "     P " << vec(sp.P) << " N " << vec(sp.N) << " uv " << vec(sp.uv) << " T " << vec(sp.T);
        if (h.replay.varyings == kPbrVaryingsExt)
            for (int set = 1; set < kMaxUvSets; ++set) o << " uv" << set << " " << vec(sp.uv_of(set));
        if (sp.has_color) o << " colour " << vec(sp.color);
        o << "\n";
        bool consistent = true;
        for (int k = 0; k < S; ++k) {
            if (!((h.cover >> k) & 1u)) continue;
            const bool passed = (h.pass >> k) & 1u;
            consistent &= passed == (h.z[k] < h.depth_before[k]);
            if (S == 1) o << "     depth " << num(h.z[k]) << " vs buffer " << num(h.depth_before[k]) << ": "
                          << (passed ? "passed" : "failed the depth test (LESS)") << "\n";
            else o << "     sample " << k << ": depth " << num(h.z[k]) << " vs " << num(h.depth_before[k]) << ": "
                   << (passed ? "passed" : "failed (LESS)") << "\n";
        }
        if (!consistent) o << "     NOTE: a recorded depth test disagrees with the depths above\n";
        if (!h.pass) {
            o << "     hidden: the depth test failed at every sample it covers\n";
        } else if (h.visible) {
            o << "     visibility pass: depth written, the winner of sample" << (__builtin_popcount(h.pass) > 1 ? "s " : " ")
              << sample_list(h.pass, S) << " so far\n";
            if (!h.shaded)
                o << "     not shaded: later fragments won all its samples (the visibility pass shades winners only)\n";
            else
                o << "     shaded once, after the tile's depth pass (it kept sample"
                  << (__builtin_popcount(h.owns) > 1 ? "s " : " ") << sample_list(h.owns, S) << "): shader out "
                  << vec(h.shading.Lo) << "\n";
        } else if (h.killed) {
            o << "     shaded in order (alpha mask): discarded by the shader (alpha " << num(h.shading.ms.alpha)
              << " below the cutoff)\n";
        } else if (h.shaded && h.blend_order) {
            o << "     shaded in order (alpha blend, back to front; depth tested, not written): blend #"
              << h.blend_order << ", shader out " << vec(h.shading.Lo) << " alpha " << num(h.alpha) << "\n";
            for (int k = 0; k < S; ++k)
                if ((h.pass >> k) & 1u)
                    o << "     " << (S > 1 ? "sample " + std::to_string(k) + ": " : std::string())
                      << "out * alpha + previous * (1 - alpha) = " << vec(h.blended[k]) << "\n";
        } else if (h.shaded) {
            o << "     shaded in order (" << (d.state.may_discard ? "alpha mask" : "no visibility pass")
              << "): shader out " << vec(h.shading.Lo) << ", written to sample" << (__builtin_popcount(h.pass) > 1 ? "s " : " ")
              << sample_list(h.pass, S) << "\n";
        }
        if (h.shaded && h.replay.in.z[l] != h.z[0] && S == 1)
            o << "     NOTE: recomputed depth " << num(h.replay.in.z[l]) << "\n";
    }
    if (S > 1) {
        o << "samples " << point << ":\n";
        for (int k = 0; k < S; ++k) {
            o << "  s" << k << " ";
            if (px.sample_owner[k] < 0) o << "cleared";
            else o << entry_name(rec, px, px.sample_owner[k]);
            o << " depth " << num(px.sample_depth[k]) << " colour " << vec(px.sample_color[k]) << "\n";
        }
        o << "resolve: the average of the " << S << " samples (summed pairwise) = " << vec(px.linear) << "\n";
    }
    if (px.contributors.empty()) {
        if (partial)
            o << "no fragment was written in the first " << px.upto << " triangles: the pixel holds the clear colour "
              << vec(px.background) << "\n";
        else
            o << "no fragment was written: the background " << vec(px.background) << "\n";
    } else {
        for (int k : px.contributors) {
            const HistoryEntry& w = px.history[std::size_t(k)];
            o << "shading of " << entry_name(rec, px, k) << ", lane " << w.lane << " of its 4x4 block";
            if (S > 1) o << ", colour of sample" << (__builtin_popcount(w.owns) > 1 ? "s " : " ") << sample_list(w.owns, S);
            o << ":\n";
            shading_text(o, s, rec, w);
        }
    }
    if (std::memcmp(&px.framebuffer, &px.linear, sizeof px.linear))
        o << "NOTE: the " << (partial ? "frame " + point : std::string("recorded frame")) << " holds "
          << vec(px.framebuffer) << "\n";
    o << "linear " << vec(px.linear) << "\n";
    o << "exposure " << num(s.exposure()) << " -> " << vec(px.exposed) << "\n";
    o << "tone map " << tonemap_name(s.tonemap()) << " -> " << vec(px.toned) << "\n";
    o << "srgb8 " << int(px.srgb8[0]) << " " << int(px.srgb8[1]) << " " << int(px.srgb8[2]) << "\n";
    return o.str();
}

json pixel_json(const FrameSetup& s, const Recording& rec, const PixelExplanation& px) {
    json j;
    j["x"] = px.x;
    j["y"] = px.y;
    j["samples"] = px.samples;
    j["triangles"] = rec.triangle_count();
    j["upto"] = px.upto == kAllTriangles ? json(nullptr) : json(px.upto);  // null: the frame's end
    j["background"] = j3(px.background);
    json hist = json::array();
    for (const HistoryEntry& h : px.history) {
        json e;
        if (h.line_draw >= 0) {
            const DrawRecord& d = rec.draws[std::size_t(h.line_draw)];
            e["draw"] = h.line_draw;
            e[d.topology == Topology::Points ? "point" : "line"] = h.line_prim;
            e["mesh"] = s.scene.meshes[std::size_t(d.mesh)].name;
        } else {
            const std::uint32_t tri = rec.pieces[h.piece].triangle;
            e["tri"] = tri;
            e["draw"] = rec.draw_index(tri);
            e["mesh"] = mesh_name(s, rec, tri);
        }
        e["depth"] = h.z[__builtin_ctz(h.cover)];
        e["cover"] = sample_list(h.cover, px.samples);
        e["pass"] = sample_list(h.pass, px.samples);
        e["owns"] = sample_list(h.owns, px.samples);
        e["result"] = !h.pass ? "depth test failed" : h.killed ? "discarded" : !h.shaded ? "passed, not shaded (later ones won)"
                      : h.visible ? "shaded once (won samples " + sample_list(h.owns, px.samples) + ")" : "written";
        if (h.written) e["out"] = j3(h.shading.Lo);
        hist.push_back(e);
    }
    j["history"] = hist;
    json samples = json::array();
    for (int k = 0; k < px.samples; ++k) {
        json e;
        e["owner"] = px.sample_owner[k];
        e["depth"] = px.sample_depth[k];
        e["color"] = j3(px.sample_color[k]);
        // The sample alone through exposure, tone map and sRGB, to show it.
        const float rgba[4] = {px.sample_color[k].r, px.sample_color[k].g, px.sample_color[k].b, 1.0f};
        std::uint8_t srgb[4];
        resolve_to_srgb8(rgba, 1, 1, s.exposure(), s.tonemap(), srgb);
        e["srgb8"] = json::array({srgb[0], srgb[1], srgb[2]});
        e["offset"] = json::array({sample_pattern(px.samples).pixel_x(k), sample_pattern(px.samples).pixel_y(k)});
        samples.push_back(e);
    }
    j["sample_list"] = samples;
    j["winner"] = px.contributors.empty() ? -1 : px.contributors[0];
    j["linear"] = j3(px.linear);
    j["srgb8"] = json::array({px.srgb8[0], px.srgb8[1], px.srgb8[2]});
    j["text"] = pixel_text(s, rec, px);
    return j;
}

} // namespace prast::stepper

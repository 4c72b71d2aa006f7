// Stage images; see stages.h. Geometry stages are drawn from the recorded
// vertices, setups and bins; coverage stages from the recorded blocks;
// surface stages by shading each pixel's winning fragment again with
// replay.h (the values `pixel X Y` prints).
#include "stepper/stages.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>

#include "shading/color.h"
#include "shading/tonemap.h"
#include "stepper/replay.h"

namespace prast::stepper {

const std::vector<StageInfo>& stage_list() {
    static const std::vector<StageInfo> kStages = {
        {"vertices", "Projected vertices",
         "Every vertex the vertex stage output, projected to the window (x/w, y/w): brighter where several land on "
         "one pixel. Vertices behind the eye (w <= 0) are not drawn."},
        {"wireframe", "Wireframe after clipping and culling",
         "The edges of every triangle as set up, snapped to 1/256 pixel: white for set-up triangles, orange for "
         "the pieces of clipped ones, dark blue for back faces culled, magenta for degenerate ones."},
        {"bins", "Tile bins",
         "How many triangles (bin entries) each tile has to walk, as a heat map from blue (few) to red (the most), "
         "on a log scale; tile borders in grey."},
        {"depth", "Depth",
         "The depth buffer after the frame, linearised between the near and far planes: white is near, black far "
         "or empty."},
        {"overdraw", "Overdraw",
         "Fragments covered per pixel, before the depth test: black 0, blue 1, green 2, yellow 3, red 4, then "
         "magenta to white for 8 or more."},
        {"shaded", "Shaded once (the visibility pass)",
         "Fragment-program runs per pixel, same colours as overdraw: the visibility pass depth-tests every "
         "fragment first and shades only each sample's final winner, so where overdraw shows 3 this is mostly 1 "
         "(2 or more along edges, where several triangles keep samples of one pixel)."},
        {"msaa", "Samples (MSAA): fragments per pixel",
         "How many fragments the resolve averages in each pixel: dark grey one (an interior pixel, all samples "
         "alike), orange two, red three or more; blue and cyan when the background keeps some samples. Black: "
         "the background alone. With --msaa 1 every pixel has one."},
        {"quad_overdraw", "Quad overdraw (helper lanes)",
         "Lanes the fragment shader ran per pixel, counting helper lanes: a 2x2 quad with any live pixel shades "
         "all four. Same colours as overdraw; edges of small triangles light up."},
        {"triangle_size", "Triangle size",
         "The area in pixels of the triangle that won each pixel, from red (1 pixel or less) through yellow and "
         "green to blue (4096 or more), on a log scale."},
        {"nan", "NaN, Inf and negative values",
         "Pixels whose linear colour holds a NaN (red), an infinity (magenta) or a negative value (blue); all "
         "others in dim grey. A clean frame is all grey."},
        {"albedo", "Albedo",
         "The base colour of the winning fragment (factor times texture), sRGB-encoded."},
        {"normal", "Shading normal",
         "The normal after normal mapping, world space, as n * 0.5 + 0.5 (red +x, green +y, blue +z)."},
        {"roughness", "Roughness", "Perceptual roughness as grey, before the BRDF's clamp to 0.045."},
        {"metallic", "Metallic", "Metalness as grey: black is a dielectric, white a metal."},
        {"occlusion", "Occlusion", "Ambient occlusion as grey (1 + strength * (map - 1)); white without a map."},
        {"mip", "Mip level",
         "The texture level of detail lambda of the base colour map (else the first map the material has): blue "
         "for magnification (level 0), then cyan, green, yellow, red for levels 1 to 4, white beyond; black "
         "without a map."},
        {"D", "D (GGX distribution), first light",
         "The microfacet distribution for the first light, shown as D / (1 + D): a highlight's core is white."},
        {"F", "F (Fresnel), first light", "Schlick's Fresnel for the first light as a colour."},
        {"G", "G (Smith shadowing-masking), first light",
         "The geometry term for the first light as grey (with --brdf gltf: the visibility V)."},
        {"diffuse", "Diffuse", "The diffuse lobe summed over the lights, times radiance and n.l, sRGB-encoded."},
        {"specular", "Specular", "The specular lobe summed over the lights, times radiance and n.l, sRGB-encoded."},
        {"final", "Final image",
         "The frame after exposure, tone map and sRGB encoding: byte for byte the PNG render writes."},
    };
    return kStages;
}

const StageInfo* find_stage(const std::string& name) {
    for (const StageInfo& s : stage_list())
        if (name == s.name) return &s;
    return nullptr;
}

namespace {

using Image = std::vector<std::uint8_t>;

void fill(Image& img, const Recording& rec, std::uint8_t v) {
    img.assign(std::size_t(rec.width) * rec.height * 4, v);
    for (std::size_t i = 3; i < img.size(); i += 4) img[i] = 255;
}

void put(Image& img, const Recording& rec, int x, int y, glm::vec3 c) {
    if (x < 0 || y < 0 || x >= rec.width || y >= rec.height) return;
    std::uint8_t* p = &img[(std::size_t(y) * rec.width + x) * 4];
    for (int k = 0; k < 3; ++k) p[k] = std::uint8_t(std::lround(glm::clamp(c[k], 0.0f, 1.0f) * 255.0f));
}

// Vertices per pixel: brighter with more, white from 4.
glm::vec3 vertex_grey(int count) { return glm::vec3(std::min(1.0f, 0.45f + 0.15f * float(count))); }

// The wireframe's colours, by what became of the triangle.
const glm::vec3 kSetUp(1.0f), kClipped(1.0f, 0.55f, 0.1f), kBack(0.15f, 0.2f, 0.6f), kDegenerate(1.0f, 0.0f, 1.0f);

// Bins: h = log2(1 + entries) / log2(1 + the fullest tile's), blue to red.
glm::vec3 bins_colour(float h) { return glm::mix(glm::vec3(0.1f, 0.2f, 1.0f), glm::vec3(1.0f, 0.15f, 0.05f), h); }
const glm::vec3 kTileBorder(0.5f);

// Depth: t = 0 at the near plane (white) to 1 at the far plane (black).
glm::vec3 depth_grey(float t) { return glm::vec3(1.0f - t); }

// MSAA: fragments per pixel, with or without background samples.
const glm::vec3 kOneFragment(0.3f), kTwo(1.0f, 0.6f, 0.1f), kThree(1.0f, 0.1f, 0.1f),
    kBackgroundAndOne(0.1f, 0.4f, 1.0f), kBackgroundAndTwo(0.2f, 1.0f, 1.0f);

// NaN stage.
const glm::vec3 kNan(1, 0, 0), kInf(1, 0, 1), kNegative(0, 0, 1), kClean(0.25f);

glm::vec3 heat(int n) {
    static const glm::vec3 kRamp[] = {{0, 0, 0}, {0, 0, 1}, {0, 1, 0}, {1, 1, 0}, {1, 0, 0},
                                      {1, 0, 1}, {1, 0.5f, 1}, {1, 0.8f, 1}, {1, 1, 1}};
    return kRamp[std::min(8, std::max(0, n))];
}

// A ramp over t in [0, 1]: red, yellow, green, cyan, blue.
glm::vec3 rainbow(float t) {
    static const glm::vec3 kStops[] = {{1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {0, 1, 1}, {0, 0, 1}};
    t = glm::clamp(t, 0.0f, 1.0f) * 4.0f;
    const int i = std::min(3, int(t));
    return glm::mix(kStops[i], kStops[i + 1], t - float(i));
}

// A line between window positions, clipped to the image by sampling.
void line(Image& img, const Recording& rec, double x0, double y0, double x1, double y1, glm::vec3 c) {
    // Clip the segment to a margin around the viewport (parametric, Liang-Barsky).
    double t0 = 0.0, t1 = 1.0;
    const double dx = x1 - x0, dy = y1 - y0;
    auto clip = [&](double p, double q) {
        if (p == 0.0) return q >= 0.0;
        const double r = q / p;
        if (p < 0.0) { if (r > t1) return false; t0 = std::max(t0, r); }
        else { if (r < t0) return false; t1 = std::min(t1, r); }
        return true;
    };
    const double lo = -1.0, hx = rec.width + 1.0, hy = rec.height + 1.0;
    if (!clip(-dx, x0 - lo) || !clip(dx, hx - x0) || !clip(-dy, y0 - lo) || !clip(dy, hy - y0)) return;
    const double ax = x0 + t0 * dx, ay = y0 + t0 * dy, bx = x0 + t1 * dx, by = y0 + t1 * dy;
    const int steps = int(std::ceil(std::max(std::fabs(bx - ax), std::fabs(by - ay)))) + 1;
    for (int i = 0; i <= steps; ++i) {
        const double t = double(i) / steps;
        put(img, rec, int(std::floor(ax + (bx - ax) * t)), int(std::floor(ay + (by - ay) * t)), c);
    }
}

bool project(const float* clip, const Recording& rec, double& x, double& y) {
    if (!(clip[3] > 0.0f)) return false;
    const SnappedVertex v = snap_vertex(clip, rec.width, rec.height);
    x = v.x_win;
    y = v.y_win;
    return std::isfinite(x) && std::isfinite(y);
}

void draw_vertices(const Recording& rec, Image& img) {
    fill(img, rec, 0);
    std::vector<std::uint16_t> count(std::size_t(rec.width) * rec.height, 0);
    for (const DrawRecord& d : rec.draws)
        for (std::uint32_t v = 0; v < d.vertex_count; ++v) {
            double x, y;
            if (!project(&d.vertices[std::size_t(v) * kStride], rec, x, y)) continue;
            if (!(x >= 0.0 && y >= 0.0 && x < rec.width && y < rec.height)) continue;
            std::uint16_t& c = count[std::size_t(int(y)) * rec.width + std::size_t(int(x))];
            if (c < 65535) ++c;
        }
    for (int y = 0; y < rec.height; ++y)
        for (int x = 0; x < rec.width; ++x) {
            const int c = count[std::size_t(y) * rec.width + x];
            if (c) put(img, rec, x, y, vertex_grey(c));
        }
}

void draw_wireframe(const FrameSetup& s, const Recording& rec, Image& img) {
    fill(img, rec, 0);
    auto triangle = [&](const float* a, const float* b, const float* c, glm::vec3 col) {
        double x[3], y[3];
        if (!project(a, rec, x[0], y[0]) || !project(b, rec, x[1], y[1]) || !project(c, rec, x[2], y[2])) return;
        for (int i = 0; i < 3; ++i) line(img, rec, x[i], y[i], x[(i + 1) % 3], y[(i + 1) % 3], col);
    };
    // Culled first, so that what was drawn stays on top.
    for (int pass = 0; pass < 2; ++pass)
        for (std::uint32_t tri = 0; tri < rec.triangle_count(); ++tri) {
            const TriangleRecord& tr = rec.triangles[tri];
            if (!tr.seen) continue;
            const bool culled = tr.fate == TriangleFate::CulledBack || tr.fate == TriangleFate::Degenerate;
            if ((pass == 0) != culled) continue;
            if (culled) {
                const ClipReplay c = replay_clip(s, rec, tri);
                if (!c.valid || c.count < 3) continue;
                const glm::vec3 col = tr.fate == TriangleFate::CulledBack ? kBack : kDegenerate;
                for (int i = 1; i + 1 < c.count; ++i) triangle(c.polygon[0], c.polygon[i], c.polygon[i + 1], col);
                continue;
            }
            if (tr.fate != TriangleFate::SetUp) continue;
            for (std::uint32_t k = 0; k < tr.piece_count; ++k) {
                const std::uint32_t pi = tr.first_piece + k;
                if (rec.pieces[pi].setup == kNone) continue;
                float v[3][kStride];
                piece_vertices(s, rec, pi, v);
                triangle(v[0], v[1], v[2], tr.clipped ? kClipped : kSetUp);
            }
        }
}

void draw_bins(const Recording& rec, Image& img) {
    fill(img, rec, 0);
    std::size_t most = 1;
    for (const TileRecord& t : rec.tiles) most = std::max(most, t.pieces.size());
    for (int y = 0; y < rec.height; ++y)
        for (int x = 0; x < rec.width; ++x) {
            const std::size_t n = rec.tiles[std::size_t(rec.tile_of(x, y))].pieces.size();
            glm::vec3 c(0.0f);
            if (n) {
                const float h = float(std::log2(1.0 + double(n)) / std::log2(1.0 + double(most)));
                c = bins_colour(h);
            }
            if (x % rec.tile_size == 0 || y % rec.tile_size == 0) c = kTileBorder;
            put(img, rec, x, y, c);
        }
}

void draw_depth(const FrameSetup& s, const Recording& rec, Image& img) {
    fill(img, rec, 0);
    const float n = s.settings.camera.near_plane, f = s.settings.camera.far_plane;
    for (int y = 0; y < rec.height; ++y)
        for (int x = 0; x < rec.width; ++x) {
            const float z = rec.fb.depth[std::size_t(y) * rec.width + x];
            if (!(z < 1.0f)) continue;
            const float z_ndc = z * 2.0f - 1.0f;
            const float d = 2.0f * n * f / (f + n - z_ndc * (f - n));
            put(img, rec, x, y, depth_grey(glm::clamp((d - n) / (f - n), 0.0f, 1.0f)));
        }
}

// Per pixel counts over the recorded blocks: covered lanes, lanes the
// fragment program ran for, or lanes of shaded quads.
enum class Count { Covered, Shaded, Quads };
void draw_counts(const Recording& rec, Image& img, Count what) {
    fill(img, rec, 0);
    std::vector<int> count(std::size_t(rec.width) * rec.height, 0);
    for (const TileRecord& t : rec.tiles)
        for (const BlockRecord& b : t.blocks) {
            std::uint32_t m = what == Count::Shaded ? b.shaded : b.mask;
            if (what == Count::Quads) {
                m = 0;
                for (int q = 0; q < 4; ++q)
                    if ((b.shaded >> (4 * q)) & 0xFu) m |= 0xFu << (4 * q);
            }
            for (; m; m &= m - 1) {
                const int l = __builtin_ctz(m);
                const int x = b.bx + lane_x(l), y = b.by + lane_y(l);
                if (x < rec.width && y < rec.height) ++count[std::size_t(y) * rec.width + x];
            }
        }
    for (int y = 0; y < rec.height; ++y)
        for (int x = 0; x < rec.width; ++x) put(img, rec, x, y, heat(count[std::size_t(y) * rec.width + x]));
}

// The fragments whose colour each sample of a tile ends the frame with,
// replayed as the tile pass ran (explain_pixel() does the same for one
// pixel): a draw taking the visibility pass makes each sample it passes its
// winner; a draw shaded in order makes the samples it writes its own.
struct TileOwners {
    int x0 = 0, y0 = 0, size = 0, samples = 1;
    std::vector<std::int32_t> owner;  // block index in the tile, -1 cleared; [(py * size + px) * samples + s]

    std::int32_t at(int x, int y, int s) const {
        return owner[(std::size_t(y - y0) * std::size_t(size) + std::size_t(x - x0)) * std::size_t(samples) + std::size_t(s)];
    }
    // The fragment holding most of the pixel's samples (the earliest on a
    // tie): the first "shading of" of `pixel X Y`. -1 for the background.
    std::int32_t main(int x, int y) const {
        std::int32_t best = -1;
        int best_n = 0;
        for (int s = 0; s < samples; ++s) {
            const std::int32_t o = at(x, y, s);
            if (o < 0) continue;
            int n = 0;
            for (int k = 0; k < samples; ++k) n += at(x, y, k) == o;
            if (n > best_n || (n == best_n && o < best)) {
                best = o;
                best_n = n;
            }
        }
        return best;
    }
    int distinct(int x, int y) const {
        int n = 0;
        for (int s = 0; s < samples; ++s) {
            const std::int32_t o = at(x, y, s);
            bool seen = false;
            for (int k = 0; k < s; ++k) seen |= at(x, y, k) == o;
            n += !seen;
        }
        return n;
    }
};

TileOwners tile_owners(const Recording& rec, int tile) {
    TileOwners o;
    o.size = rec.tile_size;
    o.samples = rec.samples;
    o.x0 = (tile % rec.tiles_x) * rec.tile_size;
    o.y0 = (tile / rec.tiles_x) * rec.tile_size;
    o.owner.assign(std::size_t(o.size) * std::size_t(o.size) * std::size_t(o.samples), -1);
    const TileRecord& t = rec.tiles[std::size_t(tile)];
    for (std::size_t i = 0; i < t.blocks.size(); ++i) {
        const BlockRecord& b = t.blocks[i];
        const bool visible = rec.draw_of(rec.pieces[b.piece].triangle).visible;
        for (int s = 0; s < rec.samples; ++s) {
            std::uint32_t m = rec.pass(t, b, s);
            if (!visible) m &= b.live;
            for (; m; m &= m - 1) {
                const int l = __builtin_ctz(m);
                const std::size_t p = std::size_t(b.by + lane_y(l) - o.y0) * std::size_t(o.size) +
                                      std::size_t(b.bx + lane_x(l) - o.x0);
                o.owner[p * std::size_t(o.samples) + std::size_t(s)] = std::int32_t(i);
            }
        }
    }
    return o;
}

// Calls fn(block index, lane) for the main fragment of every pixel of the tile.
template <class Fn>
void for_each_winner(const Recording& rec, int tile, Fn&& fn) {
    const TileOwners o = tile_owners(rec, tile);
    const int x1 = std::min(o.x0 + o.size, rec.width), y1 = std::min(o.y0 + o.size, rec.height);
    for (int y = o.y0; y < y1; ++y)
        for (int x = o.x0; x < x1; ++x) {
            const std::int32_t b = o.main(x, y);
            if (b < 0) continue;
            int lane = 0;
            for (int l = 0; l < kBlockLanes; ++l)
                if (lane_x(l) == (x & 3) && lane_y(l) == (y & 3)) lane = l;
            fn(std::size_t(b), lane);
        }
}

// Per pixel: how many fragments (and the background) the resolve averages.
void draw_msaa(const Recording& rec, Image& img) {
    fill(img, rec, 0);
    for (int tile = 0; tile < int(rec.tiles.size()); ++tile) {
        const TileOwners o = tile_owners(rec, tile);
        const int x1 = std::min(o.x0 + o.size, rec.width), y1 = std::min(o.y0 + o.size, rec.height);
        for (int y = o.y0; y < y1; ++y)
            for (int x = o.x0; x < x1; ++x) {
                bool background = false;
                for (int s = 0; s < o.samples; ++s) background |= o.at(x, y, s) < 0;
                const int n = o.distinct(x, y);
                glm::vec3 c(0.0f);
                if (n == 1 && !background) c = kOneFragment;
                else if (n == 2) c = background ? kBackgroundAndOne : kTwo;
                else if (n >= 3) c = background ? kBackgroundAndTwo : kThree;
                put(img, rec, x, y, c);
            }
    }
}

void draw_triangle_size(const Recording& rec, Image& img) {
    fill(img, rec, 0);
    for (int tile = 0; tile < int(rec.tiles.size()); ++tile)
        for_each_winner(rec, tile, [&](std::size_t i, int lane) {
            const BlockRecord& b = rec.tiles[std::size_t(tile)].blocks[i];
            const TriangleSetup& s = rec.setups[rec.pieces[b.piece].setup];
            // 2 x area = |A0 B1 - A1 B0| / 65536 px^2, from the edge coefficients.
            const double area2 = std::fabs(double(s.A[0]) * double(s.B[1]) - double(s.A[1]) * double(s.B[0]));
            const double px = area2 / (2.0 * 65536.0);
            put(img, rec, b.bx + lane_x(lane), b.by + lane_y(lane),
                rainbow(float(std::log2(std::max(1.0, px)) / 12.0)));
        });
}

void draw_nan(const Recording& rec, Image& img) {
    fill(img, rec, 0);
    for (int y = 0; y < rec.height; ++y)
        for (int x = 0; x < rec.width; ++x) {
            const float* c = rec.fb.pixel(x, y);
            bool nan = false, inf = false, neg = false;
            for (int k = 0; k < 3; ++k) {
                nan |= std::isnan(c[k]);
                inf |= std::isinf(c[k]);
                neg |= c[k] < 0.0f;
            }
            put(img, rec, x, y, nan ? kNan : inf ? kInf : neg ? kNegative : kClean);
        }
}

void draw_final(const FrameSetup& s, const Recording& rec, Image& img) {
    img.resize(std::size_t(rec.width) * rec.height * 4);
    resolve_to_srgb8(rec.fb.color.data(), rec.width, rec.height, s.exposure(), s.tonemap(), img.data());
}

bool is_surface_stage(const std::string& n) {
    static const char* kNames[] = {"albedo", "normal", "roughness", "metallic", "occlusion", "mip",
                                   "D", "F", "G", "diffuse", "specular"};
    for (const char* k : kNames)
        if (n == k) return true;
    return false;
}

glm::vec3 srgb(glm::vec3 c) {
    return glm::vec3(linear_to_srgb8(c.r), linear_to_srgb8(c.g), linear_to_srgb8(c.b)) / 255.0f;
}

glm::vec3 mip_colour(float lambda) {
    if (!(lambda > 0.0f)) return glm::vec3(0.0f, 0.0f, 1.0f);
    static const glm::vec3 kLevels[] = {{0, 0, 1}, {0, 1, 1}, {0, 1, 0}, {1, 1, 0}, {1, 0, 0}, {1, 1, 1}};
    const float l = std::min(lambda, 5.0f);
    const int i = std::min(4, int(l));
    return glm::mix(kLevels[i], kLevels[i + 1], l - float(i));
}

glm::vec3 surface_value(const std::string& n, const FrameSetup& s, const BoundMaterial& bm, const LaneShading& sh) {
    const MaterialSample& ms = sh.ms;
    if (n == "albedo") return srgb(ms.albedo);
    if (n == "normal") return ms.N * 0.5f + 0.5f;
    if (n == "roughness") return glm::vec3(ms.roughness);
    if (n == "metallic") return glm::vec3(ms.metallic);
    if (n == "occlusion") return glm::vec3(ms.occlusion);
    if (n == "mip") {
        const MaterialLods& l = sh.lods;
        if (bm.base_color) return mip_colour(l.base_color);
        if (bm.metallic_roughness) return mip_colour(l.metallic_roughness);
        if (bm.normal) return mip_colour(l.normal);
        if (bm.roughness) return mip_colour(l.roughness);
        if (bm.metallic) return mip_colour(l.metallic);
        if (bm.occlusion) return mip_colour(l.occlusion);
        if (bm.emissive) return mip_colour(l.emissive);
        return glm::vec3(0.0f);
    }
    if (sh.lights.empty()) return glm::vec3(0.0f);
    const BrdfTerms& t = sh.lights[0].terms;
    if (n == "D") return glm::vec3(t.D / (1.0f + t.D));
    if (n == "F") return t.F;
    if (n == "G") return glm::vec3(t.G);
    glm::vec3 sum(0.0f);
    for (const LightStep& L : sh.lights)
        sum += (n == "diffuse" ? L.terms.diffuse : L.terms.specular) * L.radiance * L.terms.NoL;
    return srgb(sum * s.exposure());
}

} // namespace

void draw_stages(FrameSetup& s, const Recording& rec, const std::vector<std::string>& names,
                 std::vector<std::vector<std::uint8_t>>& images) {
    images.assign(names.size(), {});
    std::vector<std::size_t> surface;
    for (std::size_t i = 0; i < names.size(); ++i) {
        const std::string& n = names[i];
        Image& img = images[i];
        if (n == "vertices") draw_vertices(rec, img);
        else if (n == "wireframe") draw_wireframe(s, rec, img);
        else if (n == "bins") draw_bins(rec, img);
        else if (n == "depth") draw_depth(s, rec, img);
        else if (n == "overdraw") draw_counts(rec, img, Count::Covered);
        else if (n == "shaded") draw_counts(rec, img, Count::Shaded);
        else if (n == "quad_overdraw") draw_counts(rec, img, Count::Quads);
        else if (n == "msaa") draw_msaa(rec, img);
        else if (n == "triangle_size") draw_triangle_size(rec, img);
        else if (n == "nan") draw_nan(rec, img);
        else if (n == "final") draw_final(s, rec, img);
        else if (is_surface_stage(n)) {
            fill(img, rec, 0);
            surface.push_back(i);
        } else fill(img, rec, 0);
    }
    if (surface.empty()) return;
    // Shade every pixel's winning fragment again, a tile per task: each
    // block that wins a pixel is replayed once, each winning lane shaded.
    const ShadingContext ctx = s.shading_context();
    s.renderer->pool().run(int(rec.tiles.size()), [&](int tile, int) {
        const TileRecord& t = rec.tiles[std::size_t(tile)];
        const int ts = rec.tile_size;
        const int x0 = (tile % rec.tiles_x) * ts, y0 = (tile / rec.tiles_x) * ts;
        std::vector<std::int32_t> winner(std::size_t(ts) * ts * 2, -1);  // block index, lane
        for_each_winner(rec, tile, [&](std::size_t i, int lane) {
            const BlockRecord& b = t.blocks[i];
            const std::size_t p = std::size_t(b.by + lane_y(lane) - y0) * ts + std::size_t(b.bx + lane_x(lane) - x0);
            winner[2 * p] = std::int32_t(i);
            winner[2 * p + 1] = lane;
        });
        // Group by block, in the tile's order.
        std::vector<std::pair<std::int32_t, std::int32_t>> order;
        for (std::size_t p = 0; p < std::size_t(ts) * ts; ++p)
            if (winner[2 * p] >= 0) order.push_back({winner[2 * p], std::int32_t(p)});
        std::sort(order.begin(), order.end());
        ReplayedBlock rb;
        std::int32_t current = -1;
        for (const auto& [bi, p] : order) {
            const BlockRecord& b = t.blocks[std::size_t(bi)];
            if (bi != current) {
                replay_block(s, rec, b, rb);
                current = bi;
            }
            const BoundMaterial& bm = material_of(s, rec, rec.pieces[b.piece].triangle);
            const int lane = winner[2 * std::size_t(p) + 1];
            const LaneShading sh = shade_lane(ctx, bm, rb, lane);
            const int x = x0 + p % ts, y = y0 + p / ts;
            for (std::size_t k : surface) put(images[k], rec, x, y, surface_value(names[k], s, bm, sh));
        }
    });
}

void draw_stage(FrameSetup& s, const Recording& rec, const std::string& name, std::vector<std::uint8_t>& rgba8) {
    std::vector<Image> images;
    draw_stages(s, rec, {name}, images);
    rgba8 = std::move(images[0]);
}

namespace {

std::uint8_t to_byte(float v) { return std::uint8_t(std::lround(glm::clamp(v, 0.0f, 1.0f) * 255.0f)); }

// The bytes put() writes for colour c.
LegendColour legend(glm::vec3 c, std::string label = "") {
    return LegendColour{{to_byte(c.r), to_byte(c.g), to_byte(c.b)}, std::move(label)};
}

std::string number(double v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.4g", v);
    return buf;
}

StageScale ramp(std::string quantity, std::string units, std::string map, double lo, double hi) {
    StageScale sc;
    sc.kind = "ramp";
    sc.quantity = std::move(quantity);
    sc.units = std::move(units);
    sc.map = std::move(map);
    sc.min = lo;
    sc.max = hi;
    return sc;
}

StageScale classes(std::string quantity, std::vector<LegendColour> list) {
    StageScale sc;
    sc.kind = "classes";
    sc.quantity = std::move(quantity);
    sc.classes = std::move(list);
    return sc;
}

StageScale channels(std::string quantity, std::vector<std::string> names, double lo, double hi, bool srgb_encoded) {
    StageScale sc;
    sc.kind = "channels";
    sc.quantity = std::move(quantity);
    sc.channels = std::move(names);
    sc.min = lo;
    sc.max = hi;
    sc.srgb = srgb_encoded;
    return sc;
}

// A grey ramp from 0 (black) to 1 (white), ticks every quarter.
StageScale grey_ramp(std::string quantity) {
    StageScale sc = ramp(std::move(quantity), "", "linear", 0.0, 1.0);
    sc.stops = {{0.0, legend(glm::vec3(0.0f))}, {1.0, legend(glm::vec3(1.0f))}};
    for (int i = 0; i <= 4; ++i) sc.ticks.push_back({i / 4.0, number(i / 4.0)});
    return sc;
}

const char* kNoFragment = "no fragment (the background)";

std::vector<LegendColour> heat_classes() {
    std::vector<LegendColour> out;
    for (int n = 0; n <= 8; ++n) out.push_back(legend(heat(n), n == 8 ? "8 or more" : std::to_string(n)));
    return out;
}

} // namespace

StageScale stage_scale(const FrameSetup& s, const Recording& rec, const std::string& name) {
    const glm::vec3 black(0.0f);
    if (name == "vertices") {
        std::vector<LegendColour> list = {legend(black, "no vertex")};
        for (int c = 1; c <= 4; ++c) list.push_back(legend(vertex_grey(c), c == 4 ? "4 or more" : std::to_string(c)));
        return classes("vertices projected to the pixel", list);
    }
    if (name == "wireframe")
        return classes("what became of the triangle",
                       {legend(kSetUp, "set up"), legend(kClipped, "a piece of a clipped triangle"),
                        legend(kBack, "back face, culled"), legend(kDegenerate, "degenerate"),
                        legend(black, "no edge")});
    if (name == "bins") {
        std::size_t most = 1;
        for (const TileRecord& t : rec.tiles) most = std::max(most, t.pieces.size());
        StageScale sc = ramp("bin entries of the pixel's tile", "triangles", "log1p", 0.0, double(most));
        sc.stops = {{0.0, legend(bins_colour(0.0f))}, {1.0, legend(bins_colour(1.0f))}};
        const double top = std::log2(1.0 + double(most));
        auto at = [&](double n) { return std::log2(1.0 + n) / top; };
        sc.ticks.push_back({at(1.0), "1"});
        for (double n = 10.0; n < double(most) * 0.7; n *= 10.0) sc.ticks.push_back({at(n), number(n)});
        if (most > 1) sc.ticks.push_back({1.0, number(double(most))});
        sc.classes = {legend(black, "an empty tile (0)"), legend(kTileBorder, "tile borders")};
        return sc;
    }
    if (name == "depth") {
        const double n = s.settings.camera.near_plane, f = s.settings.camera.far_plane;
        StageScale sc = ramp("distance from the eye along the view axis (linearised depth)", "scene units", "linear",
                             n, f);
        sc.stops = {{0.0, legend(depth_grey(0.0f))}, {1.0, legend(depth_grey(1.0f))}};
        for (int i = 0; i <= 4; ++i) sc.ticks.push_back({i / 4.0, number(n + (f - n) * i / 4.0)});
        sc.ticks.front().second += " (near)";
        sc.ticks.back().second += " (far)";
        sc.classes = {legend(black, "far, or no fragment (depth 1)")};
        return sc;
    }
    if (name == "overdraw") return classes("fragments covered per pixel, before the depth test", heat_classes());
    if (name == "shaded") return classes("fragment-program runs per pixel", heat_classes());
    if (name == "quad_overdraw") return classes("shader lanes per pixel, helper lanes included", heat_classes());
    if (name == "msaa")
        return classes("fragments the resolve averages",
                       {legend(black, "background only"), legend(kOneFragment, "1 fragment"),
                        legend(kTwo, "2 fragments"), legend(kThree, "3 or more fragments"),
                        legend(kBackgroundAndOne, "background and 1 fragment"),
                        legend(kBackgroundAndTwo, "background and 2 or more")});
    if (name == "triangle_size") {
        StageScale sc = ramp("area of the triangle that won the pixel", "px", "log", 1.0, 4096.0);
        for (int i = 0; i <= 4; ++i) {
            sc.stops.push_back({i / 4.0, legend(rainbow(float(i) / 4.0f))});
            sc.ticks.push_back({i / 4.0, std::to_string(1 << (3 * i))});
        }
        sc.ticks.front().second = "1 or less";
        sc.ticks.back().second = "4096 or more";
        sc.classes = {legend(black, kNoFragment)};
        return sc;
    }
    if (name == "nan")
        return classes("the pixel's linear colour",
                       {legend(kNan, "a NaN"), legend(kInf, "an infinity"), legend(kNegative, "a negative value"),
                        legend(kClean, "finite and not negative")});
    StageScale sc;
    if (name == "albedo") sc = channels("base colour", {"red", "green", "blue"}, 0.0, 1.0, true);
    else if (name == "normal") sc = channels("world-space shading normal", {"x", "y", "z"}, -1.0, 1.0, false);
    else if (name == "roughness") sc = grey_ramp("perceptual roughness");
    else if (name == "metallic") sc = grey_ramp("metalness");
    else if (name == "occlusion") sc = grey_ramp("ambient occlusion");
    else if (name == "G") sc = grey_ramp("G, Smith shadowing-masking (first light)");
    else if (name == "F") sc = channels("F, Schlick Fresnel (first light)", {"red", "green", "blue"}, 0.0, 1.0, false);
    else if (name == "diffuse" || name == "specular")
        sc = channels(name + " radiance times exposure", {"red", "green", "blue"}, 0.0, 1.0, true);
    else if (name == "mip") {
        sc = ramp("level of detail lambda of the base colour map", "mip levels", "linear", 0.0, 5.0);
        for (int l = 0; l <= 5; ++l) {
            sc.stops.push_back({l / 5.0, legend(mip_colour(float(l)))});
            sc.ticks.push_back({l / 5.0, l == 0 ? "0 or less" : l == 5 ? "5 or more" : std::to_string(l)});
        }
        sc.classes = {legend(black, "no texture map, or no fragment")};
        return sc;
    } else if (name == "D") {
        sc = ramp("D, the GGX distribution (first light), drawn as D / (1 + D)", "1/sr", "x/(1+x)", 0.0, 0.0);
        sc.stops = {{0.0, legend(glm::vec3(0.0f))}, {1.0, legend(glm::vec3(1.0f))}};
        for (double d : {0.0, 0.25, 1.0, 3.0, 9.0}) sc.ticks.push_back({d / (1.0 + d), number(d)});
        sc.ticks.push_back({1.0, "infinity"});
    } else return sc;  // final: the picture itself
    sc.classes.push_back(legend(black, kNoFragment));
    return sc;
}

std::string css_colour(const std::uint8_t rgb[3]) {
    char buf[8];
    std::snprintf(buf, sizeof buf, "#%02x%02x%02x", rgb[0], rgb[1], rgb[2]);
    return buf;
}

nlohmann::json stage_list_json(const FrameSetup& s, const Recording& rec) {
    using nlohmann::json;
    json list = json::array();
    for (const StageInfo& st : stage_list()) {
        const StageScale sc = stage_scale(s, rec, st.name);
        json scale = {{"kind", sc.kind}, {"quantity", sc.quantity}, {"units", sc.units}, {"map", sc.map},
                      {"min", sc.min}, {"max", sc.max}, {"srgb", sc.srgb}, {"channels", sc.channels}};
        json stops = json::array(), ticks = json::array(), list_classes = json::array();
        for (const auto& [t, c] : sc.stops) stops.push_back({t, css_colour(c.rgb)});
        for (const auto& [t, label] : sc.ticks) ticks.push_back({t, label});
        for (const LegendColour& c : sc.classes) list_classes.push_back({css_colour(c.rgb), c.label});
        scale["stops"] = stops;
        scale["ticks"] = ticks;
        scale["classes"] = list_classes;
        list.push_back({{"name", st.name}, {"title", st.title}, {"about", st.about}, {"scale", scale}});
    }
    return list;
}

} // namespace prast::stepper

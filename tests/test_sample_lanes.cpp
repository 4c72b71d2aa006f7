// The 4x4-block texture sampler (sample_lanes.h) and material sampling
// (material_lanes.h) against the scalar Texture::sample_trilinear() /
// sample_lod() and sample_material(): they must agree bit for bit, for every
// wrap mode, filter, level count, level of detail and coordinate (NaN and
// infinities included), with the block unpacked (16 lanes) or its live lanes
// packed into 4 or 8, with UV set 1 and vertex colours. Then the whole lit
// path of PbrProgram::fragment() against the scalar functions.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <vector>

#include "raster/fragment.h"
#include "shading/material_lanes.h"
#include "shading/pbr_program.h"
#include "shading/sample_lanes.h"
#include "tests/shading_test_util.h"

using namespace prast;
using prast::test::add_test_lights;
using prast::test::bits;

namespace {

// A texture of random content in one of the storages: float RGBA, 8-bit with
// 1 to 4 channels (sRGB-encoded colour or linear), or a packed roughness +
// metal pair (two bytes per texel, swizzled).
Texture random_texture(std::mt19937& rng, int w, int h, Wrap s, Wrap t) {
    std::uniform_int_distribution<int> kind(0, 9), byte(0, 255);
    const int k = kind(rng);
    auto random_bytes = [&](int channels, bool srgb) {
        Image img;
        img.width = w;
        img.height = h;
        img.channels = channels;
        img.srgb = srgb;
        img.pixels.resize(img.texel_count() * std::size_t(channels));
        for (std::uint8_t& c : img.pixels) c = std::uint8_t(byte(rng));
        return img;
    };
    if (k == 9) return Texture::pack_roughness_metal(random_bytes(1, false), random_bytes(1, false), s, t);
    if (k >= 1) return Texture::from_image(random_bytes(1 + (k - 1) % 4, k >= 5), s, t);
    std::uniform_real_distribution<float> uni(0.0f, 1.0f);
    Image img;
    img.width = w;
    img.height = h;
    img.rgba.resize(std::size_t(w) * h * 4);
    for (float& c : img.rgba) c = uni(rng);
    return Texture::from_image(std::move(img), s, t);
}

// A coordinate: mostly ordinary, sometimes on a texel centre or edge, at
// the ends of [0, 1], far away, or not a number at all.
float random_coord(std::mt19937& rng, int size) {
    std::uniform_real_distribution<float> uni(-3.0f, 3.0f);
    std::uniform_int_distribution<int> pick(0, 19), texel(-2 * size, 2 * size);
    switch (pick(rng)) {
    case 0: return std::numeric_limits<float>::quiet_NaN();
    case 1: return std::numeric_limits<float>::infinity();
    case 2: return -std::numeric_limits<float>::infinity();
    case 3: return 1e30f * uni(rng);
    case 4: return float(texel(rng)) / float(size);                  // texel edge
    case 5: return (float(texel(rng)) + 0.5f) / float(size);         // texel centre
    case 6: return float(texel(rng) / size);                         // integer
    case 7: return -1e-9f;  // Repeat folds it to exactly 1: the last texel and the first
    case 8: return 1.0f;
    default: return uni(rng);
    }
}

float random_lambda(std::mt19937& rng, int levels) {
    std::uniform_real_distribution<float> uni(-2.0f, float(levels) + 1.0f);
    std::uniform_int_distribution<int> pick(0, 9), level(-1, levels + 1);
    switch (pick(rng)) {
    case 0: return std::numeric_limits<float>::quiet_NaN();
    case 1: return float(level(rng));  // integer lambda: one level
    case 2: return 0.0f;
    case 3: return -64.0f;
    case 4: return 64.0f;
    default: return uni(rng);
    }
}

// Picks N lanes of a 16-lane block: unpacked (N = 16) or the live lanes of a
// random mask packed first, the spare lanes repeating the first.
template <int N>
struct Packing {
    std::uint8_t lane[N], quad[N];
    std::uint32_t block_live = 0, live = 0;

    explicit Packing(std::mt19937& rng) {
        std::uniform_int_distribution<std::uint32_t> mask(1, 0xFFFFu);
        if (N == kBlockLanes) {
            block_live = live = mask(rng);
            for (int l = 0; l < N; ++l) lane[l] = std::uint8_t(l);
        } else {
            do block_live = mask(rng);
            while (__builtin_popcount(block_live) > N);
            int n = 0;
            for (std::uint32_t m = block_live; m; m &= m - 1) lane[n++] = std::uint8_t(__builtin_ctz(m));
            live = (1u << n) - 1u;
            for (int l = n; l < N; ++l) lane[l] = lane[0];
        }
        for (int l = 0; l < N; ++l) quad[l] = std::uint8_t(lane[l] >> 2);
    }
};

const Filter kFilters[2] = {Filter::Nearest, Filter::Linear};
const MinFilter kMinFilters[6] = {MinFilter::Nearest, MinFilter::Linear, MinFilter::NearestMipmapNearest,
                                  MinFilter::LinearMipmapNearest, MinFilter::NearestMipmapLinear,
                                  MinFilter::LinearMipmapLinear};

SamplerState random_sampler(std::mt19937& rng, Wrap s, Wrap t) {
    std::uniform_int_distribution<int> mag(0, 1), min(0, 5);
    return SamplerState{s, t, kFilters[mag(rng)], kMinFilters[min(rng)]};
}

// filtered: the texture gets a random sampler (else trilinear), and `fixed`
// when given.
template <int N>
void check_sampler(std::uint32_t seed, bool filtered = false, const SamplerState* fixed = nullptr) {
    std::mt19937 rng(seed);
    const Wrap wraps[3] = {Wrap::Repeat, Wrap::ClampToEdge, Wrap::MirroredRepeat};
    std::uniform_int_distribution<int> size_pick(0, 7), wrap_pick(0, 2);
    const int sizes[8] = {1, 2, 3, 5, 8, 17, 32, 64};
    const int w = sizes[size_pick(rng)], h = sizes[size_pick(rng)];
    Texture tex = random_texture(rng, w, h, wraps[wrap_pick(rng)], wraps[wrap_pick(rng)]);
    if (fixed) tex = tex.with_sampler(*fixed);
    else if (filtered) tex = tex.with_sampler(random_sampler(rng, tex.wrap_s(), tex.wrap_t()));

    Packing<N> pk(rng);
    alignas(64) float u[kBlockLanes], v[kBlockLanes], block_u[kBlockLanes], block_v[kBlockLanes];
    for (int l = 0; l < kBlockLanes; ++l) {
        block_u[l] = random_coord(rng, w);
        block_v[l] = random_coord(rng, h);
    }
    for (int l = 0; l < N; ++l) {
        u[l] = block_u[pk.lane[l]];
        v[l] = block_v[pk.lane[l]];
    }
    float lambda[4];
    for (float& x : lambda) x = random_lambda(rng, tex.levels());

    TrilinearLanes at;
    prepare_trilinear_lanes<N>(tex, u, v, lambda, pk.quad, pk.live, at);
    TexelLanes out;
    fetch_trilinear_lanes<N>(tex, at, out);
    for (int l = 0; l < N; ++l) {
        if (!((pk.live >> l) & 1u)) continue;
        const glm::vec4 ref = filtered || fixed ? tex.sample_lod(u[l], v[l], lambda[pk.quad[l]])
                                                : tex.sample_trilinear(u[l], v[l], lambda[pk.quad[l]]);
        INFO("seed ", seed, " N ", N, " lane ", l, " size ", w, "x", h, " uv ", u[l], ",", v[l],
             " lambda ", lambda[pk.quad[l]], " sampler key ", tex.sampler_key());
        CHECK(bits(out.r[l]) == bits(ref.r));
        CHECK(bits(out.g[l]) == bits(ref.g));
        CHECK(bits(out.b[l]) == bits(ref.b));
        CHECK(bits(out.a[l]) == bits(ref.a));
    }
    // Sixteen lanes in block order are also the unpacked block (no quad
    // list; lane l in quad l / 4), which chooses its levels on its own path.
    if (N == kBlockLanes) {
        TrilinearLanes block;
        prepare_trilinear_lanes<N>(tex, u, v, lambda, nullptr, pk.live, block);
        TexelLanes block_out;
        fetch_trilinear_lanes<N>(tex, block, block_out);
        for (int l = 0; l < N; ++l) {
            if (!((pk.live >> l) & 1u)) continue;
            INFO("seed ", seed, " unpacked lane ", l, " lambda ", lambda[l / 4], " levels ", tex.levels());
            CHECK(bits(block_out.r[l]) == bits(out.r[l]));
            CHECK(bits(block_out.g[l]) == bits(out.g[l]));
            CHECK(bits(block_out.b[l]) == bits(out.b[l]));
            CHECK(bits(block_out.a[l]) == bits(out.a[l]));
        }
    }
    // A subset of the components, as the material asks for them: those
    // asked for are the same bits, whichever stored channels that leaves
    // the 8-bit fetch to read.
    const std::uint8_t asked = std::uint8_t(std::uniform_int_distribution<int>(1, 15)(rng));
    const Texture* one[1] = {&tex};
    TexelLanes part;
    TexelLanes* part_out[1] = {&part};
    fetch_trilinear_lanes<N>(one, 1, at, part_out, &asked);
    const float* const full_c[4] = {out.r, out.g, out.b, out.a};
    const float* const part_c[4] = {part.r, part.g, part.b, part.a};
    for (int l = 0; l < N; ++l) {
        if (!((pk.live >> l) & 1u)) continue;
        for (int k = 0; k < 4; ++k) {
            if (!((asked >> k) & 1u)) continue;
            INFO("seed ", seed, " N ", N, " lane ", l, " component ", k, " of mask ", int(asked), " channels ",
                 tex.channels());
            CHECK(bits(part_c[k][l]) == bits(full_c[k][l]));
        }
    }
}

// extended: random samplers on the maps, each map on UV set 0 or 1, and a
// vertex colour.
template <int N>
void check_material(std::uint32_t seed, bool extended = false) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> uni(0.0f, 1.0f), sym(-1.0f, 1.0f);
    std::uniform_int_distribution<int> coin(0, 1), pick(0, 9);
    const Wrap wraps[3] = {Wrap::Repeat, Wrap::ClampToEdge, Wrap::MirroredRepeat};
    std::uniform_int_distribution<int> wrap_pick(0, 2);

    // Maps of two layouts, so that some share a preparation and some do not.
    const Wrap ws = wraps[wrap_pick(rng)], wt = wraps[wrap_pick(rng)];
    std::vector<Texture> textures;
    for (int i = 0; i < 7; ++i)
        textures.push_back(coin(rng) ? random_texture(rng, 16, 16, ws, wt)
                                     : random_texture(rng, 8, 32, wraps[wrap_pick(rng)], Wrap::Repeat));
    if (extended)  // half of them through another sampler of the same texels
        for (Texture& t : textures)
            if (coin(rng)) t = t.with_sampler(random_sampler(rng, t.wrap_s(), t.wrap_t()));
    Material m;
    m.base_color_factor = {uni(rng), uni(rng), uni(rng), uni(rng)};
    m.metallic_factor = 1.5f * uni(rng) - 0.2f;  // the clamps to [0, 1] matter
    m.roughness_factor = 1.5f * uni(rng) - 0.2f;
    m.emissive_factor = {uni(rng), uni(rng), uni(rng)};
    m.normal_scale = 2.0f * sym(rng);
    m.occlusion_strength = uni(rng);
    m.ior = 1.2f + uni(rng);
    m.alpha_mode = coin(rng) ? AlphaMode::Mask : AlphaMode::Opaque;
    m.alpha_cutoff = uni(rng);
    BoundMaterial bm;
    bm.m = &m;
    if (extended) {
        std::uint8_t* sets[7] = {&bm.uv.base_color, &bm.uv.metallic_roughness, &bm.uv.roughness, &bm.uv.metallic,
                                 &bm.uv.normal, &bm.uv.occlusion, &bm.uv.emissive};
        for (std::uint8_t* set : sets) *set = std::uint8_t(coin(rng));
        if (coin(rng)) m.alpha_mode = AlphaMode::Blend;
    }
    const Texture** slots[7] = {&bm.base_color, &bm.metallic_roughness, &bm.roughness, &bm.metallic,
                                &bm.normal, &bm.occlusion, &bm.emissive};
    for (int i = 0; i < 7; ++i)
        if (coin(rng)) *slots[i] = &textures[std::size_t(i)];
    // glTF's occlusion often lives in R of the metal-roughness map: one texture bound twice.
    if (bm.metallic_roughness && coin(rng)) bm.occlusion = bm.metallic_roughness;

    // A block of surface points; a few lanes with degenerate normals or
    // tangents exercise the fallbacks.
    Packing<N> pk(rng);
    const bool front = coin(rng);
    // 0-11 the narrow layout, 12-13 UV set 1, 14-17 the colour.
    alignas(64) float var[18][kBlockLanes];
    const float du = 0.05f * sym(rng), dv = 0.05f * sym(rng);
    const float u0 = 2.0f * sym(rng), v0 = 2.0f * sym(rng);
    const float du1 = extended ? 0.2f * sym(rng) : 0.0f, dv1 = extended ? 0.01f * sym(rng) : 0.0f;
    for (int l = 0; l < kBlockLanes; ++l) {
        var[12][l] = var[13][l] = 0.0f;
        for (int k = 14; k < 18; ++k) var[k][l] = 1.0f;
        if (extended) {
            var[12][l] = 1.0f + du1 * float(lane_x(l)) + 0.01f * sym(rng);
            var[13][l] = -0.5f + dv1 * float(lane_y(l)) + 0.01f * sym(rng);
            for (int k = 14; k < 18; ++k) var[k][l] = 1.2f * uni(rng);
        }
        for (int k = 0; k < 3; ++k) var[k][l] = 3.0f * sym(rng);
        for (int k = 3; k < 6; ++k) var[k][l] = sym(rng);
        var[6][l] = u0 + du * float(lane_x(l)) + 0.01f * sym(rng);
        var[7][l] = v0 + dv * float(lane_y(l)) + 0.01f * sym(rng);
        for (int k = 8; k < 11; ++k) var[k][l] = sym(rng);
        var[11][l] = coin(rng) ? 1.0f : -1.0f;
        switch (pick(rng)) {
        case 0: var[3][l] = var[4][l] = var[5][l] = 0.0f; break;      // no normal
        case 1: for (int k = 0; k < 3; ++k) var[8 + k][l] = var[3 + k][l]; break;  // T parallel to N
        case 2: var[8][l] = var[9][l] = var[10][l] = 0.0f; break;     // no tangent
        default: break;
        }
    }
    alignas(64) float packed[18][kBlockLanes];
    for (int k = 0; k < 18; ++k)
        for (int l = 0; l < N; ++l) packed[k][l] = var[k][pk.lane[l]];
    SurfaceLanes s;
    s.Px = packed[0]; s.Py = packed[1]; s.Pz = packed[2];
    s.Nx = packed[3]; s.Ny = packed[4]; s.Nz = packed[5];
    s.u = packed[6]; s.v = packed[7];
    s.Tx = packed[8]; s.Ty = packed[9]; s.Tz = packed[10]; s.Tw = packed[11];
    s.quad = pk.quad;
    for (int q = 0; q < 4; ++q) {
        const int l = 4 * q;
        s.dudx[q] = var[6][l + 1] - var[6][l]; s.dvdx[q] = var[7][l + 1] - var[7][l];
        s.dudy[q] = var[6][l + 2] - var[6][l]; s.dvdy[q] = var[7][l + 2] - var[7][l];
        s.dudx_more[0][q] = var[12][l + 1] - var[12][l]; s.dvdx_more[0][q] = var[13][l + 1] - var[13][l];
        s.dudy_more[0][q] = var[12][l + 2] - var[12][l]; s.dvdy_more[0][q] = var[13][l + 2] - var[13][l];
    }
    s.back_facing = front ? 0u : 0xFFFFu;
    if (extended) {
        s.u_more[0] = packed[12]; s.v_more[0] = packed[13];
        s.Cr = packed[14]; s.Cg = packed[15]; s.Cb = packed[16]; s.Ca = packed[17];
    }

    // Planned by the call itself, in advance (as a draw does), or with a
    // plan of another binding (ignored): the same lanes.
    MaterialBlock mb;
    LookupPlan plan, other;
    plan_lookups(bm, plan);
    const BoundMaterial bare{&m};
    plan_lookups(bare, other);
    const int way = int(seed % 3);
    const std::uint32_t kill = sample_material_lanes<N>(bm, s, pk.live, mb, way == 0 ? nullptr : way == 1 ? &plan : &other);
    for (int l = 0; l < N; ++l) {
        if (!((pk.live >> l) & 1u)) continue;
        const int bl = pk.lane[l], q = bl & ~3;
        SurfacePoint sp;
        sp.P = {var[0][bl], var[1][bl], var[2][bl]};
        sp.N = {var[3][bl], var[4][bl], var[5][bl]};
        sp.uv = {var[6][bl], var[7][bl]};
        sp.T = {var[8][bl], var[9][bl], var[10][bl], var[11][bl]};
        sp.duv_dx = {var[6][q + 1] - var[6][q], var[7][q + 1] - var[7][q]};
        sp.duv_dy = {var[6][q + 2] - var[6][q], var[7][q + 2] - var[7][q]};
        sp.front_facing = front;
        if (extended) {
            sp.uv_more[0] = {var[12][bl], var[13][bl]};
            sp.duv_more_dx[0] = {var[12][q + 1] - var[12][q], var[13][q + 1] - var[13][q]};
            sp.duv_more_dy[0] = {var[12][q + 2] - var[12][q], var[13][q + 2] - var[13][q]};
            sp.has_color = true;
            sp.color = {var[14][bl], var[15][bl], var[16][bl], var[17][bl]};
        }
        const MaterialSample ms = sample_material(bm, sp);
        INFO("seed ", seed, " N ", N, " lane ", l, " (block lane ", bl, ")");
        const bool killed = m.alpha_mode == AlphaMode::Mask && !(ms.alpha >= m.alpha_cutoff);
        CHECK(((kill >> l) & 1u) == (killed ? 1u : 0u));
        CHECK(bits(mb.ar[l]) == bits(ms.albedo.r));
        CHECK(bits(mb.ag[l]) == bits(ms.albedo.g));
        CHECK(bits(mb.ab[l]) == bits(ms.albedo.b));
        CHECK(bits(mb.metallic[l]) == bits(ms.metallic));
        CHECK(bits(mb.roughness[l]) == bits(ms.roughness));
        CHECK(bits(mb.occlusion[l]) == bits(ms.occlusion));
        CHECK(bits(mb.er[l]) == bits(ms.emissive.r));
        CHECK(bits(mb.eg[l]) == bits(ms.emissive.g));
        CHECK(bits(mb.eb[l]) == bits(ms.emissive.b));
        CHECK(bits(mb.Nx[l]) == bits(ms.N.x));
        CHECK(bits(mb.Ny[l]) == bits(ms.N.y));
        CHECK(bits(mb.Nz[l]) == bits(ms.N.z));
        CHECK(bits(mb.Px[l]) == bits(sp.P.x));
        CHECK(bits(mb.ior) == bits(ms.ior));
        if (m.alpha_mode != AlphaMode::Opaque) CHECK(bits(mb.alpha[l]) == bits(ms.alpha));
    }
}

// A random PBR program (textured or not, alpha MASK or opaque) and random
// blocks for it.
struct ProgramFixture {
    Texture albedo, normal, orm;
    Material m;
    BoundMaterial bm;
    ShadingContext ctx;
    PbrProgram prog;

    ProgramFixture(std::mt19937& rng, BrdfModel model)
        : albedo(random_texture(rng, 32, 32, Wrap::Repeat, Wrap::Repeat)),
          normal(random_texture(rng, 32, 32, Wrap::Repeat, Wrap::Repeat)),
          orm(random_texture(rng, 16, 64, Wrap::MirroredRepeat, Wrap::ClampToEdge)) {
        std::uniform_real_distribution<float> uni(0.0f, 1.0f), sym(-1.0f, 1.0f);
        std::uniform_int_distribution<int> coin(0, 1);
        m.base_color_factor = {uni(rng), uni(rng), uni(rng), uni(rng)};
        m.metallic_factor = uni(rng);
        m.roughness_factor = uni(rng);
        m.alpha_mode = coin(rng) ? AlphaMode::Mask : AlphaMode::Opaque;
        m.alpha_cutoff = 0.3f * uni(rng);
        bm.m = &m;
        if (coin(rng)) {
            bm.base_color = &albedo;
            bm.normal = &normal;
            bm.metallic_roughness = &orm;
        }
        ctx.eye = {sym(rng), 2.0f, 5.0f};
        ctx.model = model;
        add_test_lights(ctx, rng);
        prog.material = &bm;
        prog.ctx = &ctx;
    }
    ProgramFixture(const ProgramFixture&) = delete;

    // Random varyings, uv with gradients `scale` times the usual (so that
    // blocks differ in level of detail), `live` lanes at random places.
    static void random_block(std::mt19937& rng, int live, float scale, FragmentBlock<kPbrVaryings>& in) {
        std::uniform_real_distribution<float> uni(0.0f, 1.0f), sym(-1.0f, 1.0f);
        std::uniform_int_distribution<int> coin(0, 1);
        for (int l = 0; l < kBlockLanes; ++l) {
            for (int k = 0; k < kPbrVaryings; ++k) in.var[k][l] = sym(rng);
            in.var[kVarUV][l] = 0.3f + scale * 0.02f * float(lane_x(l)) + 0.001f * sym(rng);
            in.var[kVarUV + 1][l] = 0.6f + scale * 0.03f * float(lane_y(l)) + 0.001f * sym(rng);
            in.z[l] = uni(rng);
        }
        std::vector<int> order(kBlockLanes);
        for (int l = 0; l < kBlockLanes; ++l) order[std::size_t(l)] = l;
        std::shuffle(order.begin(), order.end(), rng);
        in.mask = 0;
        for (int i = 0; i < live; ++i) in.mask |= 1u << order[std::size_t(i)];
        in.front_facing = coin(rng);
    }
};

// PbrProgram::fragment() on a block with a random coverage mask (so that it
// takes the 4-, 8- or 16-lane path) against sample_material() and
// shade_surface() lane by lane.
void check_program(std::uint32_t seed, BrdfModel model) {
    std::mt19937 rng(seed);
    std::uniform_int_distribution<int> count(1, 16);
    ProgramFixture f(rng, model);
    const BoundMaterial& bm = f.bm;
    const Material& m = f.m;
    FragmentBlock<kPbrVaryings> in;
    const int n = count(rng);
    ProgramFixture::random_block(rng, n, 1.0f, in);

    FragmentOut out;
    f.prog.fragment(in, out);
    MaterialLods lods;
    for (int l = 0; l < kBlockLanes; ++l) {
        if (!((in.mask >> l) & 1u)) continue;
        const SurfacePoint sp = PbrProgram::surface_point(in, l);
        lods = material_lods(bm, sp.duv_dx, sp.duv_dy);
        const MaterialSample ms = sample_material(bm, sp, lods);
        INFO("seed ", seed, " live ", n, " lane ", l);
        const bool killed = m.alpha_mode == AlphaMode::Mask && !(ms.alpha >= m.alpha_cutoff);
        CHECK(((out.kill >> l) & 1u) == (killed ? 1u : 0u));
        if (killed) continue;
        const glm::vec3 ref = shade_surface(ms, sp, f.ctx);
        CHECK(bits(out.r[l]) == bits(ref.r));
        CHECK(bits(out.g[l]) == bits(ref.g));
        CHECK(bits(out.b[l]) == bits(ref.b));
        CHECK(out.a[l] == 1.0f);
    }
    CHECK((out.kill & ~in.mask) == 0u);
}

// PbrProgram::fragment_batch() on up to kMaxBatchBlocks blocks (each its own
// facing, level of detail and coverage; some with centroid-moved lanes, whose
// derivatives come from centre_var) against fragment() on each block: every
// lane's output and every kill, bit for bit.
void check_batch(std::uint32_t seed) {
    std::mt19937 rng(seed);
    std::uniform_int_distribution<int> blocks_pick(1, kMaxBatchBlocks), coin(0, 3);
    std::uniform_real_distribution<float> scale_pick(0.2f, 40.0f);
    ProgramFixture f(rng, BrdfModel::Default);
    if (coin(rng) == 0) f.m.alpha_mode = AlphaMode::Blend;  // alpha comes back through the batch too
    const int count = blocks_pick(rng);
    std::vector<FragmentBlock<kPbrVaryings>> in(static_cast<std::size_t>(kMaxBatchBlocks));
    int budget = kBlockLanes - count;  // one live lane each, then the rest at random
    for (int b = 0; b < count; ++b) {
        std::uniform_int_distribution<int> extra(0, std::min(budget, kBlockLanes - 1));
        const int live = 1 + extra(rng);
        budget -= live - 1;
        FragmentBlock<kPbrVaryings>& B = in[std::size_t(b)];
        ProgramFixture::random_block(rng, live, scale_pick(rng), B);
        B.centroid_mask = 0;
        if (coin(rng) == 0) {  // a multisampled block: centroids moved the live lanes a little
            std::memcpy(B.centre_var, B.var, sizeof B.var);
            B.centroid_mask = B.mask;
            for (int l = 0; l < kBlockLanes; ++l)
                if ((B.mask >> l) & 1u) B.var[kVarUV][l] += 0.003f;
        }
    }
    std::vector<FragmentOut> batched(static_cast<std::size_t>(kMaxBatchBlocks)), alone(static_cast<std::size_t>(kMaxBatchBlocks));
    const FragmentBlock<kPbrVaryings>* ins[kMaxBatchBlocks];
    FragmentOut* outs[kMaxBatchBlocks];
    for (int b = 0; b < count; ++b) {
        ins[b] = &in[std::size_t(b)];
        outs[b] = &batched[std::size_t(b)];
        batched[std::size_t(b)].kill = 0;
        alone[std::size_t(b)].kill = 0;
        f.prog.fragment(in[std::size_t(b)], alone[std::size_t(b)]);
    }
    f.prog.fragment_batch(ins, outs, count);
    for (int b = 0; b < count; ++b) {
        const FragmentOut &x = batched[std::size_t(b)], &y = alone[std::size_t(b)];
        INFO("seed ", seed, " blocks ", count, " block ", b, " mask ", in[std::size_t(b)].mask);
        CHECK(x.kill == y.kill);
        for (int l = 0; l < kBlockLanes; ++l) {
            if (!((in[std::size_t(b)].mask >> l) & 1u)) continue;
            CHECK(bits(x.r[l]) == bits(y.r[l]));
            CHECK(bits(x.g[l]) == bits(y.g[l]));
            CHECK(bits(x.b[l]) == bits(y.b[l]));
            CHECK(bits(x.a[l]) == bits(y.a[l]));
        }
    }
}

#ifdef __AVX2__
// gather_texel_pairs() against the bytes: for W lanes of a C-channel texture,
// texel i's bytes and texel i + 1's, up to the chain's last texel (whose
// "next" lies in the spare bytes).
template <int W, int C>
void check_texel_pairs(std::mt19937& rng) {
    using V = Simd<W>;
    Image img;
    img.width = 37;
    img.height = 5;
    img.channels = C;
    img.pixels.resize(img.texel_count() * C);
    std::uniform_int_distribution<int> byte(0, 255);
    for (std::uint8_t& c : img.pixels) c = std::uint8_t(byte(rng));
    const Texture tex = Texture::from_image(std::move(img), Wrap::Repeat, Wrap::Repeat);
    const std::int32_t texels = std::int32_t(tex.level_offset(tex.levels() - 1)) + 1;
    const std::uint8_t* base = tex.unorm8_data();
    std::uniform_int_distribution<std::int32_t> any(0, texels - 1);
    for (int iter = 0; iter < 200; ++iter) {
        alignas(32) std::int32_t idx[W];
        for (int l = 0; l < W; ++l) idx[l] = iter % 4 == 0 && l == iter % W ? texels - 1 : any(rng);
        typename V::I left, right;
        sample_lanes_detail::gather_texel_pairs<V, C>(base, idx, left, right);
        alignas(32) std::uint32_t got_left[W], got_right[W];
        std::memcpy(got_left, &left, sizeof got_left);
        std::memcpy(got_right, &right, sizeof got_right);
        for (int l = 0; l < W; ++l) {
            for (int c = 0; c < C; ++c) {
                INFO("W ", W, " C ", C, " lane ", l, " texel ", idx[l], " channel ", c);
                CHECK(((got_left[l] >> (8 * c)) & 0xFFu) == base[std::size_t(idx[l]) * C + c]);
                if (idx[l] + 1 < texels)
                    CHECK(((got_right[l] >> (8 * c)) & 0xFFu) == base[std::size_t(idx[l] + 1) * C + c]);
            }
        }
    }
}
#endif

} // namespace

TEST_SUITE("sample_lanes") {
#ifdef __AVX2__
TEST_CASE("texel pairs gathered in one read per lane equal the texels' bytes") {
    std::mt19937 rng(11);
    check_texel_pairs<8, 1>(rng);
    check_texel_pairs<8, 2>(rng);
    check_texel_pairs<8, 3>(rng);
    check_texel_pairs<8, 4>(rng);
    check_texel_pairs<4, 1>(rng);
    check_texel_pairs<4, 2>(rng);
    check_texel_pairs<4, 3>(rng);
    check_texel_pairs<4, 4>(rng);
}
#endif

// A uv derivative: ordinary sizes over many octaves, zero, subnormal,
// huge (squares overflow), infinite or NaN, of either sign.
float random_derivative(std::mt19937& rng) {
    std::uniform_real_distribution<float> uni(-1.0f, 1.0f), octave(-40.0f, 40.0f);
    std::uniform_int_distribution<int> pick(0, 17);
    const float near_min = std::sqrt(std::numeric_limits<float>::min()), near_max = std::sqrt(std::numeric_limits<float>::max());
    switch (pick(rng)) {
    case 16: return near_min * uni(rng) * 1.5f / float(1 + rng() % 2048);  // rho2 near the smallest normal
    case 17: return near_max * uni(rng) * 1.5f / float(1 + rng() % 2048);  // rho2 near overflow
    case 0: return std::numeric_limits<float>::quiet_NaN();
    case 1: return std::numeric_limits<float>::infinity();
    case 2: return -std::numeric_limits<float>::infinity();
    case 3: return 0.0f;
    case 4: return -0.0f;
    case 5: return std::numeric_limits<float>::denorm_min() * float(1 + (rng() % 1000));
    case 6: return 1e30f * uni(rng);
    case 7: return std::ldexp(1.0f, int(octave(rng)));  // a power of two: an integer lambda
    default: return uni(rng) * std::exp2(octave(rng));
    }
}

TEST_CASE("quad_lods equals Texture::lod bit for bit on the quads asked for") {
    std::mt19937 rng(7);
    long wrong = 0, cases[4] = {};
    const int sizes[][2] = {{1, 1}, {64, 64}, {1024, 1024}, {2048, 512}, {3, 7000}};
    for (const auto& wh : sizes) {
        const Texture tex = random_texture(rng, wh[0], wh[1], Wrap::Repeat, Wrap::Repeat);
        for (int round = 0; round < 4000; ++round) {
            float d[4][kMaxQuadSlots];
            for (auto& row : d)
                for (float& x : row) x = random_derivative(rng);
            const std::uint32_t quads = rng() & ((1u << kMaxQuadSlots) - 1u);
            float lambda[kMaxQuadSlots];
            for (float& x : lambda) x = 12345.0f;
            quad_lods<>(tex, d[0], d[1], d[2], d[3], quads, lambda);
            for (int q = 0; q < kMaxQuadSlots; ++q) {
                if (!((quads >> q) & 1u)) continue;
                const float ref = tex.lod(d[0][q], d[1][q], d[2][q], d[3][q]);
                ++cases[ref == 0.0f ? 0 : (ref == -64.0f ? 1 : (ref == 64.0f ? 2 : 3))];
                if (bits(lambda[q]) != bits(ref)) {
                    INFO("size " << wh[0] << "x" << wh[1] << " quad " << q << ": " << d[0][q] << " " << d[1][q] << " "
                                 << d[2][q] << " " << d[3][q]);
                    CHECK(lambda[q] == ref);
                    ++wrong;
                }
            }
        }
    }
    CHECK(wrong == 0);
    // Every branch of Texture::lod was taken many times: NaN (or an integer 0), below the smallest normal, infinite, ordinary.
    for (long n : cases) CHECK(n > 1000);
}

TEST_CASE("block trilinear sampling equals Texture::sample_trilinear bit for bit") {
    for (std::uint32_t seed = 1; seed <= 3000; ++seed) {
        check_sampler<16>(seed);
        check_sampler<8>(seed);
        check_sampler<4>(seed);
    }
}

TEST_CASE("block sampling with glTF filters equals Texture::sample_lod bit for bit") {
    for (std::uint32_t seed = 1; seed <= 3000; ++seed) {
        check_sampler<16>(seed, true);
        check_sampler<8>(seed, true);
        check_sampler<4>(seed, true);
    }
    // Every (wrap s, wrap t, mag, min) combination, each on many blocks.
    const Wrap wraps[3] = {Wrap::Repeat, Wrap::ClampToEdge, Wrap::MirroredRepeat};
    std::uint32_t seed = 100000;
    for (Wrap s : wraps)
        for (Wrap t : wraps)
            for (Filter mag : kFilters)
                for (MinFilter min : kMinFilters) {
                    const SamplerState st{s, t, mag, min};
                    for (int i = 0; i < 40; ++i, ++seed) {
                        check_sampler<16>(seed, true, &st);
                        check_sampler<4>(seed, true, &st);
                    }
                }
}

TEST_CASE("material lanes with samplers, UV set 1 and vertex colours equal sample_material bit for bit") {
    for (std::uint32_t seed = 1; seed <= 1500; ++seed) {
        check_material<16>(seed, true);
        check_material<8>(seed, true);
        check_material<4>(seed, true);
    }
}

TEST_CASE("a 512x512 texture: every level, uniform and mixed levels across quads") {
    std::mt19937 rng(7);
    const Texture tex = random_texture(rng, 512, 512, Wrap::Repeat, Wrap::MirroredRepeat);
    std::uniform_real_distribution<float> uni(-2.0f, 2.0f), lam(0.0f, 10.0f);
    for (int iter = 0; iter < 500; ++iter) {
        alignas(64) float u[kBlockLanes], v[kBlockLanes];
        for (int l = 0; l < kBlockLanes; ++l) { u[l] = uni(rng); v[l] = uni(rng); }
        float lambda[4];
        const float shared = lam(rng);
        for (float& x : lambda) x = iter % 2 ? shared : lam(rng);
        TrilinearLanes at;
        prepare_trilinear_lanes<16>(tex, u, v, lambda, nullptr, 0xFFFFu, at);
        TexelLanes out;
        fetch_trilinear_lanes<16>(tex, at, out);
        for (int l = 0; l < kBlockLanes; ++l) {
            const glm::vec4 ref = tex.sample_trilinear(u[l], v[l], lambda[l / 4]);
            CHECK(bits(out.r[l]) == bits(ref.r));
            CHECK(bits(out.a[l]) == bits(ref.a));
        }
    }
}

TEST_CASE("the lit fragment path (4, 8 or 16 lanes) equals the scalar functions bit for bit") {
    for (std::uint32_t seed = 1; seed <= 1500; ++seed) {
        check_program(seed, BrdfModel::Default);
        check_program(seed, BrdfModel::Gltf);
    }
}

TEST_CASE("a batch of sparse blocks shades each block as fragment() does, bit for bit") {
    for (std::uint32_t seed = 1; seed <= 1500; ++seed) check_batch(seed);
}

TEST_CASE("block material sampling equals sample_material bit for bit") {
    for (std::uint32_t seed = 1; seed <= 1000; ++seed) {
        check_material<16>(seed);
        check_material<8>(seed);
        check_material<4>(seed);
    }
}
}

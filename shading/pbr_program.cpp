// The PBR fragment stage; see pbr_program.h. One call per 4x4 block, or per
// batch of sparse blocks (raster/fragment.h). The lit image takes the lane
// paths: a block's 16 lanes in place (shade_block), or the live lanes of one
// or several blocks packed (shade_packed); debug views and conductor materials
// loop over the lanes with the scalar sample_material() and shade_surface()
// inlined, the functions the stepper explains pixels with.
#include "shading/pbr_program.h"

#include "shading/light_block.h"
#include "shading/material_lanes.h"

#include <algorithm>
#include <cmath>
#include <cstring>

#if defined(__AVX2__)
#include <immintrin.h>
#endif

namespace prast {

namespace {

glm::vec3 sum_lobes(const MaterialSample& ms, const SurfacePoint& sp, const ShadingContext& ctx,
                    bool specular) {
    BrdfInputs bi = brdf_inputs(ms, sp, ctx);
    glm::vec3 sum(0.0f);
    for (const ShadingLight& L : ctx.lights) {
        glm::vec3 radiance;
        light_at(L, sp.P, bi.l, radiance);
        radiance *= light_visibility(L, sp.P, ms.N_geom);
        BrdfTerms t = evaluate_brdf(bi, ctx.model);
        sum += (specular ? t.specular : t.diffuse) * radiance * t.NoL;
        if (specular && t.coat) sum += glm::vec3(t.coat_specular) * radiance * t.coat_NoL;  // the clear coat's lobe
    }
    // The split sum's lobe of the environment (not in reference mode: the
    // integral does not split into lobes).
    if (ctx.env && ctx.ibl == IblMode::SplitSum) {
        const IblTerms t = ibl_terms(ms, sp, ctx);
        sum += specular ? t.specular : t.diffuse;
        if (specular && t.coat) sum += t.coat_specular;
    }
    return sum;
}

BrdfTerms first_light_terms(const MaterialSample& ms, const SurfacePoint& sp, const ShadingContext& ctx) {
    BrdfInputs bi = brdf_inputs(ms, sp, ctx);
    if (ctx.lights.empty()) return BrdfTerms{};
    glm::vec3 radiance;
    light_at(ctx.lights[0], sp.P, bi.l, radiance);
    return evaluate_brdf(bi, ctx.model);
}

// The varyings' arrays as the lit path's surface (the wide layout's UV sets
// and colour too: colour only when the mesh has one).
// The position-and-normal layout's tangents and UVs: surface_point()'s
// constants, as lanes (packed rows hold up to kBlockLanes + 8).
alignas(64) constexpr float kZeroLanes[kBlockLanes + 8] = {};
alignas(64) constexpr float kOneLanes[kBlockLanes + 8] = {1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1,
                                                          1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1};

template <int NV>
void set_surface(SurfaceLanes& s, const float* const* var, bool has_color) {
    s.Px = var[kVarP]; s.Py = var[kVarP + 1]; s.Pz = var[kVarP + 2];
    s.Nx = var[kVarN]; s.Ny = var[kVarN + 1]; s.Nz = var[kVarN + 2];
    if constexpr (NV == kPbrVaryingsLite) {
        s.Tx = kOneLanes; s.Ty = kZeroLanes; s.Tz = kZeroLanes; s.Tw = kOneLanes;
        s.u = kZeroLanes; s.v = kZeroLanes;
    } else {
        s.Tx = var[kVarT]; s.Ty = var[kVarT + 1]; s.Tz = var[kVarT + 2]; s.Tw = var[kVarT + 3];
        s.u = var[kVarUV]; s.v = var[kVarUV + 1];
    }
    if constexpr (NV == kPbrVaryingsExt) {
        for (int set = 1; set < kMaxUvSets; ++set) {
            s.u_more[set - 1] = var[var_uv(set)];
            s.v_more[set - 1] = var[var_uv(set) + 1];
        }
        if (has_color) {
            s.Cr = var[kVarColor]; s.Cg = var[kVarColor + 1]; s.Cb = var[kVarColor + 2]; s.Ca = var[kVarColor + 3];
        }
    } else {
        (void)has_color;
    }
}

// Quad q's derivatives of UV set 0, from lane l of `in`, into slot.
template <int NV>
inline void set_derivatives(SurfaceLanes& s, const FragmentBlock<NV>& in, int l, int slot) {
    if constexpr (NV == kPbrVaryingsLite) {
        s.dudx[slot] = s.dvdx[slot] = s.dudy[slot] = s.dvdy[slot] = 0.0f;
        (void)in; (void)l;
    } else {
        s.dudx[slot] = in.ddx(kVarUV, l); s.dvdx[slot] = in.ddx(kVarUV + 1, l);
        s.dudy[slot] = in.ddy(kVarUV, l); s.dvdy[slot] = in.ddy(kVarUV + 1, l);
    }
}

// Quad q's derivatives of the UV sets past 0, from lane l of `in`, into slot.
template <int NV>
inline void set_more_derivatives(SurfaceLanes& s, const FragmentBlock<NV>& in, int l, int slot) {
    if constexpr (NV == kPbrVaryingsExt) {
        for (int set = 1; set < kMaxUvSets; ++set) {
            const int k = var_uv(set);
            s.dudx_more[set - 1][slot] = in.ddx(k, l); s.dvdx_more[set - 1][slot] = in.ddx(k + 1, l);
            s.dudy_more[set - 1][slot] = in.ddy(k, l); s.dvdy_more[set - 1][slot] = in.ddy(k + 1, l);
        }
    } else {
        (void)s; (void)in; (void)l; (void)slot;
    }
}

// The lanes of mask m in order, as bytes, into out[0, 16) (zero past them).
#if defined(__AVX2__) && defined(__BMI2__)
using LaneList = __m128i;
// Also returned in a register: read back from memory at once, two 8-byte
// stores would stall the 16-byte load (no store forwarding across them).
inline __m128i list_lanes(std::uint32_t m, std::uint8_t* out) {
    // Nibble l of `live` is 0xF for a live lane l; pext gathers those lanes'
    // numbers from the nibble sequence 0..15, and pdep spreads them to bytes.
    const std::uint64_t live = _pdep_u64(m, 0x1111111111111111ull) * 0xF;
    const std::uint64_t lanes = _pext_u64(0xFEDCBA9876543210ull, live);
    const std::uint64_t lo = _pdep_u64(lanes, 0x0F0F0F0F0F0F0F0Full);
    const std::uint64_t hi = _pdep_u64(lanes >> 32, 0x0F0F0F0F0F0F0F0Full);
    const __m128i v = _mm_set_epi64x(std::int64_t(hi), std::int64_t(lo));
    _mm_storeu_si128(reinterpret_cast<__m128i*>(out), v);
    return v;
}
#else
struct LaneList {};
inline void list_lanes(std::uint32_t m, std::uint8_t* out) {
    std::memset(out, 0, 16);
    for (int n = 0; m; m &= m - 1) out[n++] = std::uint8_t(__builtin_ctz(m));
}
#endif

#if defined(__AVX2__) && defined(__BMI2__)
// 0xFF in byte l (of eight) for each set bit l of m.
inline std::uint64_t byte_mask(std::uint32_t m) { return _pdep_u64(m & 0xFFu, 0x0101010101010101ull) * 0xFF; }

// Block lanes (eight, from lane h0) that are live in m, as int32 masks, and
// for each its packed position: `next` for the first live one, then on.
inline void unpack_positions(std::uint32_t m, int h0, int next, __m256i& live, __m256i& pos) {
    const std::uint64_t bytes = byte_mask(m >> h0);
    const std::uint64_t seq = 0x0706050403020100ull + std::uint64_t(next) * 0x0101010101010101ull;
    live = _mm256_cvtepi8_epi32(_mm_cvtsi64_si128(std::int64_t(bytes)));
    pos = _mm256_cvtepu8_epi32(_mm_cvtsi64_si128(std::int64_t(_pdep_u64(seq, bytes))));
}

// The eight packed values src[pos] (pos < 16; src holds 8 or 16 floats).
template <int N>
inline __m256 take_packed(const float* src, __m256i pos) {
    const __m256 lo = _mm256_permutevar8x32_ps(_mm256_load_ps(src), pos);
    if constexpr (N <= 8) return lo;
    const __m256 hi = _mm256_permutevar8x32_ps(_mm256_load_ps(src + 8), pos);
    return _mm256_blendv_ps(lo, hi, _mm256_castsi256_ps(_mm256_cmpgt_epi32(pos, _mm256_set1_epi32(7))));
}
#endif

// packed[k][i] = in[b]->var[k][lane[i]] for the packed lanes i in
// [first[b], first[b + 1]) of each block b, then the spare lanes up to N
// repeat the last live one. Rows hold N + 8 floats: with AVX2 each block's
// lanes are stored eight at a time, spilling into the next block's (written
// after) or the spare lanes (written last).
// With AVX2 and BMI2 the lanes come as each block's list_lanes() register
// (block_lanes), not read back from `lane`.
template <int N, int NV>
void pack_lanes(const FragmentBlock<NV>* const* in, int count, const std::uint8_t* first,
                [[maybe_unused]] const std::uint8_t* lane, [[maybe_unused]] const LaneList* block_lanes,
                float (*packed)[N + 8]) {
    const int n = first[count];
#if defined(__AVX2__) && defined(__BMI2__)
    for (int b = 0; b < count; ++b) {
        __m128i lanes = block_lanes[b];
        for (int j = first[b]; j < first[b + 1]; j += 8, lanes = _mm_srli_si128(lanes, 8)) {
            // Both halves of each varying permuted, then blended. Past the
            // block's lanes the bytes are zero: any lane will do there.
            const __m256i idx = _mm256_cvtepu8_epi32(lanes);
            const __m256 from_high = _mm256_castsi256_ps(_mm256_cmpgt_epi32(idx, _mm256_set1_epi32(7)));
            for (int k = 0; k < NV; ++k) {
                const __m256 lo = _mm256_permutevar8x32_ps(_mm256_load_ps(in[b]->var[k]), idx);
                const __m256 hi = _mm256_permutevar8x32_ps(_mm256_load_ps(in[b]->var[k] + 8), idx);
                _mm256_storeu_ps(packed[k] + j, _mm256_blendv_ps(lo, hi, from_high));
            }
        }
    }
#else
    for (int b = 0; b < count; ++b)
        for (int i = first[b]; i < first[b + 1]; ++i)
            for (int k = 0; k < NV; ++k) packed[k][i] = in[b]->var[k][lane[i]];
#endif
    if (n == N) return;
#if defined(__AVX2__)
    // Lanes n.. take lane n - 1's value, eight at a time (stored over, not
    // blended: reading back what the overlapping stores above wrote stalls).
    for (int k = 0; k < NV; ++k) {
        const __m256 last = _mm256_broadcast_ss(&packed[k][n - 1]);
        for (int h = n; h < N; h += 8) _mm256_storeu_ps(packed[k] + h, last);
    }
#else
    for (int k = 0; k < NV; ++k)
        for (int i = n; i < N; ++i) packed[k][i] = packed[k][n - 1];
#endif
}

} // namespace

// The lit path (material_lanes.h, then light_block.h) for all 16 lanes of a
// block in place. Each lane does the float operations of sample_material()
// and shade_surface().
template <int NV>
void PbrProgramT<NV>::shade_block(const FragmentBlock<kVaryings>& in, FragmentOut& out) const {
    SurfaceLanes s;
    const float* var[kVaryings];
    for (int k = 0; k < kVaryings; ++k) var[k] = in.var[k];
    set_surface<NV>(s, var, has_color());
    for (int q = 0; q < 4; ++q) {
        const int l = 4 * q;  // the quad's derivatives, as surface_point() takes them
        set_derivatives<NV>(s, in, l, q);
        set_more_derivatives<NV>(s, in, l, q);
    }
    s.back_facing = in.front_facing ? 0u : 0xFFFFu;

    MaterialBlock mb;
    out.kill = sample_material_lanes<kBlockLanes>(*material, s, in.mask, mb, plan);
    RadianceBlock rb;
    shade_block_lanes<kBlockLanes>(mb, *ctx, rb);
    const bool blend = material->m->alpha_mode == AlphaMode::Blend;
    for (int l = 0; l < kBlockLanes; ++l) {
        out.r[l] = rb.r[l]; out.g[l] = rb.g[l]; out.b[l] = rb.b[l]; out.a[l] = blend ? mb.alpha[l] : 1.0f;
    }
}

// The lit path for the live lanes of `count` blocks, packed into the first N
// (4, 8 or 16): half the blocks of a typical frame have at most 4 live lanes
// (small triangles, edges), and a lane costs the same whether live or not.
// Each (block, quad) with a live lane gets a quad slot of its own, with its
// derivatives; the spare packed lanes repeat the last live lane (valid
// inputs, results dropped).
template <int NV>
template <int N>
void PbrProgramT<NV>::shade_packed(const FragmentBlock<kVaryings>* const* in, FragmentOut* const* out, int count) const {
    static_assert(N == 4 || N == 8 || N == 16, "packed calls have 4, 8 or 16 lanes");
    SurfaceLanes s;
    // lane[i], quad[i]: packed lane i's block lane and quad slot; each block
    // writes 16 bytes from its first lane on, the next block overwriting the excess.
    std::uint8_t lane[kBlockLanes + 16], quad[kBlockLanes + 16], first[kMaxBatchBlocks + 1];
    LaneList block_lanes[kMaxBatchBlocks];  // [0, count) set below
    int n = 0, slots = 0;
    for (int b = 0; b < count; ++b) {
        const FragmentBlock<kVaryings>& B = *in[b];
        std::uint32_t slot_of = 0;  // byte q: quad q's slot
        // Without branches (which quads are live is a coin toss at the
        // edges): a quad without a live lane writes its derivatives to the
        // spare slot kMaxQuadSlots, and no lane names its slot.
        for (int q = 0; q < 4; ++q) {
            const bool quad_live = B.quad_live(q);
            const int at = quad_live ? slots : kMaxQuadSlots;
            slot_of |= std::uint32_t(slots) << (8 * q);
            set_derivatives<NV>(s, B, 4 * q, at);
            set_more_derivatives<NV>(s, B, 4 * q, at);
            slots += quad_live;
        }
        first[b] = std::uint8_t(n);
        const int nb = __builtin_popcount(B.mask);
#if defined(__AVX2__) && defined(__BMI2__)
        // quad[i] = slot_of[lane[i] / 4], sixteen at a time.
        block_lanes[b] = list_lanes(B.mask, lane + n);
        const __m128i q = _mm_and_si128(_mm_srli_epi16(block_lanes[b], 2), _mm_set1_epi8(3));
        _mm_storeu_si128(reinterpret_cast<__m128i*>(quad + n), _mm_shuffle_epi8(_mm_cvtsi32_si128(int(slot_of)), q));
#else
        list_lanes(B.mask, lane + n);
        for (int i = n; i < n + nb; ++i) quad[i] = std::uint8_t(slot_of >> (8 * (lane[i] >> 2)));
#endif
        if (!B.front_facing) s.back_facing |= ((1u << nb) - 1u) << n;
        n += nb;
    }
    first[count] = std::uint8_t(n);
    const std::uint32_t live = (1u << n) - 1u;
    for (int l = n; l < N; ++l) quad[l] = quad[n - 1];
    s.back_facing |= ((s.back_facing >> (n - 1)) & 1u) * (((1u << N) - 1u) & ~live);

    alignas(64) float packed[kVaryings][N + 8];
    const float* var[kVaryings];
    pack_lanes<N, NV>(in, count, first, lane, block_lanes, packed);
    for (int k = 0; k < kVaryings; ++k) var[k] = packed[k];
    set_surface<NV>(s, var, has_color());
    s.quad = quad;

    MaterialBlock mb;
    const std::uint32_t kill = sample_material_lanes<N>(*material, s, live, mb, plan);
    RadianceBlock rb;
    shade_block_lanes<N>(mb, *ctx, rb);

    // Back to each block's lanes (0, 0, 0, 1 in its dead lanes). Alpha: the
    // blend weight of BLEND materials (docs/shadows-and-transparency.md), 1 otherwise.
    const bool blend = material->m->alpha_mode == AlphaMode::Blend;
    for (int b = 0; b < count; ++b) {
        FragmentOut& o = *out[b];
        const int nb = first[b + 1] - first[b];
#if defined(__AVX2__) && defined(__BMI2__)
        const std::uint32_t m = in[b]->mask;
        o.kill = _pdep_u32((kill >> first[b]) & ((1u << nb) - 1u), m);
        int next = first[b];
        for (int h = 0; h < kBlockLanes; h += 8) {
            __m256i live_lanes, pos;
            unpack_positions(m, h, next, live_lanes, pos);
            next += __builtin_popcount((m >> h) & 0xFFu);
            const __m256 keep = _mm256_castsi256_ps(live_lanes);
            _mm256_store_ps(o.r + h, _mm256_and_ps(take_packed<N>(rb.r, pos), keep));
            _mm256_store_ps(o.g + h, _mm256_and_ps(take_packed<N>(rb.g, pos), keep));
            _mm256_store_ps(o.b + h, _mm256_and_ps(take_packed<N>(rb.b, pos), keep));
            _mm256_store_ps(o.a + h, blend ? _mm256_blendv_ps(_mm256_set1_ps(1.0f), take_packed<N>(mb.alpha, pos), keep)
                                           : _mm256_set1_ps(1.0f));
        }
#else
        std::fill(o.r, o.r + kBlockLanes, 0.0f);
        std::fill(o.g, o.g + kBlockLanes, 0.0f);
        std::fill(o.b, o.b + kBlockLanes, 0.0f);
        std::fill(o.a, o.a + kBlockLanes, 1.0f);
        o.kill = 0;
        for (int i = first[b]; i < first[b] + nb && i < N; ++i) {  // (i < N always: for the compiler)
            const int l = lane[i];
            o.r[l] = rb.r[i]; o.g[l] = rb.g[i]; o.b[l] = rb.b[i]; o.a[l] = blend ? mb.alpha[i] : 1.0f;
            o.kill |= ((kill >> i) & 1u) << l;
        }
#endif
    }
}

template <int NV>
bool PbrProgramT<NV>::lit_lanes() const {
    const bool reference = ctx->env && ctx->ibl == IblMode::Reference;
    // Layered materials (KHR_materials_specular, _clearcoat) shade lane by
    // lane with the scalar code, as conductors do.
    return (view == DebugView::None || view == DebugView::Tiles) && material->m->conductor == Conductor::None &&
           !material->m->layered() && !reference;
}

template <int NV>
void PbrProgramT<NV>::fragment_batch(const FragmentBlock<kVaryings>* const* in, FragmentOut* const* out,
                                int count) const {
    if (!lit_lanes()) {
        for (int b = 0; b < count; ++b) fragment(*in[b], *out[b]);
        return;
    }
    shade_packed_lanes(in, out, count);
}

// shade_packed() with the fewest lanes that hold the blocks' live ones.
template <int NV>
void PbrProgramT<NV>::shade_packed_lanes(const FragmentBlock<kVaryings>* const* in, FragmentOut* const* out,
                                    int count) const {
    int live = 0;
    for (int b = 0; b < count; ++b) live += __builtin_popcount(in[b]->mask);
    if (live > kBlockLanes) {  // more than one call's lanes: not a batch the rasterizer makes
        for (int b = 0; b < count; ++b) fragment(*in[b], *out[b]);
        return;
    }
    if (live > 8) this->template shade_packed<16>(in, out, count);
    else if (live > 4) this->template shade_packed<8>(in, out, count);
    else this->template shade_packed<4>(in, out, count);
}

template <int NV>
void PbrProgramT<NV>::fragment(const FragmentBlock<kVaryings>& in, FragmentOut& out) const {
    const Material& m = *material->m;
    // The lit path samples the material and lights the lanes together, packed
    // when few are live; debug views, conductor and layered materials and the
    // reference integral of the environment go lane by lane.
    if (lit_lanes()) {
        if (__builtin_popcount(in.mask) > 8) {
            shade_block(in, out);
        } else {
            const FragmentBlock<kVaryings>* b = &in;
            FragmentOut* o = &out;
            shade_packed_lanes(&b, &o, 1);
        }
        return;
    }

    const bool alpha_mask = m.alpha_mode == AlphaMode::Mask;
    const bool colored = has_color();
    MaterialLods lods;
    for (int l = 0; l < kBlockLanes; ++l) {
        out.r[l] = 0.0f; out.g[l] = 0.0f; out.b[l] = 0.0f; out.a[l] = 1.0f;
        if (!(in.mask & (1u << l))) continue;
        SurfacePoint sp = surface_point(in, l, colored);
        // The quad's lanes share derivatives, hence levels of detail: compute
        // them at the first live lane of each quad.
        if (!(in.mask & (0xFu << (l & ~3)) & ((1u << l) - 1)))
            lods = material_lods(*material, sp);
        MaterialSample ms = sample_material(*material, sp, lods);
        if (alpha_mask && !(ms.alpha >= m.alpha_cutoff)) {
            out.kill |= 1u << l;
            continue;
        }
        glm::vec3 c;
        switch (view) {
        case DebugView::None:
        case DebugView::Tiles:  // lit image; the tile overlay is drawn afterwards
            c = shade_surface(ms, sp, *ctx);
            break;
        case DebugView::Albedo: c = ms.albedo; break;
        case DebugView::Normal: c = ms.N * 0.5f + 0.5f; break;
        case DebugView::Roughness: c = glm::vec3(ms.roughness); break;
        case DebugView::Metallic: c = glm::vec3(ms.metallic); break;
        case DebugView::Uv: c = glm::vec3(sp.uv - glm::floor(sp.uv), 0.0f); break;
        case DebugView::Depth: {
            float n = near_plane, f = far_plane;
            float z_ndc = in.z[l] * 2.0f - 1.0f;
            float d = 2.0f * n * f / (f + n - z_ndc * (f - n));
            c = glm::vec3(1.0f - glm::clamp((d - n) / (f - n), 0.0f, 1.0f));
            break;
        }
        case DebugView::Overdraw: c = glm::vec3(1.0f); break;  // counted with additive blending
        case DebugView::Ndf: c = glm::vec3(first_light_terms(ms, sp, *ctx).D); break;
        case DebugView::Fresnel: c = first_light_terms(ms, sp, *ctx).F; break;
        case DebugView::Geometry: c = glm::vec3(first_light_terms(ms, sp, *ctx).G); break;
        case DebugView::Diffuse: c = sum_lobes(ms, sp, *ctx, false); break;
        case DebugView::Specular: c = sum_lobes(ms, sp, *ctx, true); break;
        case DebugView::Irradiance: c = ctx->env ? ctx->env->irradiance(ms.N) : glm::vec3(0.0f); break;
        }
        out.r[l] = c.r; out.g[l] = c.g; out.b[l] = c.b;
        if (m.alpha_mode == AlphaMode::Blend) out.a[l] = ms.alpha;
    }
}

template struct PbrProgramT<kPbrVaryings>;
template struct PbrProgramT<kPbrVaryingsExt>;
template struct PbrProgramT<kPbrVaryingsLite>;

} // namespace prast

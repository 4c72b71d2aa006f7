// plan_lookups() of material_lanes.h: once per bound material and frame
// (SceneRenderer), or once per call of the lanes given no plan. Compiled
// once, for the default instruction set, so the AVX-512 copy of the lanes
// shares no inline copy of it (tests/check_isa.sh).
#include "shading/material_lanes.h"

namespace prast {

void plan_lookups(const BoundMaterial& bm, LookupPlan& p) {
    constexpr int kMaps = LookupPlan::kMaps;
    const Material& m = *bm.m;
    const Texture* maps[kMaps];
    material_lanes_detail::lane_maps(bm, maps);
    const bool alpha_read = m.alpha_mode == AlphaMode::Mask || m.alpha_mode == AlphaMode::Blend;
    const std::uint8_t used[kMaps] = {std::uint8_t(alpha_read ? 0xF : 0x7), 0x6, 0x1, 0x1, 0x7, 0x1, 0x7};
    std::uint64_t uv_word = 0;
    static_assert(sizeof(bm.uv) <= sizeof(uv_word), "the UV sets fit one word");
    std::memcpy(&uv_word, &bm.uv, sizeof(bm.uv));
    const std::uint8_t transformed = bm.transformed;
    const bool multi_uv = uv_word != 0 || transformed != 0;
    std::uint8_t key[kMaps] = {};
    if (multi_uv) {
        const std::uint8_t set[kMaps] = {bm.uv.base_color, bm.uv.metallic_roughness, bm.uv.roughness, bm.uv.metallic,
                                         bm.uv.normal,     bm.uv.occlusion,          bm.uv.emissive};
        for (int i = 0; i < kMaps; ++i) {
            key[i] = std::uint8_t(set[i] * 8);
            if (!((transformed >> i) & 1u)) continue;
            int j = 0;
            while (!((transformed >> j) & 1u) || !(bm.xf[j] == bm.xf[i])) ++j;
            key[i] = std::uint8_t(key[i] + 1 + j);
        }
    }
    p.bm = &bm;
    p.groups = 0;
    for (int i = 0; i < kMaps; ++i) p.slot[i] = std::uint8_t(i);
    for (int i = 0; i < kMaps; ++i) {
        if (!maps[i]) continue;
        int j = 0;
        while (j < i && (maps[j] != maps[i] || key[j] != key[i])) ++j;
        if (j < i) {  // the same texture at the same uv again: share its lookup
            p.slot[i] = p.slot[j];
            for (int g = 0; g < p.groups; ++g)
                for (int k = 0; k < p.size[g]; ++k)
                    if (p.tex[g][k] == maps[i] && p.key[g] == key[i]) p.used[g][k] |= used[i];
            continue;
        }
        int g = 0;
        while (g < p.groups && !(p.key[g] == key[i] && same_sampling_layout(*p.tex[g][0], *maps[i]))) ++g;
        if (g == p.groups) {
            p.key[p.groups] = key[i];
            p.size[p.groups++] = 0;
        }
        p.tex[g][p.size[g]] = maps[i];
        p.used[g][p.size[g]] = used[i];
        p.out[g][p.size[g]++] = std::uint8_t(i);
    }
}

} // namespace prast

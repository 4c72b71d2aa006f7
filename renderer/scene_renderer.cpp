// Texture binding and frame rendering for a Scene; see scene_renderer.h.
#include "renderer/scene_renderer.h"
#include "renderer/draw_order.h"
#include "scene/det_math.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <mutex>
#include <new>

#include "scene/image.h"
#include "shading/output8.h"

namespace prast {

std::vector<ShadingLight> shading_lights(const Scene& scene) {
    std::vector<ShadingLight> out;
    for (const Light& L : scene.lights) {
        ShadingLight s;
        s.point = L.type == Light::Type::Point || L.type == Light::Type::Spot;
        float len = glm::length(L.direction);
        s.direction = len > 0.0f ? L.direction / len : glm::vec3(0.0f, 1.0f, 0.0f);
        s.position = L.position;
        s.radiance = L.color * L.intensity;
        // KHR_lights_punctual: the spot cone and the range window (the loader
        // checked the numbers; here only what is drawable passes).
        if (L.type == Light::Type::Spot) {
            s.spot = true;
            spot_cone(L.inner_cone, L.outer_cone, s.cone_scale, s.cone_offset);
        }
        if (s.point && std::isfinite(L.range) && L.range > 0.0f) {
            const double inv = 1.0 / (double(L.range) * double(L.range));
            s.range_inv2 = std::isfinite(float(inv)) ? float(inv) : 0.0f;
        }
        out.push_back(s);
    }
    return out;
}

std::vector<ShadingLight> default_light_rig() {
    ShadingLight key, fill;
    key.direction = glm::normalize(glm::vec3(-0.5f, 0.8f, 0.6f));
    key.radiance = glm::vec3(3.0f, 2.9f, 2.7f);
    fill.direction = glm::normalize(glm::vec3(0.7f, 0.3f, 0.4f));
    fill.radiance = glm::vec3(0.6f, 0.7f, 0.9f);
    return {key, fill};
}

std::vector<ShadingLight> frame_lights(const Scene& scene, const std::vector<ShadingLight>& flag_lights,
                                       bool file_lights, bool no_default_lights, bool environment,
                                       bool& used_default_rig) {
    std::vector<ShadingLight> lights;
    if (file_lights) lights = shading_lights(scene);
    lights.insert(lights.end(), flag_lights.begin(), flag_lights.end());
    used_default_rig = lights.empty() && !no_default_lights && !environment;
    if (used_default_rig) lights = default_light_rig();
    return lights;
}

SceneRenderer::SceneRenderer(const Scene& scene, Renderer& renderer, DecodedImages* kept)
    : scene_(scene), renderer_(renderer) {
    // Which (image, colour space) pairs the materials need, slot image * 2 + srgb.
    const std::size_t n_images = scene.images.size();
    auto slot_of = [&](const TextureRef& r, bool srgb) -> int {
        return r.valid() && std::size_t(r.image) < n_images ? r.image * 2 + int(srgb) : -1;
    };
    // Wrap modes live on the reference; an image takes its first user's.
    std::vector<const TextureRef*> first_user(n_images, nullptr);
    for (const Material& m : scene.materials)
        for (const TextureRef* r : {&m.base_color, &m.emissive, &m.metallic_roughness, &m.roughness, &m.metallic,
                                    &m.normal, &m.occlusion})
            if (r->valid() && std::size_t(r->image) < n_images && !first_user[std::size_t(r->image)])
                first_user[std::size_t(r->image)] = r;
    for (const Material& m : scene.materials)
        for (const TextureRef* r : m.extension_textures())
            if (r->valid() && std::size_t(r->image) < n_images && !first_user[std::size_t(r->image)])
                first_user[std::size_t(r->image)] = r;
    auto wraps_of = [&](int slot) {
        const TextureRef* u = first_user[std::size_t(slot / 2)];
        return std::make_pair(u ? u->wrap_s : Wrap::Repeat, u ? u->wrap_t : Wrap::Repeat);
    };

    // Separate roughness and metal maps (OBJ map_Pr + map_Pm) are packed into
    // one texture, one lookup instead of two, when they sample alike (same
    // wrap modes here, same size and 8-bit grey once decoded).
    std::vector<char> direct(n_images * 2, 0);
    std::vector<std::pair<int, int>> packs;            // (roughness slot, metal slot)
    std::vector<int> material_pack(scene.materials.size(), -1);
    for (std::size_t mi = 0; mi < scene.materials.size(); ++mi) {
        const Material& m = scene.materials[mi];
        for (auto [r, srgb] : {std::pair{&m.base_color, true}, {&m.emissive, true}, {&m.metallic_roughness, false},
                               {&m.normal, false}, {&m.occlusion, false}})
            if (slot_of(*r, srgb) >= 0) direct[std::size_t(slot_of(*r, srgb))] = 1;
        // KHR_materials_specular's colour map is sRGB, the other extension maps linear.
        for (const TextureRef* r : m.extension_textures()) {
            const int slot = slot_of(*r, m.extension_texture_srgb(r));
            if (slot >= 0) direct[std::size_t(slot)] = 1;
        }
        const int rs = slot_of(m.roughness, false), ms = slot_of(m.metallic, false);
        if (rs >= 0 && ms >= 0 && rs != ms && !m.metallic_roughness.valid() && wraps_of(rs) == wraps_of(ms) &&
            m.roughness.texcoord == m.metallic.texcoord && m.roughness.transform == m.metallic.transform) {
            const auto key = std::make_pair(rs, ms);
            auto it = std::find(packs.begin(), packs.end(), key);
            material_pack[mi] = int(it - packs.begin());
            if (it == packs.end()) packs.push_back(key);
        } else {
            if (rs >= 0) direct[std::size_t(rs)] = 1;
            if (ms >= 0) direct[std::size_t(ms)] = 1;
        }
    }
    std::vector<char> needed = direct;
    for (const auto& [rs, ms] : packs) needed[std::size_t(rs)] = needed[std::size_t(ms)] = 1;

    // Decode in parallel, one task per image; each task owns its slot, so the
    // result is the same for any thread count. Failures become warnings in
    // image order.
    textures_.resize(needed.size());
    std::vector<std::string> errors(needed.size());
    std::vector<Image> images(needed.size());
    std::vector<char> decoded(needed.size(), 0);
    std::vector<int> slots;
    for (std::size_t i = 0; i < needed.size(); ++i)
        if (needed[i]) slots.push_back(int(i));
    renderer.pool().run(int(slots.size()), [&](int task, int) {
        const std::size_t slot = std::size_t(slots[std::size_t(task)]);
        const ImageSource& src = scene.images[slot / 2];
        try {
            std::shared_ptr<const Image> have;
            if (kept && !src.decoded) {
                std::lock_guard<std::mutex> lock(kept->mutex);
                if (kept->slots.size() > slot) have = kept->slots[slot];
            }
            // A map drawn as it is decodes with room for its mip chain (no copy of level 0).
            const PixelCapacity room = direct[slot] ? &Texture::unorm8_bytes : nullptr;
            // (Not one conditional expression: its const lvalue arms would make
            // even the fresh decode a copy, which loses the reserved capacity.)
            if (src.decoded) images[slot] = *src.decoded;
            else if (have) images[slot] = *have;
            else images[slot] = decode_image(src, slot % 2 == 1, room);
            if (kept && !src.decoded && !have) {
                auto copy = std::make_shared<const Image>(images[slot]);
                std::lock_guard<std::mutex> lock(kept->mutex);
                if (kept->slots.size() <= slot) kept->slots.resize(n_images * 2);
                kept->slots[slot] = std::move(copy);
            }
            decoded[slot] = 1;
        } catch (const std::bad_alloc&) {
            errors[slot] = (src.name.empty() ? src.path : src.name) + ": out of memory while decoding";
        } catch (const std::exception& e) {
            errors[slot] = e.what();
        }
    });

    // Packs whose maps decoded alike; the others fall back to separate maps.
    std::vector<char> pack_ok(packs.size(), 0);
    for (std::size_t p = 0; p < packs.size(); ++p) {
        const std::size_t rs = std::size_t(packs[p].first), ms = std::size_t(packs[p].second);
        const Image& r = images[rs];
        const Image& m = images[ms];
        pack_ok[p] = decoded[rs] && decoded[ms] && r.is_8bit() && m.is_8bit() && !r.srgb && !m.srgb &&
                     r.width == m.width && r.height == m.height;
        if (!pack_ok[p]) direct[rs] = direct[ms] = 1;
    }

    // Mip chains, each level's rows in parallel on the pool.
    packed_.resize(packs.size());
    for (std::size_t p = 0; p < packs.size(); ++p) {
        if (!pack_ok[p]) continue;
        const auto [ws, wt] = wraps_of(packs[p].first);
        packed_[p] = std::make_unique<Texture>(Texture::pack_roughness_metal(
            images[std::size_t(packs[p].first)], images[std::size_t(packs[p].second)], ws, wt, &renderer.pool()));
    }
    for (std::size_t slot = 0; slot < needed.size(); ++slot) {
        if (!decoded[slot] || !direct[slot]) continue;
        const auto [ws, wt] = wraps_of(int(slot));
        try {
            textures_[slot] = std::make_unique<Texture>(
                Texture::from_image(std::move(images[slot]), ws, wt, &renderer.pool()));
        } catch (const std::bad_alloc&) {
            const ImageSource& src = scene.images[slot / 2];
            errors[slot] = (src.name.empty() ? src.path : src.name) + ": out of memory while building its mip maps";
        } catch (const std::exception& e) {
            errors[slot] = e.what();
        }
        images[slot] = Image();
    }
    images.clear();
    for (const std::string& e : errors)
        if (!e.empty()) warnings_.push_back(e + " (texture ignored)");

    // Each reference samples the shared decoded texels through its own
    // sampler: the decoded texture itself when the samplers agree, else one
    // view per (image, colour space, sampler).
    auto bind = [&](const TextureRef& r, bool srgb) -> const Texture* {
        const int slot = slot_of(r, srgb);
        const Texture* base = slot >= 0 ? textures_[std::size_t(slot)].get() : nullptr;
        const SamplerState want = sampler_of(r);
        if (!base || base->sampler() == want) return base;
        for (const std::unique_ptr<Texture>& v : views_)
            if (v->shares_storage(*base) && v->sampler() == want) return v.get();
        views_.push_back(std::make_unique<Texture>(base->with_sampler(want)));
        return views_.back().get();
    };
    auto set_of = [](const TextureRef& r) {
        return std::uint8_t(r.texcoord > 0 && r.texcoord < kMaxUvSets ? r.texcoord : 0);
    };
    for (std::size_t mi = 0; mi < scene.materials.size(); ++mi) {
        const Material& m = scene.materials[mi];
        BoundMaterial b;
        b.m = &m;
        b.base_color = bind(m.base_color, true);
        b.emissive = bind(m.emissive, true);
        b.metallic_roughness = bind(m.metallic_roughness, false);
        const int p = material_pack[mi];
        if (p >= 0 && pack_ok[std::size_t(p)]) {
            b.metallic_roughness = packed_[std::size_t(p)].get();  // G rough, B metal
        } else {
            b.roughness = bind(m.roughness, false);
            b.metallic = bind(m.metallic, false);
        }
        b.normal = bind(m.normal, false);
        b.occlusion = bind(m.occlusion, false);
        b.uv.base_color = set_of(m.base_color);
        b.uv.emissive = set_of(m.emissive);
        b.uv.metallic_roughness = set_of(p >= 0 && pack_ok[std::size_t(p)] ? m.roughness : m.metallic_roughness);
        b.uv.roughness = set_of(m.roughness);
        b.uv.metallic = set_of(m.metallic);
        b.uv.normal = set_of(m.normal);
        b.uv.occlusion = set_of(m.occlusion);
        // KHR_texture_transform, for the maps that have one.
        const bool packed = p >= 0 && pack_ok[std::size_t(p)];
        const TextureRef* refs[BoundMaterial::kMaps] = {&m.base_color, packed ? &m.roughness : &m.metallic_roughness,
                                                        &m.roughness, &m.metallic, &m.normal, &m.occlusion,
                                                        &m.emissive};
        for (int i = 0; i < BoundMaterial::kMaps; ++i) {
            if (!refs[i]->transform.present) continue;
            b.transformed = std::uint8_t(b.transformed | (1u << i));
            b.xf[i] = UvTransform::of(refs[i]->transform);
        }
        const std::vector<const TextureRef*> ext = m.extension_textures();
        for (int i = 0; i < BoundMaterial::kExtMaps; ++i) {
            const TextureRef& r = *ext[std::size_t(i)];
            b.ext[i] = bind(r, m.extension_texture_srgb(&r));
            b.ext_uv[i] = set_of(r);
            if (!r.transform.present) continue;
            b.ext_transformed = std::uint16_t(b.ext_transformed | (1u << i));
            b.ext_xf[i] = UvTransform::of(r.transform);
        }
        bound_.push_back(b);
    }
}

std::vector<ShadingLight> SceneRenderer::shadowed_lights(const FrameSettings& s, float aspect) {
    std::vector<ShadingLight> lights = s.lights;
    const bool lit = debug_view_is_lit(s.view);
    if (!s.shadows.enabled || !lit || !(aspect > 0.0f)) {
        for (ShadingLight& L : lights) L.shadow = nullptr;
        return lights;
    }
    // The maps depend on the camera, the aspect, the lights, the size and the
    // scene's pose only.
    const Camera& c = s.camera;
    std::vector<float> key = {aspect, float(s.shadows.size), c.eye.x, c.eye.y, c.eye.z, c.target.x, c.target.y,
                              c.target.z, c.up.x, c.up.y, c.up.z, c.fov_y_deg, c.near_plane, c.far_plane,
                              float(c.orthographic), c.ortho_ymag, float(c.infinite_far),
                              float(scene_.pose_serial & 0xffffffu), float(scene_.pose_serial >> 24)};
    for (const ShadingLight& L : lights)
        key.insert(key.end(), {float(L.point), L.direction.x, L.direction.y, L.direction.z, L.position.x,
                               L.position.y, L.position.z});
    if (key != shadow_key_ || shadow_maps_.maps().size() != lights.size()) {
        for (ShadingLight& L : lights) L.shadow = nullptr;  // stays so when the scene is empty
        shadow_maps_.draw(scene_, bound_, renderer_, s.shadows, s.camera, aspect, lights);
        shadow_key_ = key;
    } else {
        for (std::size_t i = 0; i < lights.size(); ++i) lights[i].shadow = shadow_maps_.maps()[i].get();
    }
    return lights;
}

const Environment* SceneRenderer::environment(const FrameSettings& s) {
    if (s.environment) return s.environment;
    if (!s.scene_environment || !scene_.environment) return nullptr;
    if (!scene_env_)
        scene_env_ = std::make_unique<Environment>(
            Environment::build(*scene_.environment, EnvironmentSettings{}, renderer_.pool()));
    return scene_env_.get();
}

const DfgTable& SceneRenderer::dfg_table(DfgModel model) {
    std::unique_ptr<DfgTable>& t = dfg_[int(model)];
    if (!t) t = std::make_unique<DfgTable>(DfgTable::build(model, renderer_.pool()));
    return *t;
}

ShadingContext SceneRenderer::shading_context(const FrameSettings& s, float aspect) {
    std::vector<ShadingLight> lights = shadowed_lights(s, aspect);
    ShadingContext ctx;
    ctx.eye = s.camera.eye;
    ctx.lights = std::move(lights);
    ctx.ambient = s.ambient;
    ctx.model = s.model;
    const bool gltf = s.model == BrdfModel::Gltf;
    ctx.env = environment(s);
    if (ctx.env) {
        ctx.dfg_ibl = &dfg_table(gltf ? DfgModel::HeightCorrelated : DfgModel::SchlickIbl);
        ctx.ibl = s.ibl;
        ctx.ibl_samples = s.ibl_samples;
    }
    ctx.energy = s.energy;
    if (s.energy) ctx.dfg_light = &dfg_table(gltf ? DfgModel::HeightCorrelated : DfgModel::SchlickDirect);
    return ctx;
}

BackgroundFill frame_background(const FrameSettings& s, const Environment* env, int width, int height) {
    const bool lit = s.view == DebugView::None || s.view == DebugView::Tiles;
    return BackgroundFill(s.camera, width, height, env, lit ? s.background : Background::Black, s.background_color);
}

const BoundMaterial& SceneRenderer::material_of(const Mesh& mesh) const {
    static const Material kFallback;
    static const BoundMaterial kFallbackBound{&kFallback};
    return mesh.material >= 0 && std::size_t(mesh.material) < bound_.size() ? bound_[std::size_t(mesh.material)]
                                                                          : kFallbackBound;
}

DrawState SceneRenderer::draw_state(const BoundMaterial& bm, DebugView view) {
    DrawState st;
    st.cull = bm.m->double_sided ? CullMode::None : CullMode::Back;
    st.may_discard = bm.m->alpha_mode == AlphaMode::Mask;  // shaded in order: discards decide visibility
    // BLEND meshes blend over what is drawn in lit views; data views draw them opaque.
    if (debug_view_is_lit(view) && bm.m->alpha_mode == AlphaMode::Blend) {
        st.blend = Blend::Alpha;  // per sample, in linear radiance
        st.depth_write = false;
    }
    if (view == DebugView::Overdraw) {
        st.blend = Blend::Add;
        st.depth_test = false;
        st.depth_write = false;
    }
    return st;
}

void SceneRenderer::begin_pass(const FrameSettings& s, Framebuffer& fb, const ImageOutput* out, Pass& pass) {
    pass.ctx = shading_context(s, float(fb.width) / float(fb.height));  // shadow maps first: not in the frame's counts
    renderer_.begin_frame();
    // Cleared in the tile pass: alpha 1, depth 1, and the background's colour
    // (black unless an environment or a colour is shown), so that samples no
    // triangle covers resolve to the background.
    FrameOptions frame;
    frame.samples = s.samples;
    frame.visibility = s.visibility;
    pass.overlay = s.view == DebugView::Overdraw || s.view == DebugView::Tiles;
    frame.transient = out && !out->keep_framebuffer && !pass.overlay;
    pass.background.emplace(frame_background(s, pass.ctx.env, fb.width, fb.height));
    pass.background->attach(frame);
    renderer_.begin(fb, frame);
    pass.view_proj = s.camera.view_projection(float(fb.width) / float(fb.height));
    // The texture lookups of every bound material, planned once per frame
    // rather than per block.
    pass.plans.resize(bound_.size());
    for (std::size_t i = 0; i < bound_.size(); ++i) plan_lookups(bound_[i], pass.plans[i]);
    // Opaque and MASK meshes in file order, then BLEND ones back to front.
    pass.order = draw_order(scene_, s.camera.eye);
}

template <class P>
P SceneRenderer::program_of(const FrameSettings& s, const Pass& pass, const Mesh& mesh, const BoundMaterial& bm) const {
    P prog;
    prog.mesh = &mesh;
    prog.view_proj = pass.view_proj;
    prog.material = &bm;
    prog.ctx = &pass.ctx;
    prog.view = s.view;
    prog.near_plane = s.camera.near_plane;
    prog.far_plane = s.camera.far_plane;
    const std::less<const BoundMaterial*> before;  // a total order, also for the fallback's address
    if (!before(&bm, bound_.data()) && before(&bm, bound_.data() + bound_.size()) && pass.plans.size() == bound_.size())
        prog.plan = &pass.plans[std::size_t(&bm - bound_.data())];
    return prog;
}

PbrProgram SceneRenderer::program(const FrameSettings& s, const Pass& pass, const Mesh& mesh,
                                  const BoundMaterial& bm) const {
    return program_of<PbrProgram>(s, pass, mesh, bm);
}

PbrProgramExt SceneRenderer::program_ext(const FrameSettings& s, const Pass& pass, const Mesh& mesh,
                                         const BoundMaterial& bm) const {
    return program_of<PbrProgramExt>(s, pass, mesh, bm);
}

PbrProgramLite SceneRenderer::program_lite(const FrameSettings& s, const Pass& pass, const Mesh& mesh,
                                           const BoundMaterial& bm) const {
    return program_of<PbrProgramLite>(s, pass, mesh, bm);
}

void SceneRenderer::end_pass(const FrameSettings& s, Framebuffer& fb, const ImageOutput* out, const Pass& pass) {
    // The 8-bit image: from each finished tile, unless a whole-image overlay
    // comes first (then after it, rows in parallel).
    TileResolve resolve;
    if (out) {
        resolve.rgba8 = out->rgba8;
        resolve.width = fb.width;
        resolve.exposure = out->exposure;
        resolve.tonemap = out->tonemap;
        resolve.raw = out->raw;
    }
    if (out && !pass.overlay) renderer_.end(resolve);
    else renderer_.end();
    if (s.view == DebugView::Overdraw) apply_overdraw_heat(fb);
    if (s.view == DebugView::Tiles) apply_tile_overlay(fb, renderer_.tile_entries(), renderer_.tile_size());
    if (out && pass.overlay) {
        constexpr int kRows = 16;
        renderer_.pool().run((fb.height + kRows - 1) / kRows, [&](int chunk, int) {
            TileView v;
            v.x0 = 0;
            v.y0 = chunk * kRows;
            v.width = fb.width;
            v.height = std::min(kRows, fb.height - v.y0);
            v.rgba = &fb.color[std::size_t(v.y0) * std::size_t(fb.width) * 4];
            v.row = std::size_t(fb.width) * 4;
            resolve(v);
        });
    }
}

void SceneRenderer::render(const FrameSettings& s, Framebuffer& fb, const ImageOutput* out) {
    render(s, fb, out, NoTaps{});
}

// Fragments per pixel (in red, counted additively) to a heat ramp:
// 0 black, 1 blue, 2 green, 3 yellow, 4 red, 8+ white.
void apply_overdraw_heat(Framebuffer& fb) {
    static const glm::vec3 kRamp[] = {{0, 0, 0}, {0, 0, 1}, {0, 1, 0}, {1, 1, 0}, {1, 0, 0},
                                      {1, 0, 1}, {1, 0.5f, 1}, {1, 0.8f, 1}, {1, 1, 1}};
    for (std::size_t i = 0; i < fb.color.size(); i += 4) {
        int n = std::min(8, int(fb.color[i]));
        fb.color[i] = kRamp[n].r; fb.color[i + 1] = kRamp[n].g; fb.color[i + 2] = kRamp[n].b;
        fb.color[i + 3] = 1.0f;
    }
}

// Tinted tiles by bin entries (log scale, blue few to red many) over the lit
// image, with the tile borders drawn.
void apply_tile_overlay(Framebuffer& fb, const std::vector<std::uint32_t>& entries, int tile_size) {
    int tiles_x = (fb.width + tile_size - 1) / tile_size;
    std::uint32_t most = 1;
    for (std::uint32_t e : entries) most = std::max(most, e);
    // Once a tile: det::log2 is a series, not an instruction.
    std::vector<float> heats(entries.size(), 0.0f);
    for (std::size_t t = 0; t < entries.size(); ++t)
        if (entries[t] > 0) heats[t] = float(det::log2(1.0 + entries[t]) / det::log2(1.0 + most));
    for (int y = 0; y < fb.height; ++y)
        for (int x = 0; x < fb.width; ++x) {
            std::size_t t = std::size_t(y / tile_size) * tiles_x + x / tile_size;
            float heat = t < heats.size() ? heats[t] : 0.0f;
            float* c = fb.pixel(x, y);
            glm::vec3 tint = glm::mix(glm::vec3(0.1f, 0.2f, 1.0f), glm::vec3(1.0f, 0.15f, 0.05f), heat);
            bool border = x % tile_size == 0 || y % tile_size == 0;
            float k = entries.size() > t && entries[t] ? 0.35f : 0.0f;
            for (int ch = 0; ch < 3; ++ch) c[ch] = border ? 1.0f : c[ch] * (1.0f - k) + tint[ch] * k;
        }
}

} // namespace prast

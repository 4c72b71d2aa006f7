// The views of the frame's draws, textures, vertices and tiles; see views.h.
#include "stepper/views.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "raster/fragment.h"
#include "scene/animation.h"
#include "scene/encode_png.h"
#include "scene/image.h"
#include "scene/messages.h"
#include "shading/color.h"
#include "shading/ibl/environment.h"
#include "shading/tonemap.h"
#include "stepper/explain.h"
#include "stepper/format.h"
#include "stepper/replay.h"
#include "stepper/session.h"

namespace prast::stepper {

using nlohmann::json;

std::string plural(std::uint64_t n, const std::string& one, const std::string& many) {
    return std::to_string(n) + " " + (n == 1 ? one : many.empty() ? one + "s" : many);
}

namespace {

// Names come from the model: escaped, so they cannot drive the terminal.
std::string quoted(const std::string& s) { return "'" + printable(s) + "'"; }

std::string range_of(std::size_t n) { return n ? "0.." + std::to_string(n - 1) : "none"; }

json j2(const glm::vec2& v) { return json::array({v.x, v.y}); }
json j3(const glm::vec3& v) { return json::array({v.x, v.y, v.z}); }
json j4(const glm::vec4& v) { return json::array({v.x, v.y, v.z, v.w}); }

const char* topology_name(Topology t) {
    return t == Topology::Lines ? "lines" : t == Topology::Points ? "points" : "triangles";
}

std::string alpha_text(const Material& m) {
    if (m.alpha_mode == AlphaMode::Mask) return "MASK " + num(m.alpha_cutoff);
    return m.alpha_mode == AlphaMode::Blend ? "BLEND" : "OPAQUE";
}

std::string program_text(int varyings) {
    if (varyings == kPbrVaryingsExt)
        return "PBR wide (" + std::to_string(varyings) + " varyings: vertex colours or UV set 1)";
    if (varyings == UnlitProgram::kVaryings) return "unlit (" + std::to_string(varyings) + " varyings: uv, rgba)";
    return "PBR narrow (" + std::to_string(varyings) + " varyings)";
}

// ---------------------------------------------------------------- textures

// The maps of a material, in BoundMaterial's order.
struct Slot {
    const char* name;
    const Texture* BoundMaterial::*tex;
    TextureRef Material::*ref;
    std::uint8_t BoundMaterial::UvSets::*uv;
    bool colour;  // sampled as sRGB colour (base colour, emissive)
};
const Slot kSlots[] = {
    {"base_color", &BoundMaterial::base_color, &Material::base_color, &BoundMaterial::UvSets::base_color, true},
    {"metallic_roughness", &BoundMaterial::metallic_roughness, &Material::metallic_roughness,
     &BoundMaterial::UvSets::metallic_roughness, false},
    {"roughness", &BoundMaterial::roughness, &Material::roughness, &BoundMaterial::UvSets::roughness, false},
    {"metallic", &BoundMaterial::metallic, &Material::metallic, &BoundMaterial::UvSets::metallic, false},
    {"normal", &BoundMaterial::normal, &Material::normal, &BoundMaterial::UvSets::normal, false},
    {"occlusion", &BoundMaterial::occlusion, &Material::occlusion, &BoundMaterial::UvSets::occlusion, false},
    {"emissive", &BoundMaterial::emissive, &Material::emissive, &BoundMaterial::UvSets::emissive, true},
};

// A packed roughness + metal map (OBJ map_Pr and map_Pm in one texture).
bool packed(const Texture& t) { return t.is_unorm8() && t.channels() == 2 && t.swizzle(3) == Texture::kOne; }
// The images a slot of a material reads.
std::vector<int> slot_images(const Material& m, const Slot& sl, const Texture& t) {
    if (sl.tex == &BoundMaterial::metallic_roughness && packed(t)) return {m.roughness.image, m.metallic.image};
    const TextureRef& r = m.*sl.ref;
    return r.valid() ? std::vector<int>{r.image} : std::vector<int>{};
}

enum class Kind { Material, Shadow, Environment };

struct Entry {
    std::string id;
    Kind kind = Kind::Material;
    const Texture* tex = nullptr;
    bool colour = false;                   // a colour map uses it
    std::vector<int> images;
    std::vector<std::string> uses;
    const ShadowMap* shadow = nullptr;
    int light = -1;
    const Environment* env = nullptr;
};

std::string image_text(const FrameSetup& s, int image) {
    if (image < 0 || std::size_t(image) >= s.scene.images.size()) return "image " + std::to_string(image);
    const ImageSource& src = s.scene.images[std::size_t(image)];
    const std::string name = !src.name.empty() ? src.name : !src.path.empty() ? src.path
                             : src.decoded ? std::string("procedural") : std::string("embedded");
    return "image " + std::to_string(image) + " " + quoted(name);
}

// Every texture of the frame, in ID order: the material maps in the order
// the materials first bind them, the shadow maps by light, the environment.
std::vector<Entry> texture_entries(const FrameSetup& s) {
    std::vector<Entry> out;
    const std::vector<BoundMaterial>& bound = s.scene_renderer->materials();
    for (std::size_t mi = 0; mi < bound.size(); ++mi) {
        const BoundMaterial& bm = bound[mi];
        for (const Slot& sl : kSlots) {
            const Texture* t = bm.*sl.tex;
            if (!t) continue;
            auto it = std::find_if(out.begin(), out.end(), [&](const Entry& e) { return e.tex == t; });
            if (it == out.end()) {
                Entry e;
                e.id = std::to_string(out.size());
                e.tex = t;
                e.images = slot_images(*bm.m, sl, *t);
                out.push_back(e);
                it = out.end() - 1;
            }
            it->colour |= sl.colour;
            it->uses.push_back("material " + std::to_string(mi) + " " + quoted(bm.m->name) + " " + sl.name +
                               " (UV set " + std::to_string(int(bm.uv.*sl.uv)) + ")");
        }
    }
    if (s.settings.shadows.enabled) {
        const ShadingContext ctx = s.shading_context();
        for (std::size_t i = 0; i < ctx.lights.size(); ++i) {
            if (!ctx.lights[i].shadow) continue;
            Entry e;
            e.id = "shadow" + std::to_string(i);
            e.kind = Kind::Shadow;
            e.shadow = ctx.lights[i].shadow;
            e.light = int(i);
            e.uses.push_back("light " + std::to_string(i) + " (" + (ctx.lights[i].point ? "point" : "sun") + ")");
            out.push_back(e);
        }
    }
    if (const Environment* env = s.scene_renderer->environment(s.settings)) {
        Entry e;
        e.id = "env";
        e.kind = Kind::Environment;
        e.env = env;
        e.uses.push_back("the environment: background, mirror reflections, the split sum's prefiltered radiance");
        out.push_back(e);
    }
    return out;
}

const char* channel_names(int channels) {
    switch (channels) {
    case 1: return "grey";
    case 2: return "grey+alpha";
    case 3: return "RGB";
    default: return "RGBA";
    }
}

TextureInfo info_of(const FrameSetup& s, const Entry& e) {
    TextureInfo t;
    t.id = e.id;
    t.uses = e.uses;
    for (int im : e.images) t.images.push_back(image_text(s, im));
    if (e.kind == Kind::Material) {
        const Texture& x = *e.tex;
        t.kind = "material";
        t.levels = x.levels();
        for (int l = 0; l < t.levels; ++l) t.level_sizes.push_back({x.width(l), x.height(l)});
        if (x.is_unorm8()) {
            t.bits = 8;
            t.channels = x.channels();
            t.colour_space = x.srgb(0) ? "sRGB" : "linear";
            if (packed(x)) {
                t.format = "roughness+metal, 2 channels 8-bit linear (samples as G roughness, B metal)";
                t.png_rule = "RGB: roughness in R and G, metal in B, the stored bytes";
            } else {
                t.format = std::string(channel_names(t.channels)) + " 8-bit " + t.colour_space;
                t.png_rule = "the stored bytes as they are (" +
                             std::string(t.colour_space == "sRGB" ? "sRGB-encoded colour" : "linear values") + ")";
            }
        } else {
            t.bits = 32;
            t.channels = 4;
            t.colour_space = "linear";
            t.format = "RGBA float32 linear";
            t.png_rule = e.colour ? "linear values clamped to [0, 1], sRGB-encoded to 8 bits"
                                  : "values clamped to [0, 1] times 255, rounded (linear, not sRGB-encoded)";
        }
    } else if (e.kind == Kind::Shadow) {
        const ShadowMap& m = *e.shadow;
        t.kind = "shadow";
        t.levels = 1;
        t.level_sizes.push_back({m.size, m.cube ? 6 * m.size : m.size});
        t.channels = 1;
        t.bits = 32;
        t.colour_space = "distance";
        t.format = std::string("distance float32, ") +
                   (m.cube ? "a cube of 6 faces of " + std::to_string(m.size) + "x" + std::to_string(m.size) +
                                 " (stacked +X -X +Y -Y +Z -Z, top to bottom)"
                           : "directional");
        t.png_rule = "grey ramp: the least distance black (0) to the greatest grey 254, texels without a caster "
                     "white (255)";
    } else {
        const Environment& env = *e.env;
        t.kind = "environment";
        t.levels = Environment::kSpecularLevels;
        for (int l = 0; l < t.levels; ++l) t.level_sizes.push_back({env.specular_level(l).w, env.specular_level(l).h});
        t.channels = 3;
        t.bits = 32;
        t.colour_space = "linear";
        t.format = "RGB float32 linear radiance, equirectangular; level 0 the map, level i GGX-prefiltered for "
                   "roughness 0.045 + 0.955 i / 7";
        t.png_rule = "radiance x exposure " + num(s.exposure()) + ", tone map " + tonemap_name(s.tonemap()) +
                     ", sRGB-encoded to 8 bits (as the frame shows it)";
    }
    t.width = t.level_sizes[0].x;
    t.height = t.level_sizes[0].y;
    return t;
}

std::string ids_hint(const std::vector<Entry>& es) {
    std::size_t materials = 0;
    std::string more;
    for (const Entry& e : es) {
        if (e.kind == Kind::Material) ++materials;
        else more += ", " + e.id;
    }
    return "textures " + range_of(materials) + more + "; `textures` lists them";
}

// Finds texture `id` and its level; "" or the error.
std::string find_texture(const FrameSetup& s, const std::string& id, const std::string& level, Entry& e,
                         TextureInfo& info, int& lv) {
    const std::vector<Entry> es = texture_entries(s);
    auto it = std::find_if(es.begin(), es.end(), [&](const Entry& x) { return x.id == id; });
    if (it == es.end()) return "texture '" + printable(id) + "': no such texture (" + ids_hint(es) + ")";
    e = *it;
    info = info_of(s, e);
    long l = 0;
    if (!level.empty() && !parse_int(level, 0, info.levels - 1, l))
        return "texture " + id + " level '" + printable(level) + "': no such level (levels " +
               range_of(std::size_t(info.levels)) + ")";
    lv = int(l);
    return "";
}

std::uint8_t unorm8(float v) {
    v = v > 0.0f ? (v < 1.0f ? v : 1.0f) : 0.0f;  // NaN -> 0
    return std::uint8_t(std::floor(v * 255.0f + 0.5f));
}

// A level as 8-bit pixels by the entry's rule: channels and bytes; `note`
// states a shadow map's range.
int level_pixels(const FrameSetup& s, const Entry& e, int level, int& w, int& h, std::vector<std::uint8_t>& px,
                 std::string& note) {
    if (e.kind == Kind::Material) {
        const Texture& t = *e.tex;
        w = t.width(level);
        h = t.height(level);
        const std::size_t n = std::size_t(w) * std::size_t(h);
        if (t.is_unorm8()) {
            const std::size_t C = std::size_t(t.channels());
            const std::uint8_t* src = t.unorm8_data() + t.level_offset(level) * C;
            if (!packed(t)) {
                px.assign(src, src + n * C);
                return t.channels();
            }
            px.resize(n * 3);
            for (std::size_t i = 0; i < n; ++i) {
                px[i * 3 + 0] = px[i * 3 + 1] = src[i * 2];
                px[i * 3 + 2] = src[i * 2 + 1];
            }
            return 3;
        }
        px.resize(n * 4);
        const bool colour = e.colour;
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) {
                const glm::vec4 c = t.texel(level, x, y);
                std::uint8_t* p = &px[(std::size_t(y) * std::size_t(w) + std::size_t(x)) * 4];
                for (int k = 0; k < 3; ++k) p[k] = colour ? linear_to_srgb8(c[k]) : unorm8(c[k]);
                p[3] = unorm8(c.a);
            }
        return 4;
    }
    if (e.kind == Kind::Shadow) {
        const ShadowMap& m = *e.shadow;
        const int faces = m.cube ? 6 : 1;
        w = m.size;
        h = m.size * faces;
        float lo = INFINITY, hi = -INFINITY;
        for (int f = 0; f < faces; ++f)
            for (int j = 0; j < m.size; ++j)
                for (int i = 0; i < m.size; ++i) {
                    const float d = m.at(f, i, j);
                    if (std::isfinite(d)) lo = std::min(lo, d), hi = std::max(hi, d);
                }
        px.resize(std::size_t(w) * std::size_t(h));
        std::size_t casters = 0;
        for (int f = 0; f < faces; ++f)
            for (int j = 0; j < m.size; ++j)
                for (int i = 0; i < m.size; ++i) {
                    const float d = m.at(f, i, j);
                    std::uint8_t g = 255;
                    if (std::isfinite(d)) {
                        ++casters;
                        const double t = hi > lo ? (double(d) - lo) / (double(hi) - lo) : 0.0;
                        g = std::uint8_t(std::floor(t * 254.0 + 0.5));
                    }
                    px[(std::size_t(f) * std::size_t(m.size) + std::size_t(j)) * std::size_t(w) + std::size_t(i)] = g;
                }
        note = casters ? "distance " + num(lo) + " (black) .. " + num(hi) + " (grey 254); " +
                             plural(std::uint64_t(w) * std::uint64_t(h) - casters, "texel") + " without a caster (white)"
                       : "no caster drawn: every texel white";
        return 1;
    }
    const Environment& env = *e.env;
    const EquirectLevel& L = env.specular_level(level);
    w = L.w;
    h = L.h;
    px.resize(std::size_t(w) * std::size_t(h) * 3);
    float peak = 0.0f;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const glm::vec4 c = env.texels()[std::size_t(L.offset) + std::size_t(y) * std::size_t(w) + std::size_t(x)];
            peak = std::max(peak, std::max(c.r, std::max(c.g, c.b)));
            const glm::vec3 d = tonemap(glm::vec3(c) * s.exposure(), s.tonemap());
            std::uint8_t* p = &px[(std::size_t(y) * std::size_t(w) + std::size_t(x)) * 3];
            for (int k = 0; k < 3; ++k) p[k] = linear_to_srgb8(d[k]);
        }
    note = "brightest radiance " + num(peak);
    return 3;
}

json info_json(const TextureInfo& t) {
    json levels = json::array();
    for (std::size_t l = 0; l < t.level_sizes.size(); ++l)
        levels.push_back({{"level", l}, {"width", t.level_sizes[l].x}, {"height", t.level_sizes[l].y}});
    return {{"id", t.id},           {"kind", t.kind},         {"width", t.width},
            {"height", t.height},   {"levels", t.levels},     {"level_sizes", levels},
            {"format", t.format},   {"channels", t.channels}, {"bits", t.bits},
            {"colour_space", t.colour_space}, {"png_rule", t.png_rule}, {"uses", t.uses},
            {"images", t.images}};
}

} // namespace

std::string TextureInfo::summary() const {
    return "texture " + id + ": " + std::to_string(width) + "x" + std::to_string(height) + ", " +
           plural(std::uint64_t(levels), "level") + ", " + format;
}

std::string TexturesView::text() const {
    std::ostringstream o;
    o << plural(textures.size(), "texture") << " (texture ID [LEVEL] writes a level as a PNG):\n";
    for (const TextureInfo& t : textures) {
        o << "  " << t.summary() << "\n";
        for (const std::string& im : t.images) o << "    " << im << "\n";
        for (const std::string& u : t.uses) o << "    " << u << "\n";
    }
    return o.str();
}

json TexturesView::json() const {
    nlohmann::json a = nlohmann::json::array();
    for (const TextureInfo& t : textures) a.push_back(info_json(t));
    return {{"textures", a}, {"text", text()}};
}

std::string make_textures(const FrameSetup& s, const Recording&, TexturesView& out) {
    out = TexturesView{};
    for (const Entry& e : texture_entries(s)) out.textures.push_back(info_of(s, e));
    return "";
}

std::string TextureView::text() const {
    std::ostringstream o;
    o << info.summary() << "\n";
    for (const std::string& im : info.images) o << "  " << im << "\n";
    o << "  levels:";
    for (std::size_t l = 0; l < info.level_sizes.size(); ++l)
        o << (l ? ", " : " ") << l << " " << info.level_sizes[l].x << "x" << info.level_sizes[l].y;
    o << "\n";
    for (const std::string& u : info.uses) o << "  used by " << u << "\n";
    o << "  level " << level << " " << info.level_sizes[std::size_t(level)].x << "x"
      << info.level_sizes[std::size_t(level)].y << " as an 8-bit PNG: " << info.png_rule << "\n";
    if (!note.empty()) o << "  " << note << "\n";
    return o.str();
}

json TextureView::json() const {
    nlohmann::json j = info_json(info);
    j["level"] = level;
    j["note"] = note;
    j["png"] = {{"endpoint", "/api/texture.png"}, {"id", info.id}, {"level", level}};
    j["text"] = text();
    return j;
}

std::string make_texture(const FrameSetup& s, const Recording&, const std::string& id, const std::string& level,
                         TextureView& out) {
    out = TextureView{};
    Entry e;
    std::string err = find_texture(s, id, level, e, out.info, out.level);
    if (!err.empty()) return err;
    // Only shadow maps and the environment have a note, which needs their texels.
    if (e.kind != Kind::Material) {
        int w = 0, h = 0;
        std::vector<std::uint8_t> px;
        level_pixels(s, e, out.level, w, h, px, out.note);
    }
    return "";
}

std::string texture_png(const FrameSetup& s, const Recording&, const std::string& id, const std::string& level,
                        std::vector<std::uint8_t>& png) {
    Entry e;
    TextureInfo info;
    int lv = 0;
    std::string err = find_texture(s, id, level, e, info, lv);
    if (!err.empty()) return err;
    int w = 0, h = 0;
    std::vector<std::uint8_t> px;
    std::string note;
    const int channels = level_pixels(s, e, lv, w, h, px, note);
    png = encode_png_pixels(px.data(), w, h, channels);
    return "";
}

namespace {

// A number as the views print it; +inf as "inf" (JSON gets null).
std::string value_text(double v) { return std::isinf(v) ? (v > 0 ? "inf" : "-inf") : num(float(v)); }

std::string values_text(const std::vector<std::string>& names, const std::vector<double>& v, bool bytes) {
    std::string s;
    for (std::size_t i = 0; i < v.size(); ++i)
        s += (i ? ", " : "") + names[i] + " " + (bytes ? std::to_string(int(v[i])) : value_text(v[i]));
    return s;
}

json values_json(const std::vector<double>& v, bool bytes = false) {
    json a = json::array();
    for (double x : v) a.push_back(bytes ? json(int(x)) : std::isfinite(x) ? json(x) : json(nullptr));
    return a;
}

} // namespace

std::string make_texel(const FrameSetup& s, const Recording&, const std::string& id, const std::string& level,
                       const std::string& x, const std::string& y, TexelView& out) {
    out = TexelView{};
    Entry e;
    std::string err = find_texture(s, id, level, e, out.info, out.level);
    if (!err.empty()) return err;
    out.width = out.info.level_sizes[std::size_t(out.level)].x;
    out.height = out.info.level_sizes[std::size_t(out.level)].y;
    long tx = 0, ty = 0;
    if (!parse_int(x, 0, out.width - 1, tx) || !parse_int(y, 0, out.height - 1, ty))
        return "texel '" + printable(x) + " " + printable(y) + "' of texture " + id + " level " +
               std::to_string(out.level) + ": outside its " + std::to_string(out.width) + "x" +
               std::to_string(out.height) + " texels (x 0.." + std::to_string(out.width - 1) + ", y 0.." +
               std::to_string(out.height - 1) + ")";
    out.x = int(tx);
    out.y = int(ty);
    const std::size_t at = std::size_t(ty) * std::size_t(out.width) + std::size_t(tx);
    static const char* kRgba[] = {"R", "G", "B", "A"};
    if (e.kind == Kind::Material) {
        const Texture& tex = *e.tex;
        const glm::vec4 v = tex.texel(out.level, out.x, out.y);  // what the samplers filter
        out.linear_names = {"R", "G", "B", "A"};
        out.linear = {v.r, v.g, v.b, v.a};
        if (tex.is_unorm8()) {
            const int C = tex.channels();
            const std::uint8_t* p = tex.unorm8_data() + (tex.level_offset(out.level) + at) * std::size_t(C);
            out.stored_type = "8-bit";
            out.stored_names = packed(tex) ? std::vector<std::string>{"roughness", "metal"}
                               : C == 1     ? std::vector<std::string>{"grey"}
                               : C == 2     ? std::vector<std::string>{"grey", "alpha"}
                                            : std::vector<std::string>(kRgba, kRgba + C);
            for (int c = 0; c < C; ++c) out.stored.push_back(p[c]);
            for (int k = 0; k < 4; ++k) {
                const int c = tex.swizzle(k);
                if (c == Texture::kOne) {
                    out.decode.push_back(std::string(kRgba[k]) + " = 1 (not stored)");
                    continue;
                }
                const bool srgb = tex.srgb(c);
                // The 15-bit code the fixed-point filter starts from (shading/texture.h).
                const int code = tex.code_table(c)[p[c]];
                out.decode.push_back(std::string(kRgba[k]) + " = " + (srgb ? "sRGB decode of " : "") +
                                     out.stored_names[std::size_t(c)] + " " + std::to_string(int(p[c])) +
                                     (srgb ? "" : " * 128") + " = code " + std::to_string(code) + " / 32640");
            }
        } else {
            out.stored_type = "float32";
            out.stored_names = out.linear_names;
            out.stored = out.linear;
            out.decode.push_back("stored linear: read as it is");
        }
    } else if (e.kind == Kind::Shadow) {
        const ShadowMap& m = *e.shadow;
        out.face = m.cube ? out.y / m.size : -1;
        out.fx = out.x;
        out.fy = m.cube ? out.y % m.size : out.y;
        const float d = m.at(m.cube ? out.face : 0, out.fx, out.fy);
        out.stored_type = "float32";
        out.stored_names = out.linear_names = {"distance"};
        out.stored = out.linear = {double(d)};
        out.decode.push_back(std::isfinite(d) ? "the distance from the light to the nearest caster"
                                              : "no caster drawn here (+inf: always lit)");
    } else {
        const EquirectLevel& L = e.env->specular_level(out.level);
        const glm::vec4 c = e.env->texels()[std::size_t(L.offset) + at];
        out.stored_type = "float32";
        out.stored_names = out.linear_names = {"R", "G", "B"};
        out.stored = out.linear = {c.r, c.g, c.b};
        out.decode.push_back("stored linear radiance: read as it is");
    }
    // The PNG's bytes there, by the level's rule (texture ID LEVEL).
    int w = 0, h = 0;
    std::vector<std::uint8_t> px;
    std::string note;
    const int channels = level_pixels(s, e, out.level, w, h, px, note);
    for (int k = 0; k < channels; ++k) out.shown.push_back(px[at * std::size_t(channels) + std::size_t(k)]);
    return "";
}

std::string TexelView::text() const {
    std::ostringstream o;
    o << "texel " << x << " " << y << " of texture " << info.id << " level " << level << " (" << width << "x" << height
      << ", " << info.format << ")";
    if (face >= 0) {
        static const char* kFaces[] = {"+X", "-X", "+Y", "-Y", "+Z", "-Z"};
        o << ": face " << kFaces[face] << " texel " << fx << " " << fy;
    }
    o << "\n";
    o << "  stored (" << stored_type << "): " << values_text(stored_names, stored, stored_type == "8-bit") << "\n";
    for (const std::string& d : decode) o << "    " << d << "\n";
    o << "  linear (what the samplers read): " << values_text(linear_names, linear, false) << "\n";
    o << "  shown in the PNG:";
    for (int v : shown) o << " " << v;
    o << " (" << info.png_rule << ")\n";
    return o.str();
}

json TexelView::json() const {
    nlohmann::json j = {{"id", info.id},         {"level", level},          {"x", x},
                        {"y", y},                {"width", width},          {"height", height},
                        {"format", info.format}, {"stored_type", stored_type}, {"stored_names", stored_names},
                        {"stored", values_json(stored, stored_type == "8-bit")}, {"decode", decode}, {"linear_names", linear_names},
                        {"linear", values_json(linear)}, {"shown", shown}, {"text", text()}};
    if (face >= 0) j["face"] = {{"face", face}, {"x", fx}, {"y", fy}};
    return j;
}

// ---------------------------------------------------------------- draws

namespace {

DrawLine draw_line(const FrameSetup& s, const Recording& rec, std::size_t di) {
    const DrawRecord& d = rec.draws[di];
    const Mesh& mesh = s.scene.meshes[std::size_t(d.mesh)];
    const BoundMaterial& bm = draw_material(s, d);
    DrawLine l;
    l.index = int(di);
    l.mesh = d.mesh;
    l.mesh_name = mesh.name;
    l.material = mesh.material >= 0 && std::size_t(mesh.material) < s.scene.materials.size() ? mesh.material : -1;
    l.material_name = bm.m->name;
    l.topology = d.topology;
    l.alpha = alpha_text(*bm.m);
    l.double_sided = bm.m->double_sided;
    l.varyings = d.varyings;
    l.program = program_text(d.varyings);
    if (d.topology == Topology::Triangles) {
        l.primitives = d.triangle_count;
        for (std::uint32_t t = 0; t < d.triangle_count; ++t)
            l.drawn += rec.triangles[d.first_triangle + t].fate == TriangleFate::SetUp;
    } else {
        l.primitives = d.primitives;
        for (std::uint32_t p = 0; p < d.primitives; ++p) l.drawn += replay_line(s, rec, di, p).drawn;
    }
    return l;
}

std::string prim_word(Topology t, std::uint64_t n) {
    return plural(n, t == Topology::Lines ? "line" : t == Topology::Points ? "point" : "triangle");
}

std::string line_text(const DrawLine& l) {
    std::string t = "draw " + std::to_string(l.index) + ": mesh " + std::to_string(l.mesh) + " " + quoted(l.mesh_name) +
                    ", material " + (l.material >= 0 ? std::to_string(l.material) + " " : std::string("(fallback) ")) +
                    quoted(l.material_name) + ", " + prim_word(l.topology, l.primitives) + ", ";
    if (l.drawn == 0) t += "culled (none survived clipping, culling and set-up)";
    else t += "visible (" + std::to_string(l.drawn) + " set up, " + std::to_string(l.primitives - l.drawn) +
              " culled or degenerate)";
    t += ", " + l.alpha + ", " + (l.double_sided ? "double-sided" : "single-sided") + ", " + l.program;
    return t;
}

json line_json(const DrawLine& l) {
    return {{"draw", l.index},           {"mesh", l.mesh},
            {"mesh_name", printable(l.mesh_name)},  {"material", l.material},
            {"material_name", printable(l.material_name)}, {"topology", topology_name(l.topology)},
            {"primitives", l.primitives}, {"drawn", l.drawn},
            {"visible", l.drawn > 0},    {"alpha", l.alpha},
            {"double_sided", l.double_sided}, {"varyings", l.varyings},
            {"program", l.program}};
}

} // namespace

std::string DrawsView::text() const {
    std::string t = plural(draws.size(), "draw") + ", in submission order:\n";
    for (const DrawLine& l : draws) t += "  " + line_text(l) + "\n";
    return t;
}

json DrawsView::json() const {
    nlohmann::json a = nlohmann::json::array();
    for (const DrawLine& l : draws) a.push_back(line_json(l));
    return {{"draws", a}, {"text", text()}};
}

std::string make_draws(const FrameSetup& s, const Recording& rec, DrawsView& out) {
    out = DrawsView{};
    for (std::size_t i = 0; i < rec.draws.size(); ++i) out.draws.push_back(draw_line(s, rec, i));
    return "";
}

std::string DrawView::text() const {
    std::string t = line_text(line) + "\n";
    for (const std::string& l : lines) t += l + "\n";
    return t;
}

json DrawView::json() const {
    nlohmann::json j = line_json(line);
    j["state"] = state;
    j["text"] = text();
    return j;
}

std::string make_draw(const FrameSetup& s, const Recording& rec, const std::string& n, DrawView& out) {
    out = DrawView{};
    long di = 0;
    if (!parse_int(n, 0, long(rec.draws.size()) - 1, di))
        return "draw '" + printable(n) + "': no such draw (draws " + range_of(rec.draws.size()) + ")";
    const DrawRecord& d = rec.draws[std::size_t(di)];
    const BoundMaterial& bm = draw_material(s, d);
    const Material& m = *bm.m;
    out.line = draw_line(s, rec, std::size_t(di));
    std::vector<std::string>& L = out.lines;
    json& st = out.state;
    if (d.topology == Topology::Triangles)
        L.push_back("  frame triangles " + std::to_string(d.first_triangle) + ".." +
                    std::to_string(d.first_triangle + d.triangle_count - (d.triangle_count ? 1 : 0)) + ", " +
                    plural(d.vertex_count, "vertex", "vertices"));
    else
        L.push_back("  " + plural(d.vertex_count, "vertex", "vertices"));
    st["vertices"] = d.vertex_count;
    st["first_triangle"] = d.first_triangle;

    // Material factors.
    L.push_back("  material: base colour " + vec(m.base_color_factor) + ", metallic " + num(m.metallic_factor) +
                ", roughness " + num(m.roughness_factor) + ", emissive " + vec(m.emissive_factor));
    L.push_back("    normal scale " + num(m.normal_scale) + ", occlusion strength " + num(m.occlusion_strength) +
                ", ior " + num(m.ior) + ", alpha " + alpha_text(m) + ", " +
                (m.double_sided ? "double-sided" : "single-sided"));
    st["material"] = {{"base_color", j4(m.base_color_factor)},
                      {"metallic", m.metallic_factor},
                      {"roughness", m.roughness_factor},
                      {"emissive", j3(m.emissive_factor)},
                      {"normal_scale", m.normal_scale},
                      {"occlusion_strength", m.occlusion_strength},
                      {"ior", m.ior},
                      {"alpha_mode", m.alpha_mode == AlphaMode::Mask    ? "MASK"
                                     : m.alpha_mode == AlphaMode::Blend ? "BLEND"
                                                                        : "OPAQUE"},
                      {"alpha_cutoff", m.alpha_cutoff},
                      {"double_sided", m.double_sided}};

    // Textures: each bound map with its texture ID, image, format and sampler.
    const std::vector<Entry> es = texture_entries(s);
    json maps = json::array();
    int count = 0;
    for (const Slot& sl : kSlots) {
        const Texture* t = bm.*sl.tex;
        const TextureRef& ref = m.*sl.ref;
        if (!t && !ref.valid()) continue;
        ++count;
        if (!t) {
            L.push_back("  map " + std::string(sl.name) + ": " + image_text(s, ref.image) +
                        " not decoded (the factor alone is used)");
            maps.push_back({{"slot", sl.name}, {"texture", nullptr}});
            continue;
        }
        auto it = std::find_if(es.begin(), es.end(), [&](const Entry& e) { return e.tex == t; });
        const TextureInfo info = info_of(s, *it);
        std::string images;
        for (const std::string& im : info.images) images += (images.empty() ? "" : " + ") + im;
        const int uv = int(bm.uv.*sl.uv);
        L.push_back("  map " + std::string(sl.name) + ": texture " + info.id + ", " + images + ", " +
                    std::to_string(info.width) + "x" + std::to_string(info.height) + ", " + info.format + ", " +
                    plural(std::uint64_t(info.levels), "mip level") + ", " + sampler_text(*t) + ", UV set " +
                    std::to_string(uv));
        const SamplerState& ss = t->sampler();
        maps.push_back({{"slot", sl.name},
                        {"texture", info.id},
                        {"images", info.images},
                        {"width", info.width},
                        {"height", info.height},
                        {"format", info.format},
                        {"colour_space", info.colour_space},
                        {"levels", info.levels},
                        {"sampler", sampler_text(*t)},
                        {"wrap_s", int(ss.wrap_s)},
                        {"wrap_t", int(ss.wrap_t)},
                        {"uv_set", uv}});
    }
    if (!count) L.push_back("  maps: none (the factors alone)");
    st["maps"] = maps;

    // Fixed-function state.
    const DrawState& ds = d.state;
    const char* blend = ds.blend == Blend::Alpha ? "alpha (src a + dst (1 - a))" : ds.blend == Blend::Add ? "add" : "replace";
    L.push_back(std::string("  state: cull ") + (d.topology != Topology::Triangles ? "n/a (lines and points)"
                                                 : ds.cull == CullMode::Back ? "back faces" : "none") +
                ", depth test " + (ds.depth_test ? "LESS" : "off") + ", depth write " + (ds.depth_write ? "on" : "off") +
                ", blend " + blend + (ds.may_discard ? ", may discard (alpha MASK)" : "") + "; " +
                (d.visible ? "visibility pass (each sample's winner shaded once)" : "shaded in submission order"));
    st["cull"] = ds.cull == CullMode::Back ? "back" : "none";
    st["depth_test"] = ds.depth_test;
    st["depth_write"] = ds.depth_write;
    st["blend"] = ds.blend == Blend::Alpha ? "alpha" : ds.blend == Blend::Add ? "add" : "replace";
    st["may_discard"] = ds.may_discard;
    st["visibility_pass"] = d.visible;

    // What lights it.
    json lights = json::array();
    const bool unlit = d.varyings == UnlitProgram::kVaryings;
    const bool shadows = s.settings.shadows.enabled;
    const ShadingContext ctx = shadows ? s.shading_context() : ShadingContext{};
    if (unlit) {
        L.push_back("  lights: none (unlit: base colour factor x texture x vertex colour)");
    } else {
        for (std::size_t i = 0; i < s.settings.lights.size(); ++i) {
            const ShadingLight& li = s.settings.lights[i];
            std::string t = "  light " + std::to_string(i) + ": " +
                            (li.point ? "point at " + vec(li.position) : "sun towards " + vec(li.direction));
            json jl = {{"light", i}, {"type", li.point ? "point" : "directional"}, {"radiance", j3(li.radiance)}};
            if (li.point) jl["position"] = j3(li.position);
            else jl["direction"] = j3(li.direction);
            if (i < s.scene.lights.size() && !s.used_default_rig) {
                const Light& sl = s.scene.lights[i];
                t += ", colour " + vec(sl.color) + " intensity " + num(sl.intensity);
                jl["colour"] = j3(sl.color);
                jl["intensity"] = sl.intensity;
            }
            t += ", radiance " + vec(li.radiance);
            const ShadowMap* map = shadows && i < ctx.lights.size() ? ctx.lights[i].shadow : nullptr;
            if (map) {
                t += ", shadow map shadow" + std::to_string(i) + " (" +
                     (map->cube ? "cube, 6 faces of " : "directional, ") + std::to_string(map->size) + "x" +
                     std::to_string(map->size) + ")";
                jl["shadow"] = {{"texture", "shadow" + std::to_string(i)}, {"size", map->size}, {"cube", map->cube}};
            } else {
                t += shadows ? ", no shadow map" : "";
            }
            L.push_back(t);
            lights.push_back(jl);
        }
        if (s.settings.lights.empty()) L.push_back("  lights: none");
    }
    st["lights"] = lights;
    L.push_back(std::string("  shadows ") + (shadows ? "on, maps of " + std::to_string(s.settings.shadows.size) +
                                                           " texels a side (cube faces half that)"
                                                     : "off"));
    st["shadows"] = {{"enabled", shadows}, {"size", s.settings.shadows.size}};
    const Environment* env = s.scene_renderer->environment(s.settings);
    if (unlit) {
        st["environment"] = nullptr;
    } else if (env) {
        L.push_back("  environment: texture env, " + std::to_string(env->width()) + "x" + std::to_string(env->height()) +
                    ", intensity " + num(s.request.env_intensity) + ", rotated " + num(s.request.env_rotate_deg) +
                    " degrees, split sum in place of the ambient term");
        st["environment"] = {{"texture", "env"}, {"width", env->width()}, {"height", env->height()}};
    } else {
        L.push_back("  ambient " + vec(s.settings.ambient) + " (no environment)");
        st["environment"] = nullptr;
        st["ambient"] = j3(s.settings.ambient);
    }
    return "";
}

// ---------------------------------------------------------------- vertices

std::string VerticesView::text() const {
    std::ostringstream o;
    o << "vertices of draw " << draw << " (mesh " << quoted(mesh_name) << "): " << rows.size() << " of "
      << plural(vertex_count, "vertex", "vertices") << " from " << first;
    if (capped) o << " (" << requested << " asked, capped at " << kMaxVertexRows << " rows: ask again with FIRST "
                  << first + rows.size() << " for more)";
    o << "\n";
    o << "  out: clip (x, y, z, w), window (x, y) px and z, then the " << varyings << " varyings: " << layout << "\n";
    for (const VertexRow& r : rows) {
        o << "  v" << r.index << " in: position " << vec(r.position);
        if (r.has_normal) o << " normal " << vec(r.normal);
        if (r.has_uv0) o << " uv0 " << vec(r.uv0);
        if (r.has_uv1) o << " uv1 " << vec(r.uv1);
        if (r.has_tangent) o << " tangent " << vec(r.tangent);
        if (r.has_color) o << " colour " << vec(r.color);
        for (int set = 0; set < r.influence_sets; ++set) {
            o << " joints" << set << " (";
            for (int k = 0; k < 4; ++k) o << (k ? ", " : "") << r.joints[std::size_t(set * 4 + k)];
            o << ") weights" << set << " (";
            for (int k = 0; k < 4; ++k) o << (k ? ", " : "") << num(r.weights[std::size_t(set * 4 + k)]);
            o << ")";
        }
        o << "\n     out: clip " << vec(glm::vec4(r.clip[0], r.clip[1], r.clip[2], r.clip[3])) << " window ("
          << num(r.window[0]) << ", " << num(r.window[1]) << ") z " << num(r.window_z) << " varyings (";
        for (std::size_t k = 0; k < r.varyings.size(); ++k) o << (k ? ", " : "") << num(r.varyings[k]);
        o << ")\n";
    }
    return o.str();
}

json VerticesView::json() const {
    nlohmann::json a = nlohmann::json::array();
    for (const VertexRow& r : rows) {
        nlohmann::json v = {{"index", r.index},
                            {"position", j3(r.position)},
                            {"clip", {r.clip[0], r.clip[1], r.clip[2], r.clip[3]}},
                            {"window", {r.window[0], r.window[1], r.window_z}},
                            {"varyings", r.varyings}};
        if (r.has_normal) v["normal"] = j3(r.normal);
        if (r.has_uv0) v["uv0"] = j2(r.uv0);
        if (r.has_uv1) v["uv1"] = j2(r.uv1);
        if (r.has_tangent) v["tangent"] = j4(r.tangent);
        if (r.has_color) v["colour"] = j4(r.color);
        if (r.influence_sets) {
            v["joints"] = r.joints;
            v["weights"] = r.weights;
        }
        a.push_back(v);
    }
    return {{"draw", draw},         {"mesh_name", printable(mesh_name)}, {"vertex_count", vertex_count},
            {"first", first},       {"requested", requested}, {"capped", capped},
            {"max_rows", kMaxVertexRows}, {"varyings", varyings}, {"layout", layout},
            {"vertices", a},        {"text", text()}};
}

std::string make_vertices(const FrameSetup& s, const Recording& rec, const std::string& n, const std::string& first,
                          const std::string& count, VerticesView& out) {
    out = VerticesView{};
    long di = 0, f = 0, c = kDefaultVertexRows;
    if (!parse_int(n, 0, long(rec.draws.size()) - 1, di))
        return "vertices '" + printable(n) + "': no such draw (draws " + range_of(rec.draws.size()) + ")";
    const DrawRecord& d = rec.draws[std::size_t(di)];
    if (!first.empty() && !parse_int(first, 0, long(d.vertex_count) - 1, f))
        return "vertices " + n + " '" + printable(first) + "': no such vertex (draw " + n + " has vertices " +
               range_of(d.vertex_count) + ")";
    if (!count.empty() && !parse_int(count, 1, 1L << 40, c))
        return "vertices " + n + " " + first + " '" + printable(count) + "': not a count (1 or more)";
    const Mesh& mesh = s.scene.meshes[std::size_t(d.mesh)];
    out.draw = int(di);
    out.mesh_name = mesh.name;
    out.vertex_count = d.vertex_count;
    out.first = std::uint32_t(f);
    out.requested = c;
    out.varyings = d.varyings;
    if (d.varyings == UnlitProgram::kVaryings) out.layout = "uv (2), rgba (4)";
    else
        out.layout = std::string("P (3), N (3), uv0 (2), T (4)") +
                     (d.varyings == kPbrVaryingsExt ? ", uv1 (2), colour (4)" : "");
    // The source primitive's skinning, when the file has one.
    const SourcePrimitive* prim = nullptr;
    if (s.scene.source && mesh.source_node >= 0 && std::size_t(mesh.source_node) < s.scene.source->nodes.size()) {
        const SourceNode& node = s.scene.source->nodes[std::size_t(mesh.source_node)];
        if (node.mesh >= 0 && std::size_t(node.mesh) < s.scene.source->meshes.size()) {
            const SourceMesh& sm = s.scene.source->meshes[std::size_t(node.mesh)];
            if (mesh.source_primitive >= 0 && std::size_t(mesh.source_primitive) < sm.primitives.size())
                prim = &sm.primitives[std::size_t(mesh.source_primitive)];
        }
    }
    const long rows = std::min<long>(std::min<long>(c, kMaxVertexRows), long(d.vertex_count) - f);
    out.capped = c > kMaxVertexRows && long(d.vertex_count) - f > kMaxVertexRows;
    for (long k = 0; k < rows; ++k) {
        const std::uint32_t i = std::uint32_t(f + k);
        VertexRow r;
        r.index = i;
        if (i < mesh.positions.size()) r.position = mesh.positions[i];
        if ((r.has_normal = i < mesh.normals.size())) r.normal = mesh.normals[i];
        if ((r.has_uv0 = i < mesh.uvs.size())) r.uv0 = mesh.uvs[i];
        if ((r.has_uv1 = i < mesh.uvs1.size())) r.uv1 = mesh.uvs1[i];
        if ((r.has_tangent = i < mesh.tangents.size())) r.tangent = mesh.tangents[i];
        if ((r.has_color = i < mesh.colors.size())) r.color = mesh.colors[i];
        if (prim && prim->influence_sets > 0 && i < mesh.source_vertex.size()) {
            const std::size_t nv = prim->positions.size(), sv = mesh.source_vertex[i];
            if (sv < nv && prim->joints.size() >= std::size_t(prim->influence_sets) * nv * 4 &&
                prim->weights.size() >= std::size_t(prim->influence_sets) * nv * 4) {
                r.influence_sets = prim->influence_sets;
                for (int set = 0; set < prim->influence_sets; ++set)
                    for (std::size_t q = 0; q < 4; ++q) {
                        const std::size_t at = (std::size_t(set) * nv + sv) * 4 + q;
                        r.joints.push_back(prim->joints[at]);
                        r.weights.push_back(prim->weights[at]);
                    }
            }
        }
        float v[kMaxStride];
        d.full_vertex(i, v);
        for (int q = 0; q < 4; ++q) r.clip[q] = v[q];
        const SnappedVertex w = snap_vertex(v, rec.width, rec.height);
        r.window[0] = w.x_win;
        r.window[1] = w.y_win;
        r.window_z = w.z;
        r.varyings.assign(v + 4, v + 4 + d.varyings);
        out.rows.push_back(r);
    }
    return "";
}

// ---------------------------------------------------------------- tile

std::string TileView::text() const {
    std::ostringstream o;
    o << "tile " << tx << " " << ty << ": pixels x " << x0 << ".." << x1 << " y " << y0 << ".." << y1 << "\n";
    o << "  " << plural(triangles, "triangle") << " binned (" << plural(bin_entries, "bin entry", "bin entries")
      << "), " << plural(blocks, "4x4 block") << ", " << plural(covered, "fragment") << " covered: " << passed
      << " passed the depth test, " << failed << " failed; " << shaded << " shaded, " << written << " written to "
      << plural(pixels_written, "pixel") << "\n";
    if (summary_only) return o.str();
    if (filter.empty())
        o << "the " << plural(bins.size(), "bin entry", "bin entries") << " in the order the tile ran them:\n";
    else
        o << plural(bins.size(), "bin entry", "bin entries") << " of " << filter << ", in the order the tile ran them:\n";
    for (const TileBin& b : bins) {
        o << "  tri " << b.triangle;
        if (b.piece_in_triangle >= 0) o << " piece " << b.piece_in_triangle;
        o << " (" << quoted(b.mesh) << "): " << plural(std::uint64_t(b.blocks), "block") << ", "
          << plural(std::uint64_t(b.covered), "fragment") << ", " << b.passed << " passed depth, " << b.shaded
          << " shaded, " << b.written << " written\n";
        for (const std::string& l : b.block_lines) o << "    " << l << "\n";
    }
    return o.str();
}

json TileView::json() const {
    nlohmann::json tris = nlohmann::json::array(), bs = nlohmann::json::array();
    for (const TileBin& b : bins) {
        tris.push_back(b.triangle);
        bs.push_back({{"triangle", b.triangle}, {"piece", b.piece}, {"mesh", printable(b.mesh)}, {"blocks", b.blocks},
                      {"covered", b.covered}, {"passed", b.passed}, {"shaded", b.shaded}, {"written", b.written}});
    }
    return {{"tile", {tx, ty}},
            {"pixels", {x0, y0, x1, y1}},
            {"summary", {{"triangles", triangles}, {"bin_entries", bin_entries}, {"blocks", blocks},
                         {"covered", covered}, {"passed", passed}, {"failed", failed}, {"shaded", shaded},
                         {"written", written}, {"pixels_written", pixels_written}}},
            {"filter", filter},
            {"triangles", tris},
            {"bins", bs},
            {"text", text()}};
}

std::string make_tile(const FrameSetup& s, const Recording& rec, const std::vector<std::string>& args, TileView& out) {
    out = TileView{};
    static const char* kUsage = "usage: tile X Y [tri N | pixel X Y | --summary] (tile column and row)";
    if (args.size() < 2) return kUsage;
    long a = 0, b = 0;
    if (!parse_int(args[0], 0, rec.tiles_x - 1, a) || !parse_int(args[1], 0, rec.tiles_y - 1, b))
        return "tile '" + printable(args[0]) + " " + printable(args[1]) + "': outside the " +
               std::to_string(rec.tiles_x) + "x" + std::to_string(rec.tiles_y) + " tiles (columns " +
               range_of(std::size_t(rec.tiles_x)) + ", rows " + range_of(std::size_t(rec.tiles_y)) + ")";
    out.tx = int(a);
    out.ty = int(b);
    out.x0 = out.tx * rec.tile_size;
    out.y0 = out.ty * rec.tile_size;
    out.x1 = std::min(out.x0 + rec.tile_size, rec.width) - 1;
    out.y1 = std::min(out.y0 + rec.tile_size, rec.height) - 1;
    long want_tri = -1, px = -1, py = -1;
    if (args.size() == 3 && args[2] == "--summary") {
        out.summary_only = true;
        out.filter = "--summary";
    } else if (args.size() == 4 && args[2] == "tri") {
        if (!parse_int(args[3], 0, long(rec.triangle_count()) - 1, want_tri))
            return "tile " + args[0] + " " + args[1] + " tri '" + printable(args[3]) + "': not a triangle number (" +
                   range_of(rec.triangle_count()) + ")";
        out.filter = "tri " + args[3];
    } else if (args.size() == 5 && args[2] == "pixel") {
        if (!parse_int(args[3], out.x0, out.x1, px) || !parse_int(args[4], out.y0, out.y1, py))
            return "tile " + args[0] + " " + args[1] + " pixel '" + printable(args[3]) + " " + printable(args[4]) +
                   "': not in the tile (x " + std::to_string(out.x0) + ".." + std::to_string(out.x1) + ", y " +
                   std::to_string(out.y0) + ".." + std::to_string(out.y1) + ")";
        out.filter = "pixel " + args[3] + " " + args[4];
    } else if (args.size() != 2) {
        return kUsage;
    }
    const TileRecord& t = rec.tiles[std::size_t(out.ty * rec.tiles_x + out.tx)];
    out.bin_entries = t.pieces.size();
    out.blocks = t.blocks.size();
    std::vector<std::uint32_t> tris;
    for (std::uint32_t pi : t.pieces) tris.push_back(rec.pieces[pi].triangle);
    std::sort(tris.begin(), tris.end());
    out.triangles = std::uint64_t(std::unique(tris.begin(), tris.end()) - tris.begin());
    // Per piece, in one pass over the tile's blocks; the pixels written.
    struct Counts { int blocks = 0, covered = 0, passed = 0, shaded = 0, written = 0; std::vector<std::size_t> at; };
    std::vector<std::uint64_t> written_px(std::size_t(rec.tile_size) * std::size_t(rec.tile_size) / 64 + 1, 0);
    std::vector<std::uint32_t> order(t.pieces);
    std::sort(order.begin(), order.end());
    order.erase(std::unique(order.begin(), order.end()), order.end());
    std::vector<Counts> per(order.size());
    const bool pixel_filter = px >= 0;
    int lane = 0;
    for (int l = 0; l < kBlockLanes; ++l)
        if (pixel_filter && lane_x(l) == int(px & 3) && lane_y(l) == int(py & 3)) lane = l;
    for (std::size_t k = 0; k < t.blocks.size(); ++k) {
        const BlockRecord& bl = t.blocks[k];
        out.covered += std::uint64_t(__builtin_popcount(bl.mask));
        out.passed += std::uint64_t(__builtin_popcount(bl.pass));
        out.shaded += std::uint64_t(__builtin_popcount(bl.shaded));
        out.written += std::uint64_t(__builtin_popcount(bl.live));
        for (std::uint32_t m = bl.live; m; m &= m - 1) {
            const int l = __builtin_ctz(m);
            const std::size_t i = std::size_t(bl.by + lane_y(l) - out.y0) * std::size_t(rec.tile_size) +
                                  std::size_t(bl.bx + lane_x(l) - out.x0);
            written_px[i / 64] |= std::uint64_t(1) << (i % 64);
        }
        const std::size_t pi = std::size_t(std::lower_bound(order.begin(), order.end(), bl.piece) - order.begin());
        if (pi >= order.size() || order[pi] != bl.piece) continue;
        Counts& c = per[pi];
        ++c.blocks;
        c.covered += __builtin_popcount(bl.mask);
        c.passed += __builtin_popcount(bl.pass);
        c.shaded += __builtin_popcount(bl.shaded);
        c.written += __builtin_popcount(bl.live);
        if (want_tri >= 0 || (pixel_filter && bl.bx == (px & ~3L) && bl.by == (py & ~3L))) c.at.push_back(k);
    }
    out.failed = out.covered - out.passed;
    for (std::uint64_t w : written_px) out.pixels_written += std::uint64_t(__builtin_popcountll(w));
    if (out.summary_only) return "";
    for (std::uint32_t pi : t.pieces) {
        const PieceRecord& p = rec.pieces[pi];
        if (want_tri >= 0 && p.triangle != std::uint32_t(want_tri)) continue;
        const Counts& c = per[std::size_t(std::lower_bound(order.begin(), order.end(), pi) - order.begin())];
        TileBin tb;
        if (pixel_filter) {
            // Only the pieces whose block covers the pixel; that block's lane.
            bool covers = false;
            for (std::size_t k : c.at) {
                const BlockRecord& bl = t.blocks[k];
                if (!(bl.mask >> lane & 1u)) continue;
                covers = true;
                tb.block_lines.push_back("block " + std::to_string(bl.bx) + " " + std::to_string(bl.by) + " lane " +
                                         std::to_string(lane) + ": covered, " +
                                         (bl.pass >> lane & 1u ? "passed depth" : "failed depth") +
                                         (bl.shaded >> lane & 1u ? ", shaded" : ", not shaded") +
                                         (bl.live >> lane & 1u ? ", written" : ", not written"));
            }
            if (!covers) continue;
        } else if (want_tri >= 0) {
            for (std::size_t k : c.at) {
                const BlockRecord& bl = t.blocks[k];
                tb.block_lines.push_back("block " + std::to_string(bl.bx) + " " + std::to_string(bl.by) + ": covered " +
                                         hex16(bl.mask) + " passed " + hex16(bl.pass) + " shaded " + hex16(bl.shaded) +
                                         " written " + hex16(bl.live));
            }
        }
        const TriangleRecord& tr = rec.triangles[p.triangle];
        tb.piece = pi;
        tb.triangle = p.triangle;
        tb.piece_in_triangle = tr.piece_count > 1 ? int(pi - tr.first_piece) : -1;
        tb.mesh = mesh_name(s, rec, p.triangle);
        tb.blocks = c.blocks;
        tb.covered = c.covered;
        tb.passed = c.passed;
        tb.shaded = c.shaded;
        tb.written = c.written;
        out.bins.push_back(tb);
    }
    return "";
}

} // namespace prast::stepper

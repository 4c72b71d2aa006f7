// llvmpipe-render: the same frame as `render`, drawn by Mesa's llvmpipe through
// OSMesa and OpenGL 3.3 core, for side-by-side speed comparisons
// (`bench --side-by-side build/llvmpipe-render build/render`). It takes
// render's command line (apps/render_options.h), sets the frame up with
// render's own set-up (renderer/frame_setup.h: the scene, camera, lights and
// memory check), decodes the textures with prast's own decoders, and
// shades with a GLSL port of the conventions' Cook-Torrance (shading/brdf.h,
// surface.h): metal-roughness maps, tangent-space normal maps, occlusion,
// emissive, suns, point lights and KHR_lights_punctual's spot cone and range
// window, the flat ambient term, exposure and the ACES / neutral / clamp tone
// maps (the sRGB encoding is the target's), the KHR_materials_specular,
// _clearcoat and _sheen lobes with their maps, KHR_materials_transmission and
// _volume under the lights (the mirrored lobe of a light behind the surface,
// the Beer-Lambert transmittance), KHR_materials_unlit, and
// KHR_texture_transform with its texCoord override on every map (TEXCOORD_0
// and _1) (docs/shading.md, "Against llvmpipe", has the agreement and
// make_lobe_models.py the test models). Textures are uploaded in
// their 8-bit form (sRGB formats for colour maps) and glGenerateMipmap builds
// their chains; sampling is trilinear, as render's.
//
// Not ported (the bench workloads do not use them): measured conductors (Pc),
// alpha MASK, debug views, image-based lighting (so transmission sees only
// the lights behind the surface, never an environment), shadows, blending,
// vertex colours, --brdf gltf and --energy conserve.
//
// Set up as a GL application would for speed, so that the comparison is fair
// to llvmpipe: one fragment program per combination of maps, their UV sets and
// transforms, layered lobes and tone map
// (shader permutations from one source with #defines, not branches on
// uniforms), vertex and index buffers, 8-bit textures with sRGB formats and
// generated mips, and an 8-bit sRGB framebuffer object (GL_FRAMEBUFFER_SRGB:
// the driver encodes, as render's resolve does) rather than the OSMesa window.
//
// Timing: `--repeat N` prints `frame_ms min=.. median=.. max=..` like render,
// where a frame is the clear, every draw, the tone map and a glFinish; one
// untimed frame first compiles llvmpipe's shader variants (it does on first
// use). The tone map runs in the fragment shader at 1 sample; with --msaa N > 1
// the linear radiance is resolved by a blit and tone mapped in a second pass,
// as render averages linear radiance before its tone map. The read back of the
// image (glReadPixels) and the PNG write follow the frames, counted in the
// whole process (--stats prints the read back). --threads N sets
// LP_NUM_THREADS. Samples: --msaa as render's, 4 by default (so bench passes
// --msaa: --help lists it). Built only with -DPRAST_LLVMPIPE=ON (libosmesa6-dev).
#define GL_GLEXT_PROTOTYPES 1
#include <GL/osmesa.h>
#include <GL/glcorearb.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <string>
#include <vector>

#include "apps/frame_request.h"
#include "apps/render_options.h"
#include "renderer/frame_setup.h"
#include "scene/camera.h"
#include "scene/image.h"
#include "scene/write_image.h"
#include "shading/brdf.h"

using namespace prast;

namespace {

using Clock = std::chrono::steady_clock;
double ms_since(Clock::time_point t0) {
    return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

const char* kVertexShader = R"(#version 330 core
layout(location = 0) in vec3 a_position;
layout(location = 1) in vec3 a_normal;
layout(location = 2) in vec2 a_uv;
layout(location = 3) in vec4 a_tangent;
layout(location = 4) in vec2 a_uv1;  // TEXCOORD_1 (disabled, so 0, for meshes without it)
uniform mat4 u_view_proj;
out vec3 v_position; out vec3 v_normal; out vec2 v_uv; out vec4 v_tangent; out vec2 v_uv1;
void main() {
    v_position = a_position; v_normal = a_normal; v_uv = a_uv; v_tangent = a_tangent; v_uv1 = a_uv1;
    gl_Position = u_view_proj * vec4(a_position, 1.0);
}
)";

// The tone maps (shading/tonemap.cpp), for both fragment programs. TONEMAP
// (0 clamp, 1 ACES, 2 neutral) is #defined before it (program_source); the
// result is in [0, 1], and the sRGB target encodes it.
const char* kToneMapGlsl = R"(
uniform float u_exposure;
float aces(float x) {
    return clamp(x * (2.51 * x + 0.03) / (x * (2.43 * x + 0.59) + 0.14), 0.0, 1.0);
}
vec3 neutral(vec3 c) {
    c = max(c, vec3(0.0));
    float x = min(c.r, min(c.g, c.b));
    float offset = x < 0.08 ? x - 6.25 * x * x : 0.04;
    c -= offset;
    float peak = max(c.r, max(c.g, c.b));
    if (peak < 0.76) return c;
    float d = 0.24;
    float new_peak = 1.0 - d * d / (peak + d - 0.76);
    c *= new_peak / peak;
    float g = 1.0 - 1.0 / (0.15 * (peak - new_peak) + 1.0);
    return mix(c, vec3(new_peak), g);
}
vec3 display(vec3 c) {
    c *= u_exposure;
#if TONEMAP == 1
    return vec3(aces(c.r), aces(c.g), aces(c.b));
#elif TONEMAP == 2
    return clamp(neutral(c), 0.0, 1.0);
#else
    return clamp(c, 0.0, 1.0);
#endif
}
)";

// The conventions' Cook-Torrance, line for line with shading/brdf.h and
// shading/surface.h (default BRDF), with KHR_materials_specular's F0 / F90,
// KHR_materials_clearcoat's lobe and KHR_materials_sheen's lobe over the base
// as evaluate_brdf() has them (in float; brdf.h takes the sheen in double),
// KHR_materials_transmission's share of the diffuse and its mirrored lobe for
// a light behind the surface with KHR_materials_volume's transmittance, the
// spot cone and range window of light_falloff() (surface.h), and the normals
// bent as facing_normal() bends them. MAPS (bits: 1 base, 2 metal-rough, 4
// rough, 8 metal, 16 normal, 32 occlusion, 64 emissive, 128 specular, 256
// specular colour, 512 clearcoat, 1024 clearcoat roughness, 2048 clearcoat
// normal, 4096 sheen colour, 8192 sheen roughness, 16384 transmission, 32768
// thickness; the sheen's albedo table of brdf.h is t_sheen_E), XF and SET1
// (the same bits: the map's UVs go through its KHR_texture_transform, u_xf;
// the map reads TEXCOORD_1), SPECULAR, CLEARCOAT, SHEEN and TRANSMISSION (1:
// the material has the lobe), UNLIT (1: KHR_materials_unlit) and LINEAR_OUT
// (1: linear radiance for the MSAA resolve) are #defined before it.
const char* kFragmentShader = R"(
#define HAS(bit) ((MAPS & bit) != 0)
in vec3 v_position; in vec3 v_normal; in vec2 v_uv; in vec4 v_tangent; in vec2 v_uv1;
out vec4 o_color;
uniform vec4 u_base_color_factor;
uniform float u_metallic_factor, u_roughness_factor, u_normal_scale, u_occlusion_strength, u_ior;
uniform vec3 u_emissive_factor;
uniform sampler2D t_base, t_mr, t_rough, t_metal, t_normal, t_occlusion, t_emissive;
uniform float u_specular_factor;
uniform vec3 u_specular_color_factor;
uniform float u_clearcoat, u_clearcoat_roughness, u_clearcoat_normal_scale;  // u_clearcoat 0: no coat
uniform sampler2D t_specular, t_specular_color, t_clearcoat, t_clearcoat_rough, t_clearcoat_normal;
uniform vec3 u_sheen_color_factor;  // 0: no sheen
uniform float u_sheen_roughness_factor;
uniform sampler2D t_sheen_color, t_sheen_rough, t_sheen_E;
uniform float u_transmission, u_thickness, u_attenuation_distance;  // thickness 0: thin; distance 0: infinite
uniform vec3 u_attenuation_color;
uniform sampler2D t_transmission, t_thickness;
uniform vec4 u_xf[16];          // map i's transform: u' = (x u + y v) + ox, v' = (z u + w v) + oy
uniform vec2 u_xf_offset[16];
uniform vec3 u_eye;
uniform int u_light_count;
uniform vec4 u_light[8];        // xyz: direction towards the light (w = 0) or position (w = 1)
uniform vec3 u_light_radiance[8];
uniform vec4 u_light_shape[8];  // point and spot: cone scale, cone offset, 1 / range^2 (0: none), 1: spot
uniform vec3 u_light_axis[8];   // spot: towards the light along its axis
uniform vec3 u_ambient;
const float PI = 3.14159265358979;

// Map i's UVs: its set, through its transform (i a constant: the branches fold).
vec2 map_uv(int i) {
    vec2 uv = ((SET1 >> i) & 1) != 0 ? v_uv1 : v_uv;
    if (((XF >> i) & 1) != 0)
        uv = vec2(u_xf[i].x * uv.x + u_xf[i].y * uv.y + u_xf_offset[i].x,
                  u_xf[i].z * uv.x + u_xf[i].w * uv.y + u_xf_offset[i].y);
    return uv;
}

vec3 safe_normalize(vec3 v, vec3 fallback) {
    float len2 = dot(v, v);
    return len2 > 1e-20 ? v / sqrt(len2) : fallback;
}
// surface.h's facing_normal(): a normal turned away from the eye is bent
// towards v until n.v = 1e-4, as render bends the base's and the coat's. At
// n.v = 0 the G and V terms would black out silhouette pixels that render
// lights with a grazing specular, coat or sheen (up to 248 levels apart).
vec3 facing_normal(vec3 n, vec3 v) {
    float d = dot(n, v);
    if (!(d < 1e-4)) return n;
    vec3 b = n + v * (1e-4 - d);
    return b / sqrt(dot(b, b));
}

// KHR_materials_sheen's Charlie distribution and visibility (brdf.h).
float sheen_l(float x, float a) {
    float t = (1.0 - a) * (1.0 - a);
    return mix(21.5473, 25.3245, t) / (1.0 + mix(3.82987, 3.32435, t) * pow(x, mix(0.19823, 0.16801, t))) +
           mix(-1.97760, -1.27393, t) * x + mix(-4.32054, -4.85967, t);
}
float sheen_lambda(float c, float a) {
    return c < 0.5 ? exp(sheen_l(c, a)) : exp(2.0 * sheen_l(0.5, a) - sheen_l(1.0 - c, a));
}
float sheen_E(float NoV, float r) {  // the table's texel centres: n.v i / 31, r j / 15
    return texture(t_sheen_E, vec2((NoV * 31.0 + 0.5) / 32.0, (r * 15.0 + 0.5) / 16.0)).r;
}

void main() {
    vec4 base = u_base_color_factor;
    if (HAS(1)) base *= texture(t_base, map_uv(0));
#if UNLIT
    // KHR_materials_unlit: the base colour term alone, no light, ambient or emission.
    o_color = LINEAR_OUT != 0 ? vec4(base.rgb, 1.0) : vec4(display(base.rgb), 1.0);
    return;
#endif
    float metallic = u_metallic_factor, roughness = u_roughness_factor;
    if (HAS(2)) { vec4 mr = texture(t_mr, map_uv(1)); roughness *= mr.g; metallic *= mr.b; }
    if (HAS(4)) roughness *= texture(t_rough, map_uv(2)).r;
    if (HAS(8)) metallic *= texture(t_metal, map_uv(3)).r;
    metallic = clamp(metallic, 0.0, 1.0);
    roughness = clamp(roughness, 0.0, 1.0);
    float occlusion = 1.0;
    if (HAS(32)) occlusion = 1.0 + u_occlusion_strength * (texture(t_occlusion, map_uv(5)).r - 1.0);
    vec3 emissive = u_emissive_factor;
    if (HAS(64)) emissive *= texture(t_emissive, map_uv(6)).rgb;
#if SPECULAR
    float spec = u_specular_factor;
    vec3 spec_color = u_specular_color_factor;
    if (HAS(128)) spec *= texture(t_specular, map_uv(7)).a;
    if (HAS(256)) spec_color *= texture(t_specular_color, map_uv(8)).rgb;
    spec = clamp(spec, 0.0, 1.0);
#endif
#if CLEARCOAT
    float cc = u_clearcoat, ccr = u_clearcoat_roughness;
    if (HAS(512)) cc *= texture(t_clearcoat, map_uv(9)).r;
    if (HAS(1024)) ccr *= texture(t_clearcoat_rough, map_uv(10)).g;
    cc = clamp(cc, 0.0, 1.0);
    ccr = clamp(ccr, 0.0, 1.0);
#endif
#if SHEEN
    vec3 sheen = u_sheen_color_factor;
    float sr = u_sheen_roughness_factor;
    if (HAS(4096)) sheen *= texture(t_sheen_color, map_uv(12)).rgb;
    if (HAS(8192)) sr *= texture(t_sheen_rough, map_uv(13)).a;
    sheen = clamp(sheen, 0.0, 1.0);
    float rs = clamp(sr, 0.045, 1.0), as = rs * rs;
    float smax = max(sheen.r, max(sheen.g, sheen.b));
#endif
#if TRANSMISSION
    float tr = u_transmission;
    if (HAS(16384)) tr *= texture(t_transmission, map_uv(14)).r;
    tr = clamp(tr, 0.0, 1.0);
    float thickness = u_thickness;
    if (HAS(32768)) thickness *= texture(t_thickness, map_uv(15)).g;
    thickness = max(thickness, 0.0);
    // Beer-Lambert over the thickness: colour^(thickness / distance) per channel.
    vec3 transmittance = vec3(1.0);
    if (thickness > 0.0 && u_attenuation_distance > 0.0) {
        float e = thickness / u_attenuation_distance;
        for (int c = 0; c < 3; ++c)
            transmittance[c] = u_attenuation_color[c] > 0.0 ? pow(u_attenuation_color[c], e) : 0.0;
    }
#endif

    vec3 N = safe_normalize(v_normal, vec3(0.0, 0.0, 1.0));
    float flip = gl_FrontFacing ? 1.0 : -1.0;
    vec3 n = N * flip;
#if CLEARCOAT
    vec3 nc = n;  // the coat's normal: the geometric one unless it has its own map
    if (HAS(2048)) {
        vec3 T = safe_normalize(v_tangent.xyz - N * dot(N, v_tangent.xyz), vec3(0.0));
        if (dot(T, T) > 0.0) {
            float w = v_tangent.w < 0.0 ? -1.0 : 1.0;
            vec3 B = cross(N, T) * w;
            vec3 nt = texture(t_clearcoat_normal, map_uv(11)).rgb * 2.0 - 1.0;
            nt.xy *= u_clearcoat_normal_scale;
            nt = safe_normalize(nt, vec3(0.0, 0.0, 1.0));
            nc = safe_normalize(T * nt.x + B * nt.y + N * nt.z, N) * flip;
        }
    }
#endif
    if (HAS(16)) {
        vec3 T = safe_normalize(v_tangent.xyz - N * dot(N, v_tangent.xyz), vec3(0.0));
        if (dot(T, T) > 0.0) {
            float w = v_tangent.w < 0.0 ? -1.0 : 1.0;
            vec3 B = cross(N, T) * w;
            vec3 nt = texture(t_normal, map_uv(4)).rgb * 2.0 - 1.0;
            nt.xy *= u_normal_scale;
            nt = safe_normalize(nt, vec3(0.0, 0.0, 1.0));
            n = safe_normalize(T * nt.x + B * nt.y + N * nt.z, N) * flip;
        }
    }
    vec3 v = safe_normalize(u_eye - v_position, n);
    n = facing_normal(n, v);
    float r = clamp(roughness, 0.045, 1.0);
    float alpha = r * r, a2 = alpha * alpha;
    float f0d = (1.0 - u_ior) / (1.0 + u_ior);
#if SPECULAR
    vec3 F0 = mix(min(vec3(f0d * f0d) * spec_color, vec3(1.0)) * spec, base.rgb, metallic);
    float F90 = mix(spec, 1.0, metallic);
#else
    vec3 F0 = mix(vec3(f0d * f0d), base.rgb, metallic);
    const float F90 = 1.0;
#endif
    float k = (r + 1.0) * (r + 1.0) / 8.0;
    float NoV = clamp(dot(n, v), 0.0, 1.0);
#if TRANSMISSION
    // The transmission lobe's roughness: r clamp(2 ior - 2, 0, 1) (applyIorToRoughness).
    float rt = clamp(roughness * clamp(u_ior * 2.0 - 2.0, 0.0, 1.0), 0.045, 1.0);
    float at2 = rt * rt * rt * rt, kt = (rt + 1.0) * (rt + 1.0) / 8.0;
#endif
    vec3 Lo = emissive;
#if CLEARCOAT
    // The coat: F_coat at n_c.v weights its lobe and attenuates what lies beneath.
    nc = facing_normal(nc, v);
    float rc = clamp(ccr, 0.045, 1.0), ac2 = rc * rc * rc * rc, kc = (rc + 1.0) * (rc + 1.0) / 8.0;
    float NcV = clamp(dot(nc, v), 0.0, 1.0);
    float Fc = 0.04 + 0.96 * pow(1.0 - NcV, 5.0);
    float atten = cc > 0.0 ? 1.0 - cc * Fc : 1.0;
    Lo *= atten;
#endif
#if TRANSMISSION
#if CLEARCOAT
    float atten_t = atten;  // the coat attenuates the transmitted light as the base
#else
    const float atten_t = 1.0;
#endif
#endif
    for (int i = 0; i < u_light_count; ++i) {
        vec3 l, radiance;
        if (u_light[i].w == 0.0) { l = u_light[i].xyz; radiance = u_light_radiance[i]; }
        else {
            vec3 d = u_light[i].xyz - v_position;
            float d2 = dot(d, d);
            if (!(d2 > 1e-12)) continue;
            l = d / sqrt(d2);
            radiance = u_light_radiance[i] / d2;
            vec4 shape = u_light_shape[i];
            if (shape.z > 0.0 || shape.w != 0.0) {
                // The range window clamp(1 - (d^2 / range^2)^2, 0, 1), then the cone's a^2,
                // a = clamp(cos(axis, l) scale + offset, 0, 1).
                float att = 1.0;
                if (shape.z > 0.0) {
                    float q = d2 * shape.z;
                    att = clamp(1.0 - q * q, 0.0, 1.0);
                }
                if (shape.w != 0.0) {
                    float a = clamp(dot(l, u_light_axis[i]) * shape.x + shape.y, 0.0, 1.0);
                    att = att * (a * a);
                }
                radiance *= att;
            }
        }
        vec3 sum = l + v;
        float len2 = dot(sum, sum);
        vec3 h = len2 > 0.0 ? sum / sqrt(len2) : n;
        float NoL = clamp(dot(n, l), 0.0, 1.0);
        float NoH = clamp(dot(n, h), 0.0, 1.0);
        float VoH = clamp(dot(v, h), 0.0, 1.0);
        vec3 F = F0 + (F90 - F0) * pow(1.0 - VoH, 5.0);
        float dd = NoH * NoH * (a2 - 1.0) + 1.0;
        float D = a2 / (PI * dd * dd);
        float G = (NoV / (NoV * (1.0 - k) + k)) * (NoL / (NoL * (1.0 - k) + k));
        vec3 specular = D * G * F / (4.0 * max(NoV, 1e-4) * max(NoL, 1e-4));
        vec3 kd = (1.0 - F) * (1.0 - metallic);
#if TRANSMISSION
        // The transmitted share leaves the diffuse; a light behind the surface
        // (n.l < 0) comes through the lobe of l mirrored through the surface's
        // plane, l' = l - 2 (n.l) n, h_t = normalize(l' + v):
        // (1 - F(v.h_t)) albedo transmittance tr (1 - metallic) D G / (4 n.v n.l'), times n.l'.
        vec3 f = kd * base.rgb / PI * (1.0 - tr) + specular;
        vec3 ft = vec3(0.0);
        float NtL = 0.0;
        float NoLs = dot(n, l);
        if (tr > 0.0 && NoLs < 0.0) {
            vec3 lm = l - n * (2.0 * NoLs);
            vec3 hs = lm + v;
            float hl2 = dot(hs, hs);
            vec3 ht = hl2 > 0.0 ? hs / sqrt(hl2) : n;
            NtL = clamp(dot(n, lm), 0.0, 1.0);
            float NtH = clamp(dot(n, ht), 0.0, 1.0), VtH = clamp(dot(v, ht), 0.0, 1.0);
            vec3 Ft = F0 + (F90 - F0) * pow(1.0 - VtH, 5.0);
            float dt = NtH * NtH * (at2 - 1.0) + 1.0;
            float Dt = at2 / (PI * dt * dt);
            float Gt = (NoV / (NoV * (1.0 - kt) + kt)) * (NtL / (NtL * (1.0 - kt) + kt));
            ft = (1.0 - Ft) * base.rgb * transmittance *
                 (tr * (1.0 - metallic) * (Dt * Gt / (4.0 * max(NoV, 1e-4) * max(NtL, 1e-4))));
        }
#else
        vec3 f = kd * base.rgb / PI + specular;
#endif
#if SHEEN
        if (smax > 0.0) {  // the sheen over the base, which keeps what it leaves
            float Ds = (2.0 + 1.0 / as) * pow(max(1.0 - NoH * NoH, 0.0), 0.5 / as) / (2.0 * PI);
            float den = (1.0 + sheen_lambda(NoV, as) + sheen_lambda(NoL, as)) * (4.0 * NoV * NoL);
            float Vs = den > 0.0 ? min(1.0 / den, 1.0) : 0.0;
            float scaling = min(1.0 - smax * sheen_E(NoV, rs), 1.0 - smax * sheen_E(NoL, rs));
            f = f * scaling + sheen * (Ds * Vs);
#if TRANSMISSION
            ft *= scaling;
#endif
        }
#endif
#if TRANSMISSION
        Lo += ft * atten_t * radiance * NtL;
#endif
#if CLEARCOAT
        Lo += f * atten * radiance * NoL;
        if (cc > 0.0) {
            float NcL = clamp(dot(nc, l), 0.0, 1.0), NcH = clamp(dot(nc, h), 0.0, 1.0);
            float dc = NcH * NcH * (ac2 - 1.0) + 1.0;
            float Dc = ac2 / (PI * dc * dc);
            float Gc = (NcV / (NcV * (1.0 - kc) + kc)) * (NcL / (NcL * (1.0 - kc) + kc));
            Lo += cc * Fc * Dc * Gc / (4.0 * max(NcV, 1e-4) * max(NcL, 1e-4)) * radiance * NcL;
        }
#else
        Lo += f * radiance * NoL;
#endif
    }
    Lo += u_ambient * base.rgb * occlusion;
    o_color = LINEAR_OUT != 0 ? vec4(Lo, 1.0) : vec4(display(Lo), 1.0);
}
)";

// The second pass with --msaa: the resolved linear image, tone mapped.
const char* kQuadVertexShader = R"(#version 330 core
void main() {
    vec2 p = vec2((gl_VertexID & 1) * 4 - 1, (gl_VertexID >> 1) * 4 - 1);
    gl_Position = vec4(p, 0.0, 1.0);
}
)";
const char* kToneMapShader = R"(
uniform sampler2D t_linear;
out vec4 o_color;
void main() {
    o_color = vec4(display(texelFetch(t_linear, ivec2(gl_FragCoord.xy), 0).rgb), 1.0);
}
)";

// A fragment program's source: the #defines that specialise it, the tone
// maps, then the body.
std::string program_source(int tonemap, const std::string& defines, const char* body) {
    return "#version 330 core\n#define TONEMAP " + std::to_string(tonemap) + "\n" + defines + kToneMapGlsl + body;
}

[[noreturn]] void die(const std::string& message, int code = 1) {
    std::fprintf(stderr, "llvmpipe-render: %s\n", message.c_str());
    std::exit(code);
}

GLuint compile(GLenum type, const char* source) {
    GLuint s = glCreateShader(type);
    glShaderSource(s, 1, &source, nullptr);
    glCompileShader(s);
    GLint ok = 0;
    glGetShaderiv(s, GL_COMPILE_STATUS, &ok);
    if (!ok) {
        char log[4096];
        glGetShaderInfoLog(s, sizeof log, nullptr, log);
        die(std::string("shader compile error: ") + log);
    }
    return s;
}

GLuint link_program(const char* vs, const char* fs) {
    GLuint p = glCreateProgram();
    glAttachShader(p, compile(GL_VERTEX_SHADER, vs));
    glAttachShader(p, compile(GL_FRAGMENT_SHADER, fs));
    glLinkProgram(p);
    GLint ok = 0;
    glGetProgramiv(p, GL_LINK_STATUS, &ok);
    if (!ok) die("shader link error");
    return p;
}

GLint wrap_gl(Wrap w) {
    return w == Wrap::ClampToEdge ? GL_CLAMP_TO_EDGE : w == Wrap::MirroredRepeat ? GL_MIRRORED_REPEAT : GL_REPEAT;
}

// One decoded image as a GL texture with a generated mip chain.
GLuint upload(const Image& img, const TextureRef& ref) {
    GLuint tex = 0;
    glGenTextures(1, &tex);
    glBindTexture(GL_TEXTURE_2D, tex);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
    if (!img.is_8bit()) {
        glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA32F, img.width, img.height, 0, GL_RGBA, GL_FLOAT, img.rgba.data());
    } else {
        // sRGB formats exist for RGB(A) only: grey sRGB maps go up as RGB.
        std::vector<std::uint8_t> expanded;
        const std::uint8_t* px = img.pixels.data();
        int channels = img.channels;
        if (img.srgb && channels <= 2) {
            expanded.resize(img.texel_count() * std::size_t(channels + 2));
            for (std::size_t i = 0; i < img.texel_count(); ++i) {
                std::uint8_t g = px[i * channels];
                std::uint8_t* o = &expanded[i * std::size_t(channels + 2)];
                o[0] = o[1] = o[2] = g;
                if (channels == 2) o[3] = px[i * 2 + 1];
            }
            px = expanded.data();
            channels += 2;
        }
        static const GLenum kFormat[5] = {0, GL_RED, GL_RG, GL_RGB, GL_RGBA};
        static const GLint kLinear[5] = {0, GL_R8, GL_RG8, GL_RGB8, GL_RGBA8};
        static const GLint kSrgb[5] = {0, 0, 0, GL_SRGB8, GL_SRGB8_ALPHA8};
        glTexImage2D(GL_TEXTURE_2D, 0, img.srgb ? kSrgb[channels] : kLinear[channels], img.width, img.height, 0,
                     kFormat[channels], GL_UNSIGNED_BYTE, px);
        if (img.channels <= 2 && !img.srgb) {
            // Grey reads as (g, g, g) like prast's samplers; grey+alpha keeps alpha.
            GLint swizzle[4] = {GL_RED, GL_RED, GL_RED, img.channels == 2 ? GL_GREEN : GL_ONE};
            glTexParameteriv(GL_TEXTURE_2D, GL_TEXTURE_SWIZZLE_RGBA, swizzle);
        }
    }
    glGenerateMipmap(GL_TEXTURE_2D);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR_MIPMAP_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, wrap_gl(ref.wrap_s));
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, wrap_gl(ref.wrap_t));
    return tex;
}

struct GpuMesh {
    GLuint vao = 0;
    GLsizei count = 0;
    int material = 0;
};

GpuMesh upload(const Mesh& m) {
    GpuMesh g;
    g.material = m.material;
    g.count = GLsizei(m.indices.size());
    glGenVertexArrays(1, &g.vao);
    glBindVertexArray(g.vao);
    // Interleaved: position 3, normal 3, uv 2, tangent 4, then uv1 2 when the
    // mesh has TEXCOORD_1 (without, attribute 4 stays disabled and reads 0).
    const bool uv1 = !m.uvs1.empty();
    const std::size_t stride = uv1 ? 14 : 12;
    std::vector<float> v(m.positions.size() * stride, 0.0f);
    for (std::size_t i = 0; i < m.positions.size(); ++i) {
        float* o = &v[i * stride];
        o[0] = m.positions[i].x; o[1] = m.positions[i].y; o[2] = m.positions[i].z;
        glm::vec3 n = i < m.normals.size() ? m.normals[i] : glm::vec3(0, 0, 1);
        o[3] = n.x; o[4] = n.y; o[5] = n.z;
        glm::vec2 uv = i < m.uvs.size() ? m.uvs[i] : glm::vec2(0.0f);
        o[6] = uv.x; o[7] = uv.y;
        glm::vec4 t = i < m.tangents.size() ? m.tangents[i] : glm::vec4(1, 0, 0, 1);
        o[8] = t.x; o[9] = t.y; o[10] = t.z; o[11] = t.w;
        if (uv1) {
            glm::vec2 u1 = i < m.uvs1.size() ? m.uvs1[i] : glm::vec2(0.0f);
            o[12] = u1.x; o[13] = u1.y;
        }
    }
    GLuint buffers[2];
    glGenBuffers(2, buffers);
    glBindBuffer(GL_ARRAY_BUFFER, buffers[0]);
    glBufferData(GL_ARRAY_BUFFER, GLsizeiptr(v.size() * sizeof(float)), v.data(), GL_STATIC_DRAW);
    const int sizes[5] = {3, 3, 2, 4, 2}, offsets[5] = {0, 3, 6, 8, 12};
    for (int a = 0; a < (uv1 ? 5 : 4); ++a) {
        glEnableVertexAttribArray(GLuint(a));
        glVertexAttribPointer(GLuint(a), sizes[a], GL_FLOAT, GL_FALSE, GLsizei(stride * sizeof(float)),
                              reinterpret_cast<const void*>(std::size_t(offsets[a]) * sizeof(float)));
    }
    glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, buffers[1]);
    glBufferData(GL_ELEMENT_ARRAY_BUFFER, GLsizeiptr(m.indices.size() * sizeof(std::uint32_t)), m.indices.data(),
                 GL_STATIC_DRAW);
    return g;
}

} // namespace

int main(int argc, char** argv) {
    RenderOptions opt;
    const std::string err = parse_render_args(argc, argv, opt);
    if (!err.empty()) die(err, 2);
    if (opt.help) {
        // render's usage: bench --side-by-side reads the flags it lists (--msaa).
        std::printf("llvmpipe-render: render's command line, drawn by Mesa's llvmpipe (see tools/llvmpipe/llvmpipe_render.cpp;\n"
                    "llvmpipe draws 1 or 4 samples: --msaa 2 runs at 4, --msaa 8 is refused)\n%s",
                    render_usage());
        return 0;
    }
    if (opt.hdr_output()) die("only PNG output", 2);
    // llvmpipe reads its thread count once, when the context is made.
    if (opt.threads > 0) setenv("LP_NUM_THREADS", std::to_string(opt.threads).c_str(), 1);

    // Scene, camera and lights from render's own frame set-up (frame 0),
    // with its memory check; the textures are decoded and uploaded below.
    FrameSetup setup;
    if (FrameError e = prepare_scene(render_frame_request(opt), setup)) die(e.message, e.code);
    if (CameraFault f = setup.orbit(0.0)) die(f.message, kFrameExitUsage);
    for (const std::string& n : setup.notes) std::fprintf(stderr, "llvmpipe-render: %s\n", n.c_str());
    if (setup.environment_image)
        std::fprintf(stderr, "llvmpipe-render: warning: image-based lighting is not ported: the environment "
                             "map is not drawn (the lights and the ambient term are)\n");
    if (opt.brdf != BrdfModel::Default || opt.energy)
        std::fprintf(stderr, "llvmpipe-render: warning: --brdf gltf and --energy conserve are not ported: the "
                             "default BRDF is drawn\n");
    const Scene& scene = setup.scene;
    const Camera& camera = setup.settings.camera;
    const std::vector<ShadingLight>& lights = setup.settings.lights;
    const double load_ms = setup.load_ms;
    const float aspect = setup.aspect();
    if (lights.size() > 8) die("more than 8 lights");

    // A GL 3.3 core context. Its OSMesa window (client memory, copied there on
    // every glFinish) is a 1x1 placeholder: the frame is drawn into an FBO.
    const int attribs[] = {OSMESA_FORMAT, OSMESA_RGBA, OSMESA_DEPTH_BITS, 0, OSMESA_PROFILE, OSMESA_CORE_PROFILE,
                           OSMESA_CONTEXT_MAJOR_VERSION, 3, OSMESA_CONTEXT_MINOR_VERSION, 3, 0};
    OSMesaContext ctx = OSMesaCreateContextAttribs(attribs, nullptr);
    if (!ctx) die("cannot create an OSMesa GL 3.3 core context");
    std::uint8_t window[4] = {};
    if (!OSMesaMakeCurrent(ctx, window, GL_UNSIGNED_BYTE, 1, 1)) die("OSMesaMakeCurrent failed");
    if (opt.stats) std::printf("renderer               %s\n", reinterpret_cast<const char*>(glGetString(GL_RENDERER)));

    // Textures: decode as render does (prast's decoders), upload, mip.
    const auto t_tex = Clock::now();
    std::vector<GLuint> textures(scene.images.size() * 2, 0);
    auto texture = [&](const TextureRef& r, bool srgb) -> GLuint {
        if (!r.valid() || std::size_t(r.image) >= scene.images.size()) return 0;
        GLuint& t = textures[std::size_t(r.image) * 2 + srgb];
        if (!t) {
            const ImageSource& src = scene.images[std::size_t(r.image)];
            try {
                t = upload(src.decoded ? *src.decoded : decode_image(src, srgb), r);
            } catch (const std::exception& e) {
                std::fprintf(stderr, "llvmpipe-render: warning: %s (texture ignored)\n", e.what());
            }
        }
        return t;
    };
    // The seven core maps, then the specular, clearcoat, sheen, transmission
    // and thickness ones (Material::extension_textures()'s order).
    constexpr int kUnits = 16;
    constexpr int kSpecularBit = 1, kClearcoatBit = 2, kSheenBit = 4, kTransmissionBit = 8, kUnlitBit = 16;
    GLint max_units = 0;
    glGetIntegerv(GL_MAX_TEXTURE_IMAGE_UNITS, &max_units);
    if (max_units < kUnits + 1) die("fewer than 17 texture units");
    // A program: which maps are bound, which of them go through a transform
    // and which read TEXCOORD_1 (bit per unit), and the lobes.
    using Permutation = std::array<int, 4>;
    struct GpuMaterial {
        const Material* m;
        GLuint tex[kUnits];
        Permutation key{};  // maps, transformed, TEXCOORD_1, lobes
        // KHR_texture_transform per unit: u' = (xf.x u + xf.y v) + off.x, v' = (xf.z u + xf.w v) + off.y.
        float xf[kUnits][4], offset[kUnits][2];
    };
    std::vector<GpuMaterial> materials;
    for (const Material& m : scene.materials) {
        GpuMaterial g{&m, {texture(m.base_color, true), texture(m.metallic_roughness, false),
                          texture(m.roughness, false), texture(m.metallic, false), texture(m.normal, false),
                          texture(m.occlusion, false), texture(m.emissive, true),
                          texture(m.specular_texture, false), texture(m.specular_color_texture, true),
                          texture(m.clearcoat_texture, false), texture(m.clearcoat_roughness_texture, false),
                          texture(m.clearcoat_normal_texture, false), texture(m.sheen_color_texture, true),
                          texture(m.sheen_roughness_texture, false), texture(m.transmission_texture, false),
                          m.has_volume ? texture(m.thickness_texture, false) : 0u}, {}, {}, {}};
        // KHR_materials_unlit reads the base colour map alone.
        if (m.unlit) std::fill(g.tex + 1, g.tex + kUnits, 0u);
        std::vector<const TextureRef*> refs = {&m.base_color, &m.metallic_roughness, &m.roughness, &m.metallic,
                                               &m.normal, &m.occlusion, &m.emissive};
        for (const TextureRef* r : m.extension_textures()) refs.push_back(r);
        for (int i = 0; i < kUnits; ++i) {
            g.key[0] |= g.tex[i] ? 1 << i : 0;
            const TextureRef& r = *refs[std::size_t(i)];
            g.key[2] |= g.tex[i] && r.texcoord == 1 ? 1 << i : 0;
            // The extension's T R S: R turns the UVs counter-clockwise in UV
            // space (u right, v down), so that its example (offset [0, 1],
            // rotation pi/2, scale 0.5) reads the lower left quadrant.
            const TextureTransform& t = r.transform;
            const double c = std::cos(double(t.rotation)), sn = std::sin(double(t.rotation));
            const float xf[4] = {float(c * double(t.scale.x)), float(sn * double(t.scale.y)),
                                 float(-sn * double(t.scale.x)), float(c * double(t.scale.y))};
            std::copy_n(xf, 4, g.xf[i]);
            g.offset[i][0] = t.offset.x;
            g.offset[i][1] = t.offset.y;
            g.key[1] |= g.tex[i] && t.present ? 1 << i : 0;
        }
        // The lobes the material has (render shades a coat of factor 0 or a
        // black sheen as no coat or sheen, an unlit material with none).
        const bool sheen = m.has_sheen && (m.sheen_color_factor.x > 0.0f || m.sheen_color_factor.y > 0.0f ||
                                           m.sheen_color_factor.z > 0.0f);
        if (m.unlit) g.key[3] = kUnlitBit;
        else {
            if (m.has_specular) g.key[3] |= kSpecularBit;
            if (m.has_clearcoat && m.clearcoat_factor > 0.0f) g.key[3] |= kClearcoatBit;
            if (sheen) g.key[3] |= kSheenBit;
            if (m.has_transmission) g.key[3] |= kTransmissionBit;
        }
        materials.push_back(g);
    }
    // The sheen's albedo table (brdf.h), bilinear between its texel centres, on the unit after the maps.
    GLuint sheen_table = 0;
    glGenTextures(1, &sheen_table);
    glActiveTexture(GLenum(GL_TEXTURE0 + kUnits));
    glBindTexture(GL_TEXTURE_2D, sheen_table);
    glTexImage2D(GL_TEXTURE_2D, 0, GL_R32F, kSheenNoV, kSheenRough, 0, GL_RED, GL_FLOAT, sheen_albedo_table().data());
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAX_LEVEL, 0);
    glActiveTexture(GL_TEXTURE0);
    glFinish();  // the uploads and mip chains are done
    const double textures_ms = ms_since(t_tex);
    // --stats: render's two load lines (bench --side-by-side reads them).
    if (opt.stats) std::printf("time load              %.3f ms\ntime textures          %.3f ms\n", load_ms, textures_ms);
    std::vector<GpuMesh> meshes;
    for (const Mesh& m : scene.meshes) meshes.push_back(upload(m));

    // One program per permutation, with its uniform locations.
    const int tonemap = opt.effective_tonemap() == ToneMap::Aces ? 1 : opt.effective_tonemap() == ToneMap::Neutral ? 2 : 0;
    const bool msaa = opt.msaa > 1;
    const glm::mat4 vp = camera.view_projection(aspect);
    auto loc = [](GLuint p, const char* name) { return glGetUniformLocation(p, name); };
    struct Program {
        GLuint id = 0;
        GLint base_color_factor, metallic_factor, roughness_factor, normal_scale, occlusion_strength, ior,
            emissive_factor;
        GLint specular_factor, specular_color_factor, clearcoat, clearcoat_roughness,
            clearcoat_normal_scale, sheen_color_factor, sheen_roughness_factor;
        GLint transmission, thickness, attenuation_distance, attenuation_color, xf, xf_offset;
    };
    std::map<Permutation, Program> programs;
    auto program_for = [&](const Permutation& key) -> const Program& {
        auto it = programs.find(key);
        if (it != programs.end()) return it->second;
        const int lobes = key[3];
        auto flag = [&](const char* name, int bit) {
            return std::string("#define ") + name + (lobes & bit ? " 1\n" : " 0\n");
        };
        const std::string defines = "#define MAPS " + std::to_string(key[0]) + "\n#define XF " +
                                    std::to_string(key[1]) + "\n#define SET1 " + std::to_string(key[2]) +
                                    "\n#define LINEAR_OUT " + (msaa ? "1" : "0") + "\n" +
                                    flag("SPECULAR", kSpecularBit) + flag("CLEARCOAT", kClearcoatBit) +
                                    flag("SHEEN", kSheenBit) + flag("TRANSMISSION", kTransmissionBit) +
                                    flag("UNLIT", kUnlitBit);
        Program p;
        p.id = link_program(kVertexShader, program_source(tonemap, defines, kFragmentShader).c_str());
        glUseProgram(p.id);
        const char* samplers[kUnits] = {"t_base", "t_mr", "t_rough", "t_metal", "t_normal", "t_occlusion",
                                        "t_emissive", "t_specular", "t_specular_color", "t_clearcoat",
                                        "t_clearcoat_rough", "t_clearcoat_normal", "t_sheen_color", "t_sheen_rough",
                                        "t_transmission", "t_thickness"};
        for (int i = 0; i < kUnits; ++i) glUniform1i(loc(p.id, samplers[i]), i);
        glUniform1i(loc(p.id, "t_sheen_E"), kUnits);
        glUniformMatrix4fv(loc(p.id, "u_view_proj"), 1, GL_FALSE, &vp[0][0]);
        glUniform3f(loc(p.id, "u_eye"), camera.eye.x, camera.eye.y, camera.eye.z);
        glUniform1i(loc(p.id, "u_light_count"), GLint(lights.size()));
        for (std::size_t i = 0; i < lights.size(); ++i) {
            const ShadingLight& L = lights[i];
            const glm::vec3 d = L.point ? L.position : L.direction;
            glUniform4f(loc(p.id, ("u_light[" + std::to_string(i) + "]").c_str()), d.x, d.y, d.z,
                        L.point ? 1.0f : 0.0f);
            glUniform3f(loc(p.id, ("u_light_radiance[" + std::to_string(i) + "]").c_str()), L.radiance.x,
                        L.radiance.y, L.radiance.z);
            // The spot cone (spot_cone()'s scale and offset) and range window of KHR_lights_punctual.
            const bool spot = L.point && L.spot;
            glUniform4f(loc(p.id, ("u_light_shape[" + std::to_string(i) + "]").c_str()), L.cone_scale,
                        L.cone_offset, L.point ? L.range_inv2 : 0.0f, spot ? 1.0f : 0.0f);
            glUniform3f(loc(p.id, ("u_light_axis[" + std::to_string(i) + "]").c_str()), L.direction.x,
                        L.direction.y, L.direction.z);
        }
        glUniform3f(loc(p.id, "u_ambient"), opt.ambient.x, opt.ambient.y, opt.ambient.z);
        glUniform1f(loc(p.id, "u_exposure"), opt.exposure);
        p.base_color_factor = loc(p.id, "u_base_color_factor");
        p.metallic_factor = loc(p.id, "u_metallic_factor");
        p.roughness_factor = loc(p.id, "u_roughness_factor");
        p.normal_scale = loc(p.id, "u_normal_scale");
        p.occlusion_strength = loc(p.id, "u_occlusion_strength");
        p.ior = loc(p.id, "u_ior");
        p.emissive_factor = loc(p.id, "u_emissive_factor");
        p.specular_factor = loc(p.id, "u_specular_factor");
        p.specular_color_factor = loc(p.id, "u_specular_color_factor");
        p.clearcoat = loc(p.id, "u_clearcoat");
        p.clearcoat_roughness = loc(p.id, "u_clearcoat_roughness");
        p.clearcoat_normal_scale = loc(p.id, "u_clearcoat_normal_scale");
        p.sheen_color_factor = loc(p.id, "u_sheen_color_factor");
        p.sheen_roughness_factor = loc(p.id, "u_sheen_roughness_factor");
        p.transmission = loc(p.id, "u_transmission");
        p.thickness = loc(p.id, "u_thickness");
        p.attenuation_distance = loc(p.id, "u_attenuation_distance");
        p.attenuation_color = loc(p.id, "u_attenuation_color");
        p.xf = loc(p.id, "u_xf");
        p.xf_offset = loc(p.id, "u_xf_offset");
        return programs.emplace(key, p).first->second;
    };
    for (const GpuMaterial& gm : materials) program_for(gm.key);

    // The target: 8-bit sRGB colour (GL_FRAMEBUFFER_SRGB: written values are
    // encoded by the driver) and a 24-bit depth buffer.
    GLuint target_fbo = 0;
    auto renderbuffer = [&](GLenum attachment, GLenum format, int samples) {
        GLuint rb = 0;
        glGenRenderbuffers(1, &rb);
        glBindRenderbuffer(GL_RENDERBUFFER, rb);
        glRenderbufferStorageMultisample(GL_RENDERBUFFER, samples, format, opt.width, opt.height);
        glFramebufferRenderbuffer(GL_FRAMEBUFFER, attachment, GL_RENDERBUFFER, rb);
        GLint granted = 0;  // the driver may round the count up
        glGetRenderbufferParameteriv(GL_RENDERBUFFER, GL_RENDERBUFFER_SAMPLES, &granted);
        return granted;
    };
    glGenFramebuffers(1, &target_fbo);
    glBindFramebuffer(GL_FRAMEBUFFER, target_fbo);
    renderbuffer(GL_COLOR_ATTACHMENT0, GL_SRGB8_ALPHA8, 0);
    if (!msaa) renderbuffer(GL_DEPTH_ATTACHMENT, GL_DEPTH_COMPONENT24, 0);
    if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE) die("sRGB target incomplete");
    glEnable(GL_FRAMEBUFFER_SRGB);

    // With MSAA: a multisampled linear float target, resolved by a blit, then
    // tone mapped into the sRGB target by a full-screen pass.
    GLuint ms_fbo = target_fbo, resolve_fbo = 0, resolved = 0, tonemap_program = 0;
    if (msaa) {
        glGenFramebuffers(1, &ms_fbo);
        glBindFramebuffer(GL_FRAMEBUFFER, ms_fbo);
        const int granted = renderbuffer(GL_COLOR_ATTACHMENT0, GL_RGBA16F, opt.msaa);
        if (opt.stats) std::printf("samples                %d (asked %d)\n", granted, opt.msaa);
        renderbuffer(GL_DEPTH_ATTACHMENT, GL_DEPTH_COMPONENT24, opt.msaa);
        if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE) die("multisampled target incomplete");
        glGenTextures(1, &resolved);
        glBindTexture(GL_TEXTURE_2D, resolved);
        glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA16F, opt.width, opt.height, 0, GL_RGBA, GL_FLOAT, nullptr);
        // One level: with the default minifying filter (mipmapped) it would be
        // incomplete, and texelFetch would read black.
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAX_LEVEL, 0);
        glGenFramebuffers(1, &resolve_fbo);
        glBindFramebuffer(GL_FRAMEBUFFER, resolve_fbo);
        glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, resolved, 0);
        tonemap_program = link_program(kQuadVertexShader, program_source(tonemap, "", kToneMapShader).c_str());
        glUseProgram(tonemap_program);
        glUniform1i(loc(tonemap_program, "t_linear"), 0);
        glUniform1f(loc(tonemap_program, "u_exposure"), opt.exposure);
    }
    GLuint empty_vao = 0;
    glGenVertexArrays(1, &empty_vao);

    auto frame = [&]() {
        glBindFramebuffer(GL_FRAMEBUFFER, ms_fbo);
        glViewport(0, 0, opt.width, opt.height);
        glEnable(GL_DEPTH_TEST);
        glDepthFunc(GL_LESS);
        glClearColor(0, 0, 0, 1);
        glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
        glFrontFace(GL_CCW);
        for (const GpuMesh& g : meshes) {
            const GpuMaterial& gm = materials[std::size_t(g.material)];
            const Material& m = *gm.m;
            const Program& p = program_for(gm.key);
            glUseProgram(p.id);
            if (m.double_sided) glDisable(GL_CULL_FACE);
            else { glEnable(GL_CULL_FACE); glCullFace(GL_BACK); }
            glUniform4fv(p.base_color_factor, 1, &m.base_color_factor[0]);
            glUniform1f(p.metallic_factor, m.metallic_factor);
            glUniform1f(p.roughness_factor, m.roughness_factor);
            glUniform1f(p.normal_scale, m.normal_scale);
            glUniform1f(p.occlusion_strength, m.occlusion_strength);
            glUniform1f(p.ior, m.ior);
            glUniform3fv(p.emissive_factor, 1, &m.emissive_factor[0]);
            glUniform1f(p.specular_factor, m.specular_factor);
            glUniform3fv(p.specular_color_factor, 1, &m.specular_color_factor[0]);
            glUniform1f(p.clearcoat, m.has_clearcoat ? m.clearcoat_factor : 0.0f);
            glUniform1f(p.clearcoat_roughness, m.clearcoat_roughness_factor);
            glUniform1f(p.clearcoat_normal_scale, m.clearcoat_normal_scale);
            const glm::vec3 sheen = m.has_sheen ? m.sheen_color_factor : glm::vec3(0.0f);
            glUniform3fv(p.sheen_color_factor, 1, &sheen[0]);
            glUniform1f(p.sheen_roughness_factor, m.sheen_roughness_factor);
            glUniform1f(p.transmission, m.has_transmission ? m.transmission_factor : 0.0f);
            glUniform1f(p.thickness, m.has_volume ? m.thickness_factor : 0.0f);
            glUniform1f(p.attenuation_distance, m.has_volume ? m.attenuation_distance : 0.0f);
            glUniform3fv(p.attenuation_color, 1, &m.attenuation_color[0]);
            if (gm.key[1]) {
                glUniform4fv(p.xf, kUnits, &gm.xf[0][0]);
                glUniform2fv(p.xf_offset, kUnits, &gm.offset[0][0]);
            }
            for (int i = 0; i < kUnits; ++i) {
                glActiveTexture(GLenum(GL_TEXTURE0 + i));
                glBindTexture(GL_TEXTURE_2D, gm.tex[i]);
            }
            glBindVertexArray(g.vao);
            glDrawElements(GL_TRIANGLES, g.count, GL_UNSIGNED_INT, nullptr);
        }
        if (msaa) {
            glBindFramebuffer(GL_READ_FRAMEBUFFER, ms_fbo);
            glBindFramebuffer(GL_DRAW_FRAMEBUFFER, resolve_fbo);
            glBlitFramebuffer(0, 0, opt.width, opt.height, 0, 0, opt.width, opt.height, GL_COLOR_BUFFER_BIT,
                              GL_NEAREST);
            glBindFramebuffer(GL_FRAMEBUFFER, target_fbo);
            glDisable(GL_DEPTH_TEST);
            glDisable(GL_CULL_FACE);
            glUseProgram(tonemap_program);
            glActiveTexture(GL_TEXTURE0);
            glBindTexture(GL_TEXTURE_2D, resolved);
            glBindVertexArray(empty_vao);
            glDrawArrays(GL_TRIANGLES, 0, 3);
        }
        glFinish();
    };

    // With --repeat, one untimed frame first: llvmpipe compiles its shader
    // variants on first use (a single frame's run pays for it, as it must).
    if (opt.repeat_given) frame();
    std::vector<double> times;
    for (int r = 0; r < opt.repeat; ++r) {
        const auto t0 = Clock::now();
        frame();
        times.push_back(ms_since(t0));
    }
    if (opt.repeat_given) {
        std::sort(times.begin(), times.end());
        const std::size_t n = times.size();
        const double median = n % 2 ? times[n / 2] : 0.5 * (times[n / 2 - 1] + times[n / 2]);
        std::printf("frame_ms min=%.3f median=%.3f max=%.3f\n", times.front(), median, times.back());
    }
    // Read back; GL's row 0 is the bottom row: flip to the image's top-down rows.
    const auto t_read = Clock::now();
    const std::size_t row = std::size_t(opt.width) * 4;
    std::vector<std::uint8_t> bottom_up(row * std::size_t(opt.height)), rgba8(bottom_up.size());
    glBindFramebuffer(GL_READ_FRAMEBUFFER, target_fbo);
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    glReadPixels(0, 0, opt.width, opt.height, GL_RGBA, GL_UNSIGNED_BYTE, bottom_up.data());
    for (int y = 0; y < opt.height; ++y)
        std::copy_n(&bottom_up[std::size_t(opt.height - 1 - y) * row], row, &rgba8[std::size_t(y) * row]);
    if (opt.stats) std::printf("time read back         %.3f ms\n", ms_since(t_read));
    if (glGetError() != GL_NO_ERROR) die("OpenGL reported an error");
    try {
        write_png_atomic(opt.output, opt.width, opt.height, rgba8.data());
    } catch (const std::exception& e) {
        die(e.what());
    }
    OSMesaDestroyContext(ctx);
    return 0;
}

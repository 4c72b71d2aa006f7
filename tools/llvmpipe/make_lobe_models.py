#!/usr/bin/env python3
# Test models for the layered lobes (KHR_materials_specular, _clearcoat,
# _sheen, _transmission with _volume), KHR_texture_transform,
# KHR_materials_unlit and KHR_lights_punctual's spot cone and range that
# llvmpipe-render and render are compared on (docs/shading.md, "Against
# llvmpipe"): one UV sphere per file, with normals, UVs (a second set where a
# model reads it) and tangents, lights as nodes where a model has its own,
# buffers and images embedded as data URIs so each model is a single .gltf.
#
#   python3 tools/llvmpipe/make_lobe_models.py --out DIR
#   python3 tools/llvmpipe/make_lobe_models.py --out DIR --compare BUILD
#
# --compare also draws each model with BUILD/render and BUILD/llvmpipe-render
# (configured with -DPRAST_LLVMPIPE=ON) at FLAGS below (or the model's own
# flags) and prints a Markdown table of BUILD/prast-diff's PSNR and largest
# channel difference; --only NAME[,NAME..] limits it to those models.
# Python 3 standard library only; the same bytes on every run.
import argparse
import base64
import json
import math
import os
import re
import struct
import subprocess
import zlib

# One sample (llvmpipe's 4-sample pattern is not render's), two suns (one
# behind the sphere, for the grazing coat and sheen) and a point light.
FLAGS = ["--msaa", "1", "--size", "512x512", "--sun", "0.4,0.7,0.6:3,3,3", "--sun", "-0.6,0.1,-0.8:2,2,2",
         "--point", "2,1.5,2.5:6,6,6"]
# The transmission models: FLAGS and a sun almost straight behind the sphere
# (the camera looks down -z), whose mirrored lobe lands near the middle.
FLAGS_BEHIND = FLAGS + ["--sun", "0.15,0.25,-1:4,4,4"]
# The light models: the file's lights and a dim sun for the sphere's shape.
FLAGS_FILE_LIGHTS = ["--msaa", "1", "--size", "512x512", "--sun", "0.4,0.7,0.6:0.4,0.4,0.4"]


def png_rgba(width, height, pixel):
    """8-bit RGBA PNG; pixel(u, v) gives (r, g, b, a) bytes at texel centres, v = 0 the top row."""
    raw = bytearray()
    for y in range(height):
        raw.append(0)
        for x in range(width):
            raw += bytes(pixel((x + 0.5) / width, (y + 0.5) / height))

    def chunk(tag, payload):
        return (struct.pack(">I", len(payload)) + tag + payload +
                struct.pack(">I", zlib.crc32(tag + payload) & 0xFFFFFFFF))

    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 8, 6, 0, 0, 0)) +
            chunk(b"IDAT", zlib.compress(bytes(raw), 9)) + chunk(b"IEND", b""))


def data_uri(mime, data):
    return "data:%s;base64,%s" % (mime, base64.b64encode(data).decode("ascii"))


def uv1_of(u, v):
    """The second UV set: turned and stretched against the first, so a map that reads it shows it."""
    return (1.5 * v + 0.25 * u, 2.0 * u)


def sphere(segments=96, rings=48):
    """Unit UV sphere: positions, normals, uvs (glTF: v = 0 at the top), tangents, CCW indices."""
    pos, nrm, uv, tan = [], [], [], []
    for j in range(rings + 1):
        v = j / rings
        th = v * math.pi
        for i in range(segments + 1):
            u = i / segments
            ph = u * 2.0 * math.pi
            p = (-math.cos(ph) * math.sin(th), math.cos(th), math.sin(ph) * math.sin(th))
            pos.append(p)
            nrm.append(p)
            uv.append((u, v))
            t = (math.sin(ph), 0.0, math.cos(ph))  # dP/du, normalised
            # Handedness: B = cross(N, T) w points towards -v (up the image).
            c = (p[1] * t[2] - p[2] * t[1], p[2] * t[0] - p[0] * t[2], p[0] * t[1] - p[1] * t[0])
            dv = (-math.cos(ph) * math.cos(th), -math.sin(th), math.sin(ph) * math.cos(th))  # dP/dv
            w = 1.0 if -(c[0] * dv[0] + c[1] * dv[1] + c[2] * dv[2]) >= 0.0 else -1.0
            tan.append(t + (w,))
    idx = []
    for j in range(rings):
        for i in range(segments):
            a = j * (segments + 1) + i
            b = a + segments + 1
            for tri in ((a, b, a + 1), (a + 1, b, b + 1)):
                # Keep the winding counter-clockwise seen from outside.
                p0, p1, p2 = (pos[k] for k in tri)
                e1 = [p1[k] - p0[k] for k in range(3)]
                e2 = [p2[k] - p0[k] for k in range(3)]
                n = (e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0])
                area2 = sum(x * x for x in n)
                if area2 < 1e-20:
                    continue  # the pole's degenerate triangles
                centre = [p0[k] + p1[k] + p2[k] for k in range(3)]
                if sum(n[k] * centre[k] for k in range(3)) < 0.0:
                    tri = (tri[0], tri[2], tri[1])
                idx.extend(tri)
    return pos, nrm, uv, tan, idx


def bump_normal(u, v):
    """A tangent-space normal map of ridges and dimples (OpenGL convention)."""
    x = 0.45 * math.sin(2.0 * math.pi * 12.0 * u)
    y = 0.45 * math.sin(2.0 * math.pi * 6.0 * v)
    n = math.sqrt(x * x + y * y + 1.0)
    return tuple(int(round((c / n * 0.5 + 0.5) * 255.0)) for c in (x, y, 1.0)) + (255,)


def checker(u, v):
    """An 8 x 4 checker whose colour changes with the quadrant, so an offset, turn or scale shows."""
    q = (0 if u < 0.5 else 1) + (0 if v < 0.5 else 2)
    colours = ((0.9, 0.2, 0.1), (0.1, 0.7, 0.2), (0.2, 0.3, 0.9), (0.9, 0.8, 0.1))
    dark = (int(u * 8.0) + int(v * 4.0)) % 2
    c = colours[q]
    k = 0.35 if dark else 1.0
    return tuple(int(round(x * k * 255.0)) for x in c) + (255,)


def stripes(u, v):
    """Channels that differ so a wrong channel shows: R, G, B, A vary along u, v, u + v, v."""
    r = 0.5 + 0.5 * math.sin(2.0 * math.pi * 3.0 * u)
    g = 0.5 + 0.5 * math.cos(2.0 * math.pi * 2.0 * v)
    b = 0.5 + 0.5 * math.sin(2.0 * math.pi * (2.0 * u + v))
    a = 0.25 + 0.75 * v
    return tuple(int(round(c * 255.0)) for c in (r, g, b, a))


# The KHR_texture_transform of a textureInfo (and its texCoord override).
def xf(offset=None, rotation=None, scale=None, tex_coord=None):
    t = {}
    if offset is not None:
        t["offset"] = offset
    if rotation is not None:
        t["rotation"] = rotation
    if scale is not None:
        t["scale"] = scale
    if tex_coord is not None:
        t["texCoord"] = tex_coord
    return {"KHR_texture_transform": t}


# KHR_lights_punctual lights of a model: (type, position, aimed at, colour, intensity, extra properties).
def spot(position, target, colour, intensity, **extra):
    return ("spot", position, target, colour, intensity, extra)


def point(position, colour, intensity, **extra):
    return ("point", position, None, colour, intensity, extra)


# name: (base colour, metallic, roughness, extensions; a key not KHR_ is a material property,
# then optionally the model's options: "flags" for --compare, "lights", "uv1" for TEXCOORD_1)
MODELS = {
    # The same sphere without extensions: the harness's agreement on this geometry and these lights.
    "plain": ((0.8, 0.2, 0.2, 1.0), 0.0, 0.35, {}),
    # The coat's normal map as the base's own (no extension): how closely the two drivers filter it.
    "normal-map": ((0.2, 0.2, 0.7, 1.0), 0.0, 0.2, {"normalTexture": {"index": "bump", "scale": 0.8}}),
    "specular-factor": ((0.8, 0.2, 0.2, 1.0), 0.0, 0.35,
                        {"KHR_materials_specular": {"specularFactor": 0.3}}),
    "specular-colour": ((0.2, 0.3, 0.8, 1.0), 0.0, 0.3,
                        {"KHR_materials_specular": {"specularColorFactor": [1.0, 0.4, 0.1]}}),
    "specular-zero": ((0.7, 0.7, 0.2, 1.0), 0.0, 0.3,
                      {"KHR_materials_specular": {"specularFactor": 0.0}}),
    "specular-metal": ((0.9, 0.6, 0.3, 1.0), 0.5, 0.3,
                       {"KHR_materials_specular": {"specularFactor": 0.5, "specularColorFactor": [0.3, 1.0, 0.6]}}),
    "clearcoat-smooth": ((0.7, 0.1, 0.1, 1.0), 0.0, 0.7,
                         {"KHR_materials_clearcoat": {"clearcoatFactor": 1.0, "clearcoatRoughnessFactor": 0.1}}),
    "clearcoat-rough": ((0.1, 0.5, 0.2, 1.0), 0.0, 0.8,
                        {"KHR_materials_clearcoat": {"clearcoatFactor": 0.6, "clearcoatRoughnessFactor": 0.45}}),
    "clearcoat-emissive": ((0.1, 0.1, 0.1, 1.0), 0.0, 0.5,
                           {"emissiveFactor": [0.6, 0.25, 0.05],
                            "KHR_materials_clearcoat": {"clearcoatFactor": 0.8, "clearcoatRoughnessFactor": 0.3}}),
    "clearcoat-normal": ((0.2, 0.2, 0.7, 1.0), 0.0, 0.6,
                         {"KHR_materials_clearcoat": {"clearcoatFactor": 1.0, "clearcoatRoughnessFactor": 0.2,
                                                      "clearcoatNormalTexture": {"index": "bump", "scale": 0.8}}}),
    "sheen": ((0.05, 0.05, 0.1, 1.0), 0.0, 0.8,
              {"KHR_materials_sheen": {"sheenColorFactor": [0.9, 0.5, 0.8], "sheenRoughnessFactor": 0.5}}),
    "sheen-smooth": ((0.3, 0.1, 0.05, 1.0), 0.0, 0.6,
                     {"KHR_materials_sheen": {"sheenColorFactor": [1.0, 1.0, 1.0], "sheenRoughnessFactor": 0.15}}),
    "sheen-rough": ((0.4, 0.4, 0.4, 1.0), 0.0, 0.9,
                    {"KHR_materials_sheen": {"sheenColorFactor": [0.2, 0.8, 0.5], "sheenRoughnessFactor": 1.0}}),
    "layered": ((0.6, 0.3, 0.1, 1.0), 0.0, 0.5,
                {"KHR_materials_specular": {"specularFactor": 0.8, "specularColorFactor": [0.8, 1.0, 1.0]},
                 "KHR_materials_clearcoat": {"clearcoatFactor": 0.7, "clearcoatRoughnessFactor": 0.25},
                 "KHR_materials_sheen": {"sheenColorFactor": [0.5, 0.5, 0.9], "sheenRoughnessFactor": 0.4}}),
    # Every extension map at once (factors 1), from one image whose channels differ.
    "lobe-maps": ((0.7, 0.5, 0.3, 1.0), 0.0, 0.5,
                  {"KHR_materials_specular": {"specularTexture": {"index": "stripes"},
                                              "specularColorTexture": {"index": "stripes"}},
                   "KHR_materials_clearcoat": {"clearcoatFactor": 1.0, "clearcoatRoughnessFactor": 1.0,
                                               "clearcoatTexture": {"index": "stripes"},
                                               "clearcoatRoughnessTexture": {"index": "stripes"}},
                   "KHR_materials_sheen": {"sheenColorFactor": [1.0, 1.0, 1.0], "sheenRoughnessFactor": 1.0,
                                           "sheenColorTexture": {"index": "stripes"},
                                           "sheenRoughnessTexture": {"index": "stripes"}}}),
    # KHR_materials_transmission (+ _volume), under the lights only: llvmpipe-render has no
    # environment, so what they compare is the diffuse's share and the mirrored lobe of the
    # suns behind, with the volume's transmittance.
    "transmission-thin": ((0.9, 0.9, 0.9, 1.0), 0.0, 0.3,
                          {"KHR_materials_transmission": {"transmissionFactor": 1.0}}, {"flags": FLAGS_BEHIND}),
    "transmission-smooth": ((0.8, 0.9, 1.0, 1.0), 0.0, 0.1,
                            {"KHR_materials_transmission": {"transmissionFactor": 1.0}}, {"flags": FLAGS_BEHIND}),
    "transmission-ior": ((0.3, 0.7, 0.9, 1.0), 0.0, 0.5,
                         {"KHR_materials_transmission": {"transmissionFactor": 0.7},
                          "KHR_materials_ior": {"ior": 1.2}}, {"flags": FLAGS_BEHIND}),
    "transmission-metal": ((0.9, 0.7, 0.4, 1.0), 0.4, 0.35,
                           {"KHR_materials_transmission": {"transmissionFactor": 0.9}}, {"flags": FLAGS_BEHIND}),
    "transmission-volume": ((1.0, 1.0, 1.0, 1.0), 0.0, 0.25,
                            {"KHR_materials_transmission": {"transmissionFactor": 1.0},
                             "KHR_materials_volume": {"thicknessFactor": 0.8, "attenuationDistance": 0.5,
                                                      "attenuationColor": [0.9, 0.5, 0.2]}}, {"flags": FLAGS_BEHIND}),
    "transmission-maps": ((0.9, 0.9, 0.9, 1.0), 0.0, 0.3,
                          {"KHR_materials_transmission": {"transmissionFactor": 1.0,
                                                          "transmissionTexture": {"index": "stripes"}},
                           "KHR_materials_volume": {"thicknessFactor": 1.0, "thicknessTexture": {"index": "stripes"},
                                                    "attenuationDistance": 0.7,
                                                    "attenuationColor": [0.3, 0.8, 0.6]}}, {"flags": FLAGS_BEHIND}),
    "transmission-layered": ((0.7, 0.8, 0.9, 1.0), 0.0, 0.3,
                             {"KHR_materials_transmission": {"transmissionFactor": 0.8},
                              "KHR_materials_volume": {"thicknessFactor": 0.5, "attenuationDistance": 1.0,
                                                       "attenuationColor": [0.6, 0.9, 0.7]},
                              "KHR_materials_specular": {"specularFactor": 0.7, "specularColorFactor": [1.0, 0.8, 0.9]},
                              "KHR_materials_clearcoat": {"clearcoatFactor": 0.6, "clearcoatRoughnessFactor": 0.2},
                              "KHR_materials_sheen": {"sheenColorFactor": [0.4, 0.3, 0.6],
                                                      "sheenRoughnessFactor": 0.5}},
                             {"flags": FLAGS_BEHIND}),
    # KHR_texture_transform: offset, rotation and scale on the core maps; the texCoord override
    # (and TEXCOORD_1 itself) on core and extension maps.
    "texture-transform": ((1.0, 1.0, 1.0, 1.0), 0.0, 0.5,
                          {"baseColorTexture": {"index": "checker",
                                                "extensions": xf([0.1, 0.25], 0.6, [2.0, 1.5])},
                           "normalTexture": {"index": "bump", "scale": 0.6,
                                             "extensions": xf(None, 1.5707963, [0.5, 0.5])},
                           "emissiveFactor": [0.3, 0.3, 0.3],
                           "emissiveTexture": {"index": "stripes", "extensions": xf([0.3, -0.2])}}),
    # The same maps untransformed: how closely the two drivers filter them.
    "texture-maps": ((1.0, 1.0, 1.0, 1.0), 0.0, 0.5,
                     {"baseColorTexture": {"index": "checker"}, "normalTexture": {"index": "bump", "scale": 0.6},
                      "emissiveFactor": [0.3, 0.3, 0.3], "emissiveTexture": {"index": "stripes"}}),
    "texture-transform-uv1": ((1.0, 1.0, 1.0, 1.0), 0.0, 0.45,
                              {"baseColorTexture": {"index": "checker", "texCoord": 0,
                                                    "extensions": xf([0.0, 1.0], 1.5707963, [0.5, 0.5], 1)},
                               "emissiveFactor": [0.3, 0.3, 0.3],
                               "emissiveTexture": {"index": "stripes", "texCoord": 1},
                               "KHR_materials_clearcoat": {"clearcoatFactor": 1.0, "clearcoatRoughnessFactor": 1.0,
                                                           "clearcoatRoughnessTexture": {
                                                               "index": "stripes",
                                                               "extensions": xf([0.5, 0.0], -0.8, [1.0, 3.0], 1)}},
                               "KHR_materials_sheen": {"sheenColorFactor": [1.0, 1.0, 1.0], "sheenRoughnessFactor": 0.5,
                                                       "sheenColorTexture": {"index": "checker",
                                                                             "extensions": xf(None, 2.5, [3.0, 3.0])}}},
                              {"uv1": True}),
    # KHR_materials_unlit: the base colour term alone (the emission and normal map are ignored).
    "unlit": ((0.9, 0.8, 0.7, 1.0), 0.0, 0.5,
              {"KHR_materials_unlit": {}, "emissiveFactor": [1.0, 0.0, 0.0],
               "normalTexture": {"index": "bump"},
               "baseColorTexture": {"index": "checker", "extensions": xf([0.2, 0.0], 0.4, [1.5, 1.0])}}),
    "unlit-factor": ((0.2, 0.5, 0.8, 1.0), 0.0, 0.5, {"KHR_materials_unlit": {}}),
    # KHR_lights_punctual from the file: spot cones (inner to outer) and range windows.
    "spot": ((0.8, 0.8, 0.8, 1.0), 0.0, 0.4, {},
             {"flags": FLAGS_FILE_LIGHTS,
              "lights": [spot([0.6, 0.9, 2.4], [0.1, 0.1, 0.0], [1.0, 0.9, 0.8], 12.0,
                              innerConeAngle=0.12, outerConeAngle=0.3),
                         spot([-1.8, -0.6, 1.6], [-0.2, -0.1, 0.0], [0.3, 0.5, 1.0], 10.0,
                              innerConeAngle=0.3, outerConeAngle=0.32)]}),
    "spot-range": ((0.7, 0.7, 0.7, 1.0), 0.0, 0.3, {},
                   {"flags": FLAGS_FILE_LIGHTS,
                    "lights": [spot([-1.4, 1.3, 1.6], [0.0, 0.0, 0.0], [1.0, 1.0, 1.0], 10.0,
                                    outerConeAngle=0.45, range=2.6)]}),
    "point-range": ((0.6, 0.7, 0.8, 1.0), 0.0, 0.35,
                    {"KHR_materials_clearcoat": {"clearcoatFactor": 0.5, "clearcoatRoughnessFactor": 0.2}},
                    {"flags": FLAGS_FILE_LIGHTS,
                     "lights": [point([1.6, -0.4, 1.4], [1.0, 0.6, 0.3], 8.0, range=2.0),
                                point([-1.2, 1.2, 1.8], [0.4, 0.6, 1.0], 6.0)]}),
}

# What each model tests, for --compare's table.
LOBES = {
    "plain": "none (dielectric r 0.35)",
    "normal-map": "none: the coat's normal map as the base's, r 0.2",
    "specular-factor": "specular 0.3",
    "specular-colour": "specular colour (1, 0.4, 0.1)",
    "specular-zero": "specular 0 (pure diffuse)",
    "specular-metal": "specular 0.5, colour, metallic 0.5",
    "clearcoat-smooth": "clearcoat 1, r_c 0.1",
    "clearcoat-rough": "clearcoat 0.6, r_c 0.45",
    "clearcoat-emissive": "clearcoat 0.8 over emission",
    "clearcoat-normal": "clearcoat 1, r_c 0.2, coat normal map",
    "sheen": "sheen (0.9, 0.5, 0.8), r_s 0.5",
    "sheen-smooth": "sheen white, r_s 0.15",
    "sheen-rough": "sheen (0.2, 0.8, 0.5), r_s 1",
    "layered": "specular + clearcoat + sheen",
    "lobe-maps": "all six extension maps (channels differ)",
    "transmission-thin": "transmission 1, thin, r 0.3",
    "transmission-smooth": "transmission 1, thin, r 0.1",
    "transmission-ior": "transmission 0.7, ior 1.2 (r_t = 0.4 r), r 0.5",
    "transmission-metal": "transmission 0.9, metallic 0.4",
    "transmission-volume": "transmission 1, volume: thickness 0.8, colour (0.9, 0.5, 0.2) at 0.5",
    "transmission-maps": "transmission and thickness maps, volume",
    "transmission-layered": "transmission 0.8 + volume + specular + clearcoat + sheen",
    "texture-transform": "offset, rotation, scale on base colour, normal, emissive maps",
    "texture-maps": "none: texture-transform's maps untransformed",
    "texture-transform-uv1": "texCoord override to TEXCOORD_1, transforms on core and extension maps",
    "unlit": "unlit, base colour map with a transform (emission, normal map ignored)",
    "unlit-factor": "unlit, factor only",
    "spot": "two spots: inner 0.12 / outer 0.3, inner 0.3 / outer 0.32",
    "spot-range": "spot outer 0.45 (inner 0), range 2.6",
    "point-range": "point light with range 2 and one without, over a coat",
}

IMAGES = {"bump": (256, 128, bump_normal), "stripes": (128, 64, stripes), "checker": (128, 128, checker)}


def aim(position, target):
    """The quaternion (x, y, z, w) that turns -z (where a spot shines) towards target."""
    d = [target[k] - position[k] for k in range(3)]
    n = math.sqrt(sum(x * x for x in d))
    d = [x / n for x in d]
    # The half-way rotation from a = (0, 0, -1) to d: (a x d, 1 + a.d), normalised.
    q = [d[1], -d[0], 0.0, 1.0 - d[2]]
    n = math.sqrt(sum(x * x for x in q))
    return [x / n for x in q]


def extension_names(node):
    """Every KHR_ key below node (the material's extensions and those of its textureInfos)."""
    names = set()
    if isinstance(node, dict):
        for k, v in node.items():
            if k.startswith("KHR_"):
                names.add(k)
            names |= extension_names(v)
    return names


def gltf_for(base, metallic, roughness, extensions, options=None):
    options = options or {}
    pos, nrm, uv, tan, idx = sphere()
    blob = bytearray()
    views, accessors = [], []

    def add(data, count, ctype, kind, target, minmax=None):
        while len(blob) % 4:
            blob.append(0)
        off = len(blob)
        blob.extend(data)
        views.append({"buffer": 0, "byteOffset": off, "byteLength": len(data), "target": target})
        acc = {"bufferView": len(views) - 1, "componentType": ctype, "count": count, "type": kind}
        if minmax:
            acc["min"], acc["max"] = minmax
        accessors.append(acc)
        return len(accessors) - 1

    flat = lambda rows: [c for r in rows for c in r]
    a_pos = add(struct.pack("<%df" % (3 * len(pos)), *flat(pos)), len(pos), 5126, "VEC3", 34962,
                ([-1.0, -1.0, -1.0], [1.0, 1.0, 1.0]))
    a_nrm = add(struct.pack("<%df" % (3 * len(nrm)), *flat(nrm)), len(nrm), 5126, "VEC3", 34962)
    a_uv = add(struct.pack("<%df" % (2 * len(uv)), *flat(uv)), len(uv), 5126, "VEC2", 34962)
    a_tan = add(struct.pack("<%df" % (4 * len(tan)), *flat(tan)), len(tan), 5126, "VEC4", 34962)
    a_idx = add(struct.pack("<%dI" % len(idx), *idx), len(idx), 5125, "SCALAR", 34963)
    attributes = {"POSITION": a_pos, "NORMAL": a_nrm, "TEXCOORD_0": a_uv, "TANGENT": a_tan}
    if options.get("uv1"):
        uv1 = [uv1_of(u, v) for u, v in uv]
        attributes["TEXCOORD_1"] = add(struct.pack("<%df" % (2 * len(uv1)), *flat(uv1)), len(uv1), 5126, "VEC2",
                                       34962)

    # Texture references name images by key: give each used key one image and texture.
    used = []

    def resolve(node):
        if isinstance(node, dict):
            out = {}
            for k, v in node.items():
                if k == "index" and isinstance(v, str):
                    if v not in used:
                        used.append(v)
                    out[k] = used.index(v)
                else:
                    out[k] = resolve(v)
            return out
        return node

    ext = resolve(extensions)
    used_extensions = extension_names(ext)
    props = {k: v for k, v in ext.items() if not k.startswith("KHR_")}
    ext = {k: v for k, v in ext.items() if k.startswith("KHR_")}
    images, textures = [], []
    for key in used:
        w, h, fn = IMAGES[key]
        images.append({"uri": data_uri("image/png", png_rgba(w, h, fn))})
        textures.append({"source": len(images) - 1, "sampler": 0})
    doc = {
        "asset": {"version": "2.0", "generator": "prast tools/llvmpipe/make_lobe_models.py"},
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [{"attributes": attributes, "indices": a_idx, "material": 0}]}],
        "materials": [{"pbrMetallicRoughness": {"baseColorFactor": list(base), "metallicFactor": metallic,
                                                "roughnessFactor": roughness},
                       "extensions": ext}],
        "buffers": [{"byteLength": len(blob), "uri": data_uri("application/octet-stream", bytes(blob))}],
        "bufferViews": views,
        "accessors": accessors,
    }
    # pbrMetallicRoughness's own textures go there; the rest are material properties.
    for k in ("baseColorTexture", "metallicRoughnessTexture"):
        if k in props:
            doc["materials"][0]["pbrMetallicRoughness"][k] = props.pop(k)
    doc["materials"][0].update(props)
    if not ext:
        del doc["materials"][0]["extensions"]
    lights = options.get("lights", [])
    if lights:
        used_extensions.add("KHR_lights_punctual")
        defs = []
        for kind, position, target, colour, intensity, extra in lights:
            light = {"type": kind, "color": colour, "intensity": intensity}
            if "range" in extra:
                light["range"] = extra["range"]
            if kind == "spot":
                light["spot"] = {k: extra[k] for k in ("innerConeAngle", "outerConeAngle") if k in extra}
            node = {"translation": position, "extensions": {"KHR_lights_punctual": {"light": len(defs)}}}
            if target is not None:
                node["rotation"] = aim(position, target)
            defs.append(light)
            doc["nodes"].append(node)
            doc["scenes"][0]["nodes"].append(len(doc["nodes"]) - 1)
        doc["extensions"] = {"KHR_lights_punctual": {"lights": defs}}
    if used_extensions:
        doc["extensionsUsed"] = sorted(used_extensions)
    if images:
        doc["images"] = images
        doc["textures"] = textures
        doc["samplers"] = [{"magFilter": 9729, "minFilter": 9987, "wrapS": 10497, "wrapT": 10497}]
    return json.dumps(doc, indent=1, sort_keys=True) + "\n"


def compare(build, path, flags):
    """PSNR (dB) and largest channel difference of render's and llvmpipe-render's images of path."""
    stem = os.path.splitext(path)[0]
    for exe, png in (("render", stem + ".render.png"), ("llvmpipe-render", stem + ".llvmpipe.png")):
        subprocess.run([os.path.join(build, exe), path] + flags + ["-o", png], check=True,
                       stdout=subprocess.DEVNULL)
    out = subprocess.run([os.path.join(build, "prast-diff"), stem + ".render.png", stem + ".llvmpipe.png"],
                         stdout=subprocess.PIPE, universal_newlines=True).stdout
    psnr = re.search(r"psnr: (\S+)", out)
    diff = re.search(r"max difference: (\d+)", out)
    if not psnr or not diff:
        raise SystemExit("make_lobe_models.py: prast-diff printed no psnr for %s:\n%s" % (path, out))
    return psnr.group(1), diff.group(1)


def main():
    ap = argparse.ArgumentParser(description="Test models for the layered lobes, transmission, texture transforms, "
                                 "unlit and spot lights (docs/shading.md, \"Against llvmpipe\").")
    ap.add_argument("--out", required=True, help="directory for the .gltf files")
    ap.add_argument("--compare", metavar="BUILD", help="build directory with render, llvmpipe-render, prast-diff")
    ap.add_argument("--only", metavar="NAMES", help="comma-separated model names (default: all)")
    args = ap.parse_args()
    only = args.only.split(",") if args.only else list(MODELS)
    for name in only:
        if name not in MODELS:
            raise SystemExit("make_lobe_models.py: no model %r" % name)
    os.makedirs(args.out, exist_ok=True)
    paths = []
    for name, model in MODELS.items():
        if name not in only:
            continue
        path = os.path.join(args.out, name + ".gltf")
        with open(path, "w") as f:
            f.write(gltf_for(*model))
        paths.append((path, model[4].get("flags", FLAGS) if len(model) > 4 else FLAGS))
        if not args.compare:
            print(path)
    if args.compare:
        print("| model | lobe | PSNR dB | max channel diff |\n| --- | --- | --- | --- |")
        for path, flags in paths:
            name = os.path.basename(path)[:-5]
            psnr, diff = compare(args.compare, path, flags)
            print("| `%s` | %s | %s | %s |" % (name, LOBES[name], psnr, diff))


if __name__ == "__main__":
    main()

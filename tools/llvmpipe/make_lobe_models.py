#!/usr/bin/env python3
# Test models for the layered lobes (KHR_materials_specular, _clearcoat,
# _sheen) that llvmpipe-render and render are compared on (docs/shading.md,
# "Against llvmpipe"): one UV sphere per file, with normals, UVs and tangents,
# buffers and images embedded as data URIs so each model is a single .gltf.
#
#   python3 tools/llvmpipe/make_lobe_models.py --out DIR
#   python3 tools/llvmpipe/make_lobe_models.py --out DIR --compare BUILD
#
# --compare also draws each model with BUILD/render and BUILD/llvmpipe-render
# (configured with -DPRAST_LLVMPIPE=ON) at FLAGS below and prints a Markdown
# table of BUILD/prast-diff's PSNR and largest channel difference.
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


def stripes(u, v):
    """Channels that differ so a wrong channel shows: R, G, B, A vary along u, v, u + v, v."""
    r = 0.5 + 0.5 * math.sin(2.0 * math.pi * 3.0 * u)
    g = 0.5 + 0.5 * math.cos(2.0 * math.pi * 2.0 * v)
    b = 0.5 + 0.5 * math.sin(2.0 * math.pi * (2.0 * u + v))
    a = 0.25 + 0.75 * v
    return tuple(int(round(c * 255.0)) for c in (r, g, b, a))


# name: (base colour, metallic, roughness, extensions; a key not KHR_ is a material property)
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
}

IMAGES = {"bump": (256, 128, bump_normal), "stripes": (128, 64, stripes)}


def gltf_for(base, metallic, roughness, extensions):
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
        "meshes": [{"primitives": [{"attributes": {"POSITION": a_pos, "NORMAL": a_nrm, "TEXCOORD_0": a_uv,
                                                   "TANGENT": a_tan}, "indices": a_idx, "material": 0}]}],
        "materials": [{"pbrMetallicRoughness": {"baseColorFactor": list(base), "metallicFactor": metallic,
                                                "roughnessFactor": roughness},
                       "extensions": ext}],
        "buffers": [{"byteLength": len(blob), "uri": data_uri("application/octet-stream", bytes(blob))}],
        "bufferViews": views,
        "accessors": accessors,
    }
    doc["materials"][0].update(props)
    if ext:
        doc["extensionsUsed"] = sorted(ext.keys())
    else:
        del doc["materials"][0]["extensions"]
    if images:
        doc["images"] = images
        doc["textures"] = textures
        doc["samplers"] = [{"magFilter": 9729, "minFilter": 9987, "wrapS": 10497, "wrapT": 10497}]
    return json.dumps(doc, indent=1, sort_keys=True) + "\n"


def compare(build, path):
    """PSNR (dB) and largest channel difference of render's and llvmpipe-render's images of path."""
    stem = os.path.splitext(path)[0]
    for exe, png in (("render", stem + ".render.png"), ("llvmpipe-render", stem + ".llvmpipe.png")):
        subprocess.run([os.path.join(build, exe), path] + FLAGS + ["-o", png], check=True,
                       stdout=subprocess.DEVNULL)
    out = subprocess.run([os.path.join(build, "prast-diff"), stem + ".render.png", stem + ".llvmpipe.png"],
                         stdout=subprocess.PIPE, universal_newlines=True).stdout
    psnr = re.search(r"psnr: (\S+)", out)
    diff = re.search(r"max difference: (\d+)", out)
    if not psnr or not diff:
        raise SystemExit("make_lobe_models.py: prast-diff printed no psnr for %s:\n%s" % (path, out))
    return psnr.group(1), diff.group(1)


def main():
    ap = argparse.ArgumentParser(description="Test models for the layered lobes (docs/shading.md, \"Against llvmpipe\").")
    ap.add_argument("--out", required=True, help="directory for the .gltf files")
    ap.add_argument("--compare", metavar="BUILD", help="build directory with render, llvmpipe-render, prast-diff")
    args = ap.parse_args()
    os.makedirs(args.out, exist_ok=True)
    paths = []
    for name, (base, metallic, roughness, extensions) in MODELS.items():
        path = os.path.join(args.out, name + ".gltf")
        with open(path, "w") as f:
            f.write(gltf_for(base, metallic, roughness, extensions))
        paths.append(path)
        if not args.compare:
            print(path)
    if args.compare:
        print("| model | lobe | PSNR dB | max channel diff |\n| --- | --- | --- | --- |")
        for path in paths:
            name = os.path.basename(path)[:-5]
            psnr, diff = compare(args.compare, path)
            print("| `%s` | %s | %s | %s |" % (name, LOBES[name], psnr, diff))


if __name__ == "__main__":
    main()

#!/usr/bin/env python3
# prast's own assets, made from nothing but this file (Python 3 standard
# library): a Cornell-box-like room in OBJ+MTL, a textured UV sphere in glTF
# with albedo/normal/ORM maps, and a small studio environment as Radiance HDR.
#
#   python3 assets/make_assets.py            # rewrites the files next to it
#   python3 assets/make_assets.py --out DIR  # writes them under DIR instead
#
# The output is the same bytes on every run (tests/test_assets.cpp regenerates
# it and compares): PNGs use stored (uncompressed) deflate blocks, so the bytes
# do not depend on the zlib build; text numbers are printed at fixed precision;
# the HDR is built from arithmetic only.
import argparse
import json
import math
import os
import struct
import zlib


# ---- writers ---------------------------------------------------------------

def zlib_stored(data):
    """A zlib stream of stored deflate blocks (no compression): fixed bytes."""
    out = bytearray(b"\x78\x01")
    pos = 0
    while True:
        chunk = data[pos:pos + 65535]
        pos += len(chunk)
        last = pos >= len(data)
        out += struct.pack("<BHH", 1 if last else 0, len(chunk), len(chunk) ^ 0xFFFF)
        out += chunk
        if last:
            break
    out += struct.pack(">I", zlib.adler32(data) & 0xFFFFFFFF)
    return bytes(out)


def png_bytes(width, height, rows):
    """8-bit RGB PNG; rows: height lists of width (r, g, b) tuples, top row first."""
    raw = bytearray()
    for row in rows:
        raw.append(0)  # filter: none
        for r, g, b in row:
            raw += bytes((r, g, b))

    def chunk(tag, payload):
        return (struct.pack(">I", len(payload)) + tag + payload +
                struct.pack(">I", zlib.crc32(tag + payload) & 0xFFFFFFFF))

    return (b"\x89PNG\r\n\x1a\n" +
            chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0)) +
            chunk(b"IDAT", zlib_stored(bytes(raw))) + chunk(b"IEND", b""))


def rgbe(r, g, b):
    """Radiance RGBE of a linear colour (Ward's encoding, as stb_image decodes it)."""
    m = max(r, g, b)
    if m < 1e-32:
        return (0, 0, 0, 0)
    mant, exp = math.frexp(m)  # m = mant * 2^exp, mant in [0.5, 1)
    scale = mant * 256.0 / m
    return (int(r * scale), int(g * scale), int(b * scale), exp + 128)


def rle_channel(values):
    """New-style Radiance run-length encoding of one channel of a scanline."""
    out = bytearray()
    i, n = 0, len(values)
    while i < n:
        run = 1
        while i + run < n and run < 127 and values[i + run] == values[i]:
            run += 1
        if run >= 3:
            out += bytes((128 + run, values[i]))
            i += run
            continue
        # Literal bytes up to the next run of 3 or more (at most 128).
        j = i
        while j < n and j - i < 128:
            if j + 2 < n and values[j] == values[j + 1] == values[j + 2]:
                break
            j += 1
        out.append(j - i)
        out += bytes(values[i:j])
        i = j
    return out


def hdr_bytes(width, height, pixel):
    """Radiance .hdr, RLE scanlines; pixel(x, y) -> linear (r, g, b), row 0 on top."""
    out = bytearray(b"#?RADIANCE\n# made by assets/make_assets.py\nFORMAT=32-bit_rle_rgbe\n\n")
    out += ("-Y %d +X %d\n" % (height, width)).encode()
    for y in range(height):
        px = [rgbe(*pixel(x, y)) for x in range(width)]
        out += bytes((2, 2, width >> 8, width & 255))
        for c in range(4):
            out += rle_channel([p[c] for p in px])
    return bytes(out)


def f4(x):
    """x rounded to float32, as a Python float."""
    return struct.unpack("<f", struct.pack("<f", x))[0]


def num(x):
    """Fixed-precision text number without a negative zero."""
    s = "%.4f" % x
    return "0.0000" if s == "-0.0000" else s


def to_byte(x):
    return max(0, min(255, int(math.floor(x * 255.0 + 0.5))))


# ---- Cornell box (OBJ + MTL) -------------------------------------------------
# A room of 2 x 2 x 2 units (x, z in [-1, 1], y in [0, 2]), open towards +Z where
# the camera stands, after the Cornell box: white floor, ceiling and back wall,
# red left wall, green right wall, an emissive panel under the ceiling, and two
# white boxes (a short one turned -18 degrees, a tall one turned +17).

CORNELL_MTL = """# Cornell-box-like room, made by assets/make_assets.py.
newmtl white
Kd 0.73 0.73 0.73
Pr 0.9
Pm 0

newmtl red
Kd 0.63 0.065 0.05
Pr 0.9
Pm 0

newmtl green
Kd 0.14 0.45 0.091
Pr 0.9
Pm 0

newmtl light
Kd 0.78 0.78 0.78
Ke 1 0.85 0.6
Pr 1
Pm 0
"""


class ObjWriter:
    def __init__(self):
        self.lines = ["# Cornell-box-like room, made by assets/make_assets.py.",
                      "# Units: the room is 2 x 2 x 2, open towards +Z; y is up.",
                      "mtllib cornell.mtl"]
        self.nv = 0
        self.nn = 0
        self.object = None

    def quad(self, name, material, corners):
        """A quad given counter-clockwise as seen from the side it faces."""
        a, b, c, _ = corners
        u = [b[i] - a[i] for i in range(3)]
        v = [c[i] - a[i] for i in range(3)]
        n = [u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]]
        length = math.sqrt(sum(x * x for x in n))
        n = [x / length for x in n]
        if name != self.object:
            self.lines.append("o " + name)
            self.lines.append("usemtl " + material)
            self.object = name
        for p in corners:
            self.lines.append("v %s %s %s" % tuple(num(x) for x in p))
        self.lines.append("vn %s %s %s" % tuple(num(x) for x in n))
        self.nn += 1
        i = self.nv
        self.lines.append("f %d//%d %d//%d %d//%d %d//%d" % (i + 1, self.nn, i + 2, self.nn, i + 3, self.nn,
                                                          i + 4, self.nn))
        self.nv += 4

    def box(self, name, cx, cz, sx, sy, sz, angle_deg):
        """An axis-aligned box of size (sx, sy, sz) on the floor, turned about +Y."""
        ca, sa = math.cos(math.radians(angle_deg)), math.sin(math.radians(angle_deg))

        def p(x, y, z):
            return (cx + ca * x + sa * z, y, cz - sa * x + ca * z)

        hx, hz = sx / 2.0, sz / 2.0
        faces = {
            "top": [(-hx, sy, hz), (hx, sy, hz), (hx, sy, -hz), (-hx, sy, -hz)],
            "front": [(-hx, 0, hz), (hx, 0, hz), (hx, sy, hz), (-hx, sy, hz)],
            "back": [(hx, 0, -hz), (-hx, 0, -hz), (-hx, sy, -hz), (hx, sy, -hz)],
            "left": [(-hx, 0, -hz), (-hx, 0, hz), (-hx, sy, hz), (-hx, sy, -hz)],
            "right": [(hx, 0, hz), (hx, 0, -hz), (hx, sy, -hz), (hx, sy, hz)],
        }
        for corners in faces.values():
            self.quad(name, "white", [p(*c) for c in corners])


def make_cornell():
    w = ObjWriter()
    # Walls face the inside of the room.
    w.quad("floor", "white", [(-1, 0, 1), (1, 0, 1), (1, 0, -1), (-1, 0, -1)])
    w.quad("ceiling", "white", [(-1, 2, -1), (1, 2, -1), (1, 2, 1), (-1, 2, 1)])
    w.quad("back", "white", [(-1, 0, -1), (1, 0, -1), (1, 2, -1), (-1, 2, -1)])
    w.quad("left", "red", [(-1, 0, 1), (-1, 0, -1), (-1, 2, -1), (-1, 2, 1)])
    w.quad("right", "green", [(1, 0, -1), (1, 0, 1), (1, 2, 1), (1, 2, -1)])
    # The light panel hangs just below the ceiling, facing down.
    w.quad("light", "light", [(-0.24, 1.995, -0.19), (0.24, 1.995, -0.19), (0.24, 1.995, 0.19),
                              (-0.24, 1.995, 0.19)])
    w.box("short_box", 0.38, 0.42, 0.6, 0.6, 0.6, -18.0)
    w.box("tall_box", -0.38, -0.3, 0.6, 1.2, 0.6, 17.0)
    return {"cornell/cornell.obj": ("\n".join(w.lines) + "\n").encode(),
            "cornell/cornell.mtl": CORNELL_MTL.encode()}


# ---- Textured sphere (glTF) ---------------------------------------------------
# A UV sphere of radius 1: u runs with longitude (u = 0.5 faces +Z, u grows
# towards +X there), v = 0 is the north pole (+Y) and the top image row, as
# glTF has it. Tangents point along +u with w = +1, so the bitangent
# cross(N, T) points north, up the image (docs/conventions.md, "Normal mapping").

TEX_W, TEX_H = 128, 64
CELL = 16  # checker cell in texels: 8 x 4 cells


def hue_rgb(h):
    """A saturated colour for hue h in [0, 1) (piecewise linear, no libm)."""
    h6 = (h % 1.0) * 6.0
    i = int(h6)
    f = h6 - i
    return [(1, f, 0), (1 - f, 1, 0), (0, 1, f), (0, 1 - f, 1), (f, 0, 1), (1, 0, 1 - f)][i]


def bump_height(x, y):
    """Height field of the normal map: a dome per checker cell, in texels."""
    fx = ((x % CELL) + 0.5) / CELL * 2.0 - 1.0
    fy = ((y % CELL) + 0.5) / CELL * 2.0 - 1.0
    r2 = fx * fx + fy * fy
    return 0.0 if r2 >= 0.64 else (0.64 - r2) * 4.0


def make_sphere_textures():
    albedo, normal, orm = [], [], []
    for y in range(TEX_H):
        arow, nrow, orow = [], [], []
        for x in range(TEX_W):
            cx, cy = x // CELL, y // CELL
            # Albedo: hue follows u (column), brightness falls from the top
            # (north) to the bottom; checker cells alternate with light grey.
            if (cx + cy) % 2 == 0:
                c = hue_rgb(cx / 8.0)
                k = 0.9 - 0.15 * cy
                arow.append(tuple(to_byte(0.15 + k * ch * 0.8) for ch in c))
            else:
                arow.append((200, 200, 196))
            # Normal: central differences of the height field (wrapping in u),
            # OpenGL convention: red along +u, green up the image (-row).
            dhdx = (bump_height((x + 1) % TEX_W, y) - bump_height((x - 1) % TEX_W, y)) / 2.0
            dhdy_up = (bump_height(x, max(y - 1, 0)) - bump_height(x, min(y + 1, TEX_H - 1))) / 2.0
            nx, ny, nz = -dhdx * 0.5, -dhdy_up * 0.5, 1.0
            length = math.sqrt(nx * nx + ny * ny + nz * nz)
            nrow.append(tuple(to_byte((c / length + 1.0) * 0.5) for c in (nx, ny, nz)))
            # ORM: occlusion darkens the rims of the domes; roughness grows
            # with u in 4 steps (0.2 .. 0.8); metal on the equator band.
            h = bump_height(x, y)
            occlusion = 1.0 if h > 0.0 else 0.75
            roughness = 0.2 + 0.2 * (x * 4 // TEX_W)
            metallic = 1.0 if TEX_H * 3 // 8 <= y < TEX_H * 5 // 8 else 0.0
            orow.append((to_byte(occlusion), to_byte(roughness), to_byte(metallic)))
        albedo.append(arow)
        normal.append(nrow)
        orm.append(orow)
    return {"textured-sphere/albedo.png": png_bytes(TEX_W, TEX_H, albedo),
            "textured-sphere/normal.png": png_bytes(TEX_W, TEX_H, normal),
            "textured-sphere/orm.png": png_bytes(TEX_W, TEX_H, orm)}


def make_sphere_gltf(segments=32, rings=16):
    pos, nrm, tan, uv = [], [], [], []
    for j in range(rings + 1):
        theta = math.pi * j / rings
        for i in range(segments + 1):
            phi = 2.0 * math.pi * i / segments
            p = (-math.sin(theta) * math.sin(phi), math.cos(theta), -math.sin(theta) * math.cos(phi))
            p = tuple(f4(c) for c in p)
            pos.append(p)
            nrm.append(p)
            tan.append((f4(-math.cos(phi)), 0.0, f4(math.sin(phi)), 1.0))
            uv.append((f4(i / segments), f4(j / rings)))
    idx = []
    for j in range(rings):
        for i in range(segments):
            a = j * (segments + 1) + i
            b, c, d = a + 1, a + segments + 1, a + segments + 2
            # Counter-clockwise seen from outside; the pole rows have one triangle.
            if j != rings - 1:
                idx += [a, c, d]
            if j != 0:
                idx += [a, d, b]
    for t in range(0, len(idx), 3):  # every triangle faces outwards
        p0, p1, p2 = (pos[k] for k in idx[t:t + 3])
        e1 = [p1[k] - p0[k] for k in range(3)]
        e2 = [p2[k] - p0[k] for k in range(3)]
        cr = [e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]]
        assert sum(cr[k] * (p0[k] + p1[k] + p2[k]) for k in range(3)) > 0.0

    blob = bytearray()
    views = []

    def add_view(data, target):
        while len(blob) % 4:
            blob.append(0)
        views.append({"buffer": 0, "byteOffset": len(blob), "byteLength": len(data), "target": target})
        blob.extend(data)
        return len(views) - 1

    def floats(rows):
        return b"".join(struct.pack("<%df" % len(r), *r) for r in rows)

    n = len(pos)
    accessors = [
        {"bufferView": add_view(floats(pos), 34962), "componentType": 5126, "count": n, "type": "VEC3",
         "min": [min(p[k] for p in pos) for k in range(3)], "max": [max(p[k] for p in pos) for k in range(3)]},
        {"bufferView": add_view(floats(nrm), 34962), "componentType": 5126, "count": n, "type": "VEC3"},
        {"bufferView": add_view(floats(tan), 34962), "componentType": 5126, "count": n, "type": "VEC4"},
        {"bufferView": add_view(floats(uv), 34962), "componentType": 5126, "count": n, "type": "VEC2"},
        {"bufferView": add_view(struct.pack("<%dH" % len(idx), *idx), 34963), "componentType": 5123,
         "count": len(idx), "type": "SCALAR"},
    ]
    gltf = {
        "asset": {"version": "2.0", "generator": "prast assets/make_assets.py"},
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0, "name": "sphere"}],
        "meshes": [{"name": "sphere", "primitives": [{
            "attributes": {"POSITION": 0, "NORMAL": 1, "TANGENT": 2, "TEXCOORD_0": 3},
            "indices": 4, "material": 0}]}],
        "materials": [{
            "name": "checker_domes",
            "pbrMetallicRoughness": {"baseColorTexture": {"index": 0}, "metallicRoughnessTexture": {"index": 2},
                                     "metallicFactor": 1.0, "roughnessFactor": 1.0},
            "normalTexture": {"index": 1, "scale": 1.0},
            "occlusionTexture": {"index": 2, "strength": 1.0}}],
        "textures": [{"source": 0, "sampler": 0}, {"source": 1, "sampler": 0}, {"source": 2, "sampler": 0}],
        "samplers": [{"magFilter": 9729, "minFilter": 9987, "wrapS": 10497, "wrapT": 33071}],
        "images": [{"uri": "albedo.png"}, {"uri": "normal.png"}, {"uri": "orm.png"}],
        "accessors": accessors,
        "bufferViews": views,
        "buffers": [{"uri": "sphere.bin", "byteLength": len(blob)}],
    }
    text = json.dumps(gltf, indent=1) + "\n"
    return {"textured-sphere/sphere.gltf": text.encode(), "textured-sphere/sphere.bin": bytes(blob)}


# ---- Studio environment (Radiance HDR) ----------------------------------------
# 128 x 64 equirectangular (docs/conventions.md, "Environment maps": row 0 looks up,
# the centre column looks along -Z, u grows towards +X): a dim warm floor, a
# grey-blue dome brighter towards the zenith, a large warm key soft box front
# left (u = 0.125, 35 degrees up), a cooler fill strip front right and a rim
# light behind. Rectangles in (u, v) with soft edges; arithmetic only.

ENV_W, ENV_H = 128, 64


def soft_box(u, v, cu, cv, hu, hv, edge):
    """1 inside the (u, v) rectangle of half sizes (hu, hv), fading to 0 over `edge`."""
    du = abs(u - cu)
    du = min(du, 1.0 - du)  # wraps around in u
    dv = abs(v - cv)
    fu = min(1.0, max(0.0, (hu + edge - du) / edge))
    fv = min(1.0, max(0.0, (hv + edge - dv) / edge))
    return fu * fv


def studio_pixel(x, y):
    u = (x + 0.5) / ENV_W
    v = (y + 0.5) / ENV_H
    if v > 0.5:  # below the horizon: floor, darker further down
        k = 0.06 + 0.04 * (1.0 - (v - 0.5) * 2.0)
        c = [k * 1.1, k, k * 0.9]
    else:  # dome: 0.25 at the horizon to 0.6 at the zenith
        k = 0.25 + 0.35 * (1.0 - v * 2.0)
        c = [k * 0.9, k * 0.95, k * 1.1]
    for cu, cv, hu, hv, edge, rgb in (
            (0.125, 0.306, 0.06, 0.07, 0.02, (24.0, 21.0, 17.0)),  # key, warm
            (0.875, 0.42, 0.02, 0.09, 0.01, (5.0, 6.0, 7.5)),      # fill, cool strip
            (0.5, 0.25, 0.1, 0.02, 0.01, (8.0, 8.0, 8.0))):        # rim, behind
        w = soft_box(u, v, cu, cv, hu, hv, edge)
        for k in range(3):
            c[k] += w * rgb[k]
    return tuple(c)


def make_env():
    return {"env/studio_small.hdr": hdr_bytes(ENV_W, ENV_H, studio_pixel)}


# ---- main -------------------------------------------------------------------

def all_assets():
    files = {}
    files.update(make_cornell())
    files.update(make_sphere_textures())
    files.update(make_sphere_gltf())
    files.update(make_env())
    return files


def main():
    here = os.path.dirname(os.path.abspath(__file__))
    parser = argparse.ArgumentParser(description="Writes prast's own assets.")
    parser.add_argument("--out", default=here, help="output folder (default: the folder of this script)")
    args = parser.parse_args()
    for name, data in sorted(all_assets().items()):
        path = os.path.join(args.out, name)
        os.makedirs(os.path.dirname(path), exist_ok=True)
        with open(path, "wb") as f:
            f.write(data)
        print("%-32s %7d bytes" % (name, len(data)))


if __name__ == "__main__":
    main()

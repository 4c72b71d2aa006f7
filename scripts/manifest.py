#!/usr/bin/env python3
# The same-bytes manifest (docs/conventions.md "Same bytes everywhere"): a set
# of renders whose PNG bytes every build must reproduce exactly -- GCC and
# Clang, Release and Debug, x86-64, x86-64-v3, x86-64-v4 and aarch64.
#
#   scripts/manifest.py check  --render "build/render"
#   scripts/manifest.py check  --render "qemu-aarch64 build-aarch64/render"
#   scripts/manifest.py update --render "build/render"     (rewrites the hashes)
#
# tests/manifest/scenes.txt names the renders (one "NAME ARGUMENTS..." a
# line; paths relative to the repository; @work/ is the folder this script
# writes its synthetic models to; "?" before a path marks an optional file,
# e.g. the shared assets, whose render is skipped with a note when absent).
# tests/manifest/hashes.txt holds, per render, the SHA-256 of the PNG and a
# hash of each 16x16 block of its pixels, so that a mismatch says where the
# image first differs. Python 3 standard library only.
import argparse
import base64
import concurrent.futures
import hashlib
import json
import os
import shlex
import struct
import subprocess
import sys
import tempfile
import zlib

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SCENES = os.path.join(ROOT, "tests", "manifest", "scenes.txt")
HASHES = os.path.join(ROOT, "tests", "manifest", "hashes.txt")
BLOCK = 16


def read_png_rgba(data):
    """(width, height, rows of RGBA bytes) of an 8-bit RGB or RGBA PNG, as render writes them."""
    if data[:8] != b"\x89PNG\r\n\x1a\n":
        raise ValueError("not a PNG")
    pos, idat, width, height, colour = 8, bytearray(), 0, 0, 0
    while pos + 8 <= len(data):
        length, tag = struct.unpack(">I4s", data[pos:pos + 8])
        body = data[pos + 8:pos + 8 + length]
        if tag == b"IHDR":
            width, height, depth, colour = struct.unpack(">IIBB", body[:10])
            if depth != 8 or colour not in (2, 6) or body[12] != 0:
                raise ValueError("only 8-bit RGB/RGBA non-interlaced PNGs")
        elif tag == b"IDAT":
            idat += body
        elif tag == b"IEND":
            break
        pos += 12 + length
    channels = 4 if colour == 6 else 3
    raw = zlib.decompress(bytes(idat))
    stride = width * channels
    rows, prev = [], bytearray(stride)
    for y in range(height):
        kind = raw[y * (stride + 1)]
        line = bytearray(raw[y * (stride + 1) + 1:(y + 1) * (stride + 1)])
        for i in range(stride):
            a = line[i - channels] if i >= channels else 0
            b = prev[i]
            c = prev[i - channels] if i >= channels else 0
            if kind == 1:
                line[i] = (line[i] + a) & 255
            elif kind == 2:
                line[i] = (line[i] + b) & 255
            elif kind == 3:
                line[i] = (line[i] + (a + b) // 2) & 255
            elif kind == 4:
                p = a + b - c
                pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                line[i] = (line[i] + (a if pa <= pb and pa <= pc else b if pb <= pc else c)) & 255
        prev = line
        if channels == 3:
            rgba = bytearray(width * 4)
            for x in range(width):
                rgba[x * 4:x * 4 + 3] = line[x * 3:x * 3 + 3]
                rgba[x * 4 + 3] = 255
            rows.append(bytes(rgba))
        else:
            rows.append(bytes(line))
    return width, height, rows


def block_hashes(width, height, rows):
    """The first 8 hex digits of the SHA-256 of each 16x16 block, row-major."""
    out = []
    for by in range(0, height, BLOCK):
        for bx in range(0, width, BLOCK):
            h = hashlib.sha256()
            for y in range(by, min(by + BLOCK, height)):
                h.update(rows[y][bx * 4:min(bx + BLOCK, width) * 4])
            out.append(h.hexdigest()[:8])
    return out


# ---- synthetic models (blending and a spot light): one small glTF, written
# the same way on every run.
def blend_gltf():
    """Three overlapping quads, two of them alpha BLEND, over an opaque floor, lit by a spot light."""
    positions, normals, indices = [], [], []

    def quad(z, half, y0):
        base = len(positions) // 3
        for x, y in ((-half, y0), (half, y0), (half, y0 + 2 * half), (-half, y0 + 2 * half)):
            positions.extend((x, y, z))
            normals.extend((0.0, 0.0, 1.0))
        indices.extend((base, base + 1, base + 2, base, base + 2, base + 3))

    quads = [(-0.5, 1.2, -1.0), (0.0, 0.8, -0.6), (0.4, 0.5, -0.3)]
    for z, half, y0 in quads:
        quad(z, half, y0)
    blob = struct.pack("<%df" % len(positions), *positions) + struct.pack("<%df" % len(normals), *normals)
    blob += struct.pack("<%dH" % len(indices), *indices)
    n_vert = len(positions) // 3
    lo = [min(positions[i::3]) for i in range(3)]
    hi = [max(positions[i::3]) for i in range(3)]
    materials = [
        {"name": "opaque", "pbrMetallicRoughness": {"baseColorFactor": [0.8, 0.8, 0.8, 1], "metallicFactor": 0,
                                                    "roughnessFactor": 0.6}},
        {"name": "red glass", "alphaMode": "BLEND",
         "pbrMetallicRoughness": {"baseColorFactor": [0.9, 0.1, 0.1, 0.5], "metallicFactor": 0,
                                  "roughnessFactor": 0.3}},
        {"name": "blue glass", "alphaMode": "BLEND", "doubleSided": True,
         "pbrMetallicRoughness": {"baseColorFactor": [0.1, 0.2, 0.9, 0.35], "metallicFactor": 0,
                                  "roughnessFactor": 0.2}},
    ]
    per_quad = 6 * 2
    pos_len, nrm_len = n_vert * 12, n_vert * 12
    doc = {
        "asset": {"version": "2.0", "generator": "prast scripts/manifest.py"},
        "extensionsUsed": ["KHR_lights_punctual"],
        "extensions": {"KHR_lights_punctual": {"lights": [
            {"type": "spot", "color": [1, 0.9, 0.8], "intensity": 30, "range": 20,
             "spot": {"innerConeAngle": 0.3, "outerConeAngle": 0.6}},
            {"type": "directional", "color": [0.6, 0.7, 1], "intensity": 1.5}]}},
        "scene": 0,
        "scenes": [{"nodes": [0, 1, 2, 3, 4]}],
        "nodes": [{"mesh": i} for i in range(3)] + [
            {"extensions": {"KHR_lights_punctual": {"light": 0}}, "translation": [0.5, 0.6, 2.5]},
            {"extensions": {"KHR_lights_punctual": {"light": 1}}, "rotation": [-0.3826834, 0, 0, 0.9238795]}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "NORMAL": 1}, "indices": 2 + i, "material": i}]}
                   for i in range(3)],
        "materials": materials,
        "buffers": [{"byteLength": len(blob)}],
        "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": pos_len},
                        {"buffer": 0, "byteOffset": pos_len, "byteLength": nrm_len},
                        {"buffer": 0, "byteOffset": pos_len + nrm_len, "byteLength": len(indices) * 2}],
        "accessors": [{"bufferView": 0, "componentType": 5126, "count": n_vert, "type": "VEC3", "min": lo, "max": hi},
                      {"bufferView": 1, "componentType": 5126, "count": n_vert, "type": "VEC3"}] +
                     [{"bufferView": 2, "byteOffset": i * per_quad, "componentType": 5123, "count": 6, "type": "SCALAR"}
                      for i in range(3)],
    }
    doc["buffers"][0]["uri"] = "data:application/octet-stream;base64," + base64.b64encode(blob).decode()
    return json.dumps(doc, indent=1, sort_keys=True).encode()


def write_models(work):
    with open(os.path.join(work, "blend.gltf"), "wb") as f:
        f.write(blend_gltf())


# ---- the manifest
def read_scenes():
    scenes = []
    with open(SCENES) as f:
        for line in f:
            line = line.strip()
            if not line or line.startswith("#"):
                continue
            name, *args = shlex.split(line)
            scenes.append((name, args))
    return scenes


def read_hashes():
    table = {}
    if os.path.exists(HASHES):
        with open(HASHES) as f:
            for line in f:
                if line.startswith("#") or not line.strip():
                    continue
                name, sha, size, blocks = line.split()
                table[name] = (sha, size, blocks.split(","))
    return table


def resolve(args, work):
    """Arguments with paths made absolute; None when an optional file is missing (and its path)."""
    out = []
    for a in args:
        optional = a.startswith("?")
        if optional:
            a = a[1:]
        if a.startswith("@work/"):
            a = os.path.join(work, a[len("@work/"):])
        elif "/" in a and not a.startswith("-") and not os.path.isabs(a):
            a = os.path.join(ROOT, a)
        if optional and not os.path.exists(a):
            return None, a
        out.append(a)
    return out, None


def render_one(render_cmd, name, args, work):
    resolved, missing = resolve(args, work)
    if resolved is None:
        return name, None, "skipped: %s is absent" % missing
    png = os.path.join(work, name + ".png")
    cmd = render_cmd + resolved + ["-o", png]
    try:
        p = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    except OSError as e:
        return name, None, "render failed: cannot run %s (%s)" % (cmd[0], e.strerror)
    if p.returncode != 0:
        return name, None, "render failed (exit %d): %s\n  %s" % (p.returncode, p.stderr.strip(), shlex.join(cmd))
    with open(png, "rb") as f:
        data = f.read()
    return name, (hashlib.sha256(data).hexdigest(), data), None


def size_and_blocks(data):
    """The "WxH" and the 16x16 block hashes of a PNG's pixels (decoded only when they are needed)."""
    width, height, rows = read_png_rgba(data)
    return "%dx%d" % (width, height), block_hashes(width, height, rows)


def first_difference(size, want, got):
    width, height = (int(v) for v in size.split("x"))
    per_row = (width + BLOCK - 1) // BLOCK
    differ = [i for i, (a, b) in enumerate(zip(want, got)) if a != b]
    if not differ:
        return "its pixels are the same: the PNG encoding differs"
    i = differ[0]
    x0, y0 = (i % per_row) * BLOCK, (i // per_row) * BLOCK
    return "pixels first differ in the 16x16 block at x %d-%d, y %d-%d (%d of %d blocks differ)" % (
        x0, min(x0 + BLOCK, width) - 1, y0, min(y0 + BLOCK, height) - 1, len(differ), len(want))


def main():
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("mode", choices=["check", "update"])
    ap.add_argument("--render", required=True, help="the render command, e.g. 'build/render' or 'qemu-aarch64 X/render'")
    ap.add_argument("--work", help="where images and models go (default: a temporary folder; kept on a mismatch)")
    ap.add_argument("--jobs", type=int, default=2, help="renders run at once (default 2)")
    ap.add_argument("--only", help="comma list of scene names")
    opt = ap.parse_args()

    render_cmd = shlex.split(opt.render)
    work = opt.work or tempfile.mkdtemp(prefix="prast-manifest-")
    os.makedirs(work, exist_ok=True)
    write_models(work)
    scenes = read_scenes()
    if opt.only:
        names = set(opt.only.split(","))
        scenes = [s for s in scenes if s[0] in names]
    want = read_hashes()

    results = {}
    with concurrent.futures.ThreadPoolExecutor(max_workers=max(1, opt.jobs)) as pool:
        for name, got, err in pool.map(lambda s: render_one(render_cmd, s[0], s[1], work), scenes):
            results[name] = (got, err)

    failed = 0
    if opt.mode == "update":
        old = read_hashes()
        lines = ["# Written by scripts/manifest.py update: the SHA-256 of each render's PNG, its size and",
                 "# the first 8 hex digits of the SHA-256 of each 16x16 block (row-major). Do not edit."]
        for name, _ in scenes:
            got, err = results[name]
            if err:
                print("manifest: %s: %s" % (name, err))
                if name in old:  # an optional file absent here keeps its line
                    sha, size, blocks = old[name]
                else:
                    failed += err.startswith("render failed")
                    continue
            else:
                sha, (size, blocks) = got[0], size_and_blocks(got[1])
            lines.append("%s %s %s %s" % (name, sha, size, ",".join(blocks)))
        with open(HASHES, "w") as f:
            f.write("\n".join(lines) + "\n")
        print("manifest: wrote %s (%d renders)" % (os.path.relpath(HASHES, ROOT), len(lines) - 2))
        return 1 if failed else 0

    matched = skipped = 0
    for name, _ in scenes:
        got, err = results[name]
        if err:
            print("manifest: %s: %s" % (name, err))
            if err.startswith("skipped"):
                skipped += 1
            else:
                failed += 1
            continue
        if name not in want:
            failed += 1
            print("manifest: %s: not in %s (run scripts/manifest.py update)" % (name, os.path.relpath(HASHES, ROOT)))
            continue
        sha, size, blocks = want[name]
        if got[0] == sha:
            matched += 1
            continue
        failed += 1
        got_size, got_blocks = size_and_blocks(got[1])
        if got_size != size:
            print("manifest: %s: size %s, the manifest's is %s" % (name, got_size, size))
        else:
            print("manifest: %s: PNG differs from the manifest's: %s; the image is %s" % (
                name, first_difference(size, blocks, got_blocks), os.path.join(work, name + ".png")))
    print("manifest: %d of %d renders match, %d differ or failed, %d skipped (%s)" % (
        matched, len(scenes), failed, skipped, " ".join(render_cmd)))
    if not opt.work and failed == 0:
        for f in os.listdir(work):
            os.remove(os.path.join(work, f))
        os.rmdir(work)
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())

# The Python module against the executables it must agree with: render's PNGs
# (byte for byte, on the same-bytes manifest's scenes too), prast-diff's
# figures and render's one-line errors. Run by scripts/check-python.sh (CTest
# `python`) against an installed module; PRAST_RENDER and PRAST_DIFF name the
# executables, PRAST_SOURCE_DIR the repository.
import base64
import hashlib
import json
import os
import shlex
import struct
import subprocess
import sys
import warnings

import numpy as np
import pytest

import prast

SOURCE = os.environ.get("PRAST_SOURCE_DIR", os.path.join(os.path.dirname(__file__), "..", ".."))
RENDER = os.environ.get("PRAST_RENDER", os.path.join(SOURCE, "build", "render"))
DIFF = os.environ.get("PRAST_DIFF", os.path.join(SOURCE, "build", "prast-diff"))
SPHERE = os.path.join(SOURCE, "assets", "textured-sphere", "sphere.gltf")
STUDIO = os.path.join(SOURCE, "assets", "env", "studio_small.hdr")
sys.path.insert(0, os.path.join(SOURCE, "scripts"))
import manifest  # noqa: E402  (scripts/manifest.py: the scenes, their hashes, the PNG reader)


def cli_png(tmp_path, args, name="cli.png"):
    out = tmp_path / name
    p = subprocess.run([RENDER] + [str(a) for a in args] + ["-o", str(out)], capture_output=True, text=True)
    assert p.returncode == 0, p.stderr
    return out.read_bytes()


def png_bytes(tmp_path, image, name="py.png"):
    out = tmp_path / name
    prast.write_png(out, image)
    return out.read_bytes()


def cli_error(args, tmp_path):
    out = tmp_path / "error.png"
    p = subprocess.run([RENDER] + [str(a) for a in args] + ["-o", str(out)], capture_output=True, text=True)
    assert p.returncode != 0
    line = p.stderr.strip().splitlines()[-1]
    assert line.startswith("render: ")
    return p.returncode, line[len("render: "):]


def test_builtin_scene_equals_render_png(tmp_path):
    img = prast.render(size=(160, 120), msaa=4)
    assert img.shape == (120, 160, 4) and img.dtype == np.uint8
    assert (img[:, :, 3] == 255).all()
    want = cli_png(tmp_path, ["--size", "160x120", "--msaa", "4"])
    assert png_bytes(tmp_path, img) == want
    assert np.array_equal(prast.read_png(tmp_path / "cli.png"), img)


def test_keywords_are_render_flags(tmp_path):
    kwargs = dict(size=(96, 80), eye=(0.5, 0.4, 3.0), target=(0, 0, 0), up=(0, 1, 0), fov=35, msaa=1,
                  env=STUDIO, shadows=True, tonemap="neutral", threads=1, exposure=1.25, shadow_size=128,
                  sun=((0.3, 1, 0.2), (2, 2, 2)), point=[((1, 1, 1), (3, 3, 3)), {"position": (-1, 1, 1), "color": (1, 2, 3)}])
    img = prast.render(SPHERE, **kwargs)
    want = cli_png(tmp_path, [SPHERE, "--size", "96x80", "--eye", "0.5,0.4,3", "--target", "0,0,0", "--up", "0,1,0",
                              "--fov", "35", "--msaa", "1", "--env", STUDIO, "--shadows", "on", "--tonemap", "neutral",
                              "--threads", "1", "--exposure", "1.25", "--shadow-size", "128",
                              "--sun", "0.3,1,0.2:2,2,2", "--point", "1,1,1:3,3,3", "--point", "-1,1,1:1,2,3"])
    assert png_bytes(tmp_path, img) == want


def test_view_and_its_default_tonemap(tmp_path):
    img = prast.render(size=(64, 48), msaa=1, view="normal")
    assert png_bytes(tmp_path, img) == cli_png(tmp_path, ["--size", "64x48", "--msaa", "1", "--view", "normal"])


def test_thread_count_does_not_change_the_image():
    a = prast.render(size=(120, 90), msaa=4, threads=1)
    b = prast.render(size=(120, 90), msaa=4, threads=3)
    assert np.array_equal(a, b)


@pytest.mark.parametrize("name,args", manifest.read_scenes(), ids=[s[0] for s in manifest.read_scenes()])
def test_manifest_scene(tmp_path, name, args):
    """prast.render_args() on each of the manifest's scenes writes the PNG bytes the manifest holds."""
    work = str(tmp_path)
    manifest.write_models(work)
    resolved, missing = manifest.resolve(args, work)
    if resolved is None:
        pytest.skip("%s is absent" % missing)
    want = manifest.read_hashes()[name][0]
    img = prast.render_args(resolved)
    assert hashlib.sha256(png_bytes(tmp_path, img)).hexdigest() == want


def test_loaded_scene_renders_again(tmp_path):
    scene = prast.load(SPHERE)
    assert scene.name == SPHERE and len(scene.meshes) >= 1 and scene.triangles > 0
    assert scene.meshes[0]["vertices"] > 0 and len(scene.materials) >= 1
    for eye in ((0, 0, 3), (2, 1, 2)):
        img = scene.render(size=(80, 80), msaa=1, eye=eye, env=STUDIO)
        want = cli_png(tmp_path, [SPHERE, "--size", "80x80", "--msaa", "1", "--eye", "%g,%g,%g" % eye, "--env", STUDIO])
        assert png_bytes(tmp_path, img) == want


def write_quad_gltf(path, positions, normals, uvs, indices, texture_png):
    blob = (np.asarray(positions, np.float32).tobytes() + np.asarray(normals, np.float32).tobytes() +
            np.asarray(uvs, np.float32).tobytes() + np.asarray(indices, np.uint16).tobytes())
    n = len(positions)
    doc = {
        "asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "NORMAL": 1, "TEXCOORD_0": 2}, "indices": 3,
                                    "material": 0}]}],
        "materials": [{"name": "quad", "pbrMetallicRoughness": {
            "baseColorFactor": [0.9, 0.8, 0.7, 1.0], "metallicFactor": 0.25, "roughnessFactor": 0.4,
            "baseColorTexture": {"index": 0}}}],
        "textures": [{"source": 0}],
        "images": [{"uri": "data:image/png;base64," + base64.b64encode(texture_png).decode()}],
        "buffers": [{"byteLength": len(blob), "uri": "data:application/octet-stream;base64," +
                     base64.b64encode(blob).decode()}],
        "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": n * 12},
                        {"buffer": 0, "byteOffset": n * 12, "byteLength": n * 12},
                        {"buffer": 0, "byteOffset": n * 24, "byteLength": n * 8},
                        {"buffer": 0, "byteOffset": n * 32, "byteLength": len(indices) * 2}],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": n, "type": "VEC3",
             "min": np.min(positions, 0).tolist(), "max": np.max(positions, 0).tolist()},
            {"bufferView": 1, "componentType": 5126, "count": n, "type": "VEC3"},
            {"bufferView": 2, "componentType": 5126, "count": n, "type": "VEC2"},
            {"bufferView": 3, "componentType": 5123, "count": len(indices), "type": "SCALAR"}],
    }
    path.write_text(json.dumps(doc))


def test_mesh_from_arrays_equals_the_same_gltf(tmp_path):
    positions = np.array([[-1, -1, 0], [1, -1, 0], [1, 1, 0], [-1, 1, 0]], np.float32)
    normals = np.tile(np.array([0, 0, 1], np.float32), (4, 1))
    uvs = np.array([[0, 1], [1, 1], [1, 0], [0, 0]], np.float32)
    indices = np.array([[0, 1, 2], [0, 2, 3]], np.uint32)
    y, x = np.mgrid[0:16, 0:16]
    texture = np.stack([x * 16, y * 16, (x ^ y) * 16, np.full_like(x, 255)], -1).astype(np.uint8)
    tex_path = tmp_path / "tex.png"
    prast.write_png(tex_path, texture)
    gltf = tmp_path / "quad.gltf"
    write_quad_gltf(gltf, positions, normals, uvs, indices.ravel(), tex_path.read_bytes())
    scene = prast.mesh(positions, indices, normals=normals, uvs=uvs, base_color=(0.9, 0.8, 0.7, 1.0),
                       texture=texture[:, :, :3], metallic=0.25, roughness=0.4, name="quad")
    view = dict(size=(96, 96), msaa=4, eye=(0.3, 0.2, 3.0), target=(0, 0, 0))
    from_arrays = prast.render(scene, **view)
    from_file = prast.render(gltf, **view)
    assert np.array_equal(from_arrays, from_file)
    as_dict = prast.render(dict(positions=positions, indices=indices, normals=normals, uvs=uvs,
                                base_color=(0.9, 0.8, 0.7, 1.0), texture=texture[:, :, :3], metallic=0.25,
                                roughness=0.4), **view)
    assert np.array_equal(as_dict, from_file)
    # Smooth normals computed when none are given: a flat quad's are its face normal.
    assert np.array_equal(prast.render(prast.mesh(positions, indices, uvs=uvs, texture=texture[:, :, :3],
                                                  base_color=(0.9, 0.8, 0.7, 1.0), metallic=0.25, roughness=0.4),
                                       **view), from_file)


@pytest.mark.parametrize("kwargs,what", [
    (dict(positions=np.zeros((2, 3))), "vertices"),
    (dict(positions=np.array([[0, 0, 0], [1, 0, 0], [np.nan, 1, 0]])), "not a finite number"),
    (dict(positions=np.eye(3), indices=[0, 1, 3]), "outside the 3 vertices"),
    (dict(positions=np.eye(3), indices=[0, 1]), "indices must be"),
    (dict(positions=np.eye(3), indices=[0.0, 1.5, 2.0]), "indices must be integers"),
    (dict(positions=np.eye(3), uvs=np.zeros((2, 2))), "uvs must be"),
    (dict(positions=np.eye(3), normals=np.zeros((3, 3))), "normal 0 is zero"),
    (dict(positions=np.eye(3), texture=np.zeros((4, 4, 3), np.uint8)), "a texture needs uvs"),
    (dict(positions=np.eye(3), base_color=(2, 0, 0, 1)), "base_color"),
])
def test_bad_mesh_arrays(kwargs, what):
    with pytest.raises(prast.UsageError, match=what):
        prast.mesh(**kwargs)


@pytest.mark.parametrize("args,kwargs", [
    (["--size", "0x10"], dict(size=(0, 10))),
    (["--msaa", "3"], dict(msaa=3)),
    (["--fov", "200"], dict(fov=200)),
    (["--view", "nonsense"], dict(view="nonsense")),
])
def test_usage_errors_are_renders(tmp_path, args, kwargs):
    code, message = cli_error(args, tmp_path)
    assert code == 2
    with pytest.raises(prast.UsageError) as e:
        prast.render(**kwargs)
    assert str(e.value) == message


def test_file_errors_are_renders(tmp_path):
    missing = tmp_path / "missing.glb"
    code, message = cli_error([missing], tmp_path)
    assert code == 1
    with pytest.raises(prast.FileError) as e:
        prast.render(missing, size=(32, 32))
    assert str(e.value) == message
    with pytest.raises(prast.FileError) as e:
        prast.load(missing)
    assert str(missing) in str(e.value)
    bad = tmp_path / "bad.gltf"
    bad.write_text('{"asset": {"version": "2.0"}, "meshes": [{"primitives": [{"attributes": {"POSITION": 7}}]}]}')
    code, message = cli_error([bad], tmp_path)
    with pytest.raises(prast.Error) as e:
        prast.render(bad, size=(32, 32))
    assert str(e.value) == message


def test_diff_gives_prast_diffs_figures(tmp_path):
    a = prast.render(size=(64, 48), msaa=1)
    b = a.copy()
    b[10, 20, 0] ^= 0x40
    b[30, 5, 2] = 255 - b[30, 5, 2]
    same = prast.diff(a, a)
    assert same.match and same.psnr == float("inf") and same.max_diff == 0 and same.box is None
    r = prast.diff(a, b)
    assert not r.match and r.differing == 2 and r.box == (5, 10, 20, 30)
    prast.write_png(tmp_path / "a.png", a)
    prast.write_png(tmp_path / "b.png", b)
    p = subprocess.run([DIFF, str(tmp_path / "a.png"), str(tmp_path / "b.png")], capture_output=True, text=True)
    assert p.returncode == 1
    # prast-diff's lines after its first ("A vs B").
    assert r.report.strip() == p.stdout.strip().split("\n", 1)[1]
    loose = prast.diff(tmp_path / "a.png", tmp_path / "b.png", tolerance=255)
    assert loose.match and r.heatmap.shape == (48, 64, 4)
    with pytest.raises(prast.UsageError, match="size"):
        prast.diff(a, a[:10])


def test_assert_image_matches(tmp_path, monkeypatch):
    img = prast.render(size=(48, 32), msaa=1)
    golden = tmp_path / "golden" / "scene.png"
    with pytest.raises(AssertionError, match="no golden image"):
        prast.assert_image_matches(img, golden)
    assert (tmp_path / "golden" / "scene.actual.png").exists()
    monkeypatch.setenv("PRAST_UPDATE_GOLDEN", "1")
    prast.assert_image_matches(img, golden)
    monkeypatch.delenv("PRAST_UPDATE_GOLDEN")
    prast.assert_image_matches(img, golden)
    changed = img.copy()
    changed[5:9, 5:9, :3] = 0
    out = tmp_path / "failures"
    with pytest.raises(AssertionError, match="differing pixels: 16 of 1536"):
        prast.assert_image_matches(changed, golden, out_dir=out)
    assert np.array_equal(prast.read_png(out / "scene.actual.png"), changed)
    heat = prast.read_png(out / "scene.diff.png")
    assert heat[6, 6, 0] == 255 and heat[0, 0, 0] == heat[0, 0, 1]  # red where it differs, grey elsewhere
    prast.assert_image_matches(changed, golden, tolerance=255)


def test_warnings_are_python_warnings(tmp_path):
    """What render prints as a warning (an ignored optional extension) is a PrastWarning, once per load."""
    positions = np.array([[-1, -1, 0], [1, -1, 0], [0, 1, 0]], np.float32)
    normals = np.tile(np.array([0, 0, 1], np.float32), (3, 1))
    uvs = np.zeros((3, 2), np.float32)
    model = tmp_path / "ext.gltf"
    prast.write_png(tmp_path / "t.png", np.zeros((2, 2, 3), np.uint8))
    write_quad_gltf(model, positions, normals, uvs, [0, 1, 2], (tmp_path / "t.png").read_bytes())
    doc = json.loads(model.read_text())
    doc["extensionsUsed"] = ["KHR_materials_anisotropy"]
    doc["materials"][0]["extensions"] = {"KHR_materials_anisotropy": {"anisotropyStrength": 0.5}}
    model.write_text(json.dumps(doc))
    p = subprocess.run([RENDER, str(model), "--size", "16x16", "-o", str(tmp_path / "o.png")], capture_output=True,
                       text=True)
    assert p.returncode == 0
    cli_warnings = [l[len("render: warning: "):] for l in p.stderr.splitlines() if l.startswith("render: warning: ")]
    assert any("KHR_materials_anisotropy" in w for w in cli_warnings), p.stderr
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        scene = prast.load(model)
        scene.render(size=(16, 16))
    said = [str(w.message) for w in caught if issubclass(w.category, prast.PrastWarning)]
    assert [w for w in said if "KHR_materials_anisotropy" in w] == [w for w in cli_warnings if "KHR_materials_anisotropy" in w]


def test_fuzzed_arrays_and_arguments_never_crash():
    """Seeded random meshes (shapes, NaN, infinities, huge and negative values, wrong dtypes) and random keyword
    values: each either renders a finite image or raises one of prast's errors (or numpy's TypeError or
    ValueError for what is not an array at all), never crashes the interpreter."""
    rng = np.random.default_rng(26)
    specials = np.array([0.0, 1.0, -1.0, np.nan, np.inf, -np.inf, 1e30, -1e30, 1e-30])
    accepted = 0
    for i in range(800):
        n = int(rng.integers(3, 13)) if rng.random() < 0.8 else int(rng.integers(0, 3))
        shape = (n, 3) if rng.random() < 0.7 else [(n, 2), (n,), (n, 3, 1), (n, 4)][int(rng.integers(0, 4))]
        pos = rng.normal(size=shape) * 10.0 ** float(rng.integers(-3, 4))
        if rng.random() < 0.3 and pos.size:
            pos.flat[int(rng.integers(0, pos.size))] = specials[int(rng.integers(0, len(specials)))]
        kwargs = {}
        if rng.random() < 0.3:  # junk indices
            kwargs["indices"] = rng.integers(-2, max(n, 1) + 2, size=int(rng.integers(0, 9)))
        elif rng.random() < 0.5:  # valid ones
            kwargs["indices"] = rng.integers(0, max(n, 1), size=3 * int(rng.integers(1, 5)))
        elif n % 3:
            continue
        if rng.random() < 0.3:
            kwargs["uvs"] = rng.normal(size=(n, 2 if rng.random() < 0.7 else int(rng.integers(1, 4))))
        if rng.random() < 0.3:
            kwargs["normals"] = rng.normal(size=(n, 3)) * (rng.random() < 0.8)
        if rng.random() < 0.3:
            kwargs["texture"] = rng.integers(0, 256, size=(int(rng.integers(0, 5)), int(rng.integers(1, 5)),
                                                           int(rng.integers(1, 6))), dtype=np.uint8)
        if rng.random() < 0.2:
            kwargs["base_color"] = tuple(rng.normal(size=int(rng.integers(3, 6))))
        if rng.random() < 0.2:
            kwargs["roughness"] = float(specials[int(rng.integers(0, len(specials)))])
        try:
            scene = prast.mesh(pos, **kwargs)
        except (prast.Error, TypeError, ValueError):
            continue
        size = (int(rng.integers(1, 24)), int(rng.integers(1, 24)))
        view = {}
        if rng.random() < 0.5:
            view["eye"] = tuple(rng.normal(size=3) * 5)
        if rng.random() < 0.3:
            view["fov"] = float(rng.choice([0.0, 1e-4, 45.0, 179.9, 180.0, np.nan, -5.0]))
        try:
            img = prast.render(scene, size=size, msaa=int(rng.choice([1, 2, 4, 8])), threads=2, **view)
        except prast.Error:
            continue
        assert img.shape == (size[1], size[0], 4) and img.dtype == np.uint8
        accepted += 1
    assert accepted > 40  # the loop reaches the renderer, not only the checks

"""prast from Python: deterministic physically based renders as numpy arrays.

    import prast
    img = prast.render("model.glb", size=(640, 480), msaa=4)   # (480, 640, 4) uint8
    prast.assert_image_matches(img, "golden/model.png")

prast.render() equals, byte for byte, the PNG `render` writes with the same
flags (RGB; alpha is 255): the keyword arguments become render's flags
(docs/flags.md) and go through render's own parser and frame set-up. Errors
raise prast.UsageError (what render answers with exit code 2) or
prast.FileError (exit code 1), both prast.Error, with render's one-line
message; what render prints as a warning is a prast.PrastWarning.
docs/python.md is the guide.
"""
import os
import warnings

import numpy as np

from . import _prast

__all__ = ["render", "render_args", "load", "mesh", "diff", "assert_image_matches", "read_png", "write_png", "Scene",
           "DiffResult", "Error", "UsageError", "FileError", "PrastWarning", "__version__"]

__version__ = _prast.version
Error = _prast.Error
UsageError = _prast.UsageError
FileError = _prast.FileError


class PrastWarning(UserWarning):
    """A warning render would print (an ignored extension, a texture that did not decode, ...)."""


def _warn(lines):
    for line in lines:
        warnings.warn(line[len("warning: "):] if line.startswith("warning: ") else line, PrastWarning, stacklevel=3)


class Scene:
    """A model loaded once (prast.load) or built from arrays (prast.mesh), drawn by render() as often as wanted;
    its textures are decoded once, on the first render that needs them."""

    def __init__(self, native):
        self._native = native
        self._info = native.describe()

    name = property(lambda self: self._info["name"], doc="The path, or '<mesh NAME>'.")
    meshes = property(lambda self: self._info["meshes"],
                      doc="One dict a drawn primitive: name, vertices, topology, primitives, material.")
    materials = property(lambda self: self._info["materials"], doc="The materials' names.")
    cameras = property(lambda self: self._info["cameras"], doc="The file's cameras: name, type.")
    animations = property(lambda self: self._info["animations"], doc="The animations' names.")
    variants = property(lambda self: self._info["variants"], doc="KHR_materials_variants' names.")
    triangles = property(lambda self: self._info["triangles"])
    bounds = property(lambda self: self._info["bounds"], doc="((x, y, z) low, (x, y, z) high), at rest.")
    extensions_used = property(lambda self: self._info["extensions_used"])

    def render(self, **kwargs):
        """prast.render(self, **kwargs)."""
        return render(self, **kwargs)

    def __repr__(self):
        return "prast.Scene(%r: %d meshes, %d triangles)" % (self.name, len(self.meshes), self.triangles)


def load(path, allow_outside_paths=False):
    """Loads a glTF 2.0 (.gltf, .glb) or OBJ model once, for many renders. Load warnings are PrastWarnings."""
    native = _prast.load(os.fspath(path), bool(allow_outside_paths))
    scene = Scene(native)
    _warn(scene._info["warnings"])
    return scene


def mesh(positions, indices=None, normals=None, uvs=None, base_color=(0.8, 0.8, 0.8, 1.0), texture=None,
         metallic=0.0, roughness=0.5, double_sided=False, name="mesh"):
    """A scene of one triangle mesh from arrays: positions (N, 3); indices (M, 3) or (3M,) (None: every three
    vertices a triangle); normals (N, 3) (None: smooth ones, area-weighted); uvs (N, 2), v = 0 at the top of the
    texture as in glTF; base_color linear RGBA, times `texture`, an sRGB (H, W, 3|4) uint8 array;
    metallic and roughness factors. Counter-clockwise triangles face the camera."""
    if indices is not None:
        indices = np.asarray(indices)
        if indices.dtype.kind not in "iu":
            raise UsageError("mesh '%s': indices must be integers, not %s" % (name, indices.dtype))
    return Scene(_prast.mesh_scene(str(name), np.asarray(positions, dtype=np.float32), indices,
                                   normals, uvs, [float(c) for c in base_color], texture,
                                   float(metallic), float(roughness), bool(double_sided)))


def _num(x):
    """A number as one types it for render: 200, 0.5 (repr: the shortest text that reads back the same)."""
    v = float(x)
    return str(int(v)) if v.is_integer() and abs(v) < 1e15 else repr(v)


def _vec(x, n, what):
    values = [float(v) for v in x]
    if len(values) != n:
        raise UsageError("%s: %d numbers expected, got %d" % (what, n, len(values)))
    return ",".join(_num(v) for v in values)


def _light(flag, light):
    """('sun'|'point', (x, y, z), (r, g, b)) or {'type':..., 'direction'|'position':..., 'color':...}."""
    if isinstance(light, dict):
        kind = light.get("type", flag)
        where = light.get("direction", light.get("position"))
        color = light.get("color", (1.0, 1.0, 1.0))
    else:
        where, color = light
        kind = flag
    return ["--" + kind, _vec(where, 3, kind) + ":" + _vec(color, 3, kind + " colour")]


def _lights(value):
    """A list of lights from one light ((x, y, z), (r, g, b)) or dict, or a list of them."""
    if value is None or (not isinstance(value, dict) and len(value) == 0):
        return []
    if isinstance(value, dict):
        return [value]
    first = value[0]
    if len(value) == 2 and not isinstance(first, dict) and np.ndim(first) == 1 and np.ndim(value[1]) == 1:
        return [value]
    return list(value)


def render(model=None, size=(1280, 720), eye=None, target=None, up=None, fov=45.0, msaa=4, env=None,
           shadows=False, tonemap=None, threads=0, time=0.0, camera=None, view="final", *, sun=(), point=(),
           ambient=None, exposure=None, background=None, env_intensity=None, env_rotate=None, ibl=None,
           samples=None, brdf=None, energy=None, variant=None, animation=None, near=None, far=None,
           file_lights=None, default_lights=True, shadow_size=None, tile=None, allow_outside_paths=False, args=()):
    """Renders `model` and returns the image as an (h, w, 4) uint8 array, equal to the PNG render writes with
    the same flags (alpha 255).

    model: None (the built-in scene), a path, a Scene (load, mesh) or a dict of mesh()'s arguments.
    size (w, h); eye, target, up (x, y, z); fov in degrees; msaa 1, 2, 4 or 8; env an equirectangular .hdr;
    shadows; tonemap 'aces', 'neutral' or 'none' (None: render's default, aces, none with a view);
    threads 0 = all cores (the image does not depend on it); time in seconds for animations; camera a file
    camera's name or index; view 'final' or a debug view (albedo, normal, ...). sun and point: lights, each
    (vector, (r, g, b)), as --sun and --point. The other keywords are render's flags of the same name;
    `args` adds raw flags (e.g. ['--ambient', '0,0,0'])."""
    argv = []
    scene = None
    if isinstance(model, Scene):
        scene = model._native
    elif isinstance(model, dict):
        scene = mesh(**model)._native
    elif model is not None:
        argv.append(os.fspath(model))
    w, h = size
    argv += ["--size", "%dx%d" % (int(w), int(h)), "--fov", _num(fov), "--msaa", str(int(msaa))]
    for flag, value in (("--eye", eye), ("--target", target), ("--up", up)):
        if value is not None:
            argv += [flag, _vec(value, 3, flag[2:])]
    if env is not None:
        argv += ["--env", os.fspath(env)]
    if shadows:
        argv += ["--shadows", "on"]
    if tonemap is not None:
        argv += ["--tonemap", str(tonemap)]
    if threads:
        argv += ["--threads", str(int(threads))]
    if time:
        argv += ["--time", _num(time)]
    if camera is not None:
        argv += ["--camera", str(camera)]
    if view and view != "final":
        argv += ["--view", str(view)]
    for kind, value in (("sun", sun), ("point", point)):
        for light in _lights(value):
            argv += _light(kind, light)
    numbers = {"--exposure": exposure, "--env-intensity": env_intensity, "--env-rotate": env_rotate,
               "--near": near, "--far": far}
    for flag, value in numbers.items():
        if value is not None:
            argv += [flag, _num(value)]
    words = {"--ibl": ibl, "--brdf": brdf, "--variant": variant, "--animation": animation}
    for flag, value in words.items():
        if value is not None:
            argv += [flag, str(value)]
    if ambient is not None:
        argv += ["--ambient", _vec(ambient, 3, "ambient")]
    if background is not None:
        argv += ["--background", background if isinstance(background, str) else _vec(background, 3, "background")]
    if samples is not None:
        argv += ["--samples", str(int(samples))]
    if energy is not None:
        argv += ["--energy", energy if isinstance(energy, str) else ("conserve" if energy else "off")]
    if file_lights is not None:
        argv += ["--file-lights", "on" if file_lights else "off"]
    if not default_lights:
        argv.append("--no-default-lights")
    if shadow_size is not None:
        argv += ["--shadow-size", str(int(shadow_size))]
    if tile is not None:
        argv += ["--tile", str(int(tile))]
    if allow_outside_paths:
        argv.append("--allow-outside-paths")
    argv += [str(a) for a in args]
    image, notes = _prast.render(argv, scene)
    _warn(notes)
    return image


def render_args(args, scene=None):
    """render's command line as a list of strings (without the program name and -o), drawn; `scene` (a Scene)
    replaces the model argument. The array equals the PNG `render ARGS -o out.png` writes."""
    image, notes = _prast.render([os.fspath(a) for a in args], scene._native if scene is not None else None)
    _warn(notes)
    return image


class DiffResult:
    """prast-diff's figures: match, psnr (dB, inf when equal), mse, max_diff and max_at (x, y), differing
    pixels and their fraction, allowed, box (x0, y0, x1, y1), heatmap (H, W, 4) and report, the text prast-diff
    prints."""

    def __init__(self, d):
        self.__dict__.update(d)

    def __bool__(self):
        return self.match

    def __repr__(self):
        return "prast.DiffResult(match=%s, psnr=%.2f, max_diff=%d, differing=%d)" % (
            self.match, self.psnr, self.max_diff, self.differing)


def _image(x):
    if isinstance(x, (str, os.PathLike)):
        return read_png(x)
    return np.ascontiguousarray(x, dtype=np.uint8)


def read_png(path):
    """An image file (PNG, JPEG, ...) as an (h, w, 4) uint8 array."""
    return _prast.read_png(os.fspath(path))


def write_png(path, image):
    """Writes an (h, w, 3|4) uint8 array as render writes its PNGs (RGB, atomically)."""
    _prast.write_png(os.fspath(path), np.ascontiguousarray(image, dtype=np.uint8))


def diff(a, b, tolerance=0, max_fraction=0.0):
    """Compares two images (arrays or paths) as prast-diff does: a channel may differ by up to `tolerance`
    (8-bit units) on all but floor(max_fraction * pixels) pixels. Returns a DiffResult (true when they match)."""
    return DiffResult(_prast.diff(_image(a), _image(b), int(tolerance), float(max_fraction)))


def assert_image_matches(image, golden, tolerance=0, max_fraction=0.0, out_dir=None):
    """Asserts that `image` matches the PNG `golden` within the tolerance (see diff). On failure, writes the
    image as NAME.actual.png and the heat map as NAME.diff.png (in out_dir, else beside the golden) and raises
    AssertionError with prast-diff's report. A missing golden fails the same way, with the image written; with
    the environment variable PRAST_UPDATE_GOLDEN=1 the golden is written instead and the assertion passes."""
    image = _image(image)
    golden = os.fspath(golden)
    stem = os.path.splitext(os.path.basename(golden))[0]
    folder = os.fspath(out_dir) if out_dir is not None else (os.path.dirname(golden) or ".")
    actual = os.path.join(folder, stem + ".actual.png")
    if os.environ.get("PRAST_UPDATE_GOLDEN") == "1":
        os.makedirs(os.path.dirname(golden) or ".", exist_ok=True)
        write_png(golden, image)
        return
    if not os.path.exists(golden):
        os.makedirs(folder, exist_ok=True)
        write_png(actual, image)
        raise AssertionError("%s: no golden image; wrote the actual image to %s (PRAST_UPDATE_GOLDEN=1 writes the "
                             "golden)" % (golden, actual))
    expected = read_png(golden)
    if expected.shape[:2] != image.shape[:2]:
        os.makedirs(folder, exist_ok=True)
        write_png(actual, image)
        raise AssertionError("%s: the golden is %dx%d, the image %dx%d; wrote the image to %s" % (
            golden, expected.shape[1], expected.shape[0], image.shape[1], image.shape[0], actual))
    result = diff(image, expected, tolerance, max_fraction)
    if result.match:
        return
    os.makedirs(folder, exist_ok=True)
    heat = os.path.join(folder, stem + ".diff.png")
    write_png(actual, image)
    write_png(heat, result.heatmap)
    raise AssertionError("%s: the image differs from the golden\n%s\nwrote %s and %s" % (
        golden, result.report.rstrip(), actual, heat))

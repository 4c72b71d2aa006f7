# Pixel tests as a Python project writes them with prast: render with a fixed
# camera and lights, compare with a golden PNG. prast's images are the same
# bytes on every thread count, compiler and CPU (docs/conventions.md), so the
# tolerance is zero. On a mismatch, assert_image_matches writes NAME.actual.png
# and NAME.diff.png (a heat map) beside the golden and fails with the figures;
# PRAST_UPDATE_GOLDEN=1 pytest writes the goldens instead.
#
#   python3 -m pytest examples/python-pixel-test
import os

import numpy as np
import prast

GOLDEN = os.path.join(os.path.dirname(__file__), "golden")


def uv_sphere(rings=24, segments=48):
    """Positions, normals, UVs and triangles of a unit sphere (v = 0 at the north pole)."""
    v, u = np.meshgrid(np.linspace(0, 1, rings + 1), np.linspace(0, 1, segments + 1), indexing="ij")
    theta, phi = v * np.pi, u * 2 * np.pi
    normals = np.stack([np.sin(theta) * np.sin(phi), np.cos(theta), np.sin(theta) * np.cos(phi)], -1).reshape(-1, 3)
    uvs = np.stack([u, v], -1).reshape(-1, 2)
    row = segments + 1
    a = (np.arange(rings)[:, None] * row + np.arange(segments)[None, :]).ravel()
    triangles = np.concatenate([np.stack([a, a + row, a + 1], -1), np.stack([a + 1, a + row, a + row + 1], -1)])
    return normals.astype(np.float32), normals.astype(np.float32), uvs.astype(np.float32), triangles


def checker(size=64, squares=8):
    y, x = np.mgrid[0:size, 0:size] * squares // size
    on = (x + y) % 2 == 1
    return np.where(on[..., None], [230, 180, 40], [40, 60, 160]).astype(np.uint8)


def test_checkered_sphere():
    positions, normals, uvs, triangles = uv_sphere()
    scene = prast.mesh(positions, triangles, normals=normals, uvs=uvs, texture=checker(), roughness=0.35)
    img = prast.render(scene, size=(128, 96), eye=(0, 0.8, 3.2), target=(0, 0, 0), msaa=4,
                       sun=((0.4, 0.8, 0.6), (3, 3, 3)), ambient=(0.05, 0.05, 0.05), default_lights=False)
    prast.assert_image_matches(img, os.path.join(GOLDEN, "checkered_sphere.png"))


def test_builtin_scene_normals():
    img = prast.render(size=(96, 64), msaa=1, view="normal")
    prast.assert_image_matches(img, os.path.join(GOLDEN, "builtin_normals.png"))

"""Cycles renders of a plane showing a photo many times, plain and after
``texsynth.break_repetition`` (the "No repetition" section and tests/blender use them).

The plane is 2 x 2 units with UVs 0-1, the photo repeated by a Mapping node (so the operator is
checked behind one) into a Principled BSDF's Base Color (rough, no specular: what the measures
see is the texture), lit by a sun 45 degrees high whose strength makes a white surface render
white, the Standard view transform. ``top``: an orthographic camera from above framing the plane
exactly, ``grazing``: a 50 mm camera 75 degrees off the normal.
"""

from __future__ import annotations

import importlib.util
import math
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from benchmarks.cycles import cpu_scene
from texsynth.io import read_png
from texsynth.metrics import luminance, mean_gradient
from texsynth.norepeat import anisotropy, period_correlation, repetition_peak

REPO = Path(__file__).resolve().parent.parent
PACKAGE = "texsynth_extension"


def extension():
    """The repository as the extension package, registered (once per process); the Blender
    tests have it installed already and pass theirs instead."""
    if PACKAGE not in sys.modules:
        spec = importlib.util.spec_from_file_location(
            PACKAGE, REPO / "__init__.py", submodule_search_locations=[str(REPO)])
        module = importlib.util.module_from_spec(spec)
        sys.modules[PACKAGE] = module
        spec.loader.exec_module(module)
        module.register()
    return sys.modules[PACKAGE]


def scene(photo: np.ndarray, tiles: int, size: int, samples: int, view: str = "top",
          threads: int = 1, colorspace: str = "sRGB"):
    """A new file: the plane with ``photo`` (H, W, 3, top row first) repeated ``tiles`` x
    ``tiles`` times, the camera, Cycles at ``size`` x ``size``. Returns the material's tree
    with the Image Texture node active and selected."""
    import bpy

    cpu_scene(samples, size, size, threads)
    bpy.context.scene.cycles.pixel_filter_type = "BOX"
    h, w = photo.shape[:2]
    image = bpy.data.images.new("photo", w, h, alpha=True)
    image.colorspace_settings.name = colorspace
    rgba = np.concatenate([photo, np.ones((h, w, 1), np.float32)], axis=2)
    image.pixels.foreach_set(np.ascontiguousarray(rgba[::-1]).ravel())
    image.pack()
    mesh = bpy.data.meshes.new("plane")
    mesh.from_pydata([(-1, -1, 0), (1, -1, 0), (1, 1, 0), (-1, 1, 0)], [], [(0, 1, 2, 3)])
    uv = mesh.uv_layers.new(name="UVMap")
    for loop, corner in zip(uv.data, ((0, 0), (1, 0), (1, 1), (0, 1)), strict=True):
        loop.uv = corner
    plane = bpy.data.objects.new("plane", mesh)
    bpy.context.scene.collection.objects.link(plane)
    material = bpy.data.materials.new("photo")
    if material.node_tree is None:  # Blender 5 gives every material its nodes
        material.use_nodes = True
    tree = material.node_tree
    tree.nodes.clear()
    coords = tree.nodes.new("ShaderNodeTexCoord")
    mapping = tree.nodes.new("ShaderNodeMapping")
    mapping.inputs["Scale"].default_value = (tiles, tiles, 1.0)
    node = tree.nodes.new("ShaderNodeTexImage")
    node.image = image
    shader = tree.nodes.new("ShaderNodeBsdfPrincipled")
    shader.inputs["Roughness"].default_value = 1.0
    shader.inputs["Specular IOR Level"].default_value = 0.0
    out = tree.nodes.new("ShaderNodeOutputMaterial")
    tree.links.new(coords.outputs["UV"], mapping.inputs["Vector"])
    tree.links.new(mapping.outputs["Vector"], node.inputs["Vector"])
    tree.links.new(node.outputs["Color"], shader.inputs["Base Color"])
    tree.links.new(shader.outputs["BSDF"], out.inputs["Surface"])
    mesh.materials.append(material)
    sun = bpy.data.objects.new("sun", bpy.data.lights.new("sun", "SUN"))
    sun.data.energy = math.pi / math.cos(math.radians(45.0))  # irradiance pi: radiance = albedo
    sun.rotation_euler = (math.radians(45.0), 0.0, 0.0)
    bpy.context.scene.collection.objects.link(sun)
    camera = bpy.data.objects.new("camera", bpy.data.cameras.new("camera"))
    bpy.context.scene.collection.objects.link(camera)
    bpy.context.scene.camera = camera
    if view == "top":
        camera.data.type = "ORTHO"
        camera.data.ortho_scale = 2.0
        camera.location = (0.0, 0.0, 5.0)
    else:  # grazing: 75 degrees off the normal, looking at the plane's centre
        angle = math.radians(75.0)
        camera.data.lens = 50.0
        camera.location = (0.0, -0.9 * math.sin(angle), 0.9 * math.cos(angle))
        camera.rotation_euler = (angle, 0.0, 0.0)
        bpy.context.scene.world = None
    for n in tree.nodes:
        n.select = n == node
    tree.nodes.active = node
    plane.active_material = material
    bpy.context.view_layer.objects.active = plane
    return tree


def render() -> tuple[np.ndarray, float]:
    """The scene rendered (float32 (H, W, 3), display-encoded values) and the seconds the
    render took."""
    import bpy

    scene = bpy.context.scene
    with tempfile.TemporaryDirectory() as folder:
        scene.render.filepath = str(Path(folder) / "render.png")
        scene.render.image_settings.file_format = "PNG"
        scene.render.image_settings.color_mode = "RGB"
        start = time.perf_counter()
        bpy.ops.render.render(write_still=True)
        seconds = time.perf_counter() - start
        return read_png(scene.render.filepath)[:, :, :3], seconds


def _quantiles(values: np.ndarray, p: np.ndarray, weights: np.ndarray | None) -> np.ndarray:
    """The ``p`` quantiles of ``values``, each counted ``weights`` times (uniformly if None)."""
    if weights is None:
        return np.quantile(values, p)
    order = np.argsort(values, axis=None)
    cumulative = np.cumsum(weights.ravel()[order])
    at = np.searchsorted(cumulative / cumulative[-1], p).clip(0, values.size - 1)
    return values.ravel()[order][at]


def wasserstein(a: np.ndarray, b: np.ndarray, quantiles: int = 512,
                weights: np.ndarray | None = None) -> list[float]:
    """Per-channel W1 distance between the pixel values of two images (those of ``b`` each
    counted ``weights`` (H, W) times, if given)."""
    p = (np.arange(quantiles) + 0.5) / quantiles
    return [float(np.abs(np.quantile(a[..., k], p) - _quantiles(b[..., k], p, weights)).mean())
            for k in range(a.shape[2])]


def drawn(use: np.ndarray, shape: tuple, period: int) -> np.ndarray:
    """Weights (H, W) of a render from above of the photo repeated every ``period`` pixels:
    each pixel's share ``use`` (the photo's (h, w), e.g. ``texsynth.norepeat.photo_use``) of
    the photo texels it shows, box-averaged to the render's pixels and laid tile by tile."""
    f = use.shape[0] // period
    block = use[:period * f, :period * f].reshape(period, f, period, f).mean(axis=(1, 3))
    return np.tile(block, (-(-shape[0] // period), -(-shape[1] // period)))[:shape[0], :shape[1]]


def measures(plain: np.ndarray, after: np.ndarray, period: int,
             use: np.ndarray | None = None) -> dict:
    """The issue's goals from a plain and an after render (from above, ``period`` pixels a
    tile): correlation at the period of each, the autocorrelation's largest peak at any shift
    of 24 px or more of each, per-channel Wasserstein between them, their gradient and
    structure-tensor anisotropy ratios (after / plain). ``use`` (the photo's (h, w)): how
    much the after render shows of each photo pixel; the plain render's pixels are then
    weighted by it in the anisotropy and Wasserstein (like with like: a Tile Set never shows
    the photo's outermost rows, a plain render shows them every tile)."""
    weights = None if use is None else drawn(use, plain.shape, period)
    return {"corr_plain": period_correlation(plain, period),
            "corr_after": period_correlation(after, period),
            "peak_plain": repetition_peak(plain), "peak_after": repetition_peak(after),
            "anisotropy_ratio": anisotropy(after)
            / max(anisotropy(plain, weights=weights), 1e-12),
            "wasserstein": max(wasserstein(after, plain, weights=weights)),
            "gradient_ratio": mean_gradient(luminance(after), wrap=False)
            / mean_gradient(luminance(plain), wrap=False)}

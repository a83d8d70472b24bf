"""Cycles renders with known truth for the "Photo to material" section (issue 43).

- :func:`light_fields`: the irradiance of a white Lambertian plane under uneven light, seen
  from straight above (orthographic): a window's ramp (an area light low at one side), a spot
  light's pool, a soft shadow (a sun of 20 deg behind a wall out of frame, a dim sky). A photo of
  a textured plane is its albedo times this field (exact for a flat Lambertian surface), times
  a cos^4 vignette for the lens. The field is smoothed by 1 render pixel (its sampling noise;
  the light's own detail is coarser) and upsampled to the photo.
- :func:`displaced`: a periodic height field displaced on a plane (the 3 x 3 tiling of it, the
  camera on the middle tile, so the render tiles and the edges see their neighbours), its
  colour under a white sky and a soft sun from above, and its shading normal as Cycles sees
  it (an emission of the Geometry node's normal: the normal pass) as the truth.

Renders are cached as .npy under ``benchmarks/.cache/material_renders``; bpy imported on use.
"""

from __future__ import annotations

import hashlib
import math
from pathlib import Path

import numpy as np
from scipy.ndimage import gaussian_filter, map_coordinates

from benchmarks.cycles import cpu_scene

CACHE = Path(__file__).resolve().parent / ".cache" / "material_renders"
LIGHT_RES, LIGHT_SAMPLES = 128, 256
SAMPLES = 48


def _read(path: Path, res: int) -> np.ndarray:
    import bpy

    image = bpy.data.images.load(str(path))
    pixels = np.empty(res * res * 4, np.float32)
    image.pixels.foreach_get(pixels)
    bpy.data.images.remove(image)
    return pixels.reshape(res, res, 4)[::-1, :, :3].copy()  # top row first


def _camera(scene, scale=2.0):
    import bpy

    camera = bpy.data.objects.new("camera", bpy.data.cameras.new("camera"))
    camera.data.type, camera.data.ortho_scale = "ORTHO", scale
    camera.location = (0.0, 0.0, 5.0)
    scene.collection.objects.link(camera)
    scene.camera = camera


def _world(scene, strength):
    import bpy

    world = bpy.data.worlds.new("sky")
    world.use_nodes = True
    background = world.node_tree.nodes["Background"]
    background.inputs["Color"].default_value = (1.0, 1.0, 1.0, 1.0)
    background.inputs["Strength"].default_value = strength
    scene.world = world


def _light(scene, kind, location, rotation, energy, **settings):
    import bpy

    data = bpy.data.lights.new(kind, kind)
    data.energy = energy
    for name, value in settings.items():
        setattr(data, name, value)
    light = bpy.data.objects.new(kind, data)
    light.location, light.rotation_euler = location, rotation
    scene.collection.objects.link(light)


def _render(scene, path: Path, res: int) -> np.ndarray:
    import bpy

    scene.render.image_settings.file_format = "OPEN_EXR"
    scene.render.filepath = str(path)
    bpy.ops.render.render(write_still=True)
    return _read(path, res)


#: The uneven lights: name -> set-up.
LIGHTS = ("window", "spot", "shadow")


def _light_scene(name: str):
    import bpy

    scene = cpu_scene(LIGHT_SAMPLES, LIGHT_RES, LIGHT_RES, threads=2)
    scene.cycles.max_bounces = 1
    scene.cycles.filter_width = 1.5
    bpy.ops.mesh.primitive_plane_add(size=2.0)
    plane = bpy.context.active_object
    material = bpy.data.materials.new("white")
    material.use_nodes = True
    material.node_tree.nodes["Principled BSDF"].inputs["Base Color"].default_value = (
        0.8, 0.8, 0.8, 1.0)
    material.node_tree.nodes["Principled BSDF"].inputs["Roughness"].default_value = 1.0
    plane.data.materials.append(material)
    _camera(scene)
    if name == "window":  # an area light low beyond the left edge, facing right and down
        _world(scene, 0.3)
        _light(scene, "AREA", (-3.2, 0.3, 1.0), (0.0, math.radians(-70), 0.0), 700.0,
               size=1.5)
    elif name == "spot":  # a spot light's pool off-centre, its edge soft
        _world(scene, 0.4)
        _light(scene, "SPOT", (0.5, -0.4, 2.2), (math.radians(12), math.radians(10), 0.0),
               600.0, spot_size=math.radians(70), spot_blend=1.0, shadow_soft_size=0.3)
    else:  # a sun behind a wall out of frame: the shadow's soft edge crosses the plane
        _world(scene, 0.25)
        _light(scene, "SUN", (0.0, 0.0, 3.0), (math.radians(50), 0.0, math.radians(20)), 3.0,
               angle=math.radians(20))
        bpy.ops.mesh.primitive_cube_add(size=1.0, location=(0.0, -1.55, 0.6))
        wall = bpy.context.active_object
        wall.scale = (6.0, 0.2, 1.2)
    return scene


def light_fields() -> dict[str, np.ndarray]:
    """name -> the irradiance field (LIGHT_RES, LIGHT_RES) float32, its maximum 1."""
    CACHE.mkdir(parents=True, exist_ok=True)
    fields = {}
    for name in LIGHTS:
        cached = CACHE / f"light_{name}.npy"
        if not cached.exists():
            scene = _light_scene(name)
            rgb = _render(scene, CACHE / f"light_{name}.exr", LIGHT_RES)
            np.save(cached, rgb.mean(axis=2).astype(np.float32))
        field = gaussian_filter(np.load(cached), 1.0, mode="nearest")  # the sampling noise
        fields[name] = field / field.max()
    return fields


def vignette(shape, strength: float = 1.0) -> np.ndarray:
    """cos^4 of the angle off the axis of a lens whose half diagonal sees 30 deg x strength."""
    h, w = shape
    y, x = np.mgrid[:h, :w]
    r = np.hypot((x + 0.5 - w / 2) / (w / 2), (y + 0.5 - h / 2) / (h / 2)) / math.sqrt(2)
    return (np.cos(np.arctan(r * math.tan(math.radians(30 * strength)))) ** 4).astype(
        np.float32)


def _displaced_scene(height_px: np.ndarray, albedo: np.ndarray, normal_pass: bool):
    import bpy

    n = height_px.shape[0]
    scene = cpu_scene(4 if normal_pass else SAMPLES, n, n, threads=2)
    scene.cycles.max_bounces = 2
    scene.cycles.filter_width = 1.0
    tiles = 3
    bpy.ops.mesh.primitive_grid_add(x_subdivisions=tiles * n, y_subdivisions=tiles * n,
                                    size=2.0 * tiles)
    plane = bpy.context.active_object
    co = np.empty(len(plane.data.vertices) * 3, np.float32)
    plane.data.vertices.foreach_get("co", co)
    co = co.reshape(-1, 3)
    px = n / 2.0  # pixels per world unit
    rows = (1.0 - co[:, 1]) * px - 0.5
    cols = (co[:, 0] + 1.0) * px - 0.5
    co[:, 2] = map_coordinates(height_px, [rows, cols], order=3, mode="grid-wrap") / px
    plane.data.vertices.foreach_set("co", co.ravel())
    plane.data.shade_smooth()
    image = bpy.data.images.new("albedo", n, n, float_buffer=True)
    rgba = np.concatenate([albedo, np.ones((n, n, 1), np.float32)], axis=2)
    image.pixels.foreach_set(rgba[::-1].astype(np.float32).ravel())
    material = bpy.data.materials.new("surface")
    material.use_nodes = True
    tree = material.node_tree
    tree.nodes.clear()
    out = tree.nodes.new("ShaderNodeOutputMaterial")
    if normal_pass:
        geometry = tree.nodes.new("ShaderNodeNewGeometry")
        emission = tree.nodes.new("ShaderNodeEmission")
        tree.links.new(geometry.outputs["Normal"], emission.inputs["Color"])
        tree.links.new(emission.outputs["Emission"], out.inputs["Surface"])
        _world(scene, 0.0)
    else:
        coords = tree.nodes.new("ShaderNodeTexCoord")
        mapping = tree.nodes.new("ShaderNodeMapping")  # object xy in [-1, 1] -> uv [0, 1]
        mapping.inputs["Location"].default_value = (0.5, 0.5, 0.0)
        mapping.inputs["Scale"].default_value = (0.5, 0.5, 1.0)
        tex = tree.nodes.new("ShaderNodeTexImage")
        tex.image, tex.interpolation, tex.extension = image, "Linear", "REPEAT"
        diffuse = tree.nodes.new("ShaderNodeBsdfDiffuse")
        tree.links.new(coords.outputs["Object"], mapping.inputs["Vector"])
        tree.links.new(mapping.outputs["Vector"], tex.inputs["Vector"])
        tree.links.new(tex.outputs["Color"], diffuse.inputs["Color"])
        tree.links.new(diffuse.outputs["BSDF"], out.inputs["Surface"])
        _world(scene, 1.0)
        _light(scene, "SUN", (0.0, 0.0, 3.0), (0.0, 0.0, 0.0), 1.5, angle=math.radians(30))
    plane.data.materials.append(material)
    _camera(scene)
    return scene


def displaced(name: str, height_px: np.ndarray, albedo: np.ndarray
              ) -> tuple[np.ndarray, np.ndarray]:
    """(colour (n, n, 3) linear float32, the truth normal (n, n, 3) unit, OpenGL: +Y up) of
    the periodic ``height_px`` (n, n) in pixels with ``albedo`` (n, n, 3) linear."""
    CACHE.mkdir(parents=True, exist_ok=True)
    key = hashlib.sha1(np.ascontiguousarray(height_px, np.float32).tobytes()
                       + np.ascontiguousarray(albedo, np.float32).tobytes()).hexdigest()[:10]
    cached = CACHE / f"surface_{name}_{key}.npz"
    n = height_px.shape[0]
    if not cached.exists():
        colour = _render(_displaced_scene(height_px, albedo, False),
                         CACHE / f"surface_{name}.exr", n)
        normal = _render(_displaced_scene(height_px, albedo, True),
                         CACHE / f"normal_{name}.exr", n)
        np.savez_compressed(cached, colour=colour, normal=normal)
    data = np.load(cached)
    normal = data["normal"] / np.linalg.norm(data["normal"], axis=2, keepdims=True)
    return data["colour"], normal.astype(np.float32)  # world +y is the image's up: OpenGL


def _fbm(n: int, beta: float, rng, low: float = 2.0) -> np.ndarray:
    """Periodic fractional Brownian relief: amplitude |f|^-beta above ``low`` cycles, unit std."""
    f = np.hypot(np.fft.fftfreq(n)[:, None], np.fft.fftfreq(n)[None, :]) * n
    spectrum = np.where(f >= low, np.maximum(f, 1.0) ** -beta, 0.0) * np.exp(
        2j * np.pi * rng.random((n, n)))
    z = np.fft.ifft2(spectrum).real
    return z / z.std()


def _cells(n: int, count: int, rng) -> tuple[np.ndarray, np.ndarray]:
    """The distances to the nearest and second nearest of ``count`` random points on the torus
    (Worley's F1, F2), in pixels."""
    points = rng.random((count, 2)) * n
    y, x = np.mgrid[:n, :n].astype(np.float64)
    d = np.empty((count, n, n))
    for k, (py, px) in enumerate(points):
        dy = np.abs(y - py)
        dx = np.abs(x - px)
        d[k] = np.hypot(np.minimum(dy, n - dy), np.minimum(dx, n - dx))
    d.sort(axis=0)
    return d[0], d[1]


def _bricks(n: int, rows: int, rng) -> np.ndarray:
    """Bricks in running bond: rounded tops, a mortar joint between them, a little roughness."""
    y, x = np.mgrid[:n, :n].astype(np.float64)
    course = n / rows
    row = np.floor(y / course)
    length = 2 * course
    shifted = x + (row % 2) * length / 2
    dy = np.minimum(y % course, course - y % course)
    dx = np.minimum(shifted % length, length - shifted % length)
    edge = np.minimum(dy, dx)
    bevel = course / 5
    return 3.0 * np.clip(edge / bevel, 0, 1) ** 0.5 + 0.25 * _fbm(n, 1.5, rng, 4)


def surfaces(n: int = 256, seed: int = 0) -> dict[str, tuple[np.ndarray, np.ndarray, str]]:
    """name -> (height in pixels (n, n), albedo linear (n, n, 3), "tune" or "held out")."""
    rng = np.random.default_rng(seed)
    out = {}

    def albedo(base, z, dirt, contrast=0.12):
        variation = contrast * _fbm(n, 1.2, rng, 3)
        grey = np.clip(1.0 + variation + dirt * (z - z.mean()) / (z.std() + 1e-9), 0.3, 1.7)
        return (np.asarray(base)[None, None, :] * grey[:, :, None]).astype(np.float32)

    z = 6.0 * _fbm(n, 1.6, rng)
    out["rock"] = (z, albedo((0.45, 0.42, 0.38), z, 0.0), "tune")
    f1, f2 = _cells(n, 40, rng)
    z = 8.0 * np.sqrt(np.clip(f2 - f1, 0, 12) / 12) + 0.4 * _fbm(n, 1.2, rng, 8)
    out["cobbles"] = (z, albedo((0.5, 0.45, 0.4), z, 0.1), "tune")
    z = _bricks(n, 8, rng)
    out["bricks"] = (z, albedo((0.55, 0.3, 0.22), z, 0.15), "tune")
    z = 5.0 * (1.0 - np.abs(_fbm(n, 1.4, rng)))
    out["ridges"] = (z, albedo((0.4, 0.4, 0.42), z, 0.05), "held out")
    f1, f2 = _cells(n, 90, rng)
    z = 5.0 * np.sqrt(np.clip(f2 - f1, 0, 8) / 8) + 0.6 * _fbm(n, 1.0, rng, 16)
    out["pebbles"] = (z, albedo((0.42, 0.4, 0.36), z, 0.0, 0.2), "held out")
    z = _bricks(n, 5, rng) + 1.5 * _fbm(n, 1.8, rng)
    out["worn bricks"] = (z, albedo((0.5, 0.35, 0.3), z, 0.1), "held out")
    return out

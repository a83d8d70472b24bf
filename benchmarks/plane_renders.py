"""Ground-truth renders of textured planes for the plane-orientation evaluation (issue 6).

Each view is rendered with the bpy module: Cycles on the CPU, an emission shader (shading gives no
cue), the texture repeated on a large plane with a random offset and rotation, a black world
beyond it (the texture's periodic component, Moisan 2011, so that repeats show no seam
lines), and a camera at a random slant in [0, 70) degrees, random azimuth and roll (so a random
tilt), orthographic or a 35 / 50 mm lens on a 36 mm sensor. The slant and tilt are computed from
the camera's world matrix and the plane's normal, independently of ``texsynth.plane``.

Views are 320 x 256 pixels unless made larger by :meth:`View.enlarged` (the same scene at a
phone's resolution: 1600 x 1280 took 10-40 s a view on one core of a loaded machine, 320 x
256 about 1 s).
Renders are cached as 8-bit PNG (a photo's encoding) with a JSON sidecar under
``benchmarks/.cache/plane_renders`` (gitignored), keyed by every parameter and the size; a view
is re-rendered when they change.
"""

from __future__ import annotations

import hashlib
import json
import math
from dataclasses import asdict, dataclass, replace
from pathlib import Path

import numpy as np

from benchmarks.cycles import cpu_scene
from texsynth.blocks.color import srgb_to_linear
from texsynth.blocks.periodic import periodic_component
from texsynth.io import read_png
from texsynth.plane import angles_from_normal, focal_px_from_lens

__all__ = ["View", "make_views", "render_views", "camera_rotation", "ground_truth"]

CACHE = Path(__file__).resolve().parent / ".cache" / "plane_renders"
WIDTH, HEIGHT = 320, 256
SENSOR_MM = 36.0
SAMPLES = 16
DISTANCE = 10.0
PLANE_HALF = 400.0
PROJECTIONS = ("ortho", "35mm", "50mm")


@dataclass(frozen=True)
class View:
    """One camera set-up; ``slant`` and ``tilt`` are the ground truth (degrees, texsynth's
    conventions)."""

    texture: str
    projection: str        # "ortho", "35mm" or "50mm"
    elevation: float       # camera angle from the plane normal (degrees): the slant
    azimuth: float         # camera direction around the normal (degrees)
    roll: float            # rotation about the optical axis (degrees): moves the tilt
    texel_px: float        # texture pixels' size on screen at the plane origin (pixels)
    rotation: float        # texture rotation on the plane (degrees)
    offset: tuple[float, float]  # texture offset (tiles)
    slant: float = 0.0
    tilt: float = 0.0
    width: int = WIDTH     # the render's size (pixels)
    height: int = HEIGHT

    @property
    def lens_mm(self) -> float | None:
        return None if self.projection == "ortho" else float(self.projection[:-2])

    @property
    def focal_px(self) -> float | None:
        lens = self.lens_mm
        return None if lens is None else focal_px_from_lens(lens, SENSOR_MM, self.width,
                                                            self.height)

    def key(self) -> str:
        fields = asdict(self)
        size = fields.pop("width"), fields.pop("height")
        text = json.dumps([fields, *size, SAMPLES, PLANE_HALF], sort_keys=True)
        return hashlib.sha1(text.encode()).hexdigest()[:12]

    def enlarged(self, scale: int, texture: str, texture_scale: float = 1.0) -> View:
        """The same scene rendered at ``scale`` times the size: the camera, plane and texture
        unchanged, a texel on the plane the same fraction of the frame. ``texture`` names the
        texture as it is rendered, ``texture_scale`` times as many pixels across as this view's
        (a photo at a higher resolution), so each of its pixels covers ``scale /
        texture_scale`` times this view's ``texel_px`` screen pixels."""
        return replace(self, texture=texture, texel_px=self.texel_px * scale / texture_scale,
                       width=self.width * scale, height=self.height * scale)


def camera_rotation(elevation: float, azimuth: float, roll: float) -> np.ndarray:
    """World-from-camera rotation: looks at the origin from (elevation, azimuth), then rolls."""
    e, a, r = (math.radians(x) for x in (elevation, azimuth, roll))
    position = np.array([math.sin(e) * math.cos(a), math.sin(e) * math.sin(a), math.cos(e)])
    back = position  # camera +Z points away from the scene
    up_hint = np.array([-math.cos(a), -math.sin(a), 0.0]) if e < 1e-6 else np.array([0, 0, 1.0])
    right = np.cross(up_hint, back)
    right /= np.linalg.norm(right)
    up = np.cross(back, right)
    rolled_right = math.cos(r) * right + math.sin(r) * up
    rolled_up = -math.sin(r) * right + math.cos(r) * up
    return np.stack([rolled_right, rolled_up, back], axis=1)


def ground_truth(rotation: np.ndarray) -> tuple[float, float]:
    """(slant, tilt) of the world XY plane (normal +Z) seen by a camera of this rotation."""
    normal_camera = rotation.T @ np.array([0.0, 0.0, 1.0])
    return angles_from_normal(normal_camera)


def make_views(textures, per_texture: int, seed: int = 6) -> list[View]:
    """``per_texture`` views of each texture; slants stratified over [0, 70), projections cycled."""
    rng = np.random.default_rng(seed)
    views = []
    for name in textures:
        strata = rng.permutation(per_texture)
        for k in range(per_texture):
            elevation = float((strata[k] + rng.random()) * 70.0 / per_texture)
            azimuth, roll = (float(x) for x in rng.uniform(0, 360, 2))
            view = View(name, PROJECTIONS[k % 3], elevation, azimuth, roll,
                        float(rng.uniform(0.8, 1.6)), float(rng.uniform(0, 360)),
                        tuple(float(x) for x in rng.random(2)))
            slant, tilt = ground_truth(camera_rotation(elevation, azimuth, roll))
            views.append(View(**{**asdict(view), "offset": view.offset, "slant": slant,
                                 "tilt": tilt}))
    return views


def render_views(views: list[View], textures: dict[str, np.ndarray], threads: int = 1,
                 progress=None) -> list[np.ndarray]:
    """The rendered images (float32 (height, width, 3)), from the cache when present."""
    CACHE.mkdir(parents=True, exist_ok=True)
    missing = [v for v in views if not (CACHE / f"{v.key()}.png").exists()]
    for size in sorted({(v.width, v.height) for v in missing}):
        _render([v for v in missing if (v.width, v.height) == size], textures, threads, progress)
    return [read_png(CACHE / f"{v.key()}.png")[:, :, :3] for v in views]


def _render(views, textures, threads, progress) -> None:
    import bpy
    from mathutils import Matrix

    scene = cpu_scene(SAMPLES, views[0].width, views[0].height, threads)
    scene.cycles.use_adaptive_sampling = False
    scene.cycles.max_bounces = 0
    scene.render.image_settings.file_format = "PNG"
    scene.render.image_settings.color_depth = "8"
    scene.render.image_settings.color_mode = "RGB"
    world = bpy.data.worlds.new("black")
    world.color = (0.0, 0.0, 0.0)
    if world.node_tree is not None:  # Blender 5 worlds come with a grey Background node
        world.node_tree.nodes["Background"].inputs["Strength"].default_value = 0.0
    scene.world = world

    s = PLANE_HALF
    mesh = bpy.data.meshes.new("plane")
    mesh.from_pydata([(-s, -s, 0), (s, -s, 0), (s, s, 0), (-s, s, 0)], [], [(0, 1, 2, 3)])
    plane = bpy.data.objects.new("plane", mesh)
    scene.collection.objects.link(plane)
    material = bpy.data.materials.new("texture")
    material.use_nodes = True
    nodes = material.node_tree.nodes
    nodes.clear()
    coords = nodes.new("ShaderNodeTexCoord")
    mapping = nodes.new("ShaderNodeMapping")
    mapping.vector_type = "TEXTURE"  # rotate, then scale: texels stay square
    image_node = nodes.new("ShaderNodeTexImage")
    image_node.interpolation = "Linear"
    image_node.extension = "REPEAT"
    emission = nodes.new("ShaderNodeEmission")
    output = nodes.new("ShaderNodeOutputMaterial")
    links = material.node_tree.links
    links.new(coords.outputs["Object"], mapping.inputs["Vector"])
    links.new(mapping.outputs["Vector"], image_node.inputs["Vector"])
    links.new(image_node.outputs["Color"], emission.inputs["Color"])
    links.new(emission.outputs["Emission"], output.inputs["Surface"])
    mesh.materials.append(material)

    camera_data = bpy.data.cameras.new("camera")
    camera_data.sensor_width = SENSOR_MM
    camera_data.sensor_fit = "AUTO"
    camera_data.clip_end = 10 * PLANE_HALF
    camera = bpy.data.objects.new("camera", camera_data)
    scene.collection.objects.link(camera)
    scene.camera = camera

    images = {}
    for i, view in enumerate(views):
        if view.texture not in images:
            tex = np.asarray(textures[view.texture], dtype=np.float32)[:, :, :3]
            tex = np.clip(periodic_component(np.broadcast_to(tex, (*tex.shape[:2], 3))), 0, 1)
            h, w = tex.shape[:2]
            img = bpy.data.images.new(view.texture.replace("/", "_"), w, h, float_buffer=True)
            rgba = np.concatenate([srgb_to_linear(tex), np.ones((h, w, 1), np.float32)], axis=2)
            img.pixels.foreach_set(rgba[::-1].ravel())  # Blender stores the bottom row first
            images[view.texture] = img
        img = images[view.texture]
        image_node.image = img
        rot = camera_rotation(view.elevation, view.azimuth, view.roll)
        matrix = np.eye(4)
        matrix[:3, :3] = rot
        matrix[:3, 3] = rot[:, 2] * DISTANCE
        camera.matrix_world = Matrix(matrix.tolist())
        if view.lens_mm is None:
            camera_data.type = "ORTHO"
            camera_data.ortho_scale = DISTANCE * SENSOR_MM / 35.0
            units_per_px = camera_data.ortho_scale / max(view.width, view.height)
        else:
            camera_data.type = "PERSP"
            camera_data.lens = view.lens_mm
            units_per_px = DISTANCE / view.focal_px
        texel = view.texel_px * units_per_px
        w, h = img.size
        mapping.inputs["Scale"].default_value = (w * texel, h * texel, 1.0)
        mapping.inputs["Rotation"].default_value = (0.0, 0.0, math.radians(view.rotation))
        mapping.inputs["Location"].default_value = (view.offset[0] * w * texel,
                                                    view.offset[1] * h * texel, 0.0)
        scene.render.filepath = str(CACHE / f"{view.key()}.png")
        bpy.ops.render.render(write_still=True)
        (CACHE / f"{view.key()}.json").write_text(json.dumps(asdict(view), indent=1))
        if progress is not None:
            progress((i + 1) / len(views), f"rendered {i + 1} of {len(views)} planes")



"""Cycles renders of a textured height field from several orthographic views, rectified to the
frontal grid of the plane z = 0 with the known camera geometry (Neubeck et al. 2004 section 2.2's
input).

Used by ``tests/blender/test_btf_align.py`` and ``benchmarks/sections/stack.py``.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from scipy.ndimage import map_coordinates

from benchmarks.cycles import cpu_scene

__all__ = ["rectified_views", "GRID"]

GRID = 96  # frontal pixels across the plane, which spans [-1, 1]^2 in world units
RES = 128  # render pixels across the camera
ORTHO = 2.6  # camera width in world units (the tilted plane stays in view)
PX = GRID / 2.0  # pixels per world unit


def _scene(albedo, height):
    import bpy

    scene = cpu_scene(4, RES, RES)
    bpy.ops.mesh.primitive_grid_add(x_subdivisions=2 * GRID, y_subdivisions=2 * GRID, size=2.0)
    plane = bpy.context.active_object
    co = np.empty(len(plane.data.vertices) * 3, np.float32)
    plane.data.vertices.foreach_get("co", co)
    co = co.reshape(-1, 3)
    rows = (1.0 - co[:, 1]) * PX - 0.5  # frontal pixel rows go down (world -y)
    cols = (co[:, 0] + 1.0) * PX - 0.5
    co[:, 2] = map_coordinates(height, [rows, cols], order=1, mode="wrap") / PX
    plane.data.vertices.foreach_set("co", co.ravel())
    image = bpy.data.images.new("albedo", GRID, GRID, float_buffer=True)
    rgba = np.concatenate([np.repeat(albedo[:, :, None], 3, 2), np.ones((GRID, GRID, 1))], 2)
    image.pixels.foreach_set(rgba[::-1].astype(np.float32).ravel())
    material = bpy.data.materials.new("albedo")
    if material.node_tree is None:
        material.use_nodes = True
    tree = material.node_tree
    tree.nodes.clear()
    tex = tree.nodes.new("ShaderNodeTexImage")
    tex.image, tex.interpolation, tex.extension = image, "Linear", "REPEAT"
    emission = tree.nodes.new("ShaderNodeEmission")
    out = tree.nodes.new("ShaderNodeOutputMaterial")
    tree.links.new(tex.outputs["Color"], emission.inputs["Color"])
    tree.links.new(emission.outputs["Emission"], out.inputs["Surface"])
    plane.data.materials.append(material)
    camera = bpy.data.objects.new("camera", bpy.data.cameras.new("camera"))
    camera.data.type, camera.data.ortho_scale = "ORTHO", ORTHO
    scene.collection.objects.link(camera)
    scene.camera = camera
    return scene, camera


def _render_rectified(scene, camera, d, path):
    """Render from direction ``d`` (world, towards the camera) and resample onto the frontal
    grid of the plane z = 0."""
    import bpy
    from mathutils import Vector

    camera.location = Vector(d) * 10.0
    camera.rotation_euler = (-Vector(d)).to_track_quat("-Z", "Y").to_euler()
    bpy.context.view_layer.update()
    scene.render.filepath = str(path)
    bpy.ops.render.render(write_still=True)
    render = bpy.data.images.load(str(path))
    pixels = np.empty(RES * RES * 4, np.float32)
    render.pixels.foreach_get(pixels)
    render_img = pixels.reshape(RES, RES, 4)[::-1, :, 0]
    m = np.array(camera.matrix_world)
    right, up, centre = m[:3, 0], m[:3, 1], m[:3, 3]
    i, j = np.mgrid[:GRID, :GRID] + 0.5
    world = np.stack([j / PX - 1.0, 1.0 - i / PX, np.zeros_like(i)], axis=-1) - centre
    u = (world @ right / ORTHO + 0.5) * RES - 0.5
    v = (0.5 - world @ up / ORTHO) * RES - 0.5
    return map_coordinates(render_img, [v, u], order=1, mode="nearest")


def rectified_views(albedo, height, world_dirs, folder) -> tuple[np.ndarray, np.ndarray]:
    """Render the surface (``albedo``, ``height`` in pixels, both (GRID, GRID)) from each unit
    direction of ``world_dirs`` (towards the camera) into ``folder``; returns the rectified
    stack (V, GRID, GRID) and the directions in image axes (x right, y down, z up) for
    ``texsynth.stack.btf.align``. Resets the current Blender file."""

    scene, camera = _scene(albedo, height)
    stack = np.stack([_render_rectified(scene, camera, d, Path(folder) / f"view{k}.png")
                      for k, d in enumerate(world_dirs)])
    return stack, np.asarray(world_dirs) * [1.0, -1.0, 1.0]

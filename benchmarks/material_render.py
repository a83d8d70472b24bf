"""The README's first picture: the phone photo beside a Cycles render of the material
`texsynth material` made from it, on a plane (``python -m benchmarks.material_render``).

The photo is :mod:`benchmarks.phone_photo`'s; `texsynth material PHOTO -o build/material/readme
--size 1024` makes the maps, which are wired as the Blender operator wires them (Color x AO
into Base Color, Roughness, NormalGL through a Normal Map node into a Bump node fed by the
Displacement map) on a 4 x 4 m plane, 1 m a tile, under a low sun; Cycles, 32 samples, 640 x
480. Writes ``docs/img/readme_photo_to_material.jpg``: the photo, then the render.
"""

from __future__ import annotations

import math
import sys
from pathlib import Path

from PIL import Image

from texsynth import cli

from .context import REPO
from .phone_photo import phone_photo

OUT = REPO / "docs" / "img" / "readme_photo_to_material.jpg"
MAPS = REPO / "build" / "material" / "readme"
SIZE = (640, 480)
SAMPLES = 32


def _maps(photo: Path) -> dict[str, Path]:
    stems = {s: MAPS / f"{photo.stem}_{s}.png" for s in ("Color", "NormalGL", "Displacement",
                                                          "Roughness", "AmbientOcclusion")}
    if not all(p.exists() for p in stems.values()):
        assert cli.main(["material", str(photo), "-o", str(MAPS), "--size", "1024"]) == 0
    return stems


def _render(maps: dict[str, Path], out: Path) -> None:
    import bpy

    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    scene.render.engine = "CYCLES"
    scene.cycles.samples = SAMPLES
    scene.cycles.use_denoising = True
    scene.render.resolution_x, scene.render.resolution_y = SIZE
    scene.render.filepath = str(out)
    world = bpy.data.worlds.new("sky")
    world.color = (0.05, 0.06, 0.08)
    scene.world = world
    bpy.ops.mesh.primitive_plane_add(size=4.0)
    plane = bpy.context.active_object
    for loop in plane.data.uv_layers.active.data:  # the material tiled 4 x 4, 1 m a tile
        loop.uv = (loop.uv[0] * 4.0, loop.uv[1] * 4.0)
    material = bpy.data.materials.new("setts")
    tree = material.node_tree
    bsdf = tree.nodes["Principled BSDF"]

    def texture(suffix, data=True):
        node = tree.nodes.new("ShaderNodeTexImage")
        node.image = bpy.data.images.load(str(maps[suffix]))
        if data:
            node.image.colorspace_settings.name = "Non-Color"
        return node

    mix = tree.nodes.new("ShaderNodeMix")
    mix.data_type, mix.blend_type = "RGBA", "MULTIPLY"
    mix.inputs["Factor"].default_value = 1.0
    sockets = {s.identifier: s for s in mix.inputs}
    tree.links.new(texture("Color", data=False).outputs["Color"], sockets["A_Color"])
    tree.links.new(texture("AmbientOcclusion").outputs["Color"], sockets["B_Color"])
    tree.links.new(next(s for s in mix.outputs if s.identifier == "Result_Color"),
                   bsdf.inputs["Base Color"])
    tree.links.new(texture("Roughness").outputs["Color"], bsdf.inputs["Roughness"])
    normal_map = tree.nodes.new("ShaderNodeNormalMap")
    tree.links.new(texture("NormalGL").outputs["Color"], normal_map.inputs["Color"])
    bump = tree.nodes.new("ShaderNodeBump")
    bump.inputs["Strength"].default_value = 0.5
    tree.links.new(texture("Displacement").outputs["Color"], bump.inputs["Height"])
    tree.links.new(normal_map.outputs["Normal"], bump.inputs["Normal"])
    tree.links.new(bump.outputs["Normal"], bsdf.inputs["Normal"])
    plane.data.materials.append(material)
    sun = bpy.data.objects.new("sun", bpy.data.lights.new("sun", "SUN"))
    sun.data.energy = 4.0
    sun.rotation_euler = (math.radians(65), 0.0, math.radians(-40))  # low: the relief shows
    scene.collection.objects.link(sun)
    camera = bpy.data.objects.new("camera", bpy.data.cameras.new("camera"))
    camera.location = (0.0, -2.1, 1.5)
    camera.rotation_euler = (math.radians(58), 0.0, 0.0)
    scene.collection.objects.link(camera)
    scene.camera = camera
    bpy.ops.render.render(write_still=True)


def main() -> None:
    photo = phone_photo()
    maps = _maps(photo)
    render = MAPS / "render.png"
    _render(maps, render)
    left = Image.open(photo).convert("RGB").resize(SIZE, Image.LANCZOS)
    right = Image.open(render).convert("RGB")
    sheet = Image.new("RGB", (SIZE[0] * 2 + 8, SIZE[1]), "white")
    sheet.paste(left, (0, 0))
    sheet.paste(right, (SIZE[0] + 8, 0))
    OUT.parent.mkdir(parents=True, exist_ok=True)
    sheet.save(OUT, quality=90)
    print(OUT, file=sys.stderr)


if __name__ == "__main__":
    main()

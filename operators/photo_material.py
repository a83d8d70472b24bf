"""``texsynth.photo_to_material``: a photo of a surface made into a new, tiling material.

The photo (the active Image Texture node's image, or a file) goes through
``texsynth.material.photo_to_material``: rectified by the plane estimate (the EXIF focal length
of its file; the Place Corners rectangle with ``use_corners``), healed where the ``mask`` image
is white or its alpha is transparent, de-lit, made to tile or synthesized to ``size``, its maps
derived. Five NEW images (``<photo>_material_<seed>_Color``, ``_NormalGL``, ``_Displacement``,
``_Roughness``, ``_AmbientOcclusion``: ambientCG's names) are wired into a NEW material in the
object's active slot:

* Color into Base Color, multiplied by the AO map (a Mix node, Multiply, factor 1: as Node
  Wrangler's Principled texture setup wires an AO map; set its factor to 0 to leave it out);
* Roughness into Roughness; NormalGL through a Normal Map node (tangent space, OpenGL: Blender's
  convention) into a Bump node whose Height is the Displacement map, into Normal (bump, not
  true displacement: it renders in EEVEE and Cycles alike without subdivision).

The user's photo, its node and material are kept (the material with a fake user when no object
uses it any more); Ctrl+Z undoes the whole. Everything is checked and computed before anything
is made: on error or Esc nothing is.
"""

import dataclasses

import bpy
import numpy as np

from .. import texsynth
from . import estimate, output, pixels, properties, source
from .job import JobOperator, Task

#: What the panel says under its button: what the operator does and what it wants.
HINT = "A photo of a flat surface: rectify, heal, delight, tile, maps"
#: Colour spaces of the new images: the colour as the photo's, the maps as data.
DATA = pixels.Encoding(is_float=True, colorspace="Non-Color", is_data=True)
_COLUMN = 400.0  # node spacing in the new material


def _read_file(path: str):
    """A photo file through the core's reader (upright, any format), its encoding (sRGB bytes,
    or linear floats for EXR) and its EXIF focal length."""
    path = bpy.path.abspath(path)
    try:
        values = texsynth.io.read_photo(path)
    except (OSError, texsynth.io.ImageReadError) as error:
        raise ValueError(str(error)) from None
    linear = texsynth.io.is_linear(path)
    encoding = pixels.Encoding(linear, "Linear Rec.709" if linear else "sRGB", False)
    return values, encoding, texsynth.focal_px_from_file(path), bpy.path.basename(path)


def _mask(name: str, shape):
    """The mask image's pixels >= 0.5 (its first channel) as bool (H, W), or None."""
    if not name:
        return None
    image = bpy.data.images.get(name)
    if image is None:
        raise ValueError(f"No image named '{name}' for the mask")
    values, _ = pixels.read_exemplar(image)
    if values.shape[:2] != shape[:2]:
        raise ValueError(f"Mask '{name}' is {values.shape[1]} x {values.shape[0]}, not the "
                         f"photo's {shape[1]} x {shape[0]}")
    return values[:, :, 0] >= 0.5


@properties.photo_material_settings
class TEXSYNTH_OT_photo_to_material(JobOperator, bpy.types.Operator):
    """Make a new tiling material from a photo of a surface: rectify, heal, take out the
    light, make it tile, derive normal, height, roughness and AO maps, wire a Principled BSDF"""

    bl_idname = "texsynth.photo_to_material"
    bl_label = "Photo to Material"
    bl_options = {"REGISTER", "UNDO"}

    def draw(self, context):
        for name in ("filepath", "size", "steps", "use_corners", "seed", "output"):
            self.layout.prop(self, name)
        self.layout.prop_search(self, "mask", bpy.data, "images")
        if self.output != "PACK":
            self.layout.prop(self, "output_dir")

    def prepare(self, context):
        """Check everything and copy the photo (and mask) out; raises ``ValueError``."""
        if self.filepath:
            values, encoding, focal, name = _read_file(self.filepath)
            src = None
        else:
            src = source.find_source(context)
            image = bpy.data.images[src.image]
            ((_, _, values, encoding),) = source.read_maps(context, src, followers=False)
            focal, name = estimate.file_focal_px(image), image.name
        mask = _mask(self.mask, values.shape)
        steps = tuple(s.lower() for s in texsynth.material.pipeline.STEPS
                      if s.upper() in self.steps)
        size = (self.size, self.size) if self.size else None
        corners = None
        if self.use_corners and "rectify" in steps:
            corners = np.reshape(context.scene.texsynth.plane.corners, (4, 2))
        masked = mask is not None or (values.shape[2] == 4 and values[:, :, 3].min() < 1)
        seconds, _ = texsynth.material.pipeline.check(values.shape, size=size, steps=steps,
                                                      seed=self.seed, masked=masked,
                                                      photo=values)
        base = self.target(name, "material")
        out = size or values.shape[1::-1]
        seconds += output.predict_seconds(values.shape[0] * values.shape[1],
                                          5 * out[0] * out[1], self.output)
        job = Task(texsynth.material.photo_to_material, values, size=size, mask=mask,
                   corners=corners, focal_px=focal, steps=steps, seed=self.seed,
                   predicted=seconds)
        obj = context.active_object
        return job, (src, obj.name if obj else "", base, encoding)

    def make(self, result, plan):
        src, object_name, base, encoding = plan
        maps = result.maps
        files = [("Color", result.colour, encoding)]
        if maps is not None:
            files += [("NormalGL", maps.normal * 0.5 + 0.5, DATA),
                      ("Displacement", maps.height[:, :, None], DATA),
                      ("Roughness", maps.roughness[:, :, None], DATA),
                      ("AmbientOcclusion", maps.ao[:, :, None], DATA)]
        images = {suffix: output.create_image(
            np.ascontiguousarray(values, np.float32), enc,
            dataclasses.replace(base, stem=f"{base.stem}_{suffix}"))
            for suffix, values, enc in files}
        material = _material(base.stem, images)
        obj = bpy.data.objects.get(object_name)
        if obj is not None and obj.type == "MESH":
            original = obj.active_material
            if obj.material_slots:
                obj.active_material = material
            else:
                obj.data.materials.append(material)
            if original is not None and original.users == 0:
                original.use_fake_user = True  # kept in the file, not lost on save
        h, w = result.colour.shape[:2]
        return (f"Made material '{material.name}' ({w} x {h}, {len(images)} maps): "
                + "; ".join(result.steps))


def _material(name: str, images: dict):
    """A new material: the images wired into a Principled BSDF (see the module)."""
    material = bpy.data.materials.new(name)
    if bpy.app.version < (5, 0, 0):  # always True from 5.0 on, where setting it is deprecated
        material.use_nodes = True
    tree = material.node_tree
    bsdf = next(n for n in tree.nodes if n.bl_idname == "ShaderNodeBsdfPrincipled")

    def texture(suffix, row):
        node = tree.nodes.new("ShaderNodeTexImage")
        node.image, node.extension, node.label = images[suffix], "REPEAT", suffix
        node.location = (bsdf.location.x - 3 * _COLUMN, bsdf.location.y - row * 300.0)
        return node

    colour = texture("Color", 0)
    base = colour.outputs["Color"]
    if "AmbientOcclusion" in images:
        ao = texture("AmbientOcclusion", 1)
        mix = tree.nodes.new("ShaderNodeMix")
        mix.data_type, mix.blend_type = "RGBA", "MULTIPLY"
        mix.inputs["Factor"].default_value = 1.0
        mix.location = (bsdf.location.x - 1.5 * _COLUMN, bsdf.location.y)
        sockets = {s.identifier: s for s in mix.inputs}
        tree.links.new(base, sockets["A_Color"])
        tree.links.new(ao.outputs["Color"], sockets["B_Color"])
        base = next(s for s in mix.outputs if s.identifier == "Result_Color")
    tree.links.new(base, bsdf.inputs["Base Color"])
    if "Roughness" in images:
        tree.links.new(texture("Roughness", 2).outputs["Color"], bsdf.inputs["Roughness"])
        normal_map = tree.nodes.new("ShaderNodeNormalMap")
        normal_map.location = (bsdf.location.x - 2 * _COLUMN, bsdf.location.y - 900.0)
        tree.links.new(texture("NormalGL", 3).outputs["Color"], normal_map.inputs["Color"])
        bump = tree.nodes.new("ShaderNodeBump")
        bump.location = (bsdf.location.x - _COLUMN, bsdf.location.y - 900.0)
        bump.inputs["Strength"].default_value = 0.5
        tree.links.new(texture("Displacement", 4).outputs["Color"], bump.inputs["Height"])
        tree.links.new(normal_map.outputs["Normal"], bump.inputs["Normal"])
        tree.links.new(bump.outputs["Normal"], bsdf.inputs["Normal"])
    return material


classes = (TEXSYNTH_OT_photo_to_material,)
register, unregister = bpy.utils.register_classes_factory(classes)

"""``texsynth.make_tileable``: the active Image Texture node's photo made to tile, as a new image.

The photo keeps its size and its pixels except in a band across its edges, re-synthesized from
the photo's own patches (``texsynth.make_tileable``). With ``all_maps`` the images of the other
*selected* Image Texture nodes of the material (normal, roughness, height maps of the same size)
follow the same pixel positions and the same correction of the band, from their own pixels
(``texsynth.tileable.follow``), so every map of the material tiles the same way. Each result is
a new image and a new node beside its source node, taking over that node's links, as
``texsynth.synthesize`` does; the user's images are never changed. Everything is checked and
computed before anything is made: on error or cancel the file is unchanged.
"""

import bpy

from .. import texsynth
from . import nodes, output, properties, source
from .job import JobOperator, Task

#: The name given to the results: ``<image>_tileable_<seed>``.
SUFFIX = "tileable"


class TEXSYNTH_OT_make_tileable(JobOperator, bpy.types.Operator):
    """Make the active Image Texture node's photo tile: keep its pixels, re-synthesize only a
    band across its edges from the photo itself, into a new image and node"""

    bl_idname = "texsynth.make_tileable"
    bl_label = "Make Tileable"
    bl_options = {"REGISTER", "UNDO"}

    band: properties.band_property({"SKIP_SAVE"})
    all_maps: bpy.props.BoolProperty(
        name="Other Selected Maps Too", default=False, options={"SKIP_SAVE"},
        description="Make the images of the other selected Image Texture nodes (normal, "
                    "roughness, height... of the same size) tile with the same pixel positions")
    seed: bpy.props.IntProperty(name="Seed", min=0, default=0, options={"SKIP_SAVE"},
                                description="Same photo, band and seed give the same result")
    output: bpy.props.EnumProperty(name="Output", items=properties.OUTPUT_ITEMS, default="PACK",
                                   options={"SKIP_SAVE"})
    output_dir: bpy.props.StringProperty(name="Output Directory", subtype="DIR_PATH",
                                         default="//",
                                         options={"SKIP_SAVE"} | properties.BLEND_RELATIVE)

    def draw(self, context):
        for name in ("band", "all_maps", "seed", "output"):
            self.layout.prop(self, name)
        if self.output != "PACK":
            self.layout.prop(self, "output_dir")

    def prepare(self, context):
        """Check everything and copy every map out of Blender; raises ``ValueError``."""
        settings = context.scene.texsynth
        for name in ("band", "seed", "output", "output_dir"):  # unset: the panel's settings
            if not self.properties.is_property_set(name):
                setattr(self, name, getattr(settings, name))
        src = source.find_source(context)
        maps = [(node_name, values, encoding, self.target(image.name, SUFFIX))
                for node_name, image, values, encoding
                in source.read_maps(context, src, followers=self.all_maps)]
        band, _ = texsynth.tileable.check(maps[0][1].shape, band=self.band or None,
                                          seed=self.seed)  # refused here, before the forecast
        predicted, _ = texsynth.tileable.predict(maps[0][1].shape, band, photo=maps[0][1])
        job = Task(_tile_all, maps[0][1], [m[1] for m in maps[1:]], band=self.band or None,
                   seed=self.seed, predicted=predicted)
        return job, (src, maps)

    def make(self, result, plan):
        src, maps = plan
        values = result
        image = values[0]
        made = [output.create_image(v, encoding, target)
                for (_, _, encoding, target), v in zip(maps, values, strict=True)]
        tree, _ = source.source_node(src)
        first = None
        for (name, *_), new_image in zip(maps, made, strict=True):
            node = tree.nodes.get(name) if tree else None
            if node is not None:
                first = first or nodes.add_result_node(tree, node, new_image)
        if first is not None:
            for node in tree.nodes:
                node.select = False
            first.select = True
            tree.nodes.active = first
        h, w = image.shape[:2]  # made[0].size would load a saved file at once
        return (f"Made {len(made)} image(s) tileable ({w} x {h}): "
                + ", ".join(f"'{m.name}'" for m in made))


def _tile_all(photo, followers, *, band, seed, progress):
    """The photo made to tile, then each follower the same way (in the worker thread)."""
    image, positions = texsynth.make_tileable_positions(photo, band=band, seed=seed,
                                                        progress=progress)
    return [image] + [texsynth.tileable.follow(positions, m, band=band) for m in followers]


classes = (TEXSYNTH_OT_make_tileable,)
register, unregister = bpy.utils.register_classes_factory(classes)

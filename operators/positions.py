"""``texsynth.synthesize_maps``: synthesize one map of a material and make its other maps follow.

The active Image Texture node's image is synthesized with a method that copies exemplar pixels
(``efros_leung``, ``multiscale_mrf``); its position map (where each output pixel came from) is
then applied to the images of the other *selected* Image Texture nodes of the material (normal,
roughness, height maps of the same size), so every map of the material follows the same
synthesis. Each result is a new image and a new node beside its source node, taking over that
node's links, as ``texsynth.synthesize`` does for one image. Everything is checked and computed
before anything is made: on error or cancel the file is unchanged.
"""

import bpy

from .. import texsynth
from . import nodes, output, properties, source
from .job import Job, JobOperator
from .panel import SidebarPanel


class TEXSYNTH_OT_synthesize_maps(JobOperator, bpy.types.Operator):
    """Synthesize the active Image Texture node's image and apply the same pixel positions to the
    other selected Image Texture nodes (normal, roughness, height...), each into a new image and
    node"""

    bl_idname = "texsynth.synthesize_maps"
    bl_label = "Synthesize Material Maps"
    bl_options = {"REGISTER", "UNDO"}

    def draw(self, context):
        properties.draw_settings(self.layout, self, self)

    def prepare(self, context):
        """Check everything and copy every map out of Blender; raises ``ValueError``."""
        src, method, maps = source.material_maps(
            self, context, "other maps", "positions apply to maps of the same size")
        job = Job(texsynth.synthesize_positions, maps[0][1], self.width, self.height,
                  method=method.name, seed=self.seed, **properties.param_values(self, method))
        return job, (src, maps)

    def make(self, result, plan):
        src, maps = plan
        image, positions = result
        values = [image] + [texsynth.apply_positions(positions, m[1]) for m in maps[1:]]
        tree, _ = source.source_node(src)
        first = None
        for (name, _, encoding, target), made in zip(maps, values, strict=True):
            image = output.create_image(made, encoding, target)
            node = tree.nodes.get(name) if tree else None
            if node is not None:
                new = nodes.add_result_node(tree, node, image)
                first = first or new
        if first is not None:
            for node in tree.nodes:
                node.select = False
            first.select = True
            tree.nodes.active = first
        return f"Synthesized {len(maps)} map(s) of {self.width} x {self.height}"


class TEXSYNTH_PT_maps(SidebarPanel, bpy.types.Panel):
    """Under the Texture Synthesis panel: which other maps will follow, and the button."""

    bl_label = "Other Maps"
    bl_parent_id = "TEXSYNTH_PT_synthesize"

    def draw(self, context):
        layout = self.layout
        method = properties.selected_method(context.scene.texsynth)
        if not method.positions:
            layout.label(text="Choose a method that copies pixels", icon="INFO")
            return
        try:
            src = source.find_source(context)
        except ValueError as error:
            layout.label(text=str(error), icon="INFO")
            return
        found = source.follower_nodes(context, src)
        if not found:
            layout.label(text="Select other Image Texture nodes to follow", icon="INFO")
        for node in found:
            layout.label(text=node.image.name, icon="IMAGE_DATA")
        layout.operator(TEXSYNTH_OT_synthesize_maps.bl_idname, icon="NODE_MATERIAL")


classes = (TEXSYNTH_OT_synthesize_maps, TEXSYNTH_PT_maps)
register_classes, unregister_classes = bpy.utils.register_classes_factory(classes)


def register():
    TEXSYNTH_OT_synthesize_maps.__annotations__ = properties.operator_annotations()
    register_classes()


unregister = unregister_classes

"""``texsynth.synthesize_material``: a whole tileable material in one step (paper 002, sec. 3.2).

The active Image Texture node's image is the support view; the images of the other *selected*
Image Texture nodes of the material (normal, roughness, height maps of the same size) follow,
synthesized consistently with it by ``texsynth.synthesize_stack`` (``guided``: each map
synthesized guided by the support; ``column``: the support's positions copied to every map).
Each result is a new image in its map's colour space (Non-Color data stays Non-Color), and the
new images are wired into a COPY of the material, put in the object's active material slot; the
original material is left as it was. Everything is checked and computed before anything is
made: on error or cancel the file is unchanged.
"""

import bpy

from .. import texsynth
from . import output, properties, source
from .job import Job, JobOperator
from .panel import SidebarPanel

MODE_ITEMS = (
    ("GUIDED", "Guided", "Synthesize each map guided by the active one (paper 002, sec. 3.2): "
                         "fewer seams, slower"),
    ("COLUMN", "Column", "Copy the active map's pixel positions to every map: fast and exactly "
                         "registered, may show more seams"),
)


class TEXSYNTH_OT_synthesize_material(JobOperator, bpy.types.Operator):
    """Synthesize the active Image Texture node's image and the other selected Image Texture
    nodes' maps consistently, into new images wired into a copy of the material"""

    bl_idname = "texsynth.synthesize_material"
    bl_label = "Synthesize Material"
    bl_options = {"REGISTER", "UNDO"}

    mode: bpy.props.EnumProperty(name="Mode", items=MODE_ITEMS, default="GUIDED",
                                 options={"SKIP_SAVE"})
    support_weight: bpy.props.FloatProperty(
        name="Support Weight", default=texsynth.stack.C_SUPPORT, min=0.0, max=1.0,
        description="Weight c of the active map in the guided distance (paper 002: 0.25)",
        options={"SKIP_SAVE"})

    def draw(self, context):
        properties.draw_settings(self.layout, self, self)
        self.layout.prop(self, "mode")
        if self.mode == "GUIDED":
            self.layout.prop(self, "support_weight")

    def prepare(self, context):
        """Check everything and copy every map out of Blender; raises ``ValueError``."""
        src, method, maps = source.material_maps(
            self, context, "the maps of a material", "the maps of a material must have one size")
        job = Job(texsynth.synthesize_stack, [m[1] for m in maps], self.width, self.height,
                  support=0, method=method.name, seed=self.seed, mode=self.mode.lower(),
                  c=self.support_weight, **properties.param_values(self, method))
        return job, (src, context.active_object.name, maps)

    def make(self, result, plan):
        src, object_name, maps = plan
        original = bpy.data.materials.get(src.material)
        if original is None or original.node_tree is None:
            raise ValueError(f"Material '{src.material}' is gone: nothing was made")
        images = [output.create_image(values, encoding, target)
                  for (_, _, encoding, target), values in zip(maps, result, strict=True)]
        material = original.copy()
        material.name = f"{original.name}_{properties.selected_method(self).name}_{self.seed}"
        tree = material.node_tree
        for (node_name, *_), image in zip(maps, images, strict=True):
            node = tree.nodes.get(node_name)
            if node is not None:
                node.image = image
                node.extension = "REPEAT"  # the maps tile
        obj = bpy.data.objects.get(object_name)
        if obj is not None and obj.active_material == original:
            obj.active_material = material
        if original.users == 0:
            original.use_fake_user = True  # kept in the file, not lost on save
        return (f"Synthesized {len(images)} map(s) of {self.width} x {self.height} into "
                f"material '{material.name}'")


class TEXSYNTH_PT_material(SidebarPanel, bpy.types.Panel):
    """Under the Texture Synthesis panel: the maps that will follow, and the button."""

    bl_label = "Whole Material"
    bl_parent_id = "TEXSYNTH_PT_synthesize"

    def draw(self, context):
        layout = self.layout
        try:
            src = source.find_source(context)
        except ValueError as error:
            layout.label(text=str(error), icon="INFO")
            return
        layout.label(text=f"{src.image} (support)", icon="IMAGE_DATA")
        for node in source.follower_nodes(context, src):
            layout.label(text=node.image.name, icon="IMAGE_DATA")
        layout.operator(TEXSYNTH_OT_synthesize_material.bl_idname, icon="MATERIAL")


classes = (TEXSYNTH_OT_synthesize_material, TEXSYNTH_PT_material)
register_classes, unregister_classes = bpy.utils.register_classes_factory(classes)


def register():
    TEXSYNTH_OT_synthesize_material.__annotations__.update(properties.operator_annotations())
    register_classes()


unregister = unregister_classes

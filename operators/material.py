"""``texsynth.synthesize_material``: the maps of a material synthesized together, the active
one leading (Neubeck et al. 2004, Neubeck, Zalesny and Van Gool, sections 2.3 and 3.2).

The active Image Texture node's image is the support; the images of the other *selected* Image
Texture nodes of the material (normal, roughness, height maps of the same size) follow it,
through ``texsynth.synthesize_stack``:

* ``GUIDED`` (sec. 3.2): each map synthesized guided by the support, weight ``support_weight``
  (the paper's c): fewer seams, slower;
* ``COLUMN`` (sec. 2.3): the support's pixel positions copied to every map: fast and exactly
  registered, may show more seams.

The support's method must copy exemplar pixels (``efros_leung``, ``multiscale_mrf``). Each
result is a new image in its map's colour space (Non-Color data stays Non-Color), and the new
images are wired into a COPY of the material, put in the object's active material slot; the
original material is left as it was. Everything is checked and computed before anything is
made: on error or cancel the file is unchanged.
"""

import bpy

from .. import texsynth
from . import output, properties, source
from .job import JobOperator, Task

MODE_ITEMS = (
    ("GUIDED", "Guided", "Synthesize each map guided by the active one (Neubeck et al. 2004, "
                         "sec. 3.2): fewer seams, slower"),
    ("COLUMN", "Column", "Copy the active map's pixel positions to every map: fast and exactly "
                         "registered, may show more seams"),
)


def material_maps(operator, context):
    """``(source, method, maps)``: the support, then each follower map, checked and copied.

    ``maps`` holds ``(node name, pixels, encoding, target)`` of the source image, then of each
    follower node's image. Raises ``ValueError`` when the operator's method copies no pixels
    or a map's size differs from the source's.
    """
    properties.fill_unset(operator, context.scene.texsynth)
    src = source.find_source(context)
    method = properties.selected_method(operator)
    if not method.positions:
        names = ", ".join(m.label for m in texsynth.methods() if m.positions)
        raise ValueError(f"{method.label} does not copy pixels, so the maps of a material cannot "
                         f"follow it; choose {names}")
    maps = [(node_name, values, encoding, operator.target(image.name, method.name))
            for node_name, image, values, encoding in source.read_maps(context, src)]
    return src, method, maps


@properties.registry_settings()
class TEXSYNTH_OT_synthesize_material(JobOperator, bpy.types.Operator):
    """Synthesize the active Image Texture node's image and make the other selected Image
    Texture nodes' maps follow it, into new images wired into a copy of the material"""

    bl_idname = "texsynth.synthesize_material"
    bl_label = "Synthesize Material"
    bl_options = {"REGISTER", "UNDO"}

    # Method, size, seed, output and every method's parameters: added by registry_settings.
    mode: bpy.props.EnumProperty(name="Mode", items=MODE_ITEMS, default="GUIDED",
                                 options={"SKIP_SAVE"})
    support_weight: bpy.props.FloatProperty(
        name="Support Weight", default=texsynth.stack.C_SUPPORT, min=0.0, max=1.0,
        description="Weight c of the active map in the guided distance (Neubeck et al. 2004: 0.25)",
        options={"SKIP_SAVE"})

    @classmethod
    def poll(cls, context):
        try:
            source.find_source(context)
        except ValueError as error:
            cls.poll_message_set(str(error))
            return False
        return True

    def draw(self, context):
        properties.draw_settings(self.layout, self, self)
        self.layout.prop(self, "mode")
        if self.mode == "GUIDED":
            self.layout.prop(self, "support_weight")

    def prepare(self, context):
        """Check everything and copy every map out of Blender; raises ``ValueError``."""
        src, method, maps = material_maps(self, context)
        job = Task(texsynth.synthesize_stack, [m[1] for m in maps], self.width, self.height,
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


classes = (TEXSYNTH_OT_synthesize_material,)
register, unregister = bpy.utils.register_classes_factory(classes)

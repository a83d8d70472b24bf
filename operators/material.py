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
from . import output, pixels, properties, source
from .job import Job
from .positions import follower_nodes
from .synthesize import TEXSYNTH_OT_synthesize

MODE_ITEMS = (
    ("GUIDED", "Guided", "Synthesize each map guided by the active one (paper 002, sec. 3.2): "
                         "fewer seams, slower"),
    ("COLUMN", "Column", "Copy the active map's pixel positions to every map: fast and exactly "
                         "registered, may show more seams"),
)


class StackJob(Job):
    """A :class:`Job` running ``texsynth.synthesize_stack`` on a list of maps (support first)."""

    def run(self) -> None:
        stack, width, height, method, seed, params = self._call
        try:
            self.result = texsynth.synthesize_stack(
                stack, width, height, support=0, method=method, seed=seed,
                progress=self._progress, **params)
        except texsynth.Cancelled:
            self.cancelled = True
        except Exception as error:  # reported on the main thread, where bpy can be used
            self.error = error


class TEXSYNTH_OT_synthesize_material(bpy.types.Operator):
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

    # The run, the worker thread, progress and Esc are texsynth.synthesize's own.
    execute = TEXSYNTH_OT_synthesize.execute
    invoke = TEXSYNTH_OT_synthesize.invoke
    modal = TEXSYNTH_OT_synthesize.modal
    cancel = TEXSYNTH_OT_synthesize.cancel
    _end_ui = TEXSYNTH_OT_synthesize._end_ui
    _fail = TEXSYNTH_OT_synthesize._fail

    def draw(self, context):
        properties.draw_settings(self.layout, self)
        self.layout.prop(self, "mode")
        if self.mode == "GUIDED":
            self.layout.prop(self, "support_weight")

    def _prepare(self, context):
        """Check everything and copy every map out of Blender; raises ``ValueError``."""
        properties.fill_unset(self, context.scene.texsynth)
        src = source.find_source(context)
        method = properties.selected_method(self)
        if not method.positions:
            names = ", ".join(m.label for m in texsynth.methods() if m.positions)
            raise ValueError(f"{method.label} does not copy pixels, so the maps of a material "
                             f"cannot follow it; choose {names}")
        maps = []
        for node_name, image in [(src.node, bpy.data.images[src.image])] + [
                (n.name, n.image) for n in follower_nodes(context, src)]:
            values, encoding = pixels.read_exemplar(image)
            if maps and values.shape[:2] != maps[0][1].shape[:2]:
                h, w = maps[0][1].shape[:2]
                raise ValueError(f"Image '{image.name}' of node '{node_name}' is "
                                 f"{values.shape[1]} x {values.shape[0]}, not {w} x {h} like "
                                 f"'{src.image}': the maps of a material must have one size")
            target = output.plan(self.output, self.output_dir, image.name, method.name,
                                 self.seed)
            maps.append((node_name, values, encoding, target))
        params = {p.name: getattr(self, name) for p, name in properties.param_properties(method)}
        params.update(mode=self.mode.lower(), c=self.support_weight)
        job = StackJob([m[1] for m in maps], self.width, self.height, method.name, self.seed,
                       params)
        return job, (src, context.active_object.name, maps)

    def _finish(self, job, plan):
        if job.cancelled:
            self.report({"INFO"}, "Synthesis cancelled: nothing was created")
            return {"CANCELLED"}
        if job.error is not None:
            return self._fail(job.error)
        src, object_name, maps = plan
        original = bpy.data.materials.get(src.material)
        if original is None or original.node_tree is None:
            return self._fail(ValueError(f"Material '{src.material}' is gone: nothing was made"))
        images = []
        for (_, _, encoding, target), values in zip(maps, job.result, strict=True):
            try:
                images.append(output.create_image(values, encoding, target))
            except OSError as error:
                return self._fail(error)
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
        self.report({"INFO"}, f"Synthesized {len(images)} map(s) of {self.width} x "
                              f"{self.height} into material '{material.name}'")
        return {"FINISHED"}


class TEXSYNTH_PT_material(bpy.types.Panel):
    """Under the Texture Synthesis panel: the maps that will follow, and the button."""

    bl_label = "Whole Material"
    bl_space_type = "NODE_EDITOR"
    bl_region_type = "UI"
    bl_category = "TexSynth"
    bl_parent_id = "TEXSYNTH_PT_synthesize"

    @classmethod
    def poll(cls, context):
        return getattr(context.space_data, "tree_type", "") == "ShaderNodeTree"

    def draw(self, context):
        layout = self.layout
        try:
            src = source.find_source(context)
        except ValueError as error:
            layout.label(text=str(error), icon="INFO")
            return
        layout.label(text=f"{src.image} (support)", icon="IMAGE_DATA")
        for node in follower_nodes(context, src):
            layout.label(text=node.image.name, icon="IMAGE_DATA")
        layout.operator(TEXSYNTH_OT_synthesize_material.bl_idname, icon="MATERIAL")


classes = (TEXSYNTH_OT_synthesize_material, TEXSYNTH_PT_material)


def register():
    TEXSYNTH_OT_synthesize_material.__annotations__.update(
        properties.settings_annotations({"SKIP_SAVE"}))
    for cls in classes:
        bpy.utils.register_class(cls)


def unregister():
    for cls in reversed(classes):
        bpy.utils.unregister_class(cls)

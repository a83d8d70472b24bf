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
from . import nodes, output, pixels, properties, source
from .job import Job
from .synthesize import TEXSYNTH_OT_synthesize


class PositionsJob(Job):
    """A :class:`Job` whose result is ``(image, positions)`` (``texsynth.synthesize_positions``)."""

    def run(self) -> None:
        exemplar, width, height, method, seed, params = self._call
        try:
            self.result = texsynth.synthesize_positions(
                exemplar, width, height, method=method, seed=seed, progress=self._progress,
                **params)
        except texsynth.Cancelled:
            self.cancelled = True
        except Exception as error:  # reported on the main thread, where bpy can be used
            self.error = error


def follower_nodes(context, src: source.Source):
    """The selected Image Texture nodes with an image, other than the source node."""
    tree = bpy.data.materials[src.material].node_tree
    return [n for n in tree.nodes if n.select and n.bl_idname == "ShaderNodeTexImage"
            and n.name != src.node and n.image is not None]


class TEXSYNTH_OT_synthesize_maps(bpy.types.Operator):
    """Synthesize the active Image Texture node's image and apply the same pixel positions to the
    other selected Image Texture nodes (normal, roughness, height...), each into a new image and
    node"""

    bl_idname = "texsynth.synthesize_maps"
    bl_label = "Synthesize Material Maps"
    bl_options = {"REGISTER", "UNDO"}

    # The run, the worker thread, progress and Esc are texsynth.synthesize's own (a registered
    # operator class cannot be subclassed); only what is prepared and made differs.
    draw = TEXSYNTH_OT_synthesize.draw
    execute = TEXSYNTH_OT_synthesize.execute
    invoke = TEXSYNTH_OT_synthesize.invoke
    modal = TEXSYNTH_OT_synthesize.modal
    cancel = TEXSYNTH_OT_synthesize.cancel
    _end_ui = TEXSYNTH_OT_synthesize._end_ui
    _fail = TEXSYNTH_OT_synthesize._fail

    def _prepare(self, context):
        """Check everything and copy every map out of Blender; raises ``ValueError``."""
        properties.fill_unset(self, context.scene.texsynth)
        src = source.find_source(context)
        method = properties.selected_method(self)
        if not method.positions:
            names = ", ".join(m.label for m in texsynth.methods() if m.positions)
            raise ValueError(f"{method.label} does not copy pixels, so other maps cannot follow "
                             f"it; choose {names}")
        image = bpy.data.images[src.image]
        exemplar, encoding = pixels.read_exemplar(image)
        followers = []
        for node in follower_nodes(context, src):
            values, enc = pixels.read_exemplar(node.image)
            if values.shape[:2] != exemplar.shape[:2]:
                raise ValueError(
                    f"Image '{node.image.name}' of node '{node.name}' is {values.shape[1]} x "
                    f"{values.shape[0]}, not {exemplar.shape[1]} x {exemplar.shape[0]} like "
                    f"'{image.name}': positions apply to maps of the same size")
            target = output.plan(self.output, self.output_dir, node.image.name, method.name,
                                 self.seed)
            followers.append((node.name, values, enc, target))
        target = output.plan(self.output, self.output_dir, image.name, method.name, self.seed)
        params = {p.name: getattr(self, name) for p, name in properties.param_properties(method)}
        job = PositionsJob(exemplar, self.width, self.height, method.name, self.seed, params)
        return job, (src, encoding, target, followers)

    def _finish(self, job, plan):
        if job.cancelled:
            self.report({"INFO"}, "Synthesis cancelled: nothing was created")
            return {"CANCELLED"}
        if job.error is not None:
            return self._fail(job.error)
        src, encoding, target, followers = plan
        result, positions = job.result
        made = [(src.node, result, encoding, target)]
        made += [(name, texsynth.apply_positions(positions, values), enc, tgt)
                 for name, values, enc, tgt in followers]
        tree, _ = source.source_node(src)
        first = None
        for name, values, enc, tgt in made:
            try:
                image = output.create_image(values, enc, tgt)
            except OSError as error:
                return self._fail(error)
            node = tree.nodes.get(name) if tree else None
            if node is not None:
                new = nodes.add_result_node(tree, node, image)
                first = first or new
        if first is not None:
            for node in tree.nodes:
                node.select = False
            first.select = True
            tree.nodes.active = first
        self.report({"INFO"}, f"Synthesized {len(made)} map(s) of {self.width} x {self.height}")
        return {"FINISHED"}


class TEXSYNTH_PT_maps(bpy.types.Panel):
    """Under the Texture Synthesis panel: which other maps will follow, and the button."""

    bl_label = "Other Maps"
    bl_space_type = "NODE_EDITOR"
    bl_region_type = "UI"
    bl_category = "TexSynth"
    bl_parent_id = "TEXSYNTH_PT_synthesize"

    @classmethod
    def poll(cls, context):
        return getattr(context.space_data, "tree_type", "") == "ShaderNodeTree"

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
        found = follower_nodes(context, src)
        if not found:
            layout.label(text="Select other Image Texture nodes to follow", icon="INFO")
        for node in found:
            layout.label(text=node.image.name, icon="IMAGE_DATA")
        layout.operator(TEXSYNTH_OT_synthesize_maps.bl_idname, icon="NODE_MATERIAL")


classes = (TEXSYNTH_OT_synthesize_maps, TEXSYNTH_PT_maps)


def register():
    TEXSYNTH_OT_synthesize_maps.__annotations__ = properties.settings_annotations({"SKIP_SAVE"})
    for cls in classes:
        bpy.utils.register_class(cls)


def unregister():
    for cls in reversed(classes):
        bpy.utils.unregister_class(cls)

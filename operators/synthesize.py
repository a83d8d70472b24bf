"""``texsynth.synthesize``: a new seamless image and Image Texture node from a source image.

The source is the active Image Texture node's image (the new node goes beside it and takes over
its links) or an image named by ``source_image`` (no node). Properties the caller did not set
are taken from the scene settings (``scene.texsynth``, the panel). The run, worker thread,
progress and Esc are :class:`job.JobOperator`'s; on error or cancel the file is unchanged.

No ``poll()``: a script may name the image, which needs no active node; the panel says what is
missing instead.
"""

import bpy

from .. import texsynth
from . import nodes, output, pixels, properties, source
from .job import JobOperator, Task


@properties.registry_settings()
class TEXSYNTH_OT_synthesize(JobOperator, bpy.types.Operator):
    """Synthesize a seamless texture of any size from the active Image Texture node's image into a
    new image and node"""

    bl_idname = "texsynth.synthesize"
    bl_label = "Synthesize Texture"
    bl_options = {"REGISTER", "UNDO"}

    # Method, size, seed, output and every method's parameters: added by registry_settings.
    source_image: bpy.props.StringProperty(
        name="Source Image",
        description="Name of the image to synthesize from; empty: the active Image Texture node's "
                    "image (a named image gets no new node)",
        options={"SKIP_SAVE"},
    )

    def draw(self, context):
        properties.draw_settings(self.layout, self, self)

    def prepare(self, context):
        """Check the input and copy the exemplar out of Blender; raises ``ValueError``."""
        properties.fill_unset(self, context.scene.texsynth)
        src = source.find_source(context, self.source_image)
        image = bpy.data.images[src.image]
        method = properties.selected_method(self)
        target = self.target(image.name, method.name)
        exemplar, encoding = pixels.read_exemplar(image)
        params = properties.param_values(self, method)
        texsynth.api.check(exemplar.shape, self.width, self.height, method=method.name,
                           seed=self.seed, **params)  # refused here, before the forecast
        predicted, _ = texsynth.budget.forecast(method.name, exemplar.shape, self.width,
                                                self.height, params, exemplar=exemplar)
        job = Task(texsynth.synthesize, exemplar, self.width, self.height, method=method.name,
                   seed=self.seed, predicted=predicted, **params)
        return job, (src, encoding, target)

    def make(self, result, plan):
        src, encoding, target = plan
        image = output.create_image(result, encoding, target)
        tree, node = source.source_node(src)
        if node is not None:
            nodes.add_result_node(tree, node, image)
        elif src.node:
            self.report({"WARNING"}, f"Node '{src.node}' is gone: image '{image.name}' was made "
                                     "without a node")
        height, width = result.shape[:2]  # image.size would load a saved file at once
        return f"Synthesized '{image.name}' ({width} x {height})"


classes = (TEXSYNTH_OT_synthesize,)
register, unregister = bpy.utils.register_classes_factory(classes)

"""Composite textures (Zalesny et al. 2002): segmentation and synthesis.

* ``texsynth.segment``: the unsupervised segmentation of the active Image Texture node's image
  as a new image, one flat palette colour per class, to inspect or to repaint and use as the
  label image.
* ``texsynth.synthesize_composite``: ``texsynth.composite.compose`` on the active Image
  Texture node's image into a new image and node (as ``texsynth.synthesize`` does), plus a new
  image of the output label map. The label source is automatic, or an image of the exemplar's
  size with one flat colour per class (``label_image``); the output layout is synthesized, or a
  painted image (``output_labels``) whose size is then the output's and whose colours are the
  label image's (or the segmentation palette's).

Unset operator properties come from the scene: the image choices from
``scene.texsynth.composite``, the composite method's parameters from
``scene.texsynth.params.composite``, size, seed and output from ``scene.texsynth`` (all declared
in ``properties.py``; the Composite panel is in ``panels.py``). Everything is checked before
anything is made; on error or cancel the file is unchanged.
"""

import bpy
import numpy as np

from .. import texsynth
from ..texsynth import composite, segmentation
from . import nodes, output, pixels, properties, source
from .job import JobOperator, Task

METHOD = "composite"


def _image(name: str, what: str):
    if name not in bpy.data.images:
        raise ValueError(f"No image named '{name}' for the {what}")
    return bpy.data.images[name]


def _chosen(operator_value: str, pointer) -> str:
    return operator_value or (pointer.name if pointer is not None else "")


def _labels_image(name: str, labels: np.ndarray):
    """A new packed image showing ``labels`` in the segmentation palette (sRGB bytes)."""
    rgb = segmentation.label_colours(labels)
    return output.create_image(rgb, pixels.Encoding(False, "sRGB", False),
                               output.Target("PACK", "", False, name))


class TEXSYNTH_OT_segment(bpy.types.Operator):
    """Segment the active Image Texture node's image into subtextures, without being told how
    many, and show the classes as a new image (flat colours, ready to repaint)"""

    bl_idname = "texsynth.segment"
    bl_label = "Show Segmentation"
    bl_options = {"REGISTER", "UNDO"}

    source_image: bpy.props.StringProperty(name="Source Image", options={"SKIP_SAVE"},
                                           description="Image to segment; empty: the active "
                                                       "Image Texture node's image")

    def execute(self, context):
        settings = context.scene.texsynth
        params = properties.method_settings(settings, texsynth.get_method(METHOD))
        try:
            src = source.find_source(context, self.source_image)
            image = bpy.data.images[src.image]
            exemplar, _ = pixels.read_exemplar(image)
            labels = segmentation.segment(exemplar, contrast=params.contrast,
                                          texture=params.texture_features, seed=settings.seed)
        except ValueError as error:
            self.report({"ERROR"}, str(error))
            return {"CANCELLED"}
        stem = f"{bpy.path.clean_name(image.name.rsplit('.', 1)[0])}_labels"
        made = _labels_image(stem, labels)
        context.scene.texsynth.composite.label_image = made
        self.report({"INFO"}, f"'{made.name}': {int(labels.max()) + 1} classes")
        return {"FINISHED"}


@properties.registry_settings(METHOD)
class TEXSYNTH_OT_synthesize_composite(JobOperator, bpy.types.Operator):
    """Synthesize a composite texture (label map + subtextures) from the active Image Texture
    node's image into a new image and node, and its label map into another new image"""

    bl_idname = "texsynth.synthesize_composite"
    bl_label = "Synthesize Composite"
    bl_options = {"REGISTER", "UNDO"}

    # Size, seed, output and the composite method's parameters: added by registry_settings.
    source_image: bpy.props.StringProperty(
        name="Source Image", options={"SKIP_SAVE"},
        description="Image to synthesize from; empty: the active Image Texture node's")
    label_image: bpy.props.StringProperty(
        name="Label Image", options={"SKIP_SAVE"},
        description="Name of the exemplar's label image; empty: the panel's choice, "
                    "else automatic segmentation")
    output_labels: bpy.props.StringProperty(
        name="Output Labels", options={"SKIP_SAVE"},
        description="Name of a painted output label map; empty: the panel's choice, "
                    "else synthesized")

    def draw(self, context):
        layout = self.layout
        layout.use_property_split = True
        for name in ("label_image", "output_labels"):
            layout.prop(self, name)
        properties.draw_params(layout, self, texsynth.get_method(METHOD))
        for name in ("width", "height", "seed", "output"):
            layout.prop(self, name)

    def prepare(self, context):
        """Check the input and copy the images out of Blender; raises ``ValueError``."""
        method = texsynth.get_method(METHOD)
        properties.fill_unset(self, context.scene.texsynth, method)
        chosen = context.scene.texsynth.composite
        src = source.find_source(context, self.source_image)
        image = bpy.data.images[src.image]
        exemplar, encoding = pixels.read_exemplar(image)
        labels = layout = None
        label_name = _chosen(self.label_image, chosen.label_image)
        if label_name:
            labels, _ = pixels.read_exemplar(_image(label_name, "label image"))
        layout_name = _chosen(self.output_labels, chosen.output_labels)
        width, height = self.width, self.height
        if layout_name:
            layout, _ = pixels.read_exemplar(_image(layout_name, "output label map"))
            height, width = layout.shape[:2]
        target = self.target(image.name, METHOD)
        params = properties.param_values(self, method)
        width, height = texsynth.validation.size(width, height)  # refused before the forecast
        predicted, _ = texsynth.budget.forecast(METHOD, exemplar.shape, width, height, params)
        job = Task(composite.compose, exemplar, width, height, labels=labels,
                   output_labels=layout, seed=self.seed, predicted=predicted, **params)
        return job, (src, encoding, target)

    def make(self, result, plan):
        src, encoding, target = plan
        image = output.create_image(result.image, encoding, target)
        layout = _labels_image(f"{target.stem}_labels", result.output_labels)
        tree, node = source.source_node(src)
        if node is not None:
            nodes.add_result_node(tree, node, image)
        classes = int(result.labels.max()) + 1
        height, width = result.image.shape[:2]  # image.size would load a saved file at once
        return (f"Synthesized '{image.name}' ({width} x {height}, {classes} "
                f"classes) and its label map '{layout.name}'")


classes = (TEXSYNTH_OT_segment, TEXSYNTH_OT_synthesize_composite)
register, unregister = bpy.utils.register_classes_factory(classes)

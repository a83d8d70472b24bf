"""Every TexSynth panel: what the user sees, in the sidebars' TexSynth tab.

Shader Editor (a material's node tree):

* **Texture Synthesis** (:class:`TEXSYNTH_PT_synthesize`): the source image, the settings of
  ``scene.texsynth`` and the ``texsynth.synthesize`` button, then the band and the
  ``texsynth.make_tileable`` button, each button under its predicted time and memory; under it
* **Material Maps** (:class:`TEXSYNTH_PT_material`): the maps that follow the active one and
  ``texsynth.synthesize_material`` (guided or column);
* **Photo to Material** (:class:`TEXSYNTH_PT_photo_material`): ``texsynth.photo_to_material``
  under a hint line and its predicted time and memory at the default 1024;
* **No Repetition** (:class:`TEXSYNTH_PT_norepeat`): ``texsynth.break_repetition`` with a
  hint on which mode suits the photo;
* **Composite** (:class:`TEXSYNTH_PT_composite`): label image, segmentation, painted layout
  and ``texsynth.synthesize_composite``.

Image Editor and 3D View: **Plane from Texture** (:class:`TEXSYNTH_PT_plane_image`,
:class:`TEXSYNTH_PT_plane_view3d`): estimate, align the camera, rectify, synthesize.

Panels only draw: the settings are declared in ``properties.py``, the work is the operators'.
"""

import functools

import bpy

from .. import texsynth
from . import composite, estimate, norepeat, output, photo_material, properties, source


class SidebarPanel:
    """Mixin of the panels of the TexSynth tab of the Shader Editor's sidebar."""

    bl_space_type = "NODE_EDITOR"
    bl_region_type = "UI"
    bl_category = "TexSynth"

    @classmethod
    def poll(cls, context):
        return getattr(context.space_data, "tree_type", "") == "ShaderNodeTree"


def _source_or_reason(layout, context):
    """The active Image Texture node's source, or None after a label saying what is missing."""
    try:
        return source.find_source(context)
    except ValueError as error:
        layout.label(text=str(error), icon="INFO")
        return None


def _source_shape(found):
    """(H, W, 3) of the source image, or None without one (the predictions' exemplar shape)."""
    image = bpy.data.images.get(found.image) if found is not None else None
    if image is None or min(image.size) == 0:
        return None
    return (image.size[1], image.size[0], 3)


def _draw_prediction(layout, settings, found) -> None:
    """Predicted time and memory of the chosen method and size (cost models only: nothing is
    run; the time includes Blender's reading and storing, ``output.predict_seconds``); a
    warning icon when over a budget. Needs the source's size: nothing without one."""
    shape = _source_shape(found)
    if shape is None:
        return
    method = properties.selected_method(settings)
    try:
        values = method.resolve(properties.param_values(
            properties.method_settings(settings, method), method))
        width, height = texsynth.validation.size(settings.width, settings.height)
        seconds = texsynth.budget.predict(method, shape, width, height, values) + \
            output.predict_seconds(shape[0] * shape[1], width * height, settings.output)
        need = method.memory(shape, width, height, values)
    except ValueError as error:
        layout.label(text=str(error), icon="ERROR")
        return
    _draw_cost(layout, seconds, need)


@functools.lru_cache(maxsize=16)
def _tileable_prediction(shape, band):
    """``texsynth.tileable.predict`` on the idle machine, kept per (photo size, band): the panel
    redraws often; the load is applied at each draw (:func:`_draw_tileable_prediction`)."""
    seconds, need = texsynth.tileable.predict(shape, band)
    return seconds / texsynth.budget.contention(), need


def _draw_tileable_prediction(layout, settings, found) -> None:
    """Make Tileable's predicted time and memory for the source's size and the band, as
    :func:`_draw_prediction` shows the synthesis' (Blender's reading and storing included)."""
    shape = _source_shape(found)
    if shape is None:
        return
    try:
        seconds, need = _tileable_prediction(shape, settings.band or None)
        seconds *= texsynth.budget.contention()
    except ValueError as error:
        layout.label(text=str(error), icon="ERROR")
        return
    pixels = shape[0] * shape[1]
    _draw_cost(layout, seconds + output.predict_seconds(pixels, pixels, settings.output), need)


def _draw_cost(layout, seconds: float, need: float) -> None:
    """'About 12 s, 0.5 GiB', with a warning icon when over the time or memory budget."""
    try:
        over = seconds > texsynth.budget.time_budget() or need > texsynth.memory_budget()
    except ValueError as error:  # a budget set to something that is not a number
        layout.label(text=str(error), icon="ERROR")
        return
    layout.label(text=f"About {texsynth.budget.describe(seconds)}, {need / 2**30:.2g} GiB",
                 icon="ERROR" if over else "TIME")


class TEXSYNTH_PT_synthesize(SidebarPanel, bpy.types.Panel):
    """The source image, the synthesis settings and the button."""

    bl_label = "Texture Synthesis"

    def draw(self, context):
        layout = self.layout
        found = _source_or_reason(layout, context)
        if found is not None:
            layout.label(text=found.image, icon="IMAGE_DATA")
        properties.draw_settings(layout, context.scene.texsynth)
        _draw_prediction(layout, context.scene.texsynth, found)
        layout.operator("texsynth.synthesize", icon="TEXTURE")
        layout.separator()
        layout.prop(context.scene.texsynth, "band")
        _draw_tileable_prediction(layout, context.scene.texsynth, found)
        layout.operator("texsynth.make_tileable", icon="MOD_ARRAY")


class TEXSYNTH_PT_material(SidebarPanel, bpy.types.Panel):
    """Under the Texture Synthesis panel: the maps that will follow the active one, and the
    buttons of the two modes."""

    bl_label = "Material Maps"
    bl_parent_id = "TEXSYNTH_PT_synthesize"

    def draw(self, context):
        layout = self.layout
        method = properties.selected_method(context.scene.texsynth)
        if not method.positions:
            layout.label(text="Choose a method that copies pixels", icon="INFO")
            return
        src = _source_or_reason(layout, context)
        if src is None:
            return
        layout.label(text=f"{src.image} (support)", icon="IMAGE_DATA")
        followers = source.follower_nodes(context, src)
        if not followers:
            layout.label(text="Select other Image Texture nodes to follow", icon="INFO")
        for node in followers:
            layout.label(text=node.image.name, icon="IMAGE_DATA")
        row = layout.row(align=True)
        row.operator("texsynth.synthesize_material", text="Guided", icon="MATERIAL").mode = \
            "GUIDED"
        row.operator("texsynth.synthesize_material", text="Column", icon="NODE_MATERIAL").mode = \
            "COLUMN"


@functools.lru_cache(maxsize=16)
def _material_prediction(shape):
    """``texsynth.material.pipeline.predict`` at the operator's default size on the idle
    machine, kept per photo size (the load is applied at each draw)."""
    seconds, need = texsynth.material.pipeline.predict(shape, size=(1024, 1024))
    return seconds / texsynth.budget.contention(), need


class TEXSYNTH_PT_photo_material(SidebarPanel, bpy.types.Panel):
    """Under the Texture Synthesis panel: the whole material from the photo, in one button."""

    bl_label = "Photo to Material"
    bl_parent_id = "TEXSYNTH_PT_synthesize"

    def draw(self, context):
        layout = self.layout
        layout.label(text=photo_material.HINT, icon="INFO")
        found = _source_or_reason(layout, context)
        shape = _source_shape(found)
        if shape is not None:
            seconds, need = _material_prediction(shape)
            _draw_cost(layout, seconds * texsynth.budget.contention(), need)
        layout.operator("texsynth.photo_to_material", icon="MATERIAL")


class TEXSYNTH_PT_norepeat(SidebarPanel, bpy.types.Panel):
    """Under the Texture Synthesis panel: ``texsynth.break_repetition`` and which mode suits
    which photo."""

    bl_label = "No Repetition"
    bl_parent_id = "TEXSYNTH_PT_synthesize"

    def draw(self, context):
        layout = self.layout
        if _source_or_reason(layout, context) is None:
            return
        layout.label(text=norepeat.HINT, icon="INFO")
        row = layout.row(align=True)
        for mode, label, _ in (module.ITEM for module in norepeat.MODES.values()):
            row.operator("texsynth.break_repetition", text=label, icon="MOD_ARRAY").mode = mode


class TEXSYNTH_PT_composite(SidebarPanel, bpy.types.Panel):
    """Under the Texture Synthesis panel: label source, segmentation, layout and the button."""

    bl_label = "Composite"
    bl_parent_id = "TEXSYNTH_PT_synthesize"
    bl_options = {"DEFAULT_CLOSED"}

    def draw(self, context):
        layout = self.layout
        layout.use_property_split = True
        settings = context.scene.texsynth
        layout.template_ID(settings.composite, "label_image", open="image.open")
        layout.operator("texsynth.segment", icon="IMAGE_RGB")
        layout.template_ID(settings.composite, "output_labels", open="image.open")
        method = texsynth.get_method(composite.METHOD)
        properties.draw_params(layout, properties.method_settings(settings, method), method)
        layout.operator("texsynth.synthesize_composite", icon="TEXTURE")


class PlanePanel:
    """Mixin of the two Plane from Texture panels; ``in_image_editor``: the photo is the
    editor's image, else the panel's ``photo``."""

    bl_label = "Plane from Texture"
    bl_region_type = "UI"
    bl_category = "TexSynth"
    in_image_editor = False

    def draw(self, context):
        settings = context.scene.texsynth.plane
        layout = self.layout
        layout.use_property_split = True
        layout.use_property_decorate = False
        if not self.in_image_editor:
            layout.prop(settings, "photo")
        layout.prop(settings, "method")
        row = layout.row()
        row.enabled = settings.method == "AUTO"
        row.prop(settings, "use_camera_focal")
        layout.operator("texsynth.estimate_plane", icon="VIEW_PERSPECTIVE")
        # The user's own reading where the estimate cannot be trusted (issue 42).
        column = layout.column(align=True)
        if self.in_image_editor:
            column.operator("texsynth.place_corners", icon="MOD_LATTICE",
                            text="Place Rectangle Corners")
        column.prop(settings, "corners", text="Corners")
        column.operator("texsynth.plane_from_rectangle", icon="SNAP_FACE")
        if not settings.has_estimate:
            return
        box = layout.box()
        box.label(text=("Rectangle on '{}'" if settings.from_rectangle else "Estimate of '{}'")
                  .format(settings.image), icon="IMAGE_DATA")
        box.prop(settings, "slant")
        box.prop(settings, "tilt")
        if settings.tilt_ambiguous:
            box.label(text="Tilt may be off by 180°", icon="INFO")
        box.prop(settings, "focal_px")
        box.label(text="Focal length from: " + dict((k, n) for k, n, _ in
                                                    properties.FOCAL_SOURCES)[settings.focal_source],
                  icon="CAMERA_DATA")
        box.prop(settings, "confidence")
        verdict = estimate.judged(settings)
        guess = verdict.guess
        if guess:  # say plainly that it is a guess, and why (issue 27)
            column = box.column(align=True)
            column.label(text="A guess, not a measurement:", icon="ERROR")
            for reason in verdict.reasons:
                column.label(text=reason)
        elif verdict.lens_prior:  # focal length unknown: frontal for any 13-200 mm lens
            box.label(text="Frontal under a lens prior (13-200 mm eq.)", icon="CHECKMARK")
        elif not verdict.slant_measured:
            box.label(text="No measurable slant: a frontal photo", icon="CHECKMARK")
        layout.prop(settings, "add_background")
        row = layout.row(align=True)
        row.operator("texsynth.align_camera", icon="CAMERA_DATA")
        if guess:
            row.operator("texsynth.align_camera", text="As Frontal").frontal = True
        column = layout.column(align=True)
        column.label(text="Rectify, then synthesize:")
        row = column.row(align=True)
        row.operator("texsynth.rectify", icon="IMAGE_PLANE")
        if guess:
            row.operator("texsynth.rectify", text="As Frontal").frontal = True
        if settings.rectified in bpy.data.images:
            op = column.operator("texsynth.synthesize", icon="TEXTURE",
                                 text=f"Synthesize from '{settings.rectified}'")
            op.source_image = settings.rectified


class TEXSYNTH_PT_plane_image(PlanePanel, bpy.types.Panel):
    bl_space_type = "IMAGE_EDITOR"
    in_image_editor = True


class TEXSYNTH_PT_plane_view3d(PlanePanel, bpy.types.Panel):
    bl_space_type = "VIEW_3D"


classes = (TEXSYNTH_PT_synthesize, TEXSYNTH_PT_material, TEXSYNTH_PT_photo_material,
           TEXSYNTH_PT_norepeat,
           TEXSYNTH_PT_composite,
           TEXSYNTH_PT_plane_image, TEXSYNTH_PT_plane_view3d)
register, unregister = bpy.utils.register_classes_factory(classes)

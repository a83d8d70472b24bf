"""Every setting TexSynth stores, in one place: the property groups behind ``scene.texsynth``
and the settings the operators take.

``scene.texsynth`` (:class:`TEXSYNTH_PG_settings`, attached by :func:`register` and nowhere
else) holds:

* ``method`` (enum, the registry's names upper-cased), ``width``, ``height``, ``seed``,
  ``output``, ``output_dir``: the panel's synthesis settings; ``band``: Make Tileable's (seed
  and output are shared);
* ``params.<method>.<param>``: one group per registry method, made from its ``Param`` specs
  with its own defaults and ranges, so methods sharing a parameter name (``levels``,
  ``threshold``) keep their own values;
* ``composite``: the composite panel's label image and painted layout;
* ``plane``: the plane estimate's photo, settings and last result.

:func:`param_property` is the one translation of a registry ``Param`` into a bpy property,
used for the scene's groups and, through :func:`registry_settings`, for the operators. An
operator decorated with :func:`registry_settings` carries the settings flat, one property per
parameter name (``bpy.ops.texsynth.synthesize(method="COOCCURRENCE", levels=16)``); a name
shared by several methods is one property whose type they must agree on (else the import fails,
naming them), whose enum items are all their choices and whose soft range covers all their
ranges. A property the caller leaves unset is taken from the scene (:func:`fill_unset`), so
an operator's own defaults are never used for a run.

Numbers get soft limits only (the sliders' range): a value outside the range, typed or passed
from a script, reaches the core and comes back as an error report rather than being clamped
without a word.
"""

import dataclasses
import inspect
import math

import bpy

from .. import texsynth

# Blender 4.5+ warns about "//" paths in properties without this flag; older versions lack it.
BLEND_RELATIVE = {"PATH_SUPPORTS_BLEND_RELATIVE"} if bpy.app.version >= (4, 5, 0) else set()

OUTPUT_ITEMS = (
    ("PACK", "Pack", "Keep the new image inside the .blend file"),
    ("EXR", "OpenEXR", "Save a 32-bit float OpenEXR file holding linear values"),
    ("PNG", "PNG", "Save an 8-bit PNG file"),
)
#: The settings every synthesis has besides the method's parameters.
COMMON = ("method", "width", "height", "seed", "output", "output_dir")
#: The plane estimate's methods offered to users (the core's "moments" baseline is for
#: benchmarks only).
FOCAL_SOURCES = (
    ("EXIF", "EXIF", "Read from the photo file's EXIF (the camera wrote it)"),
    ("CAMERA", "Scene Camera", "The scene camera's lens and sensor"),
    ("ESTIMATED", "Estimated", "Estimated from the photo's perspective"),
    ("NONE", "None (Orthographic)", "No perspective: the estimate is orthographic"),
)
PLANE_METHOD_ITEMS = (
    ("AUTO", "Auto", "Isotropy and homogeneity under perspective: the receding direction and, "
                     "when the focal length is unknown, an estimate of it"),
    ("ISOTROPY", "Isotropy", "Orthographic isotropy search: tilt known only up to 180 degrees"),
)


# --- registry parameters as bpy properties -------------------------------------------------


def param_property(p: texsynth.Param, options: set):
    """The bpy property holding parameter ``p``: its type, label, default and soft range."""
    common = {"name": p.label, "description": p.description, "default": p.default,
              "options": options}
    if p.type is bool:
        return bpy.props.BoolProperty(**common)
    if p.type is str:
        items = [(c, c.replace("_", " ").capitalize(), "") for c in p.choices]
        return bpy.props.EnumProperty(items=items, **common)
    limits = {k: v for k, v in (("soft_min", p.min), ("soft_max", p.max)) if v is not None}
    if p.type is int:
        return bpy.props.IntProperty(**common, **limits)
    return bpy.props.FloatProperty(**common, **limits)


def shared_params(methods) -> dict[str, texsynth.Param]:
    """One ``Param`` per parameter name of ``methods``, standing for every method declaring it.

    Label, description and default are the first declaring method's; choices are all of theirs
    and the range covers all of theirs. Raises ``ValueError`` when the methods disagree on the
    type. ``methods`` may hold one method only (the composite operator).
    """
    merged: dict[str, texsynth.Param] = {}
    owners: dict[str, str] = {}
    for m in methods:
        for p in m.params:
            first = merged.setdefault(p.name, p)
            owners.setdefault(p.name, m.name)
            if p.type is not first.type:
                raise ValueError(
                    f"parameter '{p.name}' is {first.type.__name__} in method "
                    f"'{owners[p.name]}' but {p.type.__name__} in '{m.name}': one operator "
                    "property cannot hold both; rename one of them")
            low = None if None in (first.min, p.min) else min(first.min, p.min)
            high = None if None in (first.max, p.max) else max(first.max, p.max)
            choices = first.choices + tuple(c for c in p.choices if c not in first.choices)
            merged[p.name] = dataclasses.replace(first, min=low, max=high, choices=choices)
    return merged


def _common_properties(options: set, methods) -> dict:
    size = {"default": 1024, "soft_min": 1, "soft_max": texsynth.MAX_SIDE, "subtype": "PIXEL",
            "options": options}
    return {
        "method": bpy.props.EnumProperty(
            name="Method",
            description="Synthesis algorithm",
            items=[(m.name.upper(), m.label, m.description) for m in methods],
            options=options,
        ),
        "width": bpy.props.IntProperty(name="Width", description="Output width", **size),
        "height": bpy.props.IntProperty(name="Height", description="Output height", **size),
        "seed": bpy.props.IntProperty(
            name="Seed", description="Same image, settings and seed give the same texture",
            default=0, soft_min=0, options=options,
        ),
        "output": bpy.props.EnumProperty(
            name="Output", description="Where the new image is stored", items=OUTPUT_ITEMS,
            options=options,
        ),
        "output_dir": bpy.props.StringProperty(
            name="Directory",
            description="Folder for saved files ('//' is the .blend file's folder)",
            default="//", subtype="DIR_PATH", options=options | BLEND_RELATIVE,
        ),
    }


def band_property(options: set):
    """Make Tileable's band width (the scene's and the operator's)."""
    return bpy.props.IntProperty(
        name="Band", default=0, min=0, soft_max=512, subtype="PIXEL", options=options,
        description="Width in pixels of the band re-synthesized across the photo's edges; "
                    "0: automatic (an eighth of the shorter side). At most half of the photo "
                    "may change")


def operator_properties(methods=None) -> dict:
    """An operator's settings: the common ones and every parameter of ``methods``, flat.

    ``methods`` defaults to the whole registry; given, the operator runs those methods only
    and has no ``method`` property when it is one. Every property is ``SKIP_SAVE`` so that one
    its caller leaves unset comes from the scene settings, not from the last run.
    """
    fixed = methods is not None and len(methods) == 1
    methods = texsynth.methods() if methods is None else methods
    options = {"SKIP_SAVE"}
    annotations = _common_properties(options, methods)
    if fixed:
        del annotations["method"]
    for name, p in shared_params(methods).items():
        annotations[name] = param_property(p, options)
    return annotations


def registry_settings(*method_names: str):
    """Class decorator: add :func:`operator_properties` to an operator's own properties.

    No names: every registry method, chosen by a ``method`` property; names: those methods
    only, and no ``method`` property when there is one.
    """
    methods = tuple(texsynth.get_method(name) for name in method_names) or None

    def decorate(cls):
        cls.__annotations__ = {**inspect.get_annotations(cls), **operator_properties(methods)}
        return cls

    return decorate


def photo_material_settings(cls):
    """Class decorator: the settings of ``texsynth.photo_to_material`` (every one
    ``SKIP_SAVE``: a run left unset takes the defaults, not the last run's)."""
    options = {"SKIP_SAVE"}
    steps = [(s.upper(), s.title(), text) for s, text in zip(texsynth.material.pipeline.STEPS, (
        "Rectify by the plane estimate (or the rectangle's corners)",
        "Re-synthesize the masked pixels from the rest of the photo",
        "Take out the light: a window's ramp, vignetting, a soft shadow",
        "Make the colour tile (its own size), or synthesize it to Size",
        "Derive normal, height, roughness and ambient occlusion from the colour"), strict=True)]
    cls.__annotations__ = {**inspect.get_annotations(cls), **{
        "filepath": bpy.props.StringProperty(
            name="Photo File", subtype="FILE_PATH", default="", options=options,
            description="A photo file to make the material from; empty: the active Image "
                        "Texture node's image"),
        "size": bpy.props.IntProperty(
            name="Size", default=1024, min=0, soft_max=4096, subtype="PIXEL", options=options,
            description="Side of the material's maps in pixels; 0: the rectified photo made to "
                        "tile at its own size"),
        "steps": bpy.props.EnumProperty(
            name="Steps", items=steps, options=options | {"ENUM_FLAG"},
            default={s[0] for s in steps}, description="The steps to run (each can be left out)"),
        "mask": bpy.props.StringProperty(
            name="Mask", default="", options=options,
            description="An image of the photo's size, white where the photo is to be healed "
                        "(a sign, a stain); empty: only a varying alpha of the photo is healed"),
        "use_corners": bpy.props.BoolProperty(
            name="Use Rectangle Corners", default=False, options=options,
            description="Rectify by the rectangle placed with Place Corners (Plane from "
                        "Texture), not by the plane estimate"),
        "seed": bpy.props.IntProperty(
            name="Seed", min=0, default=0, options=options,
            description="Same photo, settings and seed give the same material"),
        "output": bpy.props.EnumProperty(name="Output", items=OUTPUT_ITEMS, default="PACK",
                                         options=options),
        "output_dir": bpy.props.StringProperty(
            name="Output Directory", subtype="DIR_PATH", default="//",
            options=options | BLEND_RELATIVE),
    }}
    return cls


# --- reading the settings ------------------------------------------------------------------


def selected_method(settings) -> texsynth.Method:
    """The registry method chosen by ``settings.method`` (the scene's or an operator's)."""
    return texsynth.get_method(settings.method.lower())


def method_settings(settings, method: texsynth.Method):
    """The scene's property group of ``method``'s parameters: ``settings.params.<method>``."""
    return getattr(settings.params, method.name)


def param_values(holder, method: texsynth.Method) -> dict:
    """``method``'s parameters as the core takes them, read from ``holder`` (an operator, or
    the scene's group of that method)."""
    return {p.name: getattr(holder, p.name) for p in method.params}


def fill_unset(operator, settings, method: texsynth.Method | None = None) -> None:
    """Copy the scene settings into the operator properties its caller did not set.

    The parameters come from the scene's group of ``method``, by default the operator's
    (already filled) method.
    """
    props = operator.properties
    for name in COMMON:
        if name in props.bl_rna.properties and not props.is_property_set(name):
            setattr(operator, name, getattr(settings, name))
    method = method or selected_method(operator)
    values = method_settings(settings, method)
    for p in method.params:
        if not props.is_property_set(p.name):
            setattr(operator, p.name, getattr(values, p.name))


# --- drawing the settings (the sidebar and the operators' redo panels) ---------------------


def draw_params(layout, holder, method: texsynth.Method) -> None:
    for p in method.params:
        layout.prop(holder, p.name)


def draw_settings(layout, settings, params=None) -> None:
    """Method, its parameters, size, seed and output: for the panel and the redo panel.

    ``params`` holds the parameters' values: the scene's group of the chosen method by default;
    an operator passes itself.
    """
    layout.use_property_split = True
    layout.use_property_decorate = False
    layout.prop(settings, "method")
    method = selected_method(settings)
    draw_params(layout, method_settings(settings, method) if params is None else params, method)
    column = layout.column(align=True)
    column.prop(settings, "width")
    column.prop(settings, "height")
    layout.prop(settings, "seed")
    layout.prop(settings, "output")
    if settings.output != "PACK":
        layout.prop(settings, "output_dir")


# --- the scene's property groups -----------------------------------------------------------


def _method_group(method: texsynth.Method) -> type:
    """A property group class holding ``method``'s parameters with its own defaults."""
    return type(f"TEXSYNTH_PG_{method.name}", (bpy.types.PropertyGroup,), {
        "__doc__": f"{method.label} parameters, per scene",
        "__annotations__": {p.name: param_property(p, set()) for p in method.params},
    })


_METHODS = texsynth.methods()
_METHOD_GROUPS = tuple(_method_group(m) for m in _METHODS)

TEXSYNTH_PG_params = type("TEXSYNTH_PG_params", (bpy.types.PropertyGroup,), {
    "__doc__": "One group per method: ``scene.texsynth.params.<method>``",
    "__annotations__": {m.name: bpy.props.PointerProperty(type=group)
                        for m, group in zip(_METHODS, _METHOD_GROUPS, strict=True)},
})


class TEXSYNTH_PG_composite(bpy.types.PropertyGroup):
    """The composite panel's image choices: ``scene.texsynth.composite``."""

    label_image: bpy.props.PointerProperty(
        type=bpy.types.Image, name="Labels",
        description="Label image of the exemplar (same size, one flat colour per class); "
                    "empty: automatic segmentation")
    output_labels: bpy.props.PointerProperty(
        type=bpy.types.Image, name="Layout",
        description="Painted output label map in the label image's colours (its size is the "
                    "output's); empty: synthesized from the label texture")


class TEXSYNTH_PG_plane(bpy.types.PropertyGroup):
    """The last plane estimate and the estimate panels' settings: ``scene.texsynth.plane``."""

    photo: bpy.props.PointerProperty(
        name="Photo", type=bpy.types.Image,
        description="Photo of a textured plane (the 3D View panel's source; the Image Editor "
                    "uses the image it shows)")
    method: bpy.props.EnumProperty(name="Method", items=PLANE_METHOD_ITEMS, default="AUTO",
                                   description="How the orientation is estimated")
    use_camera_focal: bpy.props.BoolProperty(
        name="Taken with Scene Camera",
        description="The photo was taken with the scene camera's lens and sensor: use its focal "
                    "length instead of the photo file's EXIF or an estimate")
    add_background: bpy.props.BoolProperty(
        name="Photo as Background", default=True,
        description="Show the photo as the camera's background image when aligning")
    has_estimate: bpy.props.BoolProperty(name="Has Estimate", options={"HIDDEN"})
    image: bpy.props.StringProperty(name="Estimated Image",
                                    description="Name of the image the estimate was made on")
    image_width: bpy.props.IntProperty(name="Width", subtype="PIXEL", options={"HIDDEN"})
    image_height: bpy.props.IntProperty(name="Height", subtype="PIXEL", options={"HIDDEN"})
    slant: bpy.props.FloatProperty(
        name="Slant", subtype="ANGLE", min=0.0, max=math.radians(89.9),
        description="Angle between the plane's normal and the camera's optical axis")
    tilt: bpy.props.FloatProperty(
        name="Tilt", subtype="ANGLE",
        description="Image direction in which the plane recedes, counter-clockwise from right")
    focal_px: bpy.props.FloatProperty(
        name="Focal Length", subtype="PIXEL", min=0.0,
        description="Focal length in pixels of the photo; 0: orthographic (unknown)")
    focal_estimated: bpy.props.BoolProperty(name="Focal Estimated", options={"HIDDEN"})
    focal_source: bpy.props.EnumProperty(
        name="Focal Length From", items=FOCAL_SOURCES, default="NONE",
        description="Where the estimate's focal length came from")
    tilt_ambiguous: bpy.props.BoolProperty(
        name="Tilt Ambiguous",
        description="The receding direction is not determined: tilt + 180 degrees fits as well")
    confidence: bpy.props.FloatProperty(name="Confidence", subtype="FACTOR", min=0.0, max=1.0,
                                        description="How far the estimate can be trusted")
    uncertainty: bpy.props.FloatProperty(
        name="Uncertainty", subtype="ANGLE", min=0.0,
        description="One-sigma uncertainty of the plane normal")
    slant_uncertainty: bpy.props.FloatProperty(
        name="Slant Uncertainty", subtype="ANGLE", min=0.0,
        description="One-sigma uncertainty of the slant")
    tilt_uncertainty: bpy.props.FloatProperty(
        name="Tilt Uncertainty", subtype="ANGLE", min=0.0,
        description="One-sigma uncertainty of the tilt")
    anisotropy: bpy.props.FloatProperty(
        name="Anisotropy", min=0.0,
        description="The texture's own directionality left after the fit (beyond 1 its grain "
                    "reads as slant)")
    line_families: bpy.props.IntProperty(
        name="Line Families", min=0, max=2,
        description="Families of straight lines (joints, edges) the estimate used")
    lines_found: bpy.props.IntProperty(
        name="Line Families Found", min=0, max=2,
        description="Families of straight lines the photo showed, used or not")
    lens_prior: bpy.props.BoolProperty(
        name="Under a Lens Prior",
        description="Focal length unknown: the lines stayed parallel under every 13-200 mm lens "
                    "(35 mm equivalent), so the photo reads as frontal under that prior")
    rectified: bpy.props.StringProperty(name="Rectified Image",
                                        description="Name of the last rectified image")
    corners: bpy.props.FloatVectorProperty(
        name="Rectangle Corners", size=8, subtype="NONE",
        description="x1, y1, ..., x4, y4: four corners of a rectangle on the plane, in order "
                    "around it, in pixels of the photo (x right, y down from its top-left "
                    "pixel); Plane from Rectangle takes the plane from them")
    from_rectangle: bpy.props.BoolProperty(
        name="From Rectangle", options={"HIDDEN"},
        description="The stored plane came from the rectangle's corners, not the estimate")


TEXSYNTH_PG_settings = type("TEXSYNTH_PG_settings", (bpy.types.PropertyGroup,), {
    "__doc__": "Everything TexSynth keeps per scene: ``scene.texsynth``",
    "__annotations__": {
        **_common_properties(set(), _METHODS),
        "band": band_property(set()),
        "params": bpy.props.PointerProperty(type=TEXSYNTH_PG_params),
        "composite": bpy.props.PointerProperty(type=TEXSYNTH_PG_composite),
        "plane": bpy.props.PointerProperty(type=TEXSYNTH_PG_plane),
    },
})

classes = (*_METHOD_GROUPS, TEXSYNTH_PG_params, TEXSYNTH_PG_composite, TEXSYNTH_PG_plane,
           TEXSYNTH_PG_settings)
_register_classes, _unregister_classes = bpy.utils.register_classes_factory(classes)


def register():
    _register_classes()
    bpy.types.Scene.texsynth = bpy.props.PointerProperty(type=TEXSYNTH_PG_settings)


def unregister():
    del bpy.types.Scene.texsynth
    _unregister_classes()

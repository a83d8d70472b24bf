"""Settings generated from the texsynth registry: the scene's ``scene.texsynth`` and the operators.

The scene settings (the panel) hold ``method`` (enum, the registry's names upper-cased),
``width``, ``height``, ``seed``, ``output``, ``output_dir`` and ``params``: one property group
per method, ``scene.texsynth.params.<method>.<param>``, made from that method's ``Param`` specs
with its own default and range. Methods that share a parameter name (``levels``, ``threshold``)
keep their own values, and switching method shows the values last used with it.

An operator carries the same settings flat, one property per parameter name
(``bpy.ops.texsynth.synthesize(method="COOCCURRENCE", levels=16)``): a name shared by several
methods is one property whose type they must agree on (else registration fails, naming them),
whose enum items are all their choices and whose soft range covers all their ranges. A property
the caller leaves unset is taken from the scene's group of the chosen method
(:func:`fill_unset`), so the operator's own defaults are never used for a run.

Numbers get soft limits only (the sliders' range): a value outside the range, typed or passed
from a script, reaches ``texsynth.synthesize`` and comes back as an error report rather than
being clamped without a word.
"""

import dataclasses

import bpy

from .. import texsynth

# Blender 4.5+ warns about "//" paths in properties without this flag; older versions lack it.
_BLEND_RELATIVE = {"PATH_SUPPORTS_BLEND_RELATIVE"} if bpy.app.version >= (4, 5, 0) else set()

OUTPUT_ITEMS = (
    ("PACK", "Pack", "Keep the new image inside the .blend file"),
    ("EXR", "OpenEXR", "Save a 32-bit float OpenEXR file holding linear values"),
    ("PNG", "PNG", "Save an 8-bit PNG file"),
)
#: The settings every synthesis has besides the method's parameters.
COMMON = ("method", "width", "height", "seed", "output", "output_dir")


def _param_property(p: texsynth.Param, options: set):
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


def _common_annotations(options: set, methods) -> dict:
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
            default="//", subtype="DIR_PATH", options=options | _BLEND_RELATIVE,
        ),
    }


def operator_annotations(methods=None) -> dict:
    """An operator's settings: the common ones and every parameter of ``methods``, flat.

    ``methods`` defaults to the whole registry; given, the operator runs those methods only
    and has no ``method`` property when it is one. Every property is ``SKIP_SAVE`` so that one
    its caller leaves unset comes from the scene settings, not from the last run.
    """
    fixed = methods is not None and len(methods) == 1
    methods = texsynth.methods() if methods is None else methods
    options = {"SKIP_SAVE"}
    annotations = _common_annotations(options, methods)
    if fixed:
        del annotations["method"]
    for name, p in shared_params(methods).items():
        annotations[name] = _param_property(p, options)
    return annotations


def method_settings(settings, method: texsynth.Method):
    """The scene's property group of ``method``'s parameters: ``settings.params.<method>``."""
    return getattr(settings.params, method.name)


def param_values(holder, method: texsynth.Method) -> dict:
    """``method``'s parameters as ``texsynth.synthesize`` takes them, read from ``holder`` (an
    operator, or the scene's group of that method)."""
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


def selected_method(settings) -> texsynth.Method:
    return texsynth.get_method(settings.method.lower())


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


def _method_group(method: texsynth.Method) -> type:
    """A property group class holding ``method``'s parameters with its own defaults."""
    return type(f"TEXSYNTH_PG_{method.name}", (bpy.types.PropertyGroup,), {
        "__doc__": f"{method.label} parameters, per scene",
        "__annotations__": {p.name: _param_property(p, set()) for p in method.params},
    })


class TEXSYNTH_PG_params(bpy.types.PropertyGroup):
    """One group per method (added by register()): ``scene.texsynth.params.<method>``."""


class TEXSYNTH_PG_settings(bpy.types.PropertyGroup):
    """The panel's settings, stored per scene; the operators fall back on them."""


_groups: list[type] = []


def register():
    methods = texsynth.methods()
    _groups[:] = [_method_group(m) for m in methods]
    TEXSYNTH_PG_params.__annotations__ = {
        m.name: bpy.props.PointerProperty(type=group) for m, group in zip(methods, _groups,
                                                                          strict=True)}
    TEXSYNTH_PG_settings.__annotations__ = {
        **_common_annotations(set(), methods),
        "params": bpy.props.PointerProperty(type=TEXSYNTH_PG_params),
    }
    for cls in (*_groups, TEXSYNTH_PG_params, TEXSYNTH_PG_settings):
        bpy.utils.register_class(cls)
    bpy.types.Scene.texsynth = bpy.props.PointerProperty(type=TEXSYNTH_PG_settings)


def unregister():
    del bpy.types.Scene.texsynth
    for cls in reversed((*_groups, TEXSYNTH_PG_params, TEXSYNTH_PG_settings)):
        bpy.utils.unregister_class(cls)
    _groups.clear()

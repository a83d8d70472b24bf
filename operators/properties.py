"""Settings generated from the texsynth registry: the scene's ``scene.texsynth`` and the operator.

Both carry the same properties, made by :func:`settings_annotations`: ``method`` (enum, the
registry's names upper-cased), ``width``, ``height``, ``seed``, ``output``, ``output_dir`` and
every method's parameters. A parameter's property has the parameter's own name (``scales``)
unless another method declares a parameter of that name with a different type, default, range
or choices; then each is namespaced as ``method__param`` (``heeger_bergen__scales``). A shared
property takes its label and description from the first method that declares it.

Numbers get soft limits only (the sliders' range): a value outside the range, typed or passed
from a script, reaches ``texsynth.synthesize`` and comes back as an error report rather than
being clamped without a word.
"""

import bpy

from .. import texsynth

# Blender 4.5+ warns about "//" paths in properties without this flag; older versions lack it.
_BLEND_RELATIVE = {"PATH_SUPPORTS_BLEND_RELATIVE"} if bpy.app.version >= (4, 5, 0) else set()

OUTPUT_ITEMS = (
    ("PACK", "Pack", "Keep the new image inside the .blend file"),
    ("EXR", "OpenEXR", "Save a 32-bit float OpenEXR file holding linear values"),
    ("PNG", "PNG", "Save an 8-bit PNG file"),
)


def param_properties(method: texsynth.Method) -> list[tuple[texsynth.Param, str]]:
    """Each parameter of ``method`` with the name of the property that holds it."""
    specs: dict[str, set] = {}
    for m in texsynth.methods():
        for p in m.params:
            specs.setdefault(p.name, set()).add((p.type, p.default, p.min, p.max, p.choices))
    return [(p, p.name if len(specs[p.name]) == 1 else f"{method.name}__{p.name}")
            for p in method.params]


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


def settings_annotations(options: set) -> dict:
    """Property definitions shared by the scene settings and the operator.

    ``options`` is passed to every property: the operator's are ``{'SKIP_SAVE'}`` so that a
    property its caller leaves unset comes from the scene settings, not from the last run.
    """
    methods = texsynth.methods()
    size = {"default": 1024, "soft_min": 1, "soft_max": texsynth.MAX_SIDE, "subtype": "PIXEL",
            "options": options}
    annotations = {
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
    for m in methods:
        for p, name in param_properties(m):
            annotations.setdefault(name, _param_property(p, options))
    return annotations


def fill_unset(operator, settings) -> None:
    """Copy the scene settings into the operator properties its caller did not set."""
    for name in TEXSYNTH_PG_settings.__annotations__:
        if not operator.properties.is_property_set(name):
            setattr(operator, name, getattr(settings, name))


def selected_method(settings) -> texsynth.Method:
    return texsynth.get_method(settings.method.lower())


def draw_settings(layout, settings) -> None:
    """Method, its parameters, size, seed and output: for the panel and the redo panel."""
    layout.use_property_split = True
    layout.use_property_decorate = False
    layout.prop(settings, "method")
    for _, name in param_properties(selected_method(settings)):
        layout.prop(settings, name)
    column = layout.column(align=True)
    column.prop(settings, "width")
    column.prop(settings, "height")
    layout.prop(settings, "seed")
    layout.prop(settings, "output")
    if settings.output != "PACK":
        layout.prop(settings, "output_dir")


class TEXSYNTH_PG_settings(bpy.types.PropertyGroup):
    """The panel's settings, stored per scene; the operator falls back on them."""


classes = (TEXSYNTH_PG_settings,)


def register():
    TEXSYNTH_PG_settings.__annotations__ = settings_annotations(set())
    for cls in classes:
        bpy.utils.register_class(cls)
    bpy.types.Scene.texsynth = bpy.props.PointerProperty(type=TEXSYNTH_PG_settings)


def unregister():
    del bpy.types.Scene.texsynth
    for cls in reversed(classes):
        bpy.utils.unregister_class(cls)

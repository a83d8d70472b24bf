"""TexSynth: seamless textures of any size from an example image (Blender extension).

Only registration lives here; the operator, panel and settings are in ``operators/`` and the
bpy-free synthesis core in ``texsynth/``.
"""


def register():
    from . import operators

    operators.register()


def unregister():
    from . import operators

    operators.unregister()

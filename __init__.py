"""TexSynth: seamless textures of any size from an example image (Blender extension).

Only registration lives here; the operator, panel and settings are in ``operators/``, the
bpy-free synthesis core in ``texsynth/``, and the check of the bundled packages in
``dependencies.py``: when scipy or OpenEXR cannot be used, a panel and operator that say why
are registered instead of the real ones.
"""


def register():
    from . import dependencies

    problem = dependencies.problem()
    if problem is None:
        try:
            from . import operators, texsynth

            texsynth.methods()  # imports every method's module, and so scipy's compiled parts
        except ImportError as error:  # e.g. a scipy built for another numpy
            problem = dependencies.import_problem(error)
    if problem is not None:
        dependencies.register_fallback(problem)
        return
    operators.register()


def unregister():
    from . import dependencies

    if dependencies.unregister_fallback():
        return
    from . import operators

    operators.unregister()

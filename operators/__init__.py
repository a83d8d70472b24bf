"""Blender glue: the TexSynth settings, operators and panels (the core is ``texsynth/``).

Read in this order:

* ``properties.py``: every setting, in ``scene.texsynth`` (property groups made from the
  texsynth registry) and on the operators (:func:`properties.registry_settings`);
* ``job.py``: :class:`job.JobOperator`, the run of a long synthesis (worker thread, progress,
  Esc; synchronous in background mode) that the synthesis operators share;
* the operators, one module per feature: ``synthesize.py`` (``texsynth.synthesize``),
  ``material.py`` (``texsynth.synthesize_material``: the maps of a material together),
  ``composite.py`` (``texsynth.segment``, ``texsynth.synthesize_composite``), ``estimate.py``
  (``texsynth.estimate_plane``, ``texsynth.align_camera``, ``texsynth.rectify``),
  ``tileable.py`` (``texsynth.make_tileable``: the photo itself made to tile),
  ``photo_material.py`` (``texsynth.photo_to_material``: a photo to a new, wired material),
  ``norepeat/`` (``texsynth.break_repetition``: never repeating at render time; a wing of
  its own, one module per mode, mirroring the core's ``texsynth/norepeat/``);
* ``panels.py``: every panel;
* helpers: ``source.py`` (which image and node), ``pixels.py`` (Blender pixels to arrays and
  back), ``output.py`` (the new image datablock or file), ``nodes.py`` (the new node).

Each module with Blender classes keeps a ``classes`` tuple and its own ``register`` and
``unregister`` (``bpy.utils.register_classes_factory``); this package only delegates, in order:
the settings before the operators, the operators before the panels that show them.
"""

from . import (
    composite,
    estimate,
    material,
    norepeat,
    panels,
    photo_material,
    properties,
    synthesize,
    tileable,
)

_modules = (properties, synthesize, material, tileable, norepeat, composite, estimate,
            photo_material, panels)


def register():
    for module in _modules:
        module.register()


def unregister():
    for module in reversed(_modules):
        module.unregister()

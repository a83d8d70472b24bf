"""Blender glue: settings, the synthesize operator and the Shader Editor panel.

Each module keeps a ``classes`` tuple and its own ``register``/``unregister``; this package only
delegates, in order (settings before the operator and panel that read them).
"""

from . import composite, estimate, material, panel, positions, properties, synthesize, tileable

_modules = (properties, synthesize, panel, positions, material, composite, estimate, tileable)


def register():
    for module in _modules:
        module.register()


def unregister():
    for module in reversed(_modules):
        module.unregister()

"""The packages TexSynth bundles as wheels, and the check that the ones Blender gives it work.

Blender installs the wheels of every enabled extension into one shared site-packages and keeps,
of each package, only the highest version. So the scipy or OpenEXR that TexSynth imports may be
another extension's: newer, or built for another numpy. :func:`problem` finds out before the
operators are loaded; register() then shows the problem in the TexSynth panel and the operator
reports it, instead of the extension failing to load with a traceback.

``BUNDLED`` is the one list of bundled packages: addon_build.py downloads these releases for
every platform and writes blender_manifest.toml's ``wheels`` from them.
"""

import importlib
import re
import sys
import textwrap
import traceback
from pathlib import Path

import bpy

from .versions import requirement, satisfies

#: Package -> {Python version: release}; the wheels are downloaded unmodified from PyPI.
#: scipy 1.15 is the last release that supports Blender 4.2's numpy 1.24 (1.16 needs numpy >=
#: 1.25.2): it serves Python 3.11 (Blender 4.2 to 5.0; 4.5 ships numpy 1.26). For Python 3.13
#: (Blender 5.1 on: numpy 1.26, then 2.3.4 from 5.2) scipy 1.16.3 (numpy >= 1.25.2, < 2.6, from
#: its METADATA) also holds the numpy 2.5 that pip gives the bpy module 5.3 from PyPI. Two
#: releases of one package for two Pythons need Blender 4.2.13 or later
#: (blender_version_min): 4.2.0 to 4.2.12 install a package's highest version whatever its
#: Python tag (bpy 4.2.0's bl_pkg/bl_extension_ops.py: "TODO: Match Python & ABI tags"),
#: 4.2.13 first skips the wheels of another Python.
#: exifread (the photo's focal length from its EXIF) and threadpoolctl (BLAS on one thread
#: inside the methods: ``texsynth.blocks.parallel.serial_blas``) are pure Python: one
#: py3-none-any wheel serves every Python and platform.
BUNDLED = {
    "scipy": {"3.11": "1.15.3", "3.13": "1.16.3"},
    "OpenEXR": {"3.11": "3.5.3", "3.13": "3.5.2"},
    "exifread": {"3.11": "3.5.1", "3.13": "3.5.1"},
    "threadpoolctl": {"3.11": "3.6.0", "3.13": "3.6.0"},
}

_problem = None  # the message shown while TexSynth cannot work, or None


def supported(package: str) -> tuple[tuple[int, int], tuple[int, int]]:
    """[lowest, above) versions of ``package`` that TexSynth works with: from the bundled
    releases' minor version up to the next major version."""
    lowest = min(_version(v) for v in BUNDLED[package].values())
    return lowest, (lowest[0] + 1, 0)


def problem() -> str | None:
    """Why the bundled packages cannot be used, or None when they can."""
    found = []
    for package in BUNDLED:
        try:
            module = importlib.import_module(package)
        except Exception as error:  # ImportError, or a compiled module built for another Python
            found.append(f"{package} could not be imported ({type(error).__name__}: {error}).")
            continue
        lowest, above = supported(package)
        version = getattr(module, "__version__", "?")
        if not lowest <= _version(version) < above:
            found.append(f"{package} {version} from {_where(module)} is installed, but TexSynth "
                         f"needs {package} >= {_dotted(lowest)} and < {_dotted(above)}.")
            continue
        found.extend(filter(None, [numpy_problem(module)]))
    return _advice(found) if found else None


def numpy_problem(module) -> str | None:
    """Why the installed numpy is not one that ``module`` (an imported bundled package)
    declares it supports in its wheel's METADATA, or None when it is (or it declares none)."""
    import numpy

    file = getattr(module, "__file__", None)
    if file is None:
        return None
    site = Path(file).parent.parent if Path(file).name == "__init__.py" else Path(file).parent
    infos = sorted(site.glob(f"{module.__name__.lower()}-*.dist-info"))
    metadata = infos[-1] / "METADATA" if infos else None
    spec = requirement(metadata.read_text(), "numpy") if metadata and metadata.is_file() else None
    if spec is None or satisfies(numpy.__version__, spec):
        return None
    return (f"{module.__name__} {module.__version__}, bundled for Python "
            f"{sys.version_info.major}.{sys.version_info.minor}, supports numpy {spec}, but "
            f"numpy {numpy.__version__} is installed (pip gives the bpy module from PyPI its "
            f"newest numpy; Blender's own downloads ship one that fits): install a numpy "
            f"{spec} (pip install \"numpy{spec}\").")


def import_problem(error: ImportError) -> str:
    """The message for an ImportError raised while loading the operators (and the core)."""
    traceback.print_exception(error)
    return _advice([f"Loading failed with {type(error).__name__}: {error}."])


def _advice(found: list[str]) -> str:
    blender = ".".join(str(v) for v in bpy.app.version)
    python = ".".join(str(v) for v in sys.version_info[:3])
    numpy = sys.modules.get("numpy")
    numpy_version = getattr(numpy, "__version__", "not imported")
    return " ".join([
        "TexSynth cannot run:", *found,
        f"(Blender {blender}, Python {python}, numpy {numpy_version}.)",
        "Another extension may bundle a different version: disable it and restart Blender, "
        "and check that the TexSynth zip is the one made for your platform.",
    ])


def _version(text: str) -> tuple[int, int]:
    """(major, minor) of a version string; (0, 0) when it has none."""
    match = re.match(r"(\d+)\.(\d+)", text)
    return (int(match[1]), int(match[2])) if match else (0, 0)


def _dotted(version: tuple[int, ...]) -> str:
    return ".".join(str(v) for v in version)


def _where(module) -> str:
    return getattr(module, "__file__", None) or "an unknown place"


class TEXSYNTH_OT_synthesize(bpy.types.Operator):
    """Synthesize a seamless texture (unavailable: see the TexSynth panel)"""

    bl_idname = "texsynth.synthesize"
    bl_label = "Synthesize Texture"

    def execute(self, context):
        self.report({"ERROR"}, _problem)
        return {"CANCELLED"}


class TEXSYNTH_PT_synthesize(bpy.types.Panel):
    bl_label = "Texture Synthesis"
    bl_space_type = "NODE_EDITOR"
    bl_region_type = "UI"
    bl_category = "TexSynth"

    def draw(self, context):
        column = self.layout.column(align=True)
        for i, line in enumerate(textwrap.wrap(_problem, 48)):
            column.label(text=line, icon="ERROR" if i == 0 else "BLANK1")


fallback_classes = (TEXSYNTH_OT_synthesize, TEXSYNTH_PT_synthesize)


def register_fallback(message: str) -> None:
    """Register a panel that shows ``message`` and an operator that reports it."""
    global _problem
    _problem = message
    print(message, file=sys.stderr)
    for cls in fallback_classes:
        bpy.utils.register_class(cls)


def unregister_fallback() -> bool:
    """Unregister the fallback classes if they are registered; True if they were."""
    global _problem
    if _problem is None:
        return False
    for cls in reversed(fallback_classes):
        bpy.utils.unregister_class(cls)
    _problem = None
    return True

"""The bundled scipy and OpenEXR: the right wheels installed, and a clear message when the
scipy or OpenEXR the extension gets cannot be used (another extension's, or a broken one)."""

import contextlib
import sys
import types
from pathlib import Path

import bpy
import pytest

import addon_build


def _site_packages() -> Path:
    return Path(bpy.utils.user_resource("EXTENSIONS"), ".local", "lib",
                f"python{sys.version_info.major}.{sys.version_info.minor}", "site-packages")


def test_blender_installed_the_wheels_built_for_this_python(addon):
    # Two Pythons' releases differ (scipy 1.15.3 and 1.16.3): this Python's, not the other's.
    python = f"{sys.version_info.major}.{sys.version_info.minor}"
    for package, releases in addon.dependencies.BUNDLED.items():
        (info,) = _site_packages().glob(f"{package.lower()}-*.dist-info")
        assert info.name == f"{package.lower()}-{releases[python]}.dist-info"
        tags = [line.split(": ")[1] for line in (info / "WHEEL").read_text().splitlines()
                if line.startswith("Tag: ")]
        assert tags and all(t.startswith(f"cp{python.replace('.', '')}-")
                            or t == "py3-none-any" for t in tags), tags
        assert sys.modules[package].__version__ == releases[python]
    assert addon.dependencies.problem() is None


def test_the_bundled_scipy_supports_the_numpy_this_blender_ships(addon):
    # SciPy warns at import when numpy is outside the range its release supports, which its
    # wheel declares (scipy 1.15.3: numpy >= 1.23.5, < 2.5; 1.16.3: >= 1.25.2, < 2.6).
    import numpy
    import scipy

    (info,) = Path(scipy.__file__).parents[1].glob("scipy-*.dist-info")
    spec = addon_build.requirement((info / "METADATA").read_text(), "numpy")
    assert spec, f"{info.name} declares no numpy requirement"
    assert addon_build.satisfies(numpy.__version__, spec), (
        f"{info.name} supports numpy {spec}; this Blender has numpy {numpy.__version__}: "
        "bundle a scipy for this Python that supports it (dependencies.BUNDLED)")


def test_the_numpy_here_fits_the_bundled_scipy_or_the_mismatch_is_named(addon):
    # addon_build.py test-compat runs bpy 5.3.0 with the numpy pip resolves (2.5.5, which the
    # cp313 scipy 1.16.3 holds); a numpy beyond the bundled scipy's range is named.
    import numpy
    import scipy

    (info,) = Path(scipy.__file__).parents[1].glob("scipy-*.dist-info")
    spec = addon_build.requirement((info / "METADATA").read_text(), "numpy")
    problem = addon.dependencies.problem()
    if addon_build.satisfies(numpy.__version__, spec):
        assert problem is None
    else:
        assert (f"scipy {scipy.__version__}, bundled for Python {sys.version_info.major}."
                f"{sys.version_info.minor}, supports numpy {spec}, but numpy "
                f"{numpy.__version__} is installed") in problem
        assert f'pip install "numpy{spec}"' in problem


def test_a_numpy_the_bundled_scipy_does_not_support_is_named_in_the_panel(
        addon, reregister, monkeypatch):
    import numpy

    monkeypatch.setattr(numpy, "__version__", "9.0.0")
    addon.register()
    text = _panel_text()
    assert "supports numpy" in text and "but numpy 9.0.0 is installed" in text
    with pytest.raises(RuntimeError, match="numpy 9.0.0 is installed"):
        bpy.ops.texsynth.synthesize()


class _Layout:
    """Records the labels a panel draws."""

    def __init__(self):
        self.labels = []

    def column(self, **_):
        return self

    def label(self, text, icon="NONE"):
        self.labels.append((text, icon))


def _panel_text():
    layout = _Layout()
    bpy.types.TEXSYNTH_PT_synthesize.draw(types.SimpleNamespace(layout=layout), bpy.context)
    assert layout.labels[0][1] == "ERROR"
    return " ".join(text for text, _ in layout.labels)


@pytest.fixture
def reregister(addon, monkeypatch):
    """Unregister the extension; the test registers it again in a broken environment; after
    the test it is registered again as it was."""
    saved = dict(sys.modules)
    addon.unregister()
    yield
    with contextlib.suppress(RuntimeError):  # a failed test may leave nothing registered
        addon.unregister()
    monkeypatch.undo()
    for name in [n for n in sys.modules if n.startswith(addon.__name__)]:
        del sys.modules[name]
    sys.modules.update({n: m for n, m in saved.items() if n.startswith(addon.__name__)})
    for name in ("operators", "texsynth"):
        setattr(addon, name, saved[f"{addon.__name__}.{name}"])
    addon.register()
    assert "width" in bpy.ops.texsynth.synthesize.get_rna_type().properties


@pytest.mark.parametrize("installed, expected", [
    (types.SimpleNamespace(__version__="1.9.0", __file__="/other/extension/scipy/__init__.py"),
     "scipy 1.9.0 from /other/extension/scipy/__init__.py is installed, but TexSynth needs "
     "scipy >= 1.15 and < 2.0."),
    (None, "scipy could not be imported (ModuleNotFoundError: import of scipy halted"),
])
def test_an_unusable_scipy_is_explained_in_the_panel_and_by_the_operator(
        addon, reregister, monkeypatch, installed, expected):
    monkeypatch.setitem(sys.modules, "scipy", installed)
    addon.register()
    assert expected in _panel_text()
    with pytest.raises(RuntimeError, match="TexSynth cannot run: scipy"):
        bpy.ops.texsynth.synthesize()


def test_an_import_error_while_loading_is_explained_too(addon, reregister, monkeypatch):
    # A scipy whose compiled parts fail (built for another numpy): the top level imports.
    for name in [n for n in sys.modules if n.startswith(f"{addon.__name__}.")]:
        monkeypatch.delitem(sys.modules, name)
    monkeypatch.delattr(addon, "operators")
    monkeypatch.delattr(addon, "texsynth")
    monkeypatch.setitem(sys.modules, "scipy.fft", None)
    addon.register()
    text = _panel_text()
    assert "Loading failed with ModuleNotFoundError: import of scipy.fft halted" in text
    assert f"numpy {sys.modules['numpy'].__version__}" in text
    with pytest.raises(RuntimeError, match="import of scipy.fft halted"):
        bpy.ops.texsynth.synthesize()

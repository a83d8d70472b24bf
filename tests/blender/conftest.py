"""Blender tests: the bpy module, with the built extension zip installed the way a user would.

BLENDER_USER_RESOURCES is pointed at a temporary folder before bpy is first imported, so the
install never touches the real Blender configuration (subprocesses inherit it too). The zip is
installed when this file is imported, before the test modules import the core: in a venv
without scipy and OpenEXR (addon_build.py test-compat) they then use the extension's bundled
wheels, as the extension does.
"""

import atexit
import os
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

import pytest

if "bpy" in sys.modules:
    raise RuntimeError("bpy was imported before tests/blender/conftest.py isolated Blender's "
                       "user folder; run the Blender tests in their own process")
USER_DIR = tempfile.mkdtemp(prefix="texsynth-blender-user-")
os.environ["BLENDER_USER_RESOURCES"] = USER_DIR
atexit.register(shutil.rmtree, USER_DIR, True)

import bpy  # noqa: E402

import addon_build  # noqa: E402  (the repository is on sys.path: pyproject's pythonpath)

PACKAGE = "bl_ext.user_default.texsynth"


def _extension_zip() -> Path:
    """This platform's zip from dist/, built first if it is missing or older than the sources."""
    if addon_build.build_is_stale():
        subprocess.run([sys.executable, str(addon_build.REPO / "addon_build.py"), "build"],
                       check=True)
    return addon_build.extension_zip()


def _install():
    result = bpy.ops.extensions.package_install_files(
        filepath=str(_extension_zip()), repo="user_default", enable_on_install=True)
    assert result == {"FINISHED"}
    return sys.modules[PACKAGE]


ADDON = _install()


@pytest.fixture(scope="session")
def addon():
    """The installed extension's root package."""
    return ADDON


@pytest.fixture(autouse=True)
def empty_file(addon):
    """Every test starts from an empty file (read_factory_settings would disable extensions)."""
    bpy.ops.wm.read_homefile(use_empty=True)
    yield

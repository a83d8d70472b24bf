"""Blender tests: the bpy module, with the built extension zip installed the way a user would.

BLENDER_USER_RESOURCES is pointed at a temporary folder before bpy is first imported, so the
install never touches the real Blender configuration (subprocesses inherit it too).
"""

import atexit
import os
import platform
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

REPO = Path(__file__).resolve().parents[2]
PACKAGE = "bl_ext.user_default.texsynth"
PLATFORMS = {("Linux", "x86_64"): "linux_x64", ("Windows", "AMD64"): "windows_x64",
             ("Darwin", "arm64"): "macos_arm64", ("Darwin", "x86_64"): "macos_x64"}


def _extension_zip() -> Path:
    """This platform's zip from dist/, built first if it is missing or older than the sources."""
    suffix = PLATFORMS[(platform.system(), platform.machine())]
    path = REPO / "dist" / f"texsynth-0.1.0-{suffix}.zip"
    sources = [REPO / "blender_manifest.toml", REPO / "__init__.py",
               *REPO.glob("operators/**/*.py"), *REPO.glob("texsynth/**/*.py")]
    if not path.exists() or path.stat().st_mtime < max(p.stat().st_mtime for p in sources):
        subprocess.run([sys.executable, str(REPO / "addon_build.py"), "build"], check=True)
    return path


@pytest.fixture(scope="session")
def addon():
    """The installed extension's root package."""
    result = bpy.ops.extensions.package_install_files(
        filepath=str(_extension_zip()), repo="user_default", enable_on_install=True)
    assert result == {"FINISHED"}
    return sys.modules[PACKAGE]


@pytest.fixture(autouse=True)
def empty_file(addon):
    """Every test starts from an empty file (read_factory_settings would disable extensions)."""
    bpy.ops.wm.read_homefile(use_empty=True)
    yield

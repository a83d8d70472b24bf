"""Set up, build, validate, test and demo texsynth.

    python3 addon_build.py setup     .venv with requirements-dev.txt (bpy, scipy, OpenEXR, ...)
    python3 addon_build.py build     bundled wheels into wheels/, extension zips into dist/
    python3 addon_build.py validate  check the manifest and the built zips
    python3 addon_build.py demo      synthesize samples/pool_water.png at 512 x 512 into out/
    python3 addon_build.py test      build, then ruff and pytest

Any Python 3 starts it: every command first makes sure of .venv and re-runs itself there. The
build uses the extension CLI that ships inside the bpy wheel (bl_pkg's blender_ext.py), since the
bpy module has no Blender binary for ``blender --command extension build``.
"""

import argparse
import importlib.util
import os
import shutil
import subprocess
import sys
from pathlib import Path

REPO = Path(__file__).resolve().parent
VENV = REPO / ".venv"
VENV_PYTHON = VENV / ("Scripts/python.exe" if os.name == "nt" else "bin/python")
REQUIREMENTS = REPO / "requirements-dev.txt"
INSTALLED_STAMP = VENV / "requirements-dev.installed"
DIST = REPO / "dist"
OUT = REPO / "out"
SAMPLE = REPO / "samples" / "pool_water.png"
WHEEL_PYTHON = "3.11"  # Blender 4.2 to 5.0, and the only Python the bpy 5.0 wheel supports


def _bl_pkg_scripts() -> Path:
    """Blender's scripts folder inside the bpy wheel (found without importing bpy)."""
    bpy_dir = Path(importlib.util.find_spec("bpy").submodule_search_locations[0])
    return next(bpy_dir.glob("[0-9]*.[0-9]*/scripts"))


def _run(*command, **kwargs) -> None:
    print("$", " ".join(str(c) for c in command), flush=True)
    subprocess.run([str(c) for c in command], check=True, **kwargs)


def _python_311() -> str:
    if sys.version_info[:2] == (3, 11):
        return sys.executable
    found = shutil.which("python3.11")
    if not found:
        sys.exit(f"the bpy module needs Python {WHEEL_PYTHON}; install python3.11 and run again")
    return found


def setup() -> None:
    """Create .venv and install requirements-dev.txt when it is missing or has changed."""
    if not VENV_PYTHON.exists():
        _run(_python_311(), "-m", "venv", VENV)
    wanted = REQUIREMENTS.read_text()
    if not INSTALLED_STAMP.exists() or INSTALLED_STAMP.read_text() != wanted:
        _run(VENV_PYTHON, "-m", "pip", "install", "-r", REQUIREMENTS)
        INSTALLED_STAMP.write_text(wanted)


def _in_venv() -> bool:
    return Path(sys.prefix).resolve() == VENV.resolve()


def download_wheels() -> None:
    """Fetch each wheel the manifest lists, by the name, version and platform in its file name."""
    import tomllib  # Python 3.11+: this runs inside .venv

    manifest = tomllib.loads((REPO / "blender_manifest.toml").read_text())
    for wheel in manifest["wheels"]:
        path = REPO / wheel
        if path.exists():
            continue
        name, version, _python, _abi, platforms = path.stem.split("-")
        _run(sys.executable, "-m", "pip", "download", "--only-binary=:all:", "--no-deps",
             "--python-version", WHEEL_PYTHON, *(f"--platform={p}" for p in platforms.split(".")),
             "-d", path.parent, f"{name}=={version}")
        if not path.exists():
            sys.exit(f"pip did not produce {wheel}: check the file name in blender_manifest.toml")


def _extension_cli(*args) -> None:
    scripts = _bl_pkg_scripts()
    cli = scripts / "addons_core" / "bl_pkg" / "cli" / "blender_ext.py"
    tags = scripts / "modules" / "_bpy_internal" / "extensions" / "tags.py"
    _run(sys.executable, cli, *args, f"--valid-tags={tags}")


def validate() -> None:
    """Validate the manifest in the source tree and every built zip."""
    _extension_cli("validate", REPO)
    for path in sorted(DIST.glob("texsynth-*.zip")):
        _extension_cli("validate", path)


def build() -> None:
    """Build and validate one extension zip per platform in dist/, and print their paths."""
    download_wheels()
    DIST.mkdir(exist_ok=True)
    for old in DIST.glob("texsynth-*.zip"):
        old.unlink()
    _extension_cli("build", "--source-dir", REPO, "--output-dir", DIST, "--split-platforms")
    validate()
    print("\nbuilt:", *sorted(DIST.glob("texsynth-*.zip")), sep="\n  ")


def demo() -> None:
    """Run the headless example on the bundled sample; Blender's user files go to .cache/."""
    env = dict(os.environ, BLENDER_USER_RESOURCES=str(REPO / ".cache" / "blender"))
    _run(sys.executable, REPO / "examples" / "synthesize_file.py", SAMPLE,
         "--width", "512", "--height", "512", "--out", OUT, env=env)


def test() -> None:
    """Build (the tests install the zip), then ruff and pytest."""
    build()
    _run(sys.executable, "-m", "ruff", "check", REPO)
    _run(sys.executable, "-m", "pytest", "-q", REPO / "tests", cwd=REPO)


COMMANDS = {"setup": setup, "build": build, "validate": validate, "demo": demo, "test": test}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("command", choices=COMMANDS)
    command = parser.parse_args().command
    setup()
    if command == "setup":
        return
    if not _in_venv():
        os.execv(VENV_PYTHON, [str(VENV_PYTHON), __file__, command])
    try:
        COMMANDS[command]()
    except subprocess.CalledProcessError as error:
        sys.exit(error.returncode)


if __name__ == "__main__":
    main()

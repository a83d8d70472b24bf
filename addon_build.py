"""Set up, build, validate, test and demo texsynth.

    python3 addon_build.py setup        .venv with requirements-dev.txt and the bundled packages
    python3 addon_build.py build        wheels into wheels/, one zip per platform and the
                                        repository listing (index.json, index.html) into dist/
    python3 addon_build.py validate     Blender's validator on the source and every zip
    python3 addon_build.py repo         the repository listing of the zips in dist/
    python3 addon_build.py demo         synthesize samples/pool_water.png at 512 x 512 into out/
    python3 addon_build.py test         what CI runs: build, ruff, the pip package (pip-check),
                                        pytest (Blender 5.0 = bpy 5.0.1), then what test-compat
                                        runs
    python3 addon_build.py test-compat  build, then the Blender tests in Blender 4.2.13, 4.5 LTS
                                        and 5.3 (bpy from PyPI, each in its own
                                        .venv-bpy-VERSION), and the core tests on 5.3's Python
                                        3.13 and numpy 2.3 with the bundled cp313 wheels
    python3 addon_build.py pip-check    the checkout pip-installed into a throwaway venv, and the
                                        texsynth command run there

test and test-compat stop at once, exit status 1, when a Python that a promised Blender needs
(3.13 for 5.3) is missing; ``--skip-missing`` skips those runs instead.

Any Python 3 starts it: every command first makes sure of .venv and re-runs itself there. The
build, validation and listing use the extension CLI that ships inside the bpy wheel (bl_pkg's
blender_ext.py), since the bpy module has no Blender binary for ``blender --command extension``.

Bundled wheels: dependencies.py's ``BUNDLED`` names the releases (one place, also read by the
extension's own version check), ``PLATFORMS`` below the systems. The build downloads each
release for each platform unmodified from PyPI into wheels/ (once: later builds are offline) and
writes blender_manifest.toml's ``platforms`` and ``wheels`` from them; that list is also the
lock, since pip picks a wheel's exact file (its glibc or macOS tag) only when downloading.
Blender's ``build --split-platforms`` then puts into each platform's zip only that platform's
wheels (for every Python), listed in a generated ``[build.generated]`` table of its manifest.
"""

import argparse
import ast
import importlib.util
import os
import re
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

from versions import requirement, satisfies  # noqa: F401  (the tests read them from here)

REPO = Path(__file__).resolve().parent
VENV = REPO / ".venv"
VENV_PYTHON = VENV / ("Scripts/python.exe" if os.name == "nt" else "bin/python")
REQUIREMENTS = REPO / "requirements-dev.txt"
INSTALLED_STAMP = "requirements-dev.installed"
MANIFEST = REPO / "blender_manifest.toml"
WHEELS = REPO / "wheels"
DIST = REPO / "dist"
OUT = REPO / "out"
SAMPLE = REPO / "samples" / "pool_water.png"
PURE = "3"  # wheel_key's Python of a py3-none-any wheel: any Python 3
DEV_PYTHON = "3.11"  # Blender 4.2 to 5.0, and the only Python the bpy 4.2-5.0 wheels support

#: Blender platform -> pip platform tags of the oldest system its zip supports: Blender 4.2+
#: needs glibc 2.28 on Linux (pip does not expand manylinux_2_28 to older glibc tags, so they
#: are listed) and macOS 11.2; scipy's Apple silicon wheels need macOS 12.
PLATFORMS = {
    "windows-x64": ("win_amd64",),
    "macos-arm64": ("macosx_12_0_arm64",),
    "macos-x64": ("macosx_11_0_x86_64",),
    "linux-x64": ("manylinux_2_28_x86_64", "manylinux_2_17_x86_64", "manylinux2014_x86_64"),
    "linux-arm64": ("manylinux_2_28_aarch64", "manylinux_2_17_aarch64", "manylinux2014_aarch64"),
}

#: Per-zip size budget (bytes); the zips hold two Pythons' scipy wheels (~35 MB each).
ZIP_BUDGET = 150 << 20

#: The other Blenders the Blender tests run in (test-compat), as the bpy module from PyPI:
#: bpy release -> (its Python, the numpy that Blender release bundles: NUMPY_VERSION in
#: Blender's versions.cmake). The bpy wheels accept a range (4.2-5.0: numpy < 2; 5.2+: >= 2.2,
#: < 3); the venvs get the numpy of the Blender downloads, except NEWEST_BPY's, which gets the
#: numpy pip resolves (2.5 for 5.3: what a headless user of the PyPI module has); the core
#: tests run on NEWEST_BPY's Python with its download's numpy.
#: Not bpy 5.1 (Python 3.13, numpy 1.26): PyPI has no numpy 1.26 wheel for Python 3.13.
COMPAT_BPY = {"4.2.13": ("3.11", "1.24.3"), "4.5.15": ("3.11", "1.26.4"),
              "5.3.0": ("3.13", "2.3.4")}
#: The newest of COMPAT_BPY: its Blender tests run with the numpy pip resolves, the core tests
#: on its Python and numpy with the bundled wheels for that Python.
NEWEST_BPY = "5.3.0"


def bundled() -> dict[str, dict[str, str]]:
    """dependencies.BUNDLED, read without importing the module (it imports bpy)."""
    tree = ast.parse((REPO / "dependencies.py").read_text())
    for node in tree.body:
        if isinstance(node, ast.Assign) and any(getattr(t, "id", "") == "BUNDLED"
                                                for t in node.targets):
            return ast.literal_eval(node.value)
    raise LookupError("dependencies.py has no BUNDLED table")


def version() -> str:
    """The extension's version: blender_manifest.toml is the one place it is written."""
    import tomllib

    return tomllib.loads(MANIFEST.read_text())["version"]


def _bl_pkg_scripts() -> Path:
    """Blender's scripts folder inside the bpy wheel (found without importing bpy)."""
    bpy_dir = Path(importlib.util.find_spec("bpy").submodule_search_locations[0])
    return next(bpy_dir.glob("[0-9]*.[0-9]*/scripts"))


def _blender_ext_path() -> Path:
    return _bl_pkg_scripts() / "addons_core" / "bl_pkg" / "cli" / "blender_ext.py"


def _blender_ext():
    """Blender's extension CLI as a module (for its wheel-platform rules)."""
    spec = importlib.util.spec_from_file_location("blender_ext", _blender_ext_path())
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def _run(*command, **kwargs) -> None:
    print("$", " ".join(str(c) for c in command), flush=True)
    subprocess.run([str(c) for c in command], check=True, **kwargs)


def _python_311() -> str:
    if sys.version_info[:2] == (3, 11):
        return sys.executable
    found = shutil.which("python3.11")
    if not found:
        sys.exit(f"the bpy module needs Python {DEV_PYTHON}; install python3.11 and run again")
    return found


def _venv_python(venv: Path) -> Path:
    return venv / ("Scripts/python.exe" if os.name == "nt" else "bin/python")


def _ensure_venv(venv: Path, requirements: list[str], base: str = "") -> Path:
    """A venv of ``base`` (default Python 3.11) with ``requirements`` installed (again only when
    they change)."""
    python = _venv_python(venv)
    if not python.exists():
        _run(base or _python_311(), "-m", "venv", venv)
    wanted = "\n".join(requirements) + "\n"
    stamp = venv / INSTALLED_STAMP
    if not stamp.exists() or stamp.read_text() != wanted:
        _run(python, "-m", "pip", "install", *requirements)
        stamp.write_text(wanted)
    return python


def setup() -> None:
    """Create .venv: requirements-dev.txt, and the bundled packages at their Python 3.11 pins."""
    lines = [line.split("#")[0].strip() for line in REQUIREMENTS.read_text().splitlines()]
    pins = [f"{package}=={releases[DEV_PYTHON]}" for package, releases in bundled().items()]
    _ensure_venv(VENV, [line for line in lines if line] + pins)


def _in_venv() -> bool:
    return Path(sys.prefix).resolve() == VENV.resolve()


# --- wheels -----------------------------------------------------------------------------


def _normalized(name: str) -> str:
    return re.sub(r"[-_.]+", "_", name).lower()


def wheel_key(filename: str, blender_ext=None) -> tuple[str, str, str, tuple[str, ...]]:
    """(package, version, Python 'X.Y', Blender platforms) of a wheel's file name.

    A pure-Python wheel (``py3-none-any``) serves every Python 3 and every platform: its Python
    is ``PURE`` and its platforms are all of :data:`PLATFORMS`.
    """
    blender_ext = blender_ext or _blender_ext()
    parts = filename.removesuffix(".whl").split("-")
    python_tag, abi_tag, platform_tag = parts[-3:]
    if (python_tag, abi_tag, platform_tag) == ("py3", "none", "any"):
        return _normalized(parts[0]), parts[1], PURE, tuple(PLATFORMS)
    if not re.fullmatch(r"cp3\d+", python_tag):
        raise ValueError(f"{filename}: neither a CPython nor a py3-none-any wheel ({python_tag})")
    python = f"3.{python_tag[3:]}"
    platforms = tuple(blender_ext.blender_platforms_from_wheel_platform(platform_tag))
    return _normalized(parts[0]), parts[1], python, platforms


def serves(wheel_python: str, python: str) -> bool:
    """Whether a wheel whose :func:`wheel_key` Python is ``wheel_python`` installs on ``python``."""
    return wheel_python in (python, PURE)


def _manifest_wheels() -> list[str]:
    import tomllib

    return tomllib.loads(MANIFEST.read_text()).get("wheels", [])


def download_wheels() -> list[str]:
    """Every bundled wheel, as manifest paths; downloads those not in wheels/ yet and writes
    the manifest's ``platforms`` and ``wheels`` when they differ from what BUNDLED asks for."""
    blender_ext = _blender_ext()
    locked = {}
    for path in _manifest_wheels():
        if (REPO / path).is_file():
            package, release, python, platforms = wheel_key(Path(path).name, blender_ext)
            for platform in platforms:
                locked[package, release, python, platform] = path
    wheels = []
    for package, releases in bundled().items():
        for python, release in releases.items():
            for platform, tags in PLATFORMS.items():
                key = (_normalized(package), release, python, platform)
                path = (locked.get(key) or locked.get((*key[:2], PURE, platform))
                        or _download(package, release, python, platform, tags, blender_ext))
                if path not in wheels:
                    wheels.append(path)
    _write_manifest_lists(list(PLATFORMS), wheels)
    return wheels


def _download(package, release, python, platform, tags, blender_ext) -> str:
    """Download one wheel unmodified (never its dependencies: numpy is Blender's)."""
    WHEELS.mkdir(exist_ok=True)
    with tempfile.TemporaryDirectory() as tmp:
        _run(sys.executable, "-m", "pip", "download", "--only-binary=:all:", "--no-deps",
             "--implementation", "cp", "--python-version", python,
             *(f"--platform={tag}" for tag in tags), "-d", tmp, f"{package}=={release}")
        (wheel,) = Path(tmp).glob("*.whl")
        got = wheel_key(wheel.name, blender_ext)
        if got[:2] != (_normalized(package), release) or not serves(got[2], python) \
                or platform not in got[3]:
            sys.exit(f"pip gave {wheel.name} for {package} {release}, Python {python}, "
                     f"{platform}")
        shutil.move(wheel, WHEELS / wheel.name)
    return f"./wheels/{wheel.name}"


def _toml_list(name: str, items: list[str]) -> str:
    return f"{name} = [\n" + "".join(f'  "{item}",\n' for item in items) + "]"


def _write_manifest_lists(platforms: list[str], wheels: list[str]) -> None:
    text = MANIFEST.read_text()
    new = text
    for name, items in (("platforms", platforms), ("wheels", wheels)):
        new, count = re.subn(rf"^{name} = \[[^\]]*\]", _toml_list(name, items), new,
                             flags=re.MULTILINE)
        if count != 1:
            sys.exit(f"blender_manifest.toml needs exactly one '{name} = [...]' list")
    if new != text:
        MANIFEST.write_text(new)
        print("updated blender_manifest.toml: platforms and wheels from dependencies.BUNDLED")


# --- build, validate, repository --------------------------------------------------------


def _extension_cli(*args, tags=True) -> None:
    tags_file = _bl_pkg_scripts() / "modules" / "_bpy_internal" / "extensions" / "tags.py"
    _run(sys.executable, _blender_ext_path(), *args,
         *([f"--valid-tags={tags_file}"] if tags else []))


def zips() -> list[Path]:
    return sorted(DIST.glob(f"texsynth-{version()}-*.zip"))


def extension_zip(platform: str = "") -> Path:
    """dist/'s zip for a Blender platform ('linux-x64', ...; default: this system's)."""
    platform = platform or _blender_ext().platform_from_this_system()
    return DIST / f"texsynth-{version()}-{platform.replace('-', '_')}.zip"


def build_is_stale() -> bool:
    """True when a zip or the listing is missing or older than a file that goes into a zip."""
    sources = [MANIFEST, REPO / "__init__.py", REPO / "dependencies.py", REPO / "LICENSE",
               *REPO.glob("operators/**/*.py"), *REPO.glob("texsynth/**/*.py")]
    built = [extension_zip(platform) for platform in PLATFORMS] + [DIST / "index.json"]
    if not all(path.exists() for path in built):
        return True
    return min(p.stat().st_mtime for p in built) < max(p.stat().st_mtime for p in sources)


def validate() -> None:
    """Validate the manifest in the source tree and every built zip."""
    _extension_cli("validate", REPO)
    for path in zips():
        _extension_cli("validate", path)


def repo() -> None:
    """dist/index.json (and index.html) listing the zips, by Blender's server-generate.

    Upload dist/ as it is to any static web host; in Blender, add a remote repository with
    the URL of index.json to install TexSynth from it and get its updates.
    """
    _extension_cli("server-generate", "--repo-dir", DIST, "--html", tags=False)


def build() -> None:
    """Build one extension zip per platform in dist/, validate them, list them in index.json."""
    download_wheels()
    DIST.mkdir(exist_ok=True)
    for old in DIST.glob("texsynth-*.zip"):
        old.unlink()
    _extension_cli("build", "--source-dir", REPO, "--output-dir", DIST, "--split-platforms")
    validate()
    repo()
    print(f"\nbuilt (budget {ZIP_BUDGET / 2**20:.0f} MiB each):")
    for path in zips():
        size = path.stat().st_size
        print(f"  {path}  {size / 2**20:6.1f} MiB{'  OVER BUDGET' if size > ZIP_BUDGET else ''}")


# --- demo and tests ---------------------------------------------------------------------


def demo() -> None:
    """Run the headless example on the bundled sample; Blender's user files go to .cache/."""
    env = dict(os.environ, BLENDER_USER_RESOURCES=str(REPO / ".cache" / "blender"))
    _run(sys.executable, REPO / "examples" / "synthesize_file.py", SAMPLE,
         "--width", "512", "--height", "512", "--out", OUT, env=env)


def test() -> None:
    """What CI runs: build (the tests install the zip), ruff, the pip package (pip-check),
    pytest in Blender 5.0, then the other Blenders and Python 3.13 of test-compat. Their venvs
    are made once per clone; Blender 5.3 adds about 4.5 minutes to a fresh clone's run (its venv
    2.2, its tests 1.7-2.4, on this 2-core machine under load) and 1.8 minutes once its venv
    exists. A missing Python for one of them stops it before anything runs (``_bases``)."""
    bases = _bases()
    build()
    _run(sys.executable, "-m", "ruff", "check", REPO)
    pip_check()
    _run(sys.executable, "-m", "pytest", "-q", REPO / "tests", cwd=REPO)
    compat(bases)


def pip_check() -> None:
    """The pip package as a user gets it: the checkout's tracked files copied to a temporary
    folder and pip-installed from there (not editable: a module or data file the package
    misses shows) into a fresh venv, with pip's cache; then ``texsynth --version``,
    ``texsynth methods`` and a 64 x 64 ``random_phase`` synthesis of the sample, read back by
    the installed package. Everything runs outside the checkout, which is never imported."""
    with tempfile.TemporaryDirectory(prefix="texsynth-pip-") as tmp:
        tmp = Path(tmp)
        listed = subprocess.run(["git", "ls-files", "-z"], cwd=REPO, capture_output=True,
                                check=True).stdout.decode().split("\0")
        for name in filter(None, listed):
            if (REPO / name).is_file():  # a tracked file deleted in the work tree is not
                (tmp / "src" / name).parent.mkdir(parents=True, exist_ok=True)
                shutil.copy2(REPO / name, tmp / "src" / name)
        _run(sys.executable, "-m", "venv", tmp / "venv")
        python = _venv_python(tmp / "venv")
        env = dict(os.environ, PIP_DISABLE_PIP_VERSION_CHECK="1")
        _run(python, "-m", "pip", "install", "--quiet", "--no-compile", tmp / "src", env=env)
        command = python.parent / ("texsynth.exe" if os.name == "nt" else "texsynth")
        shown = subprocess.run([command, "--version"], capture_output=True, text=True,
                               check=True, cwd=tmp).stdout.strip()
        if shown != f"texsynth {version()}":
            sys.exit(f"pip-check: texsynth --version says {shown!r}, the manifest {version()}")
        _run(command, "methods", cwd=tmp, stdout=subprocess.DEVNULL)
        out = tmp / "o.png"
        _run(command, "--quiet", "synthesize", SAMPLE, "-o", out, "--size", "64", "--method",
             "random_phase", cwd=tmp)
        _run(python, "-c", "import sys; from texsynth.io import read_photo; "
             "shape = read_photo(sys.argv[1]).shape; "
             "sys.exit(None if shape[:2] == (64, 64) else f'{sys.argv[1]} is {shape}')", out,
             cwd=tmp)
        print("pip-check: the pip package installs and its command runs", flush=True)


def _find_python(version: str) -> str | None:
    """A working ``pythonX.Y`` on PATH or installed by pyenv, or None."""
    candidates = [shutil.which(f"python{version}"),
                  *map(str, sorted(Path.home().glob(f".pyenv/versions/{version}.*/bin/python")))]
    for candidate in filter(None, candidates):
        if subprocess.run([candidate, "-c", ""], capture_output=True).returncode == 0:
            return candidate
    return None


def test_compat() -> None:
    """Build, then the Blender tests in each Blender of COMPAT_BPY, and the core tests on the
    newest one's Python and numpy with the bundled wheels for that Python.

    Each runs in its own .venv-*: the Blender ones hold only bpy, the numpy its Blender bundles
    and pytest, so scipy and OpenEXR come from the wheels the installed zip bundles (the
    Blender tests install it before they import anything else).
    """
    bases = _bases()
    build()
    compat(bases)


#: Set by ``--skip-missing`` (kept in the environment across the re-run in .venv).
SKIP_MISSING = "TEXSYNTH_SKIP_MISSING"


def _base_python(version: str, purpose: str) -> str | None:
    """The Python ``version`` to make a venv from. When there is none: exit with one line
    saying what to install (a promised Blender is not skipped quietly, in CI or here), or,
    after ``--skip-missing``, None (skip)."""
    if version == DEV_PYTHON:
        return _python_311()
    found = _find_python(version)
    if found is None:
        missing = f"no Python {version} (python{version} on the PATH, or pyenv's) for {purpose}"
        if not os.environ.get(SKIP_MISSING):
            sys.exit(f"{missing}: install it (pyenv install {version}, or your system's "
                     f"python{version} package), or run again with --skip-missing to skip it")
        print(f"\n--- skipped: {missing}", flush=True)
    return found


def _bases() -> dict[str, str | None]:
    """Python version -> the base Python for its venvs, for every Python test-compat needs
    (checked before anything runs)."""
    purposes = {}
    for bpy_version, (python_version, _) in COMPAT_BPY.items():
        purposes.setdefault(python_version, []).append(f"the Blender tests in bpy {bpy_version}")
    purposes[COMPAT_BPY[NEWEST_BPY][0]].append(f"the core tests on Blender {NEWEST_BPY}'s stack")
    return {python: _base_python(python, " and ".join(uses)) for python, uses in purposes.items()}


def compat(bases: dict[str, str | None]) -> None:
    """The test-compat runs, on the zips already in dist/, from the base Pythons ``bases``
    (``_bases``; None: skipped)."""
    for bpy_version, (python_version, numpy_version) in COMPAT_BPY.items():
        base = bases[python_version]
        if base is None:
            print(f"\n--- skipped: Blender {bpy_version} (no Python {python_version})",
                  flush=True)
            continue
        as_pip = bpy_version == NEWEST_BPY  # numpy as pip resolves it (a new venv: newest)
        python = _ensure_venv(REPO / f".venv-bpy-{bpy_version}{'-pip' if as_pip else ''}",
                              [f"bpy=={bpy_version}",
                               "numpy" if as_pip else f"numpy=={numpy_version}", "pytest",
                               "hypothesis"],  # tests/blender/test_fuzz_followers.py
                              base=base)
        print(f"\n--- Blender {bpy_version} (Python {python_version}, numpy "
              f"{'as pip resolves' if as_pip else numpy_version}) ---", flush=True)
        _run(python, "-m", "pytest", "-q", "-p", "no:cacheprovider", REPO / "tests" / "blender",
             cwd=REPO)
    python_version, numpy_version = COMPAT_BPY[NEWEST_BPY]
    base = bases[python_version]
    if base is None:
        print(f"\n--- skipped: the core tests on Python {python_version}", flush=True)
        return
    python = _ensure_venv(REPO / f".venv-py{python_version}",
                          [f"numpy=={numpy_version}", "pytest", "hypothesis",
                           "pillow",  # the pip package's JPEG reader: test_plane_photos, test_cli
                           *_wheels_here(python_version)],
                          base=base)
    print(f"\n--- core on Python {python_version}, numpy {numpy_version} (Blender "
          f"{NEWEST_BPY}'s), bundled wheels ---", flush=True)
    tests = REPO / "tests"
    _run(python, "-m", "pytest", "-q", "-p", "no:cacheprovider", tests, "--ignore",
         tests / "blender", "--ignore", tests / "test_distribution.py", cwd=REPO)


def _wheels_here(python: str) -> list[str]:
    """The bundled wheels for ``python`` on this system (absolute paths)."""
    blender_ext = _blender_ext()
    here = blender_ext.platform_from_this_system()
    keys = {path: wheel_key(Path(path).name, blender_ext) for path in _manifest_wheels()}
    return [str(REPO / path) for path, (_, _, py, platforms) in keys.items()
            if serves(py, python) and here in platforms]


COMMANDS = {"setup": setup, "build": build, "validate": validate, "repo": repo, "demo": demo,
            "test": test, "test-compat": test_compat, "pip-check": pip_check}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("command", choices=COMMANDS)
    parser.add_argument("--skip-missing", action="store_true",
                        help="test, test-compat: skip the Blenders whose Python is missing "
                             "(default: stop, naming it)")
    args = parser.parse_args()
    command = args.command
    if args.skip_missing:
        os.environ[SKIP_MISSING] = "1"
    if command in ("test", "test-compat") and not os.environ.get(SKIP_MISSING):
        _bases()  # a missing Python stops it before the set-up too
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

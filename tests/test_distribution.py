"""The built zips and repository listing, as a user or a hosting team gets them (no bpy).

The zips are built first when missing or older than the sources (``addon_build.py build``).
"""

import hashlib
import importlib.util
import json
import re
import subprocess
import sys
import tomllib
import zipfile
from pathlib import Path

import pytest

import addon_build

ALLOWED = re.compile(r"blender_manifest\.toml|LICENSE|__init__\.py|dependencies\.py|versions\.py"
                     r"|operators/([a-z_]+/)?[a-z_]+\.py|texsynth/([a-z_]+/)*[a-z_]+\.py|wheels/[^/]+\.whl")


@pytest.fixture(scope="module")
def zips():
    """Blender platform -> (zip path, the zip's manifest with [build.generated] applied)."""
    if addon_build.build_is_stale():
        subprocess.run([sys.executable, str(addon_build.REPO / "addon_build.py"), "build"],
                       check=True)
    found = {}
    for platform in addon_build.PLATFORMS:
        path = addon_build.extension_zip(platform)
        with zipfile.ZipFile(path) as archive:
            manifest = tomllib.loads(archive.read("blender_manifest.toml").decode())
        manifest.update(manifest["build"].pop("generated"))
        found[platform] = path, manifest
    return found


def test_every_zip_and_the_source_pass_blenders_validator(zips):
    run = subprocess.run([sys.executable, str(addon_build.REPO / "addon_build.py"), "validate"],
                         capture_output=True, text=True)
    assert run.returncode == 0, run.stdout + run.stderr
    assert run.stdout.count("Success parsing TOML") == 1 + len(addon_build.PLATFORMS)


def test_each_zip_holds_the_wheels_of_its_platform_for_both_pythons_unmodified(zips):
    bundled = addon_build.bundled()
    for platform, (path, manifest) in zips.items():
        assert manifest["platforms"] == [platform]
        with zipfile.ZipFile(path) as archive:
            in_zip = sorted(n for n in archive.namelist() if n.startswith("wheels/"))
            assert sorted(w.removeprefix("./") for w in manifest["wheels"]) == in_zip
            for name in in_zip:
                cached = (addon_build.REPO / name).read_bytes()
                assert hashlib.sha256(archive.read(name)).digest() == \
                    hashlib.sha256(cached).digest(), name
        keys = [addon_build.wheel_key(name.removeprefix("wheels/")) for name in in_zip]
        assert all(platform in platforms for *_, platforms in keys), (platform, in_zip)
        # Each bundled release for each Python, served by its own wheel or a pure-Python one.
        served = sorted((package, release, python) for package, release, wheel_python, _ in keys
                        for python in ("3.11", "3.13")
                        if addon_build.serves(wheel_python, python))
        assert served == sorted((package.lower(), release, python)
                                for package, releases in bundled.items()
                                for python, release in releases.items()), platform
        assert len(keys) == len(set(in_zip))
        assert not any(name.startswith("wheels/numpy") for name in in_zip)


def test_the_zips_hold_only_the_extension(zips):
    for path, _ in zips.values():
        with zipfile.ZipFile(path) as archive:
            names = archive.namelist()
        strays = [n for n in names if not ALLOWED.fullmatch(n)]
        assert not strays, f"{path.name} holds files users do not need: {strays}"
        assert {"__init__.py", "dependencies.py", "LICENSE", "operators/__init__.py",
                "texsynth/__init__.py"} <= set(names)


def test_every_zip_is_within_the_size_budget(zips):
    sizes = {path.name: path.stat().st_size for path, _ in zips.values()}
    over = {name: f"{size / 2**20:.1f} MiB" for name, size in sizes.items()
            if size > addon_build.ZIP_BUDGET}
    assert not over, f"over {addon_build.ZIP_BUDGET >> 20} MiB: {over}"


def test_the_repository_listing_offers_every_zip_for_its_platform(zips):
    listing = json.loads((addon_build.DIST / "index.json").read_text())
    assert listing["version"] == "v1" and listing["blocklist"] == []
    entries = {entry["platforms"][0]: entry for entry in listing["data"]}
    assert sorted(entries) == sorted(zips)
    for platform, (path, manifest) in zips.items():
        entry = entries[platform]
        assert entry["archive_url"] == f"./{path.name}"
        assert entry["archive_size"] == path.stat().st_size
        assert entry["archive_hash"] == "sha256:" + hashlib.sha256(path.read_bytes()).hexdigest()
        assert entry["python_versions"] == ["3.11", "3.13"]
        for key in ("id", "version", "blender_version_min", "license", "permissions"):
            assert entry[key] == manifest[key], key
    assert (addon_build.DIST / "index.html").is_file()


def test_the_manifest_is_complete():
    manifest = tomllib.loads(addon_build.MANIFEST.read_text())
    assert manifest["blender_version_min"] == "4.2.13"
    assert manifest["license"] == ["SPDX:GPL-3.0-or-later"]
    assert list(manifest["permissions"]) == ["files"]
    for key in ("tagline", "website", "copyright", "tags", "maintainer"):
        assert manifest[key], key


def _blender_dedup():
    """The rule by which Blender picks one wheel per package name among the wheels of its own
    Python (4.2.13 on filter them first); read from the bpy 5.0 wheel."""
    scripts = addon_build._bl_pkg_scripts()
    spec = importlib.util.spec_from_file_location(
        "wheel_manager", scripts / "modules" / "_bpy_internal" / "extensions" /
        "wheel_manager.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module.wheel_list_deduplicate_as_skip_set


def test_each_python_gets_its_own_bundled_release_of_every_package(zips):
    skip = _blender_dedup()
    bundled = addon_build.bundled()
    for platform, (_, manifest) in zips.items():
        for python in ("3.11", "3.13"):
            wheels = [w for w in manifest["wheels"]
                      if addon_build.serves(addon_build.wheel_key(Path(w).name)[2], python)]
            kept = [w for w in wheels if w not in skip([("texsynth", wheels)])]
            releases = {Path(w).name.split("-")[0]: Path(w).name.split("-")[1] for w in kept}
            assert releases == {package.lower(): release[python]
                                for package, release in bundled.items()}, (platform, python)


def test_the_bundled_wheels_support_the_numpy_of_every_blender_the_tests_run_in(zips):
    # SciPy warns at import when numpy is outside the range its wheel declares; each Blender of
    # addon_build.COMPAT_BPY is tested with the numpy it ships.
    _, manifest = zips["linux-x64"]
    checked = []
    for bpy_version, (python, numpy_version) in addon_build.COMPAT_BPY.items():
        for wheel in manifest["wheels"]:
            if not addon_build.serves(addon_build.wheel_key(Path(wheel).name)[2], python):
                continue
            with zipfile.ZipFile(addon_build.REPO / wheel) as archive:
                (metadata,) = [n for n in archive.namelist()
                               if n.endswith(".dist-info/METADATA")]
                text = archive.read(metadata).decode()
            spec = addon_build.requirement(text, "numpy")
            if spec is not None:
                assert addon_build.satisfies(numpy_version, spec), (bpy_version, wheel, spec)
                checked.append(Path(wheel).name.split("-")[0])
    assert sorted(set(checked)) == ["openexr", "scipy"]


def test_version_comparisons_read_as_pip_reads_them():
    assert addon_build.requirement("Requires-Dist: numpy<2.5,>=1.23.5\n"
                                   'Requires-Dist: numpydoc; extra == "doc"', "numpy") \
        == "<2.5,>=1.23.5"
    assert addon_build.requirement('Requires-Dist: numpydoc; extra == "doc"', "numpy") is None
    assert addon_build.satisfies("2.3.4", "<2.5,>=1.23.5")
    assert addon_build.satisfies("1.23.5", "<2.5,>=1.23.5")
    assert not addon_build.satisfies("2.5.5", "<2.5,>=1.23.5")
    assert not addon_build.satisfies("2.5.0", "<2.5,>=1.23.5")
    assert not addon_build.satisfies("1.23.4", "<2.5,>=1.23.5")
    assert addon_build.satisfies("2.10.0", ">=2.9")
    assert not addon_build.satisfies("2.5", "<2.5.0") and addon_build.satisfies("2.5", "<=2.5.0")
    with pytest.raises(ValueError, match="no comparisons"):
        addon_build.satisfies("2.3.4", "")

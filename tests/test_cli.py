"""The ``texsynth`` command as a user meets it: files in, files out, one-line errors, exit codes."""

import io
import json
import subprocess
import sys
import tomllib
from pathlib import Path

import numpy as np
import pytest
from scipy.ndimage import gaussian_filter

import texsynth
from texsynth import cli
from texsynth.blocks.color import srgb_to_linear
from texsynth.io import read_exr, read_png, write_image, write_png
from texsynth.metrics import seam_ratio

from _images import ramp_photo

REPO = Path(__file__).resolve().parents[1]
#: Two-sided: an output whose wrap is smoother than its inside is as wrong as one with a line.
SEAM = (0.7, 1.4)


@pytest.fixture()
def photo(tmp_path):
    path = tmp_path / "wall.png"
    write_png(path, ramp_photo((80, 96)), bits=16)
    assert seam_ratio(read_png(path)) > 2  # the photo itself does not tile
    return path


def _run(capsys, *argv):
    code = cli.main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return code, out, err


def test_synthesize_writes_a_tiling_png_of_the_size_asked(tmp_path, photo, capsys):
    out = tmp_path / "out" / "tex.png"
    code, stdout, _ = _run(capsys, "-q", "synthesize", photo, "-o", out, "--size", "112x64")
    assert code == 0 and f"wrote {out}" in stdout
    result = read_png(out)
    assert result.shape == (64, 112, 3)
    assert SEAM[0] <= seam_ratio(result) <= SEAM[1]
    with open(out, "rb") as f:
        assert f.read(25)[24] == 16  # the input's bit depth


def test_same_seed_same_bytes_other_seed_other_texture(tmp_path, photo, capsys):
    paths = [tmp_path / f"{name}.png" for name in ("a", "b", "c")]
    for path, seed in zip(paths, (3, 3, 4), strict=True):
        assert _run(capsys, "-q", "synthesize", photo, "-o", path, "--size", "64",
                    "--method", "heeger_bergen", "--seed", seed, "--scales", 2)[0] == 0
    assert paths[0].read_bytes() == paths[1].read_bytes()
    assert paths[0].read_bytes() != paths[2].read_bytes()


def test_exr_out_holds_linear_colour(tmp_path, photo, capsys):
    common = ["-q", "synthesize", photo, "--size", "64", "--method", "heeger_bergen",
              "--scales", "2", "--bits", "16"]
    assert _run(capsys, *common, "-o", tmp_path / "t.png")[0] == 0
    assert _run(capsys, *common, "-o", tmp_path / "t.exr")[0] == 0
    encoded, linear = read_png(tmp_path / "t.png"), read_exr(tmp_path / "t.exr")
    assert linear.dtype == np.float32 and linear.shape == (64, 64, 3)
    np.testing.assert_allclose(linear, srgb_to_linear(np.clip(encoded, 0, 1)), atol=2e-4)


def test_tile_keeps_the_size_and_other_maps_follow(tmp_path, photo, capsys):
    normal = tmp_path / "wall_normal.png"
    normal.write_bytes(photo.read_bytes())  # a map that is the photo: must follow exactly
    out = tmp_path / "out" / "tiled.png"
    code, stdout, _ = _run(capsys, "-q", "tile", photo, "-o", out, "--maps", normal)
    assert code == 0
    result, follower = read_png(out), read_png(out.with_name("wall_normal.png"))
    assert result.shape == read_png(photo).shape
    # A ramp across the photo: its level must turn back within the band (the photo beyond it
    # is kept), which the plain seam ratio reads (a band of 16 on 96 px: the turn is 5x the
    # ramp's slope, about 1.4 by itself; this one 1.5). High-passed at a quarter band, the
    # band holds no step: 1.0 across it (1.8 when the cuts kept the ramp's step, before the
    # band's level was corrected).
    detail = result - gaussian_filter(result, (4, 4, 0), mode="wrap")
    across = np.mean([seam_ratio(np.roll(detail, (k, k), axis=(0, 1))) for k in range(-8, 8)])
    assert 0.9 <= across <= 1.1
    assert SEAM[0] <= seam_ratio(result) <= 1.6
    np.testing.assert_array_equal(follower, result)


@pytest.mark.parametrize("argv, code, named", [
    (["synthesize", "{tmp}/missing.png", "-o", "{tmp}/new/o.png"], 3, "missing.png"),
    (["synthesize", "{photo}", "-o", "{tmp}/o.webp"], 2, "o.webp"),
    (["synthesize", "{photo}", "-o", "{tmp}/o.png", "--method", "heeger_bergen", "--radius", "2"],
     2, "--radius"),
    (["synthesize", "{photo}", "-o", "{tmp}/o.png", "--method", "heeger_bergen", "--scales",
      "30"], 2, "scales"),
    (["synthesize", "{photo}", "-o", "{photo}"], 2, "overwrite"),
    (["synthesize", "{photo}", "-o", "{tmp}/sub/o.png", "--method", "heeger_bergen", "--maps",
      "{photo}"], 2, "--maps"),
    (["tile", "{photo}", "-o", "{tmp}/o.png", "--band", "1000"], 2, "band"),
    (["estimate", "{tmp}/missing.png"], 3, "missing.png"),
])
def test_bad_input_exits_with_one_line_naming_it_and_writes_nothing(
        tmp_path, photo, capsys, argv, code, named):
    before = sorted(tmp_path.rglob("*"))
    argv = [a.format(tmp=tmp_path, photo=photo) for a in argv]
    got, _, err = _run(capsys, "-q", *argv)
    assert got == code
    assert len(err.strip().splitlines()) == 1 and named in err and "Traceback" not in err
    assert sorted(tmp_path.rglob("*")) == before


def test_the_installed_command_exits_non_zero_without_a_traceback(tmp_path):
    run = subprocess.run([sys.executable, "-m", "texsynth", "tile", str(tmp_path / "no.png"),
                          "-o", str(tmp_path / "o.png")], capture_output=True, text=True,
                         cwd=REPO)
    assert run.returncode == 3
    assert run.stderr.strip() == f"texsynth: error: {tmp_path / 'no.png'}: no such file"


@pytest.mark.parametrize("command", ["synthesize", "batch"])
def test_help_lists_every_method_parameter_and_the_exit_codes(command, capsys):
    with pytest.raises(SystemExit) as done:
        cli.main([command, "--help"])
    assert done.value.code == 0
    text = capsys.readouterr().out
    for method in texsynth.methods():
        assert method.name in text
        for p in method.params:
            assert "--" + p.name.replace("_", "-") in text, (method.name, p.name)
    assert "exit codes" in text and "130" in text


def test_every_subcommand_has_help(capsys):
    for command in ("synthesize", "tile", "estimate", "rectify", "batch", "methods"):
        with pytest.raises(SystemExit) as done:
            cli.main([command, "--help"])
        assert done.value.code == 0 and "usage: texsynth " + command in capsys.readouterr().out


def test_methods_json_is_the_registry(capsys):
    code, out, _ = _run(capsys, "methods", "--json")
    listing = json.loads(out)
    assert code == 0
    assert [m["name"] for m in listing] == [m.name for m in texsynth.methods()]
    assert [p["name"] for p in listing[0]["params"]] == [p.name for p in
                                                         texsynth.methods()[0].params]


def test_estimate_prints_the_plane_as_json(tmp_path, capsys):
    path = tmp_path / "flat.png"
    write_image(path, ramp_photo((96, 96)))
    code, out, _ = _run(capsys, "-q", "estimate", path, "--method", "isotropy")
    plane = json.loads(out)
    assert code == 0 and 0 <= plane["slant"] < 90 and plane["focal_from"] == "none (orthographic)"


def test_rectify_writes_the_frontal_view(tmp_path, capsys):
    path, out = tmp_path / "flat.png", tmp_path / "frontal.png"
    write_image(path, ramp_photo((96, 96)))
    code, _, _ = _run(capsys, "-q", "rectify", path, "-o", out, "--method", "isotropy")
    assert code == 0 and read_png(out).shape[2] == 3


def test_progress_is_a_bar_with_time_left_on_a_terminal_and_plain_lines_when_piped():
    tty, piped = io.StringIO(), io.StringIO()
    for stream, is_tty in ((tty, True), (piped, False)):
        bar = cli.Bar(stream, tty=is_tty)
        for k in range(41):
            bar(k / 40, f"step {k}")
        bar.close()
    assert tty.getvalue().count("\r") == 41 and "left" in tty.getvalue()
    lines = piped.getvalue().splitlines()
    assert "\r" not in piped.getvalue() and 10 <= len(lines) <= 11
    assert lines[-1].startswith("100%") and "left" in lines[5]


def test_a_failed_write_leaves_no_file(tmp_path):
    target = tmp_path / "t.png"
    target.write_bytes(b"old")
    with pytest.raises(ValueError, match="channels|image"):
        write_image(target, np.zeros((4, 4, 2), np.float32))  # two channels: refused
    assert target.read_bytes() == b"old" and [p.name for p in tmp_path.iterdir()] == ["t.png"]


def test_the_pip_package_is_the_core_with_the_extensions_version():
    project = tomllib.loads((REPO / "pyproject.toml").read_text())
    manifest = tomllib.loads((REPO / "blender_manifest.toml").read_text())
    assert project["project"]["version"] == manifest["version"]
    assert project["project"]["scripts"]["texsynth"] == "texsynth_command:main"
    assert project["tool"]["setuptools"]["py-modules"] == ["texsynth_command"]
    assert project["tool"]["setuptools"]["packages"]["find"]["include"] == ["texsynth",
                                                                            "texsynth.*"]


def test_a_camera_jpeg_is_read_through_pillow(tmp_path, capsys):
    pil = pytest.importorskip("PIL.Image")
    path = tmp_path / "IMG_0001.jpg"
    pixels = np.rint(ramp_photo((72, 88)) * 255).astype(np.uint8)
    pil.fromarray(pixels).save(path, quality=95)
    code, _, _ = _run(capsys, "-q", "tile", path, "-o", tmp_path / "tile.png")
    assert code == 0 and read_png(tmp_path / "tile.png").shape == (72, 88, 3)

"""`texsynth material` and a batch's `material` operation: five tiling maps named as ambientCG
names them, the forecast before the work, one-line refusals before anything is written."""

import numpy as np
import pytest

from texsynth import batch, cli, metrics
from texsynth.io import read_photo, write_png
from texsynth.material.pipeline import SUFFIXES

from _images import ramp_photo

FAST = ["--size", "32", "--skip", "rectify"]


def _run(capsys, *argv):
    code = cli.main([*map(str, argv)])
    out, err = capsys.readouterr()
    return code, out, err


@pytest.fixture()
def photo(tmp_path):
    path = tmp_path / "floor.png"
    write_png(path, ramp_photo((64, 80)))
    return path


def test_a_photo_becomes_five_tiling_maps_after_the_forecast(photo, tmp_path, capsys):
    code, out, err = _run(capsys, "material", photo, "-o", tmp_path / "out", *FAST)
    assert code == 0, err
    assert err.startswith("predicted: about ")
    assert "rectify: left out" in err and "tile: synthesized 32 x 32" in err
    names = [f"floor_{s}.png" for s in SUFFIXES]
    assert out.split() == [w for n in names for w in ("wrote", str(tmp_path / "out" / n))]
    for name in names:
        image = read_photo(tmp_path / "out" / name)
        assert image.shape[:2] == (32, 32) and metrics.seam_ratio(image) < 1.6


def test_refusals_are_one_line_and_write_nothing(photo, tmp_path, capsys):
    write_png(tmp_path / "small.png", np.zeros((16, 16, 3), np.float32))
    write_png(tmp_path / "all.png", np.ones((64, 80, 3), np.float32))
    out = tmp_path / "new" / "out"
    for argv, code, named in [
        (["--mask", tmp_path / "small.png"], 3, "not the photo's 80 x 64"),
        (["--mask", tmp_path / "all.png"], 1, "mask covers the whole photo"),
        (["--corners", "1,2,3"], 2, "--corners must be 8 numbers"),
        (["--skip", "blur"], 2, "invalid choice"),
        (["--format", "jpg"], 2, "invalid choice"),
    ]:
        result, _, err = _run(capsys, "-q", "material", photo, "-o", out, "--size", "32", *argv)
        assert result == code and len(err.strip().splitlines()) == 1 and named in err, err
        assert not (tmp_path / "new").exists()  # not even the folder it made to check


def test_a_mask_in_the_output_folder_is_never_written_over(photo, tmp_path, capsys):
    mask = tmp_path / "floor_NormalGL.png"
    write_png(mask, np.zeros((64, 80, 3), np.float32))
    before = mask.read_bytes()
    code, _, err = _run(capsys, "-q", "material", photo, "-o", tmp_path, "--mask", mask, *FAST)
    assert code == 2 and "would overwrite the input" in err
    assert mask.read_bytes() == before and not (tmp_path / "floor_Color.png").exists()


def test_a_file_already_in_the_output_folder_is_kept(photo, tmp_path, capsys):
    kept = tmp_path / "floor_Roughness.png"
    kept.write_bytes(b"the user's own")
    code, out, err = _run(capsys, "-q", "material", photo, "-o", tmp_path, *FAST)
    assert code == 4 and err.count("\n") == 1 and "exists; nothing was written" in err
    assert kept.read_bytes() == b"the user's own" and not (tmp_path / "floor_Color.png").exists()


def test_a_manifest_plans_material_tasks_and_refuses_maps_on_them(photo, tmp_path):
    (tmp_path / "list.csv").write_text("photo,operation,size,corners\n"
                                       "floor.png,material,32,\"1,1,70,1,70,60,1,60\"\n")
    (job,) = batch.plan(tmp_path / "list.csv", tmp_path / "out")
    assert [p.rsplit("/", 1)[1] for p in job.outputs] == [
        f"floor_material_32x32_s0_{s}.png" for s in SUFFIXES]
    assert dict(job.params)["corners"] == (1, 1, 70, 1, 70, 60, 1, 60)
    (tmp_path / "maps.csv").write_text("photo,maps,operation\nfloor.png,floor.png,material\n")
    with pytest.raises(batch.UsageError, match="maps.csv:2: maps: a material derives"):
        batch.plan(tmp_path / "maps.csv", tmp_path / "out")


def test_an_exr_photo_is_delit_as_the_linear_light_it_holds(tmp_path, capsys):
    """An EXR holds linear light: delight divides the light out of its values as they are
    (encoded=False), not of an sRGB decoding of them; the Color EXR is that, linear."""
    from texsynth.io import write_image
    from texsynth.material import delight

    lit = ramp_photo((48, 64))
    write_image(tmp_path / "floor.exr", lit)
    code, _, err = _run(capsys, "material", tmp_path / "floor.exr", "-o", tmp_path / "out",
                        "--skip", "rectify", "tile", "maps")
    assert code == 0, err
    colour = read_photo(tmp_path / "out" / "floor_Color.exr")[:, :, :3]
    assert np.abs(colour - delight(lit, encoded=False)).max() < 1e-3
    assert np.abs(colour - delight(lit, encoded=True)).max() > 1e-2

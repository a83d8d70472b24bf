"""The plane from a rectangle the user marks (issue 42): the projected corners of a square give
the plane within 2 deg with the focal length given, and the focal length within 5 % when it is
not; a parallelogram (no vanishing point) is an honest error with the focal length unknown."""

import numpy as np
import pytest
from _planes import normal_error

from texsynth.plane import from_rectangle, plane_to_image, rectify

SHAPE = (768, 1024)  # height, width
FOCAL = 900.0


def corners(slant, tilt, focal, turn=25.0, half=250.0, jitter=0.0, seed=0):
    """Image corners (x right, y down, pixels) of a square turned ``turn`` deg on the plane,
    rounded to whole pixels and moved by ``jitter`` pixels (sd), as a user places them."""
    angle = np.radians(turn + 90.0 * np.arange(4))
    square = half * np.stack([np.cos(angle), np.sin(angle)], axis=1)
    x, y = plane_to_image(square, slant, tilt, focal).T
    h, w = SHAPE
    out = np.stack([x + (w - 1) / 2, (h - 1) / 2 - y], axis=1)
    out += np.random.default_rng(seed).normal(0.0, jitter, out.shape)
    return np.round(out)


@pytest.mark.parametrize("slant, tilt", [(20.0, 90.0), (40.0, 30.0), (60.0, 200.0)])
def test_the_square_gives_the_plane_and_the_focal_length(slant, tilt):
    given = from_rectangle(corners(slant, tilt, FOCAL), SHAPE, focal_px=FOCAL)
    assert normal_error((slant, tilt), (given.slant, given.tilt)) < 2.0
    assert given.method == "rectangle" and not given.tilt_ambiguous_180
    found = from_rectangle(corners(slant, tilt, FOCAL), SHAPE)
    assert found.focal_estimated and abs(found.focal_px / FOCAL - 1.0) < 0.05
    assert normal_error((slant, tilt), (found.slant, found.tilt)) < 2.0


def test_the_stated_uncertainty_covers_a_user_s_placement():
    """Corners placed 2 pixels off (sd): the normal's error within 2.5 of its stated sigmas."""
    for seed in range(5):
        plane = from_rectangle(corners(40.0, 30.0, FOCAL, jitter=2.0, seed=seed), SHAPE,
                               focal_px=FOCAL)
        assert normal_error((40.0, 30.0), (plane.slant, plane.tilt)) \
            < 2.5 * plane.normal_uncertainty


def test_the_corners_may_go_round_either_way():
    c = corners(35.0, 120.0, FOCAL)
    a, b = from_rectangle(c, SHAPE), from_rectangle(c[::-1], SHAPE)
    assert abs(a.slant - b.slant) < 1e-6 and abs(a.focal_px - b.focal_px) < 1e-6


def test_a_parallelogram_gives_no_focal_length():
    """Sides parallel in the image: frontal with the focal length given, an error without."""
    square = np.array([[300.0, 200.0], [700.0, 200.0], [700.0, 600.0], [300.0, 600.0]])
    assert from_rectangle(square, SHAPE, focal_px=FOCAL).slant < 1e-6
    with pytest.raises(ValueError, match="focal_px"):
        from_rectangle(square, SHAPE)


@pytest.mark.parametrize("bad", [np.zeros((3, 2)), [[0, 0], [1, 1], [2, 2], [3, 3]],
                                 [[0, 0], [1, 0], [np.nan, 1], [0, 1]]])
def test_corners_that_mark_no_rectangle_are_refused(bad):
    with pytest.raises(ValueError):
        from_rectangle(bad, SHAPE, focal_px=FOCAL)


def test_rectify_takes_the_rectangle_s_plane():
    """The plane record is the estimate's: rectify uses it as it is."""
    image = np.random.default_rng(0).random(SHAPE).astype(np.float32)
    plane = from_rectangle(corners(30.0, 90.0, FOCAL), SHAPE, focal_px=FOCAL)
    assert rectify(image, plane).ndim == 3


def test_the_command_takes_the_corners(tmp_path, capsys):
    """texsynth estimate --corners: the rectangle's plane as JSON; a wrong count is an error."""
    import json

    from texsynth import cli
    from texsynth.io import write_image

    path = tmp_path / "photo.png"
    write_image(path, np.random.default_rng(0).random((*SHAPE, 3)).astype(np.float32))
    text = ",".join(f"{v:g}" for v in corners(40.0, 30.0, FOCAL).ravel())
    assert cli.main(["-q", "estimate", str(path), "--corners", text]) == 0
    plane = json.loads(capsys.readouterr().out)
    assert plane["method"] == "rectangle" and abs(plane["focal_px"] / FOCAL - 1.0) < 0.05
    assert cli.main(["-q", "estimate", str(path), "--corners", "1,2,3"]) != 0
    assert "--corners must be 8 numbers" in capsys.readouterr().err


def test_the_command_warns_of_a_guess(tmp_path, capsys):
    """White noise shows no plane: the estimate is a guess, and the command says so."""
    from texsynth import cli
    from texsynth.io import write_image

    path = tmp_path / "noise.png"
    write_image(path, np.random.default_rng(0).random((96, 96, 3)).astype(np.float32))
    assert cli.main(["-q", "estimate", str(path)]) == 0
    assert "the plane is a guess" in capsys.readouterr().err

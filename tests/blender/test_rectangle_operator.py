"""Plane from Rectangle headless (issue 42): the corners of a square the user places give the
plane, Align Camera and Rectify use it, and corners that give no plane change nothing."""

import math

import bpy
import numpy as np
import pytest
from scenes import generated_image

from tests._planes import normal_error
from texsynth.plane import plane_to_image

SLANT, TILT, FOCAL = 40.0, 60.0, 500.0
W, H = 320, 240


def _corners(slant=SLANT, tilt=TILT, focal=FOCAL):
    angle = np.radians(20.0 + 90.0 * np.arange(4))
    x, y = plane_to_image(90.0 * np.stack([np.cos(angle), np.sin(angle)], axis=1),
                          slant, tilt, focal).T
    return [float(v) for v in np.stack([x + (W - 1) / 2, (H - 1) / 2 - y], axis=1).ravel()]


@pytest.fixture
def photo():
    pixels = np.random.default_rng(0).random((H, W, 1)).astype(np.float32)
    return generated_image(pixels, name="photo")


def test_the_rectangle_s_plane_is_stored_and_used(photo):
    assert bpy.ops.texsynth.plane_from_rectangle(image="photo", corners=_corners()) \
        == {"FINISHED"}
    settings = bpy.context.scene.texsynth.plane
    assert settings.has_estimate and settings.from_rectangle
    assert settings.focal_source == "ESTIMATED"
    assert settings.focal_px == pytest.approx(FOCAL, rel=0.01)
    got = (math.degrees(settings.slant), math.degrees(settings.tilt))
    assert normal_error((SLANT, TILT), got) < 0.5
    assert list(settings.corners) == pytest.approx(_corners(), abs=1e-3)
    assert bpy.ops.texsynth.align_camera() == {"FINISHED"}
    assert bpy.ops.texsynth.rectify() == {"FINISHED"}
    assert settings.rectified in bpy.data.images


def test_a_parallelogram_without_a_focal_length_changes_nothing(photo):
    square = [60.0, 40.0, 260.0, 40.0, 260.0, 200.0, 60.0, 200.0]
    with pytest.raises(RuntimeError, match="focal"):
        bpy.ops.texsynth.plane_from_rectangle(image="photo", corners=square)
    assert not bpy.context.scene.texsynth.plane.has_estimate

"""Line families against a plane hypothesis: residuals in the image's own noise, and the test
of whether two families are orthogonal on the plane (texsynth.plane.lines, .combine)."""

import math

import numpy as np
import pytest
from _planes import brick_texture, photograph, rhombus_texture

from texsynth.plane import lines, spectra
from texsynth.plane.combine import orthogonality_z
from texsynth.plane.geometry import gradient


def _families(photo):
    small, _ = spectra.downsample(spectra.luminance(photo))
    side = float(max(small.shape))
    return lines.families(lines.segments(small, spectra.texture_mask(small)), side)


def test_a_steep_slant_does_not_explain_converging_joints():
    """At a slant near 90 deg every direction back-projects close to the tilt, so plane-angle
    residuals vanish; measured in the image they do not. The true plane must cost less than
    any steep one (on tiles, 35 mm, slant 59, a steep orthographic plane won and the families
    were dropped: focal length 78 % off; these 96 x 48 bricks did the same)."""
    slant, tilt, focal = 59.0, 185.0, 300.0
    cost = lines.LineCost(_families(photograph(brick_texture(brick=(96, 48)), slant, tilt,
                                               focal)))
    p = gradient(slant, tilt)
    true = cost(p, p / focal)
    for steep_tilt in np.arange(0.0, 360.0, 15.0):
        q = gradient(85.0, steep_tilt)
        for f in (focal, 3.0 * focal, np.inf):
            assert cost(q, q / f) > 2.0 * true, (steep_tilt, f)


@pytest.mark.parametrize("slant, tilt, focal", [(50.0, 120.0, 300.0), (40.0, 250.0, 260.0)])
def test_orthogonality_is_tested_on_the_plane(slant, tilt, focal):
    """With the focal length known, two finite vanishing points fix the plane: rhombic cells
    (families 63 deg apart) fail the test by many sigmas, bricks (90 deg) pass it."""
    p = gradient(slant, tilt)

    def z(texture):
        cost = lines.LineCost(_families(photograph(texture, slant, tilt, focal)))
        assert len(cost.families) == 2
        cost.calibrate(p, p / focal)

        def split(theta):
            return np.asarray(theta), np.asarray(theta) / focal

        return orthogonality_z(cost, lambda th: 0.5 * cost(*split(th)), split, p)

    assert z(brick_texture()) < 3.0
    assert z(rhombus_texture()) > 6.0
    assert math.isfinite(z(rhombus_texture()))

"""Line families against a plane hypothesis: residuals in the image's own noise, and the test
of whether two families are orthogonal on the plane (texsynth.plane.lines, .combine)."""

import numpy as np
import pytest
from _planes import (
    brick_texture,
    normal_error,
    photograph,
    rhombus_texture,
    rough_brick_texture,
)

from texsynth.plane import estimate_plane, lines, normal_from_angles, spectra
from texsynth.plane.combine import _ORTHOGONAL_Z, orthogonality_chi2
from texsynth.plane.geometry import gradient
from texsynth.plane.search import minimize

#: A NaN or an overflow in the estimate is garbage on its way out (issue 27): an error here.
pytestmark = pytest.mark.filterwarnings("error::RuntimeWarning")


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
    """With the focal length known, two finite vanishing points fix the plane: imposing
    orthogonality on rhombic cells (families 63 deg apart) costs many sigmas, on bricks (90 deg)
    next to nothing."""
    def chi2(texture):
        cost = lines.LineCost(_families(photograph(texture, slant, tilt, focal)), False)
        assert len(cost.families) == 2
        p = gradient(slant, tilt)
        cost.calibrate(p, p / focal)

        def fit():
            return minimize(lambda q: 0.5 * cost(q, q / focal), [p], np.array([0.05, 0.05])).fun

        free = fit()
        cost.orthogonal = True
        return orthogonality_chi2(free, fit())

    assert chi2(brick_texture()) < _ORTHOGONAL_Z ** 2
    assert chi2(rhombus_texture()) > 4.0 * _ORTHOGONAL_Z ** 2


def test_rhombic_cells_give_the_plane_with_the_focal_length():
    """Non-orthogonal families still fix the vanishing line; with the focal length that is the
    plane (the orthogonality they lack is not imposed)."""
    slant, tilt, focal = 60.0, 20.0, 280.0
    result = estimate_plane(photograph(rhombus_texture(), slant, tilt, focal), focal_px=focal)
    assert result.line_families == 2 and not result.tilt_ambiguous_180
    n = np.array(result.normal)
    assert np.degrees(np.arccos(min(1.0, n @ normal_from_angles(slant, tilt)))) < 2.0


def test_irregular_shaded_joints_give_both_families():
    """Mortar as a photo shows it (issue 27): grey joints about as bright as the red bricks,
    wandering, 2-5 pixels wide, a fifth of the head joints closed, under a shading gradient.
    Step edges in luminance left no family the estimate could use; the joints' centre lines in
    luminance and chroma give both, and with them the plane."""
    slant, tilt, focal = 45.0, 60.0, 400.0
    texture = rough_brick_texture(brick=(96, 32))
    photo = np.stack([photograph(texture[..., c], slant, tilt, focal) for c in range(3)],
                     axis=-1) - 0.5
    lum = spectra.luminance(photo)
    small, k = spectra.downsample(lum)
    mask = spectra.texture_mask(small)
    side = float(max(small.shape))
    assert len(lines.families(lines.fine_segments(lum, small, k, mask), side)) < 2  # edges
    found = lines.families(lines.fine_segments(lum, small, k, mask, photo, ridges=True), side)
    assert len(found) == 2
    assert len(lines.photo_families(lum, small, k, mask, photo)) == 2
    for given in (None, focal):
        result = estimate_plane(photo, focal_px=given)
        assert result.line_families == 2, given
        assert normal_error((slant, tilt), (result.slant, result.tilt)) < 2.0, given

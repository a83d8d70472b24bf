"""The lens prior (issue 27): with the focal length unknown, parallel lines cannot tell a frontal
photo from a slanted telephoto one; photos come from lenses of 13-200 mm (35 mm equivalent), and
under that prior a frontal photo of bricks reads frontal, measured. An orthographic render lies
beyond the prior: a slanted one must not be called frontal.
"""

import math

import pytest
from _planes import brick_texture, normal_error, photograph

from texsynth.plane import estimate_plane, verdict

#: A NaN or an overflow is how a textured photo came to be refused: an error here.
pytestmark = pytest.mark.filterwarnings("error::RuntimeWarning")

COVER_80 = math.sqrt(math.log(5.0))  # the normal's error is within this many sigmas on 80 %


@pytest.fixture(scope="module")
def bricks():
    return brick_texture()


def test_a_frontal_photo_of_bricks_reads_frontal_under_the_lens_prior(bricks):
    result = estimate_plane(photograph(bricks, 0.0, 0.0, 300.0))  # no focal length given
    assert result.slant <= 5.0 and result.confidence >= 0.5, (result.slant, result.confidence)
    assert result.lens_prior and result.line_families == 2
    said = verdict(result)
    assert not said.guess and not said.slant_measured
    assert said.summary == "Measured under a lens prior (13-200 mm equivalent): frontal"


def test_a_nearly_frontal_perspective_photo_is_covered_by_its_uncertainty(bricks):
    """3 deg of slant at a 300 px lens (about 50 mm equivalent): under the prior the lines'
    slight convergence could be up to 4 times that slant (200 mm); the stated uncertainty spans
    the prior's lenses and covers the truth."""
    result = estimate_plane(photograph(bricks, 3.0, 50.0, 300.0))
    error = normal_error((3.0, 50.0), (result.slant, result.tilt), mod180=True)
    assert error <= COVER_80 * result.normal_uncertainty, (error, result.normal_uncertainty)


@pytest.mark.parametrize(("slant", "tilt"), [(40.0, 30.0), (30.0, 0.0), (50.0, 120.0)])
def test_a_slanted_orthographic_view_is_not_called_frontal(bricks, slant, tilt):
    """An orthographic render is the telephoto extreme, beyond the prior: its families stay
    parallel, but they are not orthogonal in the image, so the prior does not hold."""
    result = estimate_plane(photograph(bricks, slant, tilt))
    assert not result.lens_prior
    assert not (result.slant <= 5.0 and result.confidence >= 0.5)
    assert not verdict(result).summary.startswith("Measured under a lens prior")

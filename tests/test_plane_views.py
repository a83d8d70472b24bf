"""Which line families a view's estimate may rest on (issue 27, rendered views of real photos):
the plane's own outline against what lies beyond it is a line of the plane but of neither
family, and must not make one."""

import numpy as np
import pytest
from _planes import normal_error, photograph, rough_brick_texture

from texsynth.plane import estimate_plane

#: A NaN or an overflow in the estimate is garbage on its way out (issue 27): an error here.
pytestmark = pytest.mark.filterwarnings("error::RuntimeWarning")


def test_the_planes_outline_makes_no_family():
    """Bricks at slant 45 with a corner of black world beyond the plane's edge (as the plane
    section's renders and a wall's end in a photo show it), the edge at 27 deg to the bed
    joints. The edge is long and strong, so the head joints' family took it and read the view
    20 deg off with the focal length unknown (and dropped both families with it known); with
    lines sought only away from untextured regions, both families are the joints and give
    the plane."""
    slant, tilt, focal = 45.0, 60.0, 400.0
    texture = rough_brick_texture(brick=(96, 32))
    photo = np.stack([photograph(texture[..., c], slant, tilt, focal) for c in range(3)],
                     axis=-1) - 0.5
    y, x = np.mgrid[0:photo.shape[0], 0:photo.shape[1]]
    centre = (photo.shape[0] - 1) / 2
    photo[(x - centre) + 0.5 * (centre - y) > 40] = 0.0  # beyond the plane's edge: black
    photo = np.clip(photo, 0.0, 1.0)
    for given in (None, focal):
        result = estimate_plane(photo, focal_px=given)
        assert result.line_families == 2, given
        assert normal_error((slant, tilt), (result.slant, result.tilt)) < 3.0, given

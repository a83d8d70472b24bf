"""A frontal brick wall whose bricks' own shape reads as slant (issue 27, focal length unknown).

The texture's homogeneity finds no perspective, so its fit is the orthographic isotropy one:
the fourth-order moment reads the bricks' elongation as a slant (the shared brick_wall.png
photo: 51 deg). Its two joint families stay parallel under every lens of the prior, which says
frontal; before, the isotropy slant ruled the lines out and the estimate read 28-51 deg with no
line family used.
"""

import math

import numpy as np
import pytest
from _planes import photograph, rough_brick_texture

from texsynth.plane import estimate_plane, verdict

pytestmark = pytest.mark.filterwarnings("error::RuntimeWarning")

COVER_80 = math.sqrt(math.log(5.0))  # the normal's error is within this many sigmas on 80 %


@pytest.mark.parametrize(("seed", "brick"), [(2, (64, 24)), (1, (128, 24)), (2, (128, 24))])
def test_a_frontal_wall_of_long_bricks_reads_frontal_from_its_lines(seed, brick):
    """A frontal photo (512 px, 26 mm-equivalent lens), focal length unknown: both families
    enter under the lens prior, the slant is small and within the stated uncertainty, and the
    verdict says no slant was measured."""
    texture = rough_brick_texture(seed=seed, brick=brick)
    photo = np.stack([photograph(texture[..., c], 0.0, 0.0, 435.0, size=512) for c in range(3)],
                     axis=-1) - 0.5
    result = estimate_plane(np.clip(photo, 0.0, 1.0).astype(np.float32))
    assert result.line_families == 2 and result.lens_prior, result
    assert result.slant <= 10.0, result.slant  # was 28-29 deg, the bricks' shape read as slant
    assert result.slant <= COVER_80 * result.normal_uncertainty
    assert not verdict(result).slant_measured

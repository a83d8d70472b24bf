"""texsynth.blocks.lattice: the period vectors of a regular photo, and no lattice for a
stochastic one."""

import numpy as np
import pytest

from texsynth.blocks.lattice import find

from _images import running_bond, smooth_noise


def _wall(shape=(300, 360), seed=0):
    """Courses of 20 px, bricks of 48, each course half a brick on: its lattice is spanned by
    (20, 24) and (20, -24), whatever the crop."""
    return running_bond(shape, seed, course=20, brick=48, joint=3, tint=(0.9, 0.5, 0.4),
                        shade=(0.5, 0.3), grain=0.1, mortar=(0.15, 0.15, 0.15),
                        speckle=0.04)[0]


@pytest.mark.parametrize("offset", [(0, 0), (7, 13)])
def test_a_running_bond_reads_its_lattice_wherever_it_is_cut(offset):
    wall = _wall()[offset[0]:, offset[1]:]
    lattice = find(wall)
    assert lattice is not None
    # every vector of the lattice read is a whole number of the wall's (within a pixel)
    true = np.array([[20.0, 24.0], [20.0, -24.0]])
    coefficients = lattice.vectors @ np.linalg.inv(true)
    assert np.abs(coefficients - np.rint(coefficients)).max() * 48 <= 1.5
    assert abs(np.linalg.det(lattice.vectors)) == pytest.approx(abs(np.linalg.det(true)), 0.1)
    assert lattice.off(np.array([[40.0, 0.0], [10.0, 0.0]])).round(0).tolist()[0] <= 1


def test_a_stochastic_photo_has_no_lattice():
    assert find(smooth_noise((256, 256), seed=3)) is None
    assert find(np.random.default_rng(0).random((200, 300, 3))) is None

"""An equal spacing is counted over a family's distinct lines, not its pieces (issue 27, rendered
views of real photos at phone resolution): three paver joints found as 29 pieces read as
equally spaced under a wrong horizon, and the two families' right plane gave way to it."""

import numpy as np
import pytest

from texsynth.plane.lines import Segments, horizon_through, spaced_horizon

pytestmark = pytest.mark.filterwarnings("error::RuntimeWarning")

SIDE = 320.0


def horizontal_family(rows, pieces=10, noise=0.0, seed=0):
    """Horizontal lines at image heights ``rows`` (centred y-up pixels), each found as
    ``pieces`` segments 20 pixels long across x in [-150, 150]."""
    rng = np.random.default_rng(seed)
    x = np.linspace(-140.0, 140.0, pieces)
    m = np.array([(xi, y + noise * rng.standard_normal()) for y in rows for xi in x])
    return Segments(m, np.tile([1.0, 0.0], (len(m), 1)), np.full(len(m), 20.0))


def test_three_lines_in_pieces_give_no_spacing():
    """Three unequally spaced joints: a horizon can always be placed that spaces three lines
    equally, so they say nothing of the plane however many pieces they are found in."""
    family = horizontal_family([-60.0, 10.0, 50.0])
    assert spaced_horizon(family, horizon_through(family, SIDE), SIDE) is None


def test_six_equally_spaced_lines_in_pieces_give_their_horizon():
    """Six courses 40 units apart on a plane whose horizon is 600 pixels above the centre
    (v = (0, 1/600)): the spacing is found, and the horizon read within its stated sigma."""
    v_y = 1.0 / 600.0
    plane_rows = -100.0 + 40.0 * np.arange(6)
    rows = plane_rows / (1.0 + v_y * plane_rows)  # y_image = y_plane / (1 + v y_plane)
    family = horizontal_family(rows, noise=0.2)
    found = spaced_horizon(family, horizon_through(family, SIDE), SIDE)
    assert found is not None
    v, cov = found
    assert abs(v[0]) < 1e-6
    assert abs(v[1] - v_y) < max(3.0 * np.sqrt(cov[1, 1]), 0.1 * v_y)

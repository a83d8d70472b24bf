"""The joint network's thinning and dead ends read as Zhang & Suen 1984 and the 8-neighbour count
say, pixel by pixel: the table-driven code (issue 45) against the rule written out."""

import numpy as np
import pytest

from texsynth.blocks import joints


def _around(a):
    """P2..P9 (N, NE, E, SE, S, SW, W, NW) of every pixel, on the torus."""
    steps = ((1, 0), (1, -1), (0, -1), (-1, -1), (-1, 0), (-1, 1), (0, 1), (1, 1))
    return [np.roll(a, step, axis=(0, 1)) for step in steps]


def _zhang_suen(mask):
    """Zhang & Suen 1984, each sub-iteration on every pixel at once, the conditions as written."""
    a = mask.copy()
    while True:
        changed = False
        for step in (0, 1):
            p = _around(a)
            b = np.sum(p, axis=0)
            transitions = np.sum([~p[k] & p[(k + 1) % 8] for k in range(8)], axis=0)
            n, e, s, w = p[0], p[2], p[4], p[6]
            keep = ((n & e & s) | (e & s & w)) if step == 0 else ((n & e & w) | (n & s & w))
            gone = a & (b >= 2) & (b <= 6) & (transitions == 1) & ~keep
            if gone.any():
                a &= ~gone
                changed = True
        if not changed:
            return a


@pytest.mark.parametrize("share", [0.2, 0.5, 0.8])
def test_thinning_and_dead_ends_follow_the_rule_on_every_neighbourhood(share):
    rng = np.random.default_rng(int(share * 10))
    mask = rng.random((40, 56)) < share
    assert np.array_equal(joints.thin(mask), _zhang_suen(mask))
    skeleton = _zhang_suen(mask)
    one = np.sum(_around(skeleton), axis=0) == 1
    assert np.array_equal(joints.ends(skeleton), skeleton & one)


def test_a_wall_thins_to_its_joints_centre_lines():
    i, j = np.mgrid[:64, :96]
    wall = (i % 16 < 4) | ((j + 16 * (i // 16 % 2)) % 32 < 4)
    assert np.array_equal(joints.thin(wall), _zhang_suen(wall))
    assert not joints.ends(joints.thin(wall)).any()  # a closed network on the torus



@pytest.mark.parametrize("shift", [(0, 0), (8, 20), (0, 26), (40, 50)])
def test_dead_ends_on_the_torus_read_the_same_wherever_the_wrap_falls(shift):
    # Bed joints broken every 60 px, tiling: read on the torus the array's edges are no place,
    # so a joint across them neither splits into pieces under MIN_AREA (dropped) nor stops.
    from texsynth import metrics
    i, j = np.mgrid[:96, :120]
    wall = np.where((i % 16 < 3) & (j % 60 < 52), 0.2, 0.7)
    wall += np.random.default_rng(0).normal(0, 0.05, wall.shape)
    rule = joints.Joints.fit(wall, sigma=1.5)
    assert metrics.dead_ends(np.roll(wall, shift, axis=(0, 1)), rule) == pytest.approx(
        metrics.dead_ends(wall, rule))

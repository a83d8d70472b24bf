"""Issue 41: the default method on a wall keeps its joints whole when told their width."""

import numpy as np

from texsynth import metrics, synthesize

from _images import running_bond


def _wall():
    wall, _ = running_bond((192, 256), 0, course=24, brick=56, joint=3, tint=(0.9, 0.5, 0.4),
                           shade=(0.6, 0.4), grain=0.1, mortar=(0.85, 0.85, 0.8), speckle=0.1)
    return wall


def test_multiscale_mrf_told_the_joint_width_leaves_no_circuit_board_of_stubs():
    """A running bond to twice its size: without the joints' width, joints end inside bricks
    (seed 0: 5.4 times the photo's dead ends per joint length); with it (the feature-distance
    channel) the joints meet as in the photo, and the output still shows only photo pixels."""
    wall = _wall()
    out = synthesize(wall, 384, 384, method="multiscale_mrf", seed=0, joint_width=3.0)
    assert metrics.dead_end_ratio(wall, out, 1.5) <= 1.25
    assert np.isin(out.reshape(-1, 3).view("V12"), wall.reshape(-1, 3).view("V12")).all()

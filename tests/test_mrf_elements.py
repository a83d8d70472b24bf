"""Issue 41: the default method on a wall keeps its joints whole, their width measured; a
photo without joints comes out as it did before the joints were measured."""

import numpy as np

from texsynth import metrics, synthesize

from _images import running_bond


def _wall():
    wall, _ = running_bond((192, 256), 0, course=24, brick=56, joint=3, tint=(0.9, 0.5, 0.4),
                           shade=(0.6, 0.4), grain=0.1, mortar=(0.85, 0.85, 0.8), speckle=0.1)
    return wall


def test_multiscale_mrf_by_default_leaves_no_circuit_board_of_stubs():
    """A running bond to twice its size, nothing told: without the joints (feature weight 0)
    joints end inside bricks (seed 0: 5.4 times the photo's dead ends per joint length); by
    default their width is measured and the joints meet as in the photo, and the output still
    shows only photo pixels."""
    wall = _wall()
    out = synthesize(wall, 384, 384, method="multiscale_mrf", seed=0)
    assert metrics.dead_end_ratio(wall, out, 1.5) <= 1.25
    assert np.isin(out.reshape(-1, 3).view("V12"), wall.reshape(-1, 3).view("V12")).all()


def test_a_photo_without_joints_is_synthesized_as_without_the_channel():
    """Gravel-like noise has no joint network: the default output is bit for bit the one with
    the joints left out."""
    noise = np.random.default_rng(3).random((64, 64, 3), dtype=np.float32)
    plain = synthesize(noise, 72, 64, method="multiscale_mrf", seed=2, feature_weight=0.0)
    assert np.array_equal(synthesize(noise, 72, 64, method="multiscale_mrf", seed=2), plain)

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


def test_the_photos_own_dead_ends_are_copied_less(monkeypatch):
    """Six gaps cut in the bed joints (12 dead ends in the photo): left free, the synthesis
    copies each stub's pixel 4.2 times where a photo pixel is copied 3 times (the photo's
    centre is copied most); with ``DEAD_END_COST`` 1.2 times."""
    from texsynth import synthesize_positions
    from texsynth.algorithms import multiscale_mrf as mm
    from texsynth.blocks import feature_distance, joint_repair
    from texsynth.blocks.joints import luma

    monkeypatch.setattr(mm, "LOCK_REPEAT", np.inf)  # the cost alone: copies not locked,
    monkeypatch.setattr(mm, "REPAIR_ROUNDS", 1)  # one round of repair (two: 1.06 left free)
    wall = _wall()
    for r in (49, 97, 145):  # bed joints' middle rows
        for x in (40, 150):
            wall[r - 2:r + 3, x:x + 8] = wall[r + 8:r + 13, x:x + 8]  # brick over the joint
    ends = joint_repair.photo_ends(luma(wall), feature_distance.fit(wall, 0.0, mm.FEATURE_WEIGHT))
    assert ends.sum() == 12

    def copies():
        _, p = synthesize_positions(wall, 384, 384, method="multiscale_mrf", seed=0)
        use = np.zeros(wall.shape[:2])
        np.add.at(use, (p[..., 0].ravel(), p[..., 1].ravel()), 1)
        return use[ends].mean() / use.mean()

    assert copies() < 0.5
    monkeypatch.setattr(mm, "DEAD_END_COST", 0.0)
    assert copies() > 1.2

"""Straight cuts between copies re-cut along their minimum error path (texsynth.blocks.recut):
a cut through the setts moves into a joint, both sides stay verbatim copies inside the
exemplar, and a map without long straight cuts is left as it is."""

import numpy as np
from test_texture_optimization import setts

from texsynth.blocks.recut import recut_straight
from texsynth.blocks.region_shift import regions


def _two_copies(offset_left, offset_right, split, shape=(64, 48)):
    """Two copies side by side (wrapping): columns before ``split`` from exemplar column
    j + offset_left, the rest from j + offset_right; rows from row i + 8."""
    i, j = np.indices(shape)
    return np.stack([i + 8, np.where(j < split, j + offset_left, j + offset_right)], axis=2)


def _setts_cut(pos, stone):
    """Pixels where a copy ends and the next begins between columns 7 and 23 (the middle cut's
    band), stone on both sides (a sett cut in two), and all such cut pixels."""
    after = np.roll(pos, -1, axis=1)
    cut = ~((after[:, :, 0] == pos[:, :, 0]) & (after[:, :, 1] == pos[:, :, 1] + 1))
    both = stone[pos[:, :, 0], pos[:, :, 1]] & stone[after[:, :, 0], after[:, :, 1]]
    return int((cut & both)[:, 7:23].sum()), int(cut[:, 7:23].sum())


def test_a_cut_through_the_setts_moves_into_the_joints():
    ex, stone = setts((96, 96))
    # Two copies of rows 8..71, 32 columns (two setts) apart, meeting mid-sett at column
    # 14 | 15: their joints line up, the cut runs through every row of setts. (The output is
    # narrower than ``run``: its wrap across the rows is not re-cut.)
    pos = _two_copies(22, 54, 15, shape=(64, 30))
    assert _setts_cut(pos, stone) == (52, 64)
    out = recut_straight(ex, pos, run=32, band=8)
    through, cut = _setts_cut(out, stone)
    assert through < 24  # the cut runs along the joints, up, across and down again
    assert cut > 64
    assert regions(out)[0] == regions(pos)[0] == 2  # still two verbatim copies
    assert out.min() >= 0 and out[:, :, 0].max() < 96 and out[:, :, 1].max() < 96


def test_short_cuts_are_left_as_they_are_and_the_input_is_not_changed():
    ex, _ = setts((96, 96))
    i, j = np.indices((40, 40))
    one = np.stack([i + 3, j + 5], axis=2)  # one copy: its only cuts are the wraps, 40 long
    assert np.array_equal(recut_straight(ex, one, run=48), one)
    pos = _two_copies(2, 35, 15, shape=(20, 30))  # cuts 20 and 30 long
    kept = pos.copy()
    assert np.array_equal(recut_straight(ex, pos, run=32), pos)
    assert np.array_equal(pos, kept)


def test_copies_at_the_exemplar_edge_never_leave_it():
    ex, _ = setts((48, 48))
    # The left copy ends 3 columns before the exemplar's last, the right one starts on its
    # third column: a cut may move only 3 and 2 columns their ways.
    pos = _two_copies(21, -22, 24, shape=(40, 48))
    out = recut_straight(ex, pos, run=16, band=12)
    assert not np.array_equal(out, pos)
    assert out.min() >= 0 and out[:, :, 0].max() < 48 and out[:, :, 1].max() < 48

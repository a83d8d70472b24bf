"""Copied regions of a position map slide into phase (texsynth.blocks.region_shift): bricks half
a row off their neighbours line up, every region stays a verbatim copy inside the exemplar."""

import numpy as np
from test_texture_optimization import bricks

from texsynth.blocks.region_shift import _coset, align_regions, lock_lattice, regions


def _rows_carry_on(image, col):
    """Share of rows where the mortar rows (dark over 6 columns) either side of the border
    before column ``col`` agree."""
    strip = np.roll(image, 6 - col, axis=1)[:, :12].mean(axis=2)
    return ((strip[:, :6].mean(axis=1) < 0.3) == (strip[:, 6:].mean(axis=1) < 0.3)).mean()


def test_copies_half_a_row_apart_slide_into_rows():
    ex = bricks((64, 64))
    i, j = np.indices((48, 64))
    # Two copies side by side (wrapping), the right one 4 rows (half a brick row) lower.
    pos = np.stack([i + 4 * (j >= 32) + 2, j % 32 + 8], axis=2)
    before = ex[pos[:, :, 0], pos[:, :, 1]]
    assert _rows_carry_on(before, 32) < 0.8 and _rows_carry_on(before, 0) < 0.8
    out = align_regions(ex, pos, radius=4)
    image = ex[out[:, :, 0], out[:, :, 1]]
    assert _rows_carry_on(image, 32) == 1.0 and _rows_carry_on(image, 0) == 1.0
    assert regions(out)[0] == 2  # each still one verbatim copy
    assert out.min() >= 0 and out[:, :, 0].max() < 64 and out[:, :, 1].max() < 64


def test_one_copy_is_left_as_it_is_and_the_input_is_not_changed():
    ex = bricks((64, 64))
    i, j = np.indices((40, 40))
    pos = np.stack([i + 3, j + 5], axis=2)
    kept = pos.copy()
    assert np.array_equal(align_regions(ex, pos), pos)
    assert np.array_equal(pos, kept)


def test_a_copy_at_the_exemplar_edge_never_moves_out_of_it():
    ex = bricks((64, 64))
    i, j = np.indices((64, 48))
    pos = np.stack([i, j % 24 + 40 * (j >= 24)], axis=2)  # right copy against the right edge
    out = align_regions(ex, pos, radius=3)
    assert out.min() >= 0 and out[:, :, 0].max() < 64 and out[:, :, 1].max() < 64


def test_a_group_of_copies_off_the_rest_follows_the_walk():
    """Four copies side by side (wrapping), the first two in one phase, the last two half a
    row lower: any one of them moving gains at one border what it loses at the other. The walk
    alone (no sweeps), placing them breadth first from the largest, brings the last two in."""
    ex = bricks((64, 64))
    i, j = np.indices((32, 64))
    cols = np.select([j < 20, j < 32, j < 48], [j + 4, j + 10, j - 22], j - 8)
    pos = np.stack([i + 2 + 4 * (j >= 32), cols], axis=2)
    borders = (20, 32, 48, 0)
    image = ex[pos[:, :, 0], pos[:, :, 1]]
    assert min(_rows_carry_on(image, b) for b in borders) < 0.8
    walked = align_regions(ex, pos, radius=4, sweeps=0, walk=True)
    image = ex[walked[:, :, 0], walked[:, :, 1]]
    assert all(_rows_carry_on(image, b) == 1.0 for b in borders)
    assert regions(walked)[0] == 4


def test_on_a_coarse_grid_copies_move_by_whole_steps():
    """A level's grid, neighbours 2 exemplar pixels apart: the right copy, 4 rows (half a
    brick row) off, moves by a multiple of 2 and its rows carry on."""
    ex = bricks((64, 64))
    i, j = np.indices((16, 32))
    pos = np.stack([2 * i + 4 * (j >= 16) + 2, 2 * (j % 16) + 1], axis=2)
    assert regions(pos, step=2)[0] == 2 and regions(pos)[0] == 16 * 32  # at step 1: all apart
    out = align_regions(ex, pos, radius=3, step=2, reach=2)
    assert np.all((out - pos) % 2 == 0)
    image = ex[out[:, :, 0], out[:, :, 1]]
    rows = image[:, [15, 16]].mean(axis=2) < 0.3  # mortar either side of the border
    assert np.array_equal(rows[:, 0], rows[:, 1])


def _bond(shape=(96, 128)):
    """A running bond: courses of 12 px, bricks of 32, each course shifted 16; joints 2 px."""
    i, j = np.indices(shape)
    return np.where((i % 12 < 2) | ((j + 16 * (i // 12)) % 32 < 2), 0.2, 0.8).astype(np.float32)


def _phases(out, step=1):
    i, j = np.indices(out.shape[:2])
    return _coset(out[:, :, 0] - step * i, out[:, :, 1] - step * j, (12, 32, 16))


def test_copies_lock_into_one_phase_broken_once_along_a_row():
    """40 rows (3 1/3 courses) around the torus: one copy carried across the wrap, another 5
    rows and 7 columns off. After the lock every row is in one phase, two phases in all, the
    break one straight row; positions stay inside the exemplar."""
    z = _bond()
    i, j = np.indices((40, 64))
    off = (j >= 20) & (j < 44)
    pos = np.stack([(i + 30) % 40 + 20 + 5 * off, j + 30 + 7 * off], axis=2)  # wraps at row 10
    out = lock_lattice(z, pos, (12, 32, 16))
    phase = _phases(out)
    assert len(np.unique(phase)) == 2 and (phase == phase[:, :1]).all()
    assert (np.diff(phase[:, 0]) != 0).sum() == 1  # one break (the other is the wrap's own)
    assert out.min() >= 0 and out[:, :, 0].max() < 96 and out[:, :, 1].max() < 128


def test_whole_courses_lock_without_a_break_on_a_coarse_grid():
    """48 rows (4 courses) on a grid of step 2: one phase, moves keep the copies whole."""
    z = _bond()
    i, j = np.indices((24, 32))
    off = j >= 16
    pos = np.stack([2 * i + 10 + 3 * off, 2 * j + 20 + 6 * off], axis=2)
    out = lock_lattice(z, pos, (12, 32, 16), step=2)
    assert len(np.unique(_phases(out, 2))) == 1
    assert regions(out, 2)[0] <= regions(pos, 2)[0]

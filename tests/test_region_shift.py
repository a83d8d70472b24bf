"""Copied regions of a position map slide into phase (texsynth.blocks.region_shift): bricks half
a row off their neighbours line up, every region stays a verbatim copy inside the exemplar."""

import numpy as np
from test_texture_optimization import bricks

from texsynth.blocks.region_shift import align_regions, regions


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

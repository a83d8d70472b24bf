"""Straight cuts between copied regions of a position map re-cut along their minimum error path.

A position map made of patches (texture optimisation's non-averaged pass) is a set of verbatim
copies. Where two copies meet along a straight line of the output (a row or column boundary
many pixels long), the line shows: it runs through bricks and setts, not along their joints.
Each such run is re-cut as image quilting cuts an overlap (Efros & Freeman 2001, "Image quilting
for texture synthesis and transfer", 2.1, the minimum error boundary cut): both copies are
continued over a band either side of the line, A left of it and B right of it, the error of the
two continuations is e(i, o) = ||A(i, o) - B(i, o)||^2 for row i and band column o, and the path
of least cumulative error through the band becomes the new boundary. Its costs are those of
graph-cut textures (Kwatra, Schoedl, Essa, Turk & Bobick 2003, 3.1), ||A(s) - B(s)||^2 +
||A(t) - B(t)||^2 for neighbours s, t taken from different copies: across the cut between band
columns k and k + 1 in row i, c(i, k) = e(i, k) + e(i, k + 1); along a row where the cut moves
from k' (row i - 1) to k (row i), e(i - 1, o) + e(i, o) for every column o between, so the
path may run along a joint of the other direction (up a vertical joint, across a horizontal
one, on up the next). The cumulative error is
E(i, k) = c(i, k) + min_k' (E(i - 1, k') + |S_i(k) - S_i(k')|), S_i the running sum of those
row costs. Left of the path the left copy, right of it the right one: both stay verbatim
copies, only the line between them moves, to where they agree (a mortar or grass joint).

Deviations, one line each:
- only straight runs are re-cut (a boundary along one row or column line for at least ``run``
  pixels), columns first, then rows; the path starts and ends on the old line, so it joins the
  rest of the boundary;
- the path may move any number of band columns between rows (Efros & Freeman: one), paying
  the seam cost along the row as above (A and B continued from each row's own copies);
- a copy grows over at most half of the other copy's width in that row (two runs facing the
  same copy never overlap) and never outside the exemplar;
- the output wraps around its columns (the torus), a run does not continue across the last row.
"""

from __future__ import annotations

import numpy as np

__all__ = ["recut_straight", "straight_runs"]

#: The error counted for a pixel where a copy would leave the exemplar (no path crosses it).
BIG = 1e6
#: Run rows (padded to a batch's longest run) handled at once: the band's pixels of both copies
#: are gathered for each, 2 * band * C float32 twice.
CELLS = 1 << 16


def _carries_on(positions: np.ndarray) -> np.ndarray:
    """(H, W) True where the copy at (i, j) carries on to (i, j + 1) (wrapping)."""
    after = np.roll(positions, -1, axis=1)
    return (after[:, :, 0] == positions[:, :, 0]) & (after[:, :, 1] == positions[:, :, 1] + 1)


def straight_runs(positions: np.ndarray, run: int) -> np.ndarray:
    """The column boundaries of ``positions`` (H, W, 2) at least ``run`` rows long: an
    (n, 3) int array of (column j, first row, last row), the cut lying between columns j and
    j + 1 (wrapping).

    Examples
    --------
    >>> i, j = np.indices((40, 12))
    >>> pos = np.stack([i, j + 5 * (j >= 6)], axis=2)  # two copies meet between columns 5, 6
    >>> straight_runs(pos, 32).tolist()  # (the wrap, between columns 11 and 0, is a cut too)
    [[5, 0, 39], [11, 0, 39]]
    """
    cut = ~_carries_on(positions)
    edges = np.diff(np.pad(cut.T.astype(np.int8), ((0, 0), (1, 1))), axis=1)
    col_start, start = np.nonzero(edges == 1)
    col_stop, stop = np.nonzero(edges == -1)  # both in order of column, then row
    long = stop - start >= run
    return np.stack([col_start[long], start[long], stop[long] - 1], axis=1).astype(np.int64)


def _extent(carry: np.ndarray, rows: np.ndarray, cols: np.ndarray, step: int, most: int):
    """How far, up to ``most``, the copy at (rows, cols) carries on in direction ``step``
    (+1 right, -1 left) within its row: 1 plus the pixels that continue it."""
    w = carry.shape[1]
    length = np.ones(rows.shape, np.int64)
    going = np.ones(rows.shape, bool)
    for m in range(1, most):
        # (i, c + m - 1) -> (i, c + m) when going right, (i, c - m) -> (i, c - m + 1) left
        edge = (cols + (m - 1 if step > 0 else -m)) % w
        going &= carry[rows, edge]
        length += going
    return length


def _recut_columns(z: np.ndarray, positions: np.ndarray, run: int, band: int,
                   tick) -> np.ndarray:
    """One pass over the column boundaries (see the module notes); returns new positions.
    The runs are taken shortest first, in batches of at most ``CELLS`` run rows (padded),
    ``tick()`` after each."""
    runs = straight_runs(positions, run)
    if len(runs) == 0:
        return positions
    runs = runs[np.argsort(runs[:, 2] - runs[:, 1], kind="stable")]
    carry = _carries_on(positions)
    out = positions.copy()
    first = 0
    while first < len(runs):
        rows_max = runs[first:, 2] - runs[first:, 1] + 1  # ascending: a batch pads to its last
        last = first + max(1, int(np.searchsorted(rows_max * np.arange(1, len(rows_max) + 1),
                                                  CELLS, side="right")))
        _recut_batch(z, positions, carry, runs[first:last], band, out)
        tick()
        first = last
    return out


def _recut_batch(z, positions, carry, runs, band, out):
    """The runs' new cuts written into ``out``; everything read from ``positions``."""
    zh, zw = z.shape[:2]
    w = positions.shape[1]
    length = runs[:, 2] - runs[:, 1] + 1
    n, rows_max = len(runs), int(length.max())
    t = np.arange(rows_max)
    inside = t[None, :] < length[:, None]  # (n, T)
    row = np.where(inside, runs[:, 1:2] + t[None, :], runs[:, 1:2])
    col = np.broadcast_to(runs[:, 0:1], row.shape)
    a = positions[row, col]  # the left copy's pixel on the line, (n, T, 2)
    b = positions[row, (col + 1) % w]  # the right copy's
    # Cuts k in [-band + 1, band - 1]: columns j + k and before take A, after take B.
    reach_b = (_extent(carry, row, (col + 1) % w, 1, 2 * band) - 1) // 2  # A may take these
    reach_a = (_extent(carry, row, col, -1, 2 * band) - 1) // 2  # B may take these
    offsets = np.arange(-band + 1, band + 1)  # band columns j + o, o = -band + 1 .. band
    a_col = a[:, :, 1, None] + offsets  # A continued over the band
    b_col = b[:, :, 1, None] + offsets - 1  # B continued over the band
    valid = (a_col >= 0) & (a_col < zw) & (b_col >= 0) & (b_col < zw)
    e = ((z[a[:, :, 0, None], np.clip(a_col, 0, zw - 1)]
          - z[b[:, :, 0, None], np.clip(b_col, 0, zw - 1)]) ** 2).sum(axis=-1)
    e = np.where(valid, e, np.inf)
    k = np.arange(-band + 1, band)
    cost = e[:, :, :-1] + e[:, :, 1:]  # c(i, k) = e(k) + e(k + 1), (n, T, 2 band - 1)
    allowed = (k <= reach_b[:, :, None]) & (-k <= reach_a[:, :, None])
    # A continued up to column k, B from k + 1: all of those inside the exemplar.
    allowed &= (a[:, :, 1, None] + np.maximum(k, 0) < zw) \
        & (b[:, :, 1, None] + np.minimum(k, 0) >= 0)
    ends = ~inside | (t[None, :] == 0) | (t[None, :] == (length - 1)[:, None])
    allowed &= ~ends[:, :, None] | (k == 0)
    cost = np.where(allowed, cost, np.inf)
    # The cumulative error, all runs at once: from cut k' in row i - 1 to k in row i the path
    # also runs along the row between them, where the rows above and below take different
    # copies: Kwatra's cost there is e(i - 1, o) + e(i, o) for the columns o between.
    g = np.minimum(e[:, :, :-1], BIG).astype(np.float64)  # columns o = k, (n, T, 2 band - 1)
    g = np.cumsum(g[:, 1:] + g[:, :-1], axis=2)  # S(k): rows i - 1 and i, columns up to k
    total = cost[:, 0].copy()
    steps = np.zeros(cost.shape, np.int8)
    for r in range(1, rows_max):
        along = np.abs(g[:, r - 1, :, None] - g[:, r - 1, None, :])  # |S(k) - S(k')|
        options = total[:, None, :] + along
        steps[:, r] = options.argmin(axis=2)
        total = cost[:, r] + options.min(axis=2)
    kk = np.full(n, band - 1)  # the path ends on the old line (k = 0, index band - 1)
    path = np.empty((n, rows_max), np.int64)
    for r in range(rows_max - 1, -1, -1):
        path[:, r] = kk
        kk = steps[np.arange(n), r, kk]
    cut_at = k[path]  # (n, T)
    ok = np.isfinite(total[np.arange(n), band - 1])[:, None] & inside
    for o in range(1, band):  # right of the line, A where o <= cut
        take = ok & (o <= cut_at)
        rr, cc = row[take], (col[take] + o) % w
        out[rr, cc, 0], out[rr, cc, 1] = a[take][:, 0], a[take][:, 1] + o
    for o in range(-band + 2, 1):  # left of the line, B where o > cut
        take = ok & (o > cut_at)
        rr, cc = row[take], (col[take] + o) % w
        out[rr, cc, 0], out[rr, cc, 1] = b[take][:, 0], b[take][:, 1] + o - 1


def recut_straight(z: np.ndarray, positions: np.ndarray, run: int = 32, band: int = 16,
                   tick=lambda: None) -> np.ndarray:
    """Re-cut the straight boundaries between copies of a position map along their minimum
    error paths; returns new positions (H, W, 2) into ``z`` (h, w, C).

    Parameters
    ----------
    z : (h, w, C) float32 exemplar.
    positions : (H, W, 2) int exemplar row and column of each output pixel (the output wraps).
    run : the shortest straight boundary (pixels along one row or column line) re-cut.
    band : the farthest a new cut lies from the old line, pixels each way.
    tick : called between batches of runs (so Esc is heard).

    References
    ----------
    Efros & Freeman 2001, "Image quilting for texture synthesis and transfer", 2.1 (the
    minimum error boundary cut); Kwatra, Schoedl, Essa, Turk & Bobick 2003, "Graphcut
    Textures", 3.1 (the seam cost between two copies).

    Examples
    --------
    >>> i, j = np.indices((24, 48))
    >>> z = np.repeat(((j % 12) == 0)[:, :, None], 3, axis=2).astype(np.float32)  # joints
    >>> i, j = np.indices((40, 20))
    >>> pos = np.stack([i % 24, j + 6 + 20 * (j >= 10)], axis=2)  # cut between columns 9, 10
    >>> out = recut_straight(z, pos, run=32, band=8)
    >>> image = z[out[:, :, 0], out[:, :, 1]][:, :, 0]
    >>> bool((image.sum(axis=0) == 40).sum() == 2)  # two straight joints, none cut in two
    True
    """
    positions = np.asarray(positions)
    out = _recut_columns(z, positions, run, band, tick)
    swapped = _recut_columns(z.transpose(1, 0, 2), out.transpose(1, 0, 2)[:, :, ::-1], run, band,
                             tick)
    return np.ascontiguousarray(swapped[:, :, ::-1].transpose(1, 0, 2))

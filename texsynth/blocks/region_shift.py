"""Moving whole copied regions of a position map so their seams join (rows stay in rows).

A position map built from patches (texture optimisation's non-averaged pass, quilting) is a
set of regions, each a verbatim copy: its pixels share one shift, exemplar position minus
output position. In shift-map terms (Pritch, Kav-Venaki & Peleg 2009, "Shift-Map Image
Editing", 3) each pixel's label is its shift and the energy is the seam cost between
neighbours of different labels. Here the seam cost of graph-cut textures (Kwatra, Schoedl,
Essa, Turk & Bobick 2003, 3.1) is used, ``||A(s) - B(s)||^2 + ||A(t) - B(t)||^2`` for
neighbours s, t, A and B the two regions' copies continued over both pixels, and the moves are
whole regions: each region's shift may change by ``delta``, a small vector, when that lowers
the seam cost along the region's border. A region placed with the wrong phase (bricks half a
row off their neighbours') then slides into phase; its inside stays a verbatim copy.

Deviations, one line each:
- greedy region moves, not alpha-expansion: in a sweep every region takes its best ``delta``,
  and only regions whose gain beats every moving neighbour's move (no two neighbours at once);
- regions are 4-connected runs of one copy on the torus (the output tiles);
- a move that would take a pixel out of the exemplar is not considered.
"""

from __future__ import annotations

import numpy as np
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components

__all__ = ["align_regions", "regions"]

#: The four neighbours (row, column steps) of a pixel.
_STEPS = ((1, 0), (-1, 0), (0, 1), (0, -1))


def regions(positions: np.ndarray) -> tuple[int, np.ndarray]:
    """The verbatim copies in ``positions`` (H, W, 2): their number and the (H, W) label of
    each pixel, neighbours (wrapping) whose exemplar pixels are neighbours the same way
    sharing a label.

    Examples
    --------
    >>> i, j = np.indices((4, 6))
    >>> pos = np.stack([i, j + 2 * (j >= 3)], axis=2)  # two copies, side by side
    >>> regions(pos)[0]
    2
    """
    h, w = positions.shape[:2]
    index = np.arange(h * w).reshape(h, w)
    a, b = [], []
    for axis, step in ((0, (1, 0)), (1, (0, 1))):
        after = np.roll(positions, -1, axis)
        same = (after[:, :, 0] == positions[:, :, 0] + step[0]) & \
            (after[:, :, 1] == positions[:, :, 1] + step[1])  # the copy carries on
        a.append(index[same])
        b.append(np.roll(index, -1, axis)[same])
    a, b = np.concatenate(a), np.concatenate(b)
    graph = coo_matrix((np.ones(len(a), np.int8), (a, b)), shape=(h * w, h * w))
    n, label = connected_components(graph, directed=False)
    return n, label.reshape(h, w).astype(np.int32)


def _seam_costs(z, positions, label, n, deltas, tick):
    """(len(deltas), n): each region's seam cost along its border with its shift moved by each
    delta (the rest fixed); infinite where a moved pixel leaves the exemplar; ``tick()`` after
    each delta."""
    zh, zw = z.shape[:2]
    cost = np.zeros((len(deltas), n))
    outside = np.zeros((len(deltas), n), bool)
    for d in _STEPS:
        other = np.roll(positions, (-d[0], -d[1]), axis=(0, 1))  # the neighbour t of each s
        border = label != np.roll(label, (-d[0], -d[1]), axis=(0, 1))
        s, t, owner = positions[border], other[border], label[border]
        b_s = z[np.clip(t[:, 0] - d[0], 0, zh - 1), np.clip(t[:, 1] - d[1], 0, zw - 1)]
        b_t = z[t[:, 0], t[:, 1]]
        for k, (dy, dx) in enumerate(deltas):
            r, c = s[:, 0] + dy, s[:, 1] + dx
            out = (r < 0) | (r >= zh) | (c < 0) | (c >= zw)
            a_s = z[np.clip(r, 0, zh - 1), np.clip(c, 0, zw - 1)]
            a_t = z[np.clip(r + d[0], 0, zh - 1), np.clip(c + d[1], 0, zw - 1)]
            e = ((a_s - b_s) ** 2).sum(axis=1) + ((a_t - b_t) ** 2).sum(axis=1)
            cost[k] += np.bincount(owner, e, n)
            outside[k] |= np.bincount(owner, out, n) > 0
            tick()
    cost[outside] = np.inf
    return cost


def _independent(label, gain):
    """Regions that may move together: those with a gain and no neighbour of a larger gain
    (of an equal one and a lower label)."""
    blocked = np.zeros(len(gain), bool)
    for axis in (0, 1):
        other = np.roll(label, -1, axis)
        border = label != other
        a, b = label[border], other[border]
        a_first = (gain[a] > gain[b]) | ((gain[a] == gain[b]) & (a < b))  # ties: lower label
        blocked[b[a_first]] = True
        blocked[a[~a_first]] = True
    return (gain > 0) & ~blocked


def align_regions(z: np.ndarray, positions: np.ndarray, radius: int = 3,
                  sweeps: int = 3, tick=lambda: None) -> np.ndarray:
    """Slide the verbatim copies of a position map by up to ``radius`` pixels each way so their
    seams join; returns new positions (H, W, 2) into ``z`` (h, w, C).

    Parameters
    ----------
    z : (h, w, C) float32 exemplar.
    positions : (H, W, 2) int exemplar row and column of each output pixel (the output wraps).
    radius : the largest move of a region, per axis, in pixels.
    sweeps : rounds of moves (fewer when no region gains).
    tick : called between steps (so Esc is heard).

    References
    ----------
    Pritch, Kav-Venaki & Peleg 2009, "Shift-Map Image Editing", 3 (labels are shifts);
    Kwatra, Schoedl, Essa, Turk & Bobick 2003, "Graphcut Textures", 3.1 (the seam cost).

    Examples
    --------
    >>> i, j = np.indices((24, 16))
    >>> z = np.repeat(((i % 4) == 0)[:, :, None], 3, axis=2).astype(np.float32)  # rows
    >>> i, j = np.indices((16, 32))
    >>> pos = np.stack([i + 2 * (j >= 16), j % 16], axis=2)  # right half 2 rows off
    >>> out = align_regions(z, pos)
    >>> image = z[out[:, :, 0], out[:, :, 1]]
    >>> bool(np.array_equal(image[:, 15], image[:, 16]))  # the rows carry on
    True
    """
    deltas = [(dy, dx) for dy in range(-radius, radius + 1) for dx in range(-radius, radius + 1)]
    still = deltas.index((0, 0))
    positions = positions.copy()
    for _ in range(sweeps):
        n, label = regions(positions)
        tick()
        if n < 2:
            break
        cost = _seam_costs(z, positions, label, n, deltas, tick)
        best = cost.argmin(axis=0)
        gain = cost[still] - cost[best, np.arange(n)]
        move = _independent(label, np.where(best != still, gain, 0.0))
        if not move.any():
            break
        step = np.asarray(deltas, np.int32)[np.where(move, best, still)]
        positions += step[label]
    return positions

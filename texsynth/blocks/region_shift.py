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

A coarse grid of a multigrid synthesis (``multiscale_mrf``'s level l) is such a map whose
neighbours lie ``step`` = 2^l exemplar pixels apart: with ``step`` a copy carries on where the
exemplar position advances by ``step``, the seam cost compares the exemplar ``step`` away, and
regions move by multiples of ``step``. There (the brick wall's map at level 3, 2048 px: 446
copies) the greedy sweeps left most steps in place, for two reasons, each answered by an
option. A group of copies in phase with each other but half a course off the rest gains
nothing from any one of them moving: ``walk`` first places the copies breadth first from the
largest, each wave of copies taking the move that best joins them to the copies already
placed, so a group follows its first member. And the seam cost of one pixel pair a coarse step
apart is noisy (its minimum found the right phase on some borders only): ``reach`` sums it over
the pixel pairs up to ``reach`` apart across the border (the MRF's neighbourhood disk, as its
eq. 3 compares them) instead of the four neighbours. The share of that map's vertical borders
where the copies' courses met over a quarter course apart (read on the photo's bed joints):
0.28 before; 0.23 after 3 sweeps; 0.19 with the walk first; 0.11 with the walk and reach 3
(0.17 with one sweep); its course steps (``texsynth.metrics.course_steps``) 0.071, 0.065,
0.052, 0.043 (0.049).

Where the copies' phase is that of a lattice (courses laid to a gauge), ``lock_lattice`` moves
every copy into one phase of it at once, the phase broken along one straight row where the
output's height is no whole number of courses (the walk and sweeps, local, left that break a
patch of half courses on the generated wall of ``benchmarks.sections.elements``).

Deviations, one line each:
- greedy region moves, not alpha-expansion: in a sweep every region takes its best ``delta``,
  and only regions whose gain beats every moving neighbour's move (no two neighbours at once);
- regions are 4-connected runs of one copy on the torus (the output tiles);
- the walk (ours) is a sequential labelling in breadth-first waves, each wave's copies moved
  at once against the placed copies only (they may border each other);
- a move that would take a pixel out of the exemplar is not considered.
"""

from __future__ import annotations

import numpy as np
from scipy import ndimage
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components, shortest_path

from .search import disk_offsets

__all__ = ["align_regions", "lock_lattice", "regions"]


#: The break of ``lock_lattice`` goes where the seam costs at most this share of the costs'
#: range over the least (0.25: breaks along a course, its upper half the next course's).
BREAK_SLACK = 0.05
#: Pixel-delta pairs whose seam costs are taken at once (bounds the temporaries: 3 MB for RGB).
CHUNK = 1 << 18


def regions(positions: np.ndarray, step: int = 1) -> tuple[int, np.ndarray]:
    """The verbatim copies in ``positions`` (H, W, 2): their number and the (H, W) label of
    each pixel, neighbours (wrapping) whose exemplar pixels are neighbours the same way
    (``step`` exemplar pixels apart) sharing a label.

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
    for axis in (0, 1):
        after = np.roll(positions, -1, axis)
        advance = (step * (axis == 0), step * (axis == 1))
        same = (after[:, :, 0] == positions[:, :, 0] + advance[0]) & \
            (after[:, :, 1] == positions[:, :, 1] + advance[1])  # the copy carries on
        a.append(index[same])
        b.append(np.roll(index, -1, axis)[same])
    a, b = np.concatenate(a), np.concatenate(b)
    graph = coo_matrix((np.ones(len(a), np.int8), (a, b)), shape=(h * w, h * w))
    n, label = connected_components(graph, directed=False)
    return n, label.reshape(h, w).astype(np.int32)


def _borders(label, reach):
    """Per step g to a pixel up to ``reach`` away (wrapping), the flat indices of the pixels s
    and t = s + g that lie in different regions."""
    h, w = label.shape
    index = np.arange(h * w).reshape(h, w)
    out = []
    for g in disk_offsets(reach).tolist():
        beside = np.roll(label, (-g[0], -g[1]), axis=(0, 1))
        border = label != beside
        out.append((g, index[border], np.roll(index, (-g[0], -g[1]), axis=(0, 1))[border]))
    return out


def _seam_costs(planes, shape, positions, label, n, deltas, step, tick, borders, movers=None,
                placed=None):
    """(len(deltas), n): each region's seam cost along its ``borders`` (``_borders``) with its
    shift moved by each delta (exemplar pixels; the rest fixed), output neighbours ``step``
    exemplar pixels apart, the exemplar (``shape``) given as its flat channel ``planes``;
    infinite where a moved pixel leaves the exemplar; ``tick(fraction)`` after each step g. With
    ``movers`` and ``placed`` (bool, n), only the borders of movers with placed regions."""
    zh, zw = shape
    dy, dx = np.asarray(deltas).T
    chunk = max(1, CHUNK // len(deltas))
    flat, labels = positions.reshape(-1, 2), label.ravel()
    cost = np.zeros((len(deltas), n))
    outside = np.zeros((len(deltas), n), bool)

    def at(r, c):  # flat exemplar index, clipped to the exemplar
        return np.clip(r, 0, zh - 1) * zw + np.clip(c, 0, zw - 1)

    for done, (g, s_at, t_at) in enumerate(borders, 1):
        owner = labels[s_at]
        if movers is not None:
            keep = movers[owner] & placed[labels[t_at]]
            s_at, t_at, owner = s_at[keep], t_at[keep], owner[keep]
        d = (step * g[0], step * g[1])  # the same neighbour in the exemplar
        for i in range(0, len(s_at), chunk):  # all deltas at once, a bounded chunk of pixels
            s, t, o = flat[s_at[i:i + chunk]], flat[t_at[i:i + chunk]], owner[i:i + chunk]
            b_s, b_t = at(t[:, 0] - d[0], t[:, 1] - d[1]), t[:, 0] * zw + t[:, 1]
            r, c = s[None, :, 0] + dy[:, None], s[None, :, 1] + dx[:, None]  # (deltas, pixels)
            a_s, a_t = at(r, c), at(r + d[0], c + d[1])
            e = np.zeros(r.shape, np.float32)
            for p in planes:  # A(s) - B(s) and A(t) - B(t), A moved
                u, v = p[a_s] - p[b_s], p[a_t] - p[b_t]
                e += u * u + v * v
            bins = (o + n * np.arange(len(deltas))[:, None]).ravel()
            cost += np.bincount(bins, e.ravel(), n * len(deltas)).reshape(-1, n)
            out = (r < 0) | (r >= zh) | (c < 0) | (c >= zw)
            outside |= np.bincount(bins, out.ravel(), n * len(deltas)).reshape(-1, n) > 0
        tick(done / len(borders))
    cost[outside] = np.inf
    return cost


def _extents(positions, label, n):
    """(4, n): each region's first and last exemplar row, first and last column."""
    index = np.arange(n)
    return np.array([f(positions[:, :, k], label, index) for k in (0, 1)
                     for f in (ndimage.minimum, ndimage.maximum)], np.int64)


def _off(extents, deltas, shape):
    """(len(deltas), n): the moves that would take some pixel of a region, inside or on its
    border, out of the exemplar (``shape``)."""
    dy, dx = (np.asarray(deltas).T)[:, :, None]
    top, bottom, left, right = extents
    return (top + dy < 0) | (bottom + dy >= shape[0]) | (left + dx < 0) | \
        (right + dx >= shape[1])


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


def _walk(planes, shape, positions, deltas, step, tick, reach, sweeps):
    """Each copy joined to those placed before it, breadth first from the largest: a wave of
    the copies bordering the placed ones takes, each, the move that best joins its seams with
    the placed copies (none unless it gains), then counts as placed. ``tick(fraction)`` is told
    the share done of the walk and the ``sweeps`` after it (:func:`_shares`); returns the
    positions and the sweeps' first share."""
    n, label = regions(positions, step)
    if n < 2:
        return positions, 0.0
    borders = _borders(label, reach)
    still = deltas.index((0, 0))
    pairs = np.concatenate([np.stack([label.ravel(), np.roll(label, -1, axis).ravel()], axis=1)
                            for axis in (0, 1)])
    pairs = pairs[pairs[:, 0] != pairs[:, 1]]
    placed = np.zeros(n, bool)
    root = np.bincount(label.ravel(), minlength=n).argmax()
    placed[root] = True
    graph = coo_matrix((np.ones(len(pairs)), (pairs[:, 0], pairs[:, 1])), shape=(n, n))
    hops = shortest_path(graph, directed=False, unweighted=True, indices=root)
    waves = int(hops[np.isfinite(hops)].max())
    wave_share, start = _shares(waves, sweeps, n, len(deltas), len(planes), borders)
    k = 0
    extents = _extents(positions, label, n)
    while not placed.all():
        wave = np.zeros(n, bool)
        wave[pairs[placed[pairs[:, 0]], 1]] = True
        wave[pairs[placed[pairs[:, 1]], 0]] = True
        wave &= ~placed
        if not wave.any():  # not reached (a region graph on the torus is connected)
            break
        cost = _seam_costs(planes, shape, positions, label, n, deltas, step,
                           lambda f, k=k: tick((k + f) * wave_share), borders, wave, placed)
        k += 1
        cost[_off(extents, deltas, shape)] = np.inf
        best = cost.argmin(axis=0)
        best[~wave | (cost[best, np.arange(n)] >= cost[still])] = still
        moved = np.asarray(deltas, np.int32)[best]
        positions += moved[label]
        extents += moved.T.repeat(2, axis=0)
        placed |= wave
    return positions, start


def _shares(waves, sweeps, n, d, c, borders):
    """The walk's share of its work per wave and the sweeps' first share: a wave counts its
    bins (n regions x D deltas, per step g) and a third of the border pairs' gathers over its
    waves (what the walk's border masks keep: 0.3-0.4 of the pairs in the brick wall's and
    pool_water's maps), a sweep its bins and every pair's (D C values each)."""
    pairs = sum(len(s_at) for _, s_at, _ in borders)
    wave = n * d * len(borders) + pairs * d * c / (3 * max(waves, 1))
    sweep = n * d * len(borders) + pairs * d * c
    total = waves * wave + sweeps * sweep
    return wave / total, waves * wave / total


def align_regions(z: np.ndarray, positions: np.ndarray, radius: int = 3,
                  sweeps: int = 3, tick=lambda fraction: None, step: int = 1,
                  walk: bool = False, reach: int = 1) -> np.ndarray:
    """Slide the verbatim copies of a position map by up to ``radius`` steps each way so their
    seams join; returns new positions (H, W, 2) into ``z`` (h, w, C).

    Parameters
    ----------
    z : (h, w, C) float32 exemplar.
    positions : (H, W, 2) int exemplar row and column of each output pixel (the output wraps).
    radius : the largest move of a region, per axis, in steps.
    sweeps : rounds of moves (fewer when no region gains).
    tick : called between steps (so Esc is heard) with the share of the work done (0..1).
    step : exemplar pixels between neighbouring output pixels (a coarse grid's 2^l), and the
        unit of the moves.
    walk : before the sweeps, join each copy to its placed neighbours, breadth first from the
        largest copy (moves a group of copies in phase with each other but not with the rest,
        which the sweeps' single moves cannot).

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
    deltas = [(step * dy, step * dx) for dy in range(-radius, radius + 1)
              for dx in range(-radius, radius + 1)]
    still = deltas.index((0, 0))
    positions = positions.copy()
    planes = [np.ascontiguousarray(z[:, :, k]).ravel() for k in range(z.shape[2])]
    start = 0.0
    if walk:
        positions, start = _walk(planes, z.shape[:2], positions, deltas, step, tick, reach,
                                 sweeps)
    for k in range(sweeps):
        n, label = regions(positions, step)
        share = (1.0 - start) / (sweeps - k)   # the sweeps left share what is left
        tick(start)
        if n < 2:
            break
        cost = _seam_costs(planes, z.shape[:2], positions, label, n, deltas, step,
                           lambda f, a=start, b=share: tick(a + f * b), _borders(label, reach))
        start += share
        cost[_off(_extents(positions, label, n), deltas, z.shape[:2])] = np.inf
        best = cost.argmin(axis=0)
        gain = cost[still] - cost[best, np.arange(n)]
        move = _independent(label, np.where(best != still, gain, 0.0))
        if not move.any():
            break
        shift = np.asarray(deltas, np.int32)[np.where(move, best, still)]
        positions += shift[label]
    return positions


def _coset(y, x, lattice):
    """The phase of the shifts (y, x) modulo the lattice ``(P, Q, s)`` (basis (P, s), (0, Q)),
    as one index ``y' Q + x'`` of its representative ``0 <= y' < P``, ``0 <= x' < Q``."""
    period, along, shift = lattice
    a = np.floor_divide(y, period)
    return (y - a * period) * along + np.mod(x - a * shift, along)


def _break(vy, vx, axis, size, cell, lattice, step):
    """The line (row for ``axis`` 0, column for 1) before which the shifts (vy, vx) take the
    phase c0 + the wrap, and c0: where the seam between the phases costs least (within a
    ``BREAK_SLACK`` of the costs' range), of those where the most grid points keep their phase."""
    period, along, _ = lattice
    n = period * along
    wrap = (size, 0) if axis == 0 else (0, size)
    sides = [_coset(vy, vx, lattice), _coset(vy - wrap[0], vx - wrap[1], lattice)]
    hist = [np.stack([np.bincount(line, minlength=n) for line in np.moveaxis(s, axis, 0)])
            for s in sides]  # (lines, n) each: the phases on each line, without and with it
    zero = np.zeros((1, n))
    count = (np.concatenate([zero, np.cumsum(hist[1], 0)])
             + np.concatenate([np.cumsum(hist[0][::-1], 0)[::-1], zero]))[:-1]
    c0 = count.argmax(axis=1)
    cy, cx = np.divmod(c0, along)
    line = step * np.arange(len(c0))[:, None]
    run = np.arange(along if axis == 0 else period)[None, :]  # across one lattice cell
    seam = 0.0
    for back in (1, 0):  # the pixels either side of the break
        y, x = (line - back, run) if axis == 0 else (run, line - back)
        below, above = _coset(y + cy[:, None], x + cx[:, None], lattice), \
            _coset(y + cy[:, None] + wrap[0], x + cx[:, None] + wrap[1], lattice)
        seam = seam + ((cell[below] - cell[above]) ** 2).sum(axis=1)
    good = seam <= seam.min() + BREAK_SLACK * (seam.max() - seam.min())
    best = int(np.argmax(np.where(good, count.max(axis=1), -1)))
    return best, wrap


def lock_lattice(luma: np.ndarray, positions: np.ndarray, lattice: tuple[int, int, int],
                 step: int = 1) -> np.ndarray:
    """Move every copy of a position map into one phase of the elements' lattice, with one
    break where the output's size is not a whole number of lattice periods; returns new
    positions (H, W, 2) into ``luma`` (h, w).

    A copy's shift (exemplar position minus output position) modulo the lattice of the courses
    (``lattice`` = (P, Q, s): courses P apart, elements Q apart along a course, each course
    shifted s, as ``texsynth.blocks.rhythm.bond`` reads it; Liu, Collins & Tsin 2004's two
    period vectors) is its phase: copies in one phase show the courses in line. A copy carried
    once around the output's torus (H = ``step`` times its rows) changes phase by (H, 0) modulo
    the lattice, nonzero when H is no whole number of periods: the phase must break once. It
    breaks along one row (and one column, for the width): the rows above take the phase
    c0 + (H, 0), those below c0, the phase the most grid points already have; the row is where
    the seam between the two phases costs least (Kwatra et al. 2003, 3.1's seam cost, on the
    photo folded onto one lattice cell: a break inside a course makes it taller, one across a
    bed joint a sliver) and, of the rows within ``BREAK_SLACK`` of the costs' range of that, where
    the most grid points keep their phase. Each copy (split at the break) then moves by the
    shortest vector into its phase that keeps it inside the exemplar (a copy that fits nowhere
    stays).

    Parameters
    ----------
    luma : (h, w) float32 exemplar luminance (the seam cost's values).
    positions : (H, W, 2) int exemplar row and column of each grid point (the output wraps).
    lattice : (P, Q, s) the courses' period down the rows, the elements' along a course, and
        the shift from one course to the next (``0 <= s < Q``).
    step : exemplar pixels between neighbouring grid points (a coarse grid's 2^l).

    References
    ----------
    Liu, Collins & Tsin 2004, "A computational model for periodic pattern perception based on
    frieze and wallpaper groups" (the lattice); Pritch, Kav-Venaki & Peleg 2009, 3 (labels are
    shifts); Kwatra, Schoedl, Essa, Turk & Bobick 2003, 3.1 (the seam cost).

    Examples
    --------
    >>> i, j = np.indices((48, 64))
    >>> z = ((i % 8 == 0) | ((j + 8 * (i // 8)) % 16 == 0)).astype(np.float32)  # running bond
    >>> i, j = np.indices((20, 32))  # 20 rows: two and a half courses
    >>> pos = np.stack([i + 3 * (j >= 16) + 4, j + 8], axis=2)  # right half 3 rows off
    >>> out = lock_lattice(z, pos, (8, 16, 8))
    >>> phase = _coset(out[:, :, 0] - i, out[:, :, 1] - j, (8, 16, 8))
    >>> len(np.unique(phase)), bool((phase == phase[:, :1]).all())  # one break, along a row
    (2, True)
    """
    period, along, _ = lattice
    gh, gw = positions.shape[:2]
    i, j = np.indices((gh, gw))
    vy, vx = positions[:, :, 0] - step * i, positions[:, :, 1] - step * j
    h, w = luma.shape
    fold = _coset(*np.indices((h, w)), lattice).ravel()
    cell = (np.bincount(fold, luma.ravel(), period * along)
            / np.maximum(np.bincount(fold, minlength=period * along), 1))
    ty, tx = vy.copy(), vx.copy()  # the shifts less the breaks' wraps
    part = np.zeros((gh, gw), np.int64)  # which side of each break
    for axis, size in ((0, step * gh), (1, step * gw)):
        if _coset(size * (axis == 0), size * (axis == 1), lattice) == 0:
            continue  # whole periods: no break
        best, wrap = _break(ty, tx, axis, size, cell, lattice, step)
        side = (i if axis == 0 else j) < best
        ty, tx = ty - wrap[0] * side, tx - wrap[1] * side
        part = 2 * part + side
    c0y, c0x = np.divmod(np.bincount(_coset(ty, tx, lattice).ravel()).argmax(), along)
    uy, ux = np.divmod(_coset(c0y - ty, c0x - tx, lattice), along)  # into c0, modulo the lattice
    _, label = regions(positions, step)
    key = (label.astype(np.int64) * 4 + part) * (period * along) + uy * along + ux  # a copy
    segment = np.unique(key, return_inverse=True)[1].reshape(gh, gw)  # carried across the wrap
    first = np.unique(segment.ravel(), return_index=True)[1]
    reps = [(a, b) for a in range(-2, 2) for b in range(-2, 2)]  # u + a (P, s) + b (0, Q)
    cost = np.empty((len(reps), len(first)))
    for k, (a, b) in enumerate(reps):
        dy, dx = uy + a * period, ux + a * lattice[2] + b * along
        y, x = positions[:, :, 0] + dy, positions[:, :, 1] + dx
        out = np.bincount(segment.ravel(), ((y < 0) | (y >= h) | (x < 0) | (x >= w)).ravel())
        cost[k] = np.where(out > 0, np.inf, (dy ** 2 + dx ** 2).ravel()[first])
    pick = cost.argmin(axis=0)
    a, b = np.array(reps)[pick].T
    stays = np.isinf(cost.min(axis=0))
    dy = np.where(stays, 0, uy.ravel()[first] + a * period)
    dx = np.where(stays, 0, ux.ravel()[first] + a * lattice[2] + b * along)
    return positions + np.stack([dy[segment], dx[segment]], axis=2).astype(positions.dtype)

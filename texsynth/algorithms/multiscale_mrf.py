"""Multiscale MRF synthesis with Ashikhmin candidates and confidence weighting, periodic.

Paper 002 (Neubeck, Zalesny, Van Gool), section 3.1: Paget & Longstaff's non-parametric multiscale
MRF, sampled from the exemplar, with Ashikhmin's candidate search, and confidences.

- The output is a position map ``S``: per pixel, the exemplar pixel whose colour it shows.
- Initialisation: random positions, so the output histogram is the exemplar's.
- A visit to output pixel (i, j): every placed neighbour (i + u, j + v) in the disk
  N = {0 < u^2 + v^2 <= r^2} proposes the exemplar position that continues it,
  S(i + u, j + v) - (u, v) (Ashikhmin, fig. 8), plus ``random_candidates`` random positions; each
  candidate (p, q) is scored by eq. 3,
      dist(i, j, p, q) = sum_(u,v in N) w(i + u, j + v) ||out(i + u, j + v) - in(p + u, q + v)||^2,
  where neighbours outside the exemplar count as the maximal difference; S(i, j) moves to the
  best candidate only when it is better than the current one.
- Confidence: every visit adds 1/T to w(i, j) (eq. 1, T = ``visits``); a pixel is visited with
  probability proportional to 1 - w (eq. 2) and is final at w = 1.
- Multigrid (fig. 9): level l is the output decimated by 2^l with coordinates kept at full
  resolution, so its neighbourhood offsets are 2^l (u, v) in the exemplar and every level reads
  the whole exemplar. The coarsest grid starts from random positions; a finished level's pixels
  seed the even pixels of the next finer one with confidence 0.5, the others start random at 0.

Periodic output: output neighbourhoods wrap around the canvas, so the result tiles. Colour:
channels are compared jointly and positions copy whole pixels.

Deviations, one line each:
- visits are made in batches: each batch is a random lattice of pixels r + 1 apart (so no pixel
  of a batch is in another's neighbourhood, and the batch equals visiting them one after
  another), each lattice pixel taken with probability (1 - w) / max(1 - w); the paper draws one
  pixel at a time with probability (1 - w) / sum(1 - w), the same proportions;
- a side not divisible by 2^l gives a coarse grid of ceil(side / 2^l) points whose last row or
  column sits closer to the first; the finest level, where this does not arise, corrects it;
- a neighbour outside the exemplar costs w (D + |O - mean|^2) instead of w D (D = the maximal
  difference), which lets eq. 3 be one dot product; such candidates lose either way;
- "placed" neighbours are those visited at least once on this level (w > 0); the random
  positions of the initialisation propose no continuation, the ``random_candidates`` do that job;
- the number of levels is capped so that the coarsest neighbourhood (2 r 2^l + 1) fits in the
  exemplar and its grid is at least 2 r + 1 points across.
"""

from __future__ import annotations

import numpy as np

from ..registry import Method, Param, register
from ..search import Rows, best_candidate, disk_offsets, exemplar_neighbours

__all__ = ["multiscale_mrf", "level_count"]


def level_count(exemplar_shape, width, height, radius, levels) -> int:
    """``levels`` capped so the coarsest neighbourhood fits the exemplar and the output grid."""
    side = min(exemplar_shape[:2])
    n = 1
    while (n < levels and 2 * radius * 2 ** n + 1 <= side
           and -(-min(width, height) // 2 ** n) >= 2 * radius + 1):
        n += 1
    return n


class _Level:
    """Eq. 3 as one dot product per candidate. Each exemplar pixel p has a row
    ``Y_p = [X, Q]``: X its neighbours' values at this level's step, Q = |X|^2, or for a
    neighbour outside the exemplar X = 0 and Q = D, the maximal difference. A visited output
    pixel has a row ``Z = [-2 w O, w]`` (O its neighbours' colours, w their confidences), so
    ``Y_p . Z + sum w |O|^2`` is eq. 3; the last sum is the same for every candidate and is
    left out. Colours are centred on the exemplar mean."""

    #: Output pixels whose candidates are scored at once (keeps the gathered rows in cache).
    CHUNK = 1024

    def __init__(self, exemplar, offsets, step, wrap, visits, random_candidates):
        h, w, c = exemplar.shape
        colours = exemplar.reshape(h * w, c)
        centred = exemplar - colours.mean(axis=0)
        values, inside = exemplar_neighbours(centred, offsets, step, wrap)
        k = len(offsets)
        self.shape, self.k, self.c, self.wrap = (h, w), k, c, wrap
        dmax = np.float32((np.ptp(colours, axis=0).astype(np.float64) ** 2).sum())
        table = np.zeros((h * w + 1, k * (c + 1)), np.float32)  # last row: "no candidate"
        table[:-1, :k * c] = values.reshape(h * w, k * c)
        table[:-1, k * c:] = np.where(inside, (values * values).sum(axis=3), dmax).reshape(-1, k)
        self.table = Rows(table)
        self.n = h * w
        self.colours = Rows(centred.reshape(h * w, c))
        self.du = (step * offsets[:, 0]).astype(np.int32)
        self.dv = (step * offsets[:, 1]).astype(np.int32)
        self.offsets = offsets
        self.random_candidates = random_candidates

    def visit(self, source, confidence, rows, cols, rng):
        """One visit of the pixels (rows, cols), none in another's neighbourhood: each moves to
        its best candidate when that beats its current position. Returns the new positions."""
        gh, gw = source.shape
        flat = (((rows[:, None] + self.offsets[:, 0]) % gh) * gw
                + (cols[:, None] + self.offsets[:, 1]) % gw)
        nb = source.ravel()[flat]  # (B, K) neighbours' exemplar positions
        nw = confidence.ravel()[flat]  # (B, K) their confidences w
        current = source[rows, cols]
        extra = rng.integers(self.n, size=(len(rows), self.random_candidates))
        out = current.copy()
        for s in range(0, len(rows), self.CHUNK):
            sl = slice(s, s + self.CHUNK)
            out[sl] = self._best(nb[sl], nw[sl], current[sl], extra[sl])
        return out

    def _best(self, nb, nw, current, extra):
        h, w = self.shape
        k, c, none = self.k, self.c, h * w
        b = len(nb)
        z = np.empty((b, k * (c + 1)), np.float32)
        z[:, :k * c] = np.multiply(self.colours[nb], (-2.0 * nw)[:, :, None]).reshape(b, k * c)
        z[:, k * c:] = nw

        # Ashikhmin: each placed neighbour (w > 0) proposes the position that continues it.
        pr, pc = np.divmod(nb, w)
        pr -= self.du
        pc -= self.dv
        if self.wrap:
            cand = (pr % h) * w + pc % w
            cand[nw <= 0] = none
        else:
            ok = (pr >= 0) & (pr < h) & (pc >= 0) & (pc < w) & (nw > 0)
            cand = np.where(ok, pr * w + pc, none)
        cand = np.concatenate([cand, extra], axis=1)
        return best_candidate(self.table, cand, z, current, none)


def multiscale_mrf(exemplar, width, height, rng, progress, radius=3, visits=4,
                   random_candidates=2, levels=4, exemplar_tiles=False):
    """Synthesize (height, width, C) and its position map; see the module notes."""
    h, w, c = exemplar.shape
    if min(h, w) < 2 * radius + 1:
        raise ValueError(f"the exemplar ({w} x {h}) is smaller than the neighbourhood "
                         f"(radius {radius}: {2 * radius + 1} x {2 * radius + 1}); use a smaller "
                         "radius or a larger exemplar")
    offsets = disk_offsets(radius)
    n_levels = level_count(exemplar.shape, width, height, radius, levels)
    shapes = [(-(-height // 2 ** lv), -(-width // 2 ** lv)) for lv in range(n_levels)]
    work = np.array([gh * gw for gh, gw in shapes], float)
    work /= work.sum()

    # Confidence w is counted in halves of a visit: w = halves / (2 T), final at 2 T.
    source = _random_positions(shapes[-1], h * w, rng)
    halves = np.zeros(shapes[-1], np.int16)
    for lv in reversed(range(n_levels)):
        if lv < n_levels - 1:
            coarse = source
            source = _random_positions(shapes[lv], h * w, rng)
            source[::2, ::2] = coarse
            halves = np.zeros(shapes[lv], np.int16)
            halves[::2, ::2] = visits  # confidence 0.5
        level = _Level(exemplar, offsets, 2 ** lv, exemplar_tiles, visits, random_candidates)
        start = work[lv + 1:].sum()
        _relax(level, source, halves, visits, rng, progress.span(start, start + work[lv]), lv)

    positions = np.stack(np.divmod(source, w), axis=2).astype(np.int32)
    return exemplar.reshape(h * w, c)[source], positions


def _random_positions(shape, n, rng):
    """Flat exemplar indices, each exemplar pixel used equally often (up to rounding)."""
    size = shape[0] * shape[1]
    pool = np.tile(np.arange(n, dtype=np.int32), -(-size // n))
    return rng.permutation(pool)[:size].reshape(shape)


def _relax(level, source, halves, visits, rng, progress, index):
    """Visit the pixels of one level, with probability proportional to 1 - w (eq. 2), until
    every confidence w reaches 1 (eq. 1)."""
    gh, gw = source.shape
    spacing = int(np.floor(np.sqrt((level.offsets ** 2).sum(axis=1).max()))) + 1
    full = 2 * visits
    total = float((full - halves).sum())
    confidence = np.empty(source.shape, np.float32)
    while True:
        need = full - halves
        remaining = int(need.sum())
        if remaining == 0:
            break
        progress(1.0 - remaining / total, f"level {index}: visiting")
        # A lattice of pixels `spacing` apart, also across the wrap, at a random offset.
        ry = (rng.integers(gh) + spacing * np.arange(max(1, gh // spacing))) % gh
        rx = (rng.integers(gw) + spacing * np.arange(max(1, gw // spacing))) % gw
        lattice_need = need[np.ix_(ry, rx)]
        take = rng.random(lattice_need.shape) * need.max() < lattice_need
        iy, ix = np.nonzero(take)
        if len(iy) == 0:
            continue
        rows, cols = ry[iy], rx[ix]
        np.multiply(halves, np.float32(1.0 / full), out=confidence)
        source[rows, cols] = level.visit(source, confidence, rows, cols, rng)
        halves[rows, cols] = np.minimum(halves[rows, cols] + 2, full)


def _memory(shape, width, height, params):
    """The level's exemplar table (K (C + 1) floats a pixel, and its build) and colour rows,
    the position, confidence and output maps, one batch's neighbour indices (a lattice pixel in
    (r + 1)^2), one chunk's candidate rows."""
    k = len(disk_offsets(params["radius"]))
    c = shape[2]
    exemplar = shape[0] * shape[1] * (k * (4 * (c + 1) + 8 * c + 1) + 4 * c + 8)  # + build
    maps = width * height * (4 + 2 + 4 + 4 * c + 8 + 4 * c)
    batch = width * height / (params["radius"] + 1) ** 2 * k * 40
    chunk = _Level.CHUNK * (k + params["random_candidates"]) * (4 * k * (c + 1) + 16)
    return exemplar + maps + batch + chunk


register(Method(
    name="multiscale_mrf",
    label="Multiscale MRF",
    description="Relax a map of exemplar positions from coarse to fine, each pixel taking the "
                "best-matching continuation of its neighbours (Paget-Longstaff with Ashikhmin "
                "candidates and confidences): structured textures, any output size",
    function=multiscale_mrf,
    params=(
        Param("radius", int, 3, "Radius r of the disk neighbourhood compared (pixels at each "
              "level)", 1, 8),
        Param("visits", int, 4, "Visits T per pixel and level; confidence grows by 1/T a visit",
              1, 16),
        Param("random_candidates", int, 2, "Random exemplar positions tried per visit besides "
              "the neighbours' continuations", 0, 32),
        Param("levels", int, 4, "Multigrid levels (capped by the exemplar and output sizes)",
              1, 8),
        Param("exemplar_tiles", bool, False, "The exemplar itself tiles: neighbourhoods may "
              "wrap around its edges"),
    ),
    min_exemplar=3,
    memory=_memory,
    reference="Neubeck, Zalesny & Van Gool 2004 (paper 002) sec. 3.1; Paget & Longstaff 1998; "
              "Ashikhmin 2001",
    positions=True,
))

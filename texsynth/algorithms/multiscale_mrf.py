"""Multiscale MRF synthesis with Ashikhmin candidates and confidence weighting, periodic.

Neubeck, Zalesny & Van Gool 2004, section 3.1: Paget & Longstaff's non-parametric multiscale
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
- Confidences (eq. 1-2) and the multigrid (fig. 9) are ``texsynth.blocks.multigrid``'s; on
  level l the neighbourhood offsets are 2^l (u, v) in the exemplar, so every level reads the
  whole exemplar.
- Levels (Paget & Longstaff 1998: the coarsest grid's neighbourhood must capture the texture's
  longest interactions): by default (``levels`` 0) enough that the coarsest neighbourhood,
  2 r 2^(L-1) pixels across, spans the exemplar's texel size (``texsynth.blocks.period``), and
  at least ``MIN_LEVELS``: 1024 px photos of a brick wall get 8, of layered rock 6, of gravel 4.

Periodic output: output neighbourhoods wrap around the canvas, so the result tiles. Colour:
channels are compared jointly and positions copy whole pixels.

Deviations, one line each (and those of ``texsynth.blocks.multigrid``):
- a neighbour outside the exemplar costs w (D + |O - mean|^2) instead of w D (D = the maximal
  difference), which lets eq. 3 be one dot product; such candidates lose either way;
- "placed" neighbours are those visited at least once on this level (w > 0); the random
  positions of the initialisation propose no continuation, the ``random_candidates`` do that job;
- production sizes (k-coherence refinement, after Tong et al. 2002 and Ashikhmin 2001): a level
  whose grid has more than ``REFINE_PIXELS`` pixels only refines the coarser level's positions:
  its candidates are the continuations of the 8 nearest neighbours alone (no random ones), and
  it is visited ``REFINE_VISITS`` times instead of T; the distance still uses the whole disk;
- a pixel whose candidates are all its current position is not scored (it would stay).
"""

from __future__ import annotations

import numpy as np

from ..blocks import multigrid
from ..blocks.multigrid import grid_shapes, level_count
from ..blocks.period import texel_size
from ..blocks.search import Rows, best_candidate, disk_offsets, neighbour_table
from ..registry import Method, Param, register

__all__ = ["multiscale_mrf", "METHOD", "REFINE_PIXELS", "REFINE_VISITS"]

#: A level with a grid larger than this (pixels) refines with coherent candidates only.
REFINE_PIXELS = 512 * 512
#: Visits per pixel on such a level.
REFINE_VISITS = 2
#: Neighbours whose continuations a refining level proposes (the 3 x 3 ring: nearest first).
REFINE_PROPOSERS = 8
#: The fewest levels the automatic choice gives (the former default).
MIN_LEVELS = 4


class _Level:
    """Eq. 3 as one dot product per candidate. Each exemplar pixel p has a row
    ``Y_p = [X, Q]``: X its neighbours' values at this level's step, Q = |X|^2, or for a
    neighbour outside the exemplar X = 0 and Q = D, the maximal difference. A visited output
    pixel has a row ``Z = [-2 w O, w]`` (O its neighbours' colours, w their confidences), so
    ``Y_p . Z + sum w |O|^2`` is eq. 3; the last sum is the same for every candidate and is
    left out. Colours are centred on the exemplar mean. The table is built in ``out`` when given
    (one array refilled level after level), ``tick()`` after each band of it."""

    #: Output pixels visited at once (keeps the gathered rows in cache).
    CHUNK = 1024

    def __init__(self, exemplar, offsets, step, wrap, random_candidates, proposers=None,
                 out=None, tick=None):
        h, w, c = exemplar.shape
        colours = exemplar.reshape(h * w, c)
        centred = exemplar - colours.mean(axis=0)
        k = len(offsets)
        self.shape, self.k, self.c, self.wrap = (h, w), k, c, wrap
        dmax = np.float32((np.ptp(colours, axis=0).astype(np.float64) ** 2).sum())
        table = neighbour_table(centred, offsets, step, wrap, dmax, out, tick)
        self.table = Rows(table)
        self.n = h * w
        self.colours = Rows(centred.reshape(h * w, c))
        self.du = (step * offsets[:, 0]).astype(np.int32)
        self.dv = (step * offsets[:, 1]).astype(np.int32)
        self.offsets = offsets
        self.random_candidates = random_candidates
        self.proposers = k if proposers is None else min(proposers, k)

    def visit(self, source, confidence, rows, cols, rng, tick):
        """One visit of the pixels (rows, cols), none in another's neighbourhood: each moves to
        its best candidate when that beats its current position. Returns the new positions.
        Taken ``CHUNK`` pixels at a time, so every temporary stays small and in cache;
        ``tick()`` after each chunk."""
        out = source[rows, cols]
        for s in range(0, len(rows), self.CHUNK):
            sl = slice(s, s + self.CHUNK)
            out[sl] = self._visit(source, confidence, rows[sl], cols[sl], out[sl], rng)
            tick()
        return out

    def _visit(self, source, confidence, rows, cols, current, rng):
        p = self.proposers
        if self.random_candidates:  # every pixel is offered new positions
            nb, nw = self._neighbours(source, confidence, rows, cols, self.k)
            extra = rng.integers(self.n, size=(len(rows), self.random_candidates))
            cand = np.concatenate([self._continuations(nb[:, :p], nw[:, :p]),
                                   extra.astype(nb.dtype)], axis=1)
            return self._best(nb, nw, current, cand)
        # A pixel offered nothing but its current position keeps it unscored.
        cand = self._continuations(*self._neighbours(source, confidence, rows, cols, p))
        todo = np.flatnonzero(((cand != current[:, None]) & (cand != self.n)).any(axis=1))
        out = current.copy()
        if len(todo):
            nb, nw = self._neighbours(source, confidence, rows[todo], cols[todo], self.k)
            out[todo] = self._best(nb, nw, current[todo], cand[todo])
        return out

    def _neighbours(self, source, confidence, rows, cols, k):
        """The first k neighbours' exemplar positions and confidences w, (B, k) each."""
        gh, gw = source.shape
        flat = (((rows[:, None] + self.offsets[:k, 0]) % gh) * gw
                + (cols[:, None] + self.offsets[:k, 1]) % gw)
        return source.ravel()[flat], confidence.ravel()[flat]

    def _continuations(self, nb, nw):
        """Ashikhmin: each placed neighbour (w > 0) proposes the position that continues it;
        the others propose nothing (``n``)."""
        h, w = self.shape
        pr, pc = np.divmod(nb, w)
        pr -= self.du[:nb.shape[1]]
        pc -= self.dv[:nb.shape[1]]
        if self.wrap:
            cand = (pr % h) * w + pc % w
            cand[nw <= 0] = self.n
            return cand
        ok = (pr >= 0) & (pr < h) & (pc >= 0) & (pc < w) & (nw > 0)
        return np.where(ok, pr * w + pc, self.n)

    def _best(self, nb, nw, current, cand):
        k, c = self.k, self.c
        b = len(nb)
        z = np.empty((b, k * (c + 1)), np.float32)
        z[:, :k * c] = np.multiply(self.colours[nb], (-2.0 * nw)[:, :, None]).reshape(b, k * c)
        z[:, k * c:] = nw
        return best_candidate(self.table, cand, z, current, self.n)


def multiscale_mrf(exemplar, width, height, rng, progress, radius=3, visits=4,
                   random_candidates=2, levels=0, exemplar_tiles=False):
    """Synthesize (height, width, C) and its position map; see the module notes."""
    h, w, c = exemplar.shape
    if min(h, w) < 2 * radius + 1:
        raise ValueError(f"the exemplar ({w} x {h}) is smaller than the neighbourhood "
                         f"(radius {radius}: {2 * radius + 1} x {2 * radius + 1}); use a smaller "
                         "radius or a larger exemplar")
    offsets = disk_offsets(radius)
    if levels == 0:
        levels = auto_levels(exemplar, radius)
    shapes = grid_shapes(width, height, level_count(exemplar.shape, width, height, radius, levels))

    def refines(lv):
        return shapes[lv][0] * shapes[lv][1] > REFINE_PIXELS

    table = []  # one table array, refilled by every level

    def make_level(lv, tick):
        level = _Level(exemplar, offsets, 2 ** lv, exemplar_tiles,
                       0 if refines(lv) else random_candidates,
                       REFINE_PROPOSERS if refines(lv) else None, table[0] if table else None,
                       tick)
        table[:] = [level.table.array]
        return level

    source = multigrid.synthesize_positions(
        make_level, h * w, shapes,
        lambda lv: min(visits, REFINE_VISITS) if refines(lv) else visits, rng, progress)
    positions = np.stack(np.divmod(source, w), axis=2).astype(np.int32)
    return exemplar.reshape(h * w, c)[source], positions


def auto_levels(exemplar, radius):
    """Levels enough for the coarsest neighbourhood (2 r 2^(L-1) across) to span a texel, and
    at least ``MIN_LEVELS``."""
    texel = texel_size(exemplar)
    return max(MIN_LEVELS, 1 + int(np.ceil(np.log2(max(1.0, texel / (2 * radius))))))


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


def _cost(shape, width, height, params):
    """Seconds on the reference machine (``texsynth.budget``). Per visit of an output pixel on
    each level, each candidate's disk neighbourhood compared over C + 1 values (a refining
    level: ``REFINE_VISITS`` visits, ``REFINE_PROPOSERS`` candidates, most pixels left unscored,
    its own coefficient); plus the exemplar table of every level (automatic levels counted at
    the most the exemplar allows). Fitted on 64 px exemplars to 64-192 px outputs and, for the
    refining levels, on the 1024 px photos to 2048 and 4096 (production section)."""
    h, w, c = shape
    k = len(disk_offsets(params["radius"]))
    per_visit = k * (c + 1)
    n_levels = level_count(shape, width, height, params["radius"], params["levels"] or 8)
    units = refine_units = 0.0
    for gh, gw in grid_shapes(width, height, n_levels):
        if gh * gw > REFINE_PIXELS:
            refine_units += gh * gw * REFINE_VISITS * per_visit * REFINE_PROPOSERS
        else:
            units += gh * gw * params["visits"] * per_visit * (params["random_candidates"] + 6)
    return (0.1 + 5.1e-9 * units + 1.05e-9 * refine_units
            + 6.0e-9 * n_levels * h * w * k * c)


METHOD = register(Method(
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
        Param("levels", int, 0, "Multigrid levels (capped by the exemplar and output sizes); 0: "
              "enough for the coarsest neighbourhood to span the exemplar's texels", 0, 8),
        Param("exemplar_tiles", bool, False, "The exemplar itself tiles: neighbourhoods may "
              "wrap around its edges"),
    ),
    min_exemplar=3,
    memory=_memory,
    cost=_cost,
    positions=True,
))

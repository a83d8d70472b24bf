"""Pairwise clique statistics and their synthesis by stochastic relaxation.

Zalesny et al. 2002, section 2 and section 4.

A clique is a pair of pixels (p, p + d); its type is the offset d = (dy, dx). The statistic of a
clique type is the histogram of intensity differences u(p + d) - u(p) over every clique of that
type; the singleton histogram is the histogram of u itself. Section 4 adds cliques whose head p
and tail p + d lie in given subtextures (classes a and b of a label map): a :class:`Term` is one
clique type restricted to heads in class a and tails in class b (a = b for a plain subtexture).

A large exemplar's histograms are estimated from a sample of its cliques (deviation: the paper
counts every pixel): the heads on ``ANCHORS`` pixels of randomly drawn whole rows
(:func:`anchor_rows`), each with the rows its clique types reach below it (:func:`strips`). The
Euclidean distance of the estimate to the full count stays below a tenth of the selection
threshold (measured on the 12 MP setts photo, 32 levels, 144 types, three seeds: at most 0.0031,
mean 0.0012-0.0020, in 1.1 s instead of 25 s; tests/test_cooccurrence.py checks it).

Images here are integer "marks" in [0, span]. For grey levels the marks are the levels
0..G-1; a label map uses marks of a Golomb ruler (0, 1, 3, 7, ...), whose pairwise differences are
all distinct, so a difference histogram of marks is the ordered co-occurrence of labels.

Synthesis (:class:`Relaxation`) drives the difference histograms of the given terms and the
singleton histogram of the free pixels towards their targets by minimising

    E(u) = sum_t || h_t(u) - target_t ||^2 + || h_s(u) - target_s ||^2,

(h the normalised histograms, the Euclidean distance of the paper's step 4), the Julesz-ensemble
sampler of Zhu, Liu & Wu (2000) at zero temperature with random proposals. The pixels are split
into sets with no selected clique inside a set (a lattice colouring of the torus,
:func:`colour_sets`, shifted by a random torus translation each sweep, visited in random
order, in chunks of at most ``CHUNK`` pixels); all pixels of a chunk are proposed a new value at
once (half drawn from the singleton target, half a step of up to ``step`` levels; when refining
a coarser synthesis, ``bounded``: clipped to the range of the pixel's 8 neighbours), each one's
exact single-pixel change of E is computed from the current histograms in one vectorised pass,
and the improving proposals are applied together. No two pixels of a set share a clique, so
their histogram changes add up exactly and the set's true change of E is known before it is
applied; when many pixels move mass into the same bins and overshoot (E would rise), only the
better half of them is kept, and so on. E therefore never increases; it is bounded below, so it
converges (measured in docs/BENCHMARKS.md: steep in the first 10 sweeps, flat after 30-60);
:meth:`Relaxation.run` ends after a sweep that changes fewer than ``CONVERGED`` of the pixels.
The grid is a torus, so every synthesized image tiles. (Zalesny et al. 2002 defers its synthesis
procedure to its reference [13]; this sampler is ours.)
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ...blocks.parallel import run

__all__ = [
    "GOLOMB",
    "ANCHORS",
    "anchor_rows",
    "strips",
    "heads",
    "half_offsets",
    "pair_values",
    "difference_histograms",
    "colour_sets",
    "PairIndex",
    "Term",
    "Relaxation",
    "CONVERGED",
]

#: Clique heads per type from which a larger exemplar's histograms are estimated.
ANCHORS = 1 << 20

#: Elements of the (pixels, 2T) work arrays a sweep forms at once (a block of a set's pixels).
BLOCK = 1 << 16

#: Most pixels of a set visited at once (between two progress reports).
CHUNK = 1 << 18

#: Clashing pixels whose clique partners :func:`colour_sets` lists at once.
RECOLOUR = 1 << 10

#: A relaxation has converged when a sweep changes fewer than this share of its free pixels.
CONVERGED = 1e-4

#: Optimal Golomb rulers: marks whose pairwise differences are all distinct (index = count).
GOLOMB = (
    (), (0,), (0, 1), (0, 1, 3), (0, 1, 4, 6), (0, 1, 4, 9, 11), (0, 1, 4, 10, 12, 17),
    (0, 1, 4, 10, 18, 23, 25), (0, 1, 4, 9, 15, 22, 32, 34), (0, 1, 5, 12, 25, 27, 35, 41, 44),
    (0, 1, 6, 10, 23, 26, 34, 41, 53, 55), (0, 1, 4, 13, 28, 33, 47, 54, 64, 70, 72),
    (0, 2, 6, 24, 29, 40, 43, 55, 68, 75, 76, 85),
)


def half_offsets(max_offset: int) -> np.ndarray:
    """Every clique type up to ``max_offset`` (Chebyshev), one of d and -d: int32 (n, 2).

    d and -d describe the same cliques (the histogram of -d is the mirror of d's), so only the
    half plane dy > 0, or dy == 0 and dx > 0, is listed; shortest first, then by angle.
    """
    m = int(max_offset)
    dy, dx = np.mgrid[0:m + 1, -m:m + 1]
    keep = (dy > 0) | (dx > 0)
    d = np.stack([dy[keep], dx[keep]], axis=1).astype(np.int32)
    order = np.lexsort((np.arctan2(d[:, 0], d[:, 1]), np.hypot(d[:, 0], d[:, 1])))
    return d[order]


def anchor_rows(shape, reach: int, rng: np.random.Generator) -> np.ndarray | None:
    """Rows of the clique heads a photograph of ``shape`` (H, W, ...) is counted on: None (every
    row) for at most ``ANCHORS`` pixels, else ceil(ANCHORS / W) rows drawn at random (sorted,
    no repeats) among those with ``reach`` rows below them. ``rng`` is used only to draw."""
    h, w = shape[:2]
    count = -(-ANCHORS // w)
    if h * w <= ANCHORS or count >= h - reach:
        return None
    return np.sort(rng.choice(h - reach, count, replace=False))


def strips(image: np.ndarray, rows: np.ndarray | None, reach: int) -> np.ndarray:
    """The sample of ``image`` (H, W, ...) the cliques are counted on: the image itself when
    ``rows`` is None, else each anchor row with the ``reach`` rows below it, (R, reach + 1, W,
    ...): clique types (dy, dx) with 0 <= dy <= reach have their heads in a strip's first row."""
    if rows is None:
        return image
    return image[rows[:, None] + np.arange(reach + 1)]


def heads(sample: np.ndarray, rows: np.ndarray | None) -> np.ndarray:
    """The anchor pixels of ``strips(image, rows, reach)`` (the image itself, or the strips'
    first rows): each pixel once, for the singleton histogram and colour statistics."""
    return sample if rows is None else sample[:, 0]


def pair_values(a: np.ndarray, offset, periodic: bool) -> tuple[np.ndarray, np.ndarray]:
    """(head, tail) values of every clique of type ``offset`` in the 2-D array ``a``.

    Periodic: every pixel is a head and its tail wraps around. Otherwise only pairs with both
    pixels inside the array (a photograph's border is no clique). ``a`` may be a sample of
    strips (R, reach + 1, W) from :func:`strips`: heads in each strip's first row, 0 <= dy <=
    reach.
    """
    dy, dx = int(offset[0]), int(offset[1])
    if periodic:
        return a, np.roll(a, (-dy, -dx), axis=(0, 1))
    if a.ndim == 3:
        w = a.shape[2]
        x0, x1 = max(0, -dx), w - max(0, dx)
        return a[:, 0, x0:x1], a[:, dy, x0 + dx:x1 + dx]
    h, w = a.shape
    y0, y1 = max(0, -dy), h - max(0, dy)
    x0, x1 = max(0, -dx), w - max(0, dx)
    return a[y0:y1, x0:x1], a[y0 + dy:y1 + dy, x0 + dx:x1 + dx]


def difference_histograms(u: np.ndarray, offsets, span: int, periodic: bool,
                          labels: np.ndarray | None = None, classes=None) -> np.ndarray:
    """Counts of u(p + d) - u(p) for each offset d: int64 (n, 2 * span + 1), bin 0 = -span.

    ``u`` holds integer marks in [0, span]: an image, or a sample of it from :func:`strips`
    (``labels`` then the same sample of the labels). With ``labels`` and ``classes`` (one
    (head, tail) class pair per offset), only cliques whose head is in the first class and tail
    in the second are counted (section 4's interaction cliques).
    """
    u = np.asarray(u, np.int32)
    bins = 2 * span + 1
    out = np.zeros((len(offsets), bins), np.int64)
    for i, d in enumerate(offsets):
        head, tail = pair_values(u, d, periodic)
        diff = tail - head + span
        if labels is not None:
            lh, lt = pair_values(labels, d, periodic)
            a, b = classes[i]
            diff = diff[(lh == a) & (lt == b)]
        out[i] = np.bincount(diff.ravel(), minlength=bins)
    return out


class PairIndex:
    """The cliques of many terms on one periodic grid, found once: their histograms are then
    one gather and one ``bincount`` per call (step 3 of the selection, repeated every round).

    ``offsets`` (n, 2) with one (head, tail) class pair each in ``classes`` (all (0, 0) without
    ``labels``).
    """

    def __init__(self, shape, offsets, span: int, labels=None, classes=None):
        h, w = shape
        self.n, self.span, self.bins = len(offsets), span, 2 * span + 1
        index = np.arange(h * w, dtype=np.int32).reshape(shape)
        heads, tails, ids = [], [], []
        for i, d in enumerate(offsets):
            head, tail = pair_values(index, d, True)
            if labels is not None:
                lh, lt = pair_values(labels, d, True)
                keep = (lh == classes[i][0]) & (lt == classes[i][1])
                head, tail = head[keep], tail[keep]
            heads.append(head.ravel())
            tails.append(tail.ravel())
            ids.append(np.full(head.size, i * self.bins + span, np.int32))
        self.head = np.concatenate(heads) if heads else np.zeros(0, np.int32)
        self.tail = np.concatenate(tails) if tails else np.zeros(0, np.int32)
        self.base = np.concatenate(ids) if ids else np.zeros(0, np.int32)

    def histograms(self, u: np.ndarray) -> np.ndarray:
        """Counts (n, bins) of u(tail) - u(head) per term."""
        flat = np.asarray(u, np.int32).ravel()
        b = flat[self.tail] - flat[self.head] + self.base
        return np.bincount(b, minlength=self.n * self.bins).reshape(self.n, self.bins)


def _lattice(offsets: np.ndarray, shape) -> tuple[int, int, int]:
    """(K, a, b) with (a*dy + b*dx) mod K != 0 for every offset: colour = (a*y + b*x) mod K.

    The smallest such K; among its solutions one that is consistent around the torus
    (K divides a*H and b*W) when there is one. K = (m+1)^2, a = m+1, b = 1 always works.
    """
    h, w = shape
    dy, dx = offsets[:, 0, None, None], offsets[:, 1, None, None]
    m = int(np.abs(offsets).max())
    for k in range(2, (m + 1) ** 2 + 1):
        a, b = np.mgrid[0:k, 0:k]
        ok = ((a * dy + b * dx) % k != 0).all(axis=0)
        if ok.any():
            torus = ok & ((a * h) % k == 0) & ((b * w) % k == 0)
            pick = np.argwhere(torus if torus.any() else ok)[0]
            return k, int(pick[0]), int(pick[1])
    raise AssertionError("unreachable: (m+1)^2 always colours the box")


def colour_sets(shape, offsets, free: np.ndarray | None = None) -> list[np.ndarray]:
    """Flat indices of the free pixels split into sets with no clique of ``offsets`` inside one.

    A lattice colouring of the plane (:func:`_lattice`); where it is not consistent around the
    torus (K does not divide the size), the pixels that meet their own colour across the wrap
    are recoloured greedily (smallest colour none of their clique partners has).
    """
    h, w = shape
    free = np.ones(shape, bool) if free is None else np.asarray(free, bool)
    offsets = np.asarray(offsets, np.int32).reshape(-1, 2)
    if len(offsets) == 0:
        return [np.flatnonzero(free)]
    # an offset that wraps onto the pixel itself pairs a pixel with itself: no colouring avoids it
    offsets = offsets[(offsets[:, 0] % h != 0) | (offsets[:, 1] % w != 0)]
    if len(offsets) == 0:
        return [np.flatnonzero(free)]
    k, a, b = _lattice(offsets, shape)
    colour = (a * np.arange(h)[:, None] + b * np.arange(w)) % k
    colour[~free] = -1
    # where the lattice does not close around the torus, a pixel may meet its own colour
    # across the wrap (only pixels within reach of the border can): of each such pair the pixel
    # with the larger index is recoloured greedily
    m = int(np.abs(offsets).max())
    frame = np.ones(shape, bool)
    frame[m:h - m, m:w - m] = False
    fy, fx = np.nonzero(frame)
    clash = []
    for dy, dx in offsets:
        ty, tx = (fy + dy) % h, (fx + dx) % w
        same = (colour[fy, fx] == colour[ty, tx]) & (colour[fy, fx] >= 0)
        clash.append(np.maximum(fy[same] * w + fx[same], ty[same] * w + tx[same]))
    clash = np.unique(np.concatenate(clash))
    if clash.size:
        both = np.concatenate([offsets, -offsets])
        flat = colour.ravel()
        flat[clash] = -1
        # the partners of RECOLOUR clashing pixels at a time: all at once, as Python lists,
        # held 96 bytes per partner (45 MiB at 4096 x 32); the order of the greedy pass is kept
        for a in range(0, clash.size, RECOLOUR):
            cy, cx = np.divmod(clash[a:a + RECOLOUR], w)
            around = ((cy[:, None] + both[:, 0]) % h) * w + (cx[:, None] + both[:, 1]) % w
            for p, ring in zip(clash[a:a + RECOLOUR].tolist(), around.tolist(), strict=True):
                used = {int(flat[q]) for q in ring}
                c = 0
                while c in used:
                    c += 1
                flat[p] = c
    flat = colour.ravel().astype(np.int16)  # a stable sort of 16-bit integers is a radix sort
    order = np.argsort(flat, kind="stable")
    counts = np.bincount(flat[order] + 1)
    bounds = np.cumsum(counts)
    return [s for s in np.split(order, bounds[:-1])[1:] if s.size]


@dataclass(frozen=True)
class Term:
    """One clique type (head class ``head``, tail class ``tail``) and its target histogram."""

    offset: tuple[int, int]
    target: np.ndarray  # float32 (2 * span + 1,), sums to 1
    head: int = 0
    tail: int = 0


class Relaxation:
    """Zero-temperature stochastic relaxation of the free pixels of ``u`` (see module notes).

    ``u``: int (H, W) initial marks, periodic. ``levels``: int marks a pixel may take (level i is
    ``levels[i]``). ``singleton``: float (len(levels),) target histogram of the free pixels.
    ``terms``: the clique terms. ``labels`` (H, W) and ``free_class``: only pixels of that
    class change (all pixels without labels); the others stay as they are. ``step``: half-width
    of the local proposals in levels (0: proposals from the singleton target only, as for
    labels, whose levels have no order). ``bounded``: every proposal is clipped to the range
    of the levels of the pixel's 8 neighbours (those of its class), so that no proposal makes
    a pixel a local extreme (for grey levels; labels are never bounded). ``tick()``, when
    given, is called while the histograms are counted (where a caller may cancel).

    A free pixel p is the head of the cliques (p, p + d) and the tail of (p - d, p): each
    (term, end) whose own end is in the free class is a column. The image is kept as codes
    ``label * bins + mark``, so one gather of p's neighbours gives, per column, both the
    neighbour's class and the clique's difference bin; per set, a table per column holds the
    change of E for a clique entering or leaving each bin, and zero where the neighbour is not
    of the column's other class (the clique is not one of the term's). The (pixels, columns)
    work of a set is then a gather, two table look-ups and a sum, whatever the labels.
    """

    def __init__(self, u, levels, singleton, terms, labels=None, free_class=0, step=3,
                 tick=None, bounded=False):
        self.levels = np.asarray(levels, np.int32)
        self.span = int(self.levels.max())
        self.bins = 2 * self.span + 1
        self.terms = list(terms)
        self.step = int(step)
        self.bounded = bool(bounded) and self.step > 0
        u = np.asarray(u, np.int32)
        self.shape = h, w = u.shape
        labels = np.zeros(self.shape, np.int64) if labels is None else np.asarray(labels,
                                                                                   np.int64)
        free = labels == free_class
        self.level_of = np.full(self.span + 1, -1, np.int32)
        self.level_of[self.levels] = np.arange(len(self.levels))
        if (self.level_of[u[free]] < 0).any():
            raise ValueError("the initial image holds marks outside the levels")
        cdf = np.cumsum(np.asarray(singleton, np.float64))
        self._cdf = cdf / cdf[-1]

        # a toroidally padded flat copy: the neighbour of padded index P at offset d is P + d_flat
        t = len(self.terms)
        offsets = np.array([term.offset for term in self.terms], np.int64).reshape(t, 2)
        m = max(1, int(np.abs(offsets).max(initial=0)))
        self.m, self.wp = m, w + 2 * m
        self._ring = np.array([dy * self.wp + dx for dy in (-1, 0, 1) for dx in (-1, 0, 1)
                               if dy or dx], np.int64)
        ghost = np.ones((h + 2 * m, self.wp), bool)
        ghost[m:m + h, m:m + w] = False
        gy, gx = np.nonzero(ghost)
        self._ghost_dst = gy * self.wp + gx
        self._ghost_src = ((gy - m) % h + m) * self.wp + (gx - m) % w + m
        # every class the codes may hold: the map's and the terms' (an interaction term may
        # name a class of the exemplar that the output map lacks, or the map be one class)
        self.classes = 1 + max([int(labels.max(initial=0)), int(free_class)]
                               + [max(term.head, term.tail) for term in self.terms])
        self.pad = np.pad(labels * self.bins + u, m, mode="wrap").ravel()  # int64 codes
        self._shift = int(free_class) * self.bins  # the code of a free pixel is mark + shift

        # the columns: (term, end) with the pixel's own end in the free class
        cols = [(i, end) for end in (0, 1) for i, term in enumerate(self.terms)
                if (term.head, term.tail)[end] == free_class]
        self._term = np.array([i for i, _ in cols], np.int64)
        self._tail = np.array([end == 1 for _, end in cols], bool)
        self._other = np.array([(self.terms[i].tail, self.terms[i].head)[end]
                                for i, end in cols], np.int64)
        sign = np.where(self._tail, -1, 1)
        self._reach = sign * (offsets[self._term, 0] * self.wp + offsets[self._term, 1])
        self._base = np.arange(len(cols), dtype=np.int64) * self.classes * self.bins + self.span
        # each clique is counted once, from its end in the free class (its head when both are)
        heads = np.array([self.terms[i].head for i, _ in cols], np.int64)
        counting = ~self._tail | (heads != free_class)

        # the colouring of the whole torus, as (row, col) per set; each sweep shifts it by a
        # random translation (a fixed one leaves the pixels its wrap-around repair recoloured as
        # a band of small sets, which take up the histograms' slack more eagerly: a seam)
        intra = [term.offset for term in self.terms
                 if term.head == free_class and term.tail == free_class]
        self.sets = [(s // w, s % w) for s in colour_sets(self.shape, intra)]
        self._free = None if free.all() else free.ravel()
        self.targets = np.array([term.target for term in self.terms], np.float64).reshape(
            t, self.bins)
        self.singleton_target = np.asarray(singleton, np.float64) / np.sum(singleton)
        self.n_free = max(int(free.sum()), 1)
        self.counts = np.zeros((t, self.bins))
        free_flat = np.flatnonzero(free)
        padded = (free_flat // w + m) * self.wp + free_flat % w + m
        x = self.pad[padded] - self._shift
        if counting.any():
            step = max(1024, BLOCK // int(counting.sum()))
            raw = np.zeros(len(cols) * self.classes * self.bins, np.int64)
            for a in range(0, x.size, step):
                if tick is not None and a:
                    tick()
                b = slice(a, a + step)
                raw += np.bincount((self._neighbours(padded[b], counting)
                                    - x[b, None]).ravel(), minlength=raw.size)
            self.counts = self._fold(raw)
        self.pairs = np.maximum(self.counts.sum(axis=1), 1.0)
        self.singleton_counts = np.bincount(self.level_of[x],
                                            minlength=len(self.levels)).astype(np.float64)

    @property
    def image(self) -> np.ndarray:
        m, (h, w) = self.m, self.shape
        core = self.pad.reshape(h + 2 * m, self.wp)[m:m + h, m:m + w]
        return (core % self.bins).astype(np.int32)

    def distances(self) -> np.ndarray:
        """Euclidean distance of each term's histogram to its target (the paper's step 4)."""
        return np.sqrt(((self.counts / self.pairs[:, None] - self.targets) ** 2).sum(axis=1))

    def singleton_distance(self) -> float:
        return float(np.sqrt(((self.singleton_counts / self.n_free
                               - self.singleton_target) ** 2).sum()))

    def energy(self) -> float:
        return float((self.distances() ** 2).sum() + self.singleton_distance() ** 2)

    def _neighbours(self, padded, columns=None) -> np.ndarray:
        """Code of the other end of each column's clique, plus the column's table base:
        int64 (pixels, columns); minus a pixel's mark it indexes the column tables."""
        reach, base = self._reach, self._base
        if columns is not None:
            reach, base = reach[columns], base[columns]
        return self.pad[padded[:, None] + reach] + base

    def _fold(self, raw) -> np.ndarray:
        """(T, bins) term counts from counts over the column tables' cells."""
        cells = raw.reshape(len(self._term), self.classes, self.bins)
        mine = cells[np.arange(len(self._term)), self._other]
        # a tail column's cell k is the clique difference -(k - span): mirrored
        mine[self._tail] = mine[self._tail, ::-1]
        out = np.zeros((len(self.terms), self.bins))
        np.add.at(out, self._term, mine)
        return out

    def _tables(self) -> tuple[np.ndarray, np.ndarray]:
        """Flat (columns, classes, bins) tables: the change of E when a clique enters (first)
        or leaves (second, negated) a bin, to first order plus its half of the 1/N^2 each."""
        n = self.pairs[:, None]
        grad = 2.0 * (self.counts / n - self.targets) / n
        second = 1.0 / n ** 2
        enter = (grad + second)[self._term]
        leave = (second - grad)[self._term]
        for table in (enter, leave):
            table[self._tail] = table[self._tail, ::-1]
        shape = (len(self._term), self.classes, self.bins)
        tables = np.zeros((2,) + shape, np.float32)
        rows = np.arange(len(self._term))
        tables[0][rows, self._other] = enter
        tables[1][rows, self._other] = leave
        return tables[0].ravel(), tables[1].ravel()

    def run(self, sweeps: int, rng, progress=None, prefix: str = "") -> int:
        """Up to ``sweeps`` sweeps, ending after the first that changes fewer than
        ``CONVERGED`` of the free pixels (deviation: the paper's reference [13] runs a fixed
        number); ``progress(fraction, message)`` after every set. Returns the sweeps done."""
        if sweeps < 1:
            return 0
        for i in range(sweeps):
            message = f"{prefix}sweep {i + 1}/{sweeps}"
            if progress is not None:
                progress(i / sweeps, message)
            tick = None if progress is None else (
                lambda done, sets, i=i, message=message: progress((i + done / sets) / sweeps,
                                                                  message))
            changed = self.sweep(rng, tick)
            if changed < CONVERGED:
                break
        if progress is not None:
            progress(1.0, message)
        return i + 1

    def _propose(self, x, padded, rng):
        n = len(self.levels)
        drawn = np.minimum(np.searchsorted(self._cdf, rng.random(x.size), side="right"), n - 1)
        if self.step > 0:
            jump = rng.integers(1, self.step + 1, x.size) * (2 * rng.integers(0, 2, x.size) - 1)
            local = np.clip(self.level_of[x] + jump, 0, n - 1)
            drawn = np.where(rng.random(x.size) < 0.5, drawn, local)
            if self.bounded:
                # the levels of the 8 neighbours of the pixel's own class (its own for others)
                code = self.pad[padded[:, None] + self._ring] - self._shift
                ring = self.level_of[np.where((code >= 0) & (code < self.bins), code,
                                              x[:, None]).clip(0, self.span)]
                drawn = np.clip(drawn, ring.min(axis=1), ring.max(axis=1))
        return self.levels[drawn]

    def sweep(self, rng, tick=None) -> float:
        """Visit every free pixel once, set by set in random order, the colouring shifted by a
        random translation; returns the fraction of changed pixels. A set is visited in chunks
        of at most ``CHUNK`` pixels (its pixels share no clique, so a chunk's changes are exact
        whatever the others do). ``tick(done, sets)``, when given, is called after every chunk
        (where a caller may cancel)."""
        changed = total = 0
        h, w = self.shape
        m, wp = self.m, self.wp
        sy, sx = rng.integers(0, h), rng.integers(0, w)
        # a fixed order of the sets would carry changes one way across the lattice
        for done, k in enumerate(rng.permutation(len(self.sets))):
            if tick is not None and done:
                tick(done, len(self.sets))
            rows, cols = self.sets[k]
            rows, cols = (rows + sy) % h, (cols + sx) % w
            if self._free is not None:
                keep = self._free[rows * w + cols]
                rows, cols = rows[keep], cols[keep]
            padded = (rows + m) * wp + cols + m
            for a in range(0, padded.size, CHUNK):
                if tick is not None and a:
                    tick(done + a / padded.size, len(self.sets))
                seen, moved = self._visit(padded[a:a + CHUNK], rng)
                total, changed = total + seen, changed + moved
        return changed / max(total, 1)

    def _visit(self, padded, rng) -> tuple[int, int]:
        """Propose new values to the pixels at ``padded`` (no two share a clique) and apply the
        improving ones; returns (pixels visited, pixels changed)."""
        c = len(self._term)
        enter, leave = self._tables() if c else (None, None)
        g_s = 2.0 * (self.singleton_counts / self.n_free - self.singleton_target) / self.n_free
        x = self.pad[padded] - self._shift
        y = self._propose(x, padded, rng)
        total = x.size
        # a proposal of the value the pixel has changes nothing: only the others are looked at
        moves = np.flatnonzero(x != y)
        padded, x, y = padded[moves], x[moves], y[moves]
        lx, ly = self.level_of[x], self.level_of[y]
        de = g_s[ly] - g_s[lx] + 2.0 / self.n_free ** 2  # the columns' 1/N^2 are in the tables
        if c:
            # in blocks of rows (the (rows, columns) temporaries stay in cache), on threads:
            # numpy releases the GIL in gathers and sums, and each block writes its own rows
            # of de, so the result does not depend on the number of threads
            def block(b, padded=padded, x=x, y=y, de=de, enter=enter, leave=leave):
                nb = self._neighbours(padded[b])
                delta = enter[nb - y[b, None]]
                delta += leave[nb - x[b, None]]
                de[b] += delta.sum(axis=1)

            step = max(1024, BLOCK // c)
            blocks = [slice(a, a + step) for a in range(0, x.size, step)]
            run(block, blocks)
        accept = np.flatnonzero(de < 0)
        nb = self._neighbours(padded[accept]) if c else None
        # backtracking: the improving pixels' changes add up exactly in the histograms, so
        # the true change of E is known; while it is not a decrease (many pixels moving mass
        # into the same bins overshoot), keep only the better half (ranked when first needed)
        ranked = False
        while accept.size:
            d_s = (np.bincount(ly[accept], minlength=len(self.levels))
                   - np.bincount(lx[accept], minlength=len(self.levels)))
            d_c = self._count_change(nb, x[accept], y[accept])
            if self._change(d_c, d_s) < 0:
                break
            if not ranked:
                order = np.argsort(de[accept], kind="stable")
                accept, nb, ranked = accept[order], None if nb is None else nb[order], True
            accept = accept[:accept.size // 2]
        if not accept.size:
            return total, 0
        self.pad[padded[accept]] = y[accept] + self._shift
        self.pad[self._ghost_dst] = self.pad[self._ghost_src]
        self.singleton_counts += d_s
        self.counts += d_c
        return total, accept.size

    def _count_change(self, nb, x, y) -> np.ndarray:
        """Change of the term counts (T, bins) when the pixels valued ``x``, whose neighbours
        are ``nb`` (the first rows of it), take the values ``y``."""
        if nb is None:
            return np.zeros((0, self.bins))
        nb = nb[:x.size]
        size = len(self._term) * self.classes * self.bins
        return self._fold(np.bincount((nb - y[:, None]).ravel(), minlength=size)
                          - np.bincount((nb - x[:, None]).ravel(), minlength=size))

    def _change(self, d_counts, d_singleton) -> float:
        """Exact change of E for the given changes of the counts."""
        n = self.pairs[:, None]
        before = self.counts / n - self.targets
        after = before + d_counts / n
        s_before = self.singleton_counts / self.n_free - self.singleton_target
        s_after = s_before + d_singleton / self.n_free
        return float((after ** 2).sum() - (before ** 2).sum()
                     + (s_after ** 2).sum() - (s_before ** 2).sum())

"""Image quilting's two steps: the patch whose overlap agrees with what is there, and the cut.

Efros & Freeman 2001, "Image quilting for texture synthesis and transfer", section 2.1:

- **Patch choice**: the error of a candidate patch B is its sum of squared differences with the
  content already fixed in its overlap region; a patch is chosen at random among those within
  a tolerance of the best. :class:`Search` computes that error for every placement in a source
  image at once, the squares expanded as FFT correlations (Kwatra et al. 2003, 2.1, the same
  expansion): SSD(p) = sum_x M S(p+x)^2 - 2 sum_x M T S(p+x) + sum_x M T^2, M the overlap mask,
  T the template, S the source, its spectra computed once.
- **Minimum error boundary cut**: with e = (B1 - B2)^2 over the overlap, the cumulative error
  E(i, j) = e(i, j) + min(E(i-1, j-1), E(i-1, j), E(i-1, j+1)); its smallest last entry traced
  back gives the cut (:func:`min_error_path`). ``closed=True`` makes the path a loop on a
  torus: its last and first entries differ by at most one (the arms of a tileable band wrap).
- **Quilting a torus** (:func:`torus_quilt`): blocks placed in raster order, each overlapping
  the ones before it (and, in the last row and column, the first ones across the wrap), chosen
  and cut as above: a position map of any size that tiles, each block a piece of the source.

Deviations, one line each:
- the SSD is computed in float64 (the expansion subtracts large sums; float32 would lose the
  small differences between good candidates);
- a closed path is found by a second pass started where the open path is cheapest, ended
  within one entry of its start (exact for the loop through that entry);
- a torus quilt's source wraps (it is a periodic pyramid level); a block may not continue a
  neighbour's copy (its offset within ``radius`` of theirs): the exact continuation has no
  error, and drawn within the tolerance of it a quilt twice the source's size is the source
  laid 2 x 2 again; where it can, its offset is also ``radius // 2`` from every block's (one
  offset twice repeats at the source's period) and its source ``radius`` from every block's
  (two blocks from one place repeat at their distance): these rules are dropped one by one,
  then the neighbours' radius halved, while no placement is left.
"""

from __future__ import annotations

import numpy as np
import scipy.fft as sfft
from scipy import ndimage

from .parallel import threads

__all__ = ["Search", "block_count", "block_means", "min_error_path", "torus_quilt"]


def block_means(image: np.ndarray, f: int) -> np.ndarray:
    """float64 means of the f x f blocks of an (h, w, C) image (the last partial blocks left
    out); the rows are summed first, in place of a copy of the whole image."""
    h, w, c = image.shape
    hc, wc = h // f, w // f
    rows = image[:hc * f].reshape(hc, f, w, c).sum(axis=1, dtype=np.float64)
    return rows[:, :wc * f].reshape(hc, wc, f, c).sum(axis=2) / (f * f)


class Search:
    """The masked SSD of a template against every placement inside ``source`` (h, w, C).

    Examples
    --------
    >>> rng = np.random.default_rng(0)
    >>> source = rng.random((40, 50, 3))
    >>> search = Search(source)
    >>> ssd = search.ssd(source[7:17, 20:32], np.ones((10, 12)))
    >>> ssd.shape, tuple(int(i) for i in np.unravel_index(ssd.argmin(), ssd.shape))
    ((31, 39), (7, 20))
    """

    def __init__(self, source: np.ndarray):
        s = np.asarray(source, np.float64)
        self.shape = s.shape[:2]
        self.fft_shape = tuple(sfft.next_fast_len(n, real=True) for n in self.shape)
        self.spectra = self._rfft2(s)
        self.energy = self._rfft2(np.einsum("ijc,ijc->ij", s, s))

    def _rfft2(self, a: np.ndarray) -> np.ndarray:
        return sfft.rfft2(a, self.fft_shape, axes=(0, 1), workers=threads())

    def prepare(self, template: np.ndarray, mask: np.ndarray) -> tuple:
        """The template's part of the SSD (its spectra and sum M T^2), reusable by every
        search of the same FFT shape."""
        t = np.asarray(template, np.float64)
        m = np.asarray(mask, np.float64)
        mt = m[:, :, None] * t
        return (m.shape, np.conj(self._rfft2(m)), np.conj(self._rfft2(mt)),
                float(np.einsum("ijc,ijc->", mt, t)))

    def ssd(self, template: np.ndarray, mask: np.ndarray, prepared: tuple | None = None
            ) -> np.ndarray:
        """SSD(p) for every placement p of the (ph, pw) ``template`` inside the source,
        (h - ph + 1, w - pw + 1), weighted by ``mask`` (ph, pw); ``prepared``: the template's
        :meth:`prepare` by a search of the same FFT shape."""
        (ph, pw), mask_spectrum, weighted, constant = prepared or self.prepare(template, mask)
        spectrum = mask_spectrum * self.energy
        spectrum -= 2 * np.einsum("ijc,ijc->ij", weighted, self.spectra)
        correlation = sfft.irfft2(spectrum, self.fft_shape, workers=threads())
        h, w = self.shape
        return np.maximum(correlation[:h - ph + 1, :w - pw + 1] + constant, 0.0)


def _cumulative(e: np.ndarray, start: int | None) -> tuple[np.ndarray, np.ndarray]:
    """E's last row and the step taken into each entry (-1, 0, 1), from row 0 (only entry
    ``start`` allowed there when given)."""
    n, k = e.shape
    steps = np.zeros((n, k), np.int8)
    total = e[0].copy()
    if start is not None:
        total[np.arange(k) != start] = np.inf
    padded = np.full(k + 2, np.inf)
    for i in range(1, n):
        padded[1:-1] = total
        left, middle, right = padded[:-2], padded[1:-1], padded[2:]
        best = np.minimum(np.minimum(left, middle), right)
        steps[i] = np.where(left == best, -1, np.where(middle == best, 0, 1))
        total = best + e[i]
    return total, steps


def _trace(steps: np.ndarray, end: int) -> np.ndarray:
    path = np.empty(len(steps), np.int64)
    path[-1] = end
    for i in range(len(steps) - 1, 0, -1):
        path[i - 1] = path[i] + steps[i, path[i]]
    return path


def min_error_path(e: np.ndarray, closed: bool = False) -> np.ndarray:
    """The minimum error boundary cut through the (n, k) error surface ``e``: one entry of
    each row, neighbouring rows at most one apart, the sum of ``e`` along it smallest; with
    ``closed``, the last entry also at most one from the first (a loop around a torus).

    Examples
    --------
    >>> e = np.ones((5, 4)); e[:, 2] = 0; e[0, 2] = e[4, 2] = 5
    >>> min_error_path(e).tolist()
    [1, 2, 2, 2, 1]
    """
    e = np.asarray(e, np.float64)
    total, steps = _cumulative(e, None)
    path = _trace(steps, int(total.argmin()))
    if not closed:
        return path
    # The loop through the entry where the open path crosses its cheapest row.
    row = int(e[np.arange(len(e)), path].argmin())
    rolled = np.roll(e, -row, axis=0)
    total, steps = _cumulative(rolled, int(path[row]))
    ends = np.arange(max(0, path[row] - 1), min(e.shape[1], path[row] + 2))
    loop = _trace(steps, int(ends[total[ends].argmin()]))
    return np.roll(loop, row)


def _cells(n: int, step: int) -> np.ndarray:
    """Boundaries of at least 2 cells of at least 2 entries, about ``step`` long, over n."""
    count = max(2, min(-(-n // max(step, 1)), n // 2))
    return np.round(np.linspace(0, n, count + 1)).astype(np.int64)


def block_count(shape: tuple[int, int], block: int, overlap: int | None = None) -> int:
    """Blocks :func:`torus_quilt` places on an output of ``shape``: its cells of about
    ``block - overlap`` a side (a cost model's count: each takes a search and its cuts).

    Examples
    --------
    >>> block_count((128, 128), 4, 1)
    1849
    """
    step = block - (max(1, block // 4) if overlap is None else overlap)
    return (len(_cells(shape[0], step)) - 1) * (len(_cells(shape[1], step)) - 1)


def torus_quilt(source: np.ndarray, shape: tuple[int, int], block: int, rng: np.random.Generator,
                overlap: int | None = None, tolerance: float = 0.1,
                radius: int | None = None, tick=None) -> np.ndarray:
    """A position map of ``shape`` (int64 flat indices into ``source``'s (h, w) grid) quilted
    from blocks of the periodic (h, w, C) ``source``: Efros & Freeman 2001, 2.1, on a torus.

    Cells of about ``block - overlap`` a side, in raster order, each taking a block that also
    covers ``overlap`` rows above and columns to its left (wrapping). Its strips that overlap
    what is placed (above and left; in the last row also below, in the last column also right:
    the first blocks across the wrap) weigh the SSD of every placement in the wrapped source
    (:class:`Search`); one is drawn among those within ``1 + tolerance`` of the best, whose
    offset is more than ``radius`` (default ``block // 2``) from the neighbours' and, where
    some are, half that from every block's, whose source is that far from every other
    block's; and each strip is cut along
    its minimum error path (:func:`min_error_path`). The map tiles: its wrap is a cut like the
    others. ``tick(fraction)``, when given, is told the share of the blocks placed after each.

    Examples
    --------
    >>> source = np.random.default_rng(0).random((16, 16, 1))
    >>> where = torus_quilt(source, (40, 24), 8, np.random.default_rng(1))
    >>> where.shape, bool(where.min() >= 0 and where.max() < 16 * 16)
    ((40, 24), True)
    """
    h, w = source.shape[:2]
    height, width = shape
    overlap = max(1, block // 4) if overlap is None else overlap
    ys, xs = _cells(height, block - overlap), _cells(width, block - overlap)
    o_y = max(1, min(overlap, int(np.diff(ys).min()) - 1))
    o_x = max(1, min(overlap, int(np.diff(xs).min()) - 1))
    tall, wide = int(np.diff(ys).max()) + o_y, int(np.diff(xs).max()) + o_x
    s = np.asarray(source, np.float64)
    padded = np.pad(s, ((0, tall - 1), (0, wide - 1), (0, 0)), mode="wrap")
    search = Search(padded)
    values = np.zeros((height, width, s.shape[2]))
    where = np.zeros((height, width), np.int64)
    offsets = {}                          # cell -> (dy, dx): source row/column minus output's
    placements = []                       # each block's first source row and column
    ny, nx = len(ys) - 1, len(xs) - 1
    for i in range(ny):
        for j in range(nx):
            rows = np.arange(ys[i] - o_y, ys[i + 1]) % height
            cols = np.arange(xs[j] - o_x, xs[j + 1]) % width
            ph, pw = len(rows), len(cols)
            sides = {"top": i > 0, "bottom": i == ny - 1, "left": j > 0, "right": j == nx - 1}
            mask = np.zeros((ph, pw))
            mask[:o_y] += sides["top"]
            mask[ph - o_y:] += sides["bottom"]
            mask[:, :o_x] += sides["left"]
            mask[:, pw - o_x:] += sides["right"]
            mask = np.minimum(mask, 1.0)
            template = values[np.ix_(rows, cols)]
            near = [offsets[c] for c in ((i - 1, j - 1), (i - 1, j), (i - 1, j + 1), (i, j - 1),
                                         (i, (j + 1) % nx), ((i + 1) % ny, j)) if c in offsets]
            py, px = _placement(search, template, mask, (h, w), (rows[0], cols[0]), near,
                                placements, offsets.values(),
                                block // 2 if radius is None else radius,
                                tolerance, rng)
            offsets[i, j] = ((py - rows[0]) % h, (px - cols[0]) % w)
            placements.append((py, px))
            new = padded[py:py + ph, px:px + pw]
            keep = np.zeros((ph, pw), bool)        # where what is placed stays (the cuts)
            e = ((new - template) ** 2).sum(axis=2)
            r, c = np.arange(ph)[:, None], np.arange(pw)[None, :]
            if sides["left"]:
                keep |= c < min_error_path(e[:, :o_x])[:, None]
            if sides["right"]:
                keep |= c > pw - o_x + min_error_path(e[:, pw - o_x:])[:, None]
            if sides["top"]:
                keep |= r < min_error_path(e[:o_y].T)[None, :]
            if sides["bottom"]:
                keep |= r > ph - o_y + min_error_path(e[ph - o_y:].T)[None, :]
            put = ~keep
            grid = np.ix_(rows, cols)
            values[grid] = np.where(put[:, :, None], new, template)
            flat = ((py + r) % h) * w + (px + c) % w
            where[grid] = np.where(put, flat, where[grid])
            if tick is not None:
                tick((i * nx + j + 1) / (ny * nx))
    return where


def _placement(search, template, mask, source_shape, corner, near, placed, offsets, radius,
               tolerance, rng):
    """A block's first source row and column: uniform where nothing overlaps it, else drawn
    among the placements within ``1 + tolerance`` of the least SSD, leaving out those whose
    offset from the output's ``corner`` is within ``radius`` of a neighbour's (``near``) and,
    while others remain, within ``radius // 2`` of any block's (``offsets``), and those within
    ``radius`` of a block's source (``placed``)."""
    h, w = source_shape
    if not mask.any():
        return int(rng.integers(0, h)), int(rng.integers(0, w))
    ssd = search.ssd(template, mask)[:h, :w]

    def away(points, r, origin=(0, 0)):
        """Placements more than r (on either axis, on the torus) from every point: the points
        marked on the (h, w) torus and dilated by a (2r + 1)-box (a box as wide as the torus
        covers it), in time that does not grow with the blocks placed."""
        marked = np.zeros((h, w), np.uint8)
        if len(points):
            q = np.asarray(list(points), np.int64).reshape(-1, 2)
            marked[(q[:, 0] + origin[0]) % h, (q[:, 1] + origin[1]) % w] = 1
        size = (min(2 * r + 1, h), min(2 * r + 1, w))
        return ndimage.maximum_filter(marked, size=size, mode="wrap") == 0

    neighbours = away(near, radius, corner)
    apart = neighbours & away(offsets, radius // 2, corner)   # at no block's offset: a tiling
    far = apart & away(placed, radius)                        # nor at any block's source
    # the rules dropped one by one, the neighbours' radius halved, until some placement is left
    allowed = next((a for a in (far, apart, neighbours, away(near, radius // 2, corner),
                                away(near, 0, corner)) if a.any()), np.ones((h, w), bool))
    ssd = np.where(allowed, ssd, np.inf)
    best = float(ssd.min())
    chosen = np.flatnonzero(ssd.ravel() <= best * (1 + tolerance) + 1e-12)
    return tuple(int(v) for v in np.divmod(int(rng.choice(chosen)), w))

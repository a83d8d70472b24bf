"""PatchMatch between the patches of a periodic output and those of an exemplar, vectorised.

Barnes, Shechtman, Finkelstein & Goldman 2009, "PatchMatch: a randomized correspondence
algorithm for structural image editing", sec. 3: a nearest-neighbour field f (here, per output
patch, the top-left corner of an exemplar patch) improved by propagation, where a patch tries its
neighbour's match shifted by their offset, and random search, where it tries matches around its
own at exponentially shrinking radii ``R alpha^i`` (alpha = 1/2).

Deviations, one line each:
- every output patch is updated at once (numpy), so propagation runs as jump flooding (Rong &
  Tan 2006): shifted-array comparisons at grid distances 4, 2, 1 in the four directions, instead
  of a scan order that carries a good match along a row within one pass;
- patches are compared through :class:`PatchFeatures` (a p x p patch as the means of up to 8 x 8
  cells, projected on its 32 principal components), not all p^2 C values;
- output patches wrap around the output (it tiles); exemplar patches lie inside the exemplar;
- an optional per-exemplar-position ``penalty`` is added to every distance (Kaspar et al. 2015's
  occurrence term, see ``texsynth.algorithms.texture_optimization``).
"""

from __future__ import annotations

import numpy as np

from .search import Rows

__all__ = ["PatchFeatures", "patchmatch", "JUMPS"]

#: Propagation distances, in grid steps, largest first (jump flooding).
JUMPS = (4, 2, 1)
#: Cells per patch side in the descriptor, and principal components kept.
CELLS = 8
DIMS = 32
#: Exemplar patches sampled to fit the principal components.
FIT_SAMPLES = 4096
#: Exemplar rows described per block (bounds the working memory on large photos).
BLOCK_ROWS = 16
#: Output patches gathered or compared at once (bounds the working memory; a ``tick`` after
#: each, so a caller can cancel within a step over a million patches).
CHUNK = 1 << 16


class PatchFeatures:
    """A short descriptor of every p x p patch: the patch's ``CELLS`` x ``CELLS`` cell means, all
    channels, projected on their ``DIMS`` principal components over the exemplar's patches.
    ``||F(x) - F(z)||^2`` approximates the patch SSD ``||x - z||^2`` / q^2 (q the cell side).

    ``exemplar`` holds the descriptors of the exemplar's patches whose top-left pixels lie on a
    lattice of spacing ``stride``, ((h - p) // stride + 1, (w - p) // stride + 1, d), indexed by
    the top-left pixel over the stride; :meth:`describe` gives an image's, wrapping around.
    ``tick()``, when given, is called after every block of rows (where a caller may cancel).
    """

    def __init__(self, exemplar: np.ndarray, size: int, rng: np.random.Generator,
                 cells: int = CELLS, dims: int = DIMS, tick=None, stride: int = 1):
        h, w, c = exemplar.shape
        if size > min(h, w):
            raise ValueError(f"patch size {size} is larger than the exemplar ({w} x {h})")
        self.size, self.stride = size, stride
        self.cells = min(cells, size)
        self.q = size // self.cells
        self.shape = ((h - size) // stride + 1, (w - size) // stride + 1)
        cells = self._cell_means(exemplar, periodic=False)
        rows = rng.integers(0, self.shape[0], min(FIT_SAMPLES, self.shape[0] * self.shape[1]))
        cols = rng.integers(0, self.shape[1], len(rows))
        sample = self._raw(cells, rows * stride, cols * stride).astype(np.float64)
        self.mean = sample.mean(axis=0)
        centred = sample - self.mean
        _, vectors = np.linalg.eigh(centred.T @ centred)
        self.basis = np.ascontiguousarray(vectors[:, ::-1][:, :dims], dtype=np.float32)
        self.mean = self.mean.astype(np.float32)
        out = np.empty(self.shape + (self.basis.shape[1],), np.float32)
        g, q, n = self.cells, self.q, (self.shape[1] - 1) * stride + 1
        for start in range(0, self.shape[0], BLOCK_ROWS):
            stop = min(start + BLOCK_ROWS, self.shape[0])
            top, bottom = start * stride, (stop - 1) * stride + 1
            raw = np.concatenate([cells[top + a * q:bottom + a * q:stride, b * q:b * q + n:stride]
                                  for a in range(g) for b in range(g)], axis=-1)
            raw -= self.mean
            np.matmul(raw, self.basis, out=out[start:stop])
            if tick is not None:
                tick()
        self.exemplar = out
        self.rows = Rows(out.reshape(-1, out.shape[2]))

    def _cell_means(self, image, periodic):
        """Means of q x q cells at every top-left pixel: (H, W, C) wrapping, else valid only."""
        q = self.q
        a = np.asarray(image, np.float32)
        if q == 1:
            return a
        for axis in (0, 1):
            n = a.shape[axis] if periodic else a.shape[axis] - q + 1
            idx = np.arange(n)
            total = np.take(a, idx, axis=axis, mode="wrap")
            for u in range(1, q):
                total = total + np.take(a, idx + u, axis=axis, mode="wrap")
            a = total
        return a / np.float32(q * q)

    def _raw(self, cells, rows, cols):
        """The CELLS^2 cell means of the patches at (rows, cols), (..., CELLS^2 C); indices wrap
        (only periodic cell maps are indexed beyond their valid range)."""
        g, q = self.cells, self.q
        hh, ww = cells.shape[:2]
        parts = [cells[(rows + a * q) % hh, (cols + b * q) % ww]
                 for a in range(g) for b in range(g)]
        return np.concatenate(parts, axis=-1)

    def describe(self, image: np.ndarray, rows: np.ndarray, cols: np.ndarray,
                 tick=None) -> np.ndarray:
        """Descriptors of the patches of a periodic ``image`` with top-left pixels
        (rows, cols), arrays of one shape; (..., d). The cell means are gathered and projected
        ``CHUNK`` patches at a time (``tick()`` after each), so the working memory is a chunk's
        cells, not every patch's."""
        cells = self._cell_means(image, periodic=True)
        shape = np.shape(rows)
        rows, cols = np.ravel(rows), np.ravel(cols)
        out = np.empty((len(rows), self.basis.shape[1]), np.float32)
        for s in range(0, len(rows), CHUNK):
            sl = slice(s, s + CHUNK)
            raw = self._raw(cells, rows[sl], cols[sl])
            raw -= self.mean
            np.matmul(raw, self.basis, out=out[sl])
            if tick is not None:
                tick()
        return out.reshape(shape + (-1,))


def _cost(features, target, flat, penalty):
    got = features.rows[flat]
    got -= target
    d = np.einsum("...k,...k->...", got, got)
    if penalty is not None:
        d += penalty.ravel()[flat]
    return d


def patchmatch(features: PatchFeatures, target: np.ndarray, nnf: np.ndarray, rows: np.ndarray,
               cols: np.ndarray, period: tuple[int, int], rng: np.random.Generator,
               iterations: int = 2, active: tuple[np.ndarray, np.ndarray] | None = None,
               penalty: np.ndarray | None = None, tick=None) -> np.ndarray:
    """Improve ``nnf`` (gh, gw, 2) int32, the exemplar top-left matched to each output grid
    patch, in place; return the cost of each active patch. Matches lie on the lattice of
    ``features`` (a pixel off it is taken at the lattice point above and left of it).

    The output grid patches have top-left pixels (``rows[i]``, ``cols[j]``) on an output of size
    ``period`` (H, W), which wraps: a grid neighbour proposes its match moved by the two
    patches' offset, measured around the torus. ``active`` = (gi, gj), the grid indices of the
    patches to improve (default: all), whose descriptors ``target`` (n, d) holds; the others keep
    their match and still propose it. ``penalty`` (``features.shape``) is added to the
    distance of each exemplar patch of the lattice. ``tick()``, when given, is called after
    every ``CHUNK`` patches compared (where a caller may cancel).
    """
    hs, ws = features.shape
    stride = features.stride
    gh, gw = nnf.shape[:2]
    if active is None:
        active = tuple(a.ravel() for a in np.mgrid[:gh, :gw])
    gi, gj = active
    grid = nnf[:, :, 0] // stride * ws + nnf[:, :, 1] // stride
    flat = grid[gi, gj]
    cost = np.empty(len(flat), np.float32)
    for s in range(0, len(flat), CHUNK):
        sl = slice(s, s + CHUNK)
        cost[sl] = _cost(features, target[sl], flat[sl], penalty)
        if tick is not None:
            tick()

    def consider(r, c):
        cand = np.clip(r, 0, hs - 1) * ws + np.clip(c, 0, ws - 1)
        for s in range(0, len(cand), CHUNK):
            sl = slice(s, s + CHUNK)
            d = _cost(features, target[sl], cand[sl], penalty)
            better = d < cost[sl]
            flat[sl][better] = cand[sl][better]
            cost[sl][better] = d[better]
            if tick is not None:
                tick()
        grid[gi, gj] = flat

    for _ in range(iterations):
        for k in JUMPS:
            for axis, n, pos, size in ((0, gh, rows, period[0]), (1, gw, cols, period[1])):
                if 2 * k >= n:
                    continue
                for sign in (1, -1):
                    # The neighbour k grid steps before (sign 1) or after proposes its match
                    # moved by the signed torus distance between the two patches.
                    mine = gi if axis == 0 else gj
                    other = (mine - sign * k) % n
                    shift = (pos[mine] - pos[other] + size // 2) % size - size // 2
                    shift = (shift + stride // 2) // stride  # in lattice steps
                    sr, sc = np.divmod(grid[other, gj] if axis == 0 else grid[gi, other], ws)
                    if axis == 0:
                        consider(sr + shift, sc)
                    else:
                        consider(sr, sc + shift)
        radius = max(hs, ws)
        while radius >= 1:
            r, c = np.divmod(flat, ws)
            consider(r + rng.integers(-radius, radius + 1, r.shape),
                     c + rng.integers(-radius, radius + 1, c.shape))
            radius //= 2
    nnf[:, :, 0], nnf[:, :, 1] = np.divmod(grid, ws)
    nnf *= stride
    return cost

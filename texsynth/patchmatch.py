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
BLOCK_ROWS = 64


class PatchFeatures:
    """A short descriptor of every p x p patch: the patch's ``CELLS`` x ``CELLS`` cell means, all
    channels, projected on their ``DIMS`` principal components over the exemplar's patches.
    ``||F(x) - F(z)||^2`` approximates the patch SSD ``||x - z||^2`` / q^2 (q the cell side).

    ``exemplar`` holds the descriptors of the exemplar's patches, (h - p + 1, w - p + 1, d),
    indexed by the patch's top-left pixel; :meth:`describe` gives an image's, wrapping around.
    """

    def __init__(self, exemplar: np.ndarray, size: int, rng: np.random.Generator,
                 cells: int = CELLS, dims: int = DIMS):
        h, w, c = exemplar.shape
        if size > min(h, w):
            raise ValueError(f"patch size {size} is larger than the exemplar ({w} x {h})")
        self.size = size
        self.cells = min(cells, size)
        self.q = size // self.cells
        self.shape = (h - size + 1, w - size + 1)
        cells = self._cell_means(exemplar, periodic=False)
        rows = rng.integers(0, self.shape[0], min(FIT_SAMPLES, self.shape[0] * self.shape[1]))
        cols = rng.integers(0, self.shape[1], len(rows))
        sample = self._raw(cells, rows, cols)
        self.mean = sample.mean(axis=0)
        _, _, vt = np.linalg.svd(sample - self.mean, full_matrices=False)
        self.basis = np.ascontiguousarray(vt[:dims].T, dtype=np.float32)
        out = np.empty(self.shape + (self.basis.shape[1],), np.float32)
        cols = np.arange(self.shape[1])
        for start in range(0, self.shape[0], BLOCK_ROWS):
            block = np.arange(start, min(start + BLOCK_ROWS, self.shape[0]))
            out[block] = self._project(cells, block[:, None], cols[None, :])
        self.exemplar = out
        #: Mean squared descriptor distance of an exemplar patch from the mean patch.
        self.rows = Rows(out.reshape(-1, out.shape[2]))

    def _cell_means(self, image, periodic):
        """Means of q x q cells at every top-left pixel: (H, W, C) wrapping, else valid only."""
        q = self.q
        a = np.asarray(image, np.float32)
        if periodic:
            a = np.concatenate([a, a[:q - 1]], axis=0)
            a = np.concatenate([a, a[:, :q - 1]], axis=1)
        s = np.zeros((a.shape[0] + 1, a.shape[1] + 1, a.shape[2]), np.float64)
        np.cumsum(np.cumsum(a, axis=0, dtype=np.float64), axis=1, out=s[1:, 1:])
        box = s[q:, q:] - s[:-q, q:] - s[q:, :-q] + s[:-q, :-q]
        return (box / (q * q)).astype(np.float32)

    def _raw(self, cells, rows, cols):
        """The CELLS^2 cell means of the patches at (rows, cols), (..., CELLS^2 C); indices wrap
        (only periodic cell maps are indexed beyond their valid range)."""
        g, q = self.cells, self.q
        hh, ww = cells.shape[:2]
        parts = [cells[(rows + a * q) % hh, (cols + b * q) % ww]
                 for a in range(g) for b in range(g)]
        return np.concatenate(parts, axis=-1)

    def _project(self, cells, rows, cols):
        return (self._raw(cells, rows, cols) - self.mean) @ self.basis

    def describe(self, image: np.ndarray, rows: np.ndarray, cols: np.ndarray) -> np.ndarray:
        """Descriptors of the patches of a periodic ``image`` at top-left (rows, cols):
        ``rows`` (n,) and ``cols`` (m,) give an (n, m, d) grid."""
        cells = self._cell_means(image, periodic=True)
        return self._project(cells, rows[:, None], cols[None, :]).astype(np.float32)


def _cost(features, target, flat, penalty):
    got = features.rows[flat]
    got -= target
    d = np.einsum("...k,...k->...", got, got)
    if penalty is not None:
        d += penalty.ravel()[flat]
    return d


def patchmatch(features: PatchFeatures, target: np.ndarray, nnf: np.ndarray, rows: np.ndarray,
               cols: np.ndarray, period: tuple[int, int], rng: np.random.Generator,
               iterations: int = 2, active: np.ndarray | None = None,
               penalty: np.ndarray | None = None) -> np.ndarray:
    """Improve ``nnf`` (gh, gw, 2) int32, the exemplar top-left matched to each output grid
    patch, in place; return each patch's cost (gh, gw).

    ``target`` (gh, gw, d) holds the descriptors of the output patches whose top-left pixels are
    (``rows[i]``, ``cols[j]``) on an output of size ``period`` (H, W), which wraps: a grid
    neighbour proposes its match moved by the two patches' offset, measured around the torus.
    ``active`` (gh, gw) bool: only those patches change (the others still propose).
    ``penalty`` (h - p + 1, w - p + 1): added to the distance of each exemplar patch.
    """
    hs, ws = features.shape
    gh, gw = nnf.shape[:2]
    flat = nnf[:, :, 0] * ws + nnf[:, :, 1]
    cost = _cost(features, target, flat, penalty)
    if active is None:
        active = np.ones((gh, gw), bool)

    def consider(r, c):
        nonlocal flat, cost
        cand = np.clip(r, 0, hs - 1) * ws + np.clip(c, 0, ws - 1)
        d = _cost(features, target, cand, penalty)
        better = (d < cost) & active
        flat = np.where(better, cand, flat)
        cost = np.where(better, d, cost)

    for _ in range(iterations):
        for k in JUMPS:
            for axis, n, pos, size in ((0, gh, rows, period[0]), (1, gw, cols, period[1])):
                if 2 * k >= n:
                    continue
                for sign in (1, -1):
                    # The neighbour k grid steps before (sign 1) or after proposes its match
                    # moved by the signed torus distance between the two patches.
                    other = (np.arange(n) - sign * k) % n
                    shift = (pos - pos[other] + size // 2) % size - size // 2
                    sr, sc = np.divmod(np.roll(flat, sign * k, axis=axis), ws)
                    if axis == 0:
                        consider(sr + shift[:, None], sc)
                    else:
                        consider(sr, sc + shift[None, :])
        radius = max(hs, ws)
        while radius >= 1:
            r, c = np.divmod(flat, ws)
            consider(r + rng.integers(-radius, radius + 1, r.shape),
                     c + rng.integers(-radius, radius + 1, c.shape))
            radius //= 2
    nnf[:, :, 0], nnf[:, :, 1] = np.divmod(flat, ws)
    return cost

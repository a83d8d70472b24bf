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

Deviations, one line each:
- the SSD is computed in float64 (the expansion subtracts large sums; float32 would lose the
  small differences between good candidates);
- a closed path is found by a second pass started where the open path is cheapest, ended
  within one entry of its start (exact for the loop through that entry).
"""

from __future__ import annotations

import numpy as np
import scipy.fft as sfft

from .parallel import threads

__all__ = ["Search", "block_means", "min_error_path"]


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

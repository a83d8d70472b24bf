"""The lattice of a regular photo: the period vectors along which its elements repeat.

Liu, Collins & Tsin 2004, 3.1: the lattice of a periodic pattern is read from the peaks of its
autocorrelation. Here the autocorrelation of the luminance's periodic component (Moisan 2011;
Wiener-Khinchin: the inverse FFT of its power spectrum), normalised to 1 at the origin; its
peaks are the local maxima above ``PEAK`` outside the origin's own lobe (the connected part
around it above ``PEAK``) that stand ``PROMINENCE`` above the autocorrelation halfway to them.
The first period vector ``t1`` is the highest peak (the shortest within ``NEAR`` of it: a
running bond's courses alone, its head joints in anti-phase, peak lower than a whole repeat);
the second, ``t2``, the shortest peak not along ``t1`` (more than ``ANGLE`` off it), at least
``HALF`` as high and no lower than the autocorrelation half a ``t1`` either side of it. A lattice
is confirmed where the autocorrelation also peaks at ``t1 + t2`` or ``t1 - t2`` (the
lattice's next points); otherwise, or without two such peaks, there is no lattice (a
stochastic photo, or rows without a repeat along them).

Deviations, one line each:
- the photo is read on block means (``f`` x ``f``, ``f`` the least power of two bringing it
  within ``SIDE`` pixels a side): a 12 MP photo's lattice is read in about 0.1 s, at the scale
  of its elements; the vectors are in the photo's pixels (within ``f``);
- peaks farther than a third of the read photo's side are not read (seen fewer than three
  times);
- no symmetry group (Liu et al. 4): only the translations;
- each row's and each column's mean taken out first: a course's bed joint correlates at every
  shift along it, and its ridge hid the repeats along the course (a running bond read as
  courses and half bricks).

Not yet used by make_tileable: its patches held within an eighth of the shorter vector of the
lattice points from where they would continue the kept photo measured no better (the test
brick wall's seam in phase 1.28 against 1.15 at most; dead ends of generated walls 0.27 and
0.13 per 1000 px against 0.34 and 0.17), and the shared photos' repeats (the brick wall's,
the pavers', the setts') read as no lattice.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.fft as sfft
from scipy import ndimage

from .joints import luma, reduce
from .periodic import periodic_component

__all__ = ["Lattice", "find"]

#: The most pixels a side of the photo is read at.
SIDE = 512
#: Least autocorrelation of a peak.
PEAK = 0.2
#: Least angle (degrees) between the two period vectors.
ANGLE = 20.0
#: How far a peak stands above the autocorrelation halfway to it, at least.
PROMINENCE = 0.1
#: Peaks within this share of the highest count as high as it (the shortest is taken).
NEAR = 0.1
#: The second vector's peak is at least this share of the first's.
HALF = 0.5


@dataclass(frozen=True)
class Lattice:
    """Two period vectors, rows ``(dy, dx)`` in the photo's pixels, and their autocorrelation
    peaks' heights."""

    vectors: np.ndarray
    heights: tuple[float, float]

    def off(self, d: np.ndarray) -> np.ndarray:
        """The distance (pixels) from each offset ``d`` (..., 2), ``(dy, dx)``, to the nearest
        lattice point.

        Examples
        --------
        >>> lattice = Lattice(np.array([[0.0, 40.0], [16.0, 20.0]]), (0.9, 0.9))
        >>> lattice.off(np.array([[32.0, 80.0], [16.0, 25.0]])).round(1).tolist()
        [0.0, 5.0]
        """
        d = np.asarray(d, np.float64)
        coefficients = d @ np.linalg.inv(self.vectors)  # d = a t1 + b t2
        nearest = np.rint(coefficients) @ self.vectors
        best = np.linalg.norm(d - nearest, axis=-1)
        for step in ((1, 0), (0, 1), (1, 1), (1, -1)):  # the nearest in pixels, not in (a, b)
            for sign in (1, -1):
                moved = nearest + sign * (np.array(step) @ self.vectors)
                best = np.minimum(best, np.linalg.norm(d - moved, axis=-1))
        return best


def _shortest_highest(d: np.ndarray, height: np.ndarray) -> np.ndarray:
    """The shortest of the peaks ``d`` within ``NEAR`` of the highest."""
    near = height >= (1 - NEAR) * height.max()
    return d[near][np.argmin(np.hypot(d[near, 0], d[near, 1]))]


def find(photo: np.ndarray) -> Lattice | None:
    """The lattice of ``photo`` (H, W[, C]), or None when it has none (see the module).

    Examples
    --------
    >>> i, j = np.mgrid[:192, :240]
    >>> wall = np.where((i % 16 < 3) | ((j + 20 * (i // 16 % 2)) % 40 < 3), 0.2, 0.7)
    >>> find(wall).vectors.tolist()  # the next course, half a brick (of 40) either way
    [[16.0, -20.0], [16.0, 20.0]]
    >>> find(np.random.default_rng(0).random((192, 240))) is None
    True
    """
    y = luma(photo)
    f = 1
    while max(y.shape) > SIDE * f:
        f *= 2
    g = periodic_component(reduce(y, f)).astype(np.float64)
    # Less each row's and each column's mean: lines along a whole row (a course's bed joint)
    # correlate at every shift along it, a ridge that would hide the repeats along it.
    g -= g.mean(axis=1, keepdims=True)
    g -= g.mean(axis=0, keepdims=True)
    h, w = g.shape
    a = sfft.irfft2(np.abs(sfft.rfft2(g)) ** 2, s=(h, w))
    if a[0, 0] <= 1e-12 * h * w:
        return None
    a = np.fft.fftshift(a / a[0, 0])
    cy, cx = h // 2, w // 2
    high = a > PEAK
    labels, _ = ndimage.label(high)
    peaks = high & (a == ndimage.maximum_filter(a, 3)) & (labels != labels[cy, cx])
    dy, dx = np.nonzero(peaks)
    d = np.stack([dy - cy, dx - cx], axis=1).astype(np.float64)
    keep = (np.abs(d[:, 0]) < h / 3) & (np.abs(d[:, 1]) < w / 3)
    d, height = d[keep], a[dy[keep], dx[keep]]
    # A period's peak stands above the autocorrelation halfway to it (elements in anti-phase
    # there); a bump on a ridge (rows that correlate along their whole length) does not.
    half = a[(cy + np.rint(d[:, 0] / 2).astype(int)) % h,
             (cx + np.rint(d[:, 1] / 2).astype(int)) % w]
    standing = height - half > PROMINENCE
    # One of each pair +-v: the upper half plane (dy > 0, or dy == 0 and dx > 0).
    upper = (d[:, 0] > 0) | ((d[:, 0] == 0) & (d[:, 1] > 0))
    d, height = d[standing & upper], height[standing & upper]
    if len(d) < 2:
        return None
    t1 = _shortest_highest(d, height)
    sine = np.abs(t1[0] * d[:, 1] - t1[1] * d[:, 0]) / (np.hypot(*t1) * np.hypot(d[:, 0], d[:, 1]))
    across = sine > np.sin(np.radians(ANGLE))
    if not across.any():
        return None
    # The shortest peak across t1 at least HALF as high, and no lower than the autocorrelation
    # half a t1 either side of it (a running bond's courses alone peak between its repeats).
    beside = [a[(cy + np.rint(d[:, 0] + k * t1[0] / 2).astype(int)) % h,
                (cx + np.rint(d[:, 1] + k * t1[1] / 2).astype(int)) % w] for k in (-1, 1)]
    across &= (height >= HALF * a[cy + int(t1[0]), (cx + int(t1[1])) % w]) & (
        height >= np.maximum(*beside))
    if not across.any():
        return None
    candidates = np.flatnonzero(across)
    t2 = d[candidates[np.argmin(np.hypot(d[candidates, 0], d[candidates, 1]))]]
    # Confirmed by a peak at t1 + t2 or t1 - t2 (within a pixel of the read photo).
    near = [np.abs(a[(cy + int(p[0]) + np.arange(-1, 2)[:, None]) % h,
                     (cx + int(p[1]) + np.arange(-1, 2)[None, :]) % w]).max()
            for p in (t1 + t2, t1 - t2)]
    if max(near) <= PEAK:
        return None
    t2 = min((t2, t2 - t1, t2 + t1), key=lambda v: float(np.hypot(*v)))  # the reduced basis
    if t2[0] < 0 or (t2[0] == 0 and t2[1] < 0):
        t2 = -t2
    vectors = np.array([t1, t2]) * f
    return Lattice(vectors, (float(a[cy + int(t1[0]), cx + int(t1[1])]),
                             float(a[(cy + int(t2[0])) % h, (cx + int(t2[1])) % w])))

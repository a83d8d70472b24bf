"""The rhythm of a man-made surface across one direction: the period of its courses.

Bricks, setts and pavers are laid in courses: the bed joints make the photo's row means (the
luminance averaged along each row) a periodic profile, whatever the bond does along the rows
(a running bond shifts the head joints half a brick a course, which row means do not see).
The period is read from the profile's autocorrelation (Wiener-Khinchin, as
``texsynth.blocks.period``; Liu, Collins & Tsin 2004 find a lattice as the autocorrelation's
peaks): at a lag ``k`` that is a local maximum, the repeat's strength is the least of the
correlations at ``k`` and ``2k`` (a period seen at least four times: Substance Sampler's Auto
Tiling asks three), and the period is the shortest lag within ``NEAR`` of the strongest
repeat. A profile whose strongest repeat is under ``LEVEL`` has no rhythm (gravel, sand, a
mixture, noise: their row means repeat nothing).

Deviations, one line each: one direction at a time, the rows' period alone (not the 2-D
lattice of Liu et al.: the band across a wrap needs only the period across it); the profile's
linear trend is removed first (a photo lit from one side); the correlation at each lag is
normalised by the pairs it sums (unbiased), lags up to a quarter of the profile (at a third,
the caustics of a 120-pixel crop of pool water read as courses).
"""

from __future__ import annotations

import numpy as np
from scipy import ndimage

from .joints import luma

__all__ = ["course_period"]

#: Least repeat strength (correlation at the period and at twice it) of a rhythm: smooth noise
#: (8 seeds) and the shared large stochastic photos (rock, asphalt, grass, dirt, layered rock)
#: read at most 0.18, the shared brick wall 0.31, the setts 0.58, walls drawn by code 0.8-1.
LEVEL = 0.3
#: The period is the shortest lag whose repeat is within this share of the strongest.
NEAR = 0.9


def course_period(image: np.ndarray) -> int | None:
    """The period in pixels of the courses of ``image`` (H, W[, C]) down its rows (transpose
    it for its columns), or ``None`` where its row means have no rhythm.

    References
    ----------
    Liu, Collins & Tsin 2004 (a lattice from the autocorrelation's peaks).

    Examples
    --------
    >>> i = np.arange(120)[:, None] + np.zeros((1, 80))
    >>> course_period((i % 24 < 3) + np.random.default_rng(0).normal(0, 0.1, i.shape))
    24
    >>> print(course_period(np.random.default_rng(0).random((120, 80))))
    None
    """
    p = luma(image).mean(axis=1, dtype=np.float64)
    n = len(p)
    if n < 9:
        return None
    t = np.arange(n)
    p = p - np.polyval(np.polyfit(t, p, 1), t)
    a = np.correlate(p, p, "full")[n - 1:] / (n - t)
    if a[0] <= 1e-12:
        return None  # a flat profile
    a /= a[0]
    below = np.nonzero(a[:n // 4 + 1] < 0)[0]  # lags inside the origin's lobe are no period
    if len(below) == 0:
        return None
    k = np.arange(below[0], n // 4 + 1)
    peak = (a[k] >= a[k - 1]) & (a[k] >= a[np.minimum(k + 1, n - 1)])
    twice = ndimage.maximum_filter1d(a, 5)[np.minimum(2 * k, n - 1)]  # within 2 px of 2k
    strength = np.where(peak, np.minimum(a[k], twice), -1.0)
    best = strength.max()
    if best < LEVEL:
        return None
    return int(k[np.nonzero(strength >= NEAR * best)[0][0]])

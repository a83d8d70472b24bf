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

Along the rows, :func:`bond` reads the rest of the lattice (Liu, Collins & Tsin 2004's second
period vector) where the courses' head joints recur: their period ``Q`` along a course and the
shift ``s`` from one course to the next (a running bond's half element, 0 for a stack bond).
Deviations, one line each:
- read on the luminance less each row's mean (the bed joints) and its trend along the row (each
  element's own shade: a Gaussian of a sixteenth of the course period), averaged down the rows
  over half a course (a head joint spans its course, the grain does not): on the luminance as
  it is, the concrete pavers' repeat along a course read 0.05-0.1, under the grain's;
- ``s`` is the strongest correlation between rows a course apart, confirmed between rows two
  courses apart at ``2 s`` (within 2 px, modulo ``Q``; where the photo holds them): courses
  each shifted at random matched by chance a course apart (0.2-0.3); ``Q`` the repeat within a
  row chosen as the period is (the shortest within ``NEAR`` of the strongest), then refined as
  the distance from ``s`` to the next peak of that correlation (on the pavers' 512 crop, two
  pavers wide, the repeat within a row read 245 px, the pavers are 258-261 px);
- lags under half the width (a repeat seen twice, not Substance Sampler's three times: a
  crop two elements wide has a bond to keep).

Where the courses are, :func:`course_phase` reads their local phase (complex demodulation at
the course frequency, Bloomfield 1976, 7: the luminance times ``exp(-2 pi i y / P)``, low-passed
down the rows over a period and along them over a band), at the strongest harmonic of the
repeat (its period ``P / m``, ``m`` 1 to 4: the shared brick wall's repeat is two courses, the
setts' three rows) read to a fraction of a pixel (the row means' spectrum, zero-padded eight
times, its peak interpolated by a parabola): a photo's courses are seldom a whole number of
pixels (the shared brick wall's are 8.2 px at 256), and copies taken at whole multiples of the
rounded period drift out of phase across the photo.
Deviations, one line each: one period for the whole photo (a wall photographed square on:
perspective would bend it); the band along the rows is a box, the low pass down them a Gaussian
of one period.
"""

from __future__ import annotations

import numpy as np
import scipy.fft as sfft
from scipy import ndimage

from .joints import luma

__all__ = ["course_period", "course_phase", "bond", "lattice"]

#: Least repeat strength (correlation at the period and at twice it) of a rhythm: smooth noise
#: (8 seeds) and the shared large stochastic photos (rock, asphalt, grass, dirt, layered rock)
#: read at most 0.18, the shared brick wall 0.31, the setts 0.58, walls drawn by code 0.8-1.
LEVEL = 0.3
#: The period is the shortest lag whose repeat is within this share of the strongest.
NEAR = 0.9
#: Least correlation of a bond: within a row at ``Q`` and between rows a course (two) apart
#: at ``s`` (``2 s``). The pavers' centre 512 reads 0.11, 0.48 (0.2 or more), walls drawn by
#: code 0.8; the shared brick wall, granite setts and the whole pavers photo (whose courses
#: drift a few pixels) fall under one of them, as do courses shifted at random.
BOND_ROW, BOND_COURSE = 0.1, 0.2


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


def course_phase(image: np.ndarray, period: int, width: int, step: int = 1
                 ) -> tuple[float, np.ndarray]:
    """The courses' period to a fraction of a pixel and their local phase: ``(P', theta)``,
    theta float32 (H, ceil(W / step)) in radians, so that the courses of ``image`` (H, W[, C])
    near row ``y`` and column ``x * step`` go as ``cos(2 pi y / P' + theta[y, x])``; ``P'`` is
    the strongest harmonic's period, ``period`` over a whole number (one course of a repeat
    of several).

    Parameters
    ----------
    image : array (H, W) or (H, W, C)
    period : int
        The courses' repeat down the rows (:func:`course_period`).
    width : int
        The band along the rows (pixels) over which the phase is averaged.
    step : int
        Every ``step``-th column of the phase is returned.

    References
    ----------
    Bloomfield 1976, "Fourier Analysis of Time Series", 7 (complex demodulation).

    Examples
    --------
    >>> y = np.arange(200)[:, None] + np.zeros((1, 60))
    >>> period, theta = course_phase(np.cos(2 * np.pi * (y - 3) / 12.4), 25, width=20)
    >>> round(period, 1), round(float(np.mod(theta[100, 30] * 12.4 / (2 * np.pi), 12.4)), 1)
    (12.4, 9.4)
    """
    z = luma(image)
    h = z.shape[0]
    y = np.arange(h)
    z = z - np.float32(z.mean())
    p = z.mean(axis=1, dtype=np.float64)
    p = p - np.polyval(np.polyfit(y, p, 1), y)
    n = 8 * sfft.next_fast_len(h)
    power = np.abs(sfft.rfft(p * np.hanning(h), n)) ** 2
    best, nu = -1.0, 1 / period
    for m in range(1, 5):  # the harmonic m / period, within half a repeat's frequency
        lo, hi = int((m - 0.5) * n / period), min(int((m + 0.5) * n / period), len(power) - 2)
        if lo >= hi:
            break
        k = lo + int(np.argmax(power[lo:hi]))
        if power[k] > best and k > 0:
            a, b, c = power[k - 1:k + 2]
            best, nu = power[k], (k + 0.5 * (a - c) / max(a - 2 * b + c, -1e300)) / n
    refined = 1 / nu
    band = ndimage.uniform_filter1d(z, max(1, width), axis=1, mode="nearest")[:, ::step]
    band = band * np.exp(-2j * np.pi * y / refined).astype(np.complex64)[:, None]
    sigma = refined
    theta = np.arctan2(ndimage.gaussian_filter1d(band.imag, sigma, axis=0, mode="nearest"),
                       ndimage.gaussian_filter1d(band.real, sigma, axis=0, mode="nearest"))
    return float(refined), theta.astype(np.float32)


def _peaks(a: np.ndarray) -> np.ndarray:
    """Where ``a`` is a local maximum (its ends never)."""
    k = np.arange(1, len(a) - 1)
    return k[(a[k] >= a[k - 1]) & (a[k] >= a[k + 1])]


def bond(image: np.ndarray, period: int | None) -> tuple[int, int] | None:
    """The bond of the courses of ``image`` (H, W[, C]) with the course ``period`` down its rows
    (:func:`course_period`): ``(Q, s)``, the head joints' period along a course and their shift
    from one course to the next (``0 <= s < Q``), so that a shift of ``n`` courses and
    ``n s + k Q`` columns maps the lattice onto itself; ``None`` where the elements of a
    course are not in line (or no period is given).

    References
    ----------
    Liu, Collins & Tsin 2004 (a lattice from the autocorrelation's peaks).

    Examples
    --------
    >>> i, j = np.mgrid[:192, :256]
    >>> wall = (i % 24 < 3) | ((j + 20 * (i // 24)) % 64 < 3)  # each course 20 px on
    >>> wall = wall + np.random.default_rng(0).normal(0, 0.1, wall.shape)
    >>> bond(wall, course_period(wall))
    (64, 44)
    """
    h, w = image.shape[:2]
    if period is None or not 0 < period < h or w < 16:
        return None
    z = luma(image).astype(np.float64)
    z -= z.mean(axis=1, keepdims=True)
    z -= ndimage.gaussian_filter1d(z, max(1.0, period / 16), axis=1, mode="nearest")
    z = ndimage.uniform_filter1d(z, max(1, period // 2), axis=0, mode="nearest")
    n = sfft.next_fast_len(2 * w, real=True)
    spectra = sfft.rfft(z, n, axis=1)
    lag = np.arange(w // 2)
    row = sfft.irfft((spectra * spectra.conj()).real.sum(axis=0), n)[:w // 2] / (h * (w - lag))
    r0 = row[0]
    if r0 <= 1e-12:
        return None
    lags = np.arange(1 - w // 2, w // 2)

    def courses(k):  # the correlation of rows k courses apart, at each lag along the rows
        c = sfft.irfft((spectra[:-k * period].conj() * spectra[k * period:]).sum(axis=0), n)
        return c[lags % n] / ((h - k * period) * (w - np.abs(lags)) * r0)

    course = courses(1)
    row /= r0
    lobe = np.nonzero(row < 0)[0]
    peaks = _peaks(row)
    peaks = peaks[peaks > (lobe[0] if len(lobe) else len(row))]
    if len(peaks) == 0 or row[peaks].max() < BOND_ROW or course.max() < BOND_COURSE:
        return None
    q = int(peaks[np.nonzero(row[peaks] >= NEAR * row[peaks].max())[0][0]])
    s = int(course.argmax())
    # Q refined: the distance from s to the nearest peak of the courses' correlation a period on.
    near = _peaks(course)
    near = near[np.abs(np.abs(near - s) - q) <= q // 8]
    if len(near):
        q = int(np.abs(near[course[near].argmax()] - s))
    if 2 * period < h:  # two courses on, the shift twice over: a lattice, not a chance match
        twice = ndimage.maximum_filter1d(courses(2), 5)
        at = 2 * lags[s] + q * np.arange(-(w // q) - 2, w // q + 3)
        at = at[np.abs(at) < w // 2] + w // 2 - 1
        if len(at) == 0 or twice[at].max() < BOND_COURSE:
            return None
    return q, int(lags[s]) % q


def lattice(image: np.ndarray, repeat: float) -> tuple[int, int, int] | None:
    """The courses' lattice ``(P, Q, s)`` of ``image`` (H, W[, C]): :func:`course_period` P and
    :func:`bond` (Q, s), where the luminance correlates with itself shifted by each period
    vector, (P, s) and (0, Q), at least ``repeat`` (elements laid to a gauge); else ``None``.

    References
    ----------
    Liu, Collins & Tsin 2004 (the lattice's two period vectors).

    Examples
    --------
    >>> i, j = np.mgrid[:192, :256]
    >>> wall = (i % 24 < 3) | ((j + 32 * (i // 24)) % 64 < 3)  # running bond
    >>> wall = wall + np.random.default_rng(0).normal(0, 0.1, wall.shape)
    >>> lattice(wall, 0.35)
    (24, 64, 32)
    >>> print(lattice(np.random.default_rng(0).random((192, 256)), 0.35))
    None
    """
    period = course_period(image)
    found = None if period is None else bond(image, period)
    if found is None:
        return None
    z = luma(image).astype(np.float64)
    h, w = z.shape
    for dy, dx in ((period, found[1]), (0, found[0])):
        a, b = z[:h - dy, :w - dx], z[dy:, dx:]
        a, b = a - a.mean(), b - b.mean()
        if (a * b).mean() < repeat * np.sqrt((a * a).mean() * (b * b).mean()):
            return None
    return period, *found

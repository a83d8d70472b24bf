"""How far an exemplar's structure reaches: its longest correlation length.

In Paget & Longstaff 1998's multiscale MRF the coarsest grid's neighbourhood, at that grid's
spacing, is what captures the texture's longest interactions. This block
measures that reach from the exemplar: the autocorrelation of its luminance (the inverse FFT of
the power spectrum, Wiener-Khinchin, of the periodic component, Moisan 2011), normalised to 1
at the origin, is followed along rays in ``ANGLES`` directions; the correlation length of a
direction is the first distance at which it falls below ``LEVEL``, and the texel size is twice
the longest of them (a lobe counted both ways). Lines and rows of bricks correlate along their
whole length, pebbles over their width.

Deviations, one line each: a measured reach, not a lattice (a photo's perspective and irregular
joints blur the off-origin peaks of Liu, Collins & Tsin 2004); reaches are capped at a third of
the exemplar, the longest any repeat can be seen twice.
"""

from __future__ import annotations

import numpy as np
import scipy.fft as sfft

from .periodic import periodic_component

__all__ = ["texel_size"]

#: The autocorrelation level that ends a correlation length.
LEVEL = 0.2
#: Directions over the half circle along which correlation lengths are measured.
ANGLES = 36


def texel_size(exemplar: np.ndarray) -> float:
    """Twice the longest correlation length of ``exemplar`` (H, W, C), in pixels: between 2 and
    two thirds of its shorter side."""
    h, w = exemplar.shape[:2]
    reach = min(h, w) // 3
    lum = periodic_component(exemplar.mean(axis=2, dtype=np.float32)).astype(np.float64)
    lum -= lum.mean()
    a = sfft.irfft2(np.abs(sfft.rfft2(lum)) ** 2, s=(h, w))
    if a[0, 0] <= 1e-12 * h * w:
        return 2.0  # a flat exemplar: nothing correlates beyond a pixel
    a /= a[0, 0]
    theta = np.pi * np.arange(ANGLES) / ANGLES
    d = np.arange(1, reach + 1)
    rows = np.rint(np.outer(np.sin(theta), d)).astype(np.int64) % h
    cols = np.rint(np.outer(np.cos(theta), d)).astype(np.int64) % w
    low = a[rows, cols] < LEVEL  # (ANGLES, reach): the autocorrelation along each ray
    length = np.where(low.any(axis=1), d[low.argmax(axis=1)], reach)
    return 2.0 * float(length.max())

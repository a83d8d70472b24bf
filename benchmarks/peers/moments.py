"""The textbook plane estimate the benchmark compares against: spectral second moments.

An isotropic texture seen at slant sigma is foreshortened by cos(sigma) along the tilt, so its
power spectrum is stretched by 1 / cos(sigma) there (Forsyth & Ponce, Computer Vision: A Modern
Approach, sec. 11.4.1, isotropy applied to the whole image at once). The second-moment matrix
M = sum_w w w^T |I(w)|^2 of the Hann-windowed image then has eigenvalues in the ratio
cos^2(sigma), the larger one along the tilt. Orthographic: tilt mod 180, no focal length.
Deviation, in one line: photos without texture are refused with texsynth's own test
(``texture_mask``), so both sides refuse the same inputs.
"""

from __future__ import annotations

import math

import numpy as np

from texsynth.plane import PlaneEstimate, normal_from_angles
from texsynth.plane.spectra import luminance, texture_mask

__all__ = ["moments", "estimate"]


def moments(lum: np.ndarray) -> tuple[float, float]:
    """(slant, tilt mod 180) in degrees from the spectral second-moment matrix of ``lum``."""
    h, w = lum.shape
    taper = np.outer(np.hanning(h), np.hanning(w))
    a = (lum - lum.mean()) * taper
    power = np.abs(np.fft.rfft2(a)) ** 2
    fx = np.fft.rfftfreq(w)[None, :] + 0 * np.fft.fftfreq(h)[:, None]
    fy = -np.fft.fftfreq(h)[:, None] + 0 * fx
    weight = power * np.where(fx > 0, 2.0, 1.0)  # the half-plane stands for both halves
    m = np.array([[np.sum(weight * fx * fx), np.sum(weight * fx * fy)],
                  [np.sum(weight * fx * fy), np.sum(weight * fy * fy)]])
    values, vectors = np.linalg.eigh(m)
    if values[1] <= 0:
        raise ValueError("image has no texture (it is blank or nearly constant)")
    slant = math.degrees(math.acos(math.sqrt(max(values[0], 0.0) / values[1])))
    tilt = math.degrees(math.atan2(vectors[1, 1], vectors[0, 1])) % 180.0
    return slant, tilt


def estimate(image) -> PlaneEstimate:
    """The baseline as a :class:`~texsynth.plane.PlaneEstimate` (it states no uncertainty:
    confidence 0, the receding direction and focal length never claimed)."""
    lum = luminance(image)
    texture_mask(lum)  # the same "no texture" error as texsynth
    slant, tilt = moments(lum)
    return PlaneEstimate(
        slant=slant, tilt=tilt, normal=tuple(float(c) for c in normal_from_angles(slant, tilt)),
        focal_px=None, focal_estimated=False, tilt_ambiguous_180=True, confidence=0.0,
        slant_uncertainty=90.0, tilt_uncertainty=180.0, normal_uncertainty=90.0,
        focal_uncertainty=None, anisotropy=0.0, method="moments",
        image_size=(lum.shape[1], lum.shape[0]))

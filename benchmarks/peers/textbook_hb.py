"""Heeger-Bergen built the textbook way: the reference texsynth's speed-ups are measured against.

Forsyth & Ponce, section 11.3.2: Algorithm 11.4 (iterate: analyse the working image, match every
subband's histogram to the exemplar's, rebuild, match the pixel histogram) with Algorithm 11.3
done by sorting: both cumulative histograms are formed at every match (the source ranked with an
argsort, the target sorted). The pyramid is pyrtools' ``SteerablePyramidFreq`` (float64, rebuilt
every iteration, as its API is used); colour is PCA-decorrelated as in Torralba, Isola & Freeman,
section 28.3. Nothing here comes from texsynth, so a bug there cannot flatter the comparison.

Deviations, one line each: the noise is uniform on [0, 1) from ``numpy.random.default_rng(seed)``;
the result is clipped to the exemplar's per-channel range, as texsynth does; no periodic + smooth
split of the exemplar (the textbook has none).
"""

from __future__ import annotations

import math
import warnings

import numpy as np


def sort_match(source: np.ndarray, target: np.ndarray) -> np.ndarray:
    """Algorithm 11.3 by sorting: the k-th smallest source value gets the k-th target quantile."""
    order = np.argsort(source, axis=None)
    values = np.sort(target, axis=None)
    out = np.empty(source.size, np.float64)
    out[order] = np.interp(np.linspace(0, 1, source.size), np.linspace(0, 1, values.size), values)
    return out.reshape(source.shape)


def _pca(exemplar: np.ndarray):
    """Mean and principal axes (columns, strongest first) of the exemplar's colours."""
    x = exemplar.reshape(-1, exemplar.shape[2]).astype(np.float64)
    mean = x.mean(axis=0)
    _, axes = np.linalg.eigh(np.atleast_2d(np.cov(x - mean, rowvar=False)))
    return mean, axes[:, ::-1]


def textbook_hb(exemplar, width, height, seed, scales=4, orientations=4, iterations=15):
    """(height, width, C) float32 from the (H, W, C) exemplar; depth capped as texsynth caps it."""
    import pyrtools as pt

    depth = min(scales, *(int(math.log2(min(s))) - 2 for s in (exemplar.shape[:2],
                                                                  (height, width))))
    mean, axes = _pca(exemplar)
    components = (exemplar.reshape(-1, exemplar.shape[2]) - mean) @ axes
    components = components.reshape(exemplar.shape)
    noise = np.random.default_rng(seed).random((height, width, exemplar.shape[2]))
    out = np.empty_like(noise)
    for c in range(exemplar.shape[2]):
        target = components[:, :, c]
        with warnings.catch_warnings():  # odd-sized exemplar: analysed only, never rebuilt
            warnings.filterwarnings("ignore", "Reconstruction will not be perfect")
            target_bands = pt.pyramids.SteerablePyramidFreq(target, depth,
                                                            orientations - 1).pyr_coeffs
        image = sort_match(noise[:, :, c], target)
        for _ in range(iterations):
            pyr = pt.pyramids.SteerablePyramidFreq(image, depth, orientations - 1)
            for key, band in pyr.pyr_coeffs.items():
                pyr.pyr_coeffs[key] = sort_match(band, target_bands[key])
            image = sort_match(pyr.recon_pyr(), target)
        out[:, :, c] = image
    result = (out.reshape(-1, out.shape[2]) @ axes.T + mean).reshape(out.shape)
    return np.clip(result, exemplar.min(axis=(0, 1)), exemplar.max(axis=(0, 1))).astype(np.float32)

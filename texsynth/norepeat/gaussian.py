"""The Gaussianised texture and its inverse look-up table, for tiling and blending.

Heitz & Neyret 2018, 3 and Deliot & Heitz 2019, 1.3-1.4: blending three randomly offset copies
of a texture with the variance-preserving operator keeps its histogram only when the values are
Gaussian. So each channel of the exemplar (decorrelated by PCA first when asked: Deliot &
Heitz 2019, 1.4) is sent by its rank onto a Gaussian (the texture ``T``), and a table ``T^-1``
sends a blended Gaussian value back to the exemplar's value (Heitz & Neyret 2018, 3.2).

Deviations, one line each:

- PCA is off by default: the principal components of real photos are uncorrelated but not
  independent, and blending them independently invents colours; the RGB channels, blended with
  the same offsets and weights, keep more of the joint colour distribution (tiling and blending
  256 px crops, sRGB W1 of the worst channel, PCA -> RGB: pool water 0.020 -> 0.013, gravel
  0.0078 -> 0.0025; colours over 0.06 from every photo colour: pool water 1.9 % -> 0.7 %,
  gravel 1.0 % -> 0.003 %, brick wall 0.6 % -> 0.2 %);
- the Gaussian is truncated to [0, 1] (Burley 2019, 2): every rank maps inside the texture's
  range, so no extreme value is clipped away before blending;
- the inverse PCA is folded into the table: row ``k`` holds ``basis[:, k] * T_k^-1(g) +
  mean / C``, so a renderer sums ``C`` looked-up colours and needs no per-texture constants;
- no LOD-filtered tables (Heitz & Neyret 2018, 4): a path tracer evaluates the look-up per
  sample, before the pixel filter averages.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.special import ndtr, ndtri

from .. import validation
from ..blocks.color import ColorPCA

__all__ = ["Gaussianized", "gaussianize", "predict_memory", "MU", "SIGMA", "LUT_SIZE",
           "CURVE_POINTS"]

#: Mean and standard deviation of the Gaussian (Deliot & Heitz 2019, 1.3: 0.5 and 1/6).
MU, SIGMA = 0.5, 1.0 / 6.0
#: Entries of the inverse table per channel (Deliot & Heitz 2019 use 128 at 8 bits; more here
#: so the table's steps stay under a 16-bit value's).
LUT_SIZE = 4096
#: Points of the table as curves (``Gaussianized.curves``): Blender's curves hold 257 samples
#: (``CM_TABLE + 1``), Cycles bakes 256.
CURVE_POINTS = 257
#: Largest exemplar side taken (pixels).
MAX_SIDE = validation.MAX_SIDE


@dataclass(frozen=True)
class Gaussianized:
    """The precomputation: ``gaussian`` (H, W, C) in [0, 1], the decorrelated channels made
    Gaussian; ``lut`` (C, L, C): row ``k``, entry ``j`` is the colour that channel ``k``'s
    Gaussian value ``(j + 0.5) / L`` contributes; the colour of Gaussian values ``g`` is
    ``sum_k lut[k, j_k]`` with ``j_k = g_k * L - 0.5`` read with linear interpolation."""

    gaussian: np.ndarray
    lut: np.ndarray
    pca: ColorPCA

    def look_up(self, g: np.ndarray) -> np.ndarray:
        """The exemplar's colours for Gaussian values ``g`` (..., C), clamped to [0, 1]."""
        c, size = self.lut.shape[:2]
        j = np.clip(np.asarray(g, np.float32) * size - 0.5, 0, size - 1)
        j0 = np.minimum(j.astype(np.int64), size - 2) if size > 1 else np.zeros(j.shape, int)
        t = (j - j0)[..., None].astype(np.float32)
        out = np.zeros(np.shape(g)[:-1] + (self.lut.shape[2],), np.float32)
        for k in range(c):
            lo = self.lut[k][j0[..., k]]
            hi = self.lut[k][np.minimum(j0[..., k] + 1, size - 1)]
            out += lo + t[..., k, :] * (hi - lo)
        return out


    def curves(self, points: int = CURVE_POINTS) -> np.ndarray:
        """The table as one curve per output channel, (points, C): channel ``j``'s colour at
        the Gaussian value ``i / (points - 1)`` of every channel, what a renderer's per-channel
        curve node (Blender's RGB Curves) reads in one go instead of ``C`` table reads. Only
        without PCA (``decorrelate=False``): then output channel ``j`` depends on Gaussian
        channel ``j`` alone.

        Examples
        --------
        >>> photo = np.random.default_rng(0).random((32, 32, 3)).astype(np.float32)
        >>> g = gaussianize(photo, lut_size=256)
        >>> g.curves(65).shape
        (65, 3)
        >>> x = np.full((1, 3), 0.25, np.float32)
        >>> bool(np.allclose(g.curves(65)[16], g.look_up(x)[0]))
        True
        """
        points = validation.whole(points, "points", 2, 65536)
        basis = self.pca.basis
        if not np.allclose(basis, np.diag(np.diag(basis))):
            raise ValueError("the table mixes channels (decorrelate=True): it is no "
                             "per-channel curve")
        x = np.linspace(0.0, 1.0, points, dtype=np.float32)
        return self.look_up(np.repeat(x[:, None], self.gaussian.shape[2], axis=1))


def predict_memory(shape) -> float:
    """Peak bytes of :func:`gaussianize` on an exemplar of ``shape`` (H, W[, C]): the float32
    input and components, the float64 Gaussian of one channel, its two int64 rank orders and the
    float32 result."""
    n = int(shape[0]) * int(shape[1])
    c = int(shape[2]) if len(shape) > 2 else 1
    return n * (4 * c * 3 + 8 * 3 + 8 * c)


def _truncated_quantile(u: np.ndarray) -> np.ndarray:
    """The Gaussian (MU, SIGMA) truncated to [0, 1]: its quantile at ``u`` in (0, 1)."""
    lo, hi = ndtr(-MU / SIGMA), ndtr((1 - MU) / SIGMA)
    return MU + SIGMA * ndtri(lo + u * (hi - lo))


def _truncated_cdf(g: np.ndarray) -> np.ndarray:
    lo, hi = ndtr(-MU / SIGMA), ndtr((1 - MU) / SIGMA)
    return (ndtr((g - MU) / SIGMA) - lo) / (hi - lo)


def gaussianize(exemplar, *, decorrelate: bool = False, lut_size: int = LUT_SIZE) -> Gaussianized:
    """The exemplar's decorrelated channels sent onto a truncated Gaussian, and the table back.

    Parameters
    ----------
    exemplar : array (H, W) or (H, W, C), C in 1, 3, 4
        The texture's values as the renderer reads them (scene-linear colour or data).
    decorrelate : bool
        Gaussianise the principal components of the colours (Deliot & Heitz 2019, 1.4) instead
        of the channels themselves (see the module's deviations for why it is off).
    lut_size : int
        Entries of the inverse table per channel, 16 to 65536.

    Returns
    -------
    Gaussianized
        ``gaussian`` float32 (H, W, C) and ``lut`` float32 (C, lut_size, C).

    References
    ----------
    Heitz & Neyret 2018, 3.2 (the histogram transformation ``T`` and its inverse); Deliot &
    Heitz 2019, 1.3-1.4 (ranks onto a Gaussian of mean 1/2 and deviation 1/6, PCA colour);
    Burley 2019, 2 (the truncated Gaussian).

    Examples
    --------
    >>> photo = np.random.default_rng(0).random((32, 32, 3)).astype(np.float32)
    >>> g = gaussianize(photo, decorrelate=True, lut_size=256)
    >>> g.gaussian.shape, g.lut.shape
    ((32, 32, 3), (3, 256, 3))
    >>> bool(np.abs(g.look_up(g.gaussian) - photo).max() < 0.02)
    True
    """
    a = validation.image(exemplar, min_side=2)
    lut_size = validation.whole(lut_size, "lut_size", 16, 65536)
    h, w, c = a.shape
    if max(h, w) > MAX_SIDE:
        raise ValueError(f"exemplar is {w} x {h} pixels; at most {MAX_SIDE} a side is taken")
    validation.check_memory(predict_memory(a.shape), f"Gaussianising a {w} x {h} texture",
                            "use a smaller texture")
    if not isinstance(decorrelate, bool):
        raise ValueError(f"decorrelate must be True or False, got {decorrelate!r}")
    pca = ColorPCA.fit(a) if decorrelate else ColorPCA(
        a.reshape(-1, c).mean(axis=0, dtype=np.float64).astype(np.float32),
        np.eye(c, dtype=np.float32))
    components = pca.forward(a).reshape(-1, c)
    n = components.shape[0]
    u = (np.arange(n) + 0.5) / n
    gaussian = np.empty((n, c), np.float32)
    x = (np.arange(lut_size) + 0.5) / lut_size  # the table's Gaussian values (texel centres)
    at = _truncated_cdf(x) * n - 0.5  # where each falls among the sorted values
    lut = np.zeros((c, lut_size, c), np.float32)
    for k in range(c):
        order = np.argsort(components[:, k], kind="stable")
        gaussian[order, k] = _truncated_quantile(u)  # rank -> Gaussian quantile
        inverse = np.interp(at, np.arange(n), components[order, k])  # T_k^-1
        lut[k] = inverse[:, None] * pca.basis[:, k] + pca.mean / c
    return Gaussianized(gaussian.reshape(h, w, c), lut, pca)

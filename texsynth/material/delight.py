"""Take the light out of a photo of a surface: a ramp from a window, vignetting, a soft shadow.

How light and surface are told apart, in one line: the light is a smooth multiplicative
field, a low-order cosine series in log-luminance (no basis function varying within
``TEXELS`` texel sizes, ``texsynth.blocks.period``) fitted robustly; the surface is stationary
above its texel size, so its own shading and colour average out of that fit and stay.

This is homomorphic filtering (Oppenheim, Schafer & Stockham 1968: a product made a sum by the
logarithm, then separated by frequency) with the retinex assumption (Land & McCann 1971:
illumination varies slowly, reflectance does not): the photo's log-luminance
l = log Y = log rho + log E is fitted by E's model, log E = sum_k c_k phi_k, phi_k the products
of cosines cos(pi u (x + 1/2) / W) cos(pi v (y + 1/2) / H) for u, v up to the order K (the
DCT-II basis: no constraint at the photo's edges, where a window's ramp is steepest), by
iteratively reweighted least squares with Tukey's biweight (Holland & Welsch 1977; Beaton &
Tukey 1974), so that dark joints, bright specks and pebbles larger than the rest do not pull
the field. Every channel is divided by exp(log E - mean log E): the photo's mean level and its
colour are kept, since a white light's field is the same in every channel.

Deviations, one line each:
- the order K is the least of ``MAX_ORDER`` and the photo's shorter side over ``TEXELS``
  texel sizes, at least 1, the texel size measured on the photo over a wide low-pass (a
  plain low-pass of a fixed width flattens the surface's own shading: the
  baseline of ``benchmarks/sections/material.py``);
- the fit is made on every f-th pixel of every f-th row for the least f that brings the photo
  under ``SAMPLE_PIXELS`` (the field is smooth: a 12 MP photo's fit as its 2^16 samples'),
  then evaluated at every pixel;
- the light's colour is not estimated (white balance is the camera's): only luminance is fitted.
"""

from __future__ import annotations

import numpy as np
from scipy.ndimage import gaussian_filter

from .. import validation
from ..blocks.period import texel_size

__all__ = ["delight", "light_field"]

#: Texel sizes within which no basis function of the light varies (the order's bound).
TEXELS = 4.0
#: Highest order of the cosine series along each axis.
MAX_ORDER = 6
#: The low-pass (share of the shorter side) the photo is divided by to measure its texel size.
PRE = 0.125
#: Pixels the fit is made on at most.
SAMPLE_PIXELS = 1 << 16
#: Tukey's biweight constant, in robust standard deviations (1.4826 x the median |residual|).
TUKEY = 4.685
#: Reweighting rounds.
ROUNDS = 6
#: Luminance floor of the logarithm (a black pixel is no evidence of the light).
FLOOR = 1e-3


def _basis(n: int, order: int, step: int = 1) -> np.ndarray:
    """DCT-II cosines cos(pi u (x + 1/2) / n) for u = 0..order at x = 0, step, ... (n', order+1)."""
    x = np.arange(0, n, step, dtype=np.float64) + 0.5
    return np.cos(np.pi * np.outer(x, np.arange(order + 1)) / n)


def light_field(photo: np.ndarray, *, order: int | None = None) -> np.ndarray:
    """The light's log-luminance field log E (H, W) float32 of ``photo`` (H, W, C), zero mean:
    :func:`delight` divides by its exponential. ``order``: the cosine series' order (default
    from the texel size).

    Examples
    --------
    >>> ramp = 0.5 * np.cos(np.pi * (np.arange(64) + 0.5) / 64)[None, :].repeat(48, axis=0)
    >>> photo = (0.4 * np.exp(ramp))[:, :, None]
    >>> bool(np.abs(light_field(photo, order=2) - ramp).max() < 1e-4)
    True
    """
    a = validation.image(photo, what="photo", channels=None)
    h, w = a.shape[:2]
    if order is None:
        # The texel size of the photo over its low-pass at ``PRE`` of its side: the light's
        # own correlation would otherwise read as a texel of the photo's size.
        rgb = a[:, :, :3] if a.shape[2] >= 3 else a[:, :, :1]
        y = _luminance(rgb)
        low = gaussian_filter(y, PRE * min(h, w), mode="reflect")
        flat = rgb / np.maximum(low, FLOOR)[:, :, None]
        order = int(np.clip(min(h, w) / (TEXELS * texel_size(flat)), 1, MAX_ORDER))
    order = validation.whole(order, "order", 0, 64)
    f = 1
    while (h // f) * (w // f) > SAMPLE_PIXELS:
        f += 1
    y = _luminance(a[::f, ::f])
    log_y = np.log(np.maximum(y, FLOOR)).ravel()
    by, bx = _basis(h, order, f), _basis(w, order, f)
    design = (by[:, None, :, None] * bx[None, :, None, :]).reshape(len(log_y), -1)
    weights = np.ones_like(log_y)
    for _ in range(ROUNDS):
        weighted = design * weights[:, None]  # the normal equations D^T W D c = D^T W l
        c = np.linalg.solve(weighted.T @ design + 1e-9 * np.eye(design.shape[1]),
                            weighted.T @ log_y)
        r = log_y - design @ c
        spread = 1.4826 * np.median(np.abs(r)) + 1e-9
        weights = np.clip(1.0 - (r / (TUKEY * spread)) ** 2, 0.0, None) ** 2
    c = c.reshape(order + 1, order + 1)
    field = _basis(h, order) @ c @ _basis(w, order).T
    return (field - field.mean()).astype(np.float32)


def _luminance(a: np.ndarray) -> np.ndarray:
    if a.shape[2] >= 3:
        return a[:, :, :3].astype(np.float64) @ np.array([0.2126, 0.7152, 0.0722])
    return a[:, :, 0].astype(np.float64)


def delight(photo, *, order: int | None = None, seed: int | None = None) -> np.ndarray:
    """``photo`` (H, W) or (H, W, C) with its light taken out: every colour channel divided by
    the light's smooth field (:func:`light_field`), the mean level and colour kept; alpha
    untouched. float32, the photo's shape.

    Parameters
    ----------
    photo : array (H, W) or (H, W, C), linear-ish values in [0, 1] as texsynth reads photos.
    order : the light's cosine-series order along each axis (default: from the texel size,
        at most ``MAX_ORDER``; 0 takes out nothing, 1 a ramp, 2-6 vignetting and soft shadows).
    seed : unused (the fit is deterministic); accepted as every step of the material takes one.

    References
    ----------
    Oppenheim, Schafer & Stockham 1968, "Nonlinear filtering of multiplied and convolved
    signals" (homomorphic filtering); Land & McCann 1971, "Lightness and retinex theory";
    Holland & Welsch 1977, "Robust regression using iteratively reweighted least-squares"
    (Tukey's biweight); Paget & Longstaff 1998 (the texel size, ``texsynth.blocks.period``).

    Examples
    --------
    >>> rng = np.random.default_rng(0)
    >>> albedo = 0.3 + 0.4 * rng.random((64, 64, 3)).astype(np.float32)
    >>> lit = albedo * np.exp(np.linspace(-0.7, 0.7, 64, dtype=np.float32))[None, :, None]
    >>> out = delight(lit)
    >>> out.shape, out.dtype, bool(np.corrcoef(out.ravel(), albedo.ravel())[0, 1] > 0.98)
    ((64, 64, 3), dtype('float32'), True)
    """
    if seed is not None:
        validation.seed(seed)
    given = np.asarray(photo)
    a = validation.image(given, what="photo", channels=None)
    gain = np.exp(-light_field(a, order=order))[:, :, None]
    out = a.copy()
    colour = min(3, a.shape[2]) if a.shape[2] != 2 else 1
    out[:, :, :colour] *= gain
    return out.reshape(given.shape) if given.ndim == 2 else out

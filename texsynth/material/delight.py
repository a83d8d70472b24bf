"""Take the light out of a photo of a surface: a ramp from a window, vignetting, a soft shadow.

How light and surface are told apart, in one line: the light is a smooth multiplicative field,
the low-degree Legendre coefficients of the log-luminance (fitted robustly) less the surface's
own power there, which is measured on the next degrees, where no light varies (spectral
subtraction: the texture's own low frequencies are kept at the level its statistics predict).

This is homomorphic filtering (Oppenheim, Schafer & Stockham 1968: a product made a sum by the
logarithm, then separated by frequency) with the retinex assumption (Land & McCann 1971:
illumination varies slowly, reflectance does not). The photo's log-luminance
l = log Y = log rho + log E is fitted by the Legendre series sum c_uv phi_uv, phi_uv =
sqrt((2u + 1)(2v + 1)) P_u(s) P_v(t), s = (2x + 1) / W - 1, t = (2y + 1) / H - 1 (orthonormal
on the pixels), u + v up to 2K: polynomials take no condition at the photo's edges (Boyd 2001,
ch. 2: a cosine series has zero slope there, so it converges slowly on a light whose log
falls steepest at the corners, a vignette, a spot's pool), by iteratively reweighted least
squares with Tukey's biweight (Holland & Welsch 1977), so that dark joints, bright specks and
pebbles larger than the rest do not pull it. The coefficients of total degree
d = u + v in (K, 2K] are the surface's alone (the light varies more slowly); their median power
P is the surface's expected power at every lower degree too (a stationary texture's spectrum is
about flat below its texel frequency). The light keeps, of each coefficient of degree d <= K,
the share beyond it: c_uv max(0, 1 - P / c_uv^2) (Boll 1979's spectral subtraction, one
coefficient at a time). Every channel is divided by exp(log E): the photo's mean level and its
colour are kept, a white light's field being the same in every channel.

Deviations, one line each:
- the surface's power is taken flat below degree 2K (a falling spectrum, extrapolated, read a
  rock face's big features as light: residual 0.40-1.00 of the lit photo's, 0.17-0.30 flat);
- the fit is made on every f-th pixel of every f-th row for the least f that brings the photo
  under ``SAMPLE_PIXELS`` (the field is smooth, (2K + 1)^2 coefficients), then evaluated at
  every pixel;
- the light's colour is not estimated (white balance is the camera's): only luminance is fitted;
- an sRGB-encoded photo is decoded first (light multiplies linear radiance; the encoding's
  curve makes it no product there, so a division there left the detail of the dark, vignetted
  corners off: detail correlation 0.975-0.992 under the section's spot light, 0.981-0.996
  decoded; 11 -> 14 of its 15 cases within both goals);
- Legendre polynomials of total degree <= K for the DCT-II cosines of radial order <= K used
  before (the best order-4 cosine fit of the section's spot + vignette field is off by 0.077
  std of log E, by up to 0.16 in a band along the edges, its detail correlation 0.983 on
  dirtRoad even with the light known; the best degree-4 polynomial 0.015, 0.9995): worst
  detail correlation 0.981 -> 0.990, worst shading band 0.956 -> 0.977, median residual
  0.159 -> 0.109, worst 0.298 -> 0.279; the soft shadow's flat-ended edge costs polynomials
  more degrees (rock under it 0.180 -> 0.243).
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from numpy.polynomial import legendre

from .. import validation
from ..blocks.color import linear_to_srgb, luminance, srgb_to_linear
from ..blocks.parallel import serial_blas
from ..progress import Progress

__all__ = ["delight", "light_field"]

#: The light's highest total degree K (the fit goes to 2K): a ramp, a pool, a soft shadow.
ORDER = 4
#: Pixels the fit is made on at most.
SAMPLE_PIXELS = 1 << 14
#: Tukey's biweight constant, in robust standard deviations (1.4826 x the median |residual|).
TUKEY = 4.685
#: Reweighting rounds.
ROUNDS = 4
#: Luminance floor of the logarithm (a black pixel is no evidence of the light).
FLOOR = 1e-3


def _legendre(n: int, degree: int, step: int = 1) -> np.ndarray:
    """sqrt(2d + 1) P_d((2x + 1) / n - 1) for d = 0..degree at x = 0, step, ... (n', degree+1):
    unit mean square over the n pixels."""
    t = (2 * np.arange(0, n, step, dtype=np.float64) + 1) / n - 1
    return legendre.legvander(t, degree) * np.sqrt(2 * np.arange(degree + 1) + 1)


def light_field(photo: np.ndarray, *, order: int = ORDER) -> np.ndarray:
    """The light's log-luminance field log E (H, W) float32 of ``photo`` (H, W, C), zero mean:
    :func:`delight` divides by its exponential. ``order``: the light's highest total degree K.

    Examples
    --------
    >>> x = np.arange(96)
    >>> ramp = 0.5 * np.cos(np.pi * (x + 0.5) / 96)[None, :].repeat(64, axis=0)
    >>> grain = 0.1 * np.random.default_rng(0).standard_normal((64, 96))
    >>> photo = (0.4 * np.exp(ramp + grain))[:, :, None]
    >>> bool(np.abs(light_field(photo) - ramp).max() < 0.02)
    True
    """
    a = validation.image(photo, what="photo", channels=None)
    k = validation.whole(order, "order", 0, 32)
    h, w = a.shape[:2]
    f = 1
    while (h // f) * (w // f) > SAMPLE_PIXELS:
        f += 1
    log_y = np.log(np.maximum(luminance(a[::f, ::f]), FLOOR)).ravel()
    by, bx = _legendre(h, 2 * k, f), _legendre(w, 2 * k, f)
    design = (by[:, None, :, None] * bx[None, :, None, :]).reshape(len(log_y), -1)
    weights = np.ones_like(log_y)
    for _ in range(ROUNDS):
        weighted = design * weights[:, None]  # the normal equations D^T W D c = D^T W l
        c = np.linalg.solve(weighted.T @ design + 1e-9 * np.eye(design.shape[1]),
                            weighted.T @ log_y)
        r = log_y - design @ c
        spread = 1.4826 * np.median(np.abs(r)) + 1e-9
        weights = np.clip(1.0 - (r / (TUKEY * spread)) ** 2, 0.0, None) ** 2
    c = c.reshape(2 * k + 1, 2 * k + 1)
    u = np.arange(2 * k + 1)
    degree = u[:, None] + u[None, :]
    power = c ** 2
    surface = np.median(power[(degree > k) & (degree <= 2 * k)]) if k else 0.0
    gain = np.where(degree <= k, np.clip(1.0 - surface / np.maximum(power, 1e-30), 0, 1), 0)
    light = (_legendre(h, 2 * k) @ (c * gain)).astype(np.float32)
    light = light @ _legendre(w, 2 * k).T.astype(np.float32)
    return light - light.mean()  # zero mean: the photo's level is kept


@serial_blas()
def delight(photo, *, order: int = ORDER, encoded: bool = True, seed: int | None = None,
            progress: Callable[[float, str], object] | None = None) -> np.ndarray:
    """``photo`` (H, W) or (H, W, C) with its light taken out: every colour channel divided by
    the light's smooth field (:func:`light_field`), the mean level and colour kept; alpha
    untouched. float32, the photo's shape.

    Parameters
    ----------
    photo : array (H, W) or (H, W, C), values in [0, 1] as texsynth reads photos.
    order : the light's highest total degree K (0 takes out nothing, 1 a ramp, 2-4 vignetting,
        a spot light's pool and soft shadows).
    encoded : the photo's values are sRGB-encoded (``texsynth.io.read_photo`` of a PNG or
        JPEG): the light is fitted and divided out in linear light, where it multiplies, and
        the result encoded again; False: the values are linear (an EXR) and used as they are.
    seed : unused (the fit is deterministic); accepted as every step of the material takes one.
    progress : ``progress(fraction, message)``; returning False cancels (``Cancelled``).

    References
    ----------
    Oppenheim, Schafer & Stockham 1968, "Nonlinear filtering of multiplied and convolved
    signals" (homomorphic filtering); Land & McCann 1971, "Lightness and retinex theory";
    Holland & Welsch 1977, "Robust regression using iteratively reweighted least-squares"
    (Tukey's biweight); Boyd 2001, "Chebyshev and Fourier Spectral Methods", ch. 2 (a
    polynomial series needs no boundary condition, a cosine series does); Boll 1979,
    "Suppression of acoustic noise in speech using spectral subtraction".

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
    report = Progress(progress)
    report(0.0, "Delight: fitting the light")
    colour = min(3, a.shape[2]) if a.shape[2] != 2 else 1
    out = np.array(a, dtype=np.float32)
    if encoded:
        out[:, :, :colour] = srgb_to_linear(out[:, :, :colour])
    gain = np.exp(-light_field(out, order=order))[:, :, None]
    report(0.7, "Delight: dividing it out")
    out[:, :, :colour] *= gain
    if encoded:
        out[:, :, :colour] = linear_to_srgb(out[:, :, :colour])
    report(1.0, "Delight: done")
    return out.reshape(given.shape) if given.ndim == 2 else out

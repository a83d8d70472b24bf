"""The maps of a material from its de-lit colour: height, normal (OpenGL), roughness, AO.

- **height**: multi-scale luminance integration. Under the soft light of a de-lit photo a
  surface is brighter where it stands out and darker in its cavities, at every scale, and the
  relief of natural surfaces has a falling spectrum (amplitude ~ |f|^-beta, Mandelbrot's
  fractional Brownian surfaces; Pentland 1984): the height's spectrum is the luminance's
  weighted by |f|^-``ALPHA`` (the larger scales' relief restored, the finest scales' noise
  damped), band-limited above ``LOW_TEXELS`` texel sizes (``texsynth.blocks.period``): the
  colour's own variation over the whole photo is not relief. With ``ALPHA`` 0 this is the
  plain luminance-gradient normal map (Crazybump, Materialize, GIMP's normal map filter).
- **normal**: the height's gradient by spectral differentiation (periodic: exact on the torus),
  n = (-s dh/dx, -s dh/dy_up, 1) / |.|, +Y up (OpenGL, Blender's convention), the strength s
  set so that the root mean square slope is ``STRENGTH`` times the root mean square gradient
  of the luminance (blurred by 1 px) per pixel, within [``MIN_SLOPE``, ``MAX_SLOPE``]: a
  height from colour has no unit, and a surface of more contrast reads as more relief, as in
  the artists' tools, whose strength multiplies the luminance's gradient;
- **coring**: where the gradient's magnitude is heavy-tailed (edges on flat faces: its rms over
  its median past ``TAIL``; a Gaussian field's is 1.20) the weak gradients are shrunk
  (:func:`coring`): the faces' low-contrast mottling is albedo, not relief (the game sets'
  flagstones and bricks: 8.7 -> 5.3 and 8.2 -> 6.0 deg; the stochastic sets untouched);
- **ao**: horizon-based ambient occlusion of the height field (Bavoil, Sainz & Dimitrov 2008):
  in ``DIRECTIONS`` directions the highest horizon elevation within a texel size, AO = 1 - the
  mean sine of those elevations (cavities dark, ridges and flats 1);
- **roughness**: the local root mean square of the height's detail finer than the texel size
  (over ``TEXELS_ROUGH`` texel sizes), mapped to [``ROUGH_MIN``, 1] by its 99th percentile:
  rough where the micro-relief is strong, smoother where the surface is even (no gloss can be
  seen in a de-lit diffuse photo: this is a convention, stated, not a measurement).

With ``wrap=True`` every filter is periodic (FFT, rolls), so a tiling colour gives tiling maps;
``wrap=False`` takes the colour's periodic component first (Moisan 2011), so its edges do not
ring, and shifts clamp at the edges.

Deviations, one line each: the height is a heuristic shape-from-shading (no light direction is
assumed: a de-lit photo has none), its scale the normal's strength; ``ALPHA`` and
``STRENGTH`` were tuned on the game sets and three Cycles renders of displaced surfaces, three
more renders held out (``benchmarks/sections/material.py``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.fft as sfft
from scipy.ndimage import gaussian_filter

from .. import validation
from ..blocks.color import luminance
from ..blocks.parallel import serial_blas
from ..blocks.period import texel_size
from ..blocks.periodic import periodic_component

__all__ = ["Maps", "coring", "derive_maps", "height_from_colour", "normal_from_height"]

#: The luminance spectrum's weight exponent for the height (|f|^-ALPHA).
ALPHA = 0.3
#: The normal map's root mean square slope per unit of the luminance's (per pixel).
STRENGTH = 12.0
#: Bounds of the normal map's root mean square slope (tan of the relief's typical tilt).
MIN_SLOPE, MAX_SLOPE = 0.03, 0.8
#: Wavelengths longer than this many texel sizes are left out of the height.
LOW_TEXELS = 8.0
#: Finest wavelength kept (pixels): the Nyquist band's noise damped (a Gaussian of FINE / 2 pi
#: px). 2 -> 3 on the game sets: rock 4.8 -> 3.8 deg, bedRock 2.7 -> 2.0, grass 2.4 -> 1.6, the
#: others within 0.15 (2.5-3.5 alike), the tune renders 0.2-0.4 deg better (chosen on those;
#: the held-out renders, printed in the same sweep, 0.1-0.2 better).
FINE = 3.0
#: The gradient's coring: a Gaussian field's rms / median magnitude is 1.20; past ``TAIL`` the
#: threshold is ``CORE`` median magnitudes per unit of the excess (the flagstones' 2.4: 1.8).
TAIL, CORE = 1.5, 2.0
#: Widest Gaussian (px) taken by ``gaussian_filter``; wider ones by the transform.
FFT_SIGMA = 8.0
#: Horizon directions of the AO.
DIRECTIONS = 8
#: The roughness window (texel sizes) and its lower bound.
TEXELS_ROUGH, ROUGH_MIN = 1.0, 0.4


@dataclass(frozen=True)
class Maps:
    """A material's maps, each (H, W) float32 in [0, 1] but ``normal`` (H, W, 3) unit vectors,
    OpenGL convention (+X right, +Y up, +Z out of the surface)."""

    normal: np.ndarray
    height: np.ndarray
    roughness: np.ndarray
    ao: np.ndarray


def _frequencies(h: int, w: int) -> tuple[np.ndarray, np.ndarray]:
    """Cycles per pixel of the real FFT's grid: fy (h, 1), fx (1, w // 2 + 1)."""
    return sfft.fftfreq(h)[:, None], sfft.rfftfreq(w)[None, :]


def height_from_colour(colour, *, alpha: float = ALPHA, low: float | None = None,
                       wrap: bool = True) -> np.ndarray:
    """The relative height (H, W) float64, zero mean, of ``colour`` (H, W, C): its luminance's
    spectrum times |f|^-alpha, band-limited to wavelengths between ``FINE`` pixels and ``low``
    (default ``LOW_TEXELS`` texel sizes).

    Examples
    --------
    >>> x = np.arange(64)
    >>> bumps = (0.5 + 0.2 * np.sin(2 * np.pi * x / 16))[None, :, None].repeat(64, 0)
    >>> h = height_from_colour(bumps)
    >>> bool(np.corrcoef(h[0], bumps[0, :, 0])[0, 1] > 0.99)
    True
    """
    a = validation.image(colour, what="colour", channels=None)
    y = luminance(a)
    if not wrap:
        y = periodic_component(y)
    h, w = y.shape
    if low is None:
        low = LOW_TEXELS * texel_size(a[:, :, :3] if a.shape[2] >= 3 else a[:, :, :1])
    fy, fx = _frequencies(h, w)
    f = np.hypot(fy, fx)
    f[0, 0] = 1.0
    weight = f ** -alpha
    weight *= 1.0 - np.exp(-(f * low) ** 2 / 2)  # wavelengths past ``low`` faded out
    weight *= np.exp(-(f * FINE) ** 2 / 2)
    weight[0, 0] = 0.0
    return sfft.irfft2(sfft.rfft2(y) * weight, s=(h, w))


def coring(dx: np.ndarray, dy: np.ndarray) -> np.ndarray:
    """The weight (H, W) of the gradient (dx, dy): r^2 / (1 + r^2), r = |g| / (kappa median |g|),
    kappa = ``CORE`` times the heavy tail's excess, rms |g| / median |g| over ``TAIL``; 1 where
    the distribution is not heavy-tailed. A heavy tail is edges on flat faces (a flagstone
    wall): the faces' weak gradients are the colour's mottling (albedo), not relief (Donoho 1995
    soft shrinkage, applied to the gradient's magnitude).

    Examples
    --------
    >>> rng = np.random.default_rng(0)
    >>> float(coring(rng.normal(size=(64, 64)), rng.normal(size=(64, 64))).min())  # Gaussian
    1.0
    >>> dx = np.where(np.arange(64) % 16 == 0, 1.0, 0.01)[None, :] + 0 * np.ones((64, 1))
    >>> w = coring(dx, 0 * dx); bool(w[0, 0] > 0.8 and w[0, 1] < 0.01)  # edges kept, flats not
    True
    """
    magnitude = np.hypot(dx, dy)
    median = float(np.median(magnitude))
    if median <= 0:
        return np.ones_like(magnitude)
    kappa = CORE * (float(np.sqrt((magnitude ** 2).mean())) / median - TAIL)
    if kappa <= 0:
        return np.ones_like(magnitude)
    r2 = (magnitude / (kappa * median)) ** 2
    return r2 / (1 + r2)


def normal_from_height(height: np.ndarray, *, slope: float | None = 0.3,
                       strength: float | None = None, core: bool = False) -> np.ndarray:
    """Unit normals (H, W, 3) float32, OpenGL (+Y up), of the periodic ``height`` (H, W) by
    spectral differentiation; the strength s scales the height (default: the root mean square
    slope made ``slope``); ``core``: the gradient weighted by :func:`coring` first.

    Examples
    --------
    >>> x = np.arange(32)
    >>> n = normal_from_height(np.sin(2 * np.pi * x / 32)[None, :].repeat(32, 0), strength=1.0)
    >>> bool(np.allclose(np.linalg.norm(n, axis=2), 1, atol=1e-6)), bool(n[0, 0, 0] < 0)
    (True, True)
    """
    h, w = height.shape
    fy, fx = _frequencies(h, w)
    spectrum = sfft.rfft2(height)
    dx = sfft.irfft2(spectrum * (2j * np.pi * fx), s=(h, w))
    dy = sfft.irfft2(spectrum * (2j * np.pi * fy), s=(h, w))  # down the rows
    if core:
        weight = coring(dx, dy)
        dx, dy = dx * weight, dy * weight
    if strength is None:
        rms = float(np.sqrt((dx ** 2 + dy ** 2).mean()))
        strength = slope / rms if rms > 0 else 0.0
    n = np.stack([-strength * dx, strength * dy, np.ones_like(dx)], axis=2)  # y up: -d/drow
    return (n / np.linalg.norm(n, axis=2, keepdims=True)).astype(np.float32)


def _rms_gradient(a: np.ndarray, wrap: bool) -> float:
    """Root mean square of the central-difference gradient's magnitude (periodic when wrap)."""
    gy = (_shift(a, 1, 0, wrap) - _shift(a, -1, 0, wrap)) / 2
    gx = (_shift(a, 0, 1, wrap) - _shift(a, 0, -1, wrap)) / 2
    return float(np.sqrt(np.mean(gx ** 2 + gy ** 2)))


def _shift(a: np.ndarray, di: int, dj: int, wrap: bool) -> np.ndarray:
    """a[i + di, j + dj]: on the torus, or clamped at the edges."""
    if wrap:
        return np.roll(a, (-di, -dj), axis=(0, 1))
    h, w = a.shape
    i = np.clip(np.arange(h) + di, 0, h - 1)
    j = np.clip(np.arange(w) + dj, 0, w - 1)
    return a[i][:, j]


def _gaussian(a: np.ndarray, sigma: float, wrap: bool) -> np.ndarray:
    """``a`` blurred by a Gaussian of ``sigma`` px, periodic (``wrap``) or with its edges
    repeated: ``gaussian_filter`` up to ``FFT_SIGMA``, beyond it by the transform (the
    Gaussian's own, exp(-2 pi^2 sigma^2 |f|^2), on the grid padded by 4 sigma without
    ``wrap``), whose cost does not grow with the window (a 2048 crop of the 12 MP setts, sigma
    about 50 px: 9.5 s of its maps' 14 s in the filter's correlations).

    Examples
    --------
    >>> a = np.random.default_rng(0).random((64, 48)).astype(np.float32)
    >>> bool(abs(_gaussian(a, 20.0, True) - gaussian_filter(a, 20.0, mode="wrap")).max() < 1e-3)
    True
    """
    if sigma <= FFT_SIGMA:
        return gaussian_filter(a, sigma, mode="wrap" if wrap else "nearest")
    pad = 0 if wrap else int(np.ceil(4 * sigma))
    b = np.pad(a, pad, mode="edge") if pad else a
    fy, fx = _frequencies(*b.shape)
    weight = np.exp(-2 * np.pi ** 2 * sigma ** 2 * (fx ** 2 + fy ** 2)).astype(np.float32)
    out = sfft.irfft2(sfft.rfft2(b) * weight, s=b.shape)
    return out[pad:pad + a.shape[0], pad:pad + a.shape[1]].astype(a.dtype, copy=False)


def _ao(z: np.ndarray, reach: float, wrap: bool) -> np.ndarray:
    """Bavoil et al. 2008's horizon-based AO of the height ``z`` in pixels."""
    distances = np.unique(np.round(np.geomspace(1, max(1.0, reach), 6)).astype(int))
    occlusion = np.zeros_like(z)
    for k in range(DIRECTIONS):
        t = 2 * np.pi * k / DIRECTIONS
        horizon = np.zeros_like(z)
        for d in distances:
            di, dj = int(round(d * np.sin(t))), int(round(d * np.cos(t)))
            rise = _shift(z, di, dj, wrap) - z
            horizon = np.maximum(horizon, rise / np.hypot(np.hypot(di, dj), rise))
        occlusion += horizon
    return 1.0 - occlusion / DIRECTIONS


@serial_blas()
def derive_maps(colour, *, wrap: bool = True, alpha: float = ALPHA,
                strength: float = STRENGTH, low: float | None = None) -> Maps:
    """Height, normal (OpenGL), roughness and AO of a de-lit ``colour`` (H, W) or (H, W, C).

    Parameters
    ----------
    colour : array (H, W) or (H, W, C), the de-lit colour (``texsynth.material.delight``).
    wrap : every filter periodic (a tiling colour gives tiling maps); False for a photo that
        does not tile.
    alpha : the luminance spectrum's exponent for the height (0: height = luminance).
    strength : the normal map's root mean square slope per unit of the luminance's gradient.
    low : longest wavelength of the height (pixels; default ``LOW_TEXELS`` texel sizes).

    References
    ----------
    Pentland 1984, "Fractal-based description of natural scenes" (relief with a falling
    spectrum); Frankot & Chellappa 1988, "A method for enforcing integrability in shape from
    shading algorithms" (height and gradients on the Fourier grid); Bavoil, Sainz & Dimitrov
    2008, "Image-space horizon-based ambient occlusion"; Moisan 2011 (periodic component).

    Examples
    --------
    >>> rng = np.random.default_rng(0)
    >>> colour = rng.random((64, 64, 3)).astype(np.float32)
    >>> maps = derive_maps(colour)
    >>> maps.normal.shape, maps.height.dtype, bool(maps.height.min() >= 0 and maps.ao.max() <= 1)
    ((64, 64, 3), dtype('float32'), True)
    """
    a = validation.image(colour, what="colour", channels=None)
    strength = validation.number(strength, "strength", 0.0, 1000.0)
    alpha = validation.number(alpha, "alpha", 0.0, 2.0)
    texel = texel_size(a[:, :, :3] if a.shape[2] >= 3 else a[:, :, :1])
    z = height_from_colour(a, alpha=alpha, low=LOW_TEXELS * texel if low is None else low,
                           wrap=wrap)
    y = gaussian_filter(luminance(a), 1.0, mode="wrap" if wrap else "nearest")
    slope = float(np.clip(strength * _rms_gradient(y, wrap), MIN_SLOPE, MAX_SLOPE))
    normal = normal_from_height(z, slope=slope, core=True)
    # The height in pixels at the normal's strength: its slopes are the normal's.
    rms = _rms_gradient(z, wrap)
    z_px = z * (slope / rms if rms > 0 else 0.0)
    span = float(np.ptp(z))
    height = ((z - z.min()) / span if span > 0 else np.full_like(z, 0.5)).astype(np.float32)
    ao = np.clip(_ao(z_px, texel, wrap), 0.0, 1.0).astype(np.float32)
    sigma = max(1.0, TEXELS_ROUGH * texel / 2)  # Gaussian windows: a box's squares showed
    detail = z_px - _gaussian(z_px, sigma, wrap)
    local = np.sqrt(np.maximum(_gaussian(detail ** 2, sigma, wrap), 0.0))
    top = float(np.percentile(local, 99))
    rough = ROUGH_MIN + (1 - ROUGH_MIN) * np.clip(local / top if top > 0 else 0 * local, 0, 1)
    return Maps(normal=normal, height=height, roughness=rough.astype(np.float32), ao=ao)

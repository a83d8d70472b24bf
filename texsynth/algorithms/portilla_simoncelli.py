"""Portilla-Simoncelli texture synthesis: joint statistics of complex wavelet coefficients.

Portilla & Simoncelli 2000 ("A parametric texture model based on joint statistics of complex
wavelet coefficients", IJCV 40(1)), section 3 (the statistical constraints) and section 4 (their
imposition by iterated projections), as in their textureSynthesis code and Vacher & Briand's
IPOL 2021 account of it. On texsynth's periodic steerable pyramid (``texsynth.blocks.pyramid``),
made complex: band m of level j is b + i H_m b, H_m the Hilbert transform along the band's
orientation theta_m (the analytic band of the paper's complex pyramid, whose real part is b).

The statistics of the exemplar (section 3.1-3.4), per level j (0 finest, S the low-pass):

- marginals: of the pixels, and of each partially reconstructed low-pass image L_j (the paper's
  skewness and kurtosis of every scale, its pixel mean, variance, skewness, kurtosis and range);
- "raw" autocorrelation: the central Na x Na lags of each L_j;
- "magnitude" statistics: each band's magnitude mean and the central Na x Na lags of its
  autocorrelation, the covariance of the K magnitudes of a level (cross-orientation) and their
  cross-covariance with the parent level's magnitudes, expanded to the level (cross-scale);
- cross-scale phase: the covariance of each band's real part with the real and imaginary parts
  of the parent bands with doubled phase, p^2 / |p|;
- the variance of the high-pass residual.

    x = Gaussian noise with the pixels' mean and variance;
    until convergence (``iterations`` times):
        analyse x; L_S = low-pass residual, its autocorrelation and marginal imposed;
        for j = S - 1 .. 0 (coarse to fine):
            magnitudes: cross-orientation and parent covariances imposed, then each band's
                autocorrelation and mean; the bands take the new magnitudes, phases kept;
            real parts: covariance with the phase-doubled parents imposed (not at S - 1);
            L_j = L_{j+1} expanded + level j's bands; its autocorrelation and marginal imposed;
        high-pass residual scaled down to its variance if above it;
        x = high-pass + L_0; pixel marginal imposed; x += 0.8 (x - x_previous) (the code's
        acceleration).

A covariance is imposed as the code's adjustCorr1s/2s: the least change of the vectors X that
gives them the covariance C_X and the cross-covariance C_XY with the fixed Y; an autocorrelation
as its modacor22: the even filter h with C_x * h = C_y on the central lags, applied as
sqrt(|F h|) in the Fourier domain.

Colour: each of the exemplar's PCA colour components (``texsynth.blocks.color.ColorPCA``) is
synthesized alone, as Vacher & Briand's implementation does, rather than with the colour
version's cross-channel statistics: the components are decorrelated, the model's cost stays
linear in the channels, and texsynth's other parametric method (Heeger-Bergen) works the same
way, so the two compare on equal terms.

Deviations, one line each:
- the marginal statistics (pixel mean, variance, skewness, kurtosis, range; each L_j's
  skewness and kurtosis) are imposed by matching the whole 1-D histogram
  (``texsynth.blocks.histogram``), which holds them all, not by the moments' gradient steps;
- the high-pass residual's variance and the magnitudes' means are imposed, as in the code;
- the pyramid is texsynth's (raised-cosine radial masks, periodic, any size), not the code's
  buildSCFpyr, and its low-pass images L_j are reconstructed by its own adjoint;
- the coarsest level's real parts keep their cross-orientation covariance (the code's
  five-column low-pass "parents" are not used there, as its synthesis does not use them);
- the neighbourhood is cut to the level's size: at most min(side) / 4 - 1 lags each way (the
  code's rule);
- the exemplar's statistics come from its periodic component (Moisan 2011), a photo larger than
  ``MAX_SIDE`` from its centred crop of that size;
- the PCA components, synthesized alone, can combine into colours the photo never had
  (magenta specks on the blue pool water): they take ``SLICES`` steps of sliced optimal
  transport towards the photo's joint colour distribution (Pitie et al. 2005;
  ``texsynth.blocks.color.sliced_transfer``), as texsynth's Heeger-Bergen ends, and are then
  projected back and clipped to the exemplar's per-channel range.

References
----------
Portilla & Simoncelli 2000, sections 3-4; Vacher & Briand 2021.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.fft as sfft

from ..blocks import fft
from ..blocks.color import ColorPCA, sliced_transfer_rows
from ..blocks.histogram import TargetHistogram, match, sample_step
from ..blocks.parallel import small_product, threads
from ..blocks.periodic import periodic_component
from ..blocks.pyramid import SteerablePyramid, pyramid_depth
from ..registry import Method, Param, register

__all__ = ["portilla_simoncelli", "METHOD"]

#: A larger photo is analysed on its centred crop of this side (statistics of a texture sample).
MAX_SIDE = 1024
#: The code's acceleration: x <- x + ALPHA (x - x_previous) after each iteration.
ALPHA = 0.8
#: Steps of sliced colour transport after the synthesis (as texsynth's Heeger-Bergen ends), and
#: the photo's colours they read (a regular sample).
SLICES = 30
SAMPLES = 1 << 20
#: The colour transport's time over its cost model's term beside the iterations' (0.12-0.2
#: at 128^2 -> 256^2 and 256^2 -> 512^2; the model keeps a budget's upper figure): its share
#: of the progress.
COLOUR_SHARE = 0.2


def portilla_simoncelli(exemplar, width, height, rng, progress, scales=4, orientations=4,
                        neighbourhood=7, iterations=25):
    """Synthesize (height, width, C) from ``exemplar`` (H, W, C float32) by imposing its
    Portilla-Simoncelli statistics on noise.

    Parameters
    ----------
    exemplar : float32 array (H, W, C)
    width, height : int
    rng : numpy.random.Generator
    progress : texsynth.progress.Progress
    scales, orientations : int
        The pyramid's levels S and oriented bands K.
    neighbourhood : int
        Na, the odd side of the central lags whose autocorrelation is constrained.
    iterations : int
        Rounds of the projections.

    Returns
    -------
    float32 array (height, width, C), periodic.

    References
    ----------
    Portilla & Simoncelli 2000, sections 3-4; Vacher & Briand 2021 (IPOL), the colour by PCA.

    Examples
    --------
    >>> import numpy as np, texsynth
    >>> stripes = np.sin(np.arange(32) * np.pi / 4)[None, :, None] * np.ones((32, 1, 3))
    >>> out = texsynth.synthesize(0.5 + 0.4 * stripes, 40, 32, method="portilla_simoncelli",
    ...                           iterations=3)
    >>> out.shape, out.dtype.name
    ((32, 40, 3), 'float32')
    """
    h, w, channels = exemplar.shape
    top, left = max(0, (h - MAX_SIDE) // 2), max(0, (w - MAX_SIDE) // 2)
    sample = exemplar[top:top + MAX_SIDE, left:left + MAX_SIDE]
    ends = np.cumsum(_phases(exemplar.shape, width, height, orientations, iterations)
                     * np.array([1.0, 1.0, COLOUR_SHARE]))
    analysed, synthesized = ends[:2] / ends[2]    # the progress by each phase's cost
    colour = progress.span(synthesized, 1.0) if channels > 1 else None
    setup, iterating = progress.span(0.0, analysed), progress.span(analysed, synthesized)
    depth = pyramid_depth(sample.shape, width, height, scales)
    pca = ColorPCA.fit(sample)
    components = pca.forward(sample)
    setup(0.0, "building the pyramids")
    pyramid = SteerablePyramid((height, width), depth, orientations)
    pe = (pyramid if sample.shape[:2] == (height, width) else
          SteerablePyramid(sample.shape[:2], depth, orientations))
    lags = [max(0, min((neighbourhood - 1) // 2, min(*a, *b) // 4 - 1))
            for a, b in zip(pyramid.level_shapes, pe.level_shapes, strict=True)]
    targets = []
    for c in range(channels):
        targets.append(_Statistics.of(periodic_component(components[:, :, c]), pe, lags))
        setup((c + 1) / channels, "the exemplar's statistics")
    colours = components.reshape(-1, channels)[::sample_step(components.shape[0]
                                                            * components.shape[1],
                                                            components.shape[1], SAMPLES)]
    del pe, components
    noise = rng.standard_normal((channels, height, width), dtype=np.float32)
    image = np.empty((channels, height, width), np.float32)
    for c in range(channels):
        t = targets[c]
        x = noise[c] * np.float32(t.deviation) + np.float32(t.mean)
        previous = x
        for it in range(iterations):
            done = iterating.span((c + it / iterations) / channels,
                                  (c + (it + 1) / iterations) / channels)
            new = _iterate(x, t, pyramid, lags, done)
            x = new + np.float32(ALPHA) * (new - previous)
            previous = new
            done(1.0, f"channel {c + 1}/{channels}, iteration {it + 1}/{iterations}")
        image[c] = previous
    if colour is not None:
        sliced_transfer_rows(image.reshape(channels, -1), colours, rng, SLICES, colour)
    lo, hi = exemplar.min(axis=(0, 1)), exemplar.max(axis=(0, 1))
    return np.clip(pca.inverse(np.moveaxis(image, 0, -1)), lo, hi).astype(np.float32)


@dataclass
class _Statistics:
    """One channel's constraints (section 3), by level j = 0 (finest) .. S (low-pass)."""

    mean: float
    deviation: float
    pixels: TargetHistogram
    highpass_variance: float
    lows: list            # TargetHistogram of L_j, j = 0..S
    low_acorr: list       # central autocorrelation of L_j, j = 0..S
    mag_means: list       # (K,) per level
    mag_acorr: list       # per level, per band
    mag_cov: list         # (K, K) per level
    mag_parent: list      # (K, K) per level, None at S - 1
    real_parent: list     # (K, 2K) per level, None at S - 1

    @classmethod
    def of(cls, x: np.ndarray, pyramid: SteerablePyramid, lags: list) -> _Statistics:
        coeffs = pyramid.analyze(x)
        s = pyramid.scales
        low = coeffs.lowpass
        lows, low_acorr = [None] * (s + 1), [None] * (s + 1)
        lows[s], low_acorr[s] = TargetHistogram(low), _autocorrelation(low, lags[s])
        mag_means, mag_acorr, mag_cov = [None] * s, [None] * s, [None] * s
        mag_parent, real_parent = [None] * s, [None] * s
        parent = None
        for j in reversed(range(s)):
            bands = [_analytic(b, j, m, pyramid) for m, b in enumerate(coeffs.bands[j])]
            magnitudes = np.stack([np.abs(b).ravel() for b in bands])
            real = np.stack([b.real.ravel() for b in bands])
            mag_means[j] = magnitudes.mean(axis=1, dtype=np.float64)
            centred = magnitudes - mag_means[j][:, None].astype(np.float32)
            mag_acorr[j] = [_autocorrelation(a.reshape(b.shape), lags[j])
                            for a, b in zip(centred, bands, strict=True)]
            mag_cov[j] = _gram(centred, centred)
            if parent is not None:
                p_mag, p_phase = _parents(parent, bands[0].shape)
                mag_parent[j] = _gram(centred, p_mag)
                real_parent[j] = _gram(real, p_phase)
            parent = bands
            low = _lowband(pyramid, low, coeffs.bands[j], j)
            lows[j], low_acorr[j] = TargetHistogram(low), _autocorrelation(low, lags[j])
        return cls(float(x.mean()), float(x.std()), TargetHistogram(x),
                   float(np.mean(coeffs.highpass.astype(np.float64) ** 2)), lows, low_acorr,
                   mag_means, mag_acorr, mag_cov, mag_parent, real_parent)


def _iterate(x, t: _Statistics, pyramid: SteerablePyramid, lags, progress) -> np.ndarray:
    """One round of the projections (section 4) on the image ``x``; a new image."""
    coeffs = pyramid.analyze(x)
    s = pyramid.scales
    low = match(_impose_autocorrelation(coeffs.lowpass, t.low_acorr[s]), t.lows[s])
    parent = None
    for j in reversed(range(s)):
        # a level's share of the progress by its pixels (4^-j), the finest three quarters
        progress((4.0 ** -(j + 1) - 4.0 ** -s) / (1 - 4.0 ** -s), "imposing the statistics")
        bands = [_analytic(b, j, m, pyramid) for m, b in enumerate(coeffs.bands[j])]
        shape = bands[0].shape
        magnitudes = np.stack([np.abs(b).ravel() for b in bands])
        centred = magnitudes - magnitudes.mean(axis=1, keepdims=True)
        if parent is None:
            centred = _adjust_covariance(centred, t.mag_cov[j])
        else:
            p_mag, p_phase = _parents(parent, shape)
            centred = _adjust_covariance(centred, t.mag_cov[j], p_mag, t.mag_parent[j])
        for m, b in enumerate(bands):
            a = _impose_autocorrelation(centred[m].reshape(shape), t.mag_acorr[j][m])
            a += np.float32(t.mag_means[j][m])
            np.maximum(a, 0, out=a)
            old = np.abs(b)
            b *= np.where(old > 0, a / np.where(old > 0, old, 1), 0)
        real = [b.real.astype(np.float32) for b in bands]
        if parent is not None:
            rows = np.stack([r.ravel() for r in real])
            rows = _adjust_covariance(rows, _gram(rows, rows), p_phase, t.real_parent[j],
                                      diagonal=True)
            real = [row.reshape(shape) for row in rows]
        parent = [_analytic(r, j, m, pyramid) for m, r in enumerate(real)]
        low = _lowband(pyramid, low, real, j)
        low = match(_impose_autocorrelation(low, t.low_acorr[j]), t.lows[j])
    highpass = coeffs.highpass
    variance = float(np.mean(highpass.astype(np.float64) ** 2))
    if variance > t.highpass_variance:
        highpass = highpass * np.float32(np.sqrt(t.highpass_variance / variance))
    spectrum = fft.rfft2(highpass)
    spectrum *= pyramid.hi0
    spectrum += fft.rfft2(low) * pyramid.lo0
    return match(fft.irfft2(spectrum, pyramid.shape), t.pixels)


def _frequencies(shape):
    """fy (column vector) and fx (row) of a real-FFT grid of ``shape`` (cycles per pixel)."""
    return np.fft.fftfreq(shape[0])[:, None], np.fft.rfftfreq(shape[1])[None, :]


def _analytic(band: np.ndarray, j: int, m: int, pyramid: SteerablePyramid) -> np.ndarray:
    """b + i H_m b: the complex band whose real part is ``band`` (level j, orientation m),
    H_m the Hilbert transform along theta_m = m pi / K (zero on the orthogonal line)."""
    fy, fx = _frequencies(band.shape)
    theta = np.pi * m / pyramid.orientations
    sign = np.sign(fx * np.cos(theta) + fy * np.sin(theta)).astype(np.float32)
    spectrum = fft.rfft2(band)
    spectrum *= np.complex64(-1j) * sign
    imaginary = fft.irfft2(spectrum, band.shape)
    return band.astype(np.complex64) + np.complex64(1j) * imaginary


def _expand(c: np.ndarray, shape) -> np.ndarray:
    """The complex band ``c`` of a coarser level on the grid of ``shape`` (its spectrum
    zero-padded, values kept)."""
    h1, w1 = c.shape
    h0, w0 = shape
    spectrum = sfft.fft2(c, workers=threads())
    out = np.zeros(shape, np.complex64)
    r1, r2, c1, c2 = (h1 + 1) // 2, h1 // 2, (w1 + 1) // 2, w1 // 2
    out[:r1, :c1] = spectrum[:r1, :c1]
    out[:r1, w0 - c2:] = spectrum[:r1, w1 - c2:]
    out[h0 - r2:, :c1] = spectrum[h1 - r2:, :c1]
    out[h0 - r2:, w0 - c2:] = spectrum[h1 - r2:, w1 - c2:]
    out = sfft.ifft2(out, workers=threads(), overwrite_x=True)
    out *= np.float32(h0 * w0 / (h1 * w1))
    return out


def _parents(parent: list, shape) -> tuple[np.ndarray, np.ndarray]:
    """The parent level's bands expanded to ``shape``: their centred magnitudes (K, N) and the
    real and imaginary parts of their phase-doubled values p^2 / |p| (2K, N)."""
    expanded = [_expand(p, shape).ravel() for p in parent]
    magnitudes = np.stack([np.abs(p) for p in expanded])
    doubled = [np.where(np.abs(p) > 0, p * p / np.where(np.abs(p) > 0, np.abs(p), 1), 0)
               for p in expanded]
    phase = np.stack([d.real for d in doubled] + [d.imag for d in doubled])
    return (magnitudes - magnitudes.mean(axis=1, keepdims=True)), phase.astype(np.float32)


def _lowband(pyramid: SteerablePyramid, low: np.ndarray, bands, j: int) -> np.ndarray:
    """L_j from L_{j+1} and level j's real bands: the adjoint of one analysis step of the
    pyramid, sum_m conj(B_m) b_m + L_j (the expanded L_{j+1})."""
    parent, child = pyramid.level_shapes[j], pyramid.level_shapes[j + 1]
    total = np.zeros((parent[0], parent[1] // 2 + 1), np.complex64)
    for b, f in zip(bands, pyramid.band_filters[j], strict=True):
        total += fft.rfft2(b) * np.conj(f)
    n1, n2, columns = (child[0] + 1) // 2, child[0] // 2, child[1] // 2 + 1
    embedded = fft.rfft2(low) * pyramid.low_masks[j]
    embedded *= np.float32(parent[0] * parent[1] / (child[0] * child[1]))
    total[:n1, :columns] += embedded[:n1]
    total[parent[0] - n2:, :columns] += embedded[n1:]
    return fft.irfft2(total, parent)


def _lag_indices(shape, lags: int):
    """Row and column indices of the lags -lags..lags on a circular grid of ``shape``."""
    r = np.arange(-lags, lags + 1)
    return np.ix_(r % shape[0], r % shape[1])


def _lags(spectrum: np.ndarray, shape, lags: int) -> np.ndarray:
    """C(tau) = mean_p x(p) x(p + tau) (circular) of x less its mean on the central
    (2 lags + 1)^2 lags, from x's real FFT ``spectrum`` (|X|^2 transformed back), float64."""
    power = (spectrum.real ** 2 + spectrum.imag ** 2).astype(np.complex64)
    power[0, 0] = 0                                              # the mean
    c = fft.irfft2(power, shape)
    return c[_lag_indices(shape, lags)].astype(np.float64) / (shape[0] * shape[1])


def _autocorrelation(x: np.ndarray, lags: int) -> np.ndarray:
    """:func:`_lags` of the image ``x``."""
    return _lags(fft.rfft2(x), x.shape, lags)


def _impose_autocorrelation(x: np.ndarray, target: np.ndarray) -> np.ndarray:
    """modacor22: the even filter h on the central lags with C_x * h = C_y there (C_x's lags
    to twice as far), applied as sqrt(|F h|), the least change of ``x`` that gives it the
    autocorrelation ``target`` on those lags (its mean kept). F h is a (2L+1)-term sum along
    each axis: two small products, not a transform."""
    n = target.shape[0]
    lags = (n - 1) // 2
    spectrum = fft.rfft2(x)
    cx = _lags(spectrum, x.shape, 2 * lags)
    r = np.arange(n)
    offsets = r[:, None] - r[None, :] + 2 * lags                # a - b, shifted into cx
    t = cx[offsets[:, None, :, None], offsets[None, :, None, :]].reshape(n * n, n * n)
    h = np.linalg.lstsq(t, target.ravel(), rcond=None)[0].reshape(n, n)
    tau = np.arange(-lags, lags + 1)
    ey = np.exp(-2j * np.pi * np.fft.fftfreq(x.shape[0])[:, None] * tau[None, :])
    ex = np.exp(-2j * np.pi * tau[:, None] * np.fft.rfftfreq(x.shape[1])[None, :])
    gain = np.sqrt(np.abs((ey @ h @ ex).real)).astype(np.float32)
    gain[0, 0] = 1.0                                           # the mean
    spectrum *= gain
    return fft.irfft2(spectrum, x.shape)


def _gram(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """A B^T / N of the (a, N) and (b, N) rows (``small_product``: no BLAS threads; float32
    sums, 3e-6 of float64's at 256^2), float64."""
    return small_product("an,bn->ab", a, b).astype(np.float64) / a.shape[1]


def _adjust_covariance(x, cx, y=None, cxy=None, diagonal=False) -> np.ndarray:
    """adjustCorr1s/2s: the rows X (a, N) changed least so that X X^T / N = ``cx`` and, given
    the fixed rows Y (b, N), X Y^T / N = ``cxy``: X' = Cxy Cy^-1 Y + M X0, X0 the part of X
    orthogonal to Y and M C0 M^T = D = Cx - Cxy Cy^-1 Cxy^T with M = D^1/2 Q C0^-1/2 (Q the
    rotation closest to the identity). ``diagonal``: each row alone (the code's per-band
    adjustCorr2s of the real parts), only the diagonal of ``cx`` imposed."""
    x = np.asarray(x, np.float32)
    cx = np.asarray(cx, np.float64)
    fixed = None
    if y is not None:
        cxy = np.asarray(cxy, np.float64)
        cy_inv = np.linalg.pinv(_gram(y, y))
        beta = cy_inv @ _gram(y, x)                                  # X's regression on Y
        x = x - small_product("ba,bn->an", beta.astype(np.float32), y)
        fixed = (cy_inv @ cxy.T).astype(np.float32)
        cx = cx - cxy @ cy_inv @ cxy.T
    c0 = _gram(x, x)
    if diagonal:
        m = np.diag(np.sqrt(np.maximum(np.diag(cx), 0) / np.maximum(np.diag(c0), 1e-30)))
    else:
        m = _root(cx) @ _rotation(c0, cx) @ _root(c0, inverse=True)
    out = small_product("ka,an->kn", m.astype(np.float32), x)
    if fixed is not None:
        out += small_product("ba,bn->an", fixed, y)
    return out


def _root(c, inverse=False) -> np.ndarray:
    """The symmetric square root of a covariance (negative eigenvalues taken as 0), or its
    pseudo-inverse."""
    e, v = np.linalg.eigh((c + c.T) / 2)
    e = np.maximum(e, 0)
    if inverse:
        e = np.where(e > 1e-12 * max(e.max(), 1e-30), 1 / np.sqrt(np.where(e > 0, e, 1)), 0)
    else:
        e = np.sqrt(e)
    return (v * e) @ v.T


def _rotation(c0, d) -> np.ndarray:
    """The orthogonal Q closest to the identity in M^T = C0^-1/2 Q^T D^1/2 (the least change
    of X): the polar factor of D^1/2 C0^1/2."""
    u, _, vt = np.linalg.svd(_root(d) @ _root(c0))
    return u @ vt


def _memory(shape, width, height, params):
    """The larger of the two phases, each about 400 B a pixel of its image (tracemalloc,
    1024^2 -> 256^2 and 256^2 to 1024^2 outputs: 370-400 B): the exemplar's analysis (its
    components and periodic component, a pyramid's bands, level 0's complex bands, magnitudes,
    real parts and the expanded parents with their phase-doubled parts, the sorted targets)
    and one channel's synthesis (the same work arrays on the output, the noise and output of
    every channel), with 4 MiB for the pyramids' filters and small arrays."""
    side = min(shape[0], MAX_SIDE) * min(shape[1], MAX_SIDE)
    per_pixel = 400 + 30 * max(params["orientations"] - 4, 0)
    return per_pixel * max(side, width * height) + 2 ** 22


def _cost(shape, width, height, params):
    """Seconds on the reference machine: per iteration and channel, the analysis, the bands'
    Hilbert transforms, expansions, autocorrelation impositions and covariance adjustments, all
    about linear in the output's pixels times (K + 2); once, the exemplar's analysis (the same
    work on its sample) and, in colour, the colour transport's steps (a constant each, as in
    Heeger-Bergen's model). Set against heeger_bergen's model in the same runs, under load (11
    to 15 on 2 cores): at 256^2 RGB it predicts 4.2x heeger_bergen's time, measured 3.5x and
    7.3x; 1024^2 -> 256^2 predicted within 1.5x of one measurement. A fixed 0.024 (K + 2)
    reference seconds per iteration and channel beside the pixels' 4e-7 (issue 45): the
    bands' small solves (21 least-squares, 7 covariance adjustments with 10 SVDs an
    iteration and channel) and numpy's per-call overhead, whatever the size; on one core a
    64^2 .. 512^2 output's iteration took 2.1 ms + 66 ns a pixel per (K + 2) (CPU time), the
    fixed part 33 000 pixels' worth, and on two cores the FFTs (the pixels' part) split
    across both while it does not. Fit: the quiet 2026-12 predictions table's 256^2, 2048 x
    64 and 512^2 rows (6.78, 9.74, 16.59 s) at the other methods' median measured / cost
    (0.283) read 0.0244 + 3.93e-7 a pixel (this model all three within 4 %), where 0.01 had
    read 0.77, 0.86 and 0.66 (the last at a calibration of 0.21, the others' 0.28-0.29).
    """
    return 0.05 + sum(_phases(shape, width, height, params["orientations"],
                              params["iterations"]))


def _phases(shape, width, height, k, iterations) -> tuple[float, float, float]:
    """:func:`_cost`'s terms: the exemplar's analysis, the iterations, the colour transport
    (reference seconds; their shares of the progress, where a fixed tenth for the analysis
    had told 10 % at a hundredth of the time at 256^2 -> 512^2)."""
    c = shape[2]
    side = min(shape[0], MAX_SIDE) * min(shape[1], MAX_SIDE)
    return (5e-7 * side * c * (k + 2), iterations * c * (4e-7 * width * height + 0.024) * (k + 2),
            0.038 * SLICES if c > 1 else 0.0)


METHOD = register(Method(
    name="portilla_simoncelli",
    label="Portilla-Simoncelli",
    description="Impose the joint statistics of complex steerable-pyramid coefficients "
                "(Portilla & Simoncelli 2000): autocorrelations, magnitude and phase "
                "correlations across orientations and scales; keeps quasi-periodic structure "
                "(weaves, ripples, regular grain) that histogram matching loses",
    function=portilla_simoncelli,
    params=(
        Param("scales", int, 4, "Pyramid levels (capped by exemplar and output sizes)", 1, 8),
        Param("orientations", int, 4, "Oriented subbands per level (K)", 1, 8),
        Param("neighbourhood", int, 7, "Side Na of the square of central autocorrelation "
              "lags constrained (an even value counts as the odd one below)", 1, 15),
        Param("iterations", int, 25, "Rounds of imposing the statistics", 1, 200),
    ),
    min_exemplar=8,
    memory=_memory,
    cost=_cost,
))

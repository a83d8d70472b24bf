"""What the plane estimate measures: the textured part of a photo, local power spectra of its
windows, and the isotropy and homogeneity of their oriented energies once back-projected.

Forsyth & Ponce, Computer Vision: A Modern Approach, sec. 11.4.1 ("Shape from texture for
planes"). Deviations from the section, one line each:
- oriented energies are computed in the Fourier domain of local windows (Parseval): back-projecting
  a window by the local Jacobian J is the linear change of frequency nu = J^-T w, so no image is
  resampled per hypothesis and no band is measured beyond what the photo resolves;
- isotropy is the spread of *log* energy across orientations, each scale weighted alike (natural
  spectra fall as 1/f, energy weights would keep only the coarsest scale);
- homogeneity is the spread of log energy of each oriented band across windows, which needs no
  texel detection (the section's marked Poisson process reasoning, applied to filter energies);
- the orthographic slant comes from a fourth-order spectral moment (:func:`moment_slant`), which
  read less of the textures' own anisotropy as slant than the log-energy spread did.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import scipy.ndimage as ndi

from .. import validation
from ..blocks import parallel
from .geometry import jacobians

__all__ = ["texture_mask", "moment_slant"]

_MIN_SIDE = 64           # smallest image side accepted (pixels)
ANALYSIS_SIDE = 320     # images are block-averaged down to at most this longer side
_ANGLES = 8             # orientation bins over [0, pi): the filter bank's K
_DLOG = 0.5             # radial bin width in octaves
_LOG_RANGE = (-14.0, 2.0)  # log2 cycles/px covered by the radial bins (texture frame)
_COVER = 0.6            # a window measures a band when its samples cover this share of it
_G_MIN = 0.15           # windows must stay this far from the horizon (depth ratio 1 / g)
_CHUNK = 1 << 14        # samples binned at once: float64 temporaries of 128 kB stay in cache
#                         (a 12 MP photo's 61 000 samples at once took twice the time)


def luminance(image) -> np.ndarray:
    """Luminance (H, W) float32 of an image array (a 12 MP photo is read at half the cost of
    float64), or ``ValueError`` saying what is wrong."""
    a = validation.image(image, what="image", min_side=_MIN_SIDE, channels=(1, 2, 3, 4))
    if a.shape[2] >= 3:
        return parallel.small_product("ijc,c->ij", a[:, :, :3],
                                      np.array([0.2126, 0.7152, 0.0722], np.float32))
    return a[:, :, 0]


def block_factor(shape: tuple[int, ...], side: int = ANALYSIS_SIDE) -> int:
    """The integer factor k that brings the longer of ``shape``'s first two sides to ``side``
    at most (:func:`downsample`'s).

    Examples
    --------
    >>> block_factor((3024, 4032), 1024)  # a 12 MP photo is read at 1008 x 756
    4
    """
    return max(1, math.ceil(max(shape[:2]) / side))


def downsample(lum: np.ndarray, side: int = ANALYSIS_SIDE) -> tuple[np.ndarray, int]:
    """Block average (float64) by the integer factor k that brings the longer side to ``side``
    at most (:func:`block_factor`), over the central crop of whole blocks; and k."""
    k = block_factor(lum.shape, side)
    if k == 1:
        return lum.astype(np.float64), 1
    return block_mean(lum, k, np.float64), k


def block_mean(a: np.ndarray, k: int, dtype=np.float64) -> np.ndarray:
    """Mean of ``a`` (H, W) or (H, W, C) over k x k blocks of its central crop of whole blocks,
    accumulated in ``dtype``.

    Summed as k column slices, then k row slices, of the whole image: each pass reads memory
    in order (a 12 MP photo's three channels at k = 4 in 0.08 s of CPU against 0.18 s for a
    mean over the axes of a (H / k, k, W / k, k) view, one strided channel at a time; the same
    sums, so the same values).

    Examples
    --------
    >>> import numpy as np
    >>> a = np.arange(30.0).reshape(5, 6)  # the central 4 x 6 crop: rows 0-3
    >>> block_mean(a, 2).tolist()
    [[3.5, 5.5, 7.5], [15.5, 17.5, 19.5]]
    """
    h, w = (a.shape[0] // k) * k, (a.shape[1] // k) * k
    r0, c0 = (a.shape[0] - h) // 2, (a.shape[1] - w) // 2
    a = a[r0:r0 + h, c0:c0 + w]
    cols = a[:, 0::k].astype(dtype)
    for i in range(1, k):
        cols += a[:, i::k]
    rows = cols[0::k].copy()
    for i in range(1, k):
        rows += cols[i::k]
    rows /= k * k
    return rows


def _box_mean(square: np.ndarray, size: int) -> np.ndarray:
    """Local mean of a non-negative quantity over ``size`` x ``size`` pixels, never negative.

    scipy's box filter is a running sum (each step adds the entering value and subtracts the
    leaving one), so past a bright region its mean of zeros comes out as -1e-17 and its square
    root as NaN (a render's or photo's black border after texture: issue 27)."""
    return np.maximum(ndi.uniform_filter(square, size, mode="reflect"), 0.0)


def texture_mask(lum: np.ndarray) -> np.ndarray:
    """Pixels with texture: local band-pass RMS above a twentieth of its 90th percentile, outside
    large flat regions.

    Black borders, blown-out areas and smooth sky fall below; ``ValueError`` if nothing has texture.
    The band-pass leaks some 30 pixels into a flat region from its edge, so flat regions (7 x 7
    standard deviation under a twentieth of its 90th percentile) that hold a 31 x 31 square are
    cut out whole, with a 3-pixel margin; thinner flat parts of a texture (mortar) stay in.
    """
    band = ndi.gaussian_filter(lum, 1.0, mode="reflect") - ndi.gaussian_filter(lum, 8.0,
                                                                                mode="reflect")
    local = np.sqrt(_box_mean(band * band, 15))
    ref = float(np.percentile(local, 90))
    scale = float(np.abs(lum).max())
    if not ref > 1e-4 * scale or scale == 0:
        raise ValueError("image has no texture (it is blank or nearly constant)")
    mean = ndi.uniform_filter(lum, 7, mode="reflect")
    fine = np.sqrt(np.maximum(_box_mean(lum * lum, 7) - mean * mean, 0.0))
    flat = (fine <= 0.05 * float(np.percentile(fine, 90))).astype(np.float32)
    square = (ndi.uniform_filter(flat, 31, mode="nearest") > 0.999).astype(np.float32)
    large_flat = ndi.uniform_filter(square, 37, mode="constant") > 0  # the squares, grown by 3
    return (local > 0.05 * ref) & ~large_flat


@dataclass(frozen=True)
class Spectra:
    """Periodograms of the textured windows: ``psd`` (N, M) at frequencies ``w`` (2, M)."""

    psd: np.ndarray
    w: np.ndarray
    centres: np.ndarray  # (N, 2) window centres, centred pixel coordinates, y up
    size: int            # window side P
    shape: tuple[int, int]


def spectra(lum: np.ndarray, mask: np.ndarray, w_max: float = 0.3, size: int = 64,
             stride: float = 0.5) -> Spectra:
    """Hann-windowed, plane-detrended periodograms on a grid of windows."""
    h, w = lum.shape
    size = min(size, 2 ** int(math.log2(min(h, w) / 2)))
    rows, cols = (np.unique(np.linspace(0, n - size, round((n - size) / size / stride) + 1).round())
                  for n in (h, w))
    corners = [(int(r), int(c)) for r in rows for c in cols
               if mask[int(r):int(r) + size, int(c):int(c) + size].mean() >= 0.95]
    if not corners:
        raise ValueError("no window of the image is textured throughout; crop to the textured "
                         "plane or use a larger image")
    windows = np.stack([lum[r:r + size, c:c + size] for r, c in corners])
    # Remove each window's least-squares plane (lighting gradients leak into low frequencies).
    yy, xx = np.mgrid[0:size, 0:size] / (size - 1) - 0.5
    basis = np.stack([np.ones_like(xx), xx, yy]).reshape(3, -1)
    flat = windows.reshape(len(windows), -1)
    coef = np.linalg.lstsq(basis.T, flat.T, rcond=None)[0]
    flat = flat - (basis.T @ coef).T
    hann = np.hanning(size + 2)[1:-1]
    taper = np.outer(hann, hann)
    spectrum = np.fft.rfft2(flat.reshape(-1, size, size) * taper)
    psd = (spectrum.real ** 2 + spectrum.imag ** 2) / (taper ** 2).sum()
    fx = np.fft.rfftfreq(size)[None, :] + 0 * np.fft.fftfreq(size)[:, None]
    fy = -np.fft.fftfreq(size)[:, None] + 0 * fx  # y up
    radius = np.hypot(fx, fy)
    keep = (radius >= 2.5 / size) & (radius <= w_max) & ~((fx == 0) & (fy < 0))
    centres = np.array([(c + (size - 1) / 2 - (w - 1) / 2, (h - 1) / 2 - r - (size - 1) / 2)
                        for r, c in corners])
    return Spectra(psd[:, keep], np.stack([fx[keep], fy[keep]]), centres, size, (h, w))


def moment_slant(spectra: Spectra) -> tuple[float, float]:
    """(slant, tilt mod 180) in degrees from the fourth-order moment of the windows' mean spectrum.

    An isotropic texture S(|nu|) seen orthographically through A (cos(sigma) along the tilt) has
    image spectrum S(|A^T w|) / |det A|. Its second moment sum P w w^T (the textbook estimate)
    has eigenvalue ratio cos^2(sigma). We weight by |w|^2 as well, M = sum P |w|^2 w w^T (the
    spectrum of the image's second derivatives: finer scales, where the renders and photos we
    measured keep less of their own anisotropy); substituting nu = A^T w, for isotropic S,
    M ~ A^-T (tr(C) I + 2 C) A^-1 with C = A^-1 A^-T, so the eigenvalue ratio is
    r = c^2 (1 + 3 c^2) / (3 + c^2), c = cos(sigma), solved here for c. The windows share one
    Jacobian in an orthographic view, so their periodograms are averaged first (Welch).
    """
    psd = spectra.psd.mean(axis=0)
    wx, wy = spectra.w
    weight = psd * (wx * wx + wy * wy)
    m = np.array([[np.sum(weight * wx * wx), np.sum(weight * wx * wy)],
                  [np.sum(weight * wx * wy), np.sum(weight * wy * wy)]])
    values, vectors = np.linalg.eigh(m)
    if not values[1] > 0:
        return 0.0, 0.0
    r = max(float(values[0]), 0.0) / float(values[1])
    c2 = (r - 1.0 + math.sqrt((1.0 - r) ** 2 + 36.0 * r)) / 6.0  # 3 c^4 + (1 - r) c^2 - 3 r = 0
    slant = math.degrees(math.acos(math.sqrt(min(c2, 1.0))))
    # The spectrum is stretched along the tilt: the larger eigenvector.
    tilt = math.degrees(math.atan2(vectors[1, 1], vectors[0, 1])) % 180.0
    return slant, tilt


class Criterion:
    """Back-projects every window's spectrum by a plane hypothesis and scores the texture.

    The bank is K = _ANGLES orientations over [0, pi) times half-octave scales, with triangular
    (linear interpolation) profiles in log radius and angle, applied in the plane's frequency
    frame: window i's sample at image frequency w lies at nu = J_i^-T w on the plane, where its
    power times |det J_i| is the plane texture's power spectrum. A band's log energy L[i, s, k]
    counts only where the window's samples cover the band (the photo resolves it there).
    """

    def __init__(self, spectra: Spectra):
        self.s = spectra
        lo, hi = _LOG_RANGE
        self.scales = int(round((hi - lo) / _DLOG)) + 1
        log_r = lo + _DLOG * np.arange(self.scales)
        self.band_area = 4.0 ** log_r * math.log(2) * _DLOG * math.pi / _ANGLES
        self.cells = self.scales * _ANGLES

    def band_limited(self, w_max: float) -> Criterion:
        """The same windows, image frequencies up to ``w_max`` only."""
        s = self.s
        keep = (s.w ** 2).sum(axis=0) <= w_max * w_max
        return Criterion(Spectra(s.psd[:, keep], s.w[:, keep], s.centres, s.size, s.shape))

    def bands(self, p: np.ndarray, v: np.ndarray):
        """Log band energies L (N, S, K), their noise variances, which count, and g.

        The windows are binned in independent chunks of ``_CHUNK`` samples, a run of chunks
        for each core side by side on the pool when called from one thread (a window's bands
        depend on its own samples only); S keeps only the scales some window measures (the
        others count nowhere)."""
        s = self.s
        jac, g = jacobians(s.centres, p, v)
        g_safe = np.maximum(g, _G_MIN)
        jac = jac * (g / g_safe)[:, None, None] ** 2
        a, b, c, d = (jac[:, i, j, None] for i in (0, 1) for j in (0, 1))
        signed = a * d - b * c
        det = np.abs(signed[:, 0])
        # nu = J^-T w, (N, M), in float32 (bin positions need no more; twice the speed)
        inv = np.concatenate([x / signed for x in (d, c, a, b)], axis=1).astype(np.float32)
        step = max(1, _CHUNK // s.psd.shape[1])
        starts = range(0, len(det), step)

        def binned(span):  # one task a core, not one a chunk: a chunk takes about 1 ms
            return [self._binned(inv[i:i + step], s.psd[i:i + step]) for i in starts[slice(*span)]]

        parts = [part for spans in parallel.run(binned, parallel.ranges(len(starts), 1))
                 for part in spans]
        wsum, w2sum, psum = (np.concatenate(x) for x in zip(*parts, strict=True))
        measured = np.flatnonzero(wsum.any(axis=(0, 2)))
        lo, hi = (measured[0], measured[-1] + 1) if len(measured) else (0, 1)
        wsum, w2sum, psum = (x[:, lo:hi] for x in (wsum, w2sum, psum))
        expected = s.size ** 2 * det[:, None, None] * self.band_area[None, lo:hi, None]
        with np.errstate(divide="ignore", invalid="ignore"):
            valid = (wsum >= _COVER * expected) & (psum > 0)
            if lo == 0:  # the clipped end bins collect out-of-range samples
                valid[:, 0] = False
            if hi == self.scales:
                valid[:, -1] = False
            energy = np.log(np.where(valid, psum / wsum, 1.0)) + np.log(det)[:, None, None]
            # Var(log mean of n exponential samples) ~ 1 / n_eff, n_eff = (sum w)^2 / sum w^2;
            # Hann neighbours are correlated (1.5).
            noise = np.where(valid, 1.5 * w2sum / (wsum * wsum), 0.0)
        return energy, noise, valid, g

    def _binned(self, inv: np.ndarray, psd: np.ndarray):
        """Bilinear sums of 1, its square and power over the (scale, orientation) cells of
        windows with inverse Jacobians ``inv`` (n, 4: J^-T = [[d, -c], [-b, a]] / det):
        (n, S, K) each. A sample's four cells are its lower corner's and the three next to it;
        the orientations are laid out with one cell either side (K + 2), folded back onto
        their periodic neighbours after the sums, so the four corners are fixed offsets."""
        wx, wy = self.s.w.astype(np.float32)
        nu_x = inv[:, 0, None] * wx - inv[:, 1, None] * wy
        nu_y = inv[:, 2, None] * wy - inv[:, 3, None] * wx
        fr = (np.float32(0.5) * np.log2(nu_x * nu_x + nu_y * nu_y)
              - np.float32(_LOG_RANGE[0])) / np.float32(_DLOG)
        fr = np.clip(fr, 0.0, self.scales - 1.001)  # the end bins, never valid, take overflow
        # angle mod pi, then in bins: adding pi where negative is what % pi does, 8x cheaper
        ft = np.arctan2(nu_y, nu_x)
        ft += np.float32(math.pi) * (ft < 0)
        ft -= np.float32(math.pi) * (ft >= np.float32(math.pi))
        ft = ft / np.float32(math.pi / _ANGLES) + np.float32(0.5)  # + 1: the cell before 0
        r0, t0 = np.floor(fr), np.floor(ft)  # t0 in 0 .. K
        a, b = (fr - r0).astype(np.float64), (ft - t0).astype(np.float64)
        row = _ANGLES + 2
        corner = (np.arange(len(inv)) * (self.scales * row))[:, None] + (
            r0.astype(np.intp) * row + t0.astype(np.intp))
        corner = corner.ravel()
        one_a, one_b = 1.0 - a, 1.0 - b
        weights = [(one_a * one_b).ravel(), (one_a * b).ravel(), (a * one_b).ravel(),
                   (a * b).ravel()]
        power = psd.ravel()
        n = len(inv) * self.scales * row
        sums = []
        for quantity in (lambda w: w, np.square, lambda w: w * power):
            total = np.zeros(n + row + 1)
            for offset, w in zip((0, 1, row, row + 1), weights, strict=True):
                total[offset:offset + n] += np.bincount(corner, quantity(w), n)
            cells = total[:n].reshape(len(inv), self.scales, row)
            cells[:, :, 1] += cells[:, :, -1]  # orientation K is orientation 0
            cells[:, :, -2] += cells[:, :, 0]  # orientation -1 is orientation K - 1
            sums.append(cells[:, :, 1:-1])
        return sums

    def homogeneity(self, p, v) -> tuple[float, float, int]:
        """Variance of each band's log energy across windows: (noise-corrected, raw, dof)."""
        energy, noise, valid, g = self.bands(p, v)
        penalty = float(np.sum(np.maximum(0.0, _G_MIN - g)) * 100.0)
        count = valid.sum(axis=0)
        shared = valid & (count >= 2)[None]
        dof = int(np.maximum(count - 1, 0)[count >= 2].sum())
        if dof < 8:
            return 10.0 + penalty, 10.0, 0
        n = np.maximum(count, 1)
        # Contrast varies across a photo (lighting, patchy textures): each window gets a log
        # gain, ridge-shrunk halfway to zero (a prior as strong as the window's own bands).
        gain = np.zeros((len(energy), 1, 1))
        bands = 2.0 * shared.sum(axis=(1, 2), keepdims=True) + 1e-9
        weight = shared.astype(np.float64)  # products, not np.where: the same sums, faster
        for _ in range(4):
            mean = ((energy - gain) * weight).sum(axis=0) / n
            gain = ((energy - mean) * weight).sum(axis=(1, 2), keepdims=True) / bands
        residual = (energy - gain - mean) * weight
        raw = float((residual ** 2).sum() / dof)
        bias = float((noise * (1 - 1 / n)[None] * weight).sum() / dof)
        return raw - bias + penalty, raw, dof

    def isotropy(self, p, v) -> tuple[float, float, int]:
        """Variance of log energy across orientations within a window and scale: (corrected,
        raw, dof), as for :meth:`homogeneity`."""
        energy, noise, valid, g = self.bands(p, v)
        penalty = float(np.sum(np.maximum(0.0, _G_MIN - g)) * 100.0)
        full = valid.all(axis=2)
        dof = int(full.sum()) * (_ANGLES - 1)
        if dof < 8:
            return 10.0 + penalty, 10.0, 0
        residual = np.where(full[..., None], energy - energy.mean(axis=2, keepdims=True), 0)
        raw = float((residual ** 2).sum() / dof)
        bias = float(np.where(full[..., None], noise, 0).sum() * (1 - 1 / _ANGLES) / dof)
        return raw - bias + penalty, raw, dof


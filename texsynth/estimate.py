"""Plane orientation from texture (shape from texture), rectification and camera pose.

Paper 000 (Forsyth and Ponce), section 11.4.1, "Shape from texture for planes". A viewing
transformation rotates the plane by the tilt and contracts it by cos(slant) along the tilt
direction; we search the *inverse* viewing transformation that makes the back-projected texture
most isotropic, measuring isotropy by the spread of oriented filter energy across orientations,
summed over scales, and optimise it with scipy. The search runs over perspective views too ("we
simply have to search over a larger family of transformations"), where homogeneity adds the cue
the section describes: the texture must look the same everywhere on the plane, so the scale
gradient of texels across the image fixes the receding direction (tilt mod 360), refines slant,
and with isotropy at the centre gives the focal length when it is unknown.

Conventions (fixed): image arrays are top row first. Image coordinates ``x = (x, y)`` are in
pixels from the image centre (the principal point), x right and y *up*. Tilt ``tau`` is measured
counter-clockwise from +x and is the image direction in which the surface recedes; slant
``sigma`` is the angle between the plane normal and the optical axis, in [0, 90). Camera
coordinates are Blender's: x right, y up, the camera looks along -z; the normal faces the camera:
n = (sin sigma cos tau, sin sigma sin tau, cos sigma).

The geometry in one line: with p = tan(sigma) (cos tau, sin tau) and v = p / f, the image point x
sees the plane point

    u = B x / (1 - v . x),    B = I + p p^T / (1 + sqrt(1 + |p|^2)),

in plane units (one unit = one pixel across the tilt direction at the image centre) and axes
that coincide with the image axes at slant 0; B stretches by 1 / cos(sigma) along the tilt
direction (the inverse viewing transformation of 11.4.1) and ``1 - v . x`` is the depth ratio
(the horizon is v . x = 1). Orthographic viewing is f = infinity, v = 0.

Deviations from the section, one line each:
- oriented energies are computed in the Fourier domain of local windows (Parseval): back-projecting
  a window by the local Jacobian J is the linear change of frequency nu = J^-T w, so no image is
  resampled per hypothesis and no band is measured beyond what the photo resolves;
- isotropy is the spread of *log* energy across orientations, each scale weighted alike (natural
  spectra fall as 1/f, energy weights would keep only the coarsest scale);
- homogeneity is the spread of log energy of each oriented band across windows, which needs no
  texel detection (the section's marked Poisson process reasoning, applied to filter energies);
- a slant found by isotropy is uncertain by at least the change that costs as much isotropy as the
  texture's own remaining anisotropy (the assumption's failure is an error, not noise).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import scipy.ndimage as ndi
import scipy.optimize as opt

from . import budget, validation

__all__ = [
    "PlaneEstimate",
    "estimate_plane",
    "rectify",
    "camera_pose",
    "normal_from_angles",
    "angles_from_normal",
    "image_to_plane",
    "plane_to_image",
    "focal_px_from_lens",
    "lens_from_focal_px",
    "ESTIMATE_METHODS",
]

#: ``method`` values of :func:`estimate_plane`.
ESTIMATE_METHODS = ("auto", "isotropy", "moments")

_MIN_SIDE = 64          # smallest image side accepted (pixels)
_ANALYSIS_SIDE = 384    # images are block-averaged down to at most this longer side
_ANGLES = 8             # orientation bins over [0, pi): the filter bank's K
_DLOG = 0.5             # radial bin width in octaves
_LOG_RANGE = (-14.0, 2.0)  # log2 cycles/px covered by the radial bins (texture frame)
_COVER = 0.6            # a window measures a band when its samples cover this share of it
_G_MIN = 0.15           # windows must stay this far from the horizon (depth ratio 1 / g)


# --- geometry ---------------------------------------------------------------------------------


def normal_from_angles(slant: float, tilt: float) -> np.ndarray:
    """Unit normal in camera coordinates (x right, y up, z toward the viewer) from degrees."""
    s, t = math.radians(slant), math.radians(tilt)
    return np.array([math.sin(s) * math.cos(t), math.sin(s) * math.sin(t), math.cos(s)])


def angles_from_normal(normal) -> tuple[float, float]:
    """(slant, tilt) in degrees of a normal in camera coordinates (flipped to face the camera)."""
    n = np.asarray(normal, dtype=np.float64)
    n = n / np.linalg.norm(n)
    if n[2] < 0:
        n = -n
    slant = math.degrees(math.acos(min(1.0, n[2])))
    tilt = math.degrees(math.atan2(n[1], n[0])) % 360.0 if slant > 0 else 0.0
    return slant, tilt


def _gradient(slant: float, tilt: float) -> np.ndarray:
    """p = tan(sigma) (cos tau, sin tau): smooth at slant 0, where tilt is undefined."""
    s, t = math.radians(slant), math.radians(tilt)
    return math.tan(s) * np.array([math.cos(t), math.sin(t)])


def _angles_from_gradient(p) -> tuple[float, float]:
    slant = math.degrees(math.atan(math.hypot(p[0], p[1])))
    tilt = math.degrees(math.atan2(p[1], p[0])) % 360.0
    return slant, tilt


def _stretch(p: np.ndarray) -> np.ndarray:
    """B: the inverse viewing transformation, 1 / cos(sigma) along the tilt direction."""
    p = np.asarray(p, dtype=np.float64)
    return np.eye(2) + np.outer(p, p) / (1.0 + math.sqrt(1.0 + p @ p))


def _vanishing(p: np.ndarray, focal_px: float | None) -> np.ndarray:
    return np.zeros(2) if focal_px is None else np.asarray(p, dtype=np.float64) / focal_px


def image_to_plane(points, slant: float, tilt: float, focal_px: float | None = None):
    """Plane coordinates u of image points x (..., 2), both centred with y up (see module)."""
    x = np.asarray(points, dtype=np.float64)
    p = _gradient(slant, tilt)
    g = 1.0 - x @ _vanishing(p, focal_px)
    return (x @ _stretch(p).T) / g[..., None]


def plane_to_image(points, slant: float, tilt: float, focal_px: float | None = None):
    """Image points x of plane coordinates u (..., 2): the inverse of :func:`image_to_plane`."""
    u = np.asarray(points, dtype=np.float64)
    p = _gradient(slant, tilt)
    binv = np.linalg.inv(_stretch(p))
    v = _vanishing(p, focal_px)
    return (u @ binv.T) / (1.0 + u @ (binv @ v))[..., None]


def _jacobians(centres: np.ndarray, p: np.ndarray, v: np.ndarray):
    """d u / d x at ``centres`` (N, 2) and the depth ratio g = 1 - v . x there."""
    b = _stretch(p)
    g = 1.0 - centres @ v
    bx = centres @ b.T
    jac = b[None] / g[:, None, None] + bx[:, :, None] * v[None, None, :] / (g * g)[:, None, None]
    return jac, g


def focal_px_from_lens(lens_mm: float, sensor_mm: float, width: int, height: int,
                       sensor_fit: str = "AUTO") -> float:
    """Focal length in pixels of a Blender camera (sensor fit AUTO, HORIZONTAL or VERTICAL)."""
    if sensor_fit == "VERTICAL":
        side = height
    elif sensor_fit == "HORIZONTAL":
        side = width
    else:
        side = max(width, height)
    return lens_mm / sensor_mm * side


def lens_from_focal_px(focal_px: float, sensor_mm: float, width: int, height: int,
                       sensor_fit: str = "AUTO") -> float:
    """Inverse of :func:`focal_px_from_lens`: the lens in millimetres."""
    return focal_px * sensor_mm / focal_px_from_lens(1.0, 1.0, width, height, sensor_fit)


def camera_pose(slant: float, tilt: float, distance: float, plane_matrix=None) -> np.ndarray:
    """4 x 4 camera-to-world matrix that sees a plane at ``slant`` and ``tilt`` (degrees).

    The plane is the local XY plane of ``plane_matrix`` (4 x 4, world from plane; identity if
    None) with normal +Z. The camera (Blender convention: looks along its -Z, +Y up) aims at the
    plane's origin from ``distance``; the plane's +X and +Y axes appear in the picture as the
    rectified image's x and y axes (see :func:`rectify`), so texturing the plane with the
    rectified photo at default UVs reproduces the photo.
    """
    slant = validation.finite(slant, "slant (degrees)")
    tilt = validation.finite(tilt, "tilt (degrees)")
    if not 0 <= slant < 90:
        raise ValueError(f"slant must be from 0 to below 90 degrees, got {slant}")
    if not validation.finite(distance, "distance") > 0:
        raise ValueError(f"distance must be positive, got {distance}")
    if plane_matrix is not None:
        plane_matrix = np.asarray(plane_matrix)
        if plane_matrix.shape != (4, 4) or plane_matrix.dtype.kind not in "fiu" \
                or not np.isfinite(plane_matrix).all():
            raise ValueError("plane_matrix must be a 4 x 4 matrix of finite numbers")
    s, t = math.radians(slant), math.radians(tilt)
    e1 = np.array([math.cos(s) * math.cos(t), math.cos(s) * math.sin(t), -math.sin(s)])
    e2 = np.array([-math.sin(t), math.cos(t), 0.0])
    n = normal_from_angles(slant, tilt)
    # Plane axes in camera coordinates: the rectified image's x and y directions (see rectify).
    axes = np.stack([math.cos(t) * e1 - math.sin(t) * e2,
                     math.sin(t) * e1 + math.cos(t) * e2, n], axis=1)
    rot = axes.T  # camera -> plane
    camera = np.eye(4)
    camera[:3, :3] = rot
    camera[:3, 3] = rot @ np.array([0.0, 0.0, distance])
    world = np.eye(4) if plane_matrix is None else np.asarray(plane_matrix, dtype=np.float64)
    return world @ camera


# --- the result -------------------------------------------------------------------------------


@dataclass(frozen=True)
class PlaneEstimate:
    """Orientation of a textured plane seen in a photo (degrees; camera coordinates).

    ``normal`` faces the camera (x right, y up, z toward the viewer). ``focal_px`` is the focal
    length in pixels of the analysed image size (given or estimated; None when the fit is
    orthographic) and ``focal_estimated`` says which. ``tilt_ambiguous_180``: the receding
    direction is not determined (orthographic view or too little perspective), ``tilt`` and
    ``tilt + 180`` explain the image equally. ``slant_uncertainty``, ``tilt_uncertainty`` and
    ``normal_uncertainty`` are one-sigma estimates in degrees; ``confidence`` in [0, 1] folds them
    with the texture's departure from the model (``anisotropy``, the RMS log-energy spread across
    orientations after rectification: near 0.1 for isotropic textures, 0.5 and more for bricks or
    weaves, where the isotropy assumption fails).
    """

    slant: float
    tilt: float
    normal: tuple[float, float, float]
    focal_px: float | None
    focal_estimated: bool
    tilt_ambiguous_180: bool
    confidence: float
    slant_uncertainty: float
    tilt_uncertainty: float
    normal_uncertainty: float
    focal_uncertainty: float | None
    anisotropy: float
    method: str
    image_size: tuple[int, int]

    @property
    def orthographic(self) -> bool:
        return self.focal_px is None


# --- measurements: local power spectra of textured windows -----------------------------------


def _validate(image) -> np.ndarray:
    """Luminance (H, W) float64 of an image array, or ``ValueError`` saying what is wrong."""
    a = np.asarray(image)
    if a.dtype.kind == "u":
        a = a.astype(np.float64) / np.iinfo(a.dtype).max
    elif a.dtype.kind not in "fi":
        raise ValueError(f"image must be a numeric array, got dtype {a.dtype}")
    if a.ndim == 3 and a.shape[2] in (1, 2, 3, 4):
        a = a[:, :, :3] @ np.array([0.2126, 0.7152, 0.0722]) if a.shape[2] >= 3 else a[:, :, 0]
    elif a.ndim != 2:
        raise ValueError(f"image must be (H, W) or (H, W, C) with C in 1..4, got shape {a.shape}")
    h, w = a.shape
    if min(h, w) < _MIN_SIDE:
        raise ValueError(f"image is {w} x {h} pixels; estimating a plane needs at least "
                         f"{_MIN_SIDE} x {_MIN_SIDE}")
    a = np.asarray(a, dtype=np.float64)
    if not np.isfinite(a).all():
        raise ValueError("image contains NaN or infinite values; repair or clamp it first")
    return a


def _downsample(lum: np.ndarray) -> tuple[np.ndarray, int]:
    """Block average by the integer factor that brings the longer side to _ANALYSIS_SIDE."""
    k = max(1, math.ceil(max(lum.shape) / _ANALYSIS_SIDE))
    if k == 1:
        return lum, 1
    h, w = (lum.shape[0] // k) * k, (lum.shape[1] // k) * k
    r0, c0 = (lum.shape[0] - h) // 2, (lum.shape[1] - w) // 2
    block = lum[r0:r0 + h, c0:c0 + w].reshape(h // k, k, w // k, k)
    return block.mean(axis=(1, 3)), k


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
    local = np.sqrt(ndi.uniform_filter(band * band, 15, mode="reflect"))
    ref = float(np.percentile(local, 90))
    scale = float(np.abs(lum).max())
    if not ref > 1e-4 * scale or scale == 0:
        raise ValueError("image has no texture (it is blank or nearly constant)")
    mean = ndi.uniform_filter(lum, 7, mode="reflect")
    fine = np.sqrt(np.maximum(ndi.uniform_filter(lum * lum, 7, mode="reflect") - mean * mean, 0))
    flat = (fine <= 0.05 * float(np.percentile(fine, 90))).astype(np.float32)
    square = (ndi.uniform_filter(flat, 31, mode="nearest") > 0.999).astype(np.float32)
    large_flat = ndi.uniform_filter(square, 37, mode="constant") > 0  # the squares, grown by 3
    return (local > 0.05 * ref) & ~large_flat


@dataclass(frozen=True)
class _Spectra:
    """Periodograms of the textured windows: ``psd`` (N, M) at frequencies ``w`` (2, M)."""

    psd: np.ndarray
    w: np.ndarray
    centres: np.ndarray  # (N, 2) window centres, centred pixel coordinates, y up
    size: int            # window side P
    shape: tuple[int, int]


def _spectra(lum: np.ndarray, mask: np.ndarray, w_max: float = 0.3, size: int = 64,
             stride: float = 0.5) -> _Spectra:
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
    return _Spectra(psd[:, keep], np.stack([fx[keep], fy[keep]]), centres, size, (h, w))


# --- the criterion: isotropy and homogeneity of back-projected oriented energies --------------


class _Criterion:
    """Back-projects every window's spectrum by a plane hypothesis and scores the texture.

    The bank is K = _ANGLES orientations over [0, pi) times half-octave scales, with triangular
    (linear interpolation) profiles in log radius and angle, applied in the plane's frequency
    frame: window i's sample at image frequency w lies at nu = J_i^-T w on the plane, where its
    power times |det J_i| is the plane texture's power spectrum. A band's log energy L[i, s, k]
    counts only where the window's samples cover the band (the photo resolves it there).
    """

    def __init__(self, spectra: _Spectra):
        self.s = spectra
        lo, hi = _LOG_RANGE
        self.scales = int(round((hi - lo) / _DLOG)) + 1
        log_r = lo + _DLOG * np.arange(self.scales)
        self.band_area = 4.0 ** log_r * math.log(2) * _DLOG * math.pi / _ANGLES
        self.cells = self.scales * _ANGLES

    def band_limited(self, w_max: float) -> _Criterion:
        """The same windows, image frequencies up to ``w_max`` only."""
        s = self.s
        keep = (s.w ** 2).sum(axis=0) <= w_max * w_max
        return _Criterion(_Spectra(s.psd[:, keep], s.w[:, keep], s.centres, s.size, s.shape))

    def bands(self, p: np.ndarray, v: np.ndarray):
        """Log band energies L (N, S, K), their noise variances, which count, and g."""
        s = self.s
        jac, g = _jacobians(s.centres, p, v)
        g_safe = np.maximum(g, _G_MIN)
        jac = jac * (g / g_safe)[:, None, None] ** 2
        a, b, c, d = (jac[:, i, j, None] for i in (0, 1) for j in (0, 1))
        signed = a * d - b * c
        det = np.abs(signed[:, 0])
        nu_x = (d * s.w[0] - c * s.w[1]) / signed  # nu = J^-T w, (N, M)
        nu_y = (a * s.w[1] - b * s.w[0]) / signed
        fr = (0.5 * np.log2(nu_x * nu_x + nu_y * nu_y) - _LOG_RANGE[0]) / _DLOG
        fr = np.clip(fr, 0.0, self.scales - 1.001)  # the end bins, never valid, take overflow
        ft = (np.arctan2(nu_y, nu_x) % math.pi) / (math.pi / _ANGLES) - 0.5
        r0, t0 = np.floor(fr), np.floor(ft)
        a, b = fr - r0, ft - t0
        t0 = t0.astype(np.int64)
        cell = (np.arange(len(det)) * self.cells)[:, None] + r0.astype(np.int64) * _ANGLES
        t_lo, t_hi = t0 % _ANGLES, (t0 + 1) % _ANGLES
        idx = np.stack([cell + t_lo, cell + t_hi, cell + _ANGLES + t_lo, cell + _ANGLES + t_hi])
        weight = np.stack([(1 - a) * (1 - b), (1 - a) * b, a * (1 - b), a * b])
        n = len(det) * self.cells
        idx, weight = idx.ravel(), weight.ravel()
        wsum = np.bincount(idx, weight, n)
        w2sum = np.bincount(idx, weight * weight, n)
        psum = np.bincount(idx, weight * np.broadcast_to(s.psd, (4, *s.psd.shape)).ravel(), n)
        shape = (len(det), self.scales, _ANGLES)
        wsum, w2sum, psum = (x.reshape(shape) for x in (wsum, w2sum, psum))
        expected = s.size ** 2 * det[:, None, None] * self.band_area[None, :, None]
        with np.errstate(divide="ignore", invalid="ignore"):
            valid = (wsum >= _COVER * expected) & (psum > 0)
            valid[:, [0, -1]] = False  # the clipped end bins collect out-of-range samples
            energy = np.log(np.where(valid, psum / wsum, 1.0)) + np.log(det)[:, None, None]
            # Var(log mean of n exponential samples) ~ 1 / n_eff, n_eff = (sum w)^2 / sum w^2;
            # Hann neighbours are correlated (1.5).
            noise = np.where(valid, 1.5 * w2sum / (wsum * wsum), 0.0)
        return energy, noise, valid, g

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
        for _ in range(4):
            mean = np.where(shared, energy - gain, 0).sum(axis=0) / n
            gain = np.where(shared, energy - mean, 0).sum(axis=(1, 2), keepdims=True) / bands
        residual = np.where(shared, energy - gain - mean, 0)
        raw = float((residual ** 2).sum() / dof)
        bias = float(np.where(shared, noise * (1 - 1 / n)[None], 0).sum() / dof)
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


# --- search -----------------------------------------------------------------------------------

_WINDOW = 48         # analysis window side (reduced image px): 48 beat 32 and 64 on renders
_W_MAX = 0.4         # highest image frequency used (cycles per pixel; Nyquist is 0.5)
_NOISE_K = 16.0      # correlation of neighbouring bands and windows: dof / _NOISE_K independent
_EVIDENCE = 0.5      # z-score a hypothesis must lose by to be ruled out (receding direction)
_SYSTEMATIC = 3.0    # deg: floor on the uncertainty (model and rendering effects)
_ISO_W_MAX = 0.3     # cycles/px: above this a pixel footprint blurs the foreshortened axis most
_ISOTROPY_FLOOR = 6.0  # deg: extra uncertainty when slant rests on the isotropy assumption


def _minimize(fun, starts, step):
    """Nelder-Mead from each start; the best result."""
    best = None
    for x0 in starts:
        x0 = np.asarray(x0, dtype=np.float64)
        simplex = np.vstack([x0, x0 + np.diag(np.broadcast_to(step, x0.shape))])
        res = opt.minimize(fun, x0, method="Nelder-Mead",
                           options={"initial_simplex": simplex, "xatol": 2e-3, "fatol": 1e-4,
                                    "maxfev": 300})
        if best is None or res.fun < best.fun:
            best = res
    return best


def _grid_starts(fun, tilts_over: float, count: int = 3):
    """The ``count`` best hypotheses p of a coarse slant x tilt grid."""
    grid = [np.zeros(2)] + [_gradient(s, t) for s in (15, 30, 45, 60, 70)
                            for t in np.arange(0.0, tilts_over, 30.0)]
    scores = [fun(p) for p in grid]
    return [grid[i] for i in np.argsort(scores)[:count]]


def _hessian(fun, x: np.ndarray, step: np.ndarray) -> np.ndarray:
    """Central finite-difference Hessian of ``fun`` at ``x``."""
    n = len(x)
    f0 = fun(x)
    hess = np.zeros((n, n))
    for i in range(n):
        ei = np.zeros(n)
        ei[i] = step[i]
        hess[i, i] = (fun(x + ei) - 2 * f0 + fun(x - ei)) / step[i] ** 2
        for j in range(i):
            ej = np.zeros(n)
            ej[j] = step[j]
            hess[i, j] = hess[j, i] = (fun(x + ei + ej) - fun(x + ei - ej) - fun(x - ei + ej)
                                       + fun(x - ei - ej)) / (4 * step[i] * step[j])
    return hess


def _noise(raw: float, dof: int) -> float:
    """Standard deviation of a criterion value from the sampling of the texture."""
    return raw * math.sqrt(2.0 * _NOISE_K / max(dof, 1))


def _covariance(fun, x, step, raw: float, dof: int, model: float = 0.0) -> np.ndarray:
    """Covariance of the minimiser x of ``fun`` (a variance of log energies): Gauss-Newton,
    cov = 2 (s^2 / dof_eff + e) H^-1 with s^2 the raw residual variance and e the criterion's
    remaining value where it rests on an assumption the texture can break (its own anisotropy:
    a shift of x that costs that much is as plausible as the fit)."""
    hess = _hessian(fun, np.asarray(x, dtype=np.float64), np.asarray(step, dtype=np.float64))
    values, vectors = np.linalg.eigh(hess)
    values = np.maximum(values, 1e-12)  # flat directions: unbounded uncertainty
    return (vectors / values) @ vectors.T * 2.0 * (raw * _NOISE_K / max(dof, 1) + model)


def _angles_cost(cost, v_of_p):
    """Criterion in (slant, tilt) degrees, for uncertainties in degrees."""
    def fun(st):
        p = _gradient(min(st[0], 89.0), st[1])
        return cost(p, v_of_p(p))[0]
    return fun


def _moments(lum: np.ndarray) -> tuple[float, float]:
    """Textbook baseline: (slant, tilt mod 180) from the spectral second-moment matrix.

    M = sum_w w w^T |I(w)|^2 over the Hann-windowed image; an isotropic texture foreshortened by
    cos(sigma) along the tilt has M's eigenvalues in the ratio cos^2(sigma), the larger one along
    the tilt (texels are compressed there, so frequencies are higher).
    """
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


@dataclass(frozen=True)
class _Fit:
    """A fitted plane in analysis-image pixels: gradient p, focal (None: orthographic)."""

    p: np.ndarray
    focal: float | None
    cov: np.ndarray  # (slant, tilt) covariance, degrees^2
    ambiguous: bool
    isotropy_based: bool
    focal_sd: float | None = None  # relative


def _fit_isotropy(crit: _Criterion) -> _Fit:
    """Section 11.4.1 as written: the orthographic inverse viewing transformation (p) that
    makes the back-projected texture most isotropic; tilt mod 180."""
    zero = np.zeros(2)

    def cost(p):
        return crit.isotropy(p, zero)[0]

    fit = _minimize(cost, _grid_starts(cost, 180.0), 0.1)
    _, raw, dof = crit.isotropy(fit.x, zero)
    st = _angles_from_gradient(fit.x)
    cov = _covariance(_angles_cost(crit.isotropy, lambda p: zero), st, (1.5, 3.0), raw, dof,
                      max(fit.fun, 0.0))
    return _Fit(fit.x, None, cov, True, True)


def _settle_direction(cost, criterion, fit, step):
    """The best fit receding either way, and by how much (noise units) it beats the best fit
    receding the other way: a second search confined to the half-plane opposite ``fit.x``."""
    axis = fit.x / max(np.linalg.norm(fit.x), 1e-12)

    def other_way(q):
        return cost(q) + 100.0 * max(0.0, float(q @ axis)) ** 2

    flipped = _minimize(other_way, [-fit.x], step)
    best, worse = (fit, flipped) if fit.fun <= flipped.fun else (flipped, fit)
    _, raw, dof = criterion(best.x)
    return best.x, (worse.fun - best.fun) / _noise(raw, dof), raw, dof


def _fit_known_focal(crit: _Criterion, f: float) -> _Fit:
    """Homogeneity with the focal length known: the texture's band energies must be the same in
    every window once back-projected; this fixes slant and the receding direction."""
    def cost(p):
        return crit.homogeneity(p, p / f)[0]

    fit = _minimize(cost, _grid_starts(cost, 360.0), 0.05)
    p, evidence, raw, dof = _settle_direction(cost, lambda q: crit.homogeneity(q, q / f), fit,
                                              0.05)
    st = _angles_from_gradient(p)
    cov = _covariance(_angles_cost(crit.homogeneity, lambda q: q / f), st, (1.5, 3.0), raw, dof)
    return _Fit(p, f, cov, evidence < _EVIDENCE, False)


def _fit_unknown_focal(crit: _Criterion, f_ref: float) -> _Fit:
    """Homogeneity gives the vanishing line v = tan(slant) / f (tilt mod 360); isotropy at that
    tilt gives the slant, and so f. Without evidence of perspective: :func:`_fit_isotropy`."""
    def cost(q):
        return crit.homogeneity(q, q / f_ref)[0]

    fit = _minimize(cost, _grid_starts(cost, 360.0), 0.05)
    if math.hypot(*fit.x) < 1e-3:
        return _fit_isotropy(crit)
    q, evidence, raw, dof = _settle_direction(cost, lambda q: crit.homogeneity(q, q / f_ref),
                                              fit, 0.05)
    if evidence < _EVIDENCE:
        return _fit_isotropy(crit)
    v = q / f_ref
    direction = v / np.linalg.norm(v)
    iso = crit.band_limited(_ISO_W_MAX)

    def slant_cost(slant):
        return iso.isotropy(math.tan(math.radians(slant)) * direction, v)[0]

    grid = np.arange(2.5, 85.0, 5.0)
    start = grid[int(np.argmin([slant_cost(s) for s in grid]))]
    best = opt.minimize_scalar(slant_cost, bounds=(max(start - 5, 0.5), min(start + 5, 85.0)),
                               method="bounded", options={"xatol": 0.05})
    slant = float(best.x)
    p = math.tan(math.radians(slant)) * direction
    _, iraw, idof = iso.isotropy(p, v)
    curvature = _hessian(lambda x: np.array(slant_cost(x[0])), np.array([slant]),
                         np.array([1.5]))[0, 0]
    var_slant = 2.0 * (iraw * _NOISE_K / max(idof, 1) + max(best.fun, 0.0)) / max(curvature,
                                                                                 1e-12)
    cov_v = _covariance(_angles_cost(crit.homogeneity, lambda x: x / f_ref),
                        _angles_from_gradient(q), (1.5, 3.0), raw, dof)
    cov = np.diag([var_slant, cov_v[1, 1]])
    # f = tan(slant) / |v|: relative error from the slant and from |v| (the slant of q).
    s_v = math.radians(_angles_from_gradient(q)[0])
    rel_v = math.sqrt(cov_v[0, 0]) * math.pi / 180 / (math.sin(s_v) * math.cos(s_v) + 1e-9)
    rel_s = math.sqrt(var_slant + _ISOTROPY_FLOOR ** 2) * math.pi / 180 / (
        math.sin(math.radians(slant)) * math.cos(math.radians(slant)) + 1e-9)
    return _Fit(p, float(math.tan(math.radians(slant)) / np.linalg.norm(v)), cov, False, True,
                math.hypot(rel_v, rel_s))


def estimate_plane(image, focal_px: float | None = None, method: str = "auto") -> PlaneEstimate:
    """Slant and tilt of the textured plane filling ``image`` (paper 000, section 11.4.1).

    Parameters
    ----------
    image : array (H, W) or (H, W, C), top row first, at least 64 x 64
        A photo of a plane; regions without texture (black borders, sky) are ignored.
    focal_px : float, optional
        Focal length in pixels of ``image`` (``focal_px_from_lens``); the principal point is the
        image centre. None: estimated (``method="auto"``) or orthographic (``"isotropy"``).
    method : {"auto", "isotropy", "moments"}
        "auto": homogeneity under perspective (receding direction, and slant when the focal
        length is given) with isotropy for the slant when it is not (then the focal length is
        estimated); isotropy alone when the photo shows no perspective.
        "isotropy": the orthographic isotropy search of 11.4.1 alone (tilt mod 180).
        "moments": the textbook spectral second-moment estimator (baseline; tilt mod 180).

    Returns
    -------
    PlaneEstimate (degrees; see its docstring for the conventions and confidence).
    """
    if method not in ESTIMATE_METHODS:
        raise ValueError(f"method must be one of {', '.join(ESTIMATE_METHODS)}, got {method!r}")
    if focal_px is not None:
        if isinstance(focal_px, bool) or not (np.isscalar(focal_px) and np.isreal(focal_px)
                                              and math.isfinite(focal_px) and focal_px > 0):
            raise ValueError(f"focal_px must be a positive number of pixels, got {focal_px!r}")
        focal_px = float(focal_px)
    lum = _validate(image)
    size = (lum.shape[1], lum.shape[0])
    if method == "moments":
        texture_mask(lum)  # the same "no texture" error as the other methods
        slant, tilt = _moments(lum)
        return _result(slant, tilt, None, False, True, np.diag([900.0, 8100.0]), None, 0.0,
                       True, method, size)
    small, k = _downsample(lum)
    crit = _Criterion(_spectra(small, texture_mask(small), _W_MAX, _WINDOW))
    if method == "isotropy":
        fit = _fit_isotropy(crit)
    elif focal_px is not None:
        fit = _fit_known_focal(crit, focal_px / k)
    else:
        fit = _fit_unknown_focal(crit, float(max(small.shape)))
    slant, tilt = _angles_from_gradient(fit.p)
    if fit.focal is None:  # p and -p are the same orthographic view
        tilt %= 180.0
    focal = None if fit.focal is None else fit.focal * k
    estimated = focal is not None and focal_px is None
    anisotropy = crit.isotropy(fit.p, np.zeros(2) if fit.focal is None else fit.p / fit.focal)
    return _result(slant, tilt, focal, estimated, fit.ambiguous, fit.cov, fit.focal_sd,
                   anisotropy[1], fit.isotropy_based, method, size)


def _result(slant, tilt, focal, estimated, ambiguous, cov, focal_sd, anisotropy, isotropy_based,
            method, size) -> PlaneEstimate:
    """The record, with uncertainties (one sigma, degrees) and confidence.

    confidence = P(normal within 8 deg) * P(receding direction within 30 deg), for Gaussian
    errors of the stated sigmas; the tilt factor is 1 when tilt is only claimed mod 180.
    """
    s_slant = math.hypot(math.sqrt(max(cov[0, 0], 0.0)), _SYSTEMATIC)
    s_tilt = min(180.0, math.hypot(math.sqrt(max(cov[1, 1], 0.0)), _SYSTEMATIC))
    if isotropy_based:
        s_slant = math.hypot(s_slant, _ISOTROPY_FLOOR)
    s_normal = math.hypot(s_slant, math.sin(math.radians(slant)) * s_tilt)
    confidence = 1.0 - math.exp(-(8.0 / s_normal) ** 2)
    confidence *= math.erf(30.0 / (s_tilt * math.sqrt(2.0)))
    n = normal_from_angles(slant, tilt)
    return PlaneEstimate(
        slant=float(slant), tilt=float(tilt), normal=tuple(float(c) for c in n),
        focal_px=None if focal is None else float(focal), focal_estimated=bool(estimated),
        tilt_ambiguous_180=bool(ambiguous), confidence=float(confidence),
        slant_uncertainty=float(s_slant), tilt_uncertainty=float(s_tilt),
        normal_uncertainty=float(s_normal),
        focal_uncertainty=None if focal_sd is None or focal is None else float(focal * focal_sd),
        anisotropy=float(math.sqrt(max(anisotropy, 0.0))), method=method, image_size=size)


# --- rectification ----------------------------------------------------------------------------

_MAX_MAGNIFICATION = 2.0  # rectify keeps the plane where no output pixel is stretched more


def _largest_rectangle(valid: np.ndarray) -> tuple[int, int, int, int]:
    """(row, col, height, width) of the largest all-True axis-aligned rectangle."""
    best = (0, 0, 0, 0)
    heights = np.zeros(valid.shape[1] + 1, dtype=np.int64)
    for r in range(valid.shape[0]):
        heights[:-1] = np.where(valid[r], heights[:-1] + 1, 0)
        stack = []
        for c, hgt in enumerate(heights):
            start = c
            while stack and stack[-1][1] >= hgt:
                start, top = stack.pop()
                if top * (c - start) > best[2] * best[3]:
                    best = (r - top + 1, start, int(top), c - start)
            stack.append((start, hgt))
    return best


def _image_coords(x: np.ndarray, shape) -> np.ndarray:
    """Centred y-up points (..., 2) -> (row, col) array coordinates."""
    h, w = shape
    return np.stack([(h - 1) / 2 - x[..., 1], x[..., 0] + (w - 1) / 2])


#: Seconds per output sample and channel (+2 for the coordinates) of rectify on the reference
#: machine (texsynth.budget), measured at 512 to 1536 pixels a side.
RECTIFY_SECONDS_PER_SAMPLE = 5e-8


def _check_estimate(estimate) -> None:
    """``ValueError`` unless ``estimate`` is a PlaneEstimate with finite angles (slant below 90
    degrees), a positive finite focal length or None, and a positive image size."""
    if not isinstance(estimate, PlaneEstimate):
        raise ValueError("estimate must be the PlaneEstimate returned by estimate_plane")
    size = estimate.image_size
    focal = estimate.focal_px
    if not (isinstance(size, (tuple, list)) and len(size) == 2
            and all(isinstance(v, (int, np.integer)) and v > 0 for v in size)) \
            or not all(isinstance(v, (int, float)) and math.isfinite(v)
                       for v in (estimate.slant, estimate.tilt)) \
            or not 0 <= estimate.slant < 90 \
            or not (focal is None or (isinstance(focal, (int, float)) and math.isfinite(focal)
                                      and focal > 0)):
        raise ValueError("the estimate is malformed (it needs finite slant below 90 degrees and "
                         "tilt, a positive focal length or None, and the image size it was made "
                         "on); use the PlaneEstimate returned by estimate_plane")


def rectify(image, estimate: PlaneEstimate, size: tuple[int, int] | None = None) -> np.ndarray:
    """Back-project ``image`` onto the plane: a frontal view of its texture (float32 (h, w, C)).

    An affine map for an orthographic estimate, a homography for a perspective one. The output is
    the largest axis-aligned rectangle of the plane that the photo shows with texture (black
    borders and sky excluded) and, under perspective, where no output pixel is magnified more than
    twice (the far part of a receding plane holds little detail). Its resolution is isotropic at
    the image centre (one output pixel = one image pixel along the foreshortened direction); its
    x and y axes are the plane's, which :func:`camera_pose` puts on the plane object's X and Y.
    ``size=(width, height)`` resamples the largest such rectangle of that aspect to that size.
    """
    _check_estimate(estimate)
    if size is not None:
        if not isinstance(size, (tuple, list)) or len(size) != 2:
            raise ValueError(f"size must be (width, height) in pixels, got {size!r}")
        size = validation.size(*size)
    a = np.asarray(image)
    lum = _validate(a)
    pixels = a.astype(np.float32) / np.iinfo(a.dtype).max if a.dtype.kind == "u" else a
    pixels = np.asarray(pixels, dtype=np.float32)
    if pixels.ndim == 2:
        pixels = pixels[:, :, None]
    h, w = lum.shape
    ew, eh = estimate.image_size
    if abs(ew / eh - w / h) > 0.01:
        raise ValueError(f"the estimate was made on a {ew} x {eh} image; this one is {w} x {h}")
    focal = None if estimate.focal_px is None else estimate.focal_px * w / ew
    slant, tilt = estimate.slant, estimate.tilt
    p = _gradient(slant, tilt)
    v = _vanishing(p, focal)
    step = math.sqrt(1.0 + p @ p)  # plane units per output pixel: 1 / cos(slant)
    g_min = 1.0 / math.sqrt(_MAX_MAGNIFICATION)

    # The plane region seen with texture, sampled on a raster at `step`.
    mask = texture_mask(lum)
    xs, ys = np.meshgrid(np.arange(w) - (w - 1) / 2, (h - 1) / 2 - np.arange(h))
    seen = mask & (1.0 - (xs * v[0] + ys * v[1]) >= g_min)
    if not seen.any():
        raise ValueError("no textured part of the image is close enough to rectify")
    corners = image_to_plane(np.stack([xs[seen], ys[seen]], axis=1), slant, tilt, focal)
    lo, hi = corners.min(axis=0), corners.max(axis=0)
    cols = np.arange(lo[0], hi[0] + step, step)
    rows = np.arange(hi[1], lo[1] - step, -step)
    grid = np.stack(np.meshgrid(cols, rows), axis=-1)
    back = plane_to_image(grid, slant, tilt, focal)
    rc = _image_coords(back, (h, w))
    inside = (rc[0] >= 0) & (rc[0] <= h - 1) & (rc[1] >= 0) & (rc[1] <= w - 1)
    near = np.clip(np.round(rc).astype(np.int64), 0, [[[h - 1]], [[w - 1]]])
    valid = inside & seen[near[0], near[1]]
    r0, c0, rh, cw = _largest_rectangle(valid)
    if rh < 8 or cw < 8:
        raise ValueError("the textured region of the plane is too small to rectify")
    top_left = np.array([cols[c0], rows[r0]])
    extent = np.array([cw, rh], dtype=np.float64) * step  # plane units (x right, y up)
    if size is None:
        out_w, out_h = cw, rh
    else:
        out_w, out_h = size
        fit = min(extent[0] / out_w, extent[1] / out_h)
        top_left = top_left + [(extent[0] - out_w * fit) / 2, -(extent[1] - out_h * fit) / 2]
        extent = np.array([out_w, out_h]) * fit
    unit = extent / [out_w, out_h]  # plane units per output pixel
    # Supersample where an output pixel covers several image pixels (the near side).
    minify = float(np.max(unit) / step * max(1.0, (1.0 - v @ back.reshape(-1, 2).T).max() ** 2))
    ss = int(np.clip(math.ceil(minify), 1, 4))
    what = f"rectifying to {out_w} x {out_h}"
    validation.check_memory(out_w * out_h * (8 * pixels.shape[2] + 8 * 7), what,
                            "ask for a smaller size")
    budget.check_time(RECTIFY_SECONDS_PER_SAMPLE * ss ** 2 * out_w * out_h
                      * (pixels.shape[2] + 2) * budget.machine_factor(), what)
    out = np.zeros((out_h, out_w, pixels.shape[2]), np.float64)
    for sy in range(ss):
        for sx in range(ss):
            jx = (np.arange(out_w) + (sx + 0.5) / ss) * unit[0]
            jy = (np.arange(out_h) + (sy + 0.5) / ss) * unit[1]
            plane = np.stack(np.meshgrid(top_left[0] + jx, top_left[1] - jy), axis=-1)
            coords = _image_coords(plane_to_image(plane, slant, tilt, focal), (h, w))
            for ch in range(pixels.shape[2]):
                out[:, :, ch] += ndi.map_coordinates(pixels[:, :, ch], coords, order=1,
                                                     mode="nearest")
    return (out / ss ** 2).astype(np.float32)

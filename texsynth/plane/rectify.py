"""Rectification: the photo back-projected onto the estimated plane, a frontal view of its texture
(conventions in :mod:`texsynth.plane.geometry`)."""

from __future__ import annotations

import math

import numpy as np
import scipy.ndimage as ndi

from .. import budget, validation
from .fit import PlaneEstimate
from .geometry import gradient, image_to_plane, plane_to_image, vanishing
from .spectra import luminance, texture_mask

__all__ = ["rectify"]

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
    """Back-project ``image`` onto the plane: a frontal view of its texture.

    An affine map for an orthographic estimate, a homography for a perspective one. The output is
    the largest axis-aligned rectangle of the plane that the photo shows with texture (black
    borders and sky excluded) and, under perspective, where no output pixel is magnified more than
    twice (the far part of a receding plane holds little detail). Its resolution is isotropic at
    the image centre (one output pixel = one image pixel along the foreshortened direction); its
    x and y axes are the plane's, which :func:`camera_pose` puts on the plane object's X and Y.

    Parameters
    ----------
    image : array (H, W) or (H, W, C), top row first
        The photo the estimate was made from (or another map of it, of its size).
    estimate : PlaneEstimate
        From :func:`texsynth.estimate_plane` (or ``texsynth.plane.from_rectangle``).
    size : (width, height), optional
        Resample the largest such rectangle of that aspect to that size.

    Returns
    -------
    numpy.ndarray
        float32 (h, w, C).

    References
    ----------
    Forsyth & Ponce, section 11.4.1 (the plane's image under orthographic and perspective
    projection, inverted here).

    Examples
    --------
    >>> import numpy as np, texsynth
    >>> noise = np.random.default_rng(0).random((96, 96), dtype=np.float32)
    >>> frontal = rectify(noise, texsynth.estimate_plane(noise, method="isotropy"), size=(32, 16))
    >>> frontal.shape, frontal.dtype
    ((16, 32, 1), dtype('float32'))
    """
    _check_estimate(estimate)
    if size is not None:
        if not isinstance(size, (tuple, list)) or len(size) != 2:
            raise ValueError(f"size must be (width, height) in pixels, got {size!r}")
        size = validation.size(*size)
    a = np.asarray(image)
    lum = luminance(a)
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
    p = gradient(slant, tilt)
    v = vanishing(p, focal)
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

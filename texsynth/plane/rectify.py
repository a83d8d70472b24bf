"""Rectification: the photo back-projected onto the estimated plane, a frontal view of its texture
(conventions in :mod:`texsynth.plane.geometry`)."""

from __future__ import annotations

import math

import numpy as np
import scipy.ndimage as ndi

from .. import budget, validation
from .fit import PlaneEstimate
from .geometry import gradient, image_to_plane, plane_to_image, stretch, vanishing
from .spectra import block_factor, block_mean, luminance, texture_mask

__all__ = ["rectify"]

_MAX_MAGNIFICATION = 2.0  # rectify keeps the plane where no output pixel is stretched more
#: The area filter's largest level (2 log2 s: an output pixel over 8 x 8 photo pixels).
_MAX_LEVEL = 6.0


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


#: The raster the largest rectangle is searched on has at most this many cells: the plane's
#: raster at the output's pixel is coarsened by an integer factor to it, and the rectangle
#: found there is grown back to the output's pixel one line at a time.
_RECTANGLE_CELLS = 2 ** 18


def _plane_rectangle(seen: np.ndarray, lo, hi, step: float, slant, tilt, focal):
    """The largest axis-aligned rectangle of the plane whose every output pixel (``step``
    plane units) falls inside the photo on a ``seen`` pixel: (top-left plane point, columns,
    rows).

    Ours: searched on a raster coarser by k (``_RECTANGLE_CELLS``), where a cell counts only
    when its centre and its 8 neighbours' are valid (the cell's pixels lie between them), then
    each side grown pixel line by pixel line while the new line is valid: the same rectangle
    to a pixel or two, at 1 / k^2 of the back-projections and of the search's Python loop."""
    h, w = seen.shape
    n_cols = int(np.floor((hi[0] - lo[0]) / step)) + 2
    n_rows = int(np.floor((hi[1] - lo[1]) / step)) + 2
    k = max(1, math.ceil(math.sqrt(n_cols * n_rows / _RECTANGLE_CELLS)))

    def valid(i, j):  # fine raster indices (broadcast) -> bool
        plane = np.stack(np.broadcast_arrays(lo[0] + j * step, hi[1] - i * step), axis=-1)
        rc = _image_coords(plane_to_image(plane, slant, tilt, focal), (h, w))
        inside = (rc[0] >= 0) & (rc[0] <= h - 1) & (rc[1] >= 0) & (rc[1] <= w - 1)
        near = np.round(rc).astype(np.int64)
        np.clip(near[0], 0, h - 1, out=near[0])
        np.clip(near[1], 0, w - 1, out=near[1])
        return inside & seen[near[0], near[1]]

    ci = np.arange(n_rows // k) * k + k // 2
    cj = np.arange(n_cols // k) * k + k // 2
    cells = valid(ci[:, None], cj[None, :])
    if k > 1:
        cells = ndi.binary_erosion(cells, np.ones((3, 3), bool), border_value=0)
    r0, c0, rh, cw = _largest_rectangle(cells)
    if rh == 0:
        return None
    top, left = r0 * k, c0 * k
    bottom, right = min(n_rows, (r0 + rh) * k), min(n_cols, (c0 + cw) * k)  # exclusive
    grow = True
    while grow and k > 1:
        grow = False
        if top > 0 and valid(np.full(right - left, top - 1), np.arange(left, right)).all():
            top, grow = top - 1, True
        if bottom < n_rows and valid(np.full(right - left, bottom),
                                     np.arange(left, right)).all():
            bottom, grow = bottom + 1, True
        if left > 0 and valid(np.arange(top, bottom), np.full(bottom - top, left - 1)).all():
            left, grow = left - 1, True
        if right < n_cols and valid(np.arange(top, bottom), np.full(bottom - top, right)).all():
            right, grow = right + 1, True
    return np.array([lo[0] + left * step, hi[1] - top * step]), right - left, bottom - top


#: The longest side the texture mask is found at: it marks borders, sky and blown-out parts,
#: features of tens of pixels, which a 12 MP photo block-averaged by 2 still shows.
_MASK_SIDE = 2048


def _texture_mask(lum: np.ndarray) -> np.ndarray:
    """:func:`texture_mask` of ``lum`` found at ``_MASK_SIDE`` and spread back to its pixels
    (the edges of a side that is no whole number of blocks take their neighbour's)."""
    k = block_factor(lum.shape, _MASK_SIDE)
    if k == 1:
        return texture_mask(lum)
    small = texture_mask(block_mean(lum, k, np.float32))
    full = np.repeat(np.repeat(small, k, axis=0), k, axis=1)
    h, w = lum.shape
    r0, c0 = (h - full.shape[0]) // 2, (w - full.shape[1]) // 2
    return np.pad(full, ((r0, h - full.shape[0] - r0), (c0, w - full.shape[1] - c0)),
                  mode="edge")


#: Seconds per output sample and channel (+2 for the coordinates) of rectify on the reference
#: machine (texsynth.budget), its texture mask and footprint levels included: the 12 MP phone
#: photo of benchmarks/phone_photo.py at 0.75, 3 and 12 MP, 3.0, 3.3 and 2.3e-7 (5e-8 had been
#: measured at 512 to 1536 pixels a side without the mask).
RECTIFY_SECONDS_PER_SAMPLE = 2.5e-7


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

    Each output pixel is sampled once (bilinear) from the photo filtered to its footprint: s,
    the longer side in photo pixels of the pixel's footprint under the homography's Jacobian,
    picks a Gaussian of variance (s^2 - 1) / 12 (a box of s pixels' less the one pixel's the
    photo already averages), from levels s = 2^(k/2) blended linearly in 2 log2 s (as a
    mipmap's levels, Williams 1983, here unsubsampled), so the cost follows the output's
    pixels, not a supersampling of the whole photo. Ours: one isotropic filter per pixel (the
    footprint's longer side), not an elliptical one (Heckbert 1989).

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
    projection, inverted here); Williams 1983, "Pyramidal parametrics" (levels of prefiltered
    images blended by the footprint); Heckbert 1989, "Fundamentals of texture mapping and image
    warping", 3.5 (the footprint from the Jacobian).

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

    # The plane region seen with texture; its bounding box on the plane from every 4th pixel,
    # padded by 4 pixels at the largest local scale (1 / g_min^2 plane units per image pixel
    # along the tilt, times the stretch `step`).
    mask = _texture_mask(lum)
    x_c = np.arange(w, dtype=np.float32) - (w - 1) / 2
    y_c = (h - 1) / 2 - np.arange(h, dtype=np.float32)
    seen = mask & (1.0 - (x_c[None, :] * v[0] + y_c[:, None] * v[1]) >= g_min)
    if not seen.any():
        raise ValueError("no textured part of the image is close enough to rectify")
    rr, cc = np.nonzero(seen[::4, ::4])
    corners = image_to_plane(np.stack([x_c[cc * 4], y_c[rr * 4]], axis=1), slant, tilt, focal)
    pad = 4 * 4 * step / g_min ** 2
    lo, hi = corners.min(axis=0) - pad, corners.max(axis=0) + pad
    found = _plane_rectangle(seen, lo, hi, step, slant, tilt, focal)
    if found is None or min(found[1:]) < 8:
        raise ValueError("the textured region of the plane is too small to rectify")
    top_left, cw, rh = found
    extent = np.array([cw, rh], dtype=np.float64) * step  # plane units (x right, y up)
    if size is None:
        out_w, out_h = cw, rh
    else:
        out_w, out_h = size
        fit = min(extent[0] / out_w, extent[1] / out_h)
        top_left = top_left + [(extent[0] - out_w * fit) / 2, -(extent[1] - out_h * fit) / 2]
        extent = np.array([out_w, out_h]) * fit
    unit = extent / [out_w, out_h]  # plane units per output pixel
    what = f"rectifying to {out_w} x {out_h}"
    validation.check_memory(out_w * out_h * (4 * pixels.shape[2] + 4 * 8), what,
                            "ask for a smaller size")
    budget.check_time(RECTIFY_SECONDS_PER_SAMPLE * 2 * out_w * out_h
                      * (pixels.shape[2] + 2) * budget.machine_factor(), what)
    coords, level = _footprints(top_left, unit, (out_h, out_w), (h, w), p, v)
    out = np.zeros((out_h * out_w, pixels.shape[2]), np.float32)
    for k in range(int(np.ceil(level.max())) + 1):
        weight = 1.0 - np.abs(level - k)  # the tent between levels k - 1, k and k + 1
        at = np.flatnonzero(weight > 0)
        if at.size == 0:
            continue
        sigma = math.sqrt((2.0 ** k - 1.0) / 12.0)
        margin = math.ceil(4 * sigma) + 2
        local, weight = coords[:, at], weight[at]
        lo_rc = np.maximum(np.floor(local.min(axis=1)).astype(int) - margin, 0)
        hi_rc = np.minimum(np.ceil(local.max(axis=1)).astype(int) + margin + 1, [h, w])
        local -= lo_rc[:, None].astype(np.float32)
        for ch in range(pixels.shape[2]):
            source = pixels[lo_rc[0]:hi_rc[0], lo_rc[1]:hi_rc[1], ch]
            if k:
                source = ndi.gaussian_filter(source, sigma, mode="nearest")
            out[at, ch] += weight * ndi.map_coordinates(source, local, order=1,
                                                        mode="nearest")
    return out.reshape(out_h, out_w, pixels.shape[2])


def _footprints(top_left, unit, out_shape, shape, p, v) -> tuple[np.ndarray, np.ndarray]:
    """Each output pixel's (row, col) in the photo, float32 (2, N), and its area filter's
    level, float32 (N,): 2 log2 s, s the length in photo pixels of the longer side of the
    pixel's footprint (at least 1), from the homography's Jacobian there.

    The output pixel (i, j) is the plane point u = (X_j, Y_i); its photo point
    x = B^-1 u / (1 + c . u), c = B^-1 v (:func:`plane_to_image`), whose derivative is
    dx/du = (B^-1 - x c^T) / (1 + c . u): its columns times the pixel's extent (``unit``) are
    the footprint's sides.
    """
    out_h, out_w = out_shape
    h, w = shape
    b_inv = np.linalg.inv(stretch(p))
    c = b_inv @ v
    big_x = (top_left[0] + (np.arange(out_w) + 0.5) * unit[0])[None, :]
    big_y = (top_left[1] - (np.arange(out_h) + 0.5) * unit[1])[:, None]
    den = (1.0 + c[0] * big_x + c[1] * big_y).astype(np.float32)
    x0 = ((b_inv[0, 0] * big_x + b_inv[0, 1] * big_y) / den).astype(np.float32)
    x1 = ((b_inv[1, 0] * big_x + b_inv[1, 1] * big_y) / den).astype(np.float32)
    side_x = np.hypot(b_inv[0, 0] - x0 * c[0], b_inv[1, 0] - x1 * c[0]) * (unit[0] / den)
    side_y = np.hypot(b_inv[0, 1] - x0 * c[1], b_inv[1, 1] - x1 * c[1]) * (unit[1] / den)
    s = np.maximum(np.maximum(side_x, side_y), 1.0)
    level = np.minimum(2.0 * np.log2(s), _MAX_LEVEL).astype(np.float32).reshape(-1)
    coords = np.stack([(h - 1) / 2 - x1, x0 + (w - 1) / 2]).reshape(2, -1)
    return coords, level

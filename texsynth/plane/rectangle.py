"""The plane from a rectangle the user marks on it: four image corners, in order around it.

The two pairs of opposite sides meet at the rectangle's two vanishing points x1, x2; their
directions from the camera centre are the rectangle's sides, so the plane's normal is their
cross product, and with the focal length unknown the sides' orthogonality gives it: f^2 =
-x1 . x2 with the principal point at the image centre (Caprile & Torre 1990, sec. 3; the
construction of Camera Calibration PVR and fSpy). Where a pair of sides stays parallel in the
image its vanishing point is at infinity: the focal length is then not determined by the
rectangle, and it must be given.
"""

from __future__ import annotations

import math

import numpy as np

from .. import validation
from .fit import PlaneEstimate, check_focal, plane_estimate
from .geometry import angles_from_normal

__all__ = ["from_rectangle"]

_CORNER_SIDE = 0.003  # one-sigma placement error of a corner, in image sides (3 px in 1000)
_FAR = 1e3            # a vanishing point farther than this many image sides is at infinity


def _homogeneous(corners: np.ndarray, shape) -> np.ndarray:
    """Corners (4, 2) as (column, row) pixels -> homogeneous centred y-up points (4, 3)."""
    h, w = shape
    x = corners[:, 0] - (w - 1) / 2.0
    y = (h - 1) / 2.0 - corners[:, 1]
    return np.stack([x, y, np.ones(4)], axis=1)


def _vanishing_points(points: np.ndarray) -> list[np.ndarray]:
    """The vanishing points (homogeneous, unit) of sides 1-2 with 4-3 and of 2-3 with 1-4."""
    out = []
    for a, b, c, d in ((0, 1, 3, 2), (1, 2, 0, 3)):
        vp = np.cross(np.cross(points[a], points[b]), np.cross(points[c], points[d]))
        norm = float(np.linalg.norm(vp))
        if not norm > 0.0:  # two sides on one line
            raise ValueError("the corners are collinear: they mark no rectangle")
        out.append(vp / norm)
    return out


def _finite(vp: np.ndarray, side: float) -> bool:
    return abs(vp[2]) * _FAR * side > np.linalg.norm(vp[:2])


def _plane(points: np.ndarray, side: float, focal: float | None):
    """(slant, tilt, focal) of the rectangle whose corners are ``points``."""
    vps = _vanishing_points(points)
    if focal is None:
        if not all(_finite(vp, side) for vp in vps):
            raise ValueError("the rectangle's opposite sides are parallel in the image (a "
                             "vanishing point at infinity): it does not give the focal length; "
                             "pass focal_px (the EXIF's, or the camera's lens)")
        x1, x2 = (vp[:2] / vp[2] for vp in vps)
        f2 = -float(x1 @ x2)
        if f2 <= 0:
            raise ValueError("no camera with its principal point at the image centre sees "
                             "these corners as a rectangle (its sides' vanishing points give "
                             "f^2 <= 0): check their order around the rectangle, or pass "
                             "focal_px")
        focal = math.sqrt(f2)
    # Directions of the sides in camera coordinates (the camera looks along -z, the image
    # plane at z = -f): (x, y, -f w) for a homogeneous vanishing point (x, y, w).
    d1, d2 = (np.array([vp[0], vp[1], -focal * vp[2]]) for vp in vps)
    normal = np.cross(d1, d2)
    if np.linalg.norm(normal) < 1e-12 * np.linalg.norm(d1) * np.linalg.norm(d2):
        raise ValueError("the corners are collinear: they mark no rectangle")
    slant, tilt = angles_from_normal(normal)
    return slant, tilt, focal


def from_rectangle(corners, shape, focal_px: float | None = None) -> PlaneEstimate:
    """The plane of a rectangle marked by its four image corners.

    Parameters
    ----------
    corners : array-like (4, 2)
        The rectangle's corners on the plane, in order around it (either way), as (x, y)
        pixels of the image: x to the right, y down, the first pixel's centre at (0, 0).
    shape : (height, width)
        The image's size in pixels (``image.shape[:2]``).
    focal_px : float, optional
        The focal length in pixels; None: found from the two vanishing points.

    Returns
    -------
    PlaneEstimate
        Its ``method`` is "rectangle"; the receding direction is claimed (``tilt`` mod 360).
        The uncertainties are those of corners placed to ``_CORNER_SIDE`` of the image's
        longer side (one sigma), by finite differences.

    Raises
    ------
    ValueError
        Where the corners mark no rectangle, or, with the focal length unknown, where a pair
        of opposite sides stays parallel in the image (a parallelogram: no vanishing point, no
        focal length).

    References
    ----------
    Caprile & Torre 1990, "Using vanishing points for camera calibration", sec. 3.

    Examples
    --------
    A square turned 30 deg on a plane at slant 30 deg, tilt 90 (receding upwards), seen with a
    focal length of 500 pixels in a 640 x 480 image:

    >>> import numpy as np
    >>> from texsynth.plane import plane_to_image
    >>> turn = np.radians(30.0 + 90.0 * np.arange(4))
    >>> square = 110.0 * np.stack([np.cos(turn), np.sin(turn)], axis=1)
    >>> x, y = plane_to_image(square, 30.0, 90.0, 500.0).T  # centred, y up
    >>> corners = np.stack([x + 319.5, 239.5 - y], axis=1)
    >>> plane = from_rectangle(corners, (480, 640), focal_px=500.0)
    >>> round(plane.slant, 3), round(plane.tilt, 3)
    (30.0, 90.0)
    >>> round(from_rectangle(corners, (480, 640)).focal_px, 3)
    500.0
    """
    corners = np.asarray(corners, dtype=np.float64)
    if corners.shape != (4, 2) or not np.isfinite(corners).all():
        raise ValueError(f"corners must be four (x, y) pixel points, got shape {corners.shape}")
    if not (isinstance(shape, (tuple, list)) and len(shape) >= 2):
        raise ValueError(f"shape must be (height, width) in pixels, got {shape!r}")
    w, h = validation.size(int(shape[1]), int(shape[0]))
    focal_px = check_focal(focal_px)
    side = float(max(h, w))
    points = _homogeneous(corners, (h, w))
    slant, tilt, focal = _plane(points, side, focal_px)
    # Corner placement error, propagated by central differences of each coordinate.
    sigma, step = _CORNER_SIDE * side, 0.5
    rows = []
    for i in range(4):
        for axis in range(2):
            ends = []
            for sign in (-1.0, 1.0):
                moved = points.copy()
                moved[i, axis] += sign * step
                ends.append(_plane(moved, side, focal_px))
            (s0, t0, f0), (s1, t1, f1) = ends
            rows.append([(s1 - s0) / (2 * step), ((t1 - t0 + 180.0) % 360.0 - 180.0)
                         / (2 * step), (f1 - f0) / (2 * step * focal)])
    jac = np.array(rows) * sigma
    cov = jac[:, :2].T @ jac[:, :2]
    focal_sd = None if focal_px is not None else float(math.sqrt(jac[:, 2] @ jac[:, 2]))
    return plane_estimate(slant, tilt, focal, focal_px is None, False, cov, focal_sd, 0.0,
                          False, "rectangle", (w, h), 0, 0.0)

"""Cameras: Blender's lens and sensor fit to a focal length in pixels, and the camera pose that
sees a plane at a given slant and tilt (conventions in :mod:`texsynth.plane.geometry`)."""

from __future__ import annotations

import math

import numpy as np

from .. import validation
from .geometry import normal_from_angles

__all__ = ["camera_pose", "focal_px_from_lens", "lens_from_focal_px"]


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

    The camera (Blender convention: looks along its -Z, +Y up) aims at the plane's origin; the
    plane's +X and +Y axes appear in the picture as the rectified image's x and y axes (see
    :func:`rectify`), so texturing the plane with the rectified photo at default UVs
    reproduces the photo.

    Parameters
    ----------
    slant, tilt : float
        Degrees, as in :class:`~texsynth.plane.fit.PlaneEstimate` (slant 0 to below 90).
    distance : float
        From the camera to the plane's origin, in world units (positive).
    plane_matrix : array (4, 4), optional
        World from plane: the plane is its local XY plane, normal +Z; identity if None.

    Returns
    -------
    numpy.ndarray
        float64 (4, 4), camera to world.

    References
    ----------
    Forsyth & Ponce, section 11.4.1 (slant and tilt); docs/ARCHITECTURE.md, Conventions, "Plane
    orientation".

    Examples
    --------
    The camera sits ``distance`` from the plane's origin, its view axis ``slant`` from the
    plane's normal.

    >>> import numpy as np
    >>> pose = camera_pose(30.0, 90.0, 2.0)
    >>> float(np.linalg.norm(pose[:3, 3])), round(float(np.degrees(np.arccos(pose[2, 2]))), 6)
    (2.0, 30.0)
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


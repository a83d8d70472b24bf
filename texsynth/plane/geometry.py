"""The plane's geometry: normals and angles, the gradient p, and the maps image <-> plane.

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
direction (the inverse viewing transformation of Forsyth & Ponce's sec. 11.4.1) and ``1 - v . x``
is the depth ratio (the horizon is v . x = 1). Orthographic viewing is f = infinity, v = 0.
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["normal_from_angles", "angles_from_normal", "image_to_plane", "plane_to_image"]


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


def gradient(slant: float, tilt: float) -> np.ndarray:
    """p = tan(sigma) (cos tau, sin tau): smooth at slant 0, where tilt is undefined."""
    s, t = math.radians(slant), math.radians(tilt)
    return math.tan(s) * np.array([math.cos(t), math.sin(t)])


def angles_from_gradient(p) -> tuple[float, float]:
    """(slant, tilt) in degrees of a gradient p (the inverse of :func:`gradient`)."""
    slant = math.degrees(math.atan(math.hypot(p[0], p[1])))
    tilt = math.degrees(math.atan2(p[1], p[0])) % 360.0
    return slant, tilt


def stretch(p: np.ndarray) -> np.ndarray:
    """B: the inverse viewing transformation, 1 / cos(sigma) along the tilt direction."""
    p = np.asarray(p, dtype=np.float64)
    return np.eye(2) + np.outer(p, p) / (1.0 + math.sqrt(1.0 + p @ p))


def vanishing(p: np.ndarray, focal_px: float | None) -> np.ndarray:
    """v = p / f, the vanishing line's coefficients (zero for an orthographic view)."""
    return np.zeros(2) if focal_px is None else np.asarray(p, dtype=np.float64) / focal_px


def image_to_plane(points, slant: float, tilt: float, focal_px: float | None = None):
    """Plane coordinates u of image points x (..., 2), both centred with y up (see module)."""
    x = np.asarray(points, dtype=np.float64)
    p = gradient(slant, tilt)
    g = 1.0 - x @ vanishing(p, focal_px)
    return (x @ stretch(p).T) / g[..., None]


def plane_to_image(points, slant: float, tilt: float, focal_px: float | None = None):
    """Image points x of plane coordinates u (..., 2): the inverse of :func:`image_to_plane`."""
    u = np.asarray(points, dtype=np.float64)
    p = gradient(slant, tilt)
    binv = np.linalg.inv(stretch(p))
    v = vanishing(p, focal_px)
    return (u @ binv.T) / (1.0 + u @ (binv @ v))[..., None]


def jacobians(centres: np.ndarray, p: np.ndarray, v: np.ndarray):
    """d u / d x at ``centres`` (N, 2) and the depth ratio g = 1 - v . x there."""
    b = stretch(p)
    g = 1.0 - centres @ v
    bx = centres @ b.T
    jac = b[None] / g[:, None, None] + bx[:, :, None] * v[None, None, :] / (g * g)[:, None, None]
    return jac, g

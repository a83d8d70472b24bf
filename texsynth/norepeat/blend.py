"""Tiling and blending (Heitz & Neyret 2018; Deliot & Heitz 2019) in numpy: the reference the
Blender node group follows, and a way to write the texture out for anything else.

Texture space is cut into a triangle grid; each grid vertex carries a random offset into the
(periodic) Gaussianised texture; a point is the variance-preserving blend of its triangle's
three offset copies, weighted by its barycentric coordinates, sent back through the inverse
table. Deviation: the vertex hash is an integer mix of our own (Blender's node group uses its
White Noise texture); both are uniform, and neither is the paper's sine hash. Offsets are
snapped to whole texels: a sub-texel offset makes the linear read average neighbouring texels,
which the variance-preserving blend does not undo (fine-grained photos came out soft).
"""

from __future__ import annotations

import numpy as np
from scipy.ndimage import map_coordinates

from .. import validation
from .gaussian import MU, Gaussianized

__all__ = ["triangle_grid", "vertex_offsets", "tile_and_blend", "predict_blend_memory",
           "GRID_SCALE", "SKEW"]

#: Triangle-grid vertices per texture tile along u (Deliot & Heitz 2019, 1.2: ``uv * 2 sqrt 3``).
GRID_SCALE = 2.0 * np.sqrt(3.0)
#: Texture space to the skewed grid, where the triangles are halves of unit squares.
SKEW = np.array([[1.0, 0.0], [-1.0 / np.sqrt(3.0), 2.0 / np.sqrt(3.0)]])


def triangle_grid(uv: np.ndarray, scale: float = GRID_SCALE):
    """Barycentric weights (..., 3) and the three vertices (..., 3, 2) (integer skewed-grid
    coordinates) of the triangle holding each point ``uv`` (..., 2).

    References
    ----------
    Deliot & Heitz 2019, 1.2, ``TriangleGrid``.

    Examples
    --------
    >>> w, v = triangle_grid(np.array([[0.0, 0.0], [0.3, 0.7]]))
    >>> np.allclose(w.sum(axis=-1), 1.0), v.shape
    (True, (2, 3, 2))
    """
    skewed = np.einsum("ij,...j->...i", SKEW, np.asarray(uv, np.float64) * scale)
    base = np.floor(skewed)
    f = skewed - base
    z = 1.0 - f[..., 0] - f[..., 1]
    lower = (z > 0)[..., None]  # the triangle below the diagonal
    w = np.where(lower, np.stack([z, f[..., 1], f[..., 0]], -1),
                 np.stack([-z, 1.0 - f[..., 1], 1.0 - f[..., 0]], -1))
    c = lower[..., None].astype(np.int64)
    corner = np.array([[0, 0], [0, 1], [1, 0]]) * c + np.array([[1, 1], [1, 0], [0, 1]]) * (1 - c)
    return w, base.astype(np.int64)[..., None, :] + corner


def vertex_offsets(vertices: np.ndarray, seed: int) -> np.ndarray:
    """A uniform random offset in [0, 1)^2 per integer vertex (..., 2) and seed: a hash, so the
    same vertex always gets the same offset."""
    v = vertices.astype(np.uint64) & np.uint64(0xFFFFFFFF)
    h = v[..., 0] * np.uint64(0x9E3779B1) ^ v[..., 1] * np.uint64(0x85EBCA77) \
        ^ np.uint64(seed) * np.uint64(0xC2B2AE3D)
    out = []
    for salt in (0x27D4EB2F, 0x165667B1):
        x = (h ^ np.uint64(salt)) * np.uint64(0xFF51AFD7ED558CCD)
        x ^= x >> np.uint64(33)
        x *= np.uint64(0xC4CEB9FE1A85EC53)
        x ^= x >> np.uint64(33)
        out.append((x >> np.uint64(40)).astype(np.float64) / float(1 << 24))
    return np.stack(out, -1)


def predict_blend_memory(width: int, height: int, channels: int) -> float:
    """Peak bytes of :func:`tile_and_blend` for a ``width`` x ``height`` output of ``channels``
    channels: the float64 coordinates, weights, vertices and offsets of every pixel, and the
    blend and look-up per channel (tracemalloc: 234 and 280 bytes a pixel for 1 and 3
    channels)."""
    return float(width) * height * (216 + 24 * channels)


def tile_and_blend(g: Gaussianized, width: int, height: int, *, scale: float = GRID_SCALE,
                   seed: int = 0) -> np.ndarray:
    """A ``width`` x ``height`` image of the tiled-and-blended texture at the exemplar's pixel
    size (pixel ``(y, x)`` at ``uv = ((x + 0.5) / w, (y + 0.5) / h)``): as large as wanted, and
    repeating nowhere.

    Parameters
    ----------
    g : Gaussianized
        From :func:`texsynth.norepeat.gaussianize`.
    width, height : int
        Output size in pixels.
    scale : float
        Triangle-grid vertices per texture tile (default ``2 sqrt 3``, Deliot & Heitz's).
    seed : int
        Picks the offsets.

    Returns
    -------
    float32 (height, width, C)

    References
    ----------
    Heitz & Neyret 2018, 3.1 (the variance-preserving blend ``(sum w_i G_i - mu) /
    sqrt(sum w_i^2) + mu``) and 5 (the triangle grid); Deliot & Heitz 2019, 1.2-1.5.

    Examples
    --------
    >>> from texsynth.norepeat import gaussianize
    >>> photo = np.random.default_rng(1).random((32, 32, 3)).astype(np.float32)
    >>> out = tile_and_blend(gaussianize(photo, lut_size=256), 96, 64, seed=3)
    >>> out.shape, out.dtype
    ((64, 96, 3), dtype('float32'))
    """
    width, height = validation.size(width, height)
    scale = validation.number(scale, "scale", 0.01, 1000.0)
    seed = validation.seed(seed)
    h, w, c = g.gaussian.shape
    validation.check_memory(predict_blend_memory(width, height, c),
                            f"Tiling and blending {width} x {height} pixels", "a smaller size")
    x, y = np.meshgrid((np.arange(width) + 0.5) / w, (np.arange(height) + 0.5) / h)
    uv = np.stack([x, y], -1)
    weights, vertices = triangle_grid(uv, scale)
    blended = np.zeros((height, width, c), np.float64)
    for i in range(3):
        at = uv + np.floor(vertex_offsets(vertices[..., i, :], seed) * (w, h)) / (w, h)
        # texel centres at (k + 0.5) / size, wrapping: the renderer's linear REPEAT look-up
        rows, cols = at[..., 1] * h - 0.5, at[..., 0] * w - 0.5
        for k in range(c):
            blended[..., k] += weights[..., i] * map_coordinates(
                g.gaussian[..., k], [rows, cols], order=1, mode="grid-wrap")
    blended = (blended - MU) / np.sqrt((weights ** 2).sum(-1))[..., None] + MU
    return g.look_up(blended.astype(np.float32))

"""Joints that stop where two copies meet, found and synthesized again (issue 41).

A position map's copies (regions copied whole from the exemplar) meet at seams; where a joint
of one copy meets the middle of another's element it stops there, a dead end the photo does
not have. After a level is relaxed its map is rendered at full resolution (each grid point
standing for its 2^l x 2^l block, copied whole), the rendered joints' dead ends (the rule
``texsynth.blocks.joints.Joints`` fitted on the photo) within ``NEAR`` joint widths of a seam
are the synthesis' own, and the grid points within ``reach`` pixels of them lose their
confidence: the level's relaxation (``texsynth.blocks.multigrid.relax``) visits them again,
the confident pixels around each hole proposing their continuations (Ashikhmin 2001) as at
the start, so the hole is filled from its rim as a constrained synthesis (Efros & Leung 1999:
a hole grown inward from its boundary). The dead ends inside one copy are the photo's own and
are left alone.

Deviations, one line each (ours, not in Neubeck et al. 2004 or Paget & Longstaff 1998):
- a level's map is relaxed a second time where the joints it renders stop at a seam;
- the rendered map of a coarse level repeats each grid point's exemplar block (the finer
  levels' interpolation of it), the joints read on it at the photo's full resolution.
"""

from __future__ import annotations

import numpy as np
from scipy.spatial import cKDTree

from .joints import Joints

__all__ = ["render", "seams", "holes", "photo_ends"]

#: A dead end within this many joint widths of a seam is the synthesis' own.
NEAR = 1.5


def render(source: np.ndarray, step: int, shape: tuple[int, int], size: tuple[int, int],
           wrap: bool) -> np.ndarray:
    """The full-resolution position map (``shape`` (H, W) rows, cols, 2) of a level's map
    ``source`` (flat positions into an exemplar of ``size`` (h, w)), each grid point spread
    over its ``step`` x ``step`` block with the block's offsets; positions past the
    exemplar's edges wrapped (``wrap``) or clipped.

    Examples
    --------
    >>> render(np.array([[5]]), 2, (2, 2), (4, 4), False)[..., 1]
    array([[1, 2],
           [1, 2]])
    """
    h, w = size
    out = np.empty((*shape, 2), np.int64)
    for k, (p, bound) in enumerate(zip(np.divmod(source, w), size, strict=True)):
        block = np.repeat(np.repeat(p, step, axis=0)[:shape[0]], step, axis=1)[:, :shape[1]]
        inner = np.arange(shape[k]) % step  # the block's offsets along rows, then columns
        np.add(block, inner[:, None] if k == 0 else inner[None, :], out=out[..., k])
        if wrap:
            np.remainder(out[..., k], bound, out=out[..., k])
        else:
            np.minimum(out[..., k], bound - 1, out=out[..., k])
    return out


def seams(positions: np.ndarray) -> np.ndarray:
    """Where two copies meet (bool, H x W): a pixel whose right or lower neighbour (on the
    torus) is not the exemplar pixel that continues it.

    Examples
    --------
    >>> p = np.stack(np.mgrid[:4, :4], axis=2); p[:, 2:, 0] += 1  # two copies (and the wrap)
    >>> seams(p)[1:3].any(axis=0)
    array([False,  True, False,  True])
    """
    down = np.roll(positions, -1, axis=0) - positions
    right = np.roll(positions, -1, axis=1) - positions
    return ((down[..., 0] != 1) | (down[..., 1] != 0) | (right[..., 0] != 0)
            | (right[..., 1] != 1))


def holes(photo: np.ndarray, positions: np.ndarray, joints: Joints, reach: float,
          step: int = 1) -> np.ndarray:
    """The grid points ``positions[::step, ::step]`` (bool) within ``reach`` pixels of a dead
    end of the joints rendered from ``photo`` (its colours or luma) at ``positions`` (read on
    the torus) that lies within ``NEAR`` joint widths of a seam (:func:`seams`).

    References
    ----------
    .. [1] A. A. Efros and T. K. Leung, "Texture synthesis by non-parametric sampling," ICCV
       1999 (a hole filled from its rim inward).
    .. [2] M. Ashikhmin, "Synthesizing natural textures," I3D 2001 (the neighbours'
       continuations proposed).

    Examples
    --------
    >>> i, j = np.mgrid[:64, :64]
    >>> wall = np.where((i % 16 < 3) | ((j + 16 * (i // 16 % 2)) % 32 < 3), 0.2, 0.7)
    >>> p = np.stack([i, j], axis=2)
    >>> joints = Joints.fit(wall, 1.5)
    >>> bool(holes(wall, p, joints, 4.0).any())  # one copy, on the torus: no hole
    False
    >>> p[:, 40:, 0] = (p[:, 40:, 0] + 8) % 64  # a copy half a course off
    >>> bool(holes(wall, p, joints, 4.0)[:, 36:44].any()), holes(wall, p, joints, 4.0, 4).shape
    (True, (16, 16))
    """
    shape = positions.shape[:2]
    _, end = joints.skeleton(photo[positions[..., 0], positions[..., 1]], wrap=True)
    f = joints.f
    r, c = np.nonzero(end)
    at = np.stack([np.minimum(r * f + f // 2, shape[0] - 1),
                   np.minimum(c * f + f // 2, shape[1] - 1)], axis=1)
    at = at[_near(seams(positions), at, NEAR * 2 * joints.sigma + f)]
    grid = np.stack(np.mgrid[0:shape[0]:step, 0:shape[1]:step], axis=2)
    if not len(at):
        return np.zeros(grid.shape[:2], bool)
    distance, _ = cKDTree(at, boxsize=shape).query(grid.reshape(-1, 2),
                                                   distance_upper_bound=reach + 1)
    return (distance <= reach).reshape(grid.shape[:2])


def photo_ends(photo: np.ndarray, joints: Joints) -> np.ndarray:
    """The photo's own dead ends (bool, (h, w)): ``joints``' skeleton of ``photo`` (its luma),
    read mirrored at the edges (as ``texsynth.metrics.dead_end_ratio`` reads a photo), its ends
    placed at full resolution.

    Examples
    --------
    >>> i, j = np.mgrid[:64, :64]
    >>> wall = np.where((i % 16 < 3) | ((j + 16 * (i // 16 % 2)) % 32 < 3), 0.2, 0.7)
    >>> joints = Joints.fit(wall, 1.5)
    >>> int(photo_ends(wall, joints).sum())  # every joint meets another (or the edge)
    0
    >>> wall[30:37, 40:48] = 0.7  # a bed joint cut through: two stubs
    >>> int(photo_ends(wall, joints).sum()) > 0
    True
    """
    _, end = joints.skeleton(photo, wrap=False)
    f = joints.f
    r, c = np.nonzero(end)
    out = np.zeros(photo.shape[:2], bool)
    out[np.minimum(r * f + f // 2, len(out) - 1), np.minimum(c * f + f // 2, out.shape[1] - 1)] = 1
    return out


def _near(mask: np.ndarray, at: np.ndarray, d: float) -> np.ndarray:
    """Whether each point ``at`` (N, 2) lies within ``d`` of ``mask`` on the torus."""
    m = int(np.ceil(d))
    dy, dx = np.mgrid[-m:m + 1, -m:m + 1]
    disk = np.hypot(dy, dx) <= d
    rows = (at[:, 0, None] + dy[disk]) % mask.shape[0]
    cols = (at[:, 1, None] + dx[disk]) % mask.shape[1]
    return mask[rows, cols].any(axis=1)

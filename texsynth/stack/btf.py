"""BTF alignment plane: the height that makes a stack of views smoothest.

Neubeck et al. 2004, section 2.2. The views of a rough planar sample,
rectified to the frontal view for a reference plane (height 0), show a surface point at height h
displaced by h (d_x, d_y) / d_z under parallel projection (d the unit viewing direction): the same
pixel drifts between views. Re-rectifying for a plane at height h0 removes the drift of the
points at that height. The paper picks the plane minimising the average Euclidean distance
between the intensities of neighbouring views sharing the same lighting.

Conventions: ``view_dirs`` (V, 3) point from the surface towards the camera in image axes
(x = column to the right, y = row downwards, z = out of the surface); heights are in pixels,
positive towards the viewer.

Deviations, one line each:
- "neighbouring camera positions" (the four neighbours on the paper's turntable grid) are each
  view's ``neighbours`` nearest views by angle with the same lighting label;
- views are shifted with linear interpolation; pixels that any shift moves in from outside
  the image (a border as wide as the largest shift) are left out of the average.
"""

from __future__ import annotations

import numpy as np
from scipy.ndimage import shift as nd_shift

from .. import validation

__all__ = ["align", "realign", "view_shifts"]


def view_shifts(view_dirs, height: float) -> np.ndarray:
    """(V, 2) (row, col) shifts that re-rectify each view for the plane at ``height``."""
    d = np.asarray(view_dirs, np.float64)
    if d.ndim != 2 or d.shape[1] != 3:
        raise ValueError(f"view_dirs must be (V, 3) directions, got shape {d.shape}")
    if (d[:, 2] <= 0).any():
        raise ValueError("every viewing direction must look at the surface from above (d_z > 0)")
    return height * d[:, [1, 0]] / d[:, 2:3]


def realign(stack, view_dirs, height: float) -> np.ndarray:
    """The stack re-rectified for the plane at ``height``: view v(x) = stack_v(x - h d_xy / d_z)."""
    a = _check(stack, view_dirs)
    out = np.empty_like(a)
    for v, (dy, dx) in enumerate(view_shifts(view_dirs, height)):
        out[v] = nd_shift(a[v], (dy, dx, 0), order=1, mode="nearest")
    return out


def align(stack, view_dirs, heights, lights=None, neighbours: int = 4):
    """Choose the alignment plane height (section 2.2).

    Parameters
    ----------
    stack : (V, H, W) or (V, H, W, C) views rectified for height 0.
    view_dirs : (V, 3) unit viewing directions (see the module notes).
    heights : candidate plane heights, in pixels.
    lights : (V,) lighting labels; only views with the same label are compared (default: one).
    neighbours : how many nearest views (by angle) each view is compared with.

    Returns
    -------
    (best_height, smoothness, realigned): the height with the smallest average distance between
    neighbouring views, the (len(heights),) curve of those averages, and the stack realigned for
    the best height.
    """
    a = _check(stack, view_dirs)
    heights = np.asarray(heights, np.float64).ravel()
    if len(heights) == 0:
        raise ValueError("give at least one candidate height")
    v_count, h, w = a.shape[:3]
    lights = np.zeros(v_count, int) if lights is None else np.asarray(lights)
    if lights.shape != (v_count,):
        raise ValueError(f"lights must give one label per view ({v_count}), got {lights.shape}")
    pairs = _neighbour_pairs(np.asarray(view_dirs, np.float64), lights, neighbours)
    if not pairs:
        raise ValueError("no two views share a lighting label: nothing to compare")
    margin = int(np.ceil(max(np.abs(view_shifts(view_dirs, hh)).max() for hh in heights)))
    if 2 * margin >= min(h, w):
        raise ValueError(f"the candidate heights shift views by up to {margin} pixels, too much "
                         f"for {w} x {h} images")
    inner = (slice(margin, h - margin or None), slice(margin, w - margin or None))
    smoothness = np.empty(len(heights))
    for n, hh in enumerate(heights):
        r = realign(a, view_dirs, hh)
        smoothness[n] = np.mean([np.sqrt(((r[i][inner] - r[j][inner]) ** 2).sum(axis=2)).mean()
                                 for i, j in pairs])
    best = float(heights[int(np.argmin(smoothness))])
    return best, smoothness, realign(a, view_dirs, best)


def _check(stack, view_dirs) -> np.ndarray:
    a = np.asarray(stack)
    if a.ndim not in (3, 4) or len(a) == 0:
        raise ValueError(f"stack must be (V, H, W) or (V, H, W, C), got shape {a.shape}")
    a = np.stack([validation.image(view, what=f"view {v}", min_side=1, channels=None)
                  for v, view in enumerate(a)])
    d = np.asarray(view_dirs)
    if d.shape != (len(a), 3):
        raise ValueError(f"view_dirs must be ({len(a)}, 3), one direction per view; "
                         f"got {d.shape}")
    return a


def _neighbour_pairs(dirs, lights, k) -> list[tuple[int, int]]:
    """Unordered pairs (i, j): j among the k views nearest i by angle, same lighting."""
    unit = dirs / np.linalg.norm(dirs, axis=1, keepdims=True)
    angle = np.arccos(np.clip(unit @ unit.T, -1.0, 1.0))
    pairs = set()
    for i in range(len(dirs)):
        same = np.flatnonzero((lights == lights[i]) & (np.arange(len(dirs)) != i))
        for j in same[np.argsort(angle[i, same], kind="stable")][:k]:
            pairs.add((min(i, j), max(i, j)))
    return sorted(pairs)

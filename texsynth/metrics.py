"""Quality measures a user would notice, usable on any image array.

``seam_ratio`` answers "does it tile?": the mean absolute jump across the wrap-around edges
divided by the mean absolute difference between interior neighbours, on luminance. A periodic
texture scores about 1; a photograph that does not tile scores 2 to 20.
"""

from __future__ import annotations

import numpy as np

__all__ = ["luminance", "seam_ratio"]


def luminance(image: np.ndarray) -> np.ndarray:
    """Rec. 709 luma of an (H, W, C) or (H, W) array; alpha is ignored; float64."""
    a = np.asarray(image, dtype=np.float64)
    if a.ndim == 2:
        return a
    if a.shape[2] >= 3:
        return a[:, :, :3] @ np.array([0.2126, 0.7152, 0.0722])
    return a[:, :, 0]


def seam_ratio(image: np.ndarray) -> float:
    """Mean |jump| across the wrap edges over mean |interior neighbour difference| (luminance)."""
    y = luminance(image)
    if min(y.shape) < 3:
        raise ValueError(f"seam_ratio needs at least 3 x 3 pixels, got {y.shape[1]} x {y.shape[0]}")
    seam = np.concatenate([np.abs(y[:, 0] - y[:, -1]), np.abs(y[0, :] - y[-1, :])]).mean()
    interior = np.concatenate([np.abs(np.diff(y, axis=1)).ravel(),
                               np.abs(np.diff(y, axis=0)).ravel()]).mean()
    if interior == 0:
        return 1.0 if seam == 0 else float("inf")
    return float(seam / interior)

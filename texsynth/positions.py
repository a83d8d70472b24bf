"""Position maps: where in the exemplar each output pixel was copied from.

A method that copies whole exemplar pixels (``efros_leung``, ``multiscale_mrf``) can return, with
its image, an int32 (height, width, 2) array of (row, col) exemplar coordinates (see
``texsynth.synthesize_positions``). Re-applying that map to another image of the exemplar's size
(a normal, roughness or height map of the same material) makes it follow the same synthesis, as
Embark's texture-synthesis does with its saved pixel mapping.
"""

from __future__ import annotations

import numpy as np

__all__ = ["apply_positions", "positions_image"]


def _check(positions) -> np.ndarray:
    p = np.asarray(positions)
    if p.ndim != 3 or p.shape[2] != 2 or p.dtype.kind not in "iu":
        raise ValueError(f"positions must be an integer array (height, width, 2), got "
                         f"{p.dtype} {p.shape}")
    if p.size and p.min() < 0:
        raise ValueError("positions hold negative coordinates")
    return p


def apply_positions(positions, image) -> np.ndarray:
    """``image[positions[..., 0], positions[..., 1]]``: ``image`` resampled by a position map.

    ``image`` is (h, w) or (h, w, C) with the exemplar's size, any dtype (kept, so 16-bit or
    float maps stay exact). Applied to the exemplar the synthesis ran on, it gives back the
    synthesized image bit for bit.
    """
    p = _check(positions)
    a = np.asarray(image)
    if a.ndim not in (2, 3):
        raise ValueError(f"image must be (H, W) or (H, W, C), got shape {a.shape}")
    if p.size:
        need = p.reshape(-1, 2).max(axis=0) + 1
        if need[0] > a.shape[0] or need[1] > a.shape[1]:
            raise ValueError(f"the position map points up to {need[1]} x {need[0]} pixels but "
                             f"the image is {a.shape[1]} x {a.shape[0]}; give an image of the "
                             "exemplar's size")
    return a[p[:, :, 0], p[:, :, 1]]


def positions_image(positions, exemplar_shape) -> np.ndarray:
    """A picture of a position map, float32 (height, width, 3): x (column) -> red,
    y (row) -> green, each 0 to 1 across the exemplar; blue 0."""
    p = _check(positions)
    h, w = exemplar_shape[:2]
    out = np.zeros(p.shape[:2] + (3,), np.float32)
    out[:, :, 0] = p[:, :, 1] / max(w - 1, 1)
    out[:, :, 1] = p[:, :, 0] / max(h - 1, 1)
    return out

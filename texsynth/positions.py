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

    Parameters
    ----------
    positions : integer array (height, width, 2)
        (row, col) into the exemplar per output pixel, as :func:`texsynth.synthesize_positions`
        returns.
    image : array (h, w) or (h, w, C)
        An image of the exemplar's size (the exemplar, or another map of its material), any
        dtype.

    Returns
    -------
    numpy.ndarray
        (height, width) or (height, width, C) of ``image``'s dtype (kept, so 16-bit or float
        maps stay exact). Applied to the exemplar the synthesis ran on, it gives back the
        synthesized image bit for bit.

    References
    ----------
    Neubeck, Zalesny & Van Gool 2004, section 2.3 (the stack's columns copied through the
    support's positions: ``synthesize_stack(mode="column")``).

    Examples
    --------
    >>> import numpy as np
    >>> image = np.arange(6).reshape(2, 3)
    >>> apply_positions(np.array([[[0, 2], [1, 0]]], np.int32), image)
    array([[2, 3]])
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
    """A picture of a position map: x (column) -> red, y (row) -> green, each 0 to 1 across the
    exemplar; blue 0.

    Parameters
    ----------
    positions : integer array (height, width, 2)
        (row, col) into the exemplar per output pixel.
    exemplar_shape : tuple
        The exemplar's shape (h, w, ...): the coordinates' range.

    Returns
    -------
    numpy.ndarray
        float32 (height, width, 3).

    References
    ----------
    Neubeck, Zalesny & Van Gool 2004, section 3.1 (the position map ``S`` it pictures).

    Examples
    --------
    >>> import numpy as np
    >>> positions_image(np.array([[[0, 0], [3, 7]]], np.int32), (4, 8, 3))
    array([[[0., 0., 0.],
            [1., 1., 0.]]], dtype=float32)
    """
    p = _check(positions)
    h, w = exemplar_shape[:2]
    out = np.zeros(p.shape[:2] + (3,), np.float32)
    out[:, :, 0] = p[:, :, 1] / max(w - 1, 1)
    out[:, :, 1] = p[:, :, 0] / max(h - 1, 1)
    return out

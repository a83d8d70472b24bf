"""How much an image of a surface still repeats: its luminance's correlation at the tile period."""

from __future__ import annotations

import numpy as np

from ..metrics import luminance

__all__ = ["period_correlation"]


def period_correlation(image, period: int) -> float:
    """The luminance's correlation coefficient between the image and itself shifted by
    ``period`` pixels, the mean of the horizontal and vertical shifts: about 1 when a texture
    repeats every ``period`` pixels, about 0 when nothing does.

    Examples
    --------
    >>> tile = np.random.default_rng(0).random((16, 16))
    >>> round(period_correlation(np.tile(tile, (4, 4)), 16), 3)
    1.0
    >>> bool(abs(period_correlation(np.random.default_rng(1).random((64, 64)), 16)) < 0.1)
    True
    """
    y = luminance(image)
    p = int(period)
    if not 0 < p < min(y.shape) - 1:
        raise ValueError(f"period must be from 1 to {min(y.shape) - 2} pixels for a "
                         f"{y.shape[1]} x {y.shape[0]} image, got {period!r}")
    pairs = ((y[:, :-p], y[:, p:]), (y[:-p], y[p:]))
    return float(np.mean([np.corrcoef(a.ravel(), b.ravel())[0, 1] for a, b in pairs]))

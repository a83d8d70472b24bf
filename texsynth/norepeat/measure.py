"""How much an image of a surface still repeats, and whether it kept its direction.

- :func:`period_correlation`: the luminance's correlation at a known tile period;
- ``repetition_peak`` (``texsynth.metrics``): the autocorrelation's largest peak at EVERY shift
  of 24 px or more: what the eye sees, a repeat at the tile's, a cell's or any other shift
  (issue 41: a Tile Set repeated at its cell, not at the photo's period where it was measured);
- ``anisotropy`` (``texsynth.metrics``): the structure tensor's, to compare a render with the
  plain one's (a photo's courses and layers turned every way fall towards 0).
"""

from __future__ import annotations

import numpy as np

from ..metrics import anisotropy, luminance, repetition_peak

__all__ = ["period_correlation", "repetition_peak", "anisotropy"]


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

"""A photo brought to another size by area averaging: the texel scale of ``--in-size``.

A 12 MP photo synthesized at 2048 pixels makes each texel as large as the photo's: reducing the
photo first sets how large its features come out. Each output pixel is the mean of the input
area it covers (the box filter of OpenCV's ``INTER_AREA`` and Pillow's ``reduce``), applied
along the rows, then the columns, as sparse matrices of the overlaps: every input pixel weighs
the same in total, so the mean is kept exactly, and a reduction by a whole factor k is the
mean over k x k blocks. Deviations, one line each: values are averaged as they are (sRGB-encoded
values too, as those libraries do); an enlargement repeats pixels, blending the two at each
boundary (the box filter's reading of a larger size: ``--in-size`` is for reducing).
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from .. import validation

__all__ = ["resample"]


def resample(image, width: int, height: int) -> np.ndarray:
    """``image`` (H, W) or (H, W, C), any C, as float32 (``height``, ``width``, C): each pixel
    the mean of the area of ``image`` it covers.

    Examples
    --------
    >>> a = np.arange(16, dtype=np.float32).reshape(4, 4)
    >>> resample(a, 2, 2)[:, :, 0].tolist()  # 2 x 2 block means
    [[2.5, 4.5], [10.5, 12.5]]
    >>> b = resample(np.random.default_rng(0).random((300, 400, 3)), 160, 120)
    >>> b.shape, b.dtype
    ((120, 160, 3), dtype('float32'))
    """
    a = validation.image(image, what="image", min_side=1, channels=None)
    width, height = validation.size(width, height)
    h, w, c = a.shape
    if (h, w) == (height, width):
        return a
    rows = _overlaps(h, height) @ a.reshape(h, w * c)  # (height, W C)
    across = np.ascontiguousarray(rows.reshape(height, w, c).transpose(1, 0, 2))
    cols = _overlaps(w, width) @ across.reshape(w, height * c)  # (width, height C)
    return np.ascontiguousarray(cols.reshape(width, height, c).transpose(1, 0, 2), np.float32)


def _overlaps(n: int, m: int) -> sp.csr_array:
    """(m, n) weights: output pixel i covers [i s, (i + 1) s) of the input, s = n / m; its
    weight for input pixel j is their overlap over s (each row sums to 1, each column to m / n)."""
    s = n / m
    lo = np.arange(m) * s
    j = np.floor(lo).astype(np.int64)[:, None] + np.arange(int(np.ceil(s)) + 1)
    overlap = np.minimum(j + 1, lo[:, None] + s) - np.maximum(j, lo[:, None])
    keep = (overlap > 1e-9 * s) & (j < n)
    i = np.broadcast_to(np.arange(m)[:, None], j.shape)[keep]
    return sp.csr_array(((overlap[keep] / s).astype(np.float32), (i, j[keep])), shape=(m, n))

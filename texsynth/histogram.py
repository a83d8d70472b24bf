"""1-D histogram matching by cumulative histograms (paper 000, section 11.3.2, Algorithm 11.3).

``v_new = ic_1(c_2(v))``: a value of the image being adjusted is sent through its own cumulative
histogram c_2 and then through the inverse cumulative histogram ic_1 of the target. Arrays of
different sizes match through quantiles: ic_1(p) interpolates the target's sorted values.

The target side (the exemplar's band) never changes across Heeger-Bergen iterations, so
:class:`TargetHistogram` sorts it once. The source side changes every iteration; instead of ranking
it with a full sort, :func:`match` builds c_2 from a ``bins``-bin histogram (one O(N) pass of
``bincount``), evaluates the transfer function ``ic_1(c_2(.))`` exactly at the bin edges and
interpolates it linearly inside each bin. At the edges this is the exact rank mapping; inside a
bin the error is bounded by the target's quantile step across that bin (measured in
tests/test_histogram.py against the sort-based ``exact=True`` path).
"""

from __future__ import annotations

import numpy as np

__all__ = ["TargetHistogram", "match"]

#: Bins of the source's cumulative histogram in the fast path.
BINS = 4096


class TargetHistogram:
    """The inverse cumulative histogram ic_1 of a target array, sorted once."""

    def __init__(self, values: np.ndarray):
        self.sorted = np.sort(np.asarray(values, dtype=np.float32), axis=None)
        if self.sorted.size == 0:
            raise ValueError("cannot match to an empty histogram")
        self._index = np.arange(self.sorted.size, dtype=np.float64)

    def quantile(self, p: np.ndarray) -> np.ndarray:
        """ic_1(p) for p in [0, 1]: linear interpolation of the sorted values."""
        return np.interp(np.asarray(p, np.float64) * (self.sorted.size - 1), self._index,
                         self.sorted).astype(np.float32)


def match(source: np.ndarray, target: TargetHistogram, exact: bool = False,
          bins: int = BINS) -> np.ndarray:
    """``source`` remapped monotonically so that its histogram is ``target``'s.

    ``exact=True`` ranks the source with a sort (rank r of n goes to ic_1(r / (n - 1))), the
    textbook way; the default uses the O(N) cumulative histogram described in the module notes.
    """
    source = np.asarray(source, dtype=np.float32)
    flat = source.ravel()
    n = flat.size
    if exact:
        out = np.empty_like(flat)
        order = np.argsort(flat, kind="stable")
        out[order] = target.quantile(np.linspace(0.0, 1.0, n) if n > 1 else np.array([0.5]))
        return out.reshape(source.shape)
    lo, hi = float(flat.min()), float(flat.max())
    if hi <= lo:
        return np.full_like(source, target.quantile(0.5))
    scale = np.float32(bins / (hi - lo))
    t = np.subtract(flat, np.float32(lo))
    t *= scale
    idx = t.astype(np.int32)
    np.minimum(idx, bins - 1, out=idx)
    t -= idx
    cdf = np.zeros(bins + 1, np.float64)
    np.cumsum(np.bincount(idx, minlength=bins), out=cdf[1:])
    # rank of the value at each bin edge in the exact mapping: r = (count below) - 1/2 shifted to
    # the sample convention r / (n - 1) used by ic_1
    edges = target.quantile(np.clip((cdf - 0.5) / max(n - 1, 1), 0.0, 1.0))
    base = edges[:-1]
    step = edges[1:] - base
    out = np.take(base, idx)
    t *= np.take(step, idx)
    out += t
    return out.reshape(source.shape)

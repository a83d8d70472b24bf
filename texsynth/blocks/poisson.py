"""Gradient-domain correction of a quilted cross across the wrap (Pérez, Gangnet & Blake 2003).

Pérez et al. 2003, "Poisson image editing", 2-3: inside a region Omega the image is replaced by
the function f whose gradient is closest to a guidance field v, with f equal to the image f* on
the boundary dOmega: their discrete Poisson equation (section 2)

    |N_p| f_p - sum_{q in N_p cap Omega} f_q = sum_{q in N_p cap dOmega} f*_q + sum_q v_pq.

Here Omega is the band of ``b`` pixels across each wrap line of a torus (a cross: a horizontal
strip around the whole width, a vertical one around the whole height), f* the photo kept
outside it, and v_pq the gradient of the photo pieces pasted at p and q, taken piece by piece
(:func:`guidance`): where p and q come from one piece it is their own difference, across a cut
one of the two pieces' own gradients there (the one nearer what is shown), so the cut
contributes no step of level; the wrap lies inside pieces, so the solution tiles.

Each strip alone is a rectangle, periodic along its length and fixed at its two long edges:
the real FFT along the strip leaves one tridiagonal system across it per frequency, solved
exactly. The cross is solved by Schwarz's alternating method
(H. A. Schwarz 1870; Smith, Bjørstad & Gropp 1996, 1.1): the strips in turn, each fixed at its
edges by the other's current values where they cross, until a sweep changes no pixel by more
than ``TOLERANCE`` of the photo's range.

Deviations, one line each:
- the region is the whole cross, not only the pasted pieces: the photo's own pixels in the band
  take the correction too, so it spreads over the band's width and is never a step at a cut;
- each sweep solves for the correction of the current values (zero at the strip's edges), so
  the solve's rounding scales with what is still to correct, not with the values.
"""

from __future__ import annotations

import numpy as np
import scipy.fft as sfft

from .parallel import threads

__all__ = ["guidance", "solve_strip", "correct_cross"]

#: A sweep of the alternating method that changes no pixel by more than this share of the
#: photo's range (per channel, the largest) ends it; a quarter of an 8-bit step.
TOLERANCE = 2.0 ** -10
#: Most sweeps (the strips' crossing is square: each sweep cuts the error there by about 3).
MAX_SWEEPS = 12


def guidance(source: np.ndarray, p: np.ndarray, q: np.ndarray, step,
             readable: np.ndarray | None = None, joint: bool = False) -> np.ndarray:
    """v_pq for output pixels p and their neighbours q = p + ``step``, which show the ``source``
    pixels at positions ``p`` and ``q`` (int, (..., 2) (row, col)). Pixels of one piece (q =
    p + step in the source) get their own difference. Across a cut, each piece offers its own
    gradient there, p's source[p + step] - source[p] and q's source[q] - source[q - step]
    (each only where it lies inside the source); of these, the one nearer the difference
    actually shown, source[q] - source[p] (per channel; 0 if neither is inside): an edge shown
    on the cut is kept (a joint beside it), an edge of a pixel the cut left out is not (a
    ledge beyond it), and the step between the pieces' levels is no piece's gradient.
    ``readable`` (bool (H, W), optional): the source pixels whose values may be read; a
    candidate that reads another (a blemish under a heal's mask) is not offered. ``joint``: the
    nearer over the sum of the channels, one candidate for all (no colour mixed from two).

    Examples
    --------
    >>> source = np.arange(12, dtype=np.float32).reshape(3, 4, 1)  # rows step 4, columns 1
    >>> source[1, 3] = 9.0  # an edge before (1, 3)
    >>> p = np.array([[0, 0], [0, 2], [2, 1], [1, 3]])  # one piece; a cut twice; p at the end
    >>> q = np.array([[0, 1], [1, 3], [0, 3], [0, 0]])
    >>> guidance(source, p, q, (0, 1))[:, 0].tolist()
    [1.0, 3.0, 1.0, 0.0]
    >>> readable = np.ones((3, 4), bool); readable[1, 2] = False  # (1, 2) under a mask
    >>> guidance(source, p, q, (0, 1), readable)[:, 0].tolist()  # q's own gradient read it
    [1.0, 1.0, 1.0, 0.0]
    >>> two = np.float32([[[0, 0], [1, 3], [3, 4]]])  # (0, 0) beside (0, 2): channels disagree
    >>> at, beside = np.array([[0, 0]]), np.array([[0, 2]])
    >>> [guidance(two, at, beside, (0, 1), joint=j).tolist() for j in (False, True)]
    [[[2.0, 3.0]], [[1.0, 3.0]]]
    """
    h, w = source.shape[:2]
    dy, dx = step
    offset = dy * w + dx
    at_p = p[..., 0].astype(np.intp) * w + p[..., 1]
    at_q = q[..., 0].astype(np.intp) * w + q[..., 1]
    flat = source.reshape(h * w, -1)
    v = np.take(flat, at_q, axis=0)
    v -= np.take(flat, at_p, axis=0)  # the difference shown
    # One piece where q is p's next pixel in the source (and the source's lines do not wrap).
    cut = (at_q != at_p + offset) | (p[..., 1] + dx >= w)
    p, q, at_p, at_q, shown = p[cut], q[cut], at_p[cut], at_q[cut], v[cut]
    has_after = (p[:, 0] + dy < h) & (p[:, 1] + dx < w)
    has_before = (q[:, 0] >= dy) & (q[:, 1] >= dx)
    if readable is not None:
        ok = np.asarray(readable, bool).reshape(-1)
        has_after &= ok[np.minimum(at_p + offset, h * w - 1)]
        has_before &= ok[np.maximum(at_q - offset, 0)]
    v_p = np.take(flat, np.minimum(at_p + offset, h * w - 1), axis=0) - np.take(flat, at_p, axis=0)
    v_q = np.take(flat, at_q, axis=0) - np.take(flat, np.maximum(at_q - offset, 0), axis=0)
    # A candidate outside the source is never the nearer (one inside is taken; else 0).
    far_p = np.where(has_after[:, None], np.abs(v_p - shown), np.inf)
    far_q = np.where(has_before[:, None], np.abs(v_q - shown), np.inf)
    if joint:  # one candidate for every channel: its channels never come from two pieces
        far_p, far_q = far_p.sum(1, keepdims=True), far_q.sum(1, keepdims=True)
    chosen = np.where(far_p <= far_q, v_p, v_q)
    chosen[~(has_after | has_before)] = 0
    v[cut] = chosen
    return v


def _divergence(source, at, across, along, kept_step) -> np.ndarray:
    """div v on the strip's pixels, (b, L, C): ``at`` (b + 2, L, 2) the positions of the strip
    and its edge rows, ``across`` and ``along`` the source steps of the strip's two axes;
    ``kept_step`` (2, C) bool: in those channels, across the first (last) edge v is the
    difference shown."""
    looped = np.concatenate([at, at[:, :1]], axis=1)  # the last pixel's neighbour along: first
    v_across = guidance(source, at[:-1], at[1:], across)  # (b + 1, L, C)
    for k, (i, j) in enumerate(((0, 1), (-2, -1))):
        shown = source[at[j, :, 0], at[j, :, 1]] - source[at[i, :, 0], at[i, :, 1]]
        v_across[i] = np.where(kept_step[k], shown, v_across[i])
    v_along = guidance(source, looped[1:-1, :-1], looped[1:-1, 1:], along)  # (b, L, C)
    return v_across[1:] - v_across[:-1] + v_along - np.roll(v_along, 1, axis=1)


def solve_strip(first: np.ndarray, last: np.ndarray, div: np.ndarray) -> np.ndarray:
    """f on a strip (b, L, C), periodic along its length L and fixed to the rows ``first``
    before it and ``last`` after it (L, C), with Laplacian ``div`` (Pérez et al. 2, the
    5-point stencil): the real FFT along the strip makes it one tridiagonal system across it
    per frequency, solved exactly (Thomas' algorithm, all frequencies at once), in float64.

    Examples
    --------
    >>> div = np.zeros((5, 8, 1), np.float32)
    >>> f = solve_strip(np.zeros((8, 1)), np.full((8, 1), 6.0), div)  # harmonic: a ramp
    >>> np.round(f[:, 0, 0], 4).tolist()
    [1.0, 2.0, 3.0, 4.0, 5.0]
    """
    b, length = div.shape[:2]
    rhs = div.astype(np.float64)
    rhs[0] -= first
    rhs[-1] -= last
    r = sfft.rfft(rhs, axis=1, workers=threads())  # (b, K, C)
    # Per frequency k: f_{i-1} + f_{i+1} + d_k f_i = r_i, d_k = 2 cos(2 pi k / L) - 4.
    d = 2 * np.cos(2 * np.pi * np.arange(r.shape[1]) / length) - 4
    c = np.empty((b, len(d)))  # Thomas' eliminated super-diagonal, c_i = 1 / (d - c_{i-1})
    c[0] = 1 / d
    for i in range(1, b):
        c[i] = 1 / (d - c[i - 1])
    c = c[:, :, None]
    r[0] *= c[0]
    for i in range(1, b):
        r[i] = (r[i] - r[i - 1]) * c[i]
    for i in range(b - 2, -1, -1):
        r[i] -= c[i] * r[i + 1]
    return sfft.irfft(r, n=length, axis=1, workers=threads())


def correct_cross(out: np.ndarray, source: np.ndarray, positions: np.ndarray, b: int,
                  span: float, kept_steps=None, tick=None) -> int:
    """Pérez et al. 2003, 3, on the cross of ``b`` pixels across the wrap of ``out`` (H, W, C),
    in place: ``out`` outside the cross is f*, ``positions`` (H, W, 2) say which ``source``
    pixel each output pixel shows (the guidance). ``span``: the photo's range, for
    ``TOLERANCE``. ``kept_steps`` (2, 2, C) bool, default none: for the horizontal arm's edge
    before it and after it, and the vertical arm's, in which channels the step shown across
    it is kept (a line of the photo beyond the band unlike the rest of it, such as a ledge,
    that the band should not fade into). ``tick(solves)``, if given, is called after each
    strip's solve (where the caller may cancel). Returns the sweeps made."""
    if kept_steps is None:
        kept_steps = np.zeros((2, 2, out.shape[2]), bool)
    h, w = out.shape[:2]
    rows = (np.arange(-1, b + 1) - b // 2) % h  # the horizontal strip and its edge rows
    cols = (np.arange(-1, b + 1) - b // 2) % w
    div_h = _divergence(source, positions[rows], (1, 0), (0, 1), kept_steps[0])
    div_v = _divergence(source, positions[:, cols].transpose(1, 0, 2), (0, 1), (1, 0),
                        kept_steps[1])
    sweeps = 0
    for sweeps in range(1, MAX_SWEEPS + 1):
        change = 0.0
        for index, div, across in ((rows, div_h, False), (cols, div_v, True)):
            strip = (out[:, index].transpose(1, 0, 2) if across else out[index]).astype(
                np.float64)
            # The correction delta of the strip's inside: zero at its edges, its Laplacian the
            # residual of the discrete Poisson equation for the current values.
            residual = div - _laplacian(strip)
            delta = solve_strip(np.zeros_like(strip[0]), np.zeros_like(strip[0]), residual)
            change = max(change, float(np.abs(delta).max()))
            f = (strip[1:-1] + delta).astype(np.float32)
            if across:
                out[:, index[1:-1]] = f.transpose(1, 0, 2)
            else:
                out[index[1:-1]] = f
            if tick is not None:
                tick(2 * sweeps - 1 + across)
        if sweeps > 1 and change <= TOLERANCE * span:
            break
    return sweeps


def _laplacian(strip: np.ndarray) -> np.ndarray:
    """The 5-point Laplacian of a strip's inside, (b, L, C), from the strip with its edge rows
    (b + 2, L, C), periodic along its length."""
    inside = strip[1:-1]
    return (strip[:-2] + strip[2:] + np.roll(inside, 1, axis=1) + np.roll(inside, -1, axis=1)
            - 4 * inside)

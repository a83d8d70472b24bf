"""How many independent lines a family of segments holds: the noise of its vanishing point.

A joint found as segments (:func:`~texsynth.plane.lines.segments`) is often broken into several
pieces along one line, and its own irregularity (a mortar joint that wanders, a row of setts) is
shared by every piece: the pieces' direction errors are not independent, and a vanishing point
fitted to them is less certain than their number says. The delete-a-group jackknife (Efron &
Tibshirani 1993, ch. 11; the groups are the lines, as the clusters of a cluster sample, Kish
1965, sec. 5.4) measures the vanishing point's variance with the lines as the independent
units; its ratio to the variance the segments' own direction noise gives the same fit
(:attr:`~texsynth.plane.lines.Segments.noise`, the noise :class:`~texsynth.plane.lines.LineCost`
starts from) is the factor by which that noise variance is widened.
Deviations: the vanishing point is the weighted least-squares fit of
:func:`~texsynth.plane.lines.vanishing_point`, summarised by its direction from the image
centre and its inverse distance, and the larger of the two ratios is taken. The reference
variance is the noise model's (first-order perturbation of the fit), not the delete-one-segment
jackknife's (Kish's design effect): the families come with collinear pieces joined
(:func:`~texsynth.plane.lines.photo_families`), a line is then mostly one segment and the two
jackknives agree, while a joined joint's pixel noise (a fraction of a degree over its length)
is far below its wander; the ratio to the model carries both, the lines' clustering and their
scatter beyond a pixel's worth.
"""

from __future__ import annotations

import math

import numpy as np

from .lines import Segments, distinct_lines, weighted_lines

__all__ = ["line_inflation"]

_MIN_LINES = 3       # fewer lines leave the vanishing point's variance unmeasured
_UNMEASURED = 1e4    # ... and then its noise is widened by this much (its direction still counts)


def _summary_jacobian(x: np.ndarray) -> np.ndarray:
    """d(direction, inverse distance) / dx of a homogeneous vanishing point x (2 x 3)."""
    r2 = float(x[0] ** 2 + x[1] ** 2)
    r = math.sqrt(r2)
    return np.array([[-x[1] / r2, x[0] / r2, 0.0],
                     [-x[2] * x[0] / r ** 3, -x[2] * x[1] / r ** 3, 1.0 / r]])


def _model_variance(family: Segments, lines: np.ndarray, side: float) -> np.ndarray:
    """Variance of the vanishing point's (direction, inverse distance) that the segments'
    direction noise (:attr:`~texsynth.plane.lines.Segments.noise`, independent) gives the
    weighted least-squares fit: first-order perturbation of the least eigenvector of
    M = L^T L when each segment turns by its noise about its midpoint."""
    values, vectors = np.linalg.eigh(lines.T @ lines)
    x = vectors[:, 0]
    weight = np.sqrt(family.weight)[:, None]
    normal = lines / weight  # (n, c): unit normal n, offset c = -n . m / side
    turned = np.concatenate([-normal[:, 1:2], normal[:, 0:1]], axis=1)  # dn / d(angle)
    d_lines = np.concatenate([turned, -(turned * family.m / side).sum(axis=1, keepdims=True)],
                             axis=1) * weight
    # dM x for a turn of one segment: r (dr . x) + dr (r . x); dx by the other eigenvectors.
    dmx = lines * (d_lines @ x)[:, None] + d_lines * (lines @ x)[:, None]
    gap = np.maximum(values[1:] - values[0], 1e-30)
    dx = -(dmx @ vectors[:, 1:]) / gap @ vectors[:, 1:].T  # (N, 3)
    ds = dx @ _summary_jacobian(x).T  # (N, 2)
    return (ds * ds * (family.noise ** 2)[:, None]).sum(axis=0)


def line_inflation(family: Segments, side: float) -> float:
    """The factor (>= 1) by which the segments' direction-noise variance is widened so that the
    family's vanishing point is as uncertain as its independent lines make it.

    Parameters
    ----------
    family : Segments
        One family (:func:`~texsynth.plane.lines.families`), centred y-up analysis pixels.
    side : float
        The analysis image's longer side (pixels), the unit of the homogeneous fits.

    Returns
    -------
    float
        The delete-one-line jackknife variance of the vanishing point over the variance the
        segments' direction noise gives it (the larger over its direction and inverse
        distance), at least 1;
        ``_UNMEASURED`` when the family holds fewer than ``_MIN_LINES`` distinct lines.

    References
    ----------
    Efron & Tibshirani 1993, "An Introduction to the Bootstrap", ch. 11 (the jackknife); Kish
    1965, "Survey Sampling", sec. 5.4 (the design effect of a cluster sample).

    Examples
    --------
    Eight joints towards a vanishing point, each found as one segment 300 pixels long (a
    pixel's worth of direction noise: 0.0033 rad) that wanders 0.02 rad as a whole:

    >>> import numpy as np
    >>> from texsynth.plane.lines import Segments
    >>> rng = np.random.default_rng(0)
    >>> vp = np.array([0.0, 900.0])
    >>> m, d = [], []
    >>> for x in np.linspace(-120, 120, 8):
    ...     along = (vp - (x, 0.0)) / np.linalg.norm(vp - (x, 0.0))
    ...     a = np.arctan2(along[1], along[0]) + rng.normal(0.0, 0.02)
    ...     m.append((x, 0.0))
    ...     d.append((np.cos(a), np.sin(a)))
    >>> family = Segments(np.array(m), np.array(d), np.full(8, 300.0))
    >>> bool(line_inflation(family, 320.0) > 5.0)  # about (0.02 / 0.0033)^2 = 36
    True
    """
    lines = weighted_lines(family, side)
    vp = np.linalg.svd(lines, full_matrices=False)[2][-1]
    labels = distinct_lines(family, vp, side)
    if labels.max() + 1 < _MIN_LINES:
        return _UNMEASURED

    def summary(keep):  # direction from the centre and inverse distance (1 / side units)
        x = np.linalg.svd(lines[keep], full_matrices=False)[2][-1]
        x = x * np.sign(x @ vp)
        return np.array([math.atan2(x[1], x[0]), x[2] / np.linalg.norm(x[:2])])

    full = summary(np.ones(len(family), bool))

    def jackknife(groups):
        d = np.array([summary(groups != g) - full for g in np.unique(groups)])
        d[:, 0] = (d[:, 0] + math.pi) % (2 * math.pi) - math.pi
        return (len(d) - 1) / len(d) * (d * d).sum(axis=0)

    ratio = jackknife(labels) / np.maximum(_model_variance(family, lines, side), 1e-30)
    return float(max(1.0, ratio.max()))

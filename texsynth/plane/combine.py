"""Texture and line evidence in one estimate, with one uncertainty.

The unknowns are theta = (p, w): the gradient p (:mod:`~texsynth.plane.geometry`) and, when the
focal length is unknown, w = side / f (0: orthographic), so v = p w / side. The texture fit
enters as a Gaussian in theta with its own covariance (isotropy's bias on directional textures is
already in it); the line families enter through their chi-square (:class:`~.lines.LineCost`),
non-linear and possibly rank-deficient (one family: one constraint). Both are robust (Cauchy
beyond three sigmas): a texture fit the lines contradict, or a stray family, stops pulling
instead of dragging the estimate between them. The estimate minimises half their sum; its
covariance is the inverse Hessian there, so directions that neither cue fixes stay uncertain.

Two families are taken as orthogonal on the plane (Caprile & Torre 1990: bricks, tiles, weaves)
only when imposing it does not cost the fit of their parallelism and the texture more than
``_ORTHOGONAL_Z`` sigmas (:func:`orthogonality_chi2`); otherwise they fix the vanishing line
only (rhombic cells). Deviation: with the focal length unknown only the texture can refute
orthogonality, so a non-orthogonal pair whose texture fit is loose is still taken as orthogonal;
and where the texture's slant rests on isotropy that the texture breaks (bricks, tiles), it
refutes nothing: its slant along the vanishing line, 36 deg off on rendered bricks, had ruled out
the two families' focal length (Caprile & Torre: f^2 = -x1 . x2), right to 1 %.

The receding direction: the texture's Gaussian is made symmetric under p -> -p, so only the lines
(vanishing points on one side) or the texture fit's own test (homogeneity) can settle it.

Two deviations in the stated uncertainty: where the texture fit and the combined plane disagree
beyond their uncertainties, the covariance is widened by the Birge ratio (:func:`_birge`), as
a model error of one cue (a false or curved family) shows there and not in the lines' scatter;
and a fit that finds no perspective is refitted as orthographic (:func:`_orthographic`), where
the lines fix p only through their orthogonality.

A lens prior, with the focal length unknown: parallel lines cannot tell a frontal photo from a
slanted telephoto one (v = p w / side is 0 either way), but photos come from lenses of about
13-200 mm (35 mm equivalent; w = side / f in ``lens``), taken as log-uniform. When two
orthogonal families stay parallel with w held at the prior's longest lens (the weakest bound on
p = v side / w; any shorter lens bounds p more), and holding it costs the fit of the lines and
the texture no more than ``_ORTHOGONAL_Z`` sigmas, the lines have measured v near 0 and the
plane is p = f v for a focal length f drawn from the prior: the estimate is its mean, its
uncertainty the slant the longest lens would still hide (:func:`_frontal_under_prior`). An
orthographic render lies outside the prior: the orthogonal families of a slanted one are not
orthogonal in the image, and imposing the prior costs their fit, unless it is tilted along a
family (then only the texture can tell: the caller offers the prior on near-isotropic textures
only). Deviation: a rhombic pattern seen frontally fails the same test and stays a guess.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .lines import ORTHOGONAL_DEG, LineCost, Segments, robust, vanishing_point
from .search import hessian, minimize

__all__ = ["Combined", "combine", "orthogonality_chi2", "st_covariance"]

_W_PRIOR = 1.0   # sd of w = side / f when the texture fit is orthographic (no perspective seen)
_DIRECTION = 2.0  # the other receding direction must cost this much more (half chi-square)
_WEAK = 1e-3     # the texture's weight while the line noise is calibrated
_MAX_P = 12.0    # |p| = tan(slant) bound of the search (slant 85 deg)
_DETERMINED = 3.0  # deg: lines alone fixing the slant this well make the estimate line-based
_ORTHOGONAL_Z = 3.0  # sigmas: two families missing orthogonality by more only fix the horizon


@dataclass(frozen=True)
class Combined:
    """The combined fit in analysis-image pixels (as the texture fit's record)."""

    p: np.ndarray
    focal: float | None
    cov: np.ndarray       # (slant, tilt) covariance, degrees^2
    focal_sd: float | None  # relative
    ambiguous: bool
    determined: bool      # the lines alone fix p (the texture's assumptions are not needed)
    under_prior: bool = False  # frontal, measured under the lens prior (``lens``)


def _p_covariance(p: np.ndarray, cov_st: np.ndarray) -> np.ndarray:
    """Covariance of p from that of (slant, tilt) in degrees."""
    slant, tilt = math.atan(math.hypot(*p)), math.atan2(p[1], p[0])
    jac = np.array([[math.cos(tilt) / math.cos(slant) ** 2, -math.tan(slant) * math.sin(tilt)],
                    [math.sin(tilt) / math.cos(slant) ** 2, math.tan(slant) * math.cos(tilt)]])
    jac = jac * (math.pi / 180.0)
    return jac @ cov_st @ jac.T + np.eye(2) * 1e-8


def st_covariance(p: np.ndarray, cov_p: np.ndarray) -> np.ndarray:
    """Covariance of (slant, tilt) in degrees from that of p."""
    r = max(math.hypot(*p), 1e-6)
    slant = math.atan(r)
    jac = np.array([[p[0] / r * math.cos(slant) ** 2, p[1] / r * math.cos(slant) ** 2],
                    [-p[1] / r ** 2, p[0] / r ** 2]]) * (180.0 / math.pi)
    cov = jac @ cov_p @ jac.T
    cov[1, 1] = min(cov[1, 1], 180.0 ** 2)
    return cov


def _closed_form(found: list[Segments], side: float, focal: float | None) -> list[np.ndarray]:
    """Starts from two finite vanishing points x1, x2 (v . x = 1 for both; f^2 = -x1 . x2 when
    the focal length is unknown)."""
    if len(found) < 2:
        return []
    vps = [vanishing_point(f, side) for f in found]
    if any(x is None for x in vps):
        return []
    x = np.array(vps)
    if abs(np.linalg.det(x)) < 1e-9 * side * side:
        return []
    v = np.linalg.solve(x, np.ones(2))
    if focal is None:
        f2 = -float(x[0] @ x[1])
        if f2 <= 0:
            return []
        focal = math.sqrt(f2)
        return [np.array([*(v * focal), side / focal])]
    return [v * focal]


def orthogonality_chi2(free: float, orthogonal: float) -> float:
    """The likelihood-ratio statistic of orthogonality: twice what the best fit of the
    families' parallelism and the texture (half chi-squares ``free``) loses when the two families
    must also be orthogonal on the plane (``orthogonal``); chi-square with one degree of freedom
    when they are. It needs no linearisation: with the focal length unknown, a loose texture fit
    can put the free fit at a slant where the miss is large and its linear sd meaningless."""
    return 2.0 * max(orthogonal - free, 0.0)


def _frontal_under_prior(cost: LineCost, total, lens: tuple[float, float], free: float,
                         starts: list[np.ndarray], side: float) -> Combined | None:
    """Frontal under the lens prior, or None: p_max, the plane with w held at the longest lens
    ``lens[0]`` and the two families orthogonal, must cost ``total`` (half chi-square) at most
    ``_ORTHOGONAL_Z`` sigmas over the fit of their parallelism alone (``free``, w free down to
    0: orthographic). The lines then fix v = p_max w_least / side, with covariance C; over the
    prior the plane is p = (f / f_max) p_max, f log-uniform in [r f_max, f_max] (r = lens[0] /
    lens[1]). The estimate is its mean b p_max, b = E[f / f_max] = (1 - r) / ln(1 / r); its
    uncertainty the bound at the longest lens, sqrt(|p_max|^2 + tr C) (near p = 0 the normal's
    error is |dp| in radians, whatever its direction), not the RMS over the prior: a photo
    from beyond the prior (an orthographic render) must not be read frontal more confidently
    than the longest lens allows. The tilt is not claimed. Deviation: the families must also
    be orthogonal within ``_ORTHOGONAL_Z`` of its sigmas on the plane stated (b p_max under the
    measured v), unweighted by the robust loss (which caps a single term's cost near that
    bound): p_max can buy orthogonality with a slant the longest lens hides, the estimate
    cannot (an orthographic render at 35 deg passed the likelihood-ratio test once the lines'
    residuals were exact, :meth:`~.lines.LineCost.residuals`)."""
    cost.orthogonal = True
    w_least, w_most = lens

    def held(q):
        return total(np.array([q[0], q[1], w_least]))

    fit = minimize(held, [np.zeros(2), *starts], np.array([0.02, 0.02]))
    p_max = np.asarray(fit.x, dtype=np.float64)
    r = w_least / w_most
    b = (1.0 - r) / math.log(1.0 / r)
    _, miss = cost.residuals(b * p_max, p_max * w_least / side)  # at the plane stated
    if orthogonality_chi2(free, fit.fun) > _ORTHOGONAL_Z ** 2 \
            or abs(miss) > _ORTHOGONAL_Z * math.radians(ORTHOGONAL_DEG):
        cost.orthogonal = False
        return None
    cov_p = _inverse(hessian(held, fit.x, np.full(2, 1e-3)))
    s_slant = math.degrees(math.sqrt(float(p_max @ p_max) + float(np.trace(cov_p))))
    cov = np.diag([s_slant ** 2, 180.0 ** 2])
    return Combined(b * p_max, None, cov, None, True, True, True)


def _birge(p: np.ndarray, p_t: np.ndarray, cov_t: np.ndarray) -> float:
    """The factor (>= 1) by which the combined covariance is widened when the texture fit
    (p_t, its (slant, tilt) covariance ``cov_t``) and the combined plane p disagree beyond
    their stated uncertainty: the Birge ratio squared, chi^2 / dof (Birge 1932; the Particle
    Data Group's scale factor, Olive et al. 2014, sec. 5.2.2), with chi^2 the texture fit's
    Mahalanobis distance in p (either receding direction) and 2 degrees of freedom. Deviation:
    only the texture's term enters (the lines' own, at the plane they lead to, is near 0); a
    model error of either cue (a false or curved family, a texture's own anisotropy) shows as
    their disagreement, not as the lines' scatter, which the jackknife measures."""
    info = np.linalg.inv(_p_covariance(p_t, cov_t))
    chi2 = min(float(d @ info @ d) for d in (p - p_t, p + p_t))
    return max(1.0, chi2 / 2.0)


def _orthographic(cost: LineCost, prior, starts: list[np.ndarray]) -> Combined:
    """The plane refitted as the orthographic view the lines show (w = 0), and its covariance
    there. Under orthography parallel lines stay parallel whatever p is: the families fix p
    only through their orthogonality on the plane (when it holds, ``cost.orthogonal``), the
    texture fit (``prior``, in theta = (p, w)) the rest or nothing. Taken from the joint fit in
    (p, w) instead, p and w trade along the ridge v = p w / side = 0, the Hessian there is a
    saddle, and its curvatures' sizes stated a precise p no cue gave (an orthographic brick view
    at slant 66 stated 1.3 deg and was 24 off); the families' weighted mean directions also
    drift with p at steep slants, which pulled p to the search's bound."""
    def flat(q):
        theta = np.array([q[0], q[1], 0.0])
        value = prior(theta)
        if cost.orthogonal:
            _, miss = cost.residuals(theta[:2], np.zeros(2))
            value += 0.5 * float(robust((miss / math.radians(ORTHOGONAL_DEG)) ** 2))
        return value

    def bounded(q):
        return flat(q) + 1e4 * max(0.0, math.hypot(q[0], q[1]) - _MAX_P) ** 2

    fit = minimize(bounded, starts, np.array([0.05, 0.05]))
    p = np.asarray(fit.x, dtype=np.float64)
    cov = _inverse(hessian(flat, p, np.maximum(1e-3, 0.01 * np.abs(p))))
    return Combined(p, None, st_covariance(p, cov), None, True, False)


def _inverse(hess: np.ndarray) -> np.ndarray:
    """Covariance from a finite-difference Hessian: curvature taken by its size (the robust
    losses and the differences can make a small one negative), none means unbounded."""
    values, vectors = np.linalg.eigh(hess)
    return (vectors / np.maximum(np.abs(values), 1e-9)) @ vectors.T


def combine(cost: LineCost, side: float, p_t: np.ndarray, cov_t: np.ndarray,
            focal_t: float | None, focal_sd_t: float | None, ambiguous_t: bool,
            focal_given: float | None,
            lens: tuple[float, float] | None = None,
            texture_slant: bool = True, *, w_limit: float) -> Combined | None:
    """The plane that best explains the texture fit (p_t, cov_t, focal_t, focal_sd_t,
    ambiguous_t) and the line families in ``cost``; ``focal_given``: the known focal length
    (analysis pixels), else it is estimated with the rest, and ``lens`` (w = side / f at the
    longest and the shortest lens photos come from) allows a frontal reading under that prior
    when the lines show no perspective. ``texture_slant`` False: the texture fit's slant rests
    on an assumption the texture breaks (isotropy), and with the focal length unknown it cannot
    refute the two families' orthogonality. ``w_limit``: the largest w = side / f searched (the
    widest lens photos come from). None when the best fit lies on the search's bounds (that
    lens or a slant of 85)."""
    known = focal_given is not None
    cov_prior = _p_covariance(p_t, cov_t)
    theta_t = np.asarray(p_t, dtype=np.float64)
    if not known:
        w_t = 0.0 if focal_t is None else side / focal_t
        s_w = _W_PRIOR if focal_t is None else max(w_t * (focal_sd_t or 1.0), 0.05)
        theta_t = np.append(theta_t, w_t)
        cov_prior = np.block([[cov_prior, np.zeros((2, 1))], [np.zeros((1, 2)), s_w ** 2]])
    info = np.linalg.inv(cov_prior)
    mirror = theta_t * np.array([-1.0, -1.0, 1.0][:len(theta_t)])

    def split(theta):
        p = np.asarray(theta[:2])
        if known:
            return p, p / focal_given
        return p, p * max(theta[2], 0.0) / side

    def prior(theta):  # robust: a texture fit the lines contradict stops pulling
        d1, d2 = theta - theta_t, theta - mirror
        return 0.5 * float(robust(min(float(d1 @ info @ d1), float(d2 @ info @ d2))))

    def lines(theta):
        return 0.5 * cost(*split(theta))

    def bounded(theta):  # the search's bounds: |p| <= _MAX_P, 0 <= w <= w_limit
        bound = max(0.0, math.hypot(theta[0], theta[1]) - _MAX_P) ** 2
        if not known:
            bound += min(theta[2], 0.0) ** 2 + max(theta[2] - w_limit, 0.0) ** 2
        return lines(theta) + 1e4 * bound

    step = np.array([0.05, 0.05, 0.05][:len(theta_t)])
    starts = [theta_t, mirror, *_closed_form(cost.families, side, focal_given)]
    cost.orthogonal = False  # calibrated and tested on parallelism alone
    alone = minimize(lambda th: bounded(th) + _WEAK * prior(th), starts, step)
    cost.calibrate(*split(alone.x))

    def total(theta):  # the uncertainty is this one's curvature: a bound is no evidence
        return lines(theta) + prior(theta)

    starts.append(alone.x)
    best = minimize(lambda th: bounded(th) + prior(th), starts, step)
    if len(cost.families) == 2:
        cost.orthogonal = True
        square = minimize(lambda th: bounded(th) + prior(th), [*starts, best.x], step)
        if orthogonality_chi2(best.fun, square.fun) <= _ORTHOGONAL_Z ** 2 or (
                not known and not texture_slant):
            best = square
        else:
            cost.orthogonal = False
    axis = best.x[:2] / max(np.linalg.norm(best.x[:2]), 1e-12)
    other = minimize(lambda th: bounded(th) + prior(th)
                     + 1e4 * max(0.0, float(th[:2] @ axis)) ** 2,
                     [best.x * np.array([-1.0, -1.0, 1.0][:len(best.x)])], step)
    settled = other.fun - best.fun >= _DIRECTION
    chosen = best
    if not settled and not ambiguous_t and float(best.x[:2] @ p_t) < 0:
        chosen = other  # the lines cannot tell; the texture fit did
    theta = chosen.x

    def under_prior():  # the lines show no perspective: frontal under the lens prior?
        if lens is None or len(cost.families) != 2:
            return None
        cost.orthogonal = False
        free = minimize(lambda th: bounded(th) + prior(th), [*starts, best.x, theta], step)
        return _frontal_under_prior(cost, total, lens, free.fun, [theta[:2], p_t], side)

    if math.hypot(theta[0], theta[1]) > 0.98 * _MAX_P or (not known
                                                        and theta[2] > 0.98 * w_limit):
        # An impossible view, or (w near 0, p unbounded) parallel lines a frontal view explains.
        return None if known else under_prior()
    hess = hessian(total, theta, np.maximum(1e-3, 0.01 * np.abs(theta)))
    cov = _inverse(hess)
    p = np.asarray(theta[:2], dtype=np.float64)
    cov_st = st_covariance(p, cov[:2, :2])
    alone = _inverse(hessian(lines, theta, np.maximum(1e-3, 0.01 * np.abs(theta))))
    determined = st_covariance(p, alone[:2, :2])[0, 0] < _DETERMINED ** 2
    if known:
        return Combined(p, focal_given, cov_st * _birge(p, p_t, cov_t), None,
                        ambiguous_t and not settled, determined)
    w, s_w = float(theta[2]), math.sqrt(max(cov[2, 2], 0.0))
    if w <= 2.0 * s_w:  # no significant perspective: frontal under the lens prior, or orthographic
        return under_prior() or _orthographic(cost, prior, [p, theta_t[:2], mirror[:2]])
    return Combined(p, side / w, cov_st * _birge(p, p_t, cov_t), s_w / w,
                    ambiguous_t and not settled, determined)

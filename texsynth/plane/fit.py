"""The plane estimate: the search over inverse viewing transformations, its uncertainty, and the
result record.

Forsyth & Ponce, Computer Vision: A Modern Approach, sec. 11.4.1 ("Shape from texture for
planes"). A viewing transformation rotates the plane by the tilt and contracts it by cos(slant)
along the tilt direction; we search the *inverse* viewing transformation that makes the
back-projected texture most isotropic (:class:`~texsynth.plane.spectra.Criterion`) and optimise
it with scipy. The search runs over perspective views too ("we simply have to search over a larger
family of transformations"), where homogeneity adds the cue the section describes: the texture
must look the same everywhere on the plane, so the scale gradient of texels across the image fixes
the receding direction (tilt mod 360), refines slant, and with isotropy at the centre gives the
focal length when it is unknown.

Deviations from the section, one line each:
- a slant found by isotropy is uncertain by at least the change that costs as much isotropy as
  the texture's own remaining anisotropy (the assumption's failure is an error, not noise);
- orthographic isotropy is read from a fourth-order spectral moment, not the log-energy spread
  (:func:`~texsynth.plane.spectra.moment_slant`);
- with the focal length unknown, a prior over the focal lengths cameras have weighs the isotropy
  slant along the vanishing line that homogeneity gives (on the renders, homogeneity alone was
  nearly flat in slant for a fixed vanishing line, leaning to long focal lengths);
- with the focal length known, the texture's inhomogeneity left at the fit widens the
  uncertainty as noise shared by a few patches (``_PATCHES``, calibrated), not by every band;
- with the focal length known, where the frontal plane fits within ``_EVIDENCE`` noise units of
  the fit, the slant's sigma is at least the slant (its local curvature there is no measurement);
- a lone line family's spacing is taken only where the texture's homogeneity does not rule its
  vanishing line out (:func:`_spacing_conflict`); on an isotropic texture only with the focal
  length known (the spacing then gives the whole plane) and where the texture recedes the same
  way (:func:`_recedes_with`: setts' courses, whose staggered sides form no second family);
- with the focal length unknown, two line families that stay parallel read as frontal under a
  prior over the lenses photos come from (``_LENS_MM``; :mod:`~texsynth.plane.combine`);
  where the texture's homogeneity found no perspective either, its isotropy slant does not
  refute that reading (a frontal brick wall's courses read 51 deg by the fourth-order moment,
  its log-energy spread 1.09 frontal against 0.98 there: the bricks' own shape).
- line families are sought ``_OUTLINE`` pixels or more inside the textured region: the plane's
  outline against a black world or sky is a line of the plane but of neither family.
- a family's segment noise is widened by the design effect of its distinct lines
  (:func:`~texsynth.plane.jackknife.line_inflation`) before the line noise is calibrated.
- with the focal length known, two families are checked against the first one's equal spacing
  (homogeneity of the lines' positions, :func:`~texsynth.plane.lines.spaced_horizon`): where
  their plane and the spacing's differ by over ``_AGREE_DEG``, the second family is dropped and
  the spacing gives the plane, as for a lone family (short head joints laid by hand misled the
  vanishing point; the spacing is tested on the joined segments, stricter than on pieces);
  with it unknown, the second family's vanishing point is checked against the spacing's
  plane at the fitted focal length instead (:func:`_spacing_miss`), and the slant along the
  spacing's vanishing line falls back to isotropy and the lens prior.
- a family's spacing is as uncertain as its own profile likelihood says, the frontal view
  included where that does not rule it out (:func:`~texsynth.plane.lines.spaced_horizon`),
  and the slant's sigma is read at the interval's ends, not linearised at the fit
  (:func:`_spacing_covariance`): frontal phone photos of setts and pavers, whose curved,
  broken courses a chirped period fitted a little better than the frontal one, read 54-62
  deg at confidence 0.85-0.98 when the peak's width was their whole uncertainty.
- with the focal length unknown, a texture whose anisotropy breaks isotropy (beyond
  ``_ANISOTROPY_OK``) does not refute two families' orthogonality: its slant, and so f, rests
  on that isotropy (:func:`~texsynth.plane.combine.combine`'s ``texture_slant``).
- with the focal length unknown, the families' focal length is searched down to the widest lens
  photos come from (``_LENS_MM``, 13 mm equivalent): families whose orthogonality needs a
  wider one are no bricks' or pavers' joints (a rhombic tiling; joints and a stone's grain).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np
import scipy.ndimage as ndi
import scipy.optimize as opt

from .. import validation
from ..blocks.parallel import serial_blas
from .combine import combine, st_covariance
from .geometry import angles_from_gradient, gradient, normal_from_angles
from .jackknife import line_inflation
from .lines import (
    LineCost,
    horizon_through,
    photo_families,
    spaced_horizon,
    vanishing_point,
    weighted_lines,
)
from .search import evaluate, hessian, minimize
from .spectra import (
    ANALYSIS_SIDE,
    Criterion,
    Spectra,
    downsample,
    luminance,
    moment_slant,
    spectra,
    texture_mask,
)

__all__ = ["PlaneEstimate", "estimate_plane", "check_focal", "ESTIMATE_METHODS"]

#: ``method`` values of :func:`estimate_plane`.
ESTIMATE_METHODS = ("auto", "isotropy")


@dataclass(frozen=True)
class PlaneEstimate:
    """Orientation of a textured plane seen in a photo (degrees; camera coordinates).

    Parameters
    ----------
    slant : float
        Angle between the plane's normal and the optical axis, 0 to below 90.
    tilt : float
        Direction in which the surface recedes, counter-clockwise from +x with +y up in the
        picture.
    normal : tuple of 3 floats
        The unit normal, facing the camera (x right, y up, z toward the viewer).
    focal_px : float or None
        Focal length in pixels of the analysed image size (given or estimated); None when the
        fit is orthographic.
    focal_estimated : bool
        ``focal_px`` was estimated, not given.
    tilt_ambiguous_180 : bool
        The receding direction is not determined (orthographic view or too little
        perspective): ``tilt`` and ``tilt + 180`` explain the image equally.
    confidence : float
        In [0, 1]: the uncertainties folded with the texture's departure from the model.
    slant_uncertainty, tilt_uncertainty, normal_uncertainty : float
        One-sigma estimates in degrees.
    focal_uncertainty : float or None
        One sigma of an estimated focal length, in pixels.
    anisotropy : float
        The texture's departure from the model: the RMS log-energy spread across orientations
        after rectification (about 0.6 to 1 for stochastic textures, 1 to 3.5 for bricks, tiles
        and planks, where the isotropy assumption fails; beyond 1 it widens the uncertainty of
        an estimate that rests on the texture).
    method : str
        The ``method`` of :func:`estimate_plane` (or ``"rectangle"``: from a marked rectangle).
    image_size : tuple of 2 ints
        (width, height) of the analysed image.
    line_families : int
        How many families of straight lines (0, 1 or 2: mortar joints, tile edges, seams)
        entered the estimate.
    lens_prior : bool
        With the focal length unknown, the lines stayed parallel under every lens of 13-200 mm
        (35 mm equivalent): the view is frontal to within ``slant_uncertainty``, as measured
        under that prior (an orthographic or telephoto photo beyond it is not covered).
    lines_found : int
        How many families the photo showed before they were checked (a lone family on an
        isotropic texture, or families no plane explains beside the texture, are found but not
        used).

    References
    ----------
    Forsyth & Ponce, section 11.4.1 (slant and tilt of a textured plane); docs/ARCHITECTURE.md,
    Conventions, "Plane orientation".

    Examples
    --------
    >>> import numpy as np
    >>> noise = np.random.default_rng(0).random((96, 96), dtype=np.float32)
    >>> estimate = estimate_plane(noise, method="isotropy")
    >>> estimate.orthographic, estimate.image_size
    (True, (96, 96))
    """

    slant: float
    tilt: float
    normal: tuple[float, float, float]
    focal_px: float | None
    focal_estimated: bool
    tilt_ambiguous_180: bool
    confidence: float
    slant_uncertainty: float
    tilt_uncertainty: float
    normal_uncertainty: float
    focal_uncertainty: float | None
    anisotropy: float
    method: str
    image_size: tuple[int, int]
    line_families: int = 0
    lens_prior: bool = False
    lines_found: int = 0

    @property
    def orthographic(self) -> bool:
        return self.focal_px is None


_WINDOW = 48         # analysis window side (reduced image px): 48 beat 32 and 64 on renders
_W_MAX = 0.4         # highest image frequency used (cycles per pixel; Nyquist is 0.5)
_MOMENT_W_MAX = 0.71  # the orthographic moment uses the whole periodogram, corners included
_GROUPS = 8          # jackknife groups of windows for the moment estimate's uncertainty
_MOMENT_FLOOR = 6.0  # deg: own anisotropy read as slant; measured ~10 (sd) at slant 20-70, but
#                     a wider floor lets lines pull the fit off on weaves and bricks (issue 16)
_NOISE_K = 16.0      # correlation of neighbouring bands and windows: dof / _NOISE_K independent
_EVIDENCE = 1.0      # z-score a hypothesis must lose by to be ruled out (receding direction);
#                     white noise (no perspective at all) reached 0.54 in 50 photos of 64-128 px
_SYSTEMATIC = 3.0    # deg: floor on the uncertainty (model and rendering effects)
_ANISOTROPY_OK = 1.0  # RMS log-energy spread left after the fit up to which that floor holds
_CONFLICT = 4.0      # sigmas: lines this far from the fit of an isotropic texture are not its own
_ISO_W_MAX = 0.3     # cycles/px: above this a pixel footprint blurs the foreshortened axis most
_ISOTROPY_FLOOR = 6.0  # deg: extra uncertainty when slant rests on the isotropy assumption
_TELEPHOTO = 12.0    # focal lengths above this many image sides leave no usable perspective
_F_MIN = 0.5         # image sides: the shortest focal length taken as possible (90 deg view)
_F_TYPICAL = 1.0     # image sides: a 36 mm-equivalent lens, between phones' 26 mm and a 50 mm
_F_SPREAD = 0.7      # natural-log sd of that prior: 0.5 to 2 image sides within one sd
_PATCHES = 9.0       # independent patches of a photo's inhomogeneity (lighting, stains, grass):
#                     the most that keep the EXIF views of the plane section's shared textures
#                     covered on >= 80 % (82 %); held out, the real photos' views: 80 % (issue 27)
_SPACING_CONFLICT = 25.0  # noise units of homogeneity a family's spacing may cost the texture
_MIN_ACROSS = 64     # analysis pixels across the shorter side: the 64 x 64 minimum's windows
_LENS_MM = (13.0, 200.0)  # the lenses photos come from, 35 mm equivalent (phones to telephoto)
_DIAGONAL_35MM = math.hypot(36.0, 24.0)  # the 35 mm frame's diagonal the equivalent refers to
_OUTLINE = 4         # analysis pixels between a segment and an untextured region
_OTHER_XATOL = 0.02  # gradient units (about 1 deg): the opposite receding direction's search
_OTHER_TOL = 0.01    # noise units: how near its minimum that search's value must come
_AGREE_DEG = 6.0     # normals of the two families' plane and that spacing's may differ this much:
#                      twice the lines' systematic floor (_SYSTEMATIC; frontal setts: 4.2)


def _grid_starts(fun, tilts_over: float, count: int = 3):
    """The ``count`` best hypotheses p of a coarse slant x tilt grid."""
    grid = [np.zeros(2)] + [gradient(s, t) for s in (15, 30, 45, 60, 70)
                            for t in np.arange(0.0, tilts_over, 30.0)]
    scores = evaluate(fun, grid)
    return [grid[i] for i in np.argsort(scores)[:count]]


def _noise(raw: float, dof: int) -> float:
    """Standard deviation of a criterion value from the sampling of the texture."""
    return raw * math.sqrt(2.0 * _NOISE_K / max(dof, 1))


def _covariance(fun, x, step, raw: float, dof: int, model: float = 0.0) -> np.ndarray:
    """Covariance of the minimiser x of ``fun`` (a variance of log energies): Gauss-Newton,
    cov = 2 (s^2 / dof_eff + e) H^-1 with s^2 the raw residual variance and e the criterion's
    remaining value where it rests on an assumption the texture can break (its own anisotropy:
    a shift of x that costs that much is as plausible as the fit)."""
    hess = hessian(fun, np.asarray(x, dtype=np.float64), np.asarray(step, dtype=np.float64))
    values, vectors = np.linalg.eigh(hess)
    values = np.maximum(values, 1e-12)  # flat directions: unbounded uncertainty
    return (vectors / values) @ vectors.T * 2.0 * (raw * _NOISE_K / max(dof, 1) + model)


def _angles_cost(cost, v_of_p):
    """Criterion in (slant, tilt) degrees, for uncertainties in degrees."""
    def fun(st):
        p = gradient(min(st[0], 89.0), st[1])
        return cost(p, v_of_p(p))[0]
    return fun



@dataclass(frozen=True)
class _Fit:
    """A fitted plane in analysis-image pixels: gradient p, focal (None: orthographic)."""

    p: np.ndarray
    focal: float | None
    cov: np.ndarray  # (slant, tilt) covariance, degrees^2
    ambiguous: bool
    isotropy_based: bool
    focal_sd: float | None = None  # relative
    spread: np.ndarray | None = None  # cov less how weakly the texture determines p (lines test)
    horizon: np.ndarray | None = None  # the vanishing line v homogeneity found (0: none)


def _fit_isotropy(crit: Criterion, fine: Spectra) -> _Fit:
    """Section 11.4.1: the orthographic inverse viewing transformation (p) that makes the
    texture isotropic; tilt mod 180. Deviation: p is the one that makes the fourth-order spectral
    moment of ``fine`` isotropic (:func:`~texsynth.plane.spectra.moment_slant`: on the shared
    textures it read half the slant the log-energy spread did at slant 0); its uncertainty is a
    jackknife over groups of windows plus the textures' own anisotropy (``_MOMENT_FLOOR``)."""
    st = moment_slant(fine)
    # Delete-one-group jackknife over _GROUPS bands of neighbouring windows (nearly independent).
    order = np.lexsort((fine.centres[:, 0], fine.centres[:, 1]))
    groups = [g for g in np.array_split(order, _GROUPS) if len(g)]
    rest = [moment_slant(Spectra(np.delete(fine.psd, g, axis=0), fine.w,
                                 np.delete(fine.centres, g, axis=0), fine.size, fine.shape))
            for g in groups] if len(groups) > 2 else []
    d = np.array([(a - st[0], (b - st[1] + 90.0) % 180.0 - 90.0) for a, b in rest]).reshape(-1, 2)
    cov = (len(d) - 1) / max(len(d), 1) * d.T @ d if len(d) else np.diag([90.0, 180.0]) ** 2
    model = _MOMENT_FLOOR ** 2 * np.diag([1.0, 1.0 / max(math.sin(math.radians(st[0])), 0.1)
                                           ** 2])
    # How well the texture determines p at all (flat for white noise): the log-energy
    # criterion's Gauss-Newton covariance there, with its remaining value as model error.
    zero = np.zeros(2)
    value, raw, dof = crit.isotropy(gradient(*st), zero)
    observed = _covariance(_angles_cost(crit.isotropy, lambda p: zero), st, (1.5, 3.0), raw, dof,
                           max(value, 0.0))
    return _Fit(gradient(*st), None, cov + model + observed, True, True, spread=cov + model)


def _settle_direction(cost, criterion, starts, step):
    """The best fit from ``starts``, the best fit receding either way, and by how much (noise
    units) it beats the best fit receding the other way: a second search confined to the
    half-plane opposite the first. That search needs the other side's best value, not where it
    lies: it stops within ``_OTHER_TOL`` noise units of it (and ``_OTHER_XATOL``); where it
    wins, it is refined to the first search's precision."""
    fit = minimize(cost, starts, step)
    _, raw, dof = criterion(fit.x)
    axis = fit.x / max(np.linalg.norm(fit.x), 1e-12)

    def other_way(q):
        return cost(q) + 100.0 * max(0.0, float(q @ axis)) ** 2

    flipped = minimize(other_way, [-fit.x], step, _OTHER_XATOL, _OTHER_TOL * _noise(raw, dof))
    if flipped.fun < fit.fun:
        flipped = minimize(other_way, [flipped.x], step)
        _, raw, dof = criterion(flipped.x)
    best, worse = (fit, flipped) if fit.fun <= flipped.fun else (flipped, fit)
    return fit, best.x, (worse.fun - best.fun) / _noise(raw, dof), raw, dof


def _spaced(cost, criterion, v_spaced, f):
    """The plane q = f v of a vanishing line from one family's spacing
    (:func:`~texsynth.plane.lines.spaced_horizon`) and the texture's evidence for its
    receding direction over the opposite one."""
    q = np.asarray(v_spaced[0], dtype=np.float64) * f
    _, raw, dof = criterion(q)
    return q, (cost(-q) - cost(q)) / _noise(raw, dof), raw, dof


def _fit_known_focal(crit: Criterion, f: float, v_spaced=None) -> _Fit:
    """Homogeneity with the focal length known: the texture's band energies must be the same in
    every window once back-projected; this fixes slant and the receding direction (unless a
    line family's spacing gave the vanishing line ``v_spaced``)."""
    def cost(p):
        return crit.homogeneity(p, p / f)[0]

    if v_spaced is not None:
        p, evidence, raw, dof = _spaced(cost, lambda q: crit.homogeneity(q, q / f), v_spaced, f)
    else:
        _, p, evidence, raw, dof = _settle_direction(
            cost, lambda q: crit.homogeneity(q, q / f), _grid_starts(cost, 360.0, 2), 0.05)
    st = angles_from_gradient(p)
    if v_spaced is not None:  # the spacing's uncertainty, not the texture's
        cov = _spacing_covariance(p, v_spaced, f)
    else:
        # The texture's own inhomogeneity left at the fit (lighting, grass between setts) is an
        # error of the assumption, not noise: shared by _PATCHES independent patches.
        value = cost(p)
        cov = _covariance(_angles_cost(crit.homogeneity, lambda q: q / f), st, (1.5, 3.0), raw,
                          dof, max(value, 0.0) / _PATCHES)
        if (cost(np.zeros(2)) - value) / _noise(raw, dof) < _EVIDENCE:
            # The frontal plane fits within noise: the scale gradient, and with it the slant,
            # is not measured, and the curvature at the fit is the wall where the horizon
            # enters the image (a close-up of setts: flat from -60 to 60 deg, sd 3.5 at 59.9).
            cov[0, 0] = max(cov[0, 0], st[0] ** 2)
    # The spacing's chirp fixes the receding direction too.
    return _Fit(p, f, cov, evidence < _EVIDENCE and v_spaced is None, False, horizon=p / f)


def _spacing_covariance(p: np.ndarray, v_spaced, f: float) -> np.ndarray:
    """(slant, tilt) covariance of the plane p = f v of a family's spacing (v and its
    covariance ``v_spaced``): linearised at p, the slant's variance no less than a quarter of
    the mean square normal angle to the planes at the two-sigma ends of the horizon's interval
    (:func:`~texsynth.plane.lines.spaced_horizon`), mapped exactly: an interval that reaches
    the frontal view is a slant interval that reaches 0, whatever the slope at p."""
    cov = st_covariance(p, v_spaced[1] * f * f + np.eye(2) * 1e-8)
    values, vectors = np.linalg.eigh(v_spaced[1])
    step = 2.0 * math.sqrt(max(float(values[-1]), 0.0)) * vectors[:, -1]
    ends = [_normal_angle(p, f * (np.asarray(v_spaced[0]) + s * step)) for s in (-1.0, 1.0)]
    cov[0, 0] = max(cov[0, 0], float(np.mean(np.square(ends))) / 4.0)
    return cov


def _fit_unknown_focal(crit: Criterion, fine: Spectra, f_ref: float, v_spaced=None) -> _Fit:
    """Homogeneity gives the vanishing line v = tan(slant) / f (tilt mod 360; or a line
    family's spacing gave it, ``v_spaced``); isotropy at that tilt gives the slant, weighed
    against a prior over cameras' focal lengths (where isotropy is weak, f falls back to a
    typical lens rather than a wrong one), and so f. Without evidence of perspective:
    :func:`_fit_isotropy`.

    Why not the foreshortening gradient (Garding 1992) for the slant along v: each window's
    local map is J_i = B K_i, with K_i fixed by v alone and B (the slant) shared, so for a fixed
    vanishing line any comparison between windows is blind to the slant; only isotropy (or a
    prior) tells it (on the renders, an affine-invariant spread of the windows' back-projected
    second moments was the same to 1e-3 at every slant from 5 to 85 deg)."""
    def cost(q):
        return crit.homogeneity(q, q / f_ref)[0]

    if v_spaced is not None:
        q, evidence, raw, dof = _spaced(cost, lambda q: crit.homogeneity(q, q / f_ref),
                                        v_spaced, f_ref)
    else:
        fit, q, evidence, raw, dof = _settle_direction(
            cost, lambda q: crit.homogeneity(q, q / f_ref), _grid_starts(cost, 360.0, 2), 0.05)
        if math.hypot(*fit.x) < 1e-3 or evidence < _EVIDENCE:
            return replace(_fit_isotropy(crit, fine), horizon=np.zeros(2))
    v = q / f_ref
    direction = v / np.linalg.norm(v)
    iso = crit.band_limited(_ISO_W_MAX)

    def slant_cost(slant):
        return iso.isotropy(math.tan(math.radians(slant)) * direction, v)[0]

    # Only slants whose focal length f = tan(slant) / |v| a camera can have (field of view
    # under about 90 deg, not telephoto): isotropy alone has collapsed to slant ~0 (f of a few
    # pixels) on textures whose own anisotropy masks the foreshortening.
    lo, hi = (math.degrees(math.atan(k * f_ref * float(np.linalg.norm(v))))
              for k in (_F_MIN, _TELEPHOTO))
    lo, hi = min(max(lo, 0.5), 80.0), min(max(hi, 5.0), 85.0)
    grid = np.linspace(lo, hi, 17)
    start = grid[int(np.argmin(evaluate(slant_cost, grid)))]
    step = grid[1] - grid[0]
    best = opt.minimize_scalar(slant_cost, bounds=(max(start - step, lo), min(start + step, hi)),
                               method="bounded", options={"xatol": 0.05})
    slant = float(best.x)
    p = math.tan(math.radians(slant)) * direction
    _, iraw, idof = iso.isotropy(p, v)
    curvature = hessian(lambda x: np.array(slant_cost(x[0])), np.array([slant]),
                         np.array([1.5]))[0, 0]
    var_slant = 2.0 * (iraw * _NOISE_K / max(idof, 1) + max(best.fun, 0.0)) / max(curvature,
                                                                                 1e-12)
    cov_v = _covariance(_angles_cost(crit.homogeneity, lambda x: x / f_ref),
                        angles_from_gradient(q), (1.5, 3.0), raw, dof)
    # The focal lengths cameras have (_F_TYPICAL image sides, log sd _F_SPREAD) as a prior on
    # the slant along the vanishing line, against the isotropy slant and its own sd.
    norm_v = float(np.linalg.norm(v))
    var_iso = var_slant + _ISOTROPY_FLOOR ** 2
    prior = math.atan(_F_TYPICAL * f_ref * norm_v)
    var_prior = math.degrees(math.sin(prior) * math.cos(prior) * _F_SPREAD) ** 2
    var_post = 1.0 / (1.0 / var_iso + 1.0 / var_prior)
    slant = var_post * (slant / var_iso + math.degrees(prior) / var_prior)
    p = math.tan(math.radians(slant)) * direction
    cov = np.diag([var_post, cov_v[1, 1]])
    # f = tan(slant) / |v|: relative error from the slant and from |v| (the slant of q).
    s_v = math.radians(angles_from_gradient(q)[0])
    rel_v = math.sqrt(cov_v[0, 0]) * math.pi / 180 / (math.sin(s_v) * math.cos(s_v) + 1e-9)
    rel_s = math.sqrt(var_post) * math.pi / 180 / (
        math.sin(math.radians(slant)) * math.cos(math.radians(slant)) + 1e-9)
    # Lines are tested against what the texture says, not against the prior.
    return _Fit(p, float(math.tan(math.radians(slant)) / norm_v), cov, False, True,
                math.hypot(rel_v, rel_s), spread=np.diag([var_slant, cov_v[1, 1]]), horizon=v)


def check_focal(focal_px) -> float | None:
    """``focal_px`` (pixels) as a positive float, None as None, else ``ValueError``: the one
    check of a given focal length (:func:`estimate_plane`, ``rectangle.from_rectangle``).

    Examples
    --------
    >>> check_focal(500), check_focal(None)
    (500.0, None)
    """
    if focal_px is None:
        return None
    focal_px = validation.finite(focal_px, "focal_px (pixels)")
    if focal_px <= 0:
        raise ValueError(f"focal_px must be a positive number of pixels, got {focal_px!r}")
    return focal_px


@serial_blas()
def estimate_plane(image, focal_px: float | None = None, method: str = "auto") -> PlaneEstimate:
    """Slant and tilt of the textured plane filling ``image`` (Forsyth & Ponce, sec. 11.4.1).

    Parameters
    ----------
    image : array (H, W) or (H, W, C), top row first, at least 64 x 64
        A photo of a plane; regions without texture (black borders, sky) are ignored.
    focal_px : float, optional
        Focal length in pixels of ``image`` (``focal_px_from_lens``); the principal point is the
        image centre. None: estimated (``method="auto"``) or orthographic (``"isotropy"``).
    method : {"auto", "isotropy"}
        "auto": homogeneity under perspective (receding direction, and slant when the focal
        length is given) with isotropy for the slant when it is not (then the focal length is
        estimated); isotropy alone when the photo shows no perspective. Straight-line families
        (:mod:`~texsynth.plane.lines`) are combined with it (:mod:`~texsynth.plane.combine`):
        on bricks, tiles and weaves they lead, on stochastic textures there are none.
        "isotropy": the orthographic isotropy search of 11.4.1 alone (tilt mod 180).

    Returns
    -------
    PlaneEstimate
        Degrees; see its docstring for the conventions and confidence.

    References
    ----------
    Forsyth & Ponce, section 11.4.1 (isotropy and homogeneity under perspective); Garding 1992
    (the foreshortening gradient: this module's docstring says why it adds nothing here).

    Examples
    --------
    White noise shows no plane: the receding direction is undetermined and the estimate says
    it is a guess.

    >>> import numpy as np
    >>> noise = np.random.default_rng(0).random((96, 96), dtype=np.float32)
    >>> estimate = estimate_plane(noise, method="isotropy")
    >>> estimate.tilt_ambiguous_180, estimate.confidence < 0.01
    (True, True)
    """
    if method not in ESTIMATE_METHODS:
        raise ValueError(f"method must be one of {', '.join(ESTIMATE_METHODS)}, got {method!r}")
    focal_px = check_focal(focal_px)
    lum = luminance(image)
    size = (lum.shape[1], lum.shape[0])
    small, k = downsample(lum)
    if min(small.shape) < _MIN_ACROSS:  # a strip: windows a few pixels wide measure nothing
        longest = ANALYSIS_SIDE * (min(size) // _MIN_ACROSS)
        raise ValueError(f"image is {size[0]} x {size[1]} pixels, too elongated to read a plane "
                         f"from: crop its longer side to at most {longest} pixels (it is "
                         f"analysed at {small.shape[1]} x {small.shape[0]} and needs "
                         f"{_MIN_ACROSS} pixels across)")
    mask = texture_mask(small)
    fine = spectra(small, mask, _MOMENT_W_MAX, _WINDOW)
    crit = Criterion(fine).band_limited(_W_MAX)
    found, spaced, under_prior, seen = [], None, False, 0
    # A telephoto view (field of view under about 5 degrees) has no perspective left to read
    # the slant from: homogeneity is flat in slant there, so the view is taken as orthographic.
    telephoto = focal_px is not None and focal_px / k > _TELEPHOTO * max(small.shape)
    if method == "isotropy" or telephoto:
        fit = _fit_isotropy(crit, fine)
    else:
        side = float(max(small.shape))

        def texture_fit(v_spaced=None):
            return _fit_known_focal(crit, focal_px / k, v_spaced) if focal_px is not None \
                else _fit_unknown_focal(crit, fine, side, v_spaced)

        fit = texture_fit()
        # Lines only away from untextured regions: the plane's outline against a black world or
        # sky is a line of the plane but of neither family, and long and strong enough to make
        # the second one.
        inner = ndi.binary_erosion(mask, iterations=_OUTLINE, border_value=1)
        found = photo_families(lum, small, k, inner, image)
        seen = len(found)
        spaced, check = None, None
        if len(found) == 2 and not found[0].dense:
            check = spaced_horizon(found[0], horizon_through(found[0], side), side)
            f_h = side if focal_px is None else focal_px / k  # the texture fit's own f_ref
            if check is not None and _spacing_conflict(crit, fit.horizon, check[0],
                                                       f_h) > _SPACING_CONFLICT:
                check = None
        isotropic = _anisotropy(crit, fit) <= _ANISOTROPY_OK ** 2
        if len(found) == 1 and not found[0].dense and (not isotropic or focal_px is not None):
            # One family on its own was wrong more often than right where the texture is
            # isotropic (foreshortened texels line up across the tilt); where it is not
            # (boards), the family's equal spacing gives the vanishing line. With the focal
            # length known, that vanishing line is the whole plane (p = f v): there the spacing
            # of an isotropic texture's courses (setts) is taken too, where the texture's
            # homogeneity recedes the same way (_recedes_with).
            spaced = spaced_horizon(found[0], horizon_through(found[0], side), side)
            if spaced is not None and focal_px is None and (
                    np.linalg.norm(spaced[0]) <= 2.0 * math.sqrt(np.trace(spaced[1]))):
                spaced = None  # no perspective seen: nothing for the spacing to fix
            f_h = side if focal_px is None else focal_px / k
            if spaced is not None and _spacing_conflict(crit, fit.horizon, spaced[0], f_h) \
                    > _SPACING_CONFLICT:
                spaced = None  # a chance period across stones or veins the texture rules out
            if spaced is not None and isotropic and not _recedes_with(crit, spaced[0], f_h):
                spaced = None  # a period across marble veins, its chirp the wrong way round
        if spaced is not None:
            fit = texture_fit(spaced)
        elif len(found) == 1:
            found = []
    # The texture's honest floor: wider the more its own anisotropy is left after the fit.
    anisotropy = math.sqrt(max(_anisotropy(crit, fit), 0.0))
    floor = _SYSTEMATIC * max(1.0, anisotropy / _ANISOTROPY_OK)
    if spaced is not None and focal_px is not None:
        floor = _SYSTEMATIC  # the lines and their spacing alone give the plane
    if found and spaced is None:  # the texture fit with the floors plane_estimate would state
        prior = fit.cov + np.diag([floor ** 2 + fit.isotropy_based * _ISOTROPY_FLOOR ** 2,
                                   floor ** 2])
        # The lens prior only where the texture could refute a frontal reading: a directional
        # one (tiles, weaves) seen orthographically along its axes shows parallel orthogonal
        # families as a frontal view does, and its own grain hides the slant.
        lens = tuple(max(small.shape) / (mm / _DIAGONAL_35MM * math.hypot(*small.shape))
                     for mm in _LENS_MM[::-1])  # w = side / f, the longest lens first
        cost, side = LineCost(found), float(max(small.shape))
        # Each family's noise as wide as its independent lines make it (a joint broken into
        # pieces shares one error): the vanishing point of a few lines weighs as a few.
        cost.sigma = [s * math.sqrt(line_inflation(f, side)) for s, f in zip(cost.sigma, found,
                                                                           strict=True)]
        both = combine(cost, side, fit.p, prior,
                       fit.focal, fit.focal_sd, fit.ambiguous,
                       None if focal_px is None else focal_px / k,
                       lens if anisotropy <= _ANISOTROPY_OK else None,
                       texture_slant=anisotropy <= _ANISOTROPY_OK, w_limit=lens[1])
        # Frontal under the lens prior where homogeneity saw no perspective either: lines and
        # texture agree on v ~ 0, and the isotropy slant left is the texture's own grain.
        agreed = both is not None and both.under_prior and fit.focal is None
        if both is None or (anisotropy <= _ANISOTROPY_OK and not agreed
                            and _distance(both, fit, prior if fit.spread is None else
                                          prior - fit.cov + fit.spread) > _CONFLICT):
            found = []  # impossible lines, or lines that contradict an isotropic texture
        else:
            fit = _Fit(both.p, both.focal, both.cov, both.ambiguous,
                       fit.isotropy_based and not both.determined, both.focal_sd)
            floor = _SYSTEMATIC if both.determined else floor
            under_prior = both.under_prior
            if check is not None and _spacing_miss(fit, check[0], found[1], focal_px is None,
                                                   side) > _AGREE_DEG:
                # The second family's vanishing point against the first's equal spacing: the
                # spacing of a wall's courses is measured along every course, a head joint's
                # direction over a course's height (a brick wall at slant 24 read 8.5 deg off).
                found, spaced, under_prior = found[:1], check, False
                fit = texture_fit(check)
                floor = _SYSTEMATIC if focal_px is not None else _SYSTEMATIC * max(
                    1.0, math.sqrt(max(_anisotropy(crit, fit), 0.0)) / _ANISOTROPY_OK)
    slant, tilt = angles_from_gradient(fit.p)
    if fit.focal is None:  # p and -p are the same orthographic view
        tilt %= 180.0
    focal = None if fit.focal is None else fit.focal * k
    estimated = focal is not None and focal_px is None
    return plane_estimate(slant, tilt, focal, estimated, fit.ambiguous, fit.cov, fit.focal_sd,
                          _anisotropy(crit, fit), fit.isotropy_based, method, size, len(found),
                          floor, under_prior, seen)


def _spacing_conflict(crit: Criterion, v_texture, v_spaced, f: float) -> float:
    """How much worse (noise units) the texture's homogeneity finds a family's spaced vanishing
    line than its own: a few units where the spacing is right (planks, courses), thousands where
    a chance period across stones or marble veins made it up."""
    def cost(v):
        v = np.asarray(v, dtype=np.float64)
        return crit.homogeneity(f * v, v)

    own, raw, dof = cost(v_texture)
    return (cost(v_spaced)[0] - own) / _noise(raw, dof)


def _recedes_with(crit: Criterion, v_spaced, f: float) -> bool:
    """Whether the texture's homogeneity finds the plane q = f v of a family's spacing better
    than its mirror -q by ``_EVIDENCE`` noise units: the spacing's chirp and the texels'
    shrinking read the same receding direction. Equally spaced courses give both; a chance
    period in a random texture has its chirp either way (the sign is a coin toss), so this
    rules out half of them whatever their strength."""
    q = np.asarray(v_spaced, dtype=np.float64) * f
    value, raw, dof = crit.homogeneity(q, q / f)
    return (crit.homogeneity(-q, -q / f)[0] - value) / _noise(raw, dof) >= _EVIDENCE


def _spacing_miss(fit: _Fit, v_spaced: np.ndarray, second, estimated: bool,
                  side: float) -> float:
    """How far (degrees) the two families' plane ``fit`` lies from the vanishing line
    ``v_spaced`` of the first family's spacing. With the focal length f known: the angle
    between the normals of p and f v_spaced. Estimated: f itself came from the second family
    (Caprile & Torre 1990), and a wrong family trades f for its fit (a brick wall at slant 24
    read 7.6 deg off with the two planes' normals 3.4 deg apart); there the test is the one
    of the second family itself, its vanishing point's angle to the spacing's plane
    p = f v_spaced on the Gauss sphere (Barnard 1983) at the fitted f; 0 when the fit has no
    perspective (no f: the spacing has nothing to check)."""
    if fit.focal is None:
        return 0.0
    if not estimated:
        return _normal_angle(fit.p, v_spaced * fit.focal)
    x = vanishing_point(second, side)
    if x is None:  # parallel in the image: the direction (x, 0) at infinity
        x = np.linalg.svd(weighted_lines(second, side), full_matrices=False)[2][-1][:2]
        direction = np.append(x, 0.0)
    else:
        direction = np.append(x, -fit.focal)
    normal = np.append(fit.focal * np.asarray(v_spaced, dtype=np.float64), 1.0)
    sine = abs(float(direction @ normal)) / (np.linalg.norm(direction) * np.linalg.norm(normal))
    return math.degrees(math.asin(min(1.0, sine)))


def _normal_angle(p: np.ndarray, q: np.ndarray) -> float:
    """Angle (degrees) between the normals of the planes of gradients p and q."""
    a, b = (np.append(x, 1.0) / math.sqrt(1.0 + float(x @ x)) for x in (p, q))
    return math.degrees(math.acos(min(1.0, float(a @ b))))


def _distance(both, fit: _Fit, prior: np.ndarray) -> float:
    """Mahalanobis distance in (slant, tilt) of the combined estimate from the texture fit
    (tilt mod 180 when the texture fit does not claim the receding direction)."""
    a, b = angles_from_gradient(both.p), angles_from_gradient(fit.p)
    turn = 180.0 if fit.ambiguous else 360.0
    d = np.array([a[0] - b[0], (a[1] - b[1] + turn / 2) % turn - turn / 2])
    d[1] *= math.sin(math.radians(max(a[0], b[0])))  # tilt matters as much as the slant allows
    return float(math.sqrt(d @ np.linalg.inv(prior) @ d))


def _anisotropy(crit: Criterion, fit: _Fit) -> float:
    """The raw isotropy criterion at the fit: the texture's own anisotropy left."""
    return crit.isotropy(fit.p, np.zeros(2) if fit.focal is None else fit.p / fit.focal)[1]


def plane_estimate(slant, tilt, focal, estimated, ambiguous, cov, focal_sd, anisotropy,
                   isotropy_based, method, size, line_families, floor, under_prior=False,
                   lines_found=0) -> PlaneEstimate:
    """The record, with uncertainties (one sigma, degrees) and confidence.

    confidence = P(normal within 8 deg) * P(receding direction within 30 deg), for Gaussian
    errors of the stated sigmas; the tilt factor is 1 when tilt is only claimed mod 180.
    Near frontal views the tilt may be off by more: by as much as moves the normal 8 deg
    (sin(slant) sin(dtau / 2) = sin 4 deg: above 30 deg under a slant of 15.6, any tilt under
    4 deg), so a precise frontal reading is not a guess for want of a receding direction.
    Under the lens prior the view is frontal within the covariance of p: the slant's sigma is
    the normal's, and no receding direction is claimed (no tilt factor).
    """
    s_slant = min(90.0, math.hypot(math.sqrt(max(cov[0, 0], 0.0)), floor))  # slant is in [0, 90)
    s_tilt = min(180.0, math.hypot(math.sqrt(max(cov[1, 1], 0.0)), floor))
    if isotropy_based:
        s_slant = min(90.0, math.hypot(s_slant, _ISOTROPY_FLOOR))
    s_normal = s_slant if under_prior else math.hypot(s_slant,
                                                      math.sin(math.radians(slant)) * s_tilt)
    confidence = 1.0 - math.exp(-(8.0 / s_normal) ** 2)  # floor: _SYSTEMATIC or wider
    half = math.sin(math.radians(4.0)) / max(math.sin(math.radians(slant)), 1e-12)
    if half < 1.0 and not under_prior:  # else no tilt error moves the normal 8 deg (slant < 4)
        tilt_ok = max(30.0, 2.0 * math.degrees(math.asin(half)))
        confidence *= math.erf(tilt_ok / (s_tilt * math.sqrt(2.0)))
    n = normal_from_angles(slant, tilt)
    return PlaneEstimate(
        slant=float(slant), tilt=float(tilt), normal=tuple(float(c) for c in n),
        focal_px=None if focal is None else float(focal), focal_estimated=bool(estimated),
        tilt_ambiguous_180=bool(ambiguous), confidence=float(confidence),
        slant_uncertainty=float(s_slant), tilt_uncertainty=float(s_tilt),
        normal_uncertainty=float(s_normal),
        focal_uncertainty=None if focal_sd is None or focal is None else float(focal * focal_sd),
        anisotropy=float(math.sqrt(max(anisotropy, 0.0))), method=method, image_size=size,
        line_families=line_families, lens_prior=bool(under_prior),
        lines_found=max(int(lines_found), line_families))



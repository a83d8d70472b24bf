"""What a plane estimate can be used for, in words a user reads: a measurement or a guess,
whether any slant was measured at all, and why not.

The estimate's own one-sigma uncertainties decide (:class:`~texsynth.plane.fit.PlaneEstimate`);
nothing is measured again here.
"""

from __future__ import annotations

from dataclasses import dataclass

__all__ = ["Verdict", "verdict"]

_GUESS = 0.5        # confidence below which an estimate is a guess (issue 27's bar for frontal)
_SLANT_Z = 2.0      # a slant under this many sigmas is no evidence of any slant (0 fits as well)
_TILT_SD = 30.0     # deg: a receding direction less certain than this is not told
#: What the verdict says when no lines entered the estimate, by the families the photo showed.
_UNUSED = ("no straight lines", "one family of lines, too weak on its own",
           "lines found but not used: no plane explains them and the texture together")
_DIRECTIONAL = 1.0  # RMS log-energy spread beyond which the texture's own grain reads as slant


@dataclass(frozen=True)
class Verdict:
    """``guess``: the estimate should not be applied as it is; ``slant_measured``: a slant was
    told from 0 (else the photo may as well be frontal); ``reasons``: why it is a guess, in a
    user's words, the most telling first (empty for a measurement); ``lens_prior``: measured
    under the prior that the photo comes from a 13-200 mm lens (35 mm equivalent), the focal
    length being unknown."""

    guess: bool
    slant_measured: bool
    reasons: tuple[str, ...]
    lens_prior: bool = False

    @property
    def summary(self) -> str:
        """One line for a panel or a report: "Measured" (a slant or a frontal view), or
        "Guess: " and the reasons."""
        if self.guess:
            return "Guess: " + "; ".join(self.reasons)
        if self.lens_prior:
            return "Measured under a lens prior (13-200 mm equivalent): frontal"
        return "Measured" if self.slant_measured else "Measured: frontal (no measurable slant)"


def verdict(estimate) -> Verdict:
    """Whether a plane estimate is a measurement or a guess, and why.

    Parameters
    ----------
    estimate : PlaneEstimate
        What :func:`~texsynth.plane.estimate_plane` returned (or a record with its
        ``confidence``, ``slant``, ``slant_uncertainty``, ``tilt_uncertainty``,
        ``tilt_ambiguous_180``, ``line_families``, ``anisotropy`` and, optionally,
        ``lens_prior`` and ``lines_found``).

    Returns
    -------
    Verdict
        ``guess`` when the confidence is under 0.5; ``slant_measured`` when the slant is more
        than two of its sigmas from 0 (a frontal photo without a cue reads 15-30 deg with a
        sigma as wide: that is no measurement of any slant); ``reasons``: no straight lines
        (or lines found but not used: a lone family on a texture that does not confirm it, or
        families that no plane explains beside the texture),
        a directional texture (its own grain reads as slant under the isotropy assumption of
        Forsyth & Ponce, sec. 11.4.1), no measurable slant, an uncertain receding direction.
        ``lens_prior``: with the focal length unknown, the lines stayed parallel under every
        lens of 13-200 mm (35 mm equivalent): a frontal view, measured under that prior.

    References
    ----------
    Forsyth & Ponce, Computer Vision: A Modern Approach, sec. 11.4.1 (the isotropy
    assumption a directional texture breaks).

    Examples
    --------
    >>> import numpy as np
    >>> from texsynth.plane import estimate_plane, verdict
    >>> noise = np.random.default_rng(0).random((96, 96))  # no plane cue at all
    >>> v = verdict(estimate_plane(noise))
    >>> v.guess, "no straight lines" in v.reasons
    (True, True)
    """
    sd_slant = max(float(estimate.slant_uncertainty), 1e-9)
    measured = float(estimate.slant) > _SLANT_Z * sd_slant
    guess = float(estimate.confidence) < _GUESS
    reasons = []
    if guess:
        if not measured:
            reasons.append(f"no measurable slant ({estimate.slant:.0f}° ± {sd_slant:.0f}°: "
                           "a frontal view fits as well)")
        if getattr(estimate, "lens_prior", False):
            reasons.append(f"lines parallel: frontal within ± {sd_slant:.0f}° for any 13-200 mm "
                           "lens (35 mm eq.)")
        if estimate.line_families == 0:
            reasons.append(_UNUSED[min(int(getattr(estimate, "lines_found", 0)), 2)])
        if estimate.anisotropy > _DIRECTIONAL and estimate.line_families < 2:
            reasons.append("texture anisotropic (its own grain reads as slant)")
        if measured and not estimate.tilt_ambiguous_180 and estimate.tilt_uncertainty > _TILT_SD:
            reasons.append(f"receding direction uncertain (± {estimate.tilt_uncertainty:.0f}°)")
        if not reasons:
            reasons.append(f"normal uncertain (± {estimate.normal_uncertainty:.0f}°)")
    under_prior = bool(getattr(estimate, "lens_prior", False)) and not measured
    return Verdict(guess, measured, tuple(reasons), under_prior)

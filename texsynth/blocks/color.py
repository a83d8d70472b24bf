"""Colour maths: PCA decorrelation and its inverse, sliced optimal transport of a colour
distribution (Pitie et al. 2005, Rabin et al. 2011), and the sRGB transfer function.

PCA (Torralba, Isola & Freeman, sec. 28.3; Van De Ville et al. 2009, sec. 3): Heeger-Bergen
synthesizes channels independently. RGB channels of a photo are strongly correlated, so
independent synthesis would invent colours; along the principal axes of the exemplar's colour
cloud the channels are decorrelated and independent synthesis is reasonable. Decorrelated is
not independent: on saturated exemplars the components combine into colours the photo never
had, which :func:`sliced_transfer` moves back onto the exemplar's joint distribution.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..progress import Progress
from .histogram import TargetHistogram, match_many
from .parallel import ranges, run, small_product

__all__ = ["ColorPCA", "luminance", "sliced_transfer", "sliced_transfer_rows", "srgb_to_linear",
           "linear_to_srgb"]

#: Target colours :func:`sliced_transfer` sorts per projection (a regular sample of ``y``).
TARGET_SAMPLES = 1 << 18


@dataclass(frozen=True)
class ColorPCA:
    """``components = (x - mean) @ basis``; ``x = components @ basis.T + mean``."""

    mean: np.ndarray
    basis: np.ndarray

    @classmethod
    def fit(cls, image: np.ndarray) -> ColorPCA:
        """Principal axes of the (H, W, C) image's colours, strongest first."""
        x = image.reshape(-1, image.shape[-1]).astype(np.float64)
        mean = x.mean(axis=0)
        cov = np.cov(x - mean, rowvar=False).reshape(x.shape[1], x.shape[1])
        eigenvalues, basis = np.linalg.eigh(cov)
        basis = basis[:, ::-1]
        # fix each axis' sign (largest entry positive) so results never depend on LAPACK's choice
        basis *= np.where(basis[np.abs(basis).argmax(axis=0), range(basis.shape[1])] < 0, -1, 1)
        return cls(mean.astype(np.float32), basis.astype(np.float32))

    def forward(self, image: np.ndarray) -> np.ndarray:
        return small_product("...c,ck->...k", np.asarray(image, np.float32) - self.mean,
                             self.basis)

    def inverse(self, components: np.ndarray) -> np.ndarray:
        x = small_product("...k,ck->...c", np.asarray(components, np.float32), self.basis)
        x += self.mean
        return x


def sliced_transfer(x: np.ndarray, y: np.ndarray, rng: np.random.Generator,
                    steps: int, progress: Progress | None = None) -> np.ndarray:
    """Move the colours ``x`` (N, C) towards the joint distribution of the colours ``y`` (M, C).

    Sliced optimal transport: Pitie, Kokaram & Dahyot 2005 ("N-dimensional probability density
    function transfer", sec. 3), in Rabin, Peyre, Delon & Bernot 2011 ("Wasserstein barycenter
    and its application to texture mixing", sec. 2.2) a gradient step on the sliced Wasserstein
    distance. Each step draws a random orthonormal basis R, matches the 1-D histogram of every
    projection x R[:, k] to that of y R[:, k], and moves x by the differences:
    ``x <- x + sum_k (match(x R_k, y R_k) - x R_k) R_k^T``. Deviations: the 1-D matching is the
    O(N) cumulative-histogram path of ``texsynth.blocks.histogram``; the target side is every
    ``ceil(M / TARGET_SAMPLES)``-th colour of ``y`` (the matching reads only ``BINS + 1`` of its
    quantiles). Returns a new float32 array; ``progress`` hears of every step.
    """
    xt = np.array(np.asarray(x, dtype=np.float32).T, order="C")  # (C, N): contiguous rows
    sliced_transfer_rows(xt, y, rng, steps, progress)
    return np.ascontiguousarray(xt.T)


def sliced_transfer_rows(xt: np.ndarray, y: np.ndarray, rng: np.random.Generator,
                         steps: int, progress: Progress | None = None) -> None:
    """:func:`sliced_transfer` in place on the colours stored as C contiguous rows ``xt`` (C, N)
    (float32), with no full-size copy.

    R being orthonormal, a step's ``x + R (match(R^T x) - R^T x)`` is ``R match(R^T x)`` (to
    rounding), so the rows hold the projections p = R_s^T x from step to step: each step matches
    them in place and turns them into the next step's, ``p <- R_{s+1}^T R_s p``, and the last
    one turns them back, ``x = R_s p``: one (C, C) product per step. The products run in
    cache-sized steps on every core, column by column, and the C matches together
    (``match_many``; the result does not depend on the split)."""
    c = xt.shape[0]
    y = np.asarray(y, dtype=np.float32)
    yt = np.ascontiguousarray(y[:: -(-len(y) // TARGET_SAMPLES)].T)
    previous = np.eye(c)
    for step in range(steps):
        basis = np.linalg.qr(rng.standard_normal((c, c)))[0]
        _turn(xt, (basis.T @ previous).astype(np.float32))
        projected = small_product("cn,ck->kn", yt, basis.astype(np.float32))
        targets = run(TargetHistogram, projected)                      # C sorts side by side
        match_many(xt, targets, xt)
        previous = basis
        if progress is not None:
            progress((step + 1) / steps, f"colour transport {step + 1}/{steps}")
    if steps:
        _turn(xt, previous.astype(np.float32))


#: Colours per step of :func:`_turn`: a step's (C, TURN_STEP) stays in cache.
TURN_STEP = 1 << 16


def _turn(x: np.ndarray, m: np.ndarray) -> None:
    """``x = m @ x`` in place, for a small (C, C) ``m`` and (C, N) rows, step by step in cache
    on every core (``np.einsum``'s own loop: half the time of one product a row and no BLAS)."""
    c = m.shape[0]

    def part(r):
        turned = np.empty((c, min(TURN_STEP, r[1] - r[0])), np.float32)
        for a in range(r[0], r[1], TURN_STEP):
            rows = x[:, a:min(a + TURN_STEP, r[1])]
            out = turned[:, :rows.shape[1]]
            np.einsum("kc,cn->kn", m, rows, out=out)
            rows[...] = out

    run(part, ranges(x.shape[1]))


def luminance(a: np.ndarray) -> np.ndarray:
    """Rec. 709 luminance Y (float64, H x W) of an (H, W, C) array; C < 3: its first channel.

    Examples
    --------
    >>> float(luminance(np.ones((1, 1, 3), np.float32))[0, 0])
    1.0
    """
    if a.shape[2] >= 3:
        return a[:, :, :3].astype(np.float64) @ np.array([0.2126, 0.7152, 0.0722])
    return a[:, :, 0].astype(np.float64)


def srgb_to_linear(v) -> np.ndarray:
    """The sRGB transfer function (IEC 61966-2-1) decoded; values above 1 follow the power law."""
    v = np.asarray(v, dtype=np.float32)
    return np.where(v <= 0.04045, v / 12.92, ((np.maximum(v, 0.04045) + 0.055) / 1.055) ** 2.4
                    ).astype(np.float32)


def linear_to_srgb(v) -> np.ndarray:
    """Inverse of :func:`srgb_to_linear`."""
    v = np.asarray(v, dtype=np.float32)
    return np.where(v <= 0.0031308, v * 12.92,
                    1.055 * np.maximum(v, 0.0031308) ** (1 / 2.4) - 0.055).astype(np.float32)

"""Heeger-Bergen pyramid-based texture synthesis.

Paper 000, section 11.3.2, Algorithm 11.4 (with Algorithm 11.3 for histogram matching); paper 003,
section 28.3 (PCA colour, about 15 iterations); paper 001, section 2.1 (steerable pyramid).

    Make a working image from noise; match its histogram to the exemplar's.
    Until convergence (``iterations`` times):
        analyse the working image into a pyramid pw;
        match every subband of pw (residuals included) to the exemplar's subband;
        synthesize the working image from pw; match its pixel histogram.

Deviations, one line each:
- the exemplar's subband statistics come from its periodic component (Moisan 2011), so the
  border jump of a non-tiling photo adds no false cross-shaped energy to the bands;
- pixel histograms come from the exemplar itself, so the output's values are the photo's;
- the subband matching uses the O(N) cumulative-histogram path of ``texsynth.histogram``;
- colour channels are the exemplar's PCA components, synthesized one after another from one shared
  noise draw, projected back and clipped to the exemplar's per-channel range.
"""

from __future__ import annotations

import numpy as np

from ..color import ColorPCA
from ..histogram import TargetHistogram, match
from ..periodic import periodic_component
from ..pyramid import SteerablePyramid, max_scales
from ..registry import Method, Param, register

__all__ = ["heeger_bergen", "pyramid_depth"]


def pyramid_depth(exemplar_shape, width: int, height: int, scales: int) -> int:
    """``scales`` capped so that both the exemplar's and the output's pyramids exist."""
    return min(scales, max_scales(exemplar_shape[:2]), max_scales((height, width)))


def heeger_bergen(exemplar, width, height, rng, progress, scales=4, orientations=4,
                  iterations=15):
    """Synthesize (height, width, C) from ``exemplar`` (H, W, C float32); see the module notes."""
    depth = pyramid_depth(exemplar.shape, width, height, scales)
    pca = ColorPCA.fit(exemplar)
    components = pca.forward(exemplar)
    periodic = periodic_component(components)
    pyr_exemplar = SteerablePyramid(exemplar.shape[:2], depth, orientations)
    pyr_output = SteerablePyramid((height, width), depth, orientations)
    channels = exemplar.shape[2]
    noise = rng.random((height, width, channels), dtype=np.float32)

    out = np.empty((height, width, channels), np.float32)
    for c in range(channels):
        step = progress.span(c / channels, (c + 1) / channels)
        pixels = TargetHistogram(components[:, :, c])
        subbands = pyr_exemplar.analyze(periodic[:, :, c])
        targets = [TargetHistogram(band) for band in subbands.arrays()]
        image = match(noise[:, :, c], pixels)
        for it in range(iterations):
            pw = pyr_output.analyze(image)
            pw = pw.replaced([match(band, t) for band, t in zip(pw.arrays(), targets, strict=True)])
            image = match(pyr_output.synthesize(pw), pixels)
            step((it + 1) / iterations,
                 f"channel {c + 1}/{channels}, iteration {it + 1}/{iterations}")
        out[:, :, c] = image

    result = pca.inverse(out)
    return np.clip(result, exemplar.min(axis=(0, 1)), exemplar.max(axis=(0, 1)))


def _memory(shape, width, height, params):
    """Output and noise (C floats), one channel's pyramid and spectra, the exemplar's targets."""
    k = params["orientations"]
    per_pixel = 8 * shape[2] + 4 * (k * 4 / 3 + 3) + 8 * 3 + 4 * k * 2 / 3
    return per_pixel * width * height + 4 * (k * 4 / 3 + 6) * shape[0] * shape[1]


register(Method(
    name="heeger_bergen",
    label="Heeger-Bergen",
    description="Match the histograms of steerable-pyramid subbands (Heeger & Bergen 1995): "
                "fast, best on stochastic textures such as sand, gravel, stucco, clouds",
    function=heeger_bergen,
    params=(
        Param("scales", int, 4, "Pyramid levels (capped by exemplar and output sizes)", 1, 8),
        Param("orientations", int, 4, "Oriented subbands per level (K)", 1, 8),
        Param("iterations", int, 15, "Rounds of subband and pixel histogram matching", 1, 100),
    ),
    min_exemplar=8,
    memory=_memory,
    reference="Heeger & Bergen 1995; paper 000 sec. 11.3.2 Alg. 11.3-11.4; paper 003 sec. 28.3",
))

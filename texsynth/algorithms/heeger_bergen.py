"""Heeger-Bergen pyramid-based texture synthesis.

Forsyth & Ponce, section 11.3.2, Algorithm 11.4 (with Algorithm 11.3 for histogram matching);
Torralba, Isola & Freeman, section 28.3 (PCA colour, about 15 iterations); Van De Ville et al. 2009,
section 2.1 (steerable pyramid). With ``steered`` and/or ``joint``: Van De Ville, Guerquin-Kern
and Unser 2009, sections 2.2-2.4, the oriented bands of each level matched as one K-vector per
position.

    Make a working image from noise; match its histogram to the exemplar's.
    Until convergence (``iterations`` times):
        analyse the working image into a pyramid pw;
        match every subband of pw (residuals included) to the exemplar's subband;
        synthesize the working image from pw; match its pixel histogram.

Van De Ville et al. 2009's algorithm (section 2.4) replaces "match every oriented subband" per level
j by:

    theta = theta_max of the output's coefficient vectors w[k] (eq. 4), theta_ref the exemplar's;
    theta_new = theta matched (1-D) to the histogram of theta_ref;
    w~ = w steered by theta (channel 0 = response of maximal orientation), w~_ref likewise;
    w~ matched to w~_ref: K-D conditional matching (``joint``) or band by band;
    w = w~ steered back by -theta_new.

``steered`` alone keeps the band-by-band matching on the steered bands; ``joint`` alone matches
the unsteered K-vectors jointly. The conditional chain is not symmetric in the orientations, and
unsteered it streaks the output along one orientation the finer the bins (measured in
benchmarks/sections/steered.py); steered, the chain starts from the orientation-free maximal
response and it does not.

Deviations, one line each:
- the exemplar's subband statistics come from its periodic component (Moisan 2011), so the
  border jump of a non-tiling photo adds no false cross-shaped energy to the bands;
- a photo larger than the output is analysed in tiles of the output's size (the fewest that
  cover it, evenly spread, each made periodic, analysed by the output's pyramid), each tile's
  subbands counted on the part of the photo it owns (an equal partition): the statistics of the
  whole photo at the output's pyramid cost, not the photo's;
- each target (a channel's pixels, a subband) keeps a regular sample of at most about
  ``SAMPLES`` values (every value up to a 1024^2 exemplar; ``histogram.sample_step``), and
  the colour PCA is fitted on the pixels' sample;
- pixel histograms come from the exemplar itself, so the output's values are the photo's;
- the subband matching uses the O(N) cumulative-histogram path of ``texsynth.blocks.histogram``;
- colour channels are the exemplar's PCA components, each iteration run on every component in
  turn from one shared noise draw; after each iteration the colours take ``SLICES_PER_ITERATION``
  steps of sliced optimal transport towards the exemplar's joint colour distribution (Pitie et al.
  2005; Rabin et al. 2011, sec. 2.2; ``texsynth.blocks.color.sliced_transfer``), ``FINAL_SLICES``
  after the last, so the PCA components do not combine into colours the photo never had; the result
  is projected back and clipped to the exemplar's per-channel range;
- joint matching bins by equal-count conditional bins (``texsynth.blocks.histogram``), not fixed.
- each subband is matched by the thread that made it as soon as it is made, the subbands'
  transforms side by side, the colour steps' matches and products by ranges, on every core
  (``texsynth.blocks.parallel``), split so that the output does not depend on the number of
  cores.

References
----------
Forsyth & Ponce, section 11.3.2, Algorithms 11.3-11.4; Heeger & Bergen 1995;
Torralba, Isola & Freeman, section 28.3; Van De Ville et al. 2009, sections 2.1-2.4
(eq. 4); Simoncelli & Freeman 1995 (the steerable pyramid); Moisan 2011 (the periodic
component); Pitie et al. 2005 and Rabin et al. 2011, section 2.2 (sliced transport).
"""

from __future__ import annotations

import numpy as np

from ..blocks.color import ColorPCA, sliced_transfer_rows
from ..blocks.histogram import (
    BINS,
    JointTarget,
    JointWork,
    TargetHistogram,
    match,
    match_joint,
    sample_step,
)
from ..blocks.parallel import run
from ..blocks.periodic import periodic_component
from ..blocks.pyramid import Coefficients, SteerablePyramid, pyramid_depth
from ..blocks.steering import Steering
from ..registry import Method, Param, register

__all__ = ["heeger_bergen", "METHOD"]

#: Sliced optimal transport steps after each iteration, and after the last one. Two, not four,
#: per iteration: a third fewer steps in all (they were 38% of the time at 2048^2), pool_water's
#: off-palette pixels 0.07% -> 0.09-0.11%, its subband distance unchanged.
SLICES_PER_ITERATION = 2
FINAL_SLICES = 30
#: One sliced transport step's time over one iteration's pyramid analysis, matching and
#: synthesis of every channel (measured at the defaults, 128 -> 256 RGB: 0.10): the progress
#: gives the last steps their share of the time, so the time left holds near the end.
SLICE_COST = 0.10
#: Rows turned back to the photo's colours at a time, on the cores, with progress between.
BACK_ROWS = 256
#: Values a target keeps (a channel's pixels, one subband): all of a 1024^2 exemplar's, a
#: regular sample of a larger photo's (quantiles to about 1e-3 of a rank, finer than a bin).
SAMPLES = 1 << 20


def heeger_bergen(exemplar, width, height, rng, progress, scales=4, orientations=4,
                  iterations=15, steered=False, joint=False, bins=50):
    """Synthesize (height, width, C) from ``exemplar`` by matching the histograms of its
    steerable pyramid's subbands and pixels (see the module notes).

    Parameters
    ----------
    exemplar : float32 array (H, W, C)
        The sample, validated by ``texsynth.synthesize``.
    width, height : int
        The output size, larger or smaller than the exemplar.
    rng, progress : numpy.random.Generator, texsynth.progress.Progress
        The seeded generator and the progress reporter ``texsynth.synthesize`` makes.
    scales : int
        Pyramid levels (capped by exemplar and output sizes).
    orientations : int
        Oriented subbands per level (K).
    iterations : int
        Rounds of subband and pixel histogram matching.
    steered : bool
        Match each level's bands turned to their orientation of maximal response, and the
        distribution of that orientation (Van De Ville et al. 2009): crisper edges.
    joint : bool
        Match the joint histogram of each level's orientations (conditional matching) instead
        of each band alone; use with ``steered`` (alone it streaks).
    bins : int
        Bins per orientation in joint matching.

    Returns
    -------
    numpy.ndarray
        float32 (height, width, C), periodic, within the exemplar's per-channel range.

    References
    ----------
    Forsyth & Ponce, section 11.3.2, Algorithm 11.4 (with Algorithm 11.3, histogram matching);
    Heeger & Bergen 1995; Torralba, Isola & Freeman, section 28.3 (PCA colour, iterations);
    Van De Ville et al. 2009, sections 2.2-2.4, eq. 4 (``steered``, ``joint``).

    Examples
    --------
    >>> import numpy as np, texsynth
    >>> photo = np.random.default_rng(0).random((32, 32, 3), dtype=np.float32)
    >>> out = texsynth.synthesize(photo, 48, 32, method="heeger_bergen", seed=1, scales=2,
    ...                           iterations=2)
    >>> out.shape, bool(photo.min() <= out.min() and out.max() <= photo.max())
    ((32, 48, 3), True)
    """
    channels = exemplar.shape[2]
    # Progress: the exemplar's analysis, the iterations, the final colour transport.
    colour_work = (FINAL_SLICES - SLICES_PER_ITERATION) * SLICE_COST if channels > 1 else 0.0
    split = 0.03 + 0.97 * iterations / (iterations + colour_work / (1 + 2 * SLICE_COST))
    setup, iterating = progress.span(0.0, 0.03), progress.span(0.03, split)
    depth = pyramid_depth(exemplar.shape, width, height, scales)
    setup(0.0, "analysing the exemplar")
    h, w = exemplar.shape[:2]
    sample = exemplar.reshape(-1, channels)[::sample_step(h * w, w, SAMPLES)]
    pca = ColorPCA.fit(sample[None])
    colours = pca.forward(sample)
    pyr_output = SteerablePyramid((height, width), depth, orientations, setup.span(0.0, 0.3))
    tile = (min(height, h), min(width, w))
    pyr_exemplar = (pyr_output if tile == pyr_output.shape else
                    SteerablePyramid(tile, depth, orientations))
    exemplar_bands, pw = _subband_samples(exemplar, pca, pyr_exemplar, setup.span(0.3, 1.0))
    if pyr_exemplar is not pyr_output:
        pw = None
    del pyr_exemplar, sample
    noise = rng.random((height, width, channels), dtype=np.float32)

    work = JointWork(width * height) if joint else None      # reused by every channel and level
    pixels, match_subbands = [], []
    for c in range(channels):
        pixels.append(TargetHistogram(colours[:, c]))
        subbands = exemplar_bands[c]
        match_subbands.append(_OrientedMatch(subbands, steered, bins, work) if steered or joint
                              else _BandMatch(subbands))
        exemplar_bands[c] = None                          # the targets keep their own copies
        setup(1.0, "analysing the exemplar")
    image = np.empty((channels, height, width), np.float32)
    for c in range(channels):
        match(noise[:, :, c], pixels[c], out=image[c])
        iterating(0.0, "matching the noise's histogram")
    synthesized = np.empty((height, width), np.float32)               # reused every step
    for it in range(iterations):
        for c in range(channels):
            message = f"iteration {it + 1}/{iterations}, channel {c + 1}/{channels}"

            def tick(step, it=it, c=c, message=message):
                """Progress within a step (a 4096^2 step runs for seconds): Esc is heard."""
                iterating((it + (c + step) / channels) / iterations, message)

            pw = match_subbands[c].analyze(pyr_output, image[c], lambda: tick(0.25), pw)
            tick(0.5)
            pyr_output.synthesize(pw, lambda: tick(0.5), out=synthesized)
            match(synthesized, pixels[c], out=image[c])
            tick(1.0)
        if channels > 1:
            last = it == iterations - 1
            done = (it + 1) / iterations
            sliced_transfer_rows(image.reshape(channels, -1), colours, rng,
                                 FINAL_SLICES if last else SLICES_PER_ITERATION,
                                 progress.span(split, 1.0) if last else iterating.span(done, done))

    result = np.empty((height, width, channels), np.float32)
    lo, hi = exemplar.min(axis=(0, 1)), exemplar.max(axis=(0, 1))

    def back(a: int) -> None:
        """Rows a.. back to the photo's colours, within its range (every pixel on its own)."""
        b = slice(a, min(a + BACK_ROWS, height))
        result[b] = np.clip(pca.inverse(np.moveaxis(image[:, b], 0, -1)), lo, hi)

    run(back, range(0, height, BACK_ROWS), lambda: progress(1.0, "back to the photo's colours"))
    return result


def _tiles(length: int, size: int) -> list[tuple[int, int, int]]:
    """(start, own_start, own_stop) along one axis: the fewest tiles of ``size`` that cover
    ``length``, evenly spread, tile i owning [i L / n, (i + 1) L / n) (inside it: L <= n size),
    given from the tile's start."""
    n = -(-length // size)
    starts = [0] if n == 1 else [i * (length - size) // (n - 1) for i in range(n)]
    bounds = [i * length // n for i in range(n + 1)]
    return [(s, bounds[i] - s, bounds[i + 1] - s) for i, s in enumerate(starts)]


def _subband_samples(exemplar, pca, pyramid, progress):
    """Per PCA channel, the exemplar's subbands as :class:`Coefficients` of 1-D samples: the
    tiles of ``pyramid``'s shape over the photo (:func:`_tiles`), each tile's principal
    components made periodic and analysed, each band's owned part sampled on a regular lattice
    (every value when the photo's band holds fewer than twice ``SAMPLES``). Also the last
    analysis (its arrays are the pyramid's to reuse)."""
    h, w, channels = exemplar.shape
    tiles = [(rows, columns) for rows in _tiles(h, pyramid.shape[0])
             for columns in _tiles(w, pyramid.shape[1])]
    levels = [0, *(j for j in range(pyramid.scales) for _ in range(pyramid.orientations)),
              pyramid.scales]                                 # of each band, arrays' order
    steps = [sample_step(h * w >> 2 * j, w >> j, SAMPLES) for j in levels]
    pooled = [[[] for _ in levels] for _ in range(channels)]
    coefficients = None
    for t, ((y, y0, y1), (x, x0, x1)) in enumerate(tiles):
        components = pca.forward(exemplar[y:y + pyramid.shape[0], x:x + pyramid.shape[1]])
        for c in range(channels):
            coefficients = pyramid.analyze(periodic_component(components[:, :, c]),
                                           out=coefficients)
            for i, (band, j, k) in enumerate(zip(coefficients.arrays(), levels, steps,
                                                 strict=True)):
                a, b = -(-y0 >> j), -(-y1 >> j)                # ceil: sample i sits at 2^j i
                owned = band[a:b, -(-x0 >> j):-(-x1 >> j)]
                every = k if k == 1 else sample_step(k * SAMPLES, owned.shape[1], SAMPLES)
                pooled[c][i].append(owned.ravel()[::every].copy())
            progress((t * channels + c + 1) / (len(tiles) * channels), "analysing the exemplar")
    return [coefficients.replaced([np.concatenate(p) for p in per_channel])
            for per_channel in pooled], coefficients


class _BandMatch:
    """Heeger and Bergen's matching: every subband (residuals included) alone, 1-D."""

    def __init__(self, exemplar: Coefficients):
        self.targets = [TargetHistogram(band) for band in exemplar.arrays()]

    def analyze(self, pyramid: SteerablePyramid, image: np.ndarray, tick,
                out: Coefficients | None) -> Coefficients:
        """The matched subbands of ``image`` (into ``out``): each band is matched in place by
        the thread that made it, as soon as it is made (one core each, the bands side by
        side); ``tick()`` after each."""
        return pyramid.analyze(image, tick, out,
                               lambda i, band: match(band, self.targets[i], out=band))


class _OrientedMatch:
    """Van De Ville et al. 2009's per-level matching of the K oriented bands (section 2.4),
    exemplar side cached.

    Residuals (high-pass, low-pass) keep the 1-D matching.
    """

    def __init__(self, exemplar: Coefficients, steered: bool, bins: int,
                 work: JointWork | None):
        k = len(exemplar.bands[0]) if exemplar.bands else 1
        self.steering = Steering(k) if steered else None
        self.work = work                                   # joint matching when given
        self.highpass = TargetHistogram(exemplar.highpass)
        self.lowpass = TargetHistogram(exemplar.lowpass)
        self.angles = []
        self.levels = []
        for level in exemplar.bands:
            w = np.stack(level)
            if steered:
                theta = self.steering.optimal_angle(w)
                self.angles.append(TargetHistogram(theta))
                w = self.steering.steer(w, theta)
            self.levels.append(JointTarget(w, bins) if work is not None else
                               [TargetHistogram(band) for band in w])

    def analyze(self, pyramid: SteerablePyramid, image: np.ndarray, tick,
                out: Coefficients | None) -> Coefficients:
        """The subbands of ``image`` (into ``out``), then each level matched; ``tick()`` after
        each band and level."""
        return self(pyramid.analyze(image, tick, out), tick)

    def __call__(self, pw: Coefficients, tick=None) -> Coefficients:
        bands = []
        for j, level in enumerate(pw.bands):
            if tick is not None:
                tick()
            w = np.stack(level)
            if self.steering is not None:
                theta = self.steering.optimal_angle(w)
                theta_new = match(theta, self.angles[j])
                w = self.steering.steer(w, theta)
            if self.work is not None:
                w = match_joint(w, self.levels[j], self.work)
            else:
                w = np.stack([match(band, t) for band, t in zip(w, self.levels[j], strict=True)])
            if self.steering is not None:
                w = self.steering.steer(w, -theta_new)
            bands.append(list(w))
        return Coefficients(match(pw.highpass, self.highpass), bands,
                            match(pw.lowpass, self.lowpass))


def _kept(n: int) -> int:
    """Values a target keeps of a band of ``n`` (every one, or about ``SAMPLES``)."""
    return n if n < 2 * SAMPLES else n // (n // SAMPLES)


def _analysed(shape, width, height, params):
    """The exemplar's analysis: (tile pixels, tiles, whether the tile has a pyramid of its own,
    the values one channel's targets keep: its pixels and every subband)."""
    h, w = shape[:2]
    k, depth = params["orientations"], pyramid_depth(shape, width, height, params["scales"])
    tile = (min(height, h), min(width, w))
    tiles = -(-h // tile[0]) * -(-w // tile[1])
    bands = [h * w, h * w, *(h * w >> 2 * j for j in range(depth) for _ in range(k)),
             h * w >> 2 * depth]
    return tile[0] * tile[1], tiles, tile != (height, width), sum(_kept(n) for n in bands)


def _memory(shape, width, height, params):
    """Per output pixel: the noise, the working image and the result (C floats each), one
    channel's pyramid, the synthesis' subband spectra (116 B at C = 3, K = 4; tracemalloc's
    peak at 1024^2 from a 1024^2 crop, and at 2048^2 from the crop and from the 12 MP photo:
    269, 659 and 761 MiB, this estimate 1.11-1.13 times them; with 86 B more of spectra and
    margin it was 1.23-1.56 times). Per pixel of the exemplar's sample: the sample and its
    principal components while the targets are made (56 B, the same fit).

    Steering and joint matching add their level-0 work arrays (tracemalloc at 1024^2 output:
    +37 B per output pixel steered, +102 joint, +130 both) and joint the exemplar's cell tables.
    The exemplar's share: a tile's principal components and periodic component (and, when the
    tile is not the output's size, its own pyramid's filters and spectra), every channel's kept
    target values (sorted), the fast matching's histogram tables
    (``BINS`` each); tests/test_contract.py holds the estimate above the measured peak.
    """
    k, c = params["orientations"], shape[2]
    per_pixel = 24 * c + 4 * (k * 4 / 3 + 3) + 4 * k * 2 / 3
    per_pixel += (105 if params.get("joint") else 0) + (30 if params.get("steered") else 0)
    tile, _, own, values = _analysed(shape, width, height, params)
    per_tile = 12 * c + (8 * (k * 4 / 3 + 6) if own else 0)
    joint = 16 * k * _kept(shape[0] * shape[1]) if params.get("joint") else 0
    sample = shape[0] * shape[1] // sample_step(shape[0] * shape[1], shape[1], SAMPLES)
    return (per_pixel * width * height + per_tile * tile + 4 * c * values + joint
            + 56 * sample + 64 * BINS)


def _cost(shape, width, height, params):
    """Seconds on the reference machine (``texsynth.budget``): per iteration, one analysis and
    synthesis of the output and the matching of its bands (output pixels x C x (K + 1)); once,
    the exemplar's tiles made periodic and analysed (tile pixels x C), a tile's own pyramid,
    the kept target values sorted; each colour transport step's sorted target projections and
    tables, a constant a step. Fitted on one quiet machine (factor 0.29-0.32) at 512^2 to
    4096^2 outputs: 1.6-1.9, 4.4 (5.1-5.4 from a 1024^2 exemplar), 13.5-15.0 and 53.5 s, all
    within 15 %; the exemplar's share on the 12 MP photo. Steered and joint matching: factors
    1.3 and 2, not fitted. The transport steps' constant refitted (issue 45: 0.038 s had told
    0.57 of 512^2 and 4096 x 64 from 128^2, quiet 2.1 and 2.2 s)."""
    c = shape[2]
    k, iterations = params["orientations"], params["iterations"]
    extra = (2.0 if params.get("joint") else 1.0) * (1.3 if params.get("steered") else 1.0)
    steps = FINAL_SLICES + SLICES_PER_ITERATION * (iterations - 1) if c > 1 else 0
    tile, tiles, own, values = _analysed(shape, width, height, params)
    exemplar = 1.6e-7 * tiles * tile * c + 5e-7 * tile * own + 1e-7 * values * c * extra
    return (0.02 + iterations * 4.5e-8 * width * height * c * (k + 1) * extra + exemplar
            + 0.073 * steps)


METHOD = register(Method(
    name="heeger_bergen",
    label="Heeger-Bergen",
    description="Match the histograms of steerable-pyramid subbands (Heeger & Bergen 1995): "
                "fast, best on stochastic textures such as sand, gravel, stucco, clouds",
    function=heeger_bergen,
    params=(
        Param("scales", int, 4, "Pyramid levels (capped by exemplar and output sizes)", 1, 8),
        Param("orientations", int, 4, "Oriented subbands per level (K)", 1, 8),
        Param("iterations", int, 15, "Rounds of subband and pixel histogram matching", 1, 100),
        Param("steered", bool, False, "Match each level's bands turned to their orientation of "
              "maximal response, and the distribution of that orientation (Van De Ville et al. "
              "2009): crisper edges"),
        Param("joint", bool, False, "Match the joint histogram of each level's orientations "
              "(conditional matching) instead of each band alone; use with Steered (alone it "
              "streaks)"),
        Param("bins", int, 50, "Bins per orientation in joint matching", 2, 256),
    ),
    min_exemplar=8,
    memory=_memory,
    cost=_cost,
))

"""The pairwise clique model (Zalesny et al. 2002, section 2): the ``cooccurrence`` method.

Everything of the method lives in this package:

- ``cliques.py``: clique types, difference histograms, the stochastic relaxation;
- ``model.py``: clique-type selection (steps 1-7), the model and its file, synthesis from it;
- here: the registered method (fit, then relax from the model) and the public names ``fit``
  and ``Model`` (fit once, then ``model.synthesize`` at any size without the exemplar).

Deviation (production sizes, multiresolution relaxation): an output of more than
``COARSE_PIXELS`` pixels is first synthesized at half size from the exemplar block-averaged by 2
(recursively), upsampled (periodic Fourier resampling), and relaxed from there for
``REFINE_SWEEPS`` sweeps instead of ``sweeps`` from noise: the coarse level lays out the large
scales, the fine sweeps restore the fine-scale statistics, by proposals of one level's step or
from the singleton target, each clipped to the range of the pixel's 8 neighbours
(``model.synthesize_channel``: unbounded ones left isolated extreme pixels, salt and pepper).

References
----------
Zalesny et al. 2002, section 2 (the pairwise clique model, clique-type selection).
"""

from __future__ import annotations

import numpy as np

from ...registry import Method, register
from .cliques import CHUNK
from .model import (
    LEVELS,
    MAX_CLIQUES,
    MAX_OFFSET,
    PARAMS,
    SELECTION_SIZE,
    SWEEPS,
    THRESHOLD,
    TYPICAL_TYPES,
    Model,
    fit,
    fit_share,
    relax,
    sampled_pixels,
)
from .model import cost as model_cost

__all__ = ["Model", "fit", "METHOD", "COARSE_PIXELS", "REFINE_SWEEPS"]

#: Outputs larger than this (pixels) start from a half-size synthesis.
COARSE_PIXELS = 512 * 512
#: Sweeps at a level that starts from the coarser level's result.
REFINE_SWEEPS = 3
#: (set pixels x columns) / output pixels of the relaxation's largest chunk (``_memory``).
SET_COLUMNS = 2.5


def cooccurrence(exemplar, width, height, rng, progress, max_offset=MAX_OFFSET,
                 threshold=THRESHOLD, max_cliques=MAX_CLIQUES, levels=LEVELS, sweeps=SWEEPS):
    """Fit the clique model of ``exemplar`` and synthesize (height, width, C) from it by
    stochastic relaxation (see ``model.py``).

    Parameters
    ----------
    exemplar : float32 array (H, W, C)
        The sample, validated by ``texsynth.synthesize``.
    width, height : int
        The output size, larger or smaller than the exemplar.
    rng, progress : numpy.random.Generator, texsynth.progress.Progress
        The seeded generator and the progress reporter ``texsynth.synthesize`` makes.
    max_offset : int
        Longest clique type considered (pixels).
    threshold : float
        Stop adding clique types when the worst histogram distance is below this.
    max_cliques : int
        Most clique types per colour component.
    levels : int
        Grey levels of the strongest colour component.
    sweeps : int
        Relaxation sweeps over the output.

    Returns
    -------
    numpy.ndarray
        float32 (height, width, C), periodic, within the exemplar's range.

    References
    ----------
    Zalesny et al. 2002, section 2 (the pairwise clique model, clique-type selection steps
    1-7, synthesis by relaxation).

    Examples
    --------
    >>> import numpy as np, texsynth
    >>> photo = np.random.default_rng(0).random((16, 16, 3), dtype=np.float32)
    >>> out = texsynth.synthesize(photo, 24, 24, method="cooccurrence", seed=1, sweeps=2,
    ...                           max_cliques=4)
    >>> out.shape, bool(photo.min() <= out.min() and out.max() <= photo.max())
    ((24, 24, 3), True)
    """
    params = dict(max_offset=max_offset, threshold=threshold, max_cliques=max_cliques,
                  levels=levels)
    start = None
    if width * height > COARSE_PIXELS and min(exemplar.shape[:2]) >= 32:
        progress(0.0, "halving the exemplar")
        h, w = exemplar.shape[0] // 2, exemplar.shape[1] // 2
        half = exemplar[:2 * h, :2 * w].reshape(h, 2, w, 2, -1).mean(axis=(1, 3))
        coarse_share = _cost(half.shape, -(-width // 2), -(-height // 2),
                             {**params, "sweeps": sweeps}) \
            / _cost(exemplar.shape, width, height, {**params, "sweeps": sweeps})
        coarse = cooccurrence(half, -(-width // 2), -(-height // 2), rng,
                              progress.span(0.0, coarse_share), sweeps=sweeps, **params)
        start = upsample_half(coarse, height, width, lambda: progress(
            coarse_share, "upsampling the half-size synthesis"))
        sweeps = min(sweeps, REFINE_SWEEPS)
        progress = progress.span(coarse_share, 1.0)
    # the fit's share of the progress by the cost model: a fixed 0.3 had told 30 % at a
    # fifth of the time, or at half of it, as the output's size went
    fitted = fit_share(exemplar.shape, width, height, {**params, "sweeps": sweeps})
    model = fit(exemplar, seed=rng, progress=progress.span(0.0, fitted), **params)
    return relax(model, width, height, rng, progress.span(fitted, 1.0), sweeps, start)


def upsample_half(coarse: np.ndarray, height: int, width: int, tick) -> np.ndarray:
    """The half-size result ``coarse`` (h, w, C) stretched over (height, width) on the torus:
    its Fourier series evaluated on the finer grid (``scipy.signal.resample``, periodic), a
    factor 2 for even sides and just under it for odd ones; channel by channel, ``tick()``
    before each. Bilinear interpolation at half-pixel phase makes every other line's jump
    about a fifth larger (a two-pixel grid the refinement keeps, the wrap on a larger line);
    a periodic resampling is the same at every pixel."""
    from scipy.signal import resample  # here: importing scipy.signal (and scipy.stats with
    # it) took 0.9 of texsynth's 2.2 s import, paid by every command and batch worker

    start = np.empty((height, width, coarse.shape[2]), np.float32)
    for c in range(coarse.shape[2]):
        tick()
        rows = resample(np.asarray(coarse[:, :, c], np.float32), height, axis=0)
        start[:, :, c] = resample(rows, width, axis=1)
    return start


def _cost(shape, width, height, params):
    """The model's cost (fit and synthesis, ``model.cost``) at every level of the
    multiresolution relaxation: ``REFINE_SWEEPS`` above ``COARSE_PIXELS``, ``sweeps`` at the
    coarsest level."""
    total = 0.0
    while width * height > COARSE_PIXELS and min(shape[:2]) >= 32:
        total += model_cost(shape, width, height,
                            {**params, "sweeps": min(params["sweeps"], REFINE_SWEEPS)})
        shape = (shape[0] // 2, shape[1] // 2, shape[2])
        width, height = -(-width // 2), -(-height // 2)
    return total + model_cost(shape, width, height, params)


def _memory(shape, width, height, params):
    """The larger of two phases, beside the half-size exemplar and 3 MiB: the fit (the
    exemplar's statistics: the sampled strips' colours and components, float32, and one
    channel's marks; the half-size synthesis' upsampled start is kept meanwhile; and the
    selection: every candidate type's pairs on the selection torus, at most
    ``SELECTION_SIZE`` square) and the synthesis (padded image, colouring and float output per
    pixel, and a set's chunk of accepted pixels with their columns' neighbour codes and the
    two counts' differences: three int64 arrays). One line each:

    - a chunk is a colour set's pixels, at most ``CHUNK``; a set times its columns is about
      ``SET_COLUMNS`` a pixel (the colouring takes about as many sets as half the columns: 15
      sets for 34 columns, 8 for 26, 2 for 4 at 256^2), where T columns a pixel had counted
      every output pixel in one set (4.5x the resident peak at 64 -> 256);
    - the phases do not overlap: tracemalloc's peak from the 12 MP photo and from its 1024^2
      crop to 2048^2 is 473 and 442 MiB (31 MiB apart, the half-size exemplar), this estimate
      1.12 times both (the phases summed: 1.65 from 12 MP);
    - the selection's pairs are freed, back to the system, before the synthesis (issue 45):
      from 64^2 the fit's resident peak is 14.2 MiB (this model's 14.4) and the synthesis'
      9.8 and 16.7 MiB at 256^2 and 4096 x 32 (7.5, 15.0); counted beside the synthesis, the
      selection had read 1.25 and 1.51 times the runs' resident peaks (17 and 19 MiB), now
      1.02 and 0.95;
    - 3 MiB: a run's resident peak over its largest phase's (2.3-2.8 MiB at 64^2 -> 256^2
      and 4096 x 32, 2 at 16^2 -> 16^2: the pool's threads, first calls' caches)."""
    t = 2 * min(params["max_cliques"], TYPICAL_TYPES)
    candidates = ((2 * params["max_offset"] + 1) ** 2 - 1) // 2
    torus = min(shape[0], SELECTION_SIZE) * min(shape[1], SELECTION_SIZE)
    selection = candidates * torus * 24
    chunk = min(CHUNK * t, SET_COLUMNS * width * height) * 8 * 3
    synthesis = width * height * (4 * 6 + 3 * 4 * shape[2]) + chunk
    statistics = sampled_pixels(shape, params["max_offset"]) * (8 * shape[2] + 4) \
        + 4 * shape[2] * width * height
    return shape[0] * shape[1] * shape[2] + max(synthesis, statistics + selection) + (3 << 20)


METHOD = register(Method(
    name="cooccurrence",
    label="Clique model",
    description="Pairwise clique model (Zalesny & Van Gool): a few KB of difference histograms "
                "of selected pixel pairs, synthesized by stochastic relaxation; never copies "
                "the exemplar; best on fine stochastic textures",
    function=cooccurrence,
    params=PARAMS,
    min_exemplar=8,
    memory=_memory,
    cost=_cost,
))

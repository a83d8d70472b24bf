"""The pairwise clique model as a registered method: fit, then synthesize from the model.

Paper 004, section 2 (steps 1-7); the model, its selection, its synthesis and its file live in
texsynth.cooccurrence (fit once and synthesize at any size without the exemplar there).
"""

from __future__ import annotations

from .. import cooccurrence as co
from ..registry import Method, Param, register

__all__ = ["cooccurrence"]


def cooccurrence(exemplar, width, height, rng, progress, max_offset=co.MAX_OFFSET,
                 threshold=co.THRESHOLD, max_cliques=co.MAX_CLIQUES, levels=co.LEVELS,
                 sweeps=co.SWEEPS):
    """Fit the clique model of ``exemplar`` and synthesize (height, width, C) from it."""
    model = co.fit(exemplar, max_offset, threshold, max_cliques, levels, seed=rng,
                   progress=progress.span(0.0, 0.3))
    return co.synthesize(model, width, height, rng, sweeps, progress.span(0.3, 1.0))


def _memory(shape, width, height, params):
    """Padded image, per-set (pixels x 2T) gathers, a colouring and the float output."""
    t = 2 * params["max_cliques"]
    return width * height * (4 * 6 + 3 * 4 * shape[2]) + 16 * t * width * height / 4


register(Method(
    name="cooccurrence",
    label="Clique model",
    description="Pairwise clique model (Zalesny & Van Gool): a few KB of difference histograms "
                "of selected pixel pairs, synthesized by stochastic relaxation; never copies "
                "the exemplar; best on fine stochastic textures",
    function=cooccurrence,
    params=(
        Param("max_offset", int, co.MAX_OFFSET, "Longest clique type considered (pixels)", 1, 16),
        Param("threshold", float, co.THRESHOLD,
              "Stop adding clique types when the worst histogram distance is below this",
              0.001, 1.0),
        Param("max_cliques", int, co.MAX_CLIQUES, "Most clique types per colour component",
              1, 100),
        Param("levels", int, co.LEVELS, "Grey levels of the strongest colour component", 4, 128),
        Param("sweeps", int, co.SWEEPS, "Relaxation sweeps over the output", 1, 500),
    ),
    min_exemplar=8,
    memory=_memory,
    reference="Zalesny & Van Gool, Composite texture descriptions, sec. 2 (paper 004)",
))

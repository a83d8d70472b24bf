"""Cost models: each method's run time in seconds on the reference machine (``Method.cost``).

Each model counts the work of the method's inner loops (the patch searches' matrix products,
the pyramids' FFTs, the relaxations' gathers) in units, and converts units to seconds with
coefficients fitted by least squares to runs measured on the reference machine
(``python -m benchmarks.cost_models`` measures, predicts at sizes not fitted on, and prints
both; :mod:`texsynth.budget` scales a prediction to the machine it runs on). A prediction is
good to about a factor of two: enough to say "12 s" or "5 h", not to time a run.

``shape`` is the exemplar's (H, W, C), ``params`` the method's resolved parameters.
"""

from __future__ import annotations

from .blocks.search import disk_offsets

__all__ = ["heeger_bergen", "efros_leung", "multiscale_mrf", "de_bonet", "cooccurrence",
           "cooccurrence_synthesis", "composite"]

#: Selection torus side and sweeps of the clique model (``cooccurrence.model``).
_SELECTION_SIZE, _SELECTION_SWEEPS = 64, 6
#: Clique types a natural texture's selection typically ends with.
TYPICAL_TYPES = 20


def heeger_bergen(shape, width, height, params):
    """Per iteration, one pyramid analysis and synthesis of the output and the histogram
    matching of each band (K + 1 band images of the output's size per channel) against the
    exemplar's sorted values. Steered and joint matching: factors 1.3 and 2, not fitted."""
    h, w, c = shape
    k = params["orientations"]
    per_iteration = 5.0e-8 * width * height * c * (k + 1) + 1.3e-6 * h * w * c
    extra = (2.0 if params.get("joint") else 1.0) * (1.3 if params.get("steered") else 1.0)
    return 0.02 + params["iterations"] * per_iteration * extra


def efros_leung(shape, width, height, params):
    """Every output pixel's window against every exemplar window: the 7 x 7 lower bound's matrix
    product over (C + 1) planes (values and mask), plus per-pixel bookkeeping."""
    h, w, c = shape
    k = params["window"]
    windows = h * w if params["exemplar_tiles"] else max(1, h - k + 1) * max(1, w - k + 1)
    units = width * height * windows * min(k, 7) ** 2 * (c + 1)
    return 0.05 + 3.4e-10 * units + 2.0e-5 * width * height


def multiscale_mrf(shape, width, height, params):
    """Per visit of an output pixel (4/3 for the coarser levels), each candidate's disk
    neighbourhood compared over C + 1 values; plus the exemplar table of every level."""
    h, w, c = shape
    k = len(disk_offsets(params["radius"]))
    candidates = params["random_candidates"] + 6
    units = width * height * 4 / 3 * params["visits"] * k * (c + 1) * candidates
    return 0.1 + 5.1e-9 * units + 2.0e-7 * h * w * k * c


def de_bonet(shape, width, height, params):
    """Per output location, a parent-structure query of a kd-tree (about ``depth`` ancestors of
    K + 1 values per channel); per exemplar location, the pyramids and the tree's build."""
    h, w, c = shape
    k, depth = params["orientations"], params["depth"]
    spread = (1.0 + params["threshold"]) ** 2
    return (0.03 + 9.0e-7 * width * height * spread * (1 + depth * (k + 1) * c / 15)
            + 4.0e-7 * h * w * depth * (k + 1) * c)


def cooccurrence(shape, width, height, params):
    """Selection: a round of sweeps over the selection torus per selected type and colour
    component; synthesis: ``sweeps`` over the output with every selected type from both ends.
    Selection stops at the threshold, after about ``TYPICAL_TYPES`` types on natural
    textures (measured: ``max_cliques`` 20 and 40 take about the same time)."""
    h, w, c = shape
    t = min(params["max_cliques"], TYPICAL_TYPES)
    torus = min(h, _SELECTION_SIZE) * min(w, _SELECTION_SIZE)
    selection = c * t * _SELECTION_SWEEPS * torus
    return 0.05 + 2.3e-6 * selection + cooccurrence_synthesis(c, t, width, height,
                                                              params["sweeps"])


def cooccurrence_synthesis(channels, types, width, height, sweeps):
    """Synthesis from a fitted clique model: ``sweeps`` over the output per channel, every
    selected type looked at from both ends."""
    return 2.7e-8 * channels * sweeps * width * height * (2 + types)


def composite(shape, width, height, params):
    """Segmentation, then a clique model per class (each over its share of the output, with
    interactions) and the label texture: measured about 3 single clique models."""
    return 0.5 + 3.0 * cooccurrence(shape, width, height, params)

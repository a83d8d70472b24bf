"""Composite textures (Zalesny et al. 2002, sections 1, 3 and 4): the ``composite`` method.

Everything of the method lives in this package:

- ``segmentation.py``: unsupervised segmentation of the exemplar into subtextures (section 3),
  and label images painted by a user;
- ``synthesis.py``: the label texture, the subtextures with their interactions (section 4), and
  :func:`synthesize`, which takes label images too;
- here: the registered method. ``texsynth.synthesize`` passes scalar parameters only, so it
  covers the fully automatic case (unsupervised segmentation, synthesized label map); a painted
  label image of the exemplar or an output label map go through ``texsynth.composite.synthesize
  (exemplar, width, height, labels=..., output_labels=...)``, which the Blender composite
  operator calls.
"""

from __future__ import annotations

from ...registry import Method, Param, methods, register
from ..cooccurrence import METHOD as CLIQUE_MODEL
from ..cooccurrence import model as co
from . import segmentation
from .segmentation import CONTRAST
from .synthesis import INTERACTION_DISTANCE, Composite, synthesize

__all__ = ["Composite", "synthesize", "segmentation", "METHOD"]


def composite(exemplar, width, height, rng, progress, fill="cooccurrence",
              interaction_distance=INTERACTION_DISTANCE, max_offset=co.MAX_OFFSET,
              threshold=co.THRESHOLD, max_cliques=co.MAX_CLIQUES, levels=co.LEVELS,
              sweeps=co.SWEEPS, label_scale=0, contrast=CONTRAST, texture_features=False):
    """Segment ``exemplar``, synthesize a label map and fill it (height, width, C)."""
    return synthesize(exemplar, width, height, fill=fill, seed=int(rng.integers(2**31)),
                         progress=progress, interaction_distance=interaction_distance,
                         max_offset=max_offset, threshold=threshold, max_cliques=max_cliques,
                         levels=levels, sweeps=sweeps, label_scale=label_scale,
                         contrast=contrast, texture_features=texture_features).image


def _memory(shape, width, height, params):
    """The clique model's working set, the label maps, and which (term, end) columns each
    pixel takes part in (2 bytes per selected type and pixel)."""
    return (CLIQUE_MODEL.memory(shape, width, height, params)
            + (16 + 2 * params["max_cliques"]) * width * height)


METHOD = register(Method(
    name="composite",
    label="Composite",
    description="Composite texture (Zalesny & Van Gool): segment the exemplar into subtextures, "
                "synthesize their layout as a label texture, fill each region with its own "
                "subtexture, with interactions across boundaries; for marble, terrain, "
                "mixtures of materials",
    function=composite,
    params=(
        Param("fill", str, "cooccurrence", "Method that fills each region (clique model: with "
              "interactions)", choices=("cooccurrence",) + tuple(
                  m.name for m in methods() if m.name not in ("composite", "cooccurrence"))),
        Param("interaction_distance", int, INTERACTION_DISTANCE,
              "Reach of the cliques across subtexture boundaries (0: none)", 0, 8),
        Param("max_offset", int, co.MAX_OFFSET, "Longest clique type considered (pixels)", 1, 16),
        Param("threshold", float, co.THRESHOLD,
              "Stop adding clique types when the worst histogram distance is below this",
              0.001, 1.0),
        Param("max_cliques", int, co.MAX_CLIQUES, "Most clique types per subtexture and "
              "colour component", 1, 100),
        Param("levels", int, co.LEVELS, "Grey levels of the strongest colour component", 4, 128),
        Param("sweeps", int, co.SWEEPS, "Relaxation sweeps over the output", 1, 500),
        Param("label_scale", int, 0, "Scale at which the label map is modelled (0: automatic)",
              0, 8),
        Param("contrast", float, CONTRAST, "Segmentation: colour difference (Lab) below which "
              "regions join one class; larger gives fewer classes (0: automatic, the largest "
              "of 6, 3, 2 that finds two classes)", 0.0, 100.0),
        Param("texture_features", bool, False, "Segmentation: add filter-bank texture features "
              "to the colour"),
    ),
    min_exemplar=16,
    memory=_memory,
))

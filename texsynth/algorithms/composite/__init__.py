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

from ...registry import Method, register
from ..cooccurrence import model as co
from . import segmentation, synthesis
from .segmentation import CONTRAST
from .synthesis import INTERACTION_DISTANCE, MIN_EXEMPLAR, PARAMS, Composite, memory, synthesize

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


METHOD = register(Method(
    name="composite",
    label="Composite",
    description="Composite texture (Zalesny & Van Gool): segment the exemplar into subtextures, "
                "synthesize their layout as a label texture, fill each region with its own "
                "subtexture, with interactions across boundaries; for marble, terrain, "
                "mixtures of materials",
    function=composite,
    params=PARAMS,
    min_exemplar=MIN_EXEMPLAR,
    memory=memory,
    cost=synthesis.cost,
))

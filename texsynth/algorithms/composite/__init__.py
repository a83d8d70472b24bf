"""Composite textures (Zalesny et al. 2002, sections 1, 3 and 4): the ``composite`` method.

Everything of the method lives in this package:

- ``segmentation.py``: unsupervised segmentation of the exemplar into subtextures (section 3),
  and label images painted by a user;
- ``synthesis.py``: the label texture, the subtextures with their interactions (section 4),
  the registered method's function ``composite`` and :func:`compose`;
- here: the registration. ``texsynth.synthesize(..., method="composite")`` takes the method's
  scalar parameters, so it covers the fully automatic case (unsupervised segmentation,
  synthesized label map) and gives the image; ``texsynth.composite.compose(exemplar, width,
  height, labels=..., output_labels=...)`` takes a painted label image of the exemplar or an
  output label map and gives the label maps beside the image (the Blender composite operator
  calls it).

References
----------
Zalesny et al. 2002, sections 1, 3 (segmentation) and 4 (label texture, subtexture
interactions).
"""

from __future__ import annotations

from ...registry import Method, register
from . import segmentation, synthesis
from .synthesis import MIN_EXEMPLAR, PARAMS, Composite, compose, composite, memory

__all__ = ["Composite", "compose", "segmentation", "METHOD"]


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

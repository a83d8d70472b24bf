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

References
----------
Zalesny et al. 2002, sections 1, 3 (segmentation) and 4 (label texture, subtexture
interactions).
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
    """Segment ``exemplar`` into subtextures, synthesize a label map and fill each region
    (height, width, C) (see ``synthesis.py``).

    Parameters
    ----------
    exemplar : float32 array (H, W, C)
        The sample, validated by ``texsynth.synthesize``.
    width, height : int
        The output size, larger or smaller than the exemplar.
    rng, progress : numpy.random.Generator, texsynth.progress.Progress
        The seeded generator and the progress reporter ``texsynth.synthesize`` makes.
    fill : str
        Method that fills each region (``cooccurrence``, the clique model, with interactions;
        or another registered method but ``composite``).
    interaction_distance : int
        Reach of the cliques across subtexture boundaries (0: none).
    max_offset : int
        Longest clique type considered (pixels).
    threshold : float
        Stop adding clique types when the worst histogram distance is below this.
    max_cliques : int
        Most clique types per subtexture and colour component.
    levels : int
        Grey levels of the strongest colour component.
    sweeps : int
        Relaxation sweeps over the output.
    label_scale : int
        Scale at which the label map is modelled (0: automatic).
    contrast : float
        Segmentation: colour difference (Lab) below which regions join one class; larger gives
        fewer classes (0: automatic, the largest of 6, 3, 2 that finds two classes).
    texture_features : bool
        Segmentation: add filter-bank texture features to the colour.

    Returns
    -------
    numpy.ndarray
        float32 (height, width, C), periodic.

    References
    ----------
    Zalesny et al. 2002, section 3 (the segmentation), section 4 (the label texture and the
    subtextures' interactions) and section 2 (the clique model that fills them).

    Examples
    --------
    A dark and a light subtexture side by side: the output holds both, in like shares.

    >>> import numpy as np, texsynth
    >>> grain = 0.05 * np.random.default_rng(0).random((24, 24, 3), dtype=np.float32)
    >>> photo = grain + np.where(np.arange(24) < 12, 0.2, 0.8).astype(np.float32)[:, None]
    >>> out = texsynth.synthesize(photo, 24, 24, method="composite", seed=1, sweeps=1,
    ...                           max_cliques=2, max_offset=2)
    >>> out.shape, 0.25 < float((out[..., 0] < 0.5).mean()) < 0.75
    ((24, 24, 3), True)
    """
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

"""The signed distance to a photo's joints, as an extra channel that neighbourhood matching reads.

Lefebvre & Hoppe 2006, "Appearance-space texture synthesis", 4 ("feature distance"): where a
texture's structure is a network of features (here the joints between bricks, setts, blocks:
``texsynth.blocks.joints``), a channel holding each pixel's signed distance to the nearest
feature edge is added to the exemplar, so a neighbourhood compares not only colours but where
it lies inside its element. A coarse level's box means average a joint a few pixels wide away;
the distance varies at the scale of the element and survives them, so the coarse levels place
elements whole and the finer levels, matching the same channel, continue joints rather than
end them inside an element. The synthesis runs on the augmented exemplar; the output copies
the photo's own pixels at the positions found (the channel is never shown).

The joints' width, when the caller gives none (0), is measured: twice the half width
``texsynth.blocks.joints.joint_scale`` reads, and no channel where it finds no joint network
(a stochastic photo: the method's path is then exactly the one without the channel).

A second channel (ours) holds the same distance saturated at a joint width, ``tanh(d / w)``:
a step at each joint's edge. Clipped at the centres of large elements, the first channel's
spread is the elements' size, and where two copies meet beside a joint a mismatch of a few
pixels costs little; so at the finest levels a joint ended, or ran doubled beside another a
few pixels off, where copies met (seen at full resolution on the ashlar blocks and the
flagstones). The saturated channel costs a joint's whole contrast there. Dead-end ratio,
``multiscale_mrf`` 512 -> 1024, seeds 0-2 (``benchmarks.sections.elements``' photos, the
joints' width measured), the distance alone / both: concrete pavers 1.67, 1.80, 1.53 / 1.43,
1.62, 1.23; flagstones 1.74, 2.40, 2.10 / 1.96, 1.28, 1.45; ashlar blocks 1.34, 1.21, 1.29 /
1.28, 0.89, 0.99. Both summed into one channel instead: pavers seed 0 1.83.

Deviations, one line each:
- the saturated distance is a second feature channel (Lefebvre & Hoppe use the distance alone);
- the distance is the Euclidean distance transform of the joint mask at the joints' working
  scale (positive inside elements, negative inside joints), resampled to the photo;
- it is clipped at the ``QUANTILE`` of its magnitude and scaled so its standard deviation is
  ``weight`` times the colours' (the root of the channels' summed variances): L&H set the
  feature channel's weight by hand.
"""

from __future__ import annotations

import numpy as np
from scipy import ndimage

from .joints import Joints, joint_scale, luma

__all__ = ["feature_distance", "fit", "augment", "working_shape"]

#: The distance's magnitude above this quantile is clipped (the centres of large elements).
QUANTILE = 0.98
#: Channels added: the clipped distance and the distance saturated at a joint width.
CHANNELS = 2


def feature_distance(photo: np.ndarray, joints: Joints,
                     mask: np.ndarray | None = None) -> np.ndarray:
    """The signed distance (photo pixels, float32, ``photo``'s height x width) from each pixel
    to the nearest edge of ``photo``'s joints (``mask``, or ``joints.mask(photo)``): positive
    inside elements, negative in joints.

    References
    ----------
    Lefebvre & Hoppe 2006, "Appearance-space texture synthesis", 4.

    Examples
    --------
    >>> i, j = np.mgrid[:96, :128]
    >>> wall = np.where((i % 16 < 3) | ((j + 16 * (i // 16 % 2)) % 32 < 3), 0.2, 0.7)
    >>> d = feature_distance(wall, Joints.fit(wall, sigma=1.5))
    >>> bool(d[1, 10] < 0 < d[8, 10]), bool(d[8, 10] > d[5, 10])
    (True, True)
    """
    mask = joints.mask(photo) if mask is None else mask
    inside = ndimage.distance_transform_edt(~mask) - ndimage.distance_transform_edt(mask)
    h, w = photo.shape[:2]
    zoom = (h / mask.shape[0], w / mask.shape[1])
    d = ndimage.zoom(inside.astype(np.float32) * joints.f, zoom, order=1, mode="nearest",
                     grid_mode=True)
    return d[:h, :w]


def fit(photo: np.ndarray, joint_width: float, weight: float) -> Joints | None:
    """The rule reading ``photo``'s joints ``joint_width`` pixels wide (at half that width,
    ``Joints.fit``; 0: the width ``joint_scale`` measures), or None when ``weight`` is 0 or the
    photo has no joint network (a flat photo, none measured).

    Raises ValueError when the joints are wider than an eighth of the shorter side.

    Examples
    --------
    >>> i, j = np.mgrid[:96, :128]
    >>> wall = np.where((i % 16 < 3) | ((j + 16 * (i // 16 % 2)) % 32 < 3), 0.2, 0.7)
    >>> fit(wall, 3.0, 2.0).sigma, fit(wall, 3.0, 0.0)
    (1.5, None)
    """
    if weight <= 0:
        return None
    h, w = photo.shape[:2]
    flat = np.ptp(luma(photo)) == 0  # a flat photo has no joints (and no threshold)
    if joint_width <= 0:
        sigma = None if flat else joint_scale(photo)
        if sigma is None:
            return None
        joint_width = 2 * sigma
    if joint_width > min(h, w) / 8:
        raise ValueError(f"a joint width of {joint_width:g} px is too wide for the {w} x {h} "
                         f"exemplar: at most an eighth of its shorter side ({min(h, w) / 8:g} "
                         "px), or 0 to measure it")
    return None if flat else Joints.fit(photo, joint_width / 2)


def augment(photo: np.ndarray, joint_width: float, weight: float,
            joints: Joints | None = None) -> np.ndarray:
    """``photo`` (H, W, C) with its feature distance ``d`` to the joints ``joint_width`` (``w``)
    pixels wide (read at half that width, ``Joints.fit``; 0: the width ``joint_scale``
    measures; or the ``joints`` :func:`fit` gave) as channel C + 1, clipped at its
    ``QUANTILE``, and ``tanh(d / w)`` as channel C + 2, each scaled to ``weight`` times the
    colours' standard deviation; ``photo`` itself (the same array) when ``weight`` is 0 or no
    joints are found (nothing changes).

    Raises ValueError when the joints are wider than an eighth of the shorter side.

    Examples
    --------
    >>> i, j = np.mgrid[:96, :128]
    >>> wall = np.where((i % 16 < 3) | ((j + 16 * (i // 16 % 2)) % 32 < 3), 0.2, 0.7)
    >>> wall = np.repeat(wall[:, :, None], 3, axis=2).astype(np.float32)
    >>> augment(wall, 3.0, 2.0).shape, augment(wall, 0.0, 2.0).shape  # given, measured
    ((96, 128, 5), (96, 128, 5))
    >>> augment(wall, 3.0, 0.0) is wall
    True
    >>> gravel = np.random.default_rng(0).random((96, 128, 3), dtype=np.float32)
    >>> augment(gravel, 0.0, 2.0) is gravel  # no joint network: nothing changes
    True
    """
    joints = fit(photo, joint_width, weight) if joints is None else joints
    if joints is None:
        return photo
    joint_width = 2 * joints.sigma
    mask = joints.mask(photo)
    if mask.all() or not mask.any():
        return photo
    d = feature_distance(photo, joints, mask)
    spread = np.sqrt(photo.reshape(-1, photo.shape[2]).var(axis=0, dtype=np.float64).sum())
    near = np.tanh(d / joint_width)  # before clipping: the step at the joint's edge
    limit = np.quantile(np.abs(d), QUANTILE)
    d = np.clip(d, -limit, limit)
    channels = [photo]
    for e in (d, near):
        e = e - e.mean()
        scale = weight * spread / max(float(e.std()), 1e-12)
        channels.append((e * scale).astype(np.float32)[:, :, None])
    return np.concatenate(channels, axis=2)


def working_shape(shape, joint_width: float) -> tuple[int, int, int]:
    """The shape (H, W, C) of the exemplar a method works on: two channels more with a given
    joint width (``joint_width`` > 0), for its memory and cost models; a measured width (0)
    adds them only where the photo has joints, which its shape does not tell: counted without.

    Examples
    --------
    >>> working_shape((512, 512, 3), 0.0), working_shape((512, 512, 3), 4.0)
    ((512, 512, 3), (512, 512, 5))
    """
    h, w, c = shape
    return (h, w, c + CHANNELS) if joint_width > 0 else (h, w, c)


def measured_width(photo: np.ndarray, joint_width: float, weight: float) -> float:
    """The joint width a method will work with on ``photo``: ``joint_width`` when given (> 0),
    0 when ``weight`` is 0 or the photo has no joint network, else the width :func:`fit`
    measures (``joint_scale``'s, doubled); what the memory and cost models need where the photo
    is at hand (a 12 MP photo of setts: 0.6 s), since :func:`working_shape` cannot tell it.

    Examples
    --------
    >>> i, j = np.mgrid[:96, :128]
    >>> wall = np.where((i % 16 < 3) | ((j + 16 * (i // 16 % 2)) % 32 < 3), 0.2, 0.7)
    >>> measured_width(wall, 0.0, 2.0) > 0, measured_width(wall, 0.0, 0.0)
    (True, 0.0)
    """
    if joint_width > 0 or weight <= 0:
        return float(joint_width if weight > 0 else 0.0)
    a = np.asarray(photo)
    if np.ptp(luma(a)) == 0:
        return 0.0
    sigma = joint_scale(a)
    return 0.0 if sigma is None else 2.0 * sigma

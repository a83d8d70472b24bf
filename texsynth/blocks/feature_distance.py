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

Deviations, one line each:
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

__all__ = ["feature_distance", "augment", "working_shape"]

#: The distance's magnitude above this quantile is clipped (the centres of large elements).
QUANTILE = 0.98


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


def augment(photo: np.ndarray, joint_width: float, weight: float) -> np.ndarray:
    """``photo`` (H, W, C) with its feature distance to the joints ``joint_width`` pixels wide
    (read at half that width, ``Joints.fit``; 0: the width ``joint_scale`` measures) as channel
    C + 1, clipped at its ``QUANTILE`` and scaled to ``weight`` times the colours' standard
    deviation; ``photo`` itself (the same array) when ``weight`` is 0 or no joints are found
    (nothing changes).

    Raises ValueError when the joints are wider than an eighth of the shorter side.

    Examples
    --------
    >>> i, j = np.mgrid[:96, :128]
    >>> wall = np.where((i % 16 < 3) | ((j + 16 * (i // 16 % 2)) % 32 < 3), 0.2, 0.7)
    >>> wall = np.repeat(wall[:, :, None], 3, axis=2).astype(np.float32)
    >>> augment(wall, 3.0, 2.0).shape, augment(wall, 0.0, 2.0).shape  # given, measured
    ((96, 128, 4), (96, 128, 4))
    >>> augment(wall, 3.0, 0.0) is wall
    True
    >>> gravel = np.random.default_rng(0).random((96, 128, 3), dtype=np.float32)
    >>> augment(gravel, 0.0, 2.0) is gravel  # no joint network: nothing changes
    True
    """
    if weight <= 0:
        return photo
    h, w = photo.shape[:2]
    flat = np.ptp(luma(photo)) == 0  # a flat photo has no joints (and no threshold)
    if joint_width <= 0:
        sigma = None if flat else joint_scale(photo)
        if sigma is None:
            return photo
        joint_width = 2 * sigma
    if joint_width > min(h, w) / 8:
        raise ValueError(f"a joint width of {joint_width:g} px is too wide for the {w} x {h} "
                         f"exemplar: at most an eighth of its shorter side ({min(h, w) / 8:g} "
                         "px), or 0 to measure it")
    if flat:
        return photo
    joints = Joints.fit(photo, joint_width / 2)
    mask = joints.mask(photo)
    if mask.all() or not mask.any():
        return photo
    d = feature_distance(photo, joints, mask)
    limit = np.quantile(np.abs(d), QUANTILE)
    d = np.clip(d, -limit, limit)
    d -= d.mean()
    spread = np.sqrt(photo.reshape(-1, photo.shape[2]).var(axis=0, dtype=np.float64).sum())
    scale = weight * spread / max(float(d.std()), 1e-12)
    return np.concatenate([photo, (d * scale).astype(np.float32)[:, :, None]], axis=2)


def working_shape(shape, joint_width: float) -> tuple[int, int, int]:
    """The shape (H, W, C) of the exemplar a method works on: a channel more with joints
    (``joint_width`` > 0), for its memory and cost models.

    Examples
    --------
    >>> working_shape((512, 512, 3), 0.0), working_shape((512, 512, 3), 4.0)
    ((512, 512, 3), (512, 512, 4))
    """
    h, w, c = shape
    return (h, w, c + 1) if joint_width > 0 else (h, w, c)

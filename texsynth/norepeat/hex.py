"""Hex tiling (Mikkelsen 2022, "Practical Real-Time Hex-Tiling", JCGT 11(2)) in numpy: the
reference the Blender node group follows, and a writer of never-repeating images.

The triangle grid of tiling and blending (:func:`.blend.triangle_grid`) read as a hexagonal
grid: each grid vertex is the centre of a hexagonal cell, which carries a random offset AND a
random rotation. A point blends the three copies of its triangle's vertices
with the paper's sharpened weights (section 4): the barycentric weights raised to a power, each
scaled by the luminance of its copy mixed towards 1 by a contrast, then normalised, so that
the brighter, more salient copy wins and the cells meet along the texture's own features
instead of cross-fading. Colours are blended as they are (no histogram transform): structured
and regular textures keep their shapes. A normal map (tangent space, OpenGL: green up) has
each copy's normal turned with its cell (section 5.1) before the blend and is renormalised.

Turns keep the photo's direction (issue 41): a copy turned by any angle turns a photo's
courses, layers, streaks and its light every way (the render's structure-tensor anisotropy fell
from 0.22-0.44 to 0.02-0.03 on held-out photos), so by default a cell turns only by the photo's
own symmetry (:func:`rotation_symmetry`): half turns (which leave a structure tensor as it is),
quarter turns for a photo whose gradients have a 4-fold but no 2-fold direction (square
setts, tiles). Any angle is for the user to ask (``turns=0``).

Deviations, one line each:

- the angle is a third hashed value per vertex, uniform in ``[-pi, pi) * rotation`` and
  rounded to a multiple of ``2 pi / turns``, not the paper's ``|x y| + |x + y| + pi``; the
  offsets are the same hash as tiling and blending's, snapped to whole texels;
- each copy is turned about the texture's origin, not its cell's centre: the two differ by a
  shift per cell, which the uniformly random offset absorbs (the renderer saves the centres);
- luminance from Rec. 709 weights of the values as read (scene-linear colour), not Rec. 601;
- no gain function (the paper's ``Gain3`` at its default ``r = 0.5`` is the identity);
- normal maps are blended as unit vectors and renormalised, not as surface gradients.
"""

from __future__ import annotations

import numpy as np
from scipy.ndimage import gaussian_filter, map_coordinates

from .. import validation
from .blend import GRID_SCALE, triangle_grid, vertex_offsets

__all__ = ["hex_tile", "hex_weights", "predict_hex_memory", "rotation_symmetry", "CONTRAST",
           "SHARPNESS", "LUMA", "TWO_FOLD", "FOUR_FOLD"]

#: The paper's defaults (section 4, ``g_fallOffContrast`` and ``g_exp``).
CONTRAST, SHARPNESS = 0.6, 7.0
#: Rec. 709 luminance weights.
LUMA = np.array([0.2126, 0.7152, 0.0722], np.float32)
#: :func:`rotation_symmetry`'s thresholds: the 2nd and 4th angular harmonics of the gradients
#: (issue 41's photos box-averaged to 256: 0.09-0.71 for the 2nd but asphalt and dirt, 0.03-0.04;
#: the 4th of granite setts 0.43, of asphalt 0.01).
TWO_FOLD, FOUR_FOLD = 0.05, 0.1
#: :func:`rotation_symmetry` reads the photo box-averaged to at most this side (its features,
#: not its grain).
SYMMETRY_SIDE = 512
#: Salt of the hash that gives the angles (another seed of :func:`.blend.vertex_offsets`).
ANGLE_SALT = 0x5F3759DF


def rotation_symmetry(texture) -> int:
    """The turns that keep ``texture`` looking as it does: 4 (quarter turns) when its gradients
    have no prevailing direction but a 4-fold one, else 2 (half turns, which every photo
    takes: they leave its structure tensor, its courses and layers as they are).

    The gradient angles' harmonics, weighted by the squared gradient: ``|sum g^2 e^(2 i
    theta)| / sum g^2`` (the structure tensor's anisotropy) under ``TWO_FOLD`` and ``|sum g^2
    e^(4 i theta)| / sum g^2`` at least ``FOUR_FOLD``; Gaussian derivatives (sigma 1) of the
    luminance, the texture box-averaged to at most ``SYMMETRY_SIDE`` a side.

    References
    ----------
    Bigun & Granlund 1987 (the structure tensor, the doubled angle); Liu, Collins & Tsin 2004
    (a texture's rotation symmetry: 2-fold for every lattice, 4-fold for square ones).

    Examples
    --------
    >>> x = np.arange(64)
    >>> rotation_symmetry(np.tile(np.sin(x / 3.0), (64, 1)))             # stripes
    2
    >>> rotation_symmetry(np.sin(x / 3.0)[:, None] + np.sin(x / 3.0)[None, :])  # a grid
    4
    """
    a = validation.image(texture, what="texture", min_side=2)
    f = max(1, -(-min(a.shape[:2]) // SYMMETRY_SIDE))
    h, w = a.shape[0] // f * f, a.shape[1] // f * f
    a = a[:h, :w].reshape(h // f, f, w // f, f, a.shape[2]).mean(axis=(1, 3))
    y = a[..., :3] @ LUMA if a.shape[2] >= 3 else a[..., 0]
    g = gaussian_filter(y, 1.0, order=(0, 1)) + 1j * gaussian_filter(y, 1.0, order=(1, 0))
    energy = float((np.abs(g) ** 2).sum())
    if energy <= 0.0:
        return 2
    second = abs((g ** 2).sum()) / energy
    fourth = abs((g ** 4 / np.maximum(np.abs(g) ** 2, 1e-30)).sum()) / energy
    return 4 if second < TWO_FOLD and fourth >= FOUR_FOLD else 2


def _cell_frames(vertices: np.ndarray, seed: int, rotation: float, turns: int, texels):
    """Per grid vertex (..., 2): its cell's angle (radians; a multiple of ``2 pi / turns``
    unless ``turns`` is 0) and offset (..., 2) snapped to the ``texels`` (w, h) grid."""
    texels = np.asarray(texels, np.float64)
    offset = np.floor(vertex_offsets(vertices, seed) * texels) / texels
    angle = (2.0 * vertex_offsets(vertices, (seed ^ ANGLE_SALT) & 0xFFFFFFFF)[..., 0] - 1.0) \
        * np.pi * rotation
    if turns:
        step = 2.0 * np.pi / turns
        angle = np.floor(angle / step + 0.5) * step
    return angle, offset


def _rotate(xy: np.ndarray, angle: np.ndarray) -> np.ndarray:
    c, s = np.cos(angle), np.sin(angle)
    return np.stack([c * xy[..., 0] - s * xy[..., 1], s * xy[..., 0] + c * xy[..., 1]], -1)


def _read(texture: np.ndarray, st: np.ndarray) -> np.ndarray:
    """Linear, wrapping reads of ``texture`` (H, W, C) at texture coordinates ``st`` (..., 2),
    texel centres at ``(k + 1/2) / size``."""
    h, w = texture.shape[:2]
    rows, cols = st[..., 1] * h - 0.5, st[..., 0] * w - 0.5
    return np.stack([map_coordinates(texture[..., k], [rows, cols], order=1, mode="grid-wrap")
                     for k in range(texture.shape[2])], -1)


def hex_weights(barycentric: np.ndarray, luminance: np.ndarray, contrast: float = CONTRAST,
                sharpness: float = SHARPNESS) -> np.ndarray:
    """The paper's blend weights (..., 3) from the barycentric weights and the three copies'
    luminances (..., 3): ``mix(1, L_i, contrast) * w_i ** sharpness``, normalised.

    References
    ----------
    Mikkelsen 2022, 4 (``hex2colTex``: ``Dw = lerp(1, Dw, g_fallOffContrast)``, ``W = Dw *
    pow(w, g_exp)``).

    Examples
    --------
    >>> w = hex_weights(np.array([0.5, 0.3, 0.2]), np.array([0.2, 0.9, 0.5]))
    >>> bool(np.isclose(w.sum(), 1.0)), int(np.argmax(w))
    (True, 0)
    """
    d = 1.0 - contrast + contrast * np.asarray(luminance, np.float64)
    weights = np.maximum(d, 1e-4) * np.asarray(barycentric, np.float64) ** sharpness
    return weights / np.maximum(weights.sum(-1, keepdims=True), 1e-30)


def predict_hex_memory(width: int, height: int, channels: int) -> float:
    """Peak bytes of :func:`hex_tile` for a ``width`` x ``height`` output of ``channels``: the
    float64 coordinates, weights, vertices and cell frames of every pixel and the three reads
    (tracemalloc: 265 and 302 bytes a pixel for 1 and 3 channels).

    Examples
    --------
    >>> predict_hex_memory(1024, 1024, 3) / 2**20
    320.0
    """
    return float(width) * height * (260 + 20 * channels)


def hex_tile(texture, width: int, height: int, *, scale: float = GRID_SCALE, seed: int = 0,
             rotation: float = 1.0, turns: int | None = None, contrast: float = CONTRAST,
             sharpness: float = SHARPNESS, normal: bool = False, weight_by=None) -> np.ndarray:
    """A ``width`` x ``height`` image of ``texture`` hex-tiled at its own pixel size (pixel
    ``(y, x)`` at ``uv = ((x + 0.5) / w, (y + 0.5) / h)``): repeating nowhere.

    Parameters
    ----------
    texture : array (H, W) or (H, W, C), C in 1, 3, 4
        The values as the renderer reads them (scene-linear colour or data).
    width, height : int
        Output size in pixels.
    scale : float
        Grid vertices (cell centres) per texture tile along u (default ``2 sqrt 3``).
    seed : int
        Picks the offsets and angles.
    rotation : float
        0 to 1: the cells' angles span ``[-pi, pi) * rotation`` (0: offsets only).
    turns : int, optional
        The angles rounded to multiples of a ``1 / turns`` turn (2: half turns, 4: quarter
        turns, 1: none); 0: any angle; default :func:`rotation_symmetry` of ``texture`` (the
        photo's direction kept).
    contrast, sharpness : float
        The weights' luminance contrast (0 to 1) and exponent (1 to 64), the paper's
        ``g_fallOffContrast`` and ``g_exp``.
    normal : bool
        ``texture`` is a tangent-space normal map (values in [0, 1], green up): each copy's
        normal is turned with its cell and the blend renormalised.
    weight_by : array (H', W'[, C']), optional
        The map whose luminance weights the cells (another map of the same material, so that
        all maps blend alike); default ``texture`` itself (a normal map: equal luminances).

    Returns
    -------
    float32 (height, width, C)

    References
    ----------
    Mikkelsen 2022, 3 (the hexagonal grid as the triangle grid's vertices, a rotation per
    cell), 4 (the luminance-weighted, sharpened blend), 5.1 (normals turned with the
    cell).

    Examples
    --------
    >>> photo = np.random.default_rng(1).random((32, 32, 3)).astype(np.float32)
    >>> out = hex_tile(photo, 96, 64, seed=3)
    >>> out.shape, out.dtype
    ((64, 96, 3), dtype('float32'))
    """
    a = validation.image(texture, what="texture", min_side=2)
    width, height = validation.size(width, height)
    scale = validation.number(scale, "scale", 0.01, 1000.0)
    seed = validation.seed(seed)
    rotation = validation.number(rotation, "rotation", 0.0, 1.0)
    turns = rotation_symmetry(a) if turns is None else validation.whole(turns, "turns", 0, 360)
    contrast = validation.number(contrast, "contrast", 0.0, 1.0)
    sharpness = validation.number(sharpness, "sharpness", 1.0, 64.0)
    if not isinstance(normal, bool):
        raise ValueError(f"normal must be True or False, got {normal!r}")
    if normal and a.shape[2] < 3:
        raise ValueError(f"a normal map needs 3 channels, got {a.shape[2]}")
    b = None if weight_by is None else validation.image(weight_by, what="weight_by",
                                                         min_side=2)
    h, w, c = a.shape
    validation.check_memory(predict_hex_memory(width, height, c),
                            f"Hex tiling {width} x {height} pixels", "a smaller size")
    x, y = np.meshgrid((np.arange(width) + 0.5) / w, (np.arange(height) + 0.5) / h)
    uv = np.stack([x, y], -1)
    barycentric, vertices = triangle_grid(uv, scale)
    copies, luminance = [], []
    for i in range(3):
        angle, offset = _cell_frames(vertices[..., i, :], seed, rotation, turns, (w, h))
        st = _rotate(uv, angle) + offset
        copy = _read(a, st)
        if normal:  # the texture turned by -angle on the surface: so are its normals
            n = 2.0 * copy[..., :3] - 1.0
            # (x, y) with y up in the tangent frame is (x, -row) in the array's frame
            turned = _rotate(n[..., :2] * (1.0, -1.0), -angle) * (1.0, -1.0)
            copy = np.concatenate([turned, n[..., 2:3], copy[..., 3:]], -1)
        copies.append(copy)
        source = a if b is None else b
        if normal and b is None:
            luminance.append(np.ones(uv.shape[:-1]))
        else:
            read = copy if b is None else _read(b, st)
            luminance.append(read[..., :3] @ LUMA if source.shape[2] >= 3 else read[..., 0])
    weights = hex_weights(barycentric, np.stack(luminance, -1), contrast, sharpness)
    out = sum(weights[..., i, None] * copies[i] for i in range(3))
    if normal:
        n = out[..., :3] / np.maximum(np.linalg.norm(out[..., :3], axis=-1, keepdims=True),
                                      1e-12)
        out = np.concatenate([0.5 * n + 0.5, out[..., 3:]], -1)
    return out.astype(np.float32)

"""Man-made textures for the plane benchmark: bricks, tiles, planks and a basket weave.

Procedural and periodic (512 x 512, RGB in [0, 1]), so they tile on the rendered plane without
seams and need no licence. They are what isotropy misreads: strongly directional, full of
straight joints in two orthogonal families (one long, one short for bricks and planks).
"""

from __future__ import annotations

import numpy as np
import scipy.ndimage as ndi

__all__ = ["textures"]

N = 512


def _grain(rng, sigma_along: float, sigma_across: float) -> np.ndarray:
    """Periodic noise stretched along x (wood grain, threads), unit variance."""
    noise = ndi.gaussian_filter(rng.standard_normal((N, N)), (sigma_across, sigma_along),
                                mode="wrap")
    return noise / noise.std()


def _colour(grey: np.ndarray, tint) -> np.ndarray:
    return np.clip(grey[:, :, None] * np.asarray(tint)[None, None], 0.0, 1.0).astype(np.float32)


def bricks(seed: int, brick=(64, 24), mortar=3, tint=(0.75, 0.42, 0.33)) -> np.ndarray:
    rng = np.random.default_rng(seed)
    bw, bh = brick
    rows, cols = np.mgrid[0:N, 0:N]
    course = rows // bh
    shifted = (cols + (course % 2) * (bw // 2)) % N
    index = course * (N // bw + 1) + shifted // bw
    shade = rng.uniform(0.7, 1.1, index.max() + 1)[index]
    grey = shade * (1.0 + 0.08 * _grain(rng, 1.5, 1.5))
    joint = ((rows % bh) < mortar) | ((shifted % bw) < mortar)
    grey = np.where(joint, 1.25 + 0.05 * _grain(rng, 1, 1), grey)
    return _colour(grey * 0.7, tint)


def tiles(seed: int, tile=(64, 64), grout=3, tint=(0.8, 0.8, 0.78)) -> np.ndarray:
    rng = np.random.default_rng(seed)
    tw, th = tile
    rows, cols = np.mgrid[0:N, 0:N]
    index = (rows // th) * (N // tw + 1) + cols // tw
    shade = rng.uniform(0.75, 1.0, index.max() + 1)[index]
    grey = shade * (1.0 + 0.05 * _grain(rng, 3, 3))
    joint = ((rows % th) < grout) | ((cols % tw) < grout)
    grey = np.where(joint, 0.35, grey)
    return _colour(grey, tint)


def planks(seed: int, width=32, length=256, tint=(0.72, 0.5, 0.3)) -> np.ndarray:
    rng = np.random.default_rng(seed)
    rows, cols = np.mgrid[0:N, 0:N]
    board = rows // width
    offsets = rng.integers(0, length, N // width + 1)
    shifted = (cols + offsets[board]) % N
    index = board * (N // length + 1) + shifted // length
    shade = rng.uniform(0.7, 1.0, index.max() + 1)[index]
    grey = shade * (1.0 + 0.12 * _grain(rng, 12.0, 0.7))
    joint = ((rows % width) < 2) | ((shifted % length) < 2)
    grey = np.where(joint, 0.25, grey)
    return _colour(grey, tint)


def weave(seed: int, cell=32, tint=(0.85, 0.82, 0.7)) -> np.ndarray:
    """Basket weave: cells of parallel threads, alternately along x and along y."""
    rng = np.random.default_rng(seed)
    rows, cols = np.mgrid[0:N, 0:N]
    along_x = ((rows // cell) + (cols // cell)) % 2 == 0
    thread = cell // 4
    stripes = np.where(along_x, np.cos(np.pi * (rows % thread) / thread),
                       np.cos(np.pi * (cols % thread) / thread)) ** 2
    fibre = np.where(along_x, _grain(rng, 4.0, 0.6), _grain(rng, 4.0, 0.6).T)
    grey = 0.45 + 0.45 * stripes + 0.05 * fibre
    edge = ((rows % cell) < 2) | ((cols % cell) < 2)
    grey = np.where(edge, 0.2, grey)
    return _colour(grey, tint)


def textures() -> dict[str, tuple[np.ndarray, str]]:
    """name -> (texture, kind): two variants of each kind."""
    out = {}
    for seed, (size, mortar) in enumerate((((64, 24), 3), ((48, 20), 4))):
        out[f"bricks_{seed}"] = (bricks(seed, size, mortar), "bricks")
    for seed, size in enumerate(((64, 64), (96, 48))):
        out[f"tiles_{seed}"] = (tiles(10 + seed, size), "tiles")
    for seed, (width, length) in enumerate(((32, 256), (24, 128))):
        out[f"planks_{seed}"] = (planks(20 + seed, width, length), "planks")
    for seed, cell in enumerate((32, 48)):
        out[f"weave_{seed}"] = (weave(30 + seed, cell), "weave")
    return out

"""Make a photo itself tile: keep its pixels, re-synthesize only a band across the wrap.

The photo is rolled by half its size, so the wrap-around seam becomes a cross through the
middle and the photo's own centre lands on the corners, where the rolled image wraps without a
seam. The pixels farther than half a band width from the cross are kept exactly; the cross band
is re-synthesized by texture optimisation (Kwatra et al. 2005, with PatchMatch, Barnes et al.
2009: ``texsynth.algorithms.texture_optimization.optimize``), each band patch taken from the
photo's own patches and the kept pixels held fixed as constraints, so the band continues the
kept content on both sides. Rolling back gives a photo that tiles: its wrap edge is the middle of
the re-synthesized band, and its centre is the photo's, untouched.

The result is made of photo pixels only, and the position map says which: apply it to the
other maps of the material (normal, roughness, height of the same size) and they tile with it.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from . import budget, validation
from .algorithms.texture_optimization import METHOD, optimize
from .progress import Progress

__all__ = ["make_tileable", "make_tileable_positions", "default_band", "predict"]

#: Patch descriptor (cells, dims): coarser than the method's default, for seconds at 1024^2.
DESCRIPTOR = (4, 16)
#: The photo's edge margin left out of the sources: band width / MARGIN, at least half a patch.
MARGIN = 8
#: Largest share of the photo a band may change (the issue asks at least half unchanged).
MAX_CHANGED = 0.5


def default_band(shape, patch_size: int = 8) -> int:
    """The band width used when none is given: an eighth of the shorter side, at least two
    patches, and never so wide that more than half of the photo would change."""
    side = min(shape[:2])
    return int(min(max(side // 8, 2 * patch_size), _widest(shape)))


def _widest(shape) -> int:
    """The widest band that changes at most ``MAX_CHANGED`` of an (h, w) photo:
    changed = b (h + w) - b^2 <= MAX_CHANGED h w."""
    h, w = shape[:2]
    return int(((h + w) - np.sqrt((h + w) ** 2 - 4 * MAX_CHANGED * h * w)) / 2)


def predict(shape, band: int | None = None) -> tuple[float, float]:
    """(seconds on this machine, peak bytes) predicted for :func:`make_tileable` of a photo of
    ``shape`` (H, W[, C]) with ``band`` (default :func:`default_band`), at the default
    settings: what the budgets check and the Blender panel shows."""
    shape = tuple(shape) if len(shape) == 3 else (*shape[:2], 1)
    h, w = shape[:2]
    values = METHOD.resolve({})
    return (budget.predict(METHOD, shape, w, h, values), float(METHOD.memory(shape, w, h, values)))


def make_tileable(photo, *, band: int | None = None, seed: int = 0,
                  progress: Callable[[float, str], object] | None = None, patch_size: int = 8,
                  levels: int = 3, iterations: int = 3, uniformity: float = 2.0) -> np.ndarray:
    """``photo`` made to tile, float32 of the photo's size and channels.

    Parameters
    ----------
    photo : array (H, W) or (H, W, C), C in 1, 3, 4
        Floats as they are, uint8/uint16 scaled to [0, 1] (as ``texsynth.synthesize``).
    band : int, optional
        Width in pixels of the re-synthesized band across the wrap (each arm of the cross);
        default :func:`default_band`. Wider bands hide larger features; at most half of the
        photo may change.
    seed : int
        Same inputs and seed give bit-identical output.
    progress : callable(fraction, message), optional
        As for ``texsynth.synthesize``; returning ``False`` cancels (``texsynth.Cancelled``).
    patch_size, levels, iterations, uniformity
        The texture optimisation's (see ``texsynth.get_method("texture_optimization")``).

    Every pixel farther than ``band / 2`` from the photo's edges is returned unchanged.
    """
    return make_tileable_positions(photo, band=band, seed=seed, progress=progress,
                                   patch_size=patch_size, levels=levels, iterations=iterations,
                                   uniformity=uniformity)[0]


def make_tileable_positions(photo, *, band: int | None = None, seed: int = 0,
                            progress: Callable[[float, str], object] | None = None,
                            patch_size: int = 8, levels: int = 3, iterations: int = 3,
                            uniformity: float = 2.0) -> tuple[np.ndarray, np.ndarray]:
    """:func:`make_tileable` and its position map, int32 (H, W, 2) (row, col) into the photo:
    ``texsynth.apply_positions(positions, other_map)`` makes another map of the material tile
    the same way (the kept pixels map to themselves)."""
    values = METHOD.resolve({"patch_size": patch_size, "levels": levels,
                             "iterations": iterations, "uniformity": uniformity})
    a = validation.image(photo, what="photo", min_side=2 * values["patch_size"])
    seed = validation.seed(seed)
    h, w = a.shape[:2]
    widest = _widest((h, w))
    band = default_band((h, w), values["patch_size"]) if band is None else \
        validation.whole(band, "band (pixels)", 1)
    if not values["patch_size"] <= band <= widest:
        raise ValueError(f"band must be between the patch size ({values['patch_size']}) and "
                         f"{widest} pixels (wider would change more than half of the "
                         f"{w} x {h} photo), got {band}")
    what = f"making the {w} x {h} photo tileable"
    validation.check_memory(METHOD.memory(a.shape, w, h, values), what)
    budget.check_time(budget.predict(METHOD, a.shape, w, h, values), what,
                      "try a smaller photo or a narrower band")
    report = Progress(progress)
    report(0.0, "Make tileable: starting")

    # The rolled photo: pixel (i, j) shows photo pixel (i - sh, j - sw); the seam is the cross
    # between rows sh - 1, sh and columns sw - 1, sw.
    sh, sw = h // 2, w // 2
    i = np.arange(h)[:, None]
    j = np.arange(w)[None, :]
    where = np.stack(np.broadcast_arrays((i - sh) % h, (j - sw) % w), axis=2).astype(np.int32)
    start_r, start_c = sh - band // 2, sw - band // 2
    cross = (((i >= start_r) & (i < start_r + band)) | ((j >= start_c) & (j < start_c + band)))
    rng = np.random.default_rng(seed)
    # Sources: the photo without a margin of m pixels along its edges, so no band patch copies
    # the photo's own edge: the band's content then crosses the wrap instead of ending on it
    # (with the edge as a source, the photo's continuation meets its other side exactly on the
    # wrap line, the seam we hide). The band starts as the rolled photo, except within m of the
    # seam (the margin), which starts from random photo pixels.
    m = max(values["patch_size"] // 2, band // MARGIN)
    source = a[m:h - m, m:w - m]
    start = where - m
    near = ((i >= sh - m) & (i < sh + m)) | ((j >= sw - m) & (j < sw + m))
    near = np.broadcast_to(near, (h, w))
    start[near] = np.stack([rng.integers(0, h - 2 * m, near.sum()),
                            rng.integers(0, w - 2 * m, near.sum())], axis=1)
    _, positions = optimize(source, h, w, rng, report.span(0.0, 0.99), values["levels"],
                            values["patch_size"], 1, values["iterations"], values["uniformity"],
                            known=(~cross, start), descriptor=DESCRIPTOR)
    positions = np.roll(positions + m, (-sh, -sw), axis=(0, 1))
    out = a[positions[:, :, 0], positions[:, :, 1]]
    report(1.0, "Make tileable: done")
    return np.ascontiguousarray(out), np.ascontiguousarray(positions)

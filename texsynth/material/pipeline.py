"""A photo to a whole material in one call: rectify, heal, delight, tile, derive the maps.

The steps, in the order an artist does them by hand (Substance 3D Sampler's Perspective
Correction, Delight, Make it Tile and Image to Material do the same in one program):

1. **rectify**: the plane's estimate (:func:`~texsynth.plane.estimate_plane`, with the EXIF
   focal length given as ``focal_px``) or the plane of the rectangle the user marks
   (``corners``: :func:`~texsynth.plane.from_rectangle`), then the frontal view
   (:func:`~texsynth.plane.rectify`): the largest axis-aligned rectangle of the plane the photo
   shows, one pixel per photo pixel at its centre (the photo's own texel size). An estimate
   that is a guess (:func:`~texsynth.plane.verdict`) is not applied without corners, and a
   measured frontal view is kept as it is: warping by a guess, or by nothing, only resamples;
2. **heal**: the masked pixels (``mask``, or where the photo's alpha is not constant, below
   one half) re-synthesized from the rest (:func:`~texsynth.material.heal`);
3. **delight**: the light taken out (:func:`~texsynth.material.delight`);
4. **tile**: :func:`~texsynth.make_tileable` at the photo's size, or a synthesis to ``size``
   (:func:`~texsynth.synthesize_positions`, ``method``), keeping the position map;
5. **maps**: :func:`~texsynth.material.derive_maps` from the final, tiling colour with
   periodic filters (``wrap=True``). Ours: derived after tiling, not before and moved by the
   position map, because a filter of a tiling image tiles exactly, with no step where two
   copied pieces meet, and costs the output's pixels instead of the photo's 12 M.

Each step can be left out (``steps``); a left-out step passes the image on unchanged. Progress
spans are weighted by each step's predicted time (:func:`predict`), the same seed gives the same
bits, and the :class:`Material` records one line per step saying what it did.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .. import api, budget, tileable, validation
from ..blocks.parallel import serial_blas
from ..io import encode, write_images
from ..plane import estimate_plane, from_rectangle, rectify, verdict
from ..plane.rectify import RECTIFY_SECONDS_PER_SAMPLE
from ..progress import Progress
from ..registry import get_method
from .delight import delight
from .heal import heal
from .maps import Maps, derive_maps

__all__ = ["STEPS", "METHOD", "SUFFIXES", "Material", "photo_to_material", "predict",
           "check", "material_files", "write_material"]

#: The steps in their order; each one on by default.
STEPS = ("rectify", "heal", "delight", "tile", "maps")
#: The synthesis method of ``size`` when none is named (the command line's default too).
METHOD = "multiscale_mrf"
#: The files' name endings, as ambientCG names them and Node Wrangler's Principled texture
#: setup (Ctrl+Shift+T) recognises them: colour, OpenGL normal, height, roughness, AO.
SUFFIXES = ("Color", "NormalGL", "Displacement", "Roughness", "AmbientOcclusion")
#: Reference-machine seconds of the steps texsynth.plane and mat-core's modules give no model
#: for, measured on the 12 MP phone photo of benchmarks/sections/material_pipeline.py: the
#: plane estimate (its analysis runs at a fixed side, plus the full photo's luminance), and
#: delight, heal and derive_maps per pixel they touch. Re-measured 2026-12-03 (CPU time over
#: ``budget.speed``) at 0.75, 3 and 12 MP: the estimate 5.9, 4.9, 6.9 s; delight 6.5, 2.2,
#: 4.3e-7 s a pixel; derive_maps at 512-2048 a side 3.2-4.5e-6 s a pixel (the old constants
#: told the 12 MP material 0.3x its time).
ESTIMATE_SECONDS = (5.0, 1.5e-7)  # (fixed, per photo pixel)
DELIGHT_SECONDS_PER_PIXEL = 3.5e-7
HEAL_SECONDS_PER_PIXEL = 2e-6  # per masked pixel
MAPS_SECONDS_PER_PIXEL = 4e-6
#: Peak bytes per pixel of the steps without a memory model of their own: rectify's (its
#: float32 copy of the photo, the output's coordinates, filter levels and result: 479 MB peak
#: measured by tracemalloc on the 12 MP phone photo, 42 per photo pixel), and float32 working
#: copies (the photo, the light, the maps' filters).
RECTIFY_BYTES_PER_PIXEL = 48
DELIGHT_BYTES_PER_PIXEL = 48
MAPS_BYTES_PER_PIXEL = 96


@dataclass(frozen=True)
class Material:
    """What :func:`photo_to_material` made.

    ``colour`` float32 (H, W, 3) in the photo's encoding; ``maps`` the derived maps (None when
    the maps step was left out); ``positions`` int32 (H, W, 2) (row, col) into the de-lit photo
    that the tile step quilted or synthesized from (None when it was left out); ``steps`` one
    line per step, in order, saying what it did or why it did nothing.
    """

    colour: np.ndarray
    maps: Maps | None
    positions: np.ndarray | None
    steps: tuple[str, ...]


def _steps(steps: Sequence[str]) -> tuple[str, ...]:
    steps = tuple(steps)
    stray = [s for s in steps if s not in STEPS]
    if stray:
        raise ValueError(f"steps must be among {', '.join(STEPS)}, got {', '.join(stray)}")
    return steps


def _corners(corners, shape) -> np.ndarray | None:
    if corners is None:
        return None
    xy = np.asarray(corners, dtype=np.float64).reshape(-1)
    if xy.size != 8 or not np.isfinite(xy).all():
        raise ValueError("corners must be 4 (x, y) pixel points around the rectangle "
                         f"(x1,y1,...,x4,y4), got {np.asarray(corners).size} values")
    h, w = shape[:2]
    pts = xy.reshape(4, 2)
    if (pts < -0.5).any() or (pts[:, 0] > w - 0.5).any() or (pts[:, 1] > h - 0.5).any():
        raise ValueError(f"corners must lie on the {w} x {h} photo (x right, y down)")
    return pts


def _keep_mask(photo: np.ndarray, mask) -> np.ndarray | None:
    """Where the photo is kept (1) and healed (0), float32 (H, W), or None when nothing is to
    be healed: the mask's True/1 pixels and, with an alpha that is not constant, the pixels
    whose alpha is under one half."""
    keep = None
    if photo.shape[2] in (2, 4):
        alpha = photo[:, :, -1]
        if alpha.min() != alpha.max():
            keep = (alpha >= 0.5).astype(np.float32)
    if mask is not None:
        m = np.asarray(mask, dtype=np.float32)
        if m.ndim == 3:
            m = m[:, :, 0]
        if m.shape != photo.shape[:2]:
            raise ValueError(f"mask is {m.shape[1] if m.ndim == 2 else '?'} x {m.shape[0]}, "
                             f"not the photo's {photo.shape[1]} x {photo.shape[0]}")
        given = (m < 0.5).astype(np.float32)
        keep = given if keep is None else np.minimum(keep, given)
    return keep


def check(shape, *, size=None, steps: Sequence[str] = STEPS, method: str | None = None,
          seed: int = 0, masked: bool = False, photo=None) -> tuple[float, float]:
    """Every check :func:`photo_to_material` makes before any work, from the photo's shape
    alone (a command line reads only the header): the steps, ``size``, the method and seed
    (``api.check``, ``tileable.check`` at the photo's shape, the rectified size not being
    known yet), and the budgets; the predicted (seconds, peak bytes), as :func:`predict`
    (``photo``, when at hand, lets it count the joints).

    Examples
    --------
    >>> seconds, peak = check((3000, 4000, 3), size=(1024, 1024))
    >>> 0 < seconds and 0 < peak < 4 * 2**30
    True
    """
    steps = _steps(steps)
    seed = validation.seed(seed)
    if "tile" in steps:
        if size is None:
            tileable.check(shape, seed=seed)
        else:
            api.check(shape, *size, method=method or METHOD, seed=seed)
    seconds, peak = predict(shape, size=size, steps=steps, method=method, masked=masked,
                            photo=photo)
    what = f"making a material of the {shape[1]} x {shape[0]} photo"
    budget.admit(what, peak=peak, seconds=seconds,
                 memory_advice="a smaller --size, or a smaller photo",
                 time_advice="try a smaller size")
    return seconds, peak


def step_costs(shape, size, steps, method, masked,
               photo=None) -> dict[str, tuple[float, float]]:
    """Each step's predicted (seconds on this machine, peak bytes); ``photo``, when at hand,
    lets the tile step's prediction count its joints (``budget.forecast``'s ``exemplar``)."""
    h, w = shape[:2]
    c = shape[2] if len(shape) == 3 else 1
    n = h * w
    factor = budget.machine_factor()
    out = (n, c) if size is None else (size[0] * size[1], 3)
    costs = {}
    if "rectify" in steps:  # the estimate, then rectify at about the photo's size (2 levels)
        seconds = (ESTIMATE_SECONDS[0] + ESTIMATE_SECONDS[1] * n
                   + 2 * RECTIFY_SECONDS_PER_SAMPLE * n * (c + 2)) * factor
        costs["rectify"] = (seconds, RECTIFY_BYTES_PER_PIXEL * n)
    if "heal" in steps and masked:
        costs["heal"] = (HEAL_SECONDS_PER_PIXEL * n / 8 * factor, 8 * n * c)
    if "delight" in steps:
        costs["delight"] = (DELIGHT_SECONDS_PER_PIXEL * n * factor,
                            DELIGHT_BYTES_PER_PIXEL * n)
    if "tile" in steps:
        if size is None:
            costs["tile"] = tileable.predict((h, w, 3))
        else:
            costs["tile"] = budget.forecast(method or METHOD, (h, w, 3), *size,
                                            exemplar=None if photo is None else photo[:, :, :3])
    if "maps" in steps:
        costs["maps"] = (MAPS_SECONDS_PER_PIXEL * out[0] * factor,
                         MAPS_BYTES_PER_PIXEL * out[0])
    return costs


def predict(shape, *, size=None, steps: Sequence[str] = STEPS, method: str | None = None,
            masked: bool = False, photo=None) -> tuple[float, float]:
    """(seconds on this machine, peak bytes) predicted for :func:`photo_to_material` of a
    photo of ``shape`` (H, W, C): the sum of the steps' own predictions (``tileable.predict``,
    ``budget.forecast``, rectify's cost per sample, the constants above) and the largest of
    their peaks over the photo and its working copy that every step holds.

    Examples
    --------
    >>> seconds, peak = predict((768, 1024, 3), size=(512, 512))
    >>> seconds > predict((768, 1024, 3), size=(512, 512), steps=("tile",))[0]
    True
    """
    costs = step_costs(tuple(shape), size, _steps(steps), method, masked, photo)
    held = 8 * shape[0] * shape[1] * (shape[2] if len(shape) == 3 else 1)
    return (sum(s for s, _ in costs.values()),
            held + max((p for _, p in costs.values()), default=0))


def _rectify(photo, corners, focal_px, report) -> tuple[np.ndarray, str]:
    """Step 1: the frontal view, or the photo as it is and why."""
    if corners is not None:
        plane = from_rectangle(corners, photo.shape[:2], focal_px)
        told = "the marked rectangle"
    else:
        report(0.0, "Material: estimating the plane")
        plane = estimate_plane(photo[:, :, :3], focal_px=focal_px)
        judged = verdict(plane)
        if judged.guess:
            return photo, (f"rectify: skipped, the plane estimate is a guess "
                           f"({'; '.join(judged.reasons)}); mark its corners to rectify")
        if not judged.slant_measured:
            return photo, "rectify: skipped, the photo is frontal (no measurable slant)"
        told = "the plane estimate"
    report(0.4, "Material: rectifying")
    frontal = rectify(photo, plane)
    return frontal, (f"rectify: slant {plane.slant:.0f} deg, tilt {plane.tilt:.0f} deg from "
                     f"{told}; cropped to {frontal.shape[1]} x {frontal.shape[0]}")


@serial_blas()
def photo_to_material(photo, *, size=None, mask=None, corners=None,
                      focal_px: float | None = None, steps: Sequence[str] = STEPS,
                      method: str | None = None, seed: int = 0, linear: bool = False,
                      progress: Callable[[float, str], object] | None = None) -> Material:
    """A photo of a surface made into a tiling material: colour, normal, height, roughness
    and ambient occlusion (see the module for the steps).

    Parameters
    ----------
    photo : array (H, W, C), C in 1, 3, 4
        The photo as ``texsynth.io.read_photo`` gives it (sRGB-encoded values in [0, 1]); a
        varying alpha marks pixels to heal (alpha under 0.5).
    size : (width, height), optional
        Synthesize the colour to this size (``method``, default :data:`METHOD`); None: the
        photo itself made to tile at its (rectified) size.
    mask : array (H, W), optional
        True or 1 where the photo is to be healed (a sign, a stain), on the photo as given.
    corners : array-like (4, 2), optional
        A rectangle on the plane, its corners in order around it, (x, y) pixels, x right,
        y down: the plane from it (:func:`~texsynth.plane.from_rectangle`), not estimated.
    focal_px : float, optional
        The focal length in pixels (``texsynth.plane.focal_px_from_file`` reads the EXIF).
        Ours: in pixels, as every plane function takes it, not the millimetres first agreed
        (a length in mm needs the sensor's size, which only the file knows).
    steps : sequence of str
        The steps to run, among :data:`STEPS` (the order is always theirs).
    method : str, optional
        The synthesis method for ``size`` (one that copies pixels keeps a position map).
    seed : int
        Same inputs and seed, the same bits.
    linear : bool
        The photo's values are linear light (an EXR: ``texsynth.io.is_linear``), not
        sRGB-encoded: delight divides the light out of them as they are (``encoded=False``).
    progress : callable(fraction, message), optional
        Returning False cancels (``texsynth.Cancelled``); spans follow each step's predicted
        time.

    Returns
    -------
    Material

    References
    ----------
    Forsyth & Ponce, Computer Vision: A Modern Approach, sec. 11.4.1 (the plane); Efros &
    Freeman 2001 (the tiling band); Neubeck et al. 2004 (the synthesis to ``size``).

    Examples
    --------
    >>> rng = np.random.default_rng(0)
    >>> photo = rng.random((96, 96, 3)).astype(np.float32)
    >>> m = photo_to_material(photo, steps=("delight", "tile", "maps"))
    >>> m.colour.shape, m.maps.normal.shape, len(m.steps)
    ((96, 96, 3), (96, 96, 3), 5)
    """
    steps = _steps(steps)
    a = validation.image(photo, what="photo", min_side=tileable.MIN_SIDE)
    seed = validation.seed(seed)
    pts = _corners(corners, a.shape)
    keep = _keep_mask(a, mask) if "heal" in steps else None
    if keep is not None and keep.min() == 1.0:
        keep = None
    costs = step_costs(a.shape, size, steps, method, keep is not None, a)
    ends = np.cumsum([seconds for seconds, _ in costs.values()] or [0.0])
    ends = list(ends / ends[-1] if ends[-1] > 0 else ends)
    spans = {name: Progress(progress, float(a), float(b)) for name, a, b
             in zip(costs, [0.0, *ends[:-1]], [*ends[:-1], 1.0], strict=False)}
    done: list[str] = []
    work = a[:, :, :3] if a.shape[2] >= 3 else np.repeat(a[:, :, :1], 3, axis=2)
    if keep is not None:
        work = np.concatenate([work, keep[:, :, None]], axis=2)  # rectified with the photo

    if "rectify" in steps:
        work, line = _rectify(work, pts, focal_px, spans["rectify"])
        done.append(line)
    else:
        done.append("rectify: left out")
    if keep is not None:
        work, keep = np.ascontiguousarray(work[:, :, :3]), work[:, :, 3] < 0.5
        spans["heal"](0.0, "Material: healing")
        work = heal(work, keep, seed=seed, progress=spans["heal"])
        done.append(f"heal: {int(keep.sum())} pixels re-synthesized from the rest")
    else:
        done.append("heal: nothing masked" if "heal" in steps else "heal: left out")
    if "delight" in steps:
        work = delight(work, encoded=not linear, seed=seed, progress=spans["delight"])
        done.append("delight: the light taken out")
    else:
        done.append("delight: left out")
    positions = None
    if "tile" in steps:
        work, positions, line = _tile(work, size, method, seed, spans["tile"])
        done.append(line)
    else:
        done.append("tile: left out")
    maps = None
    if "maps" in steps:
        spans["maps"](0.0, "Material: deriving the maps")
        maps = derive_maps(work, wrap="tile" in steps)
        spans["maps"](1.0, "Material: maps derived")
        done.append("maps: normal (OpenGL), height, roughness and AO from the colour"
                    + (", periodic" if "tile" in steps else ""))
    else:
        done.append("maps: left out")
    return Material(np.ascontiguousarray(work, np.float32), maps, positions, tuple(done))


def _tile(colour, size, method, seed, report) -> tuple[np.ndarray, np.ndarray | None, str]:
    """Step 4: the colour made to tile (its size) or synthesized to ``size``."""
    h, w = colour.shape[:2]
    if size is None:
        tiled, positions = tileable.make_tileable_positions(colour, seed=seed, progress=report)
        return tiled, positions, f"tile: made tileable at {w} x {h}"
    name = method or METHOD
    width, height = size
    if get_method(name).positions:
        tiled, positions = api.synthesize_positions(colour, width, height, method=name,
                                                    seed=seed, progress=report)
    else:
        tiled = api.synthesize(colour, width, height, method=name, seed=seed, progress=report)
        positions = None
    return tiled, positions, f"tile: synthesized {width} x {height} with {name} from {w} x {h}"


# --- files ---------------------------------------------------------------------------------

def material_files(material: Material, folder, stem: str, *, fmt: str = "png",
                   from_linear: bool = False) -> list[tuple[Path, np.ndarray]]:
    """``(path, image)`` of each file of ``material``: ``<stem>_Color``, ``_NormalGL``,
    ``_Displacement``, ``_Roughness``, ``_AmbientOcclusion`` (:data:`SUFFIXES`) with the
    suffix of ``fmt`` ("png" or "exr"), as they are to be written: the colour in the file's
    encoding (sRGB in PNG, linear in EXR; ``from_linear``: the material's colour is linear),
    the normal as (n + 1) / 2 (the Normal Map node's colour), the rest as grey data.

    Examples
    --------
    >>> m = photo_to_material(np.full((32, 32, 3), 0.5, np.float32), steps=("maps",))
    >>> [p.name for p, _ in material_files(m, "out", "floor")][:2]
    ['floor_Color.png', 'floor_NormalGL.png']
    """
    if fmt not in ("png", "exr"):
        raise ValueError(f"format must be png or exr, got {fmt!r}")
    folder = Path(folder)
    colour = encode(material.colour, from_linear, fmt == "exr")
    images = [colour]
    if material.maps is not None:
        m = material.maps
        images += [np.clip(m.normal * 0.5 + 0.5, 0.0, 1.0), m.height[:, :, None],
                   m.roughness[:, :, None], m.ao[:, :, None]]
    return [(folder / f"{stem}_{suffix}.{fmt}", np.ascontiguousarray(image, np.float32))
            for suffix, image in zip(SUFFIXES, images, strict=False)]


def write_material(material: Material, folder, stem: str, *, bits: int = 8,
                   fmt: str = "png") -> list[Path]:
    """Write ``material``'s files into ``folder`` (made) and return their paths
    (:func:`material_files`: PNG of ``bits`` 8 or 16, or float EXR).

    Nothing is lost: a file of any of those names already there refuses the whole set
    (``FileExistsError``) before anything is written, and every file is written to a
    temporary name beside it and renamed only when all are complete.

    Examples
    --------
    >>> import tempfile
    >>> m = photo_to_material(np.full((32, 32, 3), 0.5, np.float32), steps=("maps",))
    >>> [p.name for p in write_material(m, tempfile.mkdtemp(), "floor")][-1]
    'floor_AmbientOcclusion.png'
    """
    if bits not in (8, 16):
        raise ValueError(f"bits must be 8 or 16, got {bits!r}")
    files = material_files(material, folder, stem, fmt=fmt)
    there = [str(p) for p, _ in files if p.exists()]
    if there:
        raise FileExistsError(f"{there[0]} exists; nothing was written (choose another folder "
                              "or stem)")
    Path(folder).mkdir(parents=True, exist_ok=True)
    write_images(files, bits)
    return [p for p, _ in files]


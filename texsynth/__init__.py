"""texsynth: example-based, seamless (periodic) texture synthesis with numpy and scipy.

The core never imports Blender. The public entry points are::

    texsynth.synthesize(exemplar, width, height, method="heeger_bergen", seed=0,
                        progress=None, **params) -> float32 (height, width, C)
    texsynth.methods() -> tuple of Method records (name, label, description, params)
    texsynth.make_tileable(photo, band=None, seed=0) -> float32, the photo's size, made to tile

Every method returns a periodic image: tiled 2 x 2 it shows no seam.
"""

from __future__ import annotations

import os
from collections.abc import Callable

import numpy as np

from . import composite, cooccurrence, segmentation
from .estimate import PlaneEstimate, camera_pose, estimate_plane, rectify
from .positions import apply_positions, positions_image
from .progress import Cancelled, Progress
from .registry import Method, Param, get, methods
from .stack import synthesize_stack
from .tileable import make_tileable, make_tileable_positions

__all__ = [
    "synthesize",
    "synthesize_positions",
    "apply_positions",
    "positions_image",
    "synthesize_stack",
    "make_tileable",
    "make_tileable_positions",
    "cooccurrence",
    "composite",
    "segmentation",
    "methods",
    "get_method",
    "validate_exemplar",
    "Cancelled",
    "Method",
    "Param",
    "MAX_SIDE",
    "memory_budget",
    "estimate_plane",
    "rectify",
    "camera_pose",
    "PlaneEstimate",
]

__version__ = "0.1.0"

#: Largest output side accepted (pixels).
MAX_SIDE = 16384

get_method = get


def memory_budget() -> int:
    """Bytes a synthesis may plan to use: ``TEXSYNTH_MEMORY_BUDGET`` (bytes) or 8 GiB."""
    return int(os.environ.get("TEXSYNTH_MEMORY_BUDGET", 8 << 30))


def validate_exemplar(exemplar, min_side: int = 8) -> np.ndarray:
    """Return the exemplar as float32 (H, W, C) or raise ``ValueError`` saying what is wrong.

    Floats are taken as they are; unsigned integer images are scaled to [0, 1] by their type's
    maximum (uint8 / 255, uint16 / 65535).
    """
    a = np.asarray(exemplar)
    if a.dtype.kind == "u":
        a = a.astype(np.float32) / np.float32(np.iinfo(a.dtype).max)
    elif a.dtype.kind not in "fi":
        raise ValueError(f"exemplar must be a numeric image array, got dtype {a.dtype}")
    if a.ndim == 2:
        a = a[:, :, None]
    if a.ndim != 3:
        raise ValueError(f"exemplar must be (H, W) or (H, W, C), got shape {a.shape}")
    if a.shape[2] not in (1, 3, 4):
        raise ValueError(f"exemplar must have 1, 3 or 4 channels, got {a.shape[2]}")
    h, w = a.shape[:2]
    if min(h, w) < min_side:
        raise ValueError(f"exemplar is {w} x {h} pixels; this method needs at least "
                         f"{min_side} x {min_side}")
    a = np.ascontiguousarray(a, dtype=np.float32)
    if not np.isfinite(a).all():
        raise ValueError("exemplar contains NaN or infinite values; "
                         "clamp or repair the image first")
    return a


def _validate_size(width, height) -> tuple[int, int]:
    out = []
    for name, v in (("width", width), ("height", height)):
        if isinstance(v, bool) or not isinstance(v, (int, np.integer)):
            raise ValueError(f"{name} must be a whole number of pixels, got {v!r}")
        if not 1 <= v <= MAX_SIDE:
            raise ValueError(f"{name} must be between 1 and {MAX_SIDE} pixels, got {v}")
        out.append(int(v))
    return out[0], out[1]


def check_memory(method: Method, exemplar_shape: tuple, width: int, height: int,
                 params: dict) -> None:
    """Raise ``ValueError`` before allocating when the estimate exceeds :func:`memory_budget`."""
    need = method.memory(exemplar_shape, width, height, params)
    budget = memory_budget()
    if need > budget:
        raise ValueError(
            f"{width} x {height} with '{method.name}' needs about {need / 2**30:.1f} GiB, over the "
            f"budget of {budget / 2**30:.1f} GiB (set TEXSYNTH_MEMORY_BUDGET to raise it)"
        )


def synthesize(
    exemplar,
    width: int,
    height: int,
    method: str = "heeger_bergen",
    seed: int = 0,
    progress: Callable[[float, str], object] | None = None,
    **params,
) -> np.ndarray:
    """Synthesize a periodic texture of ``width`` x ``height`` pixels from ``exemplar``.

    Parameters
    ----------
    exemplar : array (H, W) or (H, W, C), C in 1, 3, 4
        The sample, top row first. Floats as they are (linear or not: the result has the same
        encoding); uint8/uint16 are scaled to [0, 1].
    width, height : int
        Output size, 1 to ``MAX_SIDE``; any shape, larger or smaller than the exemplar.
    method : str
        A name from :func:`methods`.
    seed : int
        Same inputs and seed give bit-identical output.
    progress : callable(fraction, message), optional
        Called during the work; returning ``False`` or raising :class:`Cancelled` cancels,
        and ``synthesize`` then raises :class:`Cancelled`.
    **params
        The method's parameters (see ``texsynth.get_method(name).params``).

    Returns
    -------
    float32 array (height, width, C), periodic in both directions.

    Alpha: a constant alpha channel (an opaque photo) is passed through unchanged; a varying one
    is synthesized together with the colour as a fourth channel.
    """
    return _run(exemplar, width, height, method, seed, progress, params, False)[0]


def synthesize_positions(
    exemplar,
    width: int,
    height: int,
    method: str = "multiscale_mrf",
    seed: int = 0,
    progress: Callable[[float, str], object] | None = None,
    **params,
) -> tuple[np.ndarray, np.ndarray]:
    """:func:`synthesize` for methods that copy exemplar pixels, with their position map.

    Returns ``(image, positions)``: the same image :func:`synthesize` gives, and int32
    (height, width, 2) (row, col) coordinates into the exemplar, so that
    ``apply_positions(positions, exemplar)`` is that image (after the same uint scaling) and
    ``apply_positions(positions, normal_map)`` makes another map of the material follow.
    Raises ``ValueError`` for methods without position maps (``get_method(name).positions``).
    """
    return _run(exemplar, width, height, method, seed, progress, params, True)


def _run(exemplar, width, height, method, seed, progress, params, want_positions):
    m = get(method)
    if want_positions and not m.positions:
        raise ValueError(f"method '{m.name}' does not copy exemplar pixels, so it has no "
                         "position map; use one of: "
                         + ", ".join(x.name for x in methods() if x.positions))
    values = m.resolve(params)
    a = validate_exemplar(exemplar, m.min_exemplar)
    width, height = _validate_size(width, height)
    if isinstance(seed, bool) or not isinstance(seed, (int, np.integer)) or seed < 0:
        raise ValueError(f"seed must be a non-negative whole number, got {seed!r}")
    check_memory(m, a.shape, width, height, values)

    constant_alpha = None
    if a.shape[2] == 4 and np.ptp(a[:, :, 3]) == 0:
        constant_alpha = a[0, 0, 3]
        a = np.ascontiguousarray(a[:, :, :3])

    report = Progress(progress)
    report(0.0, f"{m.label}: starting")
    rng = np.random.default_rng(int(seed))
    out = m.function(a, width, height, rng, report, **values)
    positions = None
    if m.positions:
        out, positions = out
        positions = np.ascontiguousarray(positions, dtype=np.int32)
    out = np.ascontiguousarray(out, dtype=np.float32)
    if out.shape != (height, width, a.shape[2]):
        raise AssertionError(f"{m.name} returned {out.shape}, "
                             f"expected {(height, width, a.shape[2])}")
    if constant_alpha is not None:
        out = np.concatenate([out, np.full((height, width, 1), constant_alpha, np.float32)], axis=2)
    report(1.0, f"{m.label}: done")
    return out, positions

"""The one validation layer: every public entry point checks its arguments here, before any work.

Each check returns the value in the form the core works with, or raises ``ValueError`` with a
message that names the argument and says what to change. Nothing in here allocates more than
the checked array itself.

- :func:`image`: an image array (H, W) or (H, W, C), numeric and finite, as float32 (H, W, C);
- :func:`size` and :func:`seed`: output sizes and seeds, whole numbers in range;
- :func:`whole` and :func:`finite`: a bounded whole number, a finite real number;
- :func:`magnitude_scale`: the power of two that brings huge or tiny values to order one, and
  :func:`ordinary`: an image multiplied by it, exactly;
- :func:`check_side`: an image's shape large enough (what a file's header alone can tell);
- :func:`memory_budget` and :func:`check_memory`: the planned peak bytes against the budget
  (the time budget is :mod:`texsynth.budget`'s); :func:`budget_variable` reads either
  budget's environment variable; a run over either budget raises :class:`BudgetError`.
"""

from __future__ import annotations

import os

import numpy as np

__all__ = ["MAX_SIDE", "BudgetError", "image", "check_side", "size", "seed", "number", "whole",
           "finite", "magnitude_scale", "ordinary", "memory_budget", "budget_variable",
           "check_memory"]

#: Largest output side accepted (pixels).
MAX_SIDE = 16384


class BudgetError(ValueError):
    """A run refused before any work because it is predicted to exceed the time or memory
    budget (a ``ValueError``, so callers that catch those still do)."""


def image(array, *, what: str = "exemplar", min_side: int = 8,
          channels: tuple[int, ...] | None = (1, 3, 4), finite: bool = True) -> np.ndarray:
    """``array`` as C-contiguous float32 (H, W, C), or ``ValueError`` saying what is wrong.

    Floats are taken as they are; unsigned integer images are scaled to [0, 1] by their type's
    maximum (uint8 / 255, uint16 / 65535). ``channels=None`` takes any count; ``finite=False`` lets
    NaN and infinities through (files may hold them; synthesis may not).
    """
    a = np.asarray(array)
    if a.dtype.kind == "u":
        a = a.astype(np.float32) / np.float32(np.iinfo(a.dtype).max)
    elif a.dtype.kind not in "fi":
        raise ValueError(f"{what} must be a numeric image array, got dtype {a.dtype}")
    if a.ndim == 2:
        a = a[:, :, None]
    if a.ndim != 3:
        raise ValueError(f"{what} must be (H, W) or (H, W, C), got shape {a.shape}")
    if channels is not None and a.shape[2] not in channels:
        listed = ", ".join(map(str, channels[:-1])) + f" or {channels[-1]}"
        raise ValueError(f"{what} must have {listed} channels, got {a.shape[2]}")
    check_side(a.shape, min_side, what)
    a = np.ascontiguousarray(a, dtype=np.float32)
    # NaN and infinities show in the extremes: two passes and no (H, W, C) mask of a 12 MP photo.
    if finite and a.size and not (np.isfinite(a.min()) and np.isfinite(a.max())):
        raise ValueError(f"{what} contains NaN or infinite values; clamp or repair the image "
                         "first")
    return a


def check_side(shape, side: int, what: str = "exemplar") -> None:
    """``ValueError`` when an image of ``shape`` (H, W, ...) is smaller than ``side`` x ``side``.

    Examples
    --------
    >>> check_side((12, 40, 3), 8)
    >>> check_side((4, 40), 8, "photo")
    Traceback (most recent call last):
    ...
    ValueError: photo is 40 x 4 pixels; this needs at least 8 x 8
    """
    h, w = shape[:2]
    if min(h, w) < side:
        raise ValueError(f"{what} is {w} x {h} pixels; this needs at least {side} x {side}")


def size(width, height) -> tuple[int, int]:
    """(width, height) as ints from 1 to :data:`MAX_SIDE`."""
    out = []
    for name, v in (("width", width), ("height", height)):
        if isinstance(v, bool) or not isinstance(v, (int, np.integer)):
            raise ValueError(f"{name} must be a whole number of pixels, got {v!r}")
        if not 1 <= v <= MAX_SIDE:
            raise ValueError(f"{name} must be between 1 and {MAX_SIDE} pixels, got {v}")
        out.append(int(v))
    return out[0], out[1]


def seed(value) -> int:
    """A seed: a non-negative whole number."""
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < 0:
        raise ValueError(f"seed must be a non-negative whole number, got {value!r}")
    return int(value)


def number(value, name: str, low: float, high: float) -> float:
    """A finite real number in [low, high]."""
    if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)) \
            or not low <= value <= high:
        raise ValueError(f"{name} must be a number from {low} to {high}, got {value!r}")
    return float(value)


def whole(value, name: str, low: int, high: int | None = None) -> int:
    """A whole number (not a bool) in [low, high] (no upper bound when ``high`` is None)."""
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < low \
            or (high is not None and value > high):
        bound = f"from {low} to {high}" if high is not None else f"of at least {low}"
        raise ValueError(f"{name} must be a whole number {bound}, got {value!r}")
    return int(value)


def finite(value, name: str) -> float:
    """A finite real number (not a bool)."""
    if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)) \
            or not np.isfinite(value):
        raise ValueError(f"{name} must be a finite number, got {value!r}")
    return float(value)


#: Magnitudes (powers of two) between which values are worked on as they are.
ORDINARY = (-16, 16)


def magnitude_scale(a: np.ndarray) -> float:
    """1.0 for values of ordinary magnitude (the largest |value| from 2^-16 to 2^16, or all
    zero); else the power of two that brings the largest to order one. Multiplying by a power
    of two is exact in floating point, so a method can work on ``a * scale`` (squared distances
    of values near 1e30 overflow float32) and its result be divided back without rounding."""
    peak = max(float(a.max()), -float(a.min())) if a.size else 0.0  # no |a| temporary
    if peak == 0.0:
        return 1.0
    k = int(np.floor(np.log2(peak)))
    return 1.0 if ORDINARY[0] <= k <= ORDINARY[1] else float(2.0 ** -k)


def ordinary(a: np.ndarray, scale: float | None = None) -> np.ndarray:
    """``a`` (float32) times ``scale``, exactly (a power of two, through float64): ``a`` itself
    when ``scale`` is 1; default ``scale``: its own :func:`magnitude_scale`.

    Examples
    --------
    >>> huge = np.full((2, 2, 1), 3e30, np.float32)
    >>> scale = magnitude_scale(huge)
    >>> scale < 1e-30, bool((ordinary(huge) / scale == huge).all())
    (True, True)
    """
    scale = magnitude_scale(a) if scale is None else scale
    return a if scale == 1.0 else (a.astype(np.float64) * scale).astype(np.float32)


#: Bytes a synthesis may plan to use when ``TEXSYNTH_MEMORY_BUDGET`` is not set.
DEFAULT_MEMORY = 8 << 30


def memory_budget() -> int:
    """Bytes a synthesis may plan to use: ``TEXSYNTH_MEMORY_BUDGET`` (bytes) or 8 GiB.

    Raises ``ValueError`` naming the variable when it is set to anything but a positive whole
    number of bytes (``1e9`` and ``4_000_000_000`` are whole; ``abc``, ``0``, ``1.5`` are not).

    Returns
    -------
    int
        Bytes; every method's ``memory`` estimate is checked against it before any work.

    References
    ----------
    docs/ARCHITECTURE.md, Conventions, "Methods" (the memory estimate, checked against the
    budget before any allocation).

    Examples
    --------
    >>> from unittest import mock
    >>> with mock.patch.dict("os.environ", {"TEXSYNTH_MEMORY_BUDGET": "4e9"}):
    ...     memory_budget()
    4000000000
    >>> with mock.patch.dict("os.environ", {"TEXSYNTH_MEMORY_BUDGET": "1.5"}):
    ...     memory_budget()
    Traceback (most recent call last):
    ...
    ValueError: TEXSYNTH_MEMORY_BUDGET...
    """
    return budget_variable("TEXSYNTH_MEMORY_BUDGET", DEFAULT_MEMORY, "a whole number of bytes",
                            whole=True)


def budget_variable(name: str, default: float, unit: str, *, whole: bool = False) -> float:
    """The environment variable ``name`` as a positive finite number (``default`` when unset
    or empty), or ``ValueError`` naming the variable, its value and ``unit``; ``whole``: an
    integral value, returned as int. The one reader of the budget variables (memory and
    time).

    Examples
    --------
    >>> budget_variable("TEXSYNTH_NO_SUCH_BUDGET", 3600.0, "a number of seconds")
    3600.0
    """
    text = os.environ.get(name, "").strip()
    if not text:
        return default
    try:
        value = float(text)
    except ValueError:
        value = float("nan")
    if not (np.isfinite(value) and value > 0) or (whole and value != int(value)):
        raise ValueError(f"{name} must be {unit} greater than 0, got {text!r}; set it to a "
                         f"number like {default:.0f} or unset it")
    return int(value) if whole else value


def check_memory(need: float, what: str, advice: str = "") -> None:
    """:class:`BudgetError` before allocating when ``need`` bytes exceed :func:`memory_budget`."""
    budget = memory_budget()
    if need > budget:
        raise BudgetError(f"{what} needs about {need / 2**30:.1f} GiB, over the budget of "
                         f"{budget / 2**30:.1f} GiB (set TEXSYNTH_MEMORY_BUDGET to raise it"
                         f"{', or ' + advice if advice else ''})")

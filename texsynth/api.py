"""The synthesis entry points: validate, run the registered method, hand back a periodic image.

Every method goes through :func:`synthesize` (or :func:`synthesize_positions`): arguments are
checked by :mod:`texsynth.validation` and the time budget (:mod:`texsynth.budget`) before any
work, a constant alpha channel is set aside and put back, values of huge or tiny magnitude are
worked on at an exact power-of-two scale (``validation.magnitude_scale``), the method gets a
seeded ``numpy.random.Generator`` and a :class:`~texsynth.progress.Progress`, and its result is
checked against the promised shape.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import scipy.fft

from . import budget, validation
from .progress import Progress
from .registry import get_method, methods

__all__ = ["synthesize", "synthesize_positions", "check"]


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
        A name from :func:`texsynth.methods`.
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


def check(shape, width: int, height: int, *, method: str = "heeger_bergen", seed: int = 0,
          positions: bool = False, **params) -> tuple[int, int, int, dict]:
    """Every check :func:`synthesize` makes before any work, from the exemplar's shape alone.

    What a file's header tells is enough: a command line or a batch checks every photo this way
    before it starts. Returns ``(width, height, seed, params)`` as the method takes them, or
    raises ``ValueError`` (:class:`~texsynth.validation.BudgetError` over a budget) naming what
    to change. ``positions``: the run must give a position map.

    Examples
    --------
    >>> check((256, 256, 3), 512, 512, method="random_phase")[:3]
    (512, 512, 0)
    >>> check((4, 4, 3), 512, 512, method="random_phase")
    Traceback (most recent call last):
    ...
    ValueError: exemplar is 4 x 4 pixels; this needs at least 8 x 8
    """
    m = get_method(method)
    if positions and not m.positions:
        raise ValueError(f"method '{m.name}' does not copy exemplar pixels, so it has no "
                         "position map; use one of: "
                         + ", ".join(x.name for x in methods() if x.positions))
    values = m.resolve(params)
    validation.check_side(shape, m.min_exemplar)
    width, height = validation.size(width, height)
    seed = validation.seed(seed)
    shape = (*shape[:2], shape[2] if len(shape) == 3 else 1)
    # Time first: a run predicted to take days is refused for that, whatever memory it needs.
    budget.check_method(m, shape, width, height, values)
    validation.check_memory(m.memory(shape, width, height, values),
                            f"{width} x {height} with '{m.name}'")
    return width, height, seed, values


def _run(exemplar, width, height, method, seed, progress, params, want_positions):
    m = get_method(method)
    a = validation.image(exemplar, min_side=1)
    width, height, seed, values = check(a.shape, width, height, method=method, seed=seed,
                                        positions=want_positions, **params)

    constant_alpha = None
    if a.shape[2] == 4 and np.ptp(a[:, :, 3]) == 0:
        constant_alpha = a[0, 0, 3]
        a = np.ascontiguousarray(a[:, :, :3])

    report = Progress(progress)
    report(0.0, f"{m.label}: starting")
    rng = np.random.default_rng(seed)
    scale = validation.magnitude_scale(a)
    work = a if scale == 1.0 else (a.astype(np.float64) * scale).astype(np.float32)
    with scipy.fft.set_workers(-1):  # every core for the FFTs; results do not depend on it
        out = m.function(work, width, height, rng, report, **values)
    positions = None
    if m.positions:
        out, positions = out
        positions = np.ascontiguousarray(positions, dtype=np.int32)
        if scale != 1.0:
            out = a[positions[:, :, 0], positions[:, :, 1]]
    elif scale != 1.0:
        out = np.asarray(out, np.float64) / scale
    out = np.ascontiguousarray(out, dtype=np.float32)
    if out.shape != (height, width, a.shape[2]):
        raise AssertionError(f"{m.name} returned {out.shape}, "
                             f"expected {(height, width, a.shape[2])}")
    if constant_alpha is not None:
        out = np.concatenate([out, np.full((height, width, 1), constant_alpha, np.float32)], axis=2)
    report(1.0, f"{m.label}: done")
    return out, positions

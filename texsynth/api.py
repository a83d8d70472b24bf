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
from .blocks.parallel import serial_blas
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
    numpy.ndarray
        float32 (height, width, C), periodic in both directions. Alpha: a constant alpha
        channel (an opaque photo) is passed through unchanged; a varying one is synthesized
        together with the colour as a fourth channel.

    References
    ----------
    Each method cites its paper in its module (``texsynth.get_method(method).function``); the
    default, ``heeger_bergen``, is Forsyth & Ponce, section 11.3.2, Algorithm 11.4 (Heeger &
    Bergen 1995). docs/REFERENCES.md lists them all.

    Examples
    --------
    >>> import numpy as np, texsynth
    >>> photo = np.random.default_rng(0).random((32, 32, 3), dtype=np.float32)
    >>> out = texsynth.synthesize(photo, 48, 24, seed=3, iterations=2)
    >>> out.shape, out.dtype
    ((24, 48, 3), dtype('float32'))
    >>> np.array_equal(out, texsynth.synthesize(photo, 48, 24, seed=3, iterations=2))
    True
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

    ``apply_positions(positions, exemplar)`` is the image (after the same uint scaling), and
    ``apply_positions(positions, normal_map)`` makes another map of the material follow.

    Parameters
    ----------
    exemplar : array (H, W) or (H, W, C), C in 1, 3, 4
        As for :func:`synthesize`.
    width, height : int
        Output size, 1 to ``MAX_SIDE``.
    method : str
        A method with position maps (``get_method(name).positions``: ``multiscale_mrf``,
        ``efros_leung``, ``texture_optimization``); others raise ``ValueError``.
    seed : int
        Same inputs and seed give bit-identical output.
    progress : callable(fraction, message), optional
        As for :func:`synthesize`.
    **params
        The method's parameters.

    Returns
    -------
    image : numpy.ndarray
        The float32 (height, width, C) image :func:`synthesize` gives.
    positions : numpy.ndarray
        int32 (height, width, 2): per output pixel, the (row, col) of the exemplar pixel it
        shows.

    References
    ----------
    Neubeck, Zalesny & Van Gool 2004, section 3.1 (the position map ``S`` of the default,
    ``multiscale_mrf``); Efros & Leung 1999, section 2 (whole pixels copied).

    Examples
    --------
    >>> import numpy as np, texsynth
    >>> photo = np.random.default_rng(0).random((16, 16, 3), dtype=np.float32)
    >>> image, positions = texsynth.synthesize_positions(photo, 24, 20, seed=1)
    >>> positions.shape, positions.dtype
    ((20, 24, 2), dtype('int32'))
    >>> np.array_equal(texsynth.apply_positions(positions, photo), image)
    True
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
    # Time first: a run predicted to take days is refused for that, whatever memory it needs
    # (check_method's refusal names a faster method; the other entries check memory first).
    budget.check_method(m, shape, width, height, values)
    budget.admit(f"{width} x {height} with '{m.name}'",
                 peak=m.memory(shape, width, height, values))
    return width, height, seed, values


@serial_blas()
def _run(exemplar, width, height, method, seed, progress, params, want_positions):
    m = get_method(method)
    a = validation.image(exemplar, min_side=1)
    width, height, seed, values = check(a.shape, width, height, method=method, seed=seed,
                                        positions=want_positions, **params)

    constant_alpha = None
    if a.shape[2] == 4 and np.ptp(a[:, :, 3]) == 0:
        constant_alpha = a[0, 0, 3]
        a = np.ascontiguousarray(a[:, :, :3])

    rng, report = budget.start(seed, progress, f"{m.label}: starting")
    scale = validation.magnitude_scale(a)
    work = validation.ordinary(a, scale)
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

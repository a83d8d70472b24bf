"""The time budget, beside the memory budget: refuse a run predicted to take too long.

A method's ``cost(exemplar_shape, width, height, params)`` (``texsynth.registry.Method``)
predicts its run time in seconds on the reference machine. Each cost model lives with its
method (``_cost`` in the method's module): it counts the work of the method's inner loops (the
patch searches' matrix products, the pyramids' FFTs, the relaxations' gathers) and converts it
to seconds with coefficients fitted to measured runs (``python -m benchmarks.cost_models``
prints predictions against measurements); a prediction is good to about a factor of two.
This machine's speed relative to the reference is measured once per process by a tiny
calibration run (:func:`machine_factor`, about 0.1 s: the FFTs, gathers, counts and sorts the
methods spend their time in, on one thread and without BLAS so that the reading does not depend
on what ran before in the process), so a prediction is ``cost * machine_factor()``.

:func:`check_time` refuses, before any work, a run predicted to exceed :func:`time_budget`
(``TEXSYNTH_TIME_BUDGET`` seconds, default one hour), with a message naming the predicted
time and what to change.
"""

from __future__ import annotations

import time
from collections.abc import Callable

import numpy as np
import scipy.fft as sfft

from . import validation
from .registry import methods

__all__ = ["time_budget", "machine_factor", "predict", "check_time", "check_method", "describe",
           "DEFAULT_BUDGET"]

#: Seconds a run may be predicted to take when ``TEXSYNTH_TIME_BUDGET`` is not set.
DEFAULT_BUDGET = 3600.0
#: Seconds a run of the calibration workload takes on the reference machine, the fastest of
#: :data:`RUNS`: set so that the machine where the cost models were fitted (2 shared cores,
#: numpy 1.26; 2.1 ms a run) keeps reading 0.34, as fresh processes read its earlier workload.
REFERENCE_SECONDS = 0.0062
#: Runs of the calibration workload (a few ms each) after the warm-up.
RUNS = 15

_factor: float | None = None


def time_budget() -> float:
    """Seconds a run may be predicted to take: ``TEXSYNTH_TIME_BUDGET`` or one hour."""
    return validation.budget_variable("TEXSYNTH_TIME_BUDGET", DEFAULT_BUDGET,
                                      "a number of seconds")


def _workload() -> Callable[[], float]:
    """A run of a fixed mix of the methods' kernels that returns its seconds: real FFTs there and
    back (the pyramids), a gather, a bincount and a sort (the tables and relaxations).

    It touches neither BLAS nor fresh pages, on one thread: OpenBLAS' threads left spinning by
    earlier work took the core a matrix product wanted (a 1.5x slower reading after the
    metrics), and fresh arrays of MBs cost page faults that depend on the allocator's state
    (glibc's mmap threshold rises after a large free; Blender brings its own allocator), which
    read 0.2 inside Blender and 0.34 in a fresh Python. Every array is kept or under 128 KiB."""
    rng = np.random.default_rng(0)
    image = rng.random((128, 128), dtype=np.float32)
    index = rng.integers(0, image.size, 1 << 14)
    gathered = np.empty(index.size, np.float32)
    bins = np.empty(index.size, np.intp)
    ordered = np.empty(index.size, np.float32)

    def run() -> float:
        start = time.perf_counter()
        for _ in range(4):
            sfft.irfft2(sfft.rfft2(image, workers=1), image.shape, workers=1)
            np.take(image.ravel(), index, out=gathered)
            np.multiply(gathered, 255.0, out=gathered)
            np.copyto(bins, gathered, casting="unsafe")
            np.bincount(bins, minlength=256)
            np.copyto(ordered, gathered)
            ordered.sort()
        return time.perf_counter() - start

    return run


def machine_factor() -> float:
    """This machine's time for the calibration workload over the reference machine's: the
    fastest of :data:`RUNS` runs after a warm-up (the slower ones lost time slices to other
    processes), measured once per process and clipped to 0.1 .. 100."""
    global _factor
    if _factor is None:
        run = _workload()
        run()
        _factor = float(np.clip(min(run() for _ in range(RUNS)) / REFERENCE_SECONDS, 0.1, 100.0))
    return _factor


def predict(method, exemplar_shape, width: int, height: int, params: dict) -> float:
    """Predicted seconds of ``method`` (a registry ``Method``) on this machine."""
    return float(method.cost(tuple(exemplar_shape), width, height, params)) * machine_factor()


def describe(seconds: float) -> str:
    """A duration as people say it: '0.4 s', '12 s', '7 min', '3.2 h', '2.5 days'."""
    if seconds < 10:
        return f"{seconds:.1f} s"
    if seconds < 120:
        return f"{seconds:.0f} s"
    if seconds < 7200:
        return f"{seconds / 60:.0f} min"
    if seconds < 172800:
        return f"{seconds / 3600:.1f} h"
    return f"{seconds / 86400:.1f} days"


def check_time(seconds: float, what: str, advice: str = "") -> None:
    """``ValueError`` before any work when ``seconds`` (predicted) exceed :func:`time_budget`."""
    budget = time_budget()
    if seconds > budget:
        raise ValueError(f"{what} is predicted to take about {describe(seconds)}, over the time "
                         f"budget of {describe(budget)}; choose a smaller size"
                         f"{', ' + advice if advice else ''}, or set TEXSYNTH_TIME_BUDGET "
                         "(seconds) to raise the budget")


def check_method(method, exemplar_shape, width: int, height: int, params: dict) -> float:
    """The predicted seconds of a synthesis with ``method``, or ``ValueError`` over the budget
    naming the predicted time and, when one fits the budget, the fastest other method."""
    seconds = predict(method, exemplar_shape, width, height, params)
    if seconds > time_budget():
        others = sorted((predict(m, exemplar_shape, width, height, m.resolve({})), m.name)
                        for m in methods() if m.name != method.name
                        and m.memory(exemplar_shape, width, height, m.resolve({}))
                        <= validation.memory_budget())
        fits = [(t, name) for t, name in others if t <= time_budget()]
        advice = (f"a faster method ('{fits[0][1]}': about {describe(fits[0][0])})"
                  if fits else "")
        check_time(seconds, f"{width} x {height} with '{method.name}'", advice)
    return seconds

"""Running independent pieces of numpy work on every core.

numpy and scipy release the GIL inside their large loops (ufuncs, ``take``, ``bincount``,
reductions, pocketfft), so Python threads run such pieces side by side. Callers split work so
that the result never depends on the split: elementwise work on disjoint ranges, exact
reductions (integer counts, minimum, maximum), or whole independent transforms combined in a
fixed order. The number of cores and the timing then change only the speed, never the output.
"""

from __future__ import annotations

import os
import threading
from concurrent.futures import ThreadPoolExecutor
from contextlib import ContextDecorator

import numpy as np
import scipy.linalg  # noqa: F401  (loads scipy's BLAS, for _BLAS to find)
from threadpoolctl import ThreadpoolController

__all__ = ["CORES", "WORKERS", "run", "ranges", "threads", "small_product", "serial_blas"]

#: The cores this process may use.
CORES = max(1, len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity")
            else os.cpu_count() or 1)
#: Threads of the shared pool: ``TEXSYNTH_THREADS`` where set (a batch's worker takes its
#: share of the cores: two workers of two threads each on 2 cores wait on each other's
#: descheduled halves), else :data:`CORES`.
WORKERS = max(1, int(os.environ.get("TEXSYNTH_THREADS") or 0) or CORES)
_pool: ThreadPoolExecutor | None = None
_lock = threading.Lock()
#: The BLAS libraries (numpy's and scipy's, both loaded by the imports above), found once at
#: import: the search (every loaded library's real path) took 10-25 ms in a process's
#: first run, before its first fraction, which the time left then read as 9 times that at 10 %
#: (issue 40: heeger_bergen 128 -> 256, the benchmark's first run, told 1.55x); later runs ~1 ms.
#: At import, the command's start watches it (``texsynth.interrupts``): the search runs in a
#: ctypes callback, which prints a KeyboardInterrupt raised in it and drops it (1 in 150 Ctrl+C
#: tries had the run go on).
_BLAS = ThreadpoolController()
_inside = threading.local()                          # set in the pool's threads


def _mark_inside() -> None:
    _inside.flag = True


def _executor() -> ThreadPoolExecutor:
    global _pool
    with _lock:
        if _pool is None:
            _pool = ThreadPoolExecutor(WORKERS, thread_name_prefix="texsynth",
                                       initializer=_mark_inside)
        return _pool


def run(function, items, tick=None) -> list:
    """``[function(item) for item in items]``, the calls spread over the pool's threads.

    Called from inside the pool (a nested split), or with one item or one core, the calls run
    in this thread, so nesting never waits on itself. ``tick()``, if given, is called in this
    thread as each result comes in (in order): a progress report, so a cancel raised there is
    heard within one item; the items not yet started are then dropped.
    """
    items = list(items)
    if len(items) < 2 or WORKERS < 2 or getattr(_inside, "flag", False):
        results = []
        for item in items:
            results.append(function(item))
            if tick is not None:
                tick()
        return results
    futures = [_executor().submit(function, item) for item in items]
    try:
        results = []
        for future in futures:
            results.append(future.result())
            if tick is not None:
                tick()
        return results
    finally:
        for future in futures:
            future.cancel()


def ranges(n: int, smallest: int = 1 << 16) -> list[tuple[int, int]]:
    """``[start, stop)`` ranges covering ``range(n)``: one per worker, none under ``smallest``
    elements (fewer ranges for small ``n``)."""
    parts = max(1, min(WORKERS, n // smallest))
    bounds = [n * i // parts for i in range(parts + 1)]
    return list(zip(bounds[:-1], bounds[1:], strict=True))


def threads() -> int:
    """Threads for a library call that splits its own work (scipy's ``workers=``): every core,
    or one inside the pool (its calls already run side by side)."""
    return 1 if getattr(_inside, "flag", False) else WORKERS


def small_product(subscripts: str, *operands: np.ndarray) -> np.ndarray:
    """``np.einsum(subscripts, *operands)`` for products of many pixels by a small matrix (the
    colour turns, the steering of K bands), in this thread: OpenBLAS's threads, which ``@``
    would wake, cost more than they save at these shapes (2x the CPU time on 2 shared cores)
    and keep spinning after the call (a tenth of Heeger-Bergen's time at 2048^2)."""
    return np.einsum(subscripts, *operands)


class serial_blas(ContextDecorator):
    """Inside it (``with serial_blas():`` or as a decorator of an entry), BLAS runs on one thread.

    The methods' matrix products are small (a neighbourhood table's rows against a few queries,
    3 x 3 colour turns, Portilla-Simoncelli's correlations): OpenBLAS's threads save little on
    them quiet and wait on each other's descheduled halves when another program holds a core.
    Measured on 2 cores with four nice-15 processes running beside it (issue 45): Efros-Leung
    4096 x 16 from 32 x 32 took 31.7 s of wall clock with OpenBLAS's 2 threads (4.95 s of CPU)
    and 2.16 s with one; texture_optimization 256 x 256 3.42 s and 0.92 s; de_bonet 1.50 s and
    0.51 s; quiet, one thread read 0.84x the two's time (2.16 s and 2.57 s). The limit is the
    process's (OpenBLAS keeps one setting), set by the first of overlapping entries in any
    thread and restored when the last leaves (threadpoolctl: it finds the loaded BLAS, whichever
    numpy brings it, where a hand-written ``openblas_set_num_threads`` would know one build).

    Examples
    --------
    >>> from threadpoolctl import threadpool_info
    >>> with serial_blas():
    ...     inside = [pool["num_threads"] for pool in threadpool_info()
    ...               if pool["user_api"] == "blas"]
    >>> bool(inside) and set(inside) == {1}
    True
    """

    _lock = threading.Lock()
    _users = 0
    _limiter = None

    def __enter__(self):
        cls = type(self)
        with cls._lock:
            if cls._users == 0:
                cls._limiter = _BLAS.limit(limits=1, user_api="blas")
            cls._users += 1
        return self

    def __exit__(self, *exc):
        cls = type(self)
        with cls._lock:
            cls._users -= 1
            if cls._users == 0:
                cls._limiter.restore_original_limits()
                cls._limiter = None
        return False

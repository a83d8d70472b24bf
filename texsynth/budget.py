"""The time budget, beside the memory budget: refuse a run predicted to take too long.

A method's ``cost(exemplar_shape, width, height, params)`` (``texsynth.registry.Method``)
predicts its run time in seconds on the reference machine. Each cost model lives with its
method (``_cost`` in the method's module): it counts the work of the method's inner loops (the
patch searches' matrix products, the pyramids' FFTs, the relaxations' gathers) and converts it
to seconds with coefficients fitted to measured runs (``python -m benchmarks.cost_models``
prints predictions against measurements); a prediction is good to about a factor of two.
This machine's speed relative to the reference is measured once per process by a short
calibration run (:func:`speed`, about 0.15 s: the FFTs, gathers and counts the methods spend
their time in, on one thread and without BLAS so that the reading does not depend on what ran
before in the process). A prediction is for the machine as it is, so the speed is
multiplied by the load other programs put on it (:func:`contention`: the tasks wanting a core
per core, read from the kernel, at least 1): ``cost * machine_factor()``, ``machine_factor() =
speed() * contention()``, plus the run's peak bytes at this machine's price of a fresh page
(:func:`seconds`, :func:`page_seconds`: the kernel's and a hypervisor's work, which the core's
speed does not tell). Why not the calibration runs' wall-clock median instead of a
load figure: on 2 cores at load 7-10 the fastest wall-clock run still read about the quiet
machine's speed (0.33-0.46) while the methods took 1.3-12x their quiet time, and the median
read 0.34-3.6 in the same processes, following neither.

:func:`check_time` refuses, before any work, a run predicted to exceed :func:`time_budget`
(``TEXSYNTH_TIME_BUDGET`` seconds, default one hour), with a message naming the predicted
time and what to change.

Every entry point's prologue has its home here too: :func:`admit` checks a run's predicted
peak bytes (``validation.check_memory``) and seconds (:func:`check_time`) before any work, and
:func:`start` makes its seeded generator and its :class:`~texsynth.progress.Progress`.
"""

from __future__ import annotations

import mmap
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np

from . import validation
from .blocks import feature_distance, fft
from .blocks.parallel import CORES
from .progress import Progress
from .registry import get_method, methods

__all__ = ["time_budget", "speed", "page_seconds", "seconds", "contention", "machine_factor",
           "predict", "forecast",
           "forecast_line", "check_time", "check_method", "describe", "admit", "start",
           "DEFAULT_BUDGET"]

#: Seconds a run may be predicted to take when ``TEXSYNTH_TIME_BUDGET`` is not set.
DEFAULT_BUDGET = 3600.0
#: Seconds a run of the calibration workload takes on the reference machine, the median of
#: :data:`RUNS`: set so that a 2026-12 host (AMD EPYC, 2 cores, the second; about 6.7 ms a
#: run at load 10) reads the median of the quiet predictions benchmark's seconds over its cost
#: models' (0.59, 27 rows but multiscale_mrf's: the median of 25 runs reads 1.13x the
#: fastest there, which had read 0.44 typical, 0.31-0.65 a row, at this constant's 0.0100).
REFERENCE_SECONDS = 0.0085
#: Runs of the calibration workload (a few ms each) after the :data:`WARMUP` runs.
RUNS = 21
#: Runs first left out: the first runs' FFT plans and caches (2.7x, then 0.8-1.0x the later
#: runs' 0.7 at load 10).
WARMUP = 4
#: Seconds a reading of the load is kept (a Blender session lasts hours; the panel redraws often).
REFRESH = 60.0
#: Linux's load figures: the 1-minute average, then runnable/all tasks at this instant.
LOADAVG = Path("/proc/loadavg")
#: Linux's tasks (``/proc/PID/task/TID/stat``: state, nice) and scheduling groups.
PROC = Path("/proc")

#: Bytes of the fresh anonymous mapping whose first touch :func:`page_seconds` times.
PAGE_PROBE = 16 << 20

_speed: float | None = None
_page: float | None = None
_load: tuple[float, float] | None = None  # (time.monotonic() of the reading, contention)


def time_budget() -> float:
    """Seconds a run may be predicted to take: ``TEXSYNTH_TIME_BUDGET`` or one hour."""
    return validation.budget_variable("TEXSYNTH_TIME_BUDGET", DEFAULT_BUDGET,
                                      "a number of seconds")


def _workload() -> Callable[[], float]:
    """A run of a fixed mix of the methods' kernels at their working-set size that returns its
    seconds of this thread's CPU time (time other processes take from it is not counted, so the
    reading stays the quiet machine's under load): real FFTs there and back of a 512 x 512
    image (the pyramids), a gather of 2^18 of its values and a bincount (the tables and
    relaxations). Arrays of MBs, as the methods' are: the earlier workload's 128 x 128 fitted in
    the caches and read a 2026-12 host (AMD EPYC, 2 cores) 3.4x faster than the reference where
    the methods ran 0.9x as fast.

    It touches neither BLAS nor fresh pages, on one thread: OpenBLAS' threads left spinning by
    earlier work took the core a matrix product wanted (a 1.5x slower reading after the
    metrics), and fresh arrays of MBs cost page faults that depend on the allocator's state
    (glibc's mmap threshold rises after a large free; Blender brings its own allocator), which
    read 0.2 inside Blender and 0.34 in a fresh Python. Every array is made once and kept; the
    FFTs write into kept buffers (``blocks.fft``).

    No sort, a deviation from the methods' mix: the 2^18 floats' sort took 10-12 ms of a 12-16
    ms run on the shared host at load 7 (about 2 ms quiet) while heeger_bergen and
    multiscale_mrf ran at their quiet speed beside it, so the reading, 0.9 there against about
    0.3 quiet, had told 3-4x their time."""
    side = 512
    rng = np.random.default_rng(0)
    image = rng.random((side, side), dtype=np.float32)
    spectrum = np.empty((side, side // 2 + 1), np.complex64)
    inverse = np.empty_like(image)
    index = rng.integers(0, image.size, 1 << 18)
    gathered = np.empty(index.size, np.float32)
    bins = np.empty(index.size, np.intp)

    def run() -> float:
        start = time.thread_time()
        fft.irfft2(fft.rfft2(image, out=spectrum, workers=1), image.shape, out=inverse,
                   workers=1)
        np.take(image.ravel(), index, out=gathered)
        np.multiply(gathered, 255.0, out=gathered)
        np.copyto(bins, gathered, casting="unsafe")
        np.bincount(bins, minlength=256)
        return time.thread_time() - start

    return run


def speed() -> float:
    """This machine's time for the calibration workload over the reference machine's: the
    median of :data:`RUNS` runs after :data:`WARMUP`, in this thread's CPU time, so that runs
    that lost the core to other processes do not read slow (at load 9 on 2 cores a process's
    fastest wall-clock run read 1.6 or more once), measured once per process and clipped to
    0.1 .. 100. The median, not the fastest: one run in 20-50 reads 0.6x the others (0.38 among
    0.68 at load 10), so the fastest of 15 read 0.31-0.65 in fresh processes of one quiet
    predictions run (0.40-0.66 at load 11, the median of 25 0.63-0.79 in the same processes).

    Examples
    --------
    >>> speed() == speed() and 0.1 <= speed() <= 100
    True
    """
    global _speed
    if _speed is None:
        run = _workload()
        for _ in range(WARMUP):
            run()
        seconds = float(np.median([run() for _ in range(RUNS)]))
        _speed = float(np.clip(seconds / REFERENCE_SECONDS, 0.1, 100.0))
    return _speed


def page_seconds() -> float:
    """Seconds this machine takes to give a process one byte of memory it has not had: the first
    touch of every page of a fresh anonymous mapping of :data:`PAGE_PROBE` bytes, in this
    thread's CPU time, once per process. A run's peak bytes are new pages at least once, and
    their price is the kernel's and the hypervisor's, not the core's: on a 2026-12 virtual
    machine whose host takes back freed memory, 0.6-3.0 ms a MiB (random_phase 4096^2 from
    32^2 spent 1.1 s of its 1.5 s touching its buffers, where the core's speed told 0.69 s in
    all); on an ordinary host about a tenth of a millisecond.

    Examples
    --------
    >>> 0 < page_seconds() < 1e-6
    True
    """
    global _page
    if _page is None:
        probe = mmap.mmap(-1, PAGE_PROBE)
        pages = np.frombuffer(probe, np.uint8)
        start = time.thread_time()
        pages[::mmap.PAGESIZE] = 1
        _page = (time.thread_time() - start) / PAGE_PROBE
        del pages
        probe.close()
    return _page


def seconds(cost: float, peak: float) -> float:
    """Seconds on this machine, as loaded now, of a run of ``cost`` reference seconds whose peak
    is ``peak`` bytes: the core's time (:func:`speed`) and the fresh pages' (:func:`page_seconds`),
    both slowed by the load (:func:`contention`)."""
    return cost * machine_factor() + peak * page_seconds() * contention()


def _weight(nice: int) -> float:
    """A task's share of a core beside a nice-0 task's: CFS gives each nice level about 1.25x
    the CPU of the next (Linux, Documentation/scheduler/sched-nice-design.rst; the kernel's
    ``sched_prio_to_weight`` table over 1024)."""
    return 1.25 ** -nice


#: The least a runnable task of lower priority counts for beside this one: the CPU goes to
#: this run, the memory bandwidth and caches it shares do not. Measured: at load 7.6 of
#: nice-15 tasks on 2 cores, a nice -19 predictions section ran 1.2-2.2x (median 1.8x) its
#: quiet times (heeger_bergen 512: 3.24 against 2.06 s), (1 + 6.6 x 0.4) / 2 = 1.8.
LOWER_FLOOR = 0.4


def _weighted_runnable() -> float | None:
    """The tasks runnable at this instant, each counted as its share beside this process
    (:func:`_weight` of its nice over this process's, at least :data:`LOWER_FLOOR`), this one
    included; another autogroup with runnable tasks counts as one where the kernel's
    autogroups are on (it shares a core between groups, then within a group by nice); None
    where ``PROC`` does not say. Ours, a deviation from the plain count: a benchmark run at
    nice -19 beside nice-15 processes had been told their whole load (3.8x its quiet time at
    load 7.6 on 2 cores) and ran 1.8x."""
    try:
        own = PROC / "self"
        autogroups = PROC.joinpath("sys/kernel/sched_autogroup_enabled")
        grouped = own.joinpath("autogroup").exists() and (
            not autogroups.exists() or autogroups.read_text().strip() != "0")
        group = own.joinpath("autogroup").read_text().split()[0] if grouped else None
        mine = _weight(int(own.joinpath("stat").read_text().rsplit(")", 1)[1].split()[16]))
        total, groups = 0.0, set()
        for stat in PROC.glob("[0-9]*/task/[0-9]*/stat"):
            try:
                fields = stat.read_text().rsplit(")", 1)[1].split()
                if fields[0] != "R":
                    continue
                other = None if group is None \
                    else stat.parents[2].joinpath("autogroup").read_text().split()[0]
            except (OSError, IndexError):
                continue                                  # the task ended meanwhile
            if other in (None, group):
                total += max(_weight(int(fields[16])) / mine, LOWER_FLOOR)
            else:
                groups.add(other)
        return max(total, 1.0) + len(groups)
    except (OSError, IndexError, ValueError):
        return None


def _runnable() -> float | None:
    """Tasks that want a core, this one included: the smaller of the 1-minute load average and
    the tasks runnable at this instant weighted by their nice (:func:`_weighted_runnable`;
    the plain count where that cannot be read; the average alone still holds a run that has
    just ended; the instant alone flickers); None where the kernel does not say (not
    Linux)."""
    try:
        fields = LOADAVG.read_text().split()
        now = _weighted_runnable() if PROC.joinpath("self").exists() else None
        return min(float(fields[0]), float(fields[3].split("/")[0]) if now is None else now)
    except (OSError, IndexError, ValueError):
        return None


def contention() -> float:
    """How many times slower than on the idle machine a run goes now: the tasks that want a core
    per core (:func:`_runnable` over the cores this process may use), at least 1, at most 100;
    1 where the kernel does not say. Read again after :data:`REFRESH` seconds.

    Ours, a deviation from fair sharing: a run of k threads among L others gets k / (L + k) of
    the cores, (L + k) / cores times slower; k is taken as 1 (this task), so a method on every
    core is predicted up to (cores - 1 + L) / (L + 1) too fast under load.

    Examples
    --------
    >>> 1.0 <= contention() <= 100.0
    True
    """
    global _load
    now = time.monotonic()
    if _load is None or now - _load[0] > REFRESH:
        runnable = _runnable()
        _load = (now, 1.0 if runnable is None else float(np.clip(runnable / CORES, 1.0, 100.0)))
    return _load[1]


def machine_factor() -> float:
    """Seconds on this machine, as loaded now, of a reference second: :func:`speed` times
    :func:`contention`.

    Examples
    --------
    >>> machine_factor() == speed() * contention()
    True
    """
    return speed() * contention()


def predict(method, exemplar_shape, width: int, height: int, params: dict) -> float:
    """Predicted seconds of ``method`` (a registry ``Method``) on this machine (:func:`seconds`
    of its cost and memory models)."""
    shape = tuple(exemplar_shape)
    return seconds(float(method.cost(shape, width, height, params)),
                   float(method.memory(shape, width, height, params)))


def forecast(method_name: str, exemplar_shape, width: int, height: int,
             params: dict | None = None, exemplar=None) -> tuple[float, float]:
    """(seconds on this machine as loaded now, peak bytes) predicted for a synthesis, before any
    work: the method's cost model (:func:`predict`) and memory model (``Method.memory``), with
    its defaults for the ``params`` not given; an exemplar of shape (H, W) is one channel.
    Given the ``exemplar`` itself, a joint width the method would measure (``joint_width`` 0)
    is measured here, so the models count the joints' channels and repair where it has them
    (``feature_distance.measured_width``; from the shape alone they are counted without: the
    12 MP setts' rectified crop to 1024 with multiscale_mrf was told 0.39x its time).

    Examples
    --------
    >>> seconds, peak = forecast("random_phase", (128, 128, 3), 256, 256)
    >>> 0 < seconds < 60 and 0 < peak < 2**30
    True
    """
    method = get_method(method_name)
    values = method.resolve(params or {})
    if exemplar is not None and values.get("joint_width") == 0:
        values["joint_width"] = feature_distance.measured_width(
            exemplar, 0.0, values.get("feature_weight", 0.0))
    shape = tuple(exemplar_shape)
    shape = shape if len(shape) == 3 else shape + (1,)
    return (predict(method, shape, width, height, values),
            float(method.memory(shape, width, height, values)))


def forecast_line(seconds: float, peak: float) -> str:
    """The one line printed before the work: 'predicted: about 12 s, 1.5 GiB peak'.

    Examples
    --------
    >>> forecast_line(70.0, 2.1 * 2**30)
    'predicted: about 70 s, 2.1 GiB peak'
    >>> forecast_line(0.4, 30 * 2**20)
    'predicted: about 0.4 s, 30 MiB peak'
    """
    memory = f"{peak / 2**30:.1f} GiB" if peak >= 2**30 else f"{peak / 2**20:.0f} MiB"
    return f"predicted: about {describe(seconds)}, {memory} peak"


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
    """:class:`~texsynth.validation.BudgetError` before any work when ``seconds`` (predicted)
    exceed :func:`time_budget`."""
    budget = time_budget()
    if seconds > budget:
        raise validation.BudgetError(
            f"{what} is predicted to take about {describe(seconds)}, over the time "
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


def admit(what: str, *, peak: float | None = None, seconds: float | None = None,
          memory_advice: str = "", time_advice: str = "") -> None:
    """Both budgets of a run, before any work: ``peak`` bytes, then ``seconds`` (predicted on
    this machine as loaded now); either left out is not checked.

    Parameters
    ----------
    what : str
        The run, as the refusal names it ("making the 512 x 512 photo tileable").
    peak : float, optional
        Its predicted peak bytes, against :func:`texsynth.validation.memory_budget`.
    seconds : float, optional
        Its predicted seconds on this machine, against :func:`time_budget`.
    memory_advice, time_advice : str
        What else to change, added to each refusal ("a narrower band").

    Raises
    ------
    texsynth.validation.BudgetError
        Over either budget (memory is checked first), naming the prediction and the budget.

    References
    ----------
    docs/ARCHITECTURE.md, Conventions, "Entry points" and "Methods" (the memory estimate and
    the cost model, checked before any allocation).

    Examples
    --------
    >>> admit("a small run", peak=2**20, seconds=0.5)
    >>> admit("a huge run", peak=2**50)
    Traceback (most recent call last):
    ...
    texsynth.validation.BudgetError: a huge run needs about 1048576.0 GiB, over the budget ...
    """
    if peak is not None:
        validation.check_memory(peak, what, memory_advice)
    if seconds is not None:
        check_time(seconds, what, time_advice)


def start(seed, progress: Callable[[float, str], object] | None = None,
          message: str | None = None) -> tuple[np.random.Generator, Progress]:
    """A run's seeded generator and progress reporter, made the one way every entry makes them.

    Parameters
    ----------
    seed : int or numpy.random.Generator
        A seed (a non-negative whole number, checked) or, inside the core, a generator passed
        down, which is used as it is.
    progress : callable(fraction, message) or Progress, optional
        The caller's callback; a :class:`~texsynth.progress.Progress` (a span handed down) is
        used as it is.
    message : str, optional
        Reported at fraction 0 before returning ("Heeger-Bergen: starting").

    Returns
    -------
    rng : numpy.random.Generator
    report : Progress

    References
    ----------
    docs/ARCHITECTURE.md, Conventions, "Randomness" (one ``default_rng(seed)`` a public call)
    and "Progress".

    Examples
    --------
    >>> rng, report = start(7)
    >>> float(rng.random()) == float(np.random.default_rng(7).random())
    True
    >>> start(-1)
    Traceback (most recent call last):
    ...
    ValueError: seed must be a non-negative whole number, got -1
    """
    rng = seed if isinstance(seed, np.random.Generator) \
        else np.random.default_rng(validation.seed(seed))
    report = progress if isinstance(progress, Progress) else Progress(progress)
    if message is not None:
        report(0.0, message)
    return rng, report

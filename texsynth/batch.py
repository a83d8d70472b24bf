"""Every photo of a folder or manifest through texsynth on Dask: survives lost workers, resumes.

:func:`plan` turns a folder (every image file in it) or a manifest (CSV or TSV, one row per
task) into :class:`~texsynth.jobs.Job` records, checked as the command line checks its one job
(:mod:`texsynth.jobs`: outputs that are inputs, outputs that are one file, a folder that would
read its own outputs next time, every photo, map, size, seed and parameter, the budgets and the
output folder, all before the cluster starts); :func:`run` sends the jobs that are not done yet
to Dask distributed (a local cluster of worker processes, or a running scheduler) as
independent tasks of :func:`~texsynth.jobs.run_job`. Dask is imported by :func:`run` alone:
the rest of the core never needs it (``pip install "texsynth[batch]"``).

The properties a batch keeps:

- **A task is a pure function** of its inputs' content and its parameters: the output's *key*
  is the SHA-256 of both and of texsynth's source code; same key, same bits.
- **Atomic writes**: a task's files go to temporary files in the output folder and are renamed
  over their names when all are complete; the keys, in ``OUTDIR/.texsynth/``, are written the
  same way after the outputs. A task killed mid-write leaves ``.texsynth-tmp-*`` files, which
  the batch removes when it ends.
- **Lost workers**: Dask runs a lost worker's tasks again on another worker. A task first looks
  for its outputs with its key and does nothing when they are there, so an output that was
  finished before the worker died is not written twice.
- **Resume**: :func:`run` leaves out the jobs whose outputs all carry their key and the bytes
  it records; a re-run does only what is missing or changed (an output deleted, truncated or
  overwritten, a changed photo, new code), and starts no cluster when nothing is.

A manifest has a header row and these columns (only ``photo`` is required; an empty cell takes
the command line's value): ``photo``, ``maps`` (other maps of the material, ``;``-separated),
``operation`` (``synthesize``, ``tile`` or ``material``), ``method``, ``size`` (``N`` or
``WxH``), ``seed``, ``band``, ``in_size`` (``N`` or ``WxH``: the photo resampled first),
``params`` (``name=value;...``), and for ``material`` ``mask`` (white: to heal) and
``corners`` (``x1,y1,...,x4,y4``: rectify by that rectangle). Paths are relative to the
manifest's folder.
"""

from __future__ import annotations

import contextlib
import csv
import hashlib
import heapq
import json
import logging
import math
import os
import signal
import time
from collections.abc import Callable
from dataclasses import dataclass, field, replace
from pathlib import Path

from .blocks.parallel import CORES
from .io.files import TEMP_PREFIX
from .jobs import (
    DEFAULT_METHOD,
    KEYS,
    OPERATIONS,
    PHOTO_SUFFIXES,
    InputError,
    Job,
    UsageError,
    check_plan,
    default_bits,
    is_done,
    key,
    material_job,
    parse_in_size,
    parse_size,
    preflight,
    run_job,
)
from .validation import memory_budget

__all__ = ["OPERATIONS", "Defaults", "Job", "Summary", "plan", "forecast", "run",
           "run_job", "is_done"]

@dataclass(frozen=True)
class Defaults:
    """The command line's values, for every photo of a folder and every empty manifest cell."""

    operations: tuple[str, ...] = ("synthesize",)
    method: str = DEFAULT_METHOD
    size: tuple[int, int] = (1024, 1024)
    seed: int = 0
    params: dict = field(default_factory=dict)
    band: int | None = None
    format: str | None = None  # an output suffix without the dot; None: EXR from EXR, else PNG
    bits: int | None = None
    data: bool = False
    in_size: tuple[int, int] | None = None  # (W, H); H 0: the longer side W, aspect kept


@dataclass
class Summary:
    """What a batch did; ``failed`` holds one line per failed task."""

    total: int
    done: int = 0
    skipped: int = 0
    failed: list[str] = field(default_factory=list)
    seconds: float = 0.0
    overhead: float = 0.0  # of ``seconds``: connecting, or starting and closing a local cluster

    def line(self) -> str:
        return (f"{self.total} tasks: {self.done} done, {self.skipped} already done, "
                f"{len(self.failed)} failed in {self.seconds:.1f} s (cluster start and close: "
                f"{self.overhead:.1f} s)")


# --- planning -------------------------------------------------------------------------------

def plan(source, out_dir, defaults: Defaults = Defaults()) -> list[Job]:
    """The jobs of a folder or manifest, every row checked before anything runs.

    Each job is checked as :mod:`texsynth.jobs` checks the command line's (``check_plan``,
    then ``preflight``): raises :class:`~texsynth.jobs.JobError` naming the manifest row and
    column of a bad value, a missing or unreadable photo or map, two tasks that would write one
    file, an output that is an input, or an output folder that would feed the next run.
    Each job carries its predicted (seconds, peak bytes) as ``forecast`` (summed by
    :func:`forecast`).

    Examples
    --------
    >>> import tempfile, numpy as np
    >>> from texsynth.io import write_image
    >>> folder = Path(tempfile.mkdtemp())
    >>> write_image(folder / "sand.png", np.zeros((32, 32, 3), np.float32))
    >>> [Path(o).name for job in plan(folder, folder / "out") for o in job.outputs]
    ['sand_multiscale_mrf_1024x1024_s0.png']
    """
    source, out_dir = Path(source), Path(out_dir)
    if not source.exists():
        raise InputError(f"{source}: no such folder or manifest")
    if source.is_dir():
        rows = [(str(p), {"photo": str(p)}) for p in sorted(source.iterdir())
                if p.is_file() and p.suffix.lower() in PHOTO_SUFFIXES]
        if not rows:
            raise InputError(f"{source}: no image files ({', '.join(PHOTO_SUFFIXES)})")
    else:
        rows = _manifest_rows(source)
    jobs = [job for where, row in rows for job in _jobs(where, row, out_dir, defaults)]
    check_plan(jobs, source_folder=source if source.is_dir() else None)
    return [replace(job, forecast=f) for job, f in zip(jobs, preflight(jobs), strict=True)]


#: How much slower a task runs on one of two cores than on both (the thread pool overlaps
#: little of it), fitted with the tasks dealt as :func:`forecast` deals them: the batch
#: section's 6 tasks 256 -> 768 took 14.0 s on 2 workers of 1 thread (its cluster's start and
#: close left out), the same one by one in one process on 2 threads 20.0 s, whose longest
#: first deal puts 0.56 of it (the 1.8x task and two others, as measured one by one: 5.6 of
#: 20.9 s and 3.1 s each) on one worker: 14.0 / (0.56 x 20.0) = 1.25; the batch of
#: d85fab1, 21.9 s against 30.6 s: 1.28 (issue 45: 1.43, 2 x 14.0 / 20.0, took the tasks as
#: evenly shared, and the deal counted the longest worker's excess over the mean again: the
#: forecast read 23.5 s for 15.0).
POOL_GAIN = 1.26
#: Seconds a local cluster takes to start and close beside the tasks (the batch section's
#: summaries: 1.0 and 1.0 s; it starts while the inputs are hashed).
CLUSTER_SECONDS = 1.0


def forecast(jobs: list[Job], workers: int | None = None,
             local: bool = True) -> tuple[float, float]:
    """The batch's predicted (seconds, peak bytes) on this machine, from each planned job's
    ``forecast`` (its seconds on every core): each task slowed by :data:`POOL_GAIN` for every
    halving of the cores its worker gets, the tasks dealt longest first to the worker free
    first (LPT, the cluster's order in :func:`run`), and a ``local`` cluster's start and close
    (:data:`CLUSTER_SECONDS`; none for a running scheduler's); the peak is the largest task's
    once per worker process (:func:`default_workers`).

    Examples
    --------
    >>> jobs = [Job(photo="a.png", outputs=("o.png",), forecast=(2.0, 100.0)),
    ...         Job(photo="b.png", outputs=("p.png",), forecast=(3.0, 300.0))]
    >>> forecast(jobs, workers=1, local=False)
    (5.0, 300.0)
    """
    known = [job.forecast for job in jobs if job.forecast is not None]
    workers = workers or default_workers(jobs)
    slowdown = POOL_GAIN ** math.log2(CORES / max(1, CORES // workers))
    free = [0.0] * workers
    for seconds in sorted((seconds for seconds, _ in known), reverse=True):
        heapq.heapreplace(free, free[0] + seconds * slowdown)
    return (float(max(free)) + (CLUSTER_SECONDS if local and known else 0.0),
            max((peak for _, peak in known), default=0.0) * workers)


#: A manifest's columns (docs/BATCH.md).
COLUMNS = ("photo", "maps", "operation", "method", "size", "seed", "params", "band", "in_size",
           "mask", "corners")


def _manifest_rows(path: Path) -> list[tuple[str, dict]]:
    try:
        text = path.read_bytes().decode("utf-8-sig")
    except UnicodeDecodeError as error:
        line = path.read_bytes()[:error.start].count(b"\n") + 1
        raise InputError(f"{path}:{line}: not UTF-8 text; save the manifest as UTF-8") from None
    except OSError as error:
        raise InputError(f"{path}: cannot read ({error.strerror or error})") from None
    if "\0" in text:  # no path holds one (a binary file or UTF-16 read as UTF-8)
        line = text[:text.index("\0")].count("\n") + 1
        raise InputError(f"{path}:{line}: a NUL byte, not text; save the manifest as UTF-8 "
                         "text") from None
    dialect = "excel-tab" if path.suffix.lower() == ".tsv" or "\t" in text.split("\n")[0] \
        else "excel"
    reader = csv.DictReader(text.splitlines(), dialect=dialect)
    if not reader.fieldnames or "photo" not in [f.strip() for f in reader.fieldnames]:
        raise UsageError(f"{path}: a manifest needs a header row with a 'photo' column")
    names = [f.strip() for f in reader.fieldnames if f.strip()]
    twice = [f for f in dict.fromkeys(names) if names.count(f) > 1]
    if twice:  # DictReader keeps the last cell of a column given twice: one value ignored
        raise UsageError(f"{path}:1: column '{twice[0]}' twice; give each column once")
    unknown = [f.strip() for f in reader.fieldnames if f.strip() and f.strip() not in COLUMNS]
    if unknown:  # a misspelt column would be ignored, its values never used
        raise UsageError(f"{path}:1: unknown column '{unknown[0]}'; the columns are "
                         f"{', '.join(COLUMNS)} (method parameters go in params, "
                         "e.g. radius=4;visits=3)")
    rows = []
    for number, row in enumerate(reader, start=2):
        if None in row:  # DictReader's key for cells past the header's: a comma in a path?
            raise UsageError(f"{path}:{number}: {len(reader.fieldnames) + len(row[None])} cells, "
                             f"the header has {len(reader.fieldnames)}; quote a cell holding "
                             "a comma")
        row = {k.strip(): (v or "").strip() for k, v in row.items() if k}
        if not row.get("photo"):
            given = [k for k, v in row.items() if v]
            if given:  # a blank row is skipped; a row of values without its photo is a mistake
                raise UsageError(f"{path}:{number}: photo: empty, in a row that gives "
                                 f"{', '.join(given)}")
            continue
        row["photo"] = str(path.parent / row["photo"])
        if row.get("mask"):
            row["mask"] = str(path.parent / row["mask"])
        if row.get("maps"):
            row["maps"] = ";".join(str(path.parent / m.strip())
                                   for m in row["maps"].split(";") if m.strip())
        rows.append((f"{path}:{number}", row))
    return rows


def _value(where: str, column: str, text: str, parse):
    try:
        return parse(text)
    except ValueError as error:
        raise UsageError(f"{where}: {column}: {error}") from None


def _param(text: str):
    text = text.strip()
    return json.loads(text.lower() if text.lower() in ("true", "false") else text)


def _jobs(where: str, row: dict, out_dir: Path, d: Defaults) -> list[Job]:
    photo = Path(row["photo"])
    maps = tuple(m for m in row.get("maps", "").split(";") if m)
    operations = (row["operation"],) if row.get("operation") else d.operations
    for column in ("mask", "corners"):
        if row.get(column) and "material" not in operations:  # it would be ignored
            raise UsageError(f"{where}: {column}: only a material row takes it, not "
                             f"{' or '.join(operations)}")
    method = row.get("method") or d.method
    width, height = (_value(where, "size", row["size"], parse_size) if row.get("size")
                     else d.size)
    seed = _value(where, "seed", row["seed"], int) if row.get("seed") else d.seed
    band = _value(where, "band", row["band"], int) if row.get("band") else d.band
    if band is not None and band < 1:  # checked here too: a row that only synthesizes ignores it
        raise UsageError(f"{where}: band: a width in pixels of at least 1, got {band}")
    in_size = (_value(where, "in_size", row["in_size"], parse_in_size) if row.get("in_size")
               else d.in_size)
    params = dict(d.params)
    for item in filter(None, row.get("params", "").split(";")):
        name, _, value = item.partition("=")
        params[name.strip()] = _value(where, "params", value, _param)
    suffix = "." + (d.format or ("exr" if photo.suffix.lower() == ".exr" else "png"))
    bits = d.bits or default_bits(photo)
    jobs = []
    for operation in operations:
        if operation == "material":
            jobs.append(_material(where, row, out_dir, d, photo, (width, height), seed,
                                  in_size, bits))
            continue
        if operation == "tile":
            tag = f"_tile_s{seed}" + ("" if band is None else f"_b{band}")
        else:
            tag = f"_{method}_{width}x{height}_s{seed}" + _params_tag(params)
        if in_size is not None:
            tag += f"_in{in_size[0]}" + (f"x{in_size[1]}" if in_size[1] else "")
        outputs = tuple(str(out_dir / f"{Path(p).stem}{tag}{suffix}") for p in (photo, *maps))
        jobs.append(Job(photo=str(photo), maps=maps, operation=operation, method=method,
                        width=width, height=height, seed=seed, band=band,
                        params=tuple(sorted(params.items())), bits=bits, data=d.data,
                        outputs=outputs, in_size=in_size, origin=where))
    return jobs


def _material(where, row, out_dir, d, photo, size, seed, in_size, bits) -> Job:
    """A row's ``material`` task: the photo (and the row's ``mask``, its ``corners``
    x1,y1,...,x4,y4) to ``<photo>_material_<W>x<H>_s<seed>_Color.png`` and its four maps."""
    if row.get("maps"):
        raise UsageError(f"{where}: maps: a material derives its own maps; name a mask to "
                         "heal in the mask column")
    corners = (_value(where, "corners", row["corners"],
                      lambda t: [float(v) for v in t.split(",")])
               if row.get("corners") else None)
    stem = f"{photo.stem}_material_{size[0]}x{size[1]}_s{seed}"
    if in_size is not None:
        stem += f"_in{in_size[0]}" + (f"x{in_size[1]}" if in_size[1] else "")
    return material_job(str(photo), out_dir, mask=row.get("mask") or None, size=size,
                        corners=corners, method=row.get("method") or d.method, seed=seed,
                        bits=bits, fmt=d.format or ("exr" if photo.suffix.lower() == ".exr"
                                                    else "png"),
                        stem=stem, in_size=in_size, origin=where)


def _params_tag(params: dict) -> str:
    """Given parameters change the name (a short hash), so two settings never share a file."""
    if not params:
        return ""
    return "_p" + hashlib.sha256(json.dumps(sorted(params.items())).encode()).hexdigest()[:8]


# --- the batch ------------------------------------------------------------------------------

#: Dask's own log lines (a worker lost, a task's traceback), in the keys folder: the user sees
#: one line per failed task, never Dask's logging. Made only when Dask logs a warning or worse.
LOG = "batch.log"
#: How a local cluster's worker processes learn the log's path (read by :func:`dask_setup`).
LOG_VARIABLE = "TEXSYNTH_BATCH_LOG"
#: Loggers to which Dask's logging configuration gives a handler writing to stderr.
DASK_LOGGERS = ("distributed", "tornado", "bokeh", "asyncio")
#: Seconds a scheduler has to answer (a connection and Dask's handshake).
CONNECT_TIMEOUT = 10.0
#: The address schemes of a scheduler a batch can reach from another process.
SCHEMES = ("tcp", "tls")
#: glibc's settings in a local cluster's worker processes: work arrays come from a heap that
#: keeps freed memory for the next ones (see :func:`_worker_environment`).
WORKER_MALLOC = {"MALLOC_MMAP_THRESHOLD_": str(1 << 30), "MALLOC_TRIM_THRESHOLD_": str(1 << 34)}
#: The thread counts of the BLAS and OpenMP libraries, which Dask sets to 1 in its workers.
THREAD_VARIABLES = ("OMP_NUM_THREADS", "MKL_NUM_THREADS", "OPENBLAS_NUM_THREADS",
                    "TEXSYNTH_THREADS")


def run(jobs: list[Job], *, client=None, scheduler: str | None = None,
        workers: int | None = None,
        progress: Callable[[float, str], object] | None = None) -> Summary:
    """Run the jobs not done yet on Dask distributed; the batch's :class:`Summary`.

    ``client``: a ``dask.distributed.Client`` to use; else ``scheduler`` (``tcp://host:port``
    of a running ``dask scheduler``), else a local cluster of ``workers`` processes (default:
    :func:`default_workers` of the jobs), one task at a time each, sharing the cores. The
    photos' and outputs' paths must be the same on every worker (a shared folder).
    ``progress(fraction, message)`` hears of each finished task.

    Raises ``ValueError`` for a ``scheduler`` that is no scheduler address, before any work,
    and ``ConnectionError`` when no Dask scheduler answers there within
    :data:`CONNECT_TIMEOUT` seconds. A failed task is one line of ``Summary.failed``
    (``output: ErrorType: message``); Dask's own log lines go to ``OUTDIR/.texsynth/batch.log``.
    ``KeyboardInterrupt`` closes the local cluster and propagates; the temporary files of the
    tasks it stopped are removed.

    References
    ----------
    Dask distributed's resilience: a lost worker's tasks are recomputed on the others
    (distributed.dask.org, "Resilience"); the futures interface (``Client.map``,
    ``as_completed``).
    """
    start = time.monotonic()
    address = None if client is not None or scheduler is None else scheduler_address(scheduler)
    summary = Summary(total=len(jobs))
    report = progress or (lambda fraction, message: None)
    todo, keys, starter, logs, ended = [], [], None, None, False
    try:
        for job in jobs:
            job_key = key(job)
            if is_done(job, job_key):
                continue
            todo.append(job)
            keys.append(job_key)
            if logs is None:  # work to do: Dask's logs to the file, the cluster starting
                logs = _route_logs(_log_path(todo))
                if client is None:  # ... while the main thread hashes the other inputs
                    starter = _Start(address, workers or default_workers(jobs),
                                     _log_path(todo))
        summary.skipped = len(jobs) - len(todo)
        report(summary.skipped / max(len(jobs), 1),
               f"{summary.skipped} of {len(jobs)} already done")
        if todo:  # the longest first (predicted): the last task to end is a short one, so
            # no worker idles long while another finishes a long one (LPT, Graham 1969)
            order = sorted(range(len(todo)), key=lambda i: -(todo[i].forecast or (0.0,))[0])
            todo, keys = [todo[i] for i in order], [keys[i] for i in order]
            _submit(todo, keys, summary, client if client is not None else starter.client(),
                    report)
        ended = True
    finally:
        if starter is not None:
            summary.overhead += starter.close(interrupted=not ended)
        if logs is not None:
            _restore_logs(logs)
        # Interrupted: a local cluster's workers are gone, so their files are stale; a remote
        # task may still be writing its own (it renames it when complete).
        if ended or (client is None and address is None):
            _remove_stale(jobs)
    summary.seconds = time.monotonic() - start
    return summary


def _remove_stale(jobs: list[Job]) -> None:
    for folder in {Path(out).parent for job in jobs for out in job.outputs}:
        for stale in [*folder.glob(TEMP_PREFIX + "*"), *(folder / KEYS).glob(TEMP_PREFIX + "*")]:
            stale.unlink(missing_ok=True)  # left by killed tasks; every task has ended


def default_workers(jobs: list[Job] | None = None) -> int:
    """Worker processes of a local cluster: one per core, no more than the ``jobs``, nor more
    than :func:`~texsynth.validation.memory_budget` holds of the largest predicted peak.

    The core's thread pool overlaps little of a task (its Python parts hold the GIL): a task of
    the batch section used 1.0 s of CPU per second of wall time with 2 pool threads. On 2
    cores, 6 tasks (256 -> 768 ``multiscale_mrf``, quiet machine) took 21.9 s on 2 worker
    processes of 1 thread against 34.9 s on 1 of 2 threads and 30.6 s one by one in one
    process. A worker's threads are the cores it is left (:func:`_worker_environment`).
    """
    workers = min(CORES, len(jobs)) if jobs else CORES
    peak = max((job.forecast[1] for job in jobs or () if job.forecast is not None),
               default=0.0)
    if peak > 0:
        workers = min(workers, int(memory_budget() // peak))
    return max(1, workers)


def scheduler_address(text: str) -> str:
    """``tcp://HOST:PORT`` from ``HOST:PORT`` or a ``tcp://`` or ``tls://`` address; else a
    ``ValueError`` naming what is wrong (before any connection is tried).

    ``inproc://`` addresses are left out: they name a scheduler inside the same process, which
    a batch reaches through ``client=``.

    Examples
    --------
    >>> scheduler_address("render-01:8786"), scheduler_address("tls://10.0.0.5:8786")
    ('tcp://render-01:8786', 'tls://10.0.0.5:8786')
    >>> scheduler_address("bogus")
    Traceback (most recent call last):
    ...
    ValueError: scheduler 'bogus': not a Dask scheduler address; give tcp://HOST:PORT (e.g. tcp://render-01:8786)
    """
    form = "give tcp://HOST:PORT (e.g. tcp://render-01:8786)"
    scheme, sep, rest = str(text).strip().rpartition("://")
    if not sep:
        scheme = "tcp"
    if scheme in ("http", "https"):
        raise ValueError(f"scheduler {text!r}: a web address (the dashboard?); a Dask "
                         f"scheduler listens on tcp:// (port 8786 by default): {form}")
    if scheme not in SCHEMES:
        raise ValueError(f"scheduler {text!r}: the scheme must be {' or '.join(SCHEMES)}, "
                         f"not {scheme!r}: {form}")
    host, colon, port = rest.rpartition(":")
    if "/" in rest or not colon or not host.strip("[]") or not port.isdigit() \
            or not 0 < int(port) < 65536:
        raise ValueError(f"scheduler {text!r}: not a Dask scheduler address; {form}")
    return f"{scheme}://{host}:{int(port)}"


def _connect(address: str, timeout: float | None = None):
    """A ``Client`` of the scheduler at ``address``, or a ``ConnectionError`` within about
    ``timeout`` seconds (default :data:`CONNECT_TIMEOUT`). Dask's own connect waits for the
    handshake without a limit: a web server or a silent port would hold the batch for
    minutes."""
    import asyncio
    import socket
    import threading

    from distributed import Client
    from distributed.comm import connect
    from distributed.security import Security

    def fail(why):
        return ConnectionError(f"{address}: no Dask scheduler answers there ({why})")

    timeout = CONNECT_TIMEOUT if timeout is None else timeout

    host, port = address.split("://", 1)[1].rsplit(":", 1)
    try:
        socket.create_connection((host.strip("[]"), int(port)), timeout=timeout).close()
    except socket.gaierror as error:
        raise fail(f"unknown host: {error.strerror}") from None
    except TimeoutError:
        raise fail(f"no connection in {timeout:g} s") from None
    except OSError as error:
        raise fail(error.strerror or type(error).__name__) from None

    async def handshake():
        args = Security().get_connection_args("client")
        comm = await asyncio.wait_for(connect(address, timeout=timeout, **args), timeout)
        await comm.close()

    outcome: list[BaseException | None] = []

    def probe():  # a thread of its own: the caller may be inside an event loop (Jupyter)
        try:
            asyncio.run(handshake())
            outcome.append(None)
        except BaseException as error:  # noqa: BLE001 - reported below, as one line
            outcome.append(error)

    thread = threading.Thread(target=probe, name="texsynth-connect", daemon=True)
    thread.start()
    thread.join(timeout + 5)
    if not outcome or isinstance(outcome[0], (TimeoutError, asyncio.TimeoutError)):
        raise fail(f"no Dask handshake in {timeout:g} s")
    if outcome[0] is not None:
        raise fail(f"it does not speak Dask's protocol: {type(outcome[0]).__name__}")
    try:
        return Client(address, timeout=timeout)
    except (OSError, TimeoutError) as error:
        raise fail(type(error).__name__) from None


def local_cluster(workers: int | None = None, log: str | os.PathLike | None = None):
    """The local cluster of a batch: ``workers`` processes (:func:`default_workers`), one task
    at a time each, Dask's log lines to the file ``log`` (or nowhere), texsynth imported in each
    worker while it starts, glibc's heap kept (:func:`_worker_environment`)."""
    import dask
    from distributed import LocalCluster

    workers = workers or default_workers()
    environ = dict(os.environ)
    os.environ.update(WORKER_MALLOC)  # Dask takes this process's values over its settings
    try:
        with dask.config.set(_worker_environment(workers)):
            return LocalCluster(n_workers=workers, threads_per_worker=1,
                                processes=True, dashboard_address=None,
                                # its HTTP routes on a free port: on 8787, taken by another
                                # batch's cluster, Dask warned in 4 lines
                                scheduler_kwargs={"dashboard_address": ":0"},
                                silence_logs=logging.CRITICAL, preload=[__name__],
                                env={LOG_VARIABLE: str(log or "")})
    finally:  # as the nanny does, each time it starts a worker: this process's are kept
        for name in [n for n in os.environ if os.environ[n] != environ.get(n)]:
            if name in environ:
                os.environ[name] = environ[name]
            else:
                del os.environ[name]


def _worker_environment(workers: int) -> dict:
    """Dask settings for the environment of ``workers`` worker processes.

    Dask's nanny sets ``OMP_NUM_THREADS``, ``MKL_NUM_THREADS`` and ``OPENBLAS_NUM_THREADS``
    to 1 (one thread per core, in as many worker threads); a batch's worker runs one task at a
    time, which uses its share of the cores through BLAS (the patch distances' matrix products)
    as through the core's thread pool, so the BLAS libraries and the pool
    (``TEXSYNTH_THREADS``, ``blocks.parallel``) get that share, :data:`THREAD_VARIABLES` (a
    variable set in the starting process still wins).

    Dask's nanny sets ``MALLOC_TRIM_THRESHOLD_=65536``, so glibc hands freed memory back at
    once and every fresh work array faults its pages in again: a task ran about 1.3x as long
    (medians of 4: 7.1 s against 5.5 s); that setting is undone. Beyond it, glibc maps each
    array above its moving threshold (at most 32 MiB) afresh and unmaps it when freed; a task
    of the batch section faulted 614 000 pages in for it (1.9 s of system time in three tasks),
    12 000 with the arrays kept on the heap (:data:`WORKER_MALLOC`), and the batch of 6 took
    72.6 and 64.6 s against 120.1 and 113.8 s without (load average 4.5-6.7 on 2 cores; the
    system time of faults grows with the load). A worker then keeps its
    largest task's memory for the next one. (Dask takes a variable of the starting process's
    environment over these: :func:`local_cluster` sets glibc's there while the workers start.)
    """
    key = "distributed.nanny.pre-spawn-environ."
    share = str(max(1, CORES // workers))
    # A worker's memory is mostly its kept heap, not Dask's data (a task returns a word): no
    # spilling, and no pause that would wait for memory a kept heap never hands back; Dask
    # still ends a worker past 95 % of its share of the memory.
    return {**{key + name: value for name, value in WORKER_MALLOC.items()},
            **{key + name: share for name in THREAD_VARIABLES},
            "distributed.worker.memory.target": False, "distributed.worker.memory.spill": False,
            "distributed.worker.memory.pause": False}


def dask_setup(worker) -> None:
    """Dask's preload hook, run in each worker process of :func:`local_cluster` as it starts
    (the import of this module is the warm-up: texsynth is loaded before the first task).

    Dask's log lines go to the batch's log file (:data:`LOG_VARIABLE`) instead of the
    terminal's stderr, and Ctrl+C in the terminal is left to the batch's own process, which
    closes the cluster (the workers are in the terminal's process group and would each print
    a traceback).
    """
    import signal
    import threading

    _route_logs(os.environ.get(LOG_VARIABLE) or None)
    if threading.current_thread() is threading.main_thread():
        signal.signal(signal.SIGINT, signal.SIG_IGN)


class _LogFile(logging.Handler):
    """Appends each record to a file, made when the first record comes (several processes may
    write to it: each record is one append). Not a ``StreamHandler``: Dask's ``silence_logs``
    sets the level of those."""

    def __init__(self, path: Path):
        super().__init__(logging.WARNING)
        self.path = path
        self.setFormatter(logging.Formatter("%(asctime)s %(process)d %(name)s %(levelname)s "
                                            "%(message)s"))

    def emit(self, record):
        try:
            text = self.format(record) + "\n"
            self.path.parent.mkdir(parents=True, exist_ok=True)
            with open(self.path, "a", encoding="utf-8") as f:
                f.write(text)
        except Exception:  # noqa: BLE001 - a log line lost is no reason to fail a task
            pass


def _route_logs(path) -> list:
    """Dask's loggers write to ``path`` (or nowhere) instead of stderr; what they had before,
    for :func:`_restore_logs`."""
    handler = _LogFile(Path(path)) if path else logging.NullHandler()
    names = [n for n in list(logging.root.manager.loggerDict)
             if n.split(".")[0] in DASK_LOGGERS] + list(DASK_LOGGERS)
    saved = []
    for name in dict.fromkeys(names):
        logger = logging.getLogger(name)
        if name not in DASK_LOGGERS and not logger.handlers:
            continue  # a child without handlers of its own: its records reach its parent's
        saved.append((logger, list(logger.handlers), logger.propagate))
        for old in list(logger.handlers):
            if isinstance(old, logging.StreamHandler) and not isinstance(old,
                                                                        logging.FileHandler):
                logger.removeHandler(old)
        logger.addHandler(handler)
        logger.propagate = False
    return saved


def _restore_logs(saved: list) -> None:
    for logger, handlers, propagate in saved:
        for handler in list(logger.handlers):
            logger.removeHandler(handler)
        for handler in handlers:
            logger.addHandler(handler)
        logger.propagate = propagate


def _log_path(jobs: list[Job]) -> Path:
    """``OUTDIR/.texsynth/batch.log`` of the first job's output folder."""
    return Path(jobs[0].outputs[0]).parent / KEYS / LOG


def _failure(name: str, error: BaseException) -> str:
    """One line for a failed task: ``name: ErrorType: message``."""
    kind = type(error).__name__
    if kind == "KilledWorker":  # distributed.scheduler.KilledWorker: a long paragraph
        text = ("its worker process died each time it ran it (out of memory? killed?); see "
                f"{LOG} in the output folder's {KEYS}")
    else:
        text = " ".join(str(error).split()) or "(no message)"
    return f"{name}: {kind}: {text}"


class _Start:
    """The local cluster started (or the scheduler reached) in a thread of its own, so that
    hashing the inputs and starting Dask overlap; :meth:`client` waits for it."""

    def __init__(self, address: str | None, workers: int | None, log: Path):
        import threading

        self.address, self.workers, self.log = address, workers, log
        self._client = self._cluster = self._error = None
        self.seconds = 0.0
        self._thread = threading.Thread(target=self._start, name="texsynth-dask", daemon=True)
        self._thread.start()

    def _start(self):
        from multiprocessing import resource_tracker

        from distributed import Client

        start = time.monotonic()
        # Ctrl+C on a terminal reaches every process of its group, the local cluster's worker
        # processes too, and each printed a traceback. This thread's signal mask is inherited
        # by the threads it starts and the worker processes they spawn (POSIX: fork and exec
        # keep the mask), so those never take SIGINT; this process's main thread still does,
        # and closing the cluster ends them (run's finally). multiprocessing's resource tracker
        # unblocks SIGINT in the thread that starts it (resource_tracker.ensure_running): it is
        # started first, here, so that the IO loop thread's mask stays as it is given.
        resource_tracker.ensure_running()
        signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT})
        try:
            if self.address is None:
                self._cluster = local_cluster(self.workers, self.log)
                self._client = Client(self._cluster)
            else:
                self._client = _connect(self.address)
        except BaseException as error:  # noqa: BLE001 - raised again in the caller's thread
            self._error = error
        self.seconds = time.monotonic() - start

    def client(self):
        self._thread.join()
        if self._error is not None:
            raise self._error
        return self._client

    def close(self, interrupted: bool = False) -> float:
        """Close what was started (once it is up); seconds of starting and closing.

        ``interrupted`` (Ctrl+C): the local cluster's worker processes are killed first, since
        closing waits for their running tasks (a 4096 texture: minutes) and they ignore SIGINT
        (:func:`dask_setup`); their temporary files are removed after (``run``).
        """
        self._thread.join()
        start = time.monotonic()
        if interrupted and self._cluster is not None:
            for nanny in self._cluster.workers.values():
                pid = getattr(getattr(nanny, "process", None), "pid", None)
                if pid:
                    with contextlib.suppress(ProcessLookupError):
                        os.kill(pid, signal.SIGKILL)
        if self._client is not None:
            self._client.close()
        if self._cluster is not None:
            self._cluster.close()
        return self.seconds + time.monotonic() - start


def _submit(todo, keys, summary, client, report) -> None:
    from distributed import as_completed

    futures = client.map(run_job, todo, keys, key=[f"texsynth-{Path(j.outputs[0]).name}"
                                             for j in todo], pure=False)
    names = {f.key: Path(j.outputs[0]).name for f, j in zip(futures, todo, strict=True)}
    # A task whose result died with its worker is run again and comes back a second time,
    # "skipped" (its outputs are there): each task counts once, by its key, done if it was.
    outcome = {}
    for future in as_completed(futures):
        name = names[future.key]
        if future.status == "finished":
            if outcome.get(future.key) != "done":
                outcome[future.key] = future.result()
        elif future.status == "cancelled":
            outcome[future.key] = f"{name}: CancelledError: the scheduler dropped it"
        else:
            outcome[future.key] = _failure(name, future.exception())
        finished = summary.skipped + len(outcome)
        report(finished / summary.total, f"{finished}/{summary.total} {name}")
    results = list(outcome.values())
    summary.done = results.count("done")
    summary.skipped += results.count("skipped")
    summary.failed = [r for r in results if r not in ("done", "skipped")]

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
``operation`` (``synthesize`` or ``tile``), ``method``, ``size`` (``N`` or ``WxH``), ``seed``,
``band``, ``in_size`` (``N`` or ``WxH``: the photo resampled first), ``params``
(``name=value;...``). Paths are relative to the manifest's folder.
"""

from __future__ import annotations

import csv
import hashlib
import json
import logging
import os
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

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
    parse_in_size,
    parse_size,
    preflight,
    run_job,
    version,
)

__all__ = ["version", "OPERATIONS", "Defaults", "Job", "Summary", "plan", "run", "run_job",
           "is_done"]

#: The Dask setting that makes worker processes hand freed memory back at once (see _submit).
NO_TRIM = "distributed.nanny.pre-spawn-environ.MALLOC_TRIM_THRESHOLD_"


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
    preflight(jobs)
    return jobs


def _manifest_rows(path: Path) -> list[tuple[str, dict]]:
    try:
        text = path.read_bytes().decode("utf-8-sig")
    except UnicodeDecodeError as error:
        line = path.read_bytes()[:error.start].count(b"\n") + 1
        raise InputError(f"{path}:{line}: not UTF-8 text; save the manifest as UTF-8") from None
    except OSError as error:
        raise InputError(f"{path}: cannot read ({error.strerror or error})") from None
    dialect = "excel-tab" if path.suffix.lower() == ".tsv" or "\t" in text.split("\n")[0] \
        else "excel"
    reader = csv.DictReader(text.splitlines(), dialect=dialect)
    if not reader.fieldnames or "photo" not in [f.strip() for f in reader.fieldnames]:
        raise UsageError(f"{path}: a manifest needs a header row with a 'photo' column")
    rows = []
    for number, row in enumerate(reader, start=2):
        row = {k.strip(): (v or "").strip() for k, v in row.items() if k}
        if not row.get("photo"):
            continue
        row["photo"] = str(path.parent / row["photo"])
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
    method = row.get("method") or d.method
    width, height = (_value(where, "size", row["size"], parse_size) if row.get("size")
                     else d.size)
    seed = _value(where, "seed", row["seed"], int) if row.get("seed") else d.seed
    band = _value(where, "band", row["band"], int) if row.get("band") else d.band
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


def _params_tag(params: dict) -> str:
    """Given parameters change the name (a short hash), so two settings never share a file."""
    if not params:
        return ""
    return "_p" + hashlib.sha256(json.dumps(sorted(params.items())).encode()).hexdigest()[:8]


# --- the batch ------------------------------------------------------------------------------

def run(jobs: list[Job], *, client=None, scheduler: str | None = None,
        workers: int | None = None,
        progress: Callable[[float, str], object] | None = None) -> Summary:
    """Run the jobs not done yet on Dask distributed; the batch's :class:`Summary`.

    ``client``: a ``dask.distributed.Client`` to use; else ``scheduler`` (``tcp://host:port``
    of a running ``dask scheduler``), else a local cluster of ``workers`` processes (default:
    :func:`default_workers`) with one thread each (the core's own thread pool uses the cores
    inside a task). The photos' and outputs' paths must be the same on every worker (a shared
    folder).
    ``progress(fraction, message)`` hears of each finished task.

    References
    ----------
    Dask distributed's resilience: a lost worker's tasks are recomputed on the others
    (distributed.dask.org, "Resilience"); the futures interface (``Client.map``,
    ``as_completed``).
    """
    start = time.monotonic()
    summary = Summary(total=len(jobs))
    report = progress or (lambda fraction, message: None)
    todo = [job for job in jobs if not is_done(job, key(job))]
    summary.skipped = len(jobs) - len(todo)
    report(summary.skipped / max(len(jobs), 1), f"{summary.skipped} of {len(jobs)} already done")
    if todo:
        _submit(todo, summary, client, scheduler, workers, report)
    for folder in {Path(out).parent for job in jobs for out in job.outputs}:
        for stale in [*folder.glob(TEMP_PREFIX + "*"), *(folder / KEYS).glob(TEMP_PREFIX + "*")]:
            stale.unlink(missing_ok=True)  # left by killed tasks; every task has ended
    summary.seconds = time.monotonic() - start
    return summary


def default_workers() -> int:
    """Worker processes of a local cluster: one per 4 cores, at least one.

    A task already uses every core through the core's thread pool (``blocks/parallel.py``). On
    2 cores, 6 tasks on 2 worker processes took 1.38x as long as on one (24.7 s against
    17.9 s, 256 x 256 ``multiscale_mrf``, load average 8-10); larger machines are untested:
    ``--workers`` sets it.
    """
    return max(1, (os.cpu_count() or 1) // 4)


def _submit(todo, summary, client, scheduler, workers, report) -> None:
    import dask
    from distributed import Client, LocalCluster, as_completed

    start = time.monotonic()
    cluster = None
    if client is None and scheduler is None:
        # Dask's nanny sets MALLOC_TRIM_THRESHOLD_ in its workers, so glibc hands freed memory
        # back at once and every fresh work array faults its pages in again: a task ran about
        # 1.3x as long (medians of 4: 7.1 s against 5.5 s). The one-thread BLAS settings stay.
        with dask.config.set({NO_TRIM: None}):  # None: not set (distributed.nanny)
            cluster = LocalCluster(n_workers=workers or default_workers(),
                                   threads_per_worker=1, processes=True, dashboard_address=None,
                                   silence_logs=logging.ERROR)  # the summary says what happened
    own = client is None
    if client is None:
        try:
            client = Client(cluster if cluster is not None else scheduler, timeout="20s")
        except (OSError, TimeoutError) as error:
            raise ConnectionError(f"{scheduler}: no Dask scheduler answers there "
                                  f"({type(error).__name__})") from None
    summary.overhead += time.monotonic() - start
    try:
        futures = client.map(run_job, todo, key=[f"texsynth-{Path(j.outputs[0]).name}"
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
            else:
                error = future.exception()
                outcome[future.key] = f"{name}: {type(error).__name__}: {error}"
            finished = summary.skipped + len(outcome)
            report(finished / summary.total, f"{finished}/{summary.total} {name}")
        results = list(outcome.values())
        summary.done = results.count("done")
        summary.skipped += results.count("skipped")
        summary.failed = [r for r in results if r not in ("done", "skipped")]
    finally:
        start = time.monotonic()
        if own:
            client.close()
        if cluster is not None:
            cluster.close()
        summary.overhead += time.monotonic() - start


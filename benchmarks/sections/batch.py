"""Batches on one machine (issue 29, goal 3): ``texsynth batch`` against the same jobs one by one.

The same jobs three ways, on the same cores:

- **one by one, in one process**: :func:`texsynth.batch.run_job` called for each job in turn
  in a fresh Python process, timed from after its imports (each job uses every core through
  the core's thread pool, as a script calling the API would);
- **one by one, as commands**: ``texsynth synthesize`` run for each photo in turn (each a fresh
  process: the import paid once a photo, as a shell loop would);
- **the batch**: ``texsynth batch`` on the folder: a local Dask cluster (its default worker
  processes, one task at a time each), cluster start-up and shut-down included.

Throughput is jobs per second; the batch's ratio to each of the other two is the figure of
goal 3 (at least 0.9). Each way runs twice, alternating, into fresh folders; medians. The
re-run of the finished batch (every output kept, nothing done) is timed too.
"""

from __future__ import annotations

import os
import re
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from texsynth.io import read_png, write_png
from texsynth.metrics import seam_ratio

ORDER = 95
TITLE = "Batches on one machine: texsynth batch against the same jobs one by one"
JOBS = 6
PHOTO_SIDE = 256
SIDE = 768
METHOD = "multiscale_mrf"
ROUNDS = 2


def _photos(ctx, folder: Path) -> list[str]:
    """``JOBS`` top-centre crops of the textures (the largest first), sRGB PNGs."""
    big = sorted((t for t in ctx.textures if min(t.image.shape[:2]) >= PHOTO_SIDE),
                 key=lambda t: -t.image.size)
    sources = big[:JOBS] or [ctx.textures[0]]
    names = []
    for k in range(JOBS):
        texture = sources[k % len(sources)]
        w = texture.image.shape[1]
        x = (w - PHOTO_SIDE) // 2 + PHOTO_SIDE * (k // len(sources))  # repeats: further right
        crop = texture.image[:PHOTO_SIDE, x % max(w - PHOTO_SIDE, 1):][:, :PHOTO_SIDE]
        if crop.shape[:2] != (PHOTO_SIDE, PHOTO_SIDE):  # the sample, smaller: tiled up
            crop = np.resize(crop, (PHOTO_SIDE, PHOTO_SIDE, 3))
        write_png(folder / f"p{k}.png", crop)
        names.append(texture.short)
    return names


def _command(*args: str) -> list[str]:
    return [sys.executable, "-m", "texsynth", "-q", *args]


#: One by one in one fresh process (this one pins glibc's mmap threshold for its memory
#: figures, which makes every fresh work array fault its pages in: not how a script runs).
_LOOP = """
import sys, time
from texsynth import batch
jobs = batch.plan(sys.argv[1], sys.argv[2], batch.Defaults(size=({side}, {side}), method="{m}"))
start = time.perf_counter()
for job in jobs:
    batch.run_job(job)
print(time.perf_counter() - start)
"""


#: The batch's forecast in a fresh process, as the command prints it before its run: this
#: process pins glibc's mmap threshold, and the calibration's FFT temporaries, a fresh mapping
#: each there, read the machine 1.19-1.27x slower (3 processes each way, 2026-12-07).
_FORECAST = """
import sys
from texsynth import batch
jobs = batch.plan(sys.argv[1], sys.argv[2], batch.Defaults(size=({side}, {side}), method="{m}"))
print(batch.forecast(jobs)[0])
"""


def _forecast(photos: Path, planned: Path) -> float:
    code = _FORECAST.format(side=SIDE, m=METHOD)
    run = subprocess.run([sys.executable, "-c", code, str(photos), str(planned)], check=True,
                         capture_output=True, text=True)
    return float(run.stdout.split()[-1])


def _one_by_one_in_process(photos: Path, out: Path) -> float:
    code = _LOOP.format(side=SIDE, m=METHOD)
    run = subprocess.run([sys.executable, "-c", code, str(photos), str(out)], check=True,
                         capture_output=True, text=True)
    return float(run.stdout.split()[-1])


def _one_by_one_commands(photos: Path, out: Path) -> float:
    start = time.perf_counter()
    for photo in sorted(photos.glob("*.png")):
        subprocess.run(_command("synthesize", str(photo), "-o", str(out / photo.name),
                                "--size", str(SIDE), "--method", METHOD), check=True,
                       stdout=subprocess.DEVNULL)
    return time.perf_counter() - start


#: Seconds of each batch run spent starting and closing its local cluster (from its summary).
OVERHEAD: list[float] = []


def _batch(photos: Path, out: Path) -> float:
    start = time.perf_counter()
    run = subprocess.run(_command("batch", str(photos), "-o", str(out), "--size", str(SIDE),
                                  "--method", METHOD), check=True, capture_output=True, text=True)
    seconds = time.perf_counter() - start
    OVERHEAD.append(float(re.search(r"cluster start and close: ([0-9.]+) s", run.stdout)[1]))
    return seconds


def run(ctx) -> str:
    try:
        import distributed
    except ImportError:
        return "Skipped: Dask is not installed (`pip install \"dask[distributed]\"`)."
    env_root = str(Path(__file__).resolve().parents[2])
    os.environ["PYTHONPATH"] = os.pathsep.join(filter(None, [env_root,
                                                             os.environ.get("PYTHONPATH")]))
    ways = {"one by one, in one process": _one_by_one_in_process,
            "one by one, as commands": _one_by_one_commands,
            "texsynth batch (local cluster)": _batch}
    times: dict[str, list[float]] = {name: [] for name in ways}
    loads = []
    with tempfile.TemporaryDirectory() as tmp:
        photos = Path(tmp) / "photos"
        photos.mkdir()
        names = _photos(ctx, photos)
        predictions = []
        for r in range(ROUNDS):
            for k, (name, way) in enumerate(ways.items()):
                loads.append(os.getloadavg()[0])
                if way is _batch:
                    predictions.append(_forecast(photos, Path(tmp) / "planned"))
                times[name].append(way(photos, Path(tmp) / f"out{r}_{k}"))
        overhead = list(OVERHEAD)
        rerun = []
        for _ in range(2):
            rerun.append(_batch(photos, Path(tmp) / f"out{ROUNDS - 1}_2"))
        outputs = sorted((Path(tmp) / f"out{ROUNDS - 1}_2").glob("*.png"))
        seams = [seam_ratio(read_png(p)) for p in outputs]
        same = all(np.array_equal(read_png(p), read_png(Path(tmp) / "out0_0" / p.name))
                   for p in outputs)
    median = {name: statistics.median(t) for name, t in times.items()}
    batch_rate = JOBS / median["texsynth batch (local cluster)"]
    lines = [
        f"{JOBS} photos of {PHOTO_SIDE} x {PHOTO_SIDE} (top-centre crops of: "
        f"{', '.join(dict.fromkeys(names))}), each to a {SIDE} x {SIDE} tile with `{METHOD}`; "
        f"{os.cpu_count()} cores, Dask distributed {distributed.__version__}; each way "
        f"{ROUNDS} times, alternating (load average "
        f"{min(loads):.1f}-{max(loads):.1f} at the starts). Run by `python -m benchmarks "
        "--no-install --only batch` (needs `dask[distributed]`).",
        "",
        "| way | time (runs) | jobs / s | batch's throughput over it |",
        "| --- | --- | --- | --- |",
    ]
    for name, t in times.items():
        rate = JOBS / median[name]
        lines.append(f"| {name} | {median[name]:.1f} s ({', '.join(f'{x:.1f}' for x in t)}) "
                     f"| {rate:.3f} | {batch_rate / rate:.2f} |")
    batch_times = times["texsynth batch (local cluster)"]
    steady = statistics.median(t - o for t, o in zip(batch_times, overhead, strict=True))
    lines.append(f"| texsynth batch, less its cluster's start and close "
                 f"({', '.join(f'{o:.1f}' for o in overhead)} s) | {steady:.1f} s | "
                 f"{JOBS / steady:.3f} | |")
    lines.append("")
    rounds = ", ".join(f"{a / b:.2f}" for a, b in zip(times["one by one, in one process"],
                                                       batch_times, strict=True))
    lines.append(f"Steady throughput of the batch over one by one in one process: "
                 f"{JOBS / steady / (JOBS / median['one by one, in one process']):.2f}; the "
                 "cluster's start and close is paid once a batch, whatever its size. The batch "
                 f"over one by one in one process, round by round (the two run minutes apart "
                 f"on a shared machine): {rounds}.")
    again = statistics.median(rerun)
    predicted = statistics.median(predictions)
    measured = median["texsynth batch (local cluster)"]
    lines += [
        "",
        f"- Re-running the finished batch (all {JOBS} outputs kept, nothing rewritten): "
        f"{again:.1f} s, {again / median['texsynth batch (local cluster)']:.0%} of the first "
        "run (the command's start-up and the inputs' hashes; no cluster is started).",
        f"- Predicted before the batch (`texsynth.batch.forecast` in a fresh process before "
        f"each batch run, as the command prints it: each task's prediction, dealt to the "
        f"workers): {predicted:.1f} s ({', '.join(f'{x:.1f}' for x in predictions)}); "
        f"measured {measured:.1f} s ({predicted / measured:.2f}x).",
        f"- The batch's outputs are bit-identical to the in-process run's: {same}; their seam "
        f"ratios {min(seams):.2f}-{max(seams):.2f}.",
    ]
    return "\n".join(lines)

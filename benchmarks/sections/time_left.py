"""The time left against the time that was left (issue 40): every method and make_tileable.

Each run's progress reports are timed on the wall and CPU clocks. After the run the true time
left at each report is known, and :class:`texsynth.progress.TimeLeft` tells what it would have
said there (it is a function of the fraction and the clock), as the command line's bar and
Blender's status line do: the prediction made before the work (``texsynth.budget.forecast``,
``texsynth.tileable.predict``) blended with the rate seen; for comparison, the rate alone
(elapsed x (1 - f) / f, the rule before issue 40), also on the CPU clock, which other programs'
load does not move. Cells: told / true at the first report past 10 %, 50 % and 90 % (goal:
0.67-1.5).
"""

from __future__ import annotations

import time

import numpy as np

import texsynth
from texsynth import budget
from texsynth.progress import TimeLeft

ORDER = 39
TITLE = "Time left: the estimate at 10, 50 and 90 % against the time that was left (issue 40)"
SEED = 0
#: Fractions at which the estimate is read.
MARKS = (0.1, 0.5, 0.9)
#: (exemplar side, output side) per method: each run a few seconds here, the section a few
#: minutes (a run that ends within a second never shows a time left but 0:00).
SIZES = {"heeger_bergen": (256, 1024), "efros_leung": (64, 256), "random_phase": (512, 4096),
         "de_bonet": (512, 2048), "multiscale_mrf": (128, 512), "cooccurrence": (128, 512),
         "texture_optimization": (128, 512), "composite": (128, 384)}
DEFAULT_SIZE = (128, 256)
#: The display's resolution: the bar and the status line show whole seconds (``TimeLeft.text``),
#: so a reading with less than this left (0:00 or 0:01 whatever the ratio) is not rated.
SHOWN_SECONDS = 1.0
#: Second runs of the methods whose fractions were furthest from the time (issue 40), larger.
LARGER = (("texture_optimization", 256, 512), ("portilla_simoncelli", 256, 512))
#: The photo side make_tileable is run on: the texture mirrored out to it, a ramp added across
#: so that it does not tile (as ``benchmarks.prediction_run`` does).
TILE_SIDE = 1536
GOAL = (1 / 1.5, 1.5)


def _trace(run) -> tuple[tuple[float, float], list[tuple[float, float, float]]]:
    """((wall, CPU) seconds at the start, [(wall, CPU seconds, fraction)] at each report and
    last at the end) of ``run(progress)``."""
    start, reports = (time.perf_counter(), time.process_time()), []

    def progress(fraction, message):
        reports.append((time.perf_counter(), time.process_time(), fraction))

    run(progress)
    return start, reports + [(time.perf_counter(), time.process_time(), 1.0)]


def _hit(reports, mark: float, clock: int):
    """The first report past ``mark`` (before the end) on the wall (``clock`` 0) or CPU (1)
    clock, or None."""
    end = reports[-1][clock]
    return next((r for r in reports[:-1] if mark <= r[2] < 1.0 and end > r[clock]), None)


def _ratio(left: TimeLeft, reports, mark: float, clock: int) -> float | None:
    """Told over true time left at :func:`_hit`; None without such a report."""
    hit = _hit(reports, mark, clock)
    if hit is None:
        return None
    told = left.seconds(hit[2], now=hit[clock])
    return None if told is None else told / (reports[-1][clock] - hit[clock])


def _shown(reports, mark: float, clock: int) -> bool:
    """Whether the true time left at :func:`_hit` is at least :data:`SHOWN_SECONDS`."""
    hit = _hit(reports, mark, clock)
    return hit is not None and reports[-1][clock] - hit[clock] >= SHOWN_SECONDS


def _cells(start, reports, predicted: float) -> tuple[list[str], list[float], list[float]]:
    """The cells of a run (wall: blended and rate alone; CPU: rate alone) and its blended wall
    and CPU ratios (for the summary)."""
    def cell(ratio, shown):
        if ratio is None:
            return "n/a"
        return f"{ratio:.2f}{'' if not shown or GOAL[0] <= ratio <= GOAL[1] else ' **'}" \
            f"{'' if shown else ' ·'}"

    wall, cpu, cells, cpu_cells = [], [], [], []
    for mark in MARKS:
        blended = _ratio(TimeLeft(predicted, lambda: start[0]), reports, mark, 0)
        alone = _ratio(TimeLeft(None, lambda: start[0]), reports, mark, 0)
        on_cpu = _ratio(TimeLeft(None, lambda: start[1]), reports, mark, 1)
        shown, cpu_shown = _shown(reports, mark, 0), _shown(reports, mark, 1)
        cells.append(cell(blended, shown) + ("" if alone is None else f" ({alone:.2f})"))
        cpu_cells.append(cell(on_cpu, cpu_shown))
        wall += [] if blended is None or not shown else [blended]
        cpu += [] if on_cpu is None or not cpu_shown else [on_cpu]
    return cells + cpu_cells, wall, cpu


def run(ctx) -> str:
    texture = max(ctx.textures, key=lambda t: min(t.image.shape[:2]))
    budget.machine_factor()  # the calibration before the first run, as the command line does
    lines = [
        f"Exemplars: top-left crops of {texture.short}, RGB, default parameters, seed {SEED}, "
        "one run each on the shared machine, at sizes where each takes seconds; make_tileable's "
        f"photo: {texture.short} mirrored out to {TILE_SIDE} x {TILE_SIDE}, a ramp added across "
        "so that it does not tile. Cells: the time left told at the first report "
        "past the mark over the time that was then left. Wall clock: with the prediction "
        "blended in (`texsynth.progress.TimeLeft`, what the command line and Blender show) and "
        "in brackets the rate alone (elapsed x (1 - f) / f, the rule before issue 40). CPU "
        "clock: the rate alone on the process's CPU time, which other programs' load does not "
        "move: how far the fractions are from the work. ** marks a ratio outside 0.67-1.5; "
        f"· a reading with under {SHOWN_SECONDS:.0f} s left, not rated (the display shows "
        "whole seconds: 0:00 or 0:01 whatever the ratio); n/a: no report between the mark and "
        "the end.",
        "",
        "| run | predicted s | took s | " + " | ".join(f"at {m:.0%}" for m in MARKS) + " | "
        + " | ".join(f"CPU at {m:.0%}" for m in MARKS) + " |",
        "|---|---:|---:|" + "---:|" * 2 * len(MARKS),
    ]
    wall, cpu = [], []

    def row(label, run, predicted):
        print(f"   {label}", flush=True)
        start, reports = _trace(run)
        cells, w, c = _cells(start, reports, predicted)
        wall.extend(w)
        cpu.extend(c)
        lines.append(f"| {label} | {predicted:.1f} | {reports[-1][0] - start[0]:.1f} | "
                     + " | ".join(cells) + " |")

    runs = [(m.name, *SIZES.get(m.name, DEFAULT_SIZE)) for m in texsynth.methods()]
    for name, side, out in runs + ([] if ctx.quick else list(LARGER)):
        side, out = (side // 2, out // 2) if ctx.quick else (side, out)
        exemplar = np.ascontiguousarray(texture.image[:side, :side])
        predicted, _ = budget.forecast(name, exemplar.shape, out, out)
        row(f"{name} {side} -> {out}", lambda p, e=exemplar, m=name, o=out: texsynth.synthesize(
            e, o, o, method=m, seed=SEED, progress=p), predicted)
    side = TILE_SIDE // 2 if ctx.quick else TILE_SIDE
    photo = np.pad(texture.image, [(0, max(side - n, 0)) for n in texture.image.shape[:2]]
                   + [(0, 0)], mode="symmetric")[:side, :side]
    photo = photo + np.linspace(0.0, 0.5, side, dtype=np.float32)[None, :, None]
    row(f"make_tileable {side}", lambda p: texsynth.make_tileable(photo, seed=SEED, progress=p),
        texsynth.tileable.predict(photo.shape)[0])

    def inside(ratios):
        return f"{sum(GOAL[0] <= r <= GOAL[1] for r in ratios)} of {len(ratios)}"

    lines += ["", f"Within 0.67-1.5: {inside(wall)} rated wall-clock readings (blended), "
              f"{inside(cpu)} CPU-clock ones."]
    return "\n".join(lines)

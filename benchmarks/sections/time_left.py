"""The time left against the time that was left (issue 40): every method and make_tileable.

Each run reports its fractions through a callback that asks :class:`texsynth.progress.TimeLeft`
for the time left at each report, as the command line's bar and Blender's status line do: from
the prediction made before the work (``texsynth.budget.forecast``, ``texsynth.tileable.predict``)
blended with the rate seen, and, for comparison, the rate alone (elapsed x (1 - f) / f, the rule
before issue 40). After the run the true time left at each report is known; the cells are
estimate / truth at the first report past 10 %, 50 % and 90 % (goal: 0.67-1.5).
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
#: (exemplar side, output side) per method: small enough for the section to take minutes; the
#: fast method at a size where it takes a measurable time, the slow one smaller.
SIZES = {"efros_leung": (64, 128), "random_phase": (256, 2048), "de_bonet": (256, 512)}
DEFAULT_SIZE = (128, 256)
#: Second runs of the methods whose fractions were furthest from the time (issue 40), larger.
LARGER = (("texture_optimization", 256, 512), ("portilla_simoncelli", 256, 512))
#: The photo side make_tileable is run on.
TILE_SIDE = 768
GOAL = (1 / 1.5, 1.5)


def _trace(run, predicted: float) -> tuple[float, list[tuple[float, float, float | None]]]:
    """(seconds of ``run(progress)``, [(report time, fraction, blended estimate, rate-alone
    estimate)]) with the estimates asked at each report."""
    reports = []
    blended = TimeLeft(predicted, time.perf_counter)
    alone = TimeLeft(None, time.perf_counter)

    def progress(fraction, message):
        now = time.perf_counter()
        reports.append((now, fraction, blended.seconds(fraction, now),
                        alone.seconds(fraction, now)))

    run(progress)
    end = time.perf_counter()
    return end - blended.start, [(end - t, f, b, a) for t, f, b, a in reports]


def _cells(reports) -> tuple[list[str], list[float]]:
    """'new / old' ratio cells at each mark and the blended ratios (for the summary)."""
    cells, ratios = [], []
    for mark in MARKS:
        hit = next(((truth, b, a) for truth, f, b, a in reports if f >= mark and f < 1.0), None)
        if hit is None or hit[0] <= 0:
            cells.append("n/a")
            continue
        truth, b, a = hit
        ratios.append(b / truth)
        old = "n/a" if a is None else f"{a / truth:.2f}"
        flag = "" if GOAL[0] <= b / truth <= GOAL[1] else " **"
        cells.append(f"{b / truth:.2f}{flag} ({old})")
    return cells, ratios


def run(ctx) -> str:
    texture = max(ctx.textures, key=lambda t: min(t.image.shape[:2]))
    budget.machine_factor()  # the calibration before the first run, as the command line does
    lines = [
        f"Exemplars: top-left crops of {texture.short}, RGB, default parameters, seed {SEED}, "
        "one run each on the shared machine. Cells: the time left told at the first report "
        "past the mark over the time that was then left, with the prediction blended in "
        "(`texsynth.progress.TimeLeft`, what the command line and Blender show) and in "
        "brackets the rate alone (elapsed x (1 - f) / f, the rule before issue 40); ** marks a "
        "ratio outside 0.67-1.5; n/a: no report between the mark and the end.",
        "",
        "| run | predicted s | took s | " + " | ".join(f"at {m:.0%}" for m in MARKS) + " |",
        "|---|---:|---:|" + "---:|" * len(MARKS),
    ]
    inside = total = 0
    runs = [(m.name, *SIZES.get(m.name, DEFAULT_SIZE)) for m in texsynth.methods()]
    for name, side, out in runs + ([] if ctx.quick else list(LARGER)):
        side, out = (side // 2, out // 2) if ctx.quick else (side, out)
        exemplar = np.ascontiguousarray(texture.image[:side, :side])
        predicted, _ = budget.forecast(name, exemplar.shape, out, out)
        print(f"   {name} {side} -> {out}", flush=True)
        took, reports = _trace(lambda p, e=exemplar, m=name, o=out: texsynth.synthesize(
            e, o, o, method=m, seed=SEED, progress=p), predicted)
        cells, ratios = _cells(reports)
        inside += sum(GOAL[0] <= r <= GOAL[1] for r in ratios)
        total += len(ratios)
        lines.append(f"| {name} {side} -> {out} | {predicted:.1f} | {took:.1f} | "
                     + " | ".join(cells) + " |")
    side = TILE_SIDE // 2 if ctx.quick else TILE_SIDE
    photo = np.ascontiguousarray(texture.image[:side, :side])
    predicted, _ = texsynth.tileable.predict(photo.shape)
    print("   make_tileable", flush=True)
    took, reports = _trace(lambda p: texsynth.make_tileable(photo, seed=SEED, progress=p),
                           predicted)
    cells, ratios = _cells(reports)
    inside += sum(GOAL[0] <= r <= GOAL[1] for r in ratios)
    total += len(ratios)
    lines.append(f"| make_tileable {side} | {predicted:.1f} | {took:.1f} | "
                 + " | ".join(cells) + " |")
    lines += ["", f"{inside} of {total} readings within 0.67-1.5."]
    return "\n".join(lines)

"""Time and peak memory of every method as the output grows, with the fitted exponent."""

from __future__ import annotations

import numpy as np

import texsynth

from ..plot import COLOURS, loglog

ORDER = 30
TITLE = "Scaling with output size"
SEED = 0
SIDES = (256, 512, 1024, 2048, 4096)
#: Largest output side a slow method is run at here (benchmark only; the method itself has no
#: such limit). A method author adds a line when a size would take far longer than a minute.
SIZE_CAP: dict[str, int] = {"efros_leung": 1024}
#: A size is skipped when the time predicted from the sizes run so far exceeds this.
BUDGET_S = 120.0


def _predict(pixels: list[int], seconds: list[float], target: int) -> float:
    """Time at ``target`` pixels from the last two points' slope (linear when only one)."""
    if len(pixels) < 2:
        return seconds[-1] * target / pixels[-1]
    slope = np.log(seconds[-1] / seconds[-2]) / np.log(pixels[-1] / pixels[-2])
    return seconds[-1] * (target / pixels[-1]) ** max(slope, 1.0)


def run(ctx) -> str:
    sides = (128, 256) if ctx.quick else SIDES
    texture = max(ctx.textures, key=lambda t: min(t.image.shape[:2]))
    exemplar = np.ascontiguousarray(texture.image[:128, :128])
    lines = [
        f"Exemplar: the {exemplar.shape[1]} x {exemplar.shape[0]} top-left crop of "
        f"{texture.short}, RGB; each method with its "
        f"default parameters, seed {SEED}, one run per size. Cells: seconds / tracemalloc peak "
        "MiB. A size is not run when the method's benchmark cap (`SIZE_CAP` in "
        f"benchmarks/sections/scaling.py) is below it, or when the time extrapolated from the "
        f"smaller sizes exceeds {BUDGET_S:.0f} s (the cell says which). The exponent is the "
        "least-squares slope of log time against log output pixels (1 = linear in the area).",
        "",
        "| method | " + " | ".join(f"{s}^2" for s in sides) + " | exponent |",
        "|---|" + "---|" * (len(sides) + 1),
    ]
    series, names = [], []
    for method in texsynth.methods():
        cap = SIZE_CAP.get(method.name, max(SIDES))
        cells, pixels, seconds = [], [], []
        for side in sides:
            if side > cap:
                cells.append(f"capped at {cap}")
                continue
            if seconds and (guess := _predict(pixels, seconds, side * side)) > BUDGET_S:
                cells.append(f"skipped (~{guess:.0f} s)")
                continue
            try:
                m = ctx.measure(lambda s=side, name=method.name: texsynth.synthesize(
                    exemplar, s, s, method=name, seed=SEED), repeats=1)
            except Exception as error:  # e.g. over the memory budget: reported, not fatal
                cells.append(f"failed: {type(error).__name__}")
                continue
            cells.append(f"{m.median_s:.2f} / {m.peak_mib:.0f}")
            pixels.append(side * side)
            seconds.append(m.median_s)
        slope = (f"{np.polyfit(np.log(pixels), np.log(seconds), 1)[0]:.2f}"
                 if len(pixels) > 1 else "n/a")
        lines.append(f"| {method.label} | " + " | ".join(cells) + f" | {slope} |")
        if pixels:
            series.append(([round(p ** 0.5) for p in pixels], seconds))
            names.append(method.label)
    if series:
        ctx.save_png("scaling.png", loglog(series, list(sides)))
        legend = ", ".join(f"{COLOURS[i % len(COLOURS)][0]}: {name}"
                           for i, name in enumerate(names))
        lines += ["", "![time against output side, log-log](img/scaling.png)", "",
                  f"Time (s) against output side (pixels), log-log. {legend}."]
    return "\n".join(lines)

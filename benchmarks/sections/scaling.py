"""Time and peak memory of every method as the output grows, with the fitted exponent."""

from __future__ import annotations

import numpy as np

import texsynth

ORDER = 30
TITLE = "Scaling with output size"
SEED = 0
SIDES = (256, 512, 1024, 2048, 4096)
BUDGET_S = 90.0  # a method stops growing after a size that took longer than this


def _plot(path, series: dict) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6, 4), dpi=100)
    for label, (pixels, seconds) in series.items():
        ax.loglog(pixels, seconds, marker="o", label=label)
    ax.set_xlabel("output pixels")
    ax.set_ylabel("seconds")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path)
    plt.close(fig)


def run(ctx) -> str:
    sides = SIDES[:3] if ctx.quick else SIDES
    texture = max(ctx.textures, key=lambda t: min(t.image.shape[:2]))
    exemplar = np.ascontiguousarray(texture.image[:128, :128])
    lines = [
        f"Exemplar: 128 x 128 from {texture.short}; default parameters; one run per size. A "
        f"method stops growing after a size that took over {BUDGET_S:.0f} s. The exponent is "
        "the slope of log time against log pixels (1 = linear in the output area).",
        "",
        "| method | " + " | ".join(f"{s}^2 s / MiB" for s in sides) + " | exponent |",
        "|---|" + "---|" * (len(sides) + 1),
    ]
    series = {}
    for method in texsynth.methods():
        cells, pixels, seconds = [], [], []
        for side in sides:
            if seconds and seconds[-1] > BUDGET_S:
                cells.append("not run")
                continue
            m = ctx.measure(lambda s=side, name=method.name: texsynth.synthesize(
                exemplar, s, s, method=name, seed=SEED), repeats=1)
            cells.append(f"{m.median_s:.2f} / {m.peak_mib:.0f}")
            pixels.append(side * side)
            seconds.append(m.median_s)
        slope = (f"{np.polyfit(np.log(pixels), np.log(seconds), 1)[0]:.2f}"
                 if len(pixels) > 1 else "n/a")
        lines.append(f"| {method.label} | " + " | ".join(cells) + f" | {slope} |")
        series[method.label] = (pixels, seconds)
    ctx.img_dir.mkdir(parents=True, exist_ok=True)
    _plot(ctx.img_dir / "scaling.png", series)
    lines += ["", "![time against output pixels](img/scaling.png)"]
    return "\n".join(lines)

"""Every registered method and every peer on every texture: time, memory, quality, pictures."""

from __future__ import annotations

import statistics

import numpy as np

import texsynth
from texsynth import metrics

from ..peers import peers

ORDER = 10
TITLE = "All methods and peers on every texture"
SEED = 0


def _crop(image: np.ndarray, side: int) -> np.ndarray:
    h, w = image.shape[:2]
    top, left = max(0, (h - side) // 2), max(0, (w - side) // 2)
    return np.ascontiguousarray(image[top:top + side, left:left + side])


def _entries():
    """(name, label, run, traced) for each method with its defaults, then each runnable peer."""
    entries = [(m.name, m.label, (lambda ex, w, h, s, name=m.name: texsynth.synthesize(
        ex, w, h, method=name, seed=s)), True) for m in texsynth.methods()]
    skipped = []
    for peer in peers():
        if peer.missing:
            skipped.append(f"{peer.label}: {peer.missing}")
        else:
            entries.append((peer.name, peer.label, peer.run, peer.in_process))
    return entries, skipped


def _fmt(values, digits=2):
    return f"{statistics.median(values):.{digits}f}" if values else "n/a"


def run(ctx) -> str:
    side, out_side = (64, 128) if ctx.quick else (128, 256)
    entries, skipped = _entries()
    methods = {m.name for m in texsynth.methods()}
    rows = {name: {"time": [], "peak": [], "rss": [], "failed": []} for name, *_ in entries}
    times = {name: {} for name, *_ in entries}  # texture -> seconds, for same-texture ratios
    quality = {name: [] for name, *_ in entries}
    natural = []
    sheets = {}  # texture name -> the contact sheet's path for the markdown
    for texture in ctx.textures:
        exemplar = _crop(texture.image, side)
        natural.append(metrics.self_distance(exemplar))
        outputs = []
        for name, _label, fn, traced in entries:
            try:
                m = ctx.measure(lambda fn=fn, ex=exemplar: fn(ex, out_side, out_side, SEED),
                                repeats=1)
            except Exception as error:  # a failing entry is reported, not fatal
                rows[name]["failed"].append(f"{texture.short}: {type(error).__name__}: {error}")
                outputs.append(None)
                continue
            output = np.asarray(m.result, np.float32)[:, :, :3]
            rows[name]["time"].append(m.median_s)
            times[name][texture.name] = m.median_s
            rows[name]["rss"].append(m.rss_mib)
            if traced:
                rows[name]["peak"].append(m.peak_mib)
            quality[name].append({"category": texture.category,
                                  **metrics.quality(exemplar, output)})
            outputs.append(output)
        tiles = [None] + [None if o is None else np.tile(o, (2, 2, 1)) for o in outputs]
        sheets[texture.name] = ctx.contact_sheet(
            f"sheet_{texture.short}.png", ["exemplar"] + [n for n, *_ in entries],
            [[exemplar] + outputs, tiles], cell=128 if ctx.quick else 96)

    lines = [
        f"Each exemplar is the central {side} x {side} crop of the texture; every method (its "
        f"default parameters) and peer makes a {out_side} x {out_side} output with seed {SEED}. "
        f"{len(ctx.textures)} textures, one run each. Medians over the textures; copy share is "
        "the mean share of output patches copied verbatim. *Exemplar halves* is the natural "
        "variation: the same distances between the two halves of each exemplar crop. Traced MiB: "
        "tracemalloc's peak (numpy methods and the textbook build; C code allocates outside it); "
        "RSS MiB: growth of the process's resident high-water mark over the call (it misses "
        "heap memory reused from earlier calls, so small outputs can show 0), or for G'MIC the "
        "whole subprocess's peak RSS, its code and libraries included (not comparable).",
        "",
        "| method / peer | time s | time vs textbook HB | traced MiB | RSS MiB | seam ratio "
        "| subband dist. | patch dist. | copy share | structure dist. |",
        "|---|---|---|---|---|---|---|---|---|---|",
    ]
    reference = rows.get("textbook_hb", {}).get("time")
    for name, label, *_ in entries:
        r, q = rows[name], quality[name]
        if not r["time"]:
            lines.append(f"| {label} | failed | | | | | | | | |")
            continue
        ratio = (f"{statistics.median(reference) / statistics.median(r['time']):.1f}x faster"
                 if reference else "n/a")
        lines.append(
            f"| {label} | {_fmt(r['time'])} [{min(r['time']):.2f}-{max(r['time']):.2f}] | {ratio} "
            f"| {_fmt(r['peak'], 0)} | {_fmt(r['rss'], 0)} | {_fmt([x['seam_ratio'] for x in q])} "
            f"| {_fmt([x['subband_distance'] for x in q], 3)} "
            f"| {_fmt([x['patch_distance'] for x in q], 3)} "
            f"| {np.mean([x['copy_share'] for x in q]):.3f} "
            f"| {_fmt([x['structure_distance'] for x in q], 3)} |")
    lines.append(
        f"| *Exemplar halves* | | | | | {_fmt([metrics.seam_ratio(t.image) for t in ctx.textures])}"
        f" (exemplars) | {_fmt([n['subband_distance'] for n in natural], 3)} "
        f"| {_fmt([n['patch_distance'] for n in natural], 3)} "
        f"| {np.mean([n['copy_share'] for n in natural]):.3f} "
        f"| {_fmt([n['structure_distance'] for n in natural], 3)} |")
    categories = sorted({t.category for t in ctx.textures})
    failures = [f"- {name}: {f}" for name, r in rows.items() for f in r["failed"]]
    if skipped or failures:
        lines += ["", "Skipped or failed:", *[f"- {s}" for s in skipped], *failures]
    lines += ["", "### Speed ratios against each peer, same textures, same run", "",
              "Median over the textures of (peer time / method time): above 1, the method is "
              "faster.", "",
              "| method | " + " | ".join(label for name, label, *_ in entries
                                        if name not in methods) + " |",
              "|---|" + "---|" * (len(entries) - len(methods))]
    for name, label, *_ in entries:
        if name in methods:
            cells = []
            for peer, *_ in entries:
                if peer in methods:
                    continue
                ratios = [times[peer][t] / s for t, s in times[name].items() if t in times[peer]]
                cells.append(f"{statistics.median(ratios):.2f}" if ratios else "n/a")
            lines.append(f"| {label} | " + " | ".join(cells) + " |")
    lines += ["", "### Structure distance per category", "",
              "| method / peer | " + " | ".join(categories) + " |",
              "|---|" + "---|" * len(categories)]
    for name, label, *_ in entries:
        cells = []
        for cat in categories:
            cells.append(_fmt([q["structure_distance"] for q in quality[name]
                               if q["category"] == cat], 3))
        lines.append(f"| {label} | " + " | ".join(cells) + " |")
    lines += ["", "### Contact sheets", "",
              "Columns: exemplar, then " + ", ".join(label for _, label, *_ in entries)
              + f". Top row: the outputs; bottom row: each output tiled 2 x 2, where seams and "
              f"repetition show; shrunk to fit {128 if ctx.quick else 96} px cells.", ""]
    lines += [f"**{t.name}** ({t.category}, {t.license})\n\n![{t.short}]({sheets[t.name]})\n"
              for t in ctx.textures]
    return "\n".join(lines)

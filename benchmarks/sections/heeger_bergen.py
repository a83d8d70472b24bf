"""Issue 2's figures: texsynth's Heeger-Bergen against the textbook build in the same run, and
(issue 45) both beside a known added load: ``n`` busy loops (``benchmarks/load.py``) on top of
what the machine already runs, texsynth on every core and on one thread, interleaved in one
process so the ratios share the load."""

from __future__ import annotations

import os
import statistics
import time

import numpy as np

import texsynth
from texsynth import metrics
from texsynth.blocks import parallel

from ..load import busy
from ..peers import peers, textbook_hb

ORDER = 20
TITLE = "Heeger-Bergen: texsynth against the textbook build"
SEED = 0
PARAMS = {"scales": 4, "orientations": 4, "iterations": 15}
#: Busy loops added for the load rows; their exemplar and output sides; runs of each (fastest).
LOADS, LOAD_SIDES, LOAD_RUNS = (0, 1, 2), (128, 256), 2
#: Goal at 2 added loops: texsynth at least this many times faster than the textbook build.
LOAD_GOAL = 5.0


def _seconds(fn) -> float:
    start = time.perf_counter()
    fn()
    return time.perf_counter() - start


def _under_load(ctx) -> list[str]:
    """Rows: per added load, the fastest of ``LOAD_RUNS`` interleaved runs of texsynth on every
    core and on one thread (``parallel.WORKERS`` = 1) and of the textbook build."""
    side, out = LOAD_SIDES
    ex = np.ascontiguousarray(_exemplars(ctx, side, 1)[0].image[:side, :side])
    ours = lambda: texsynth.synthesize(ex, out, out, seed=SEED, **PARAMS)  # noqa: E731
    workers = parallel.WORKERS
    lines = [
        "", f"Beside an added load ({side} x {side} -> {out} x {out}, same parameters; n busy "
        f"loops at the benchmark's priority on top of what the machine runs; fastest of "
        f"{LOAD_RUNS} interleaved runs; 'slower': the time over the same column's at 0 added):",
        "", f"| added loops | load average | every core ({workers}) s | slower | one thread s "
        "| slower | textbook s | speed-up, every core | speed-up, one thread |",
        "|---:|---:|---:|---:|---:|---:|---:|---:|---:|",
    ]
    first = None
    for n in (LOADS[:2] if ctx.quick else LOADS):
        times = {"all": [], "one": [], "book": []}
        with busy(n):
            for _ in range(LOAD_RUNS):
                times["all"].append(_seconds(ours))
                parallel.WORKERS = 1
                try:
                    times["one"].append(_seconds(ours))
                finally:
                    parallel.WORKERS = workers
                times["book"].append(_seconds(lambda: textbook_hb(ex, out, out, SEED)))
            load = os.getloadavg()[0]
        best = {k: min(v) for k, v in times.items()}
        first = first or best
        lines.append(f"| {n} | {load:.1f} | {best['all']:.2f} | {best['all'] / first['all']:.2f}x "
                     f"| {best['one']:.2f} | {best['one'] / first['one']:.2f}x "
                     f"| {best['book']:.2f} | {best['book'] / best['all']:.1f}x "
                     f"| {best['book'] / best['one']:.1f}x |")
    if LOADS[-1] == n:
        lines += ["", f"At {n} added loops texsynth is **{best['book'] / best['all']:.1f}x** the "
                  f"textbook build (goal: at least {LOAD_GOAL:g}x)."]
    return lines


def _exemplars(ctx, side: int, count: int):
    """The first ``count`` textures (manifest order) at least ``side`` a side, cropped to it."""
    chosen = [t for t in ctx.textures if min(t.image.shape[:2]) >= side][:count]
    return chosen or ctx.textures[:1]


def run(ctx) -> str:
    side, out_side = (128, 256) if ctx.quick else (256, 512)
    repeats = 1 if ctx.quick else 3
    missing = next(p.missing for p in peers() if p.name == "textbook_hb")
    lines = [
        f"{side} x {side} RGB exemplar (central crop) to {out_side} x {out_side}, "
        f"{PARAMS['scales']} scales x {PARAMS['orientations']} orientations x "
        f"{PARAMS['iterations']} iterations, seed {SEED}; median of {repeats} runs each. The "
        "textbook build is Forsyth & Ponce's Algorithm 11.4 on pyrtools' SteerablePyramidFreq with "
        "sort-based matching (benchmarks/peers/textbook_hb.py). Subband distance: "
        "texsynth.metrics, lower is closer to the exemplar. Peak: tracemalloc's, MiB.",
        "",
        "| texture | texsynth s | textbook s | speed-up | texsynth peak MiB | textbook peak MiB "
        "| subband dist. texsynth | subband dist. textbook |",
        "|---|---|---|---|---|---|---|---|",
    ]
    speedups = []
    for texture in _exemplars(ctx, side, 1 if ctx.quick else 3):
        h, w = texture.image.shape[:2]
        ex = np.ascontiguousarray(texture.image[(h - side) // 2:(h - side) // 2 + side,
                                                (w - side) // 2:(w - side) // 2 + side])
        ours = ctx.measure(lambda ex=ex: texsynth.synthesize(ex, out_side, out_side, seed=SEED,
                                                             **PARAMS), repeats)
        d_ours = metrics.subband_distance(ex, ours.result)
        if missing:
            lines.append(f"| {texture.short} | {ours.median_s:.2f} | skipped | | "
                         f"{ours.peak_mib:.0f} | | {d_ours:.3f} | |")
            continue
        book = ctx.measure(lambda ex=ex: textbook_hb(ex, out_side, out_side, SEED), repeats)
        speedups.append(book.median_s / ours.median_s)
        lines.append(
            f"| {texture.short} | {ours.median_s:.2f} [{ours.min_s:.2f}-{ours.max_s:.2f}] "
            f"| {book.median_s:.2f} [{book.min_s:.2f}-{book.max_s:.2f}] | {speedups[-1]:.1f}x "
            f"| {ours.peak_mib:.0f} | {book.peak_mib:.0f} | {d_ours:.3f} "
            f"| {metrics.subband_distance(ex, book.result):.3f} |")
    if missing:
        lines += ["", f"Textbook build skipped: {missing}."]
    elif speedups:
        lines += ["", f"Median speed-up: **{statistics.median(speedups):.1f}x**."]

    big = 512 if ctx.quick else 4096
    texture = _exemplars(ctx, side, 1)[0]
    ex = np.ascontiguousarray(texture.image[:side, :side])
    m = ctx.measure(lambda: texsynth.synthesize(ex, big, big, seed=SEED, **PARAMS), repeats=1)
    tiles = metrics.seam_ratio(m.result)
    lines += ["", f"A {big} x {big} RGB output from {texture.short} with the same parameters: "
              f"{m.median_s:.1f} s, peak traced memory {m.peak_mib:.0f} MiB (resident growth "
              f"{m.rss_mib:.0f} MiB), seam ratio {tiles:.2f}."]
    if not missing:
        lines += _under_load(ctx)
    return "\n".join(lines)

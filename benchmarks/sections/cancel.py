"""Esc at production size (issue 18): how long a cancel waits before the work stops.

The Blender operators run a method in a worker thread whose progress callback returns False once
Esc is pressed (``operators/job.py``); the method stops at its next progress report. Here each
method runs in a thread on the production section's brick photo (1024 -> 2048), and a cancel is
requested at fixed moments after the start; the latency is the time from the request until
``texsynth.synthesize`` has raised ``Cancelled``. One fresh run per moment, so every phase
(the exemplar's analysis, coarse levels, the finest level) is sampled.
"""

from __future__ import annotations

import threading
import time

import numpy as np

import texsynth
from texsynth.progress import Cancelled

from .production import LARGE, METHODS, PHOTOS, SIDE, load

ORDER = 36
TITLE = "Esc at production size: how long a cancel waits"
SEED = 0
#: Seconds after the start at which a cancel is requested.
MOMENTS = (0.5, 2.0, 5.0, 12.0)


def _latency(exemplar: np.ndarray, method: str, moment: float) -> float | None:
    """Seconds from a cancel requested ``moment`` s after the start until the method stopped;
    None when it finished first."""
    asked = threading.Event()
    outcome = {}

    def progress(fraction, message):
        return not asked.is_set()

    def work():
        try:
            texsynth.synthesize(exemplar, SIDE, SIDE, method=method, seed=SEED,
                                progress=progress)
            outcome["finished"] = True
        except Cancelled:
            outcome["stopped"] = time.perf_counter()

    worker = threading.Thread(target=work)
    worker.start()
    worker.join(moment)
    if not worker.is_alive():
        return None
    request = time.perf_counter()
    asked.set()
    worker.join()
    return outcome["stopped"] - request if "stopped" in outcome else None


def run(ctx) -> str:
    if not LARGE.exists():
        return "Skipped: ../shared/textures/large is absent."
    photo = PHOTOS[0][0]
    exemplar = load(LARGE / photo)
    moments = MOMENTS[:2] if ctx.quick else MOMENTS
    lines = [
        f"Photo: {photo} ({exemplar.shape[1]} x {exemplar.shape[0]}), output {SIDE} x {SIDE}, "
        f"default parameters, seed {SEED}. A cancel is requested at each moment after the start "
        "(a fresh run each); cells: seconds until the method had stopped (what Esc waits for in "
        "Blender; goal: under 1 s). Blank: the run had finished before that moment.",
        "",
        "| method | " + " | ".join(f"at {m:g} s" for m in moments) + " | longest |",
        "|---|" + "---:|" * (len(moments) + 1),
    ]
    for method in METHODS:
        print(f"   {method}", flush=True)
        waits = [_latency(exemplar, method, m) for m in moments]
        seen = [w for w in waits if w is not None]
        cells = ["" if w is None else f"{w:.2f}" for w in waits]
        longest = f"{max(seen):.2f}" if seen else ""
        lines.append(f"| {method} | " + " | ".join(cells) + f" | {longest} |")
    return "\n".join(lines)

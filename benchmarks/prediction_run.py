"""python -m benchmarks.prediction_run JSON: one run's predicted time and memory against its own.

JSON: ``{"method": NAME or "make_tileable", "exemplar": [H, W], "size": [W, H], "params": {}}``
(the exemplar is the pool_water sample's corner, tiled up when larger; make_tileable's photo is
``exemplar`` with a ramp across it, so that it does not already tile). In this fresh process,
after the imports, the exemplar and the calibration: the prediction (``budget.forecast`` /
``tileable.predict``: what the panel shows and the budgets check; given the exemplar, as the
panel and the batch jobs give it, so that a joint width the method would measure is measured:
the pool_water corners read joints 2 px wide, and from their shape alone multiscale_mrf's 64 ->
256 was told 0.53-0.61x its time), then the run (seed 0); one
JSON line with the measured wall seconds and the peak resident memory above the baseline (the
high-water mark ``VmHWM``, reset through ``/proc/self/clear_refs`` before the run, over the
resident size ``VmRSS`` then, in bytes: ``ru_maxrss`` cannot be reset, and a transient peak
of the imports, freed before the run, had hidden a run's peak below it), which is what the
memory budget must hold.
"""

from __future__ import annotations

import json
import sys
import time
from pathlib import Path

import numpy as np

import texsynth
from texsynth import budget, tileable
from texsynth.io import read_photo

from .context import reset_high_water, status_kib

SAMPLE = Path(__file__).resolve().parents[1] / "samples" / "pool_water.png"


def exemplar(h: int, w: int) -> np.ndarray:
    """The sample's corner (H, W, 3), mirrored and tiled up when larger than the sample."""
    photo = read_photo(SAMPLE)[..., :3]
    reps = (-(-h // photo.shape[0]), -(-w // photo.shape[1]), 1)
    return np.ascontiguousarray(np.tile(photo, reps)[:h, :w], np.float32)


def main(case: dict) -> dict:
    x = exemplar(*case["exemplar"])
    width, height = case["size"]
    params = case.get("params", {})
    if case["method"] == "make_tileable":
        x += np.linspace(0.0, 0.5, x.shape[1], dtype=np.float32)[None, :, None]
        seconds, peak = tileable.predict(x.shape)
        run = lambda: tileable.make_tileable(x, seed=0)  # noqa: E731
    else:
        seconds, peak = budget.forecast(case["method"], x.shape, width, height, params,
                                        exemplar=x)
        run = lambda: texsynth.synthesize(x, width, height, method=case["method"],  # noqa: E731
                                          seed=0, **params)
    reset_high_water()
    base = status_kib("VmRSS")
    start = time.perf_counter()
    run()
    wall = time.perf_counter() - start
    return {**case, "predicted_s": seconds, "measured_s": wall, "predicted_bytes": peak,
            "resident_bytes": max(status_kib("VmHWM") - base, 0) * 1024,
            "factor": budget.machine_factor(), "speed": budget.speed()}


if __name__ == "__main__":
    print(json.dumps(main(json.loads(sys.argv[1]))), flush=True)

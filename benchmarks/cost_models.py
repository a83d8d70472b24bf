"""python -m benchmarks.cost_models [--fit]: each method's cost model against measured runs.

For every method, a few sizes are run once (small: the whole takes a few minutes on 2 shared
cores; run it when the machine is quiet: a loaded machine skews single short runs by 2-3x) and
the measured seconds printed beside the prediction (``texsynth.budget.predict``:
the method's ``cost`` times this machine's speed factor) and their ratio. The rows marked
``fit`` are the sizes the coefficients of each method's ``_cost`` (in its module) were fitted on;
the others check the prediction at sizes it was not fitted on. ``--fit`` also prints, per method,
the least-squares scale that would make the predictions match the measurements on the fit rows.
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

import numpy as np

import texsynth
from texsynth import budget
from texsynth.io import read_photo

REPO = Path(__file__).resolve().parents[1]

#: (method, exemplar side, width, height, params, used for fitting)
CASES = [
    ("heeger_bergen", 64, 64, 64, {}, True),
    ("heeger_bergen", 64, 256, 256, {}, True),
    ("heeger_bergen", 64, 160, 128, {"iterations": 5}, False),
    ("heeger_bergen", 64, 384, 256, {}, False),
    ("efros_leung", 32, 24, 24, {}, True),
    ("efros_leung", 48, 48, 48, {}, True),
    ("efros_leung", 40, 40, 32, {"window": 7}, False),
    ("efros_leung", 32, 56, 48, {}, False),
    ("efros_leung", 48, 96, 96, {}, False),
    ("multiscale_mrf", 64, 64, 64, {}, True),
    ("multiscale_mrf", 64, 192, 192, {}, True),
    ("multiscale_mrf", 48, 128, 96, {"radius": 2}, False),
    ("multiscale_mrf", 64, 256, 128, {}, False),
    ("de_bonet", 64, 64, 64, {}, True),
    ("de_bonet", 64, 256, 256, {}, True),
    ("de_bonet", 48, 160, 128, {}, False),
    ("de_bonet", 64, 384, 384, {}, False),
    ("cooccurrence", 48, 48, 48, {}, True),
    ("cooccurrence", 48, 128, 128, {}, True),
    ("cooccurrence", 40, 96, 80, {"max_cliques": 20}, False),
    ("cooccurrence", 48, 192, 160, {}, False),
    ("composite", 48, 48, 48, {}, True),
    ("composite", 48, 96, 96, {}, False),
]


def _exemplar(side: int) -> np.ndarray:
    return np.ascontiguousarray(read_photo(REPO / "samples" / "pool_water.png")[:side, :side, :3])


def measure() -> list[tuple]:
    rows = []
    for name, side, width, height, params, fitted in CASES:
        exemplar = _exemplar(side)
        method = texsynth.get_method(name)
        predicted = budget.predict(method, exemplar.shape, width, height, method.resolve(params))
        start = time.perf_counter()
        texsynth.synthesize(exemplar, width, height, method=name, seed=1, **params)
        seconds = time.perf_counter() - start
        rows.append((name, side, width, height, params, fitted, seconds, predicted))
        print(f"{name:15s} {side:3d}^2 -> {width:4d} x {height:<4d} {str(params):22s} "
              f"{'fit ' if fitted else 'test'} measured {seconds:7.2f} s  predicted "
              f"{predicted:7.2f} s  ratio {predicted / seconds:5.2f}", flush=True)
    return rows


def main() -> None:
    print(f"machine factor {budget.machine_factor():.2f} (calibration workload / reference)")
    rows = measure()
    if "--fit" in sys.argv:
        for name in dict.fromkeys(r[0] for r in rows):
            fit = [(r[6], r[7]) for r in rows if r[0] == name and r[5]]
            m, p = np.array(fit).T
            print(f"{name}: scale the coefficients by {float((m * p).sum() / (p * p).sum()):.2f}")


if __name__ == "__main__":
    main()

"""python -m benchmarks.predictions METHOD PHOTO SIDE: one run's predicted time against its own.

PHOTO is a key of the photos section (``camera`` for its 12 MP photo, ``camera@1024x1024`` for
its centre, or a file below ``../shared/textures/large``). In this fresh process: this machine's
speed and load (``texsynth.budget.speed``, ``contention``), the method's cost model, then the
run (defaults, seed 0, SIDE x SIDE) and one JSON line: the prediction at the speed alone (what a
quiet machine would be told), at speed and load (what the budget and the panel say now), the
measured wall time, their ratios and the load average before and after. Run it at a quiet
moment and beside a busy loop or two (``python -c "while 1: pass" &``) to see both.
"""

from __future__ import annotations

import json
import os
import sys
import time

import texsynth
from texsynth import budget

from .sections.photos import photo


def main(name: str, key: str, side: int) -> dict:
    image = photo(key)
    load = os.getloadavg()[0]
    speed, contention = budget.speed(), budget.contention()
    method = texsynth.get_method(name)
    values = method.resolve({})
    quiet = method.cost(image.shape, side, side, values) * speed
    predicted = budget.predict(method, image.shape, side, side, values)  # the budget's figure
    start = time.perf_counter()
    texsynth.synthesize(image, side, side, method=name, seed=0)
    seconds = time.perf_counter() - start
    return {"method": name, "photo": key, "side": side, "load": load,
            "load_after": os.getloadavg()[0], "speed": speed, "contention": contention,
            "seconds": seconds, "quiet_predicted": quiet, "predicted": predicted,
            "ratio_quiet": quiet / seconds, "ratio": predicted / seconds}


if __name__ == "__main__":
    print(json.dumps(main(sys.argv[1], sys.argv[2], int(sys.argv[3]))), flush=True)

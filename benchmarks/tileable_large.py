"""make_tileable on each large photo at its own size, one line each (a cheap check, not a
section): seam (plain / in phase, as sections/regular.py), band sharpness, gradient ratio,
unchanged share, time and predicted time. ``python -m benchmarks.tileable_large [SEED]``;
with PYTHONPATH pointing at another checkout it measures that one's code."""

import csv
import sys
import time

import numpy as np

from texsynth import make_tileable, metrics
from texsynth.io import read_photo
from texsynth.tileable import default_band, predict

from .sections.photos import LARGE
from .sections.tileable import unchanged


def main(seed: int = 0) -> None:
    with (LARGE / "MANIFEST.tsv").open() as f:
        names = [row["file"] for row in csv.DictReader(f, delimiter="\t")]
    print("photo | size | seam | in phase | band sharpness | gradient | unchanged | s | "
          "predicted s")
    for name in names:
        photo = np.ascontiguousarray(read_photo(LARGE / name)[:, :, :3], np.float32)
        h, w = photo.shape[:2]
        band = default_band(photo.shape)
        start = time.perf_counter()
        out = make_tileable(photo, seed=seed)
        seconds = time.perf_counter() - start
        print(f"{name} | {w}x{h} | {metrics.seam_ratio(out):.2f} | "
              f"{metrics.seam_ratio_in_phase(out):.2f} | {metrics.band_sharpness(out, band):.2f} | "
              f"{metrics.gradient_ratio(photo, out):.2f} | {unchanged(photo, out):.2f} | "
              f"{seconds:.2f} | {predict(photo.shape)[0]:.2f}", flush=True)


if __name__ == "__main__":
    main(int(sys.argv[1]) if len(sys.argv) > 1 else 0)

"""Brick courses at production size, a cheap check (not a section): each photo (1024 px) to
2048 by one method, seeds as given, one process.

    .venv/bin/python -m benchmarks.brick_rows --before --seeds 0 1 bricks gravel rock

Columns: seconds, gradient ratio (``texsynth.metrics.gradient_ratio``), seam ratio (the wrap's
against the inside, ``texsynth.metrics.seam_ratio``, and against the lines at the same place in
the rows' rhythm, ``seam_ratio_in_phase``), the row disagreement of
``benchmarks.straight_cuts`` (photo / output) and the course steps (photo / output): where the
bed joints of neighbouring column strips stand a quarter course or more apart
(``texsynth.metrics.course_steps``, the course height read from the photo).
``--crops DIR`` saves the output's 512 px crop across the wrap and its middle as PNG.

The row disagreement does not see the courses' steps (a per-pixel share that head joints and
the bricks' shades dominate): on the brick wall, seeds 0 and 1, it read 0.129 before the MRF's
copies slid into phase and 0.126-0.127 after, while the course steps went from 0.070 and 0.087
to 0.044 and 0.048 (photo 0.019), matching what the crops show.
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np

import texsynth
from texsynth.algorithms import multiscale_mrf as mrf
from texsynth.io import read_photo, write_image
from texsynth.metrics import (
    course_period,
    course_steps,
    gradient_ratio,
    seam_ratio,
    seam_ratio_in_phase,
)

from .context import SHARED_TEXTURES
from .straight_cuts import row_disagreement

PHOTOS = {"bricks": "ufoai-textures/brick_wall.png",
          "gravel": "torcs-data/gravel_pebbles.png",
          "rock": "ufoai-textures/layered_grey_rock.png"}
CROP = 512


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--method", default="multiscale_mrf")
    parser.add_argument("--side", type=int, default=2048)
    parser.add_argument("--seeds", type=int, nargs="+", default=[0])
    parser.add_argument("--before", action="store_true",
                        help="multiscale_mrf: each run also without its copies slid into phase "
                        "(ALIGN_PIXELS 0, as before issue 25's fix), first")
    parser.add_argument("--crops", type=Path, help="save 512 px crops here")
    parser.add_argument("photos", nargs="+", choices=sorted(PHOTOS))
    args = parser.parse_args()
    print("| photo | method | seed | s | gradient | seam / in phase | rows photo / out | "
          "course steps photo / out |")
    print("|---|---|---|---|---|---|---|---|")
    aligned = mrf.ALIGN_PIXELS
    for key in args.photos:
        z = np.ascontiguousarray(read_photo(SHARED_TEXTURES / "large" / PHOTOS[key])[:, :, :3],
                                 np.float32)
        period = course_period(z)
        for seed in args.seeds:
            for before in (True, False) if args.before else (False,):
                mrf.ALIGN_PIXELS = 0 if before else aligned
                name = args.method + (" before" if before else "")
                start = time.perf_counter()
                out = texsynth.synthesize(z, args.side, args.side, method=args.method,
                                          seed=seed)
                seconds = time.perf_counter() - start
                print(f"| {key} | {name} | {seed} | {seconds:.1f} | "
                      f"{gradient_ratio(z, out):.3f} | {seam_ratio(out):.3f} / "
                      f"{seam_ratio_in_phase(out):.3f} | "
                      f"{row_disagreement(z):.3f} / {row_disagreement(out):.3f} | "
                      f"{course_steps(z, period, wrap=False):.3f} / "
                      f"{course_steps(out, period):.3f} |", flush=True)
                if args.crops:
                    args.crops.mkdir(parents=True, exist_ok=True)
                    stem = args.crops / f"{key}_{name.replace(' ', '_')}_{seed}"
                    wrap = np.roll(out, (CROP // 2, CROP // 2), axis=(0, 1))[:CROP, :CROP]
                    mid = (args.side - CROP) // 2
                    write_image(f"{stem}_wrap.png", wrap)
                    write_image(f"{stem}_middle.png", out[mid:mid + CROP, mid:mid + CROP])


if __name__ == "__main__":
    main()

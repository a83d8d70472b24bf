"""Brick courses at production size, a cheap check (not a section): each photo (1024 px) to
2048 by one method, seeds as given, one process.

    .venv/bin/python -m benchmarks.brick_rows --seeds 0 1 bricks gravel rock

Columns: seconds, gradient ratio (``texsynth.metrics.gradient_ratio``), seam ratio (the wrap's
against the inside, ``texsynth.metrics.seam_ratio``), the row disagreement of
``benchmarks.straight_cuts`` (photo / output) and the course steps (photo / output): where the
bed joints of neighbouring column strips stand a quarter course or more apart (``course_steps``).
``--crops DIR`` saves the output's 512 px crop across the wrap and its middle as PNG.
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np

import texsynth
from texsynth.io import read_image, write_image
from texsynth.metrics import gradient_ratio, luminance, seam_ratio

from .context import SHARED_TEXTURES
from .straight_cuts import row_disagreement

PHOTOS = {"bricks": "ufoai-textures/brick_wall.png",
          "gravel": "torcs-data/gravel_pebbles.png",
          "rock": "ufoai-textures/layered_grey_rock.png"}
#: Column strips (pixels wide) whose bed-joint rows are compared with the next strip's.
STRIP = 32
CROP = 512


def course_period(photo: np.ndarray) -> int:
    """The course height of a photo of rows: the first autocorrelation peak of its row profile
    (the mean luminance of each row), between 8 px and a quarter of the height."""
    p = luminance(photo).mean(axis=1)
    p = p - p.mean()
    a = np.correlate(p, p, "full")[len(p) - 1:]
    return 8 + int(np.argmax(a[8:len(p) // 4]))


def course_steps(image: np.ndarray, period: int, wrap: bool = True) -> float:
    """The share of places where the courses step: per pair of neighbouring column strips
    (``STRIP`` px; across the wrap too when ``wrap``) and window of two courses (every course),
    the vertical shift, within half a course either way, at which the two strips' row profiles
    correlate best is a quarter course or more."""
    y = luminance(image)
    h, w = y.shape
    n = w // STRIP
    prof = y[:, :n * STRIP].reshape(h, n, STRIP).mean(axis=2)
    left, right = (prof, np.roll(prof, -1, axis=1)) if wrap else (prof[:, :-1], prof[:, 1:])
    half = period // 2
    shifts = np.arange(-half, half + 1)
    starts = np.arange(half, h - 2 * period - half, period)
    rows = starts[:, None] + np.arange(2 * period)[None, :]  # (windows, 2 T)

    def standard(a):  # (windows, 2 T, strips): each window's profile centred, unit norm
        a = a - a.mean(axis=1, keepdims=True)
        return a / np.maximum(np.sqrt((a * a).sum(axis=1, keepdims=True)), 1e-6)

    a = standard(left[rows])
    corr = np.stack([(a * standard(right[rows + d])).sum(axis=1) for d in shifts])
    best = shifts[corr.argmax(axis=0)]  # (windows, strips)
    return float((np.abs(best) >= period / 4).mean())


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--method", default="multiscale_mrf")
    parser.add_argument("--side", type=int, default=2048)
    parser.add_argument("--seeds", type=int, nargs="+", default=[0])
    parser.add_argument("--crops", type=Path, help="save 512 px crops here")
    parser.add_argument("photos", nargs="+", choices=sorted(PHOTOS))
    args = parser.parse_args()
    print("| photo | method | seed | s | gradient | seam | rows photo / out | course steps "
          "photo / out |")
    print("|---|---|---|---|---|---|---|---|")
    for key in args.photos:
        z = np.ascontiguousarray(read_image(SHARED_TEXTURES / "large" / PHOTOS[key])[:, :, :3],
                                 np.float32)
        period = course_period(z)
        for seed in args.seeds:
            start = time.perf_counter()
            out = texsynth.synthesize(z, args.side, args.side, method=args.method, seed=seed)
            seconds = time.perf_counter() - start
            print(f"| {key} | {args.method} | {seed} | {seconds:.1f} | "
                  f"{gradient_ratio(z, out):.3f} | {seam_ratio(out):.3f} | "
                  f"{row_disagreement(z):.3f} / {row_disagreement(out):.3f} | "
                  f"{course_steps(z, period, False):.3f} / {course_steps(out, period):.3f} |",
                  flush=True)
            if args.crops:
                args.crops.mkdir(parents=True, exist_ok=True)
                stem = args.crops / f"{key}_{args.method}_{seed}"
                wrap = np.roll(out, (CROP // 2, CROP // 2), axis=(0, 1))[:CROP, :CROP]
                mid = (args.side - CROP) // 2
                write_image(f"{stem}_wrap.png", wrap)
                write_image(f"{stem}_middle.png", out[mid:mid + CROP, mid:mid + CROP])


if __name__ == "__main__":
    main()

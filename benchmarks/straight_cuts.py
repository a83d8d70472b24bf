"""texture_optimization's straight cuts, a cheap check (not a section): each photo's central
crop synthesized at twice its size, one process, one run each.

    .venv/bin/python -m benchmarks.straight_cuts --size 512 bricks setts gravel

Columns: seconds (and those of the re-cut, ``texsynth.blocks.recut``), gradient ratio, the
row-profile disagreement of photo and output (the share of pixels where the dark rows, under
the photo's 25th luminance percentile as 6-column means, left and right of a column differ),
straight copy boundaries of 64 px or more along one row or column line (all; visible: their
seam error, Kwatra et al. 2003's, above the photo's mean squared neighbour difference; the
longest), and the copies (regions of the position map).
"""

from __future__ import annotations

import argparse
import time

import numpy as np

import texsynth
from texsynth.algorithms import texture_optimization as method
from texsynth.blocks.recut import straight_runs
from texsynth.blocks.region_shift import regions
from texsynth.io import read_photo
from texsynth.metrics import gradient_ratio

from .context import SHARED_TEXTURES

PHOTOS = {"bricks": "ufoai-textures/brick_wall.png",
          "setts": "0ad-data/granite_setts_grass.png",
          "gravel": "torcs-data/gravel_pebbles.png"}
LONG = 64


def crop(key: str, n: int) -> np.ndarray:
    image = read_photo(SHARED_TEXTURES / "large" / PHOTOS[key])[:, :, :3]
    h, w = image.shape[:2]
    top, left = (h - n) // 2, (w - n) // 2
    return np.ascontiguousarray(image[top:top + n, left:left + n], np.float32)


def row_disagreement(image: np.ndarray, gap: int = 6) -> float:
    y = image.mean(axis=2)
    dark = np.percentile(y, 25)
    c = np.cumsum(np.concatenate([np.zeros((y.shape[0], 1)), y, y[:, :gap]], axis=1), axis=1)
    left = (c[:, gap:gap + y.shape[1]] - c[:, :y.shape[1]]) / gap < dark
    return float((left != np.roll(left, -gap, axis=1)).mean())


def straight_cuts(z: np.ndarray, positions: np.ndarray) -> tuple[int, int, int]:
    """(all, visible, longest) straight boundaries of ``LONG`` px or more."""
    base = (((z[:, 1:] - z[:, :-1]) ** 2).sum(axis=2).mean()
            + ((z[1:] - z[:-1]) ** 2).sum(axis=2).mean()) / 2
    count = visible = longest = 0
    for p, e in ((positions, z), (positions.transpose(1, 0, 2)[:, :, ::-1], z.transpose(1, 0, 2))):
        for j, first, last in straight_runs(p, LONG):
            a, b = p[first:last + 1, j], p[first:last + 1, (j + 1) % p.shape[1]]
            ok = (a[:, 1] + 1 < e.shape[1]) & (b[:, 1] >= 1)
            a, b = a[ok], b[ok]
            seam = ((e[a[:, 0], a[:, 1] + 1] - e[b[:, 0], b[:, 1]]) ** 2).sum(axis=1) \
                + ((e[a[:, 0], a[:, 1]] - e[b[:, 0], b[:, 1] - 1]) ** 2).sum(axis=1)
            count += 1
            visible += bool(len(seam)) and seam.mean() / 2 > base
            longest = max(longest, int(last - first + 1))
    return count, visible, longest


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--size", type=int, default=512, help="crop side; the output is twice")
    parser.add_argument("photos", nargs="+", choices=sorted(PHOTOS))
    args = parser.parse_args()
    spent = [0.0]
    recut = method.recut_straight

    def timed(*a, **k):
        start = time.perf_counter()
        try:
            return recut(*a, **k)
        finally:
            spent[0] += time.perf_counter() - start

    method.recut_straight = timed
    print("| photo | size | s | re-cut s | gradient | rows photo / out | straight >= 64: all / "
          "visible / longest | copies |")
    print("|---|---|---|---|---|---|---|---|")
    for key in args.photos:
        z, n = crop(key, args.size), args.size
        spent[0] = 0.0
        start = time.perf_counter()
        out, pos = texsynth.synthesize_positions(z, 2 * n, 2 * n,
                                                 method="texture_optimization", seed=0)
        seconds = time.perf_counter() - start
        print(f"| {key} | {n} -> {2 * n} | {seconds:.1f} | {spent[0]:.1f} | "
              f"{gradient_ratio(z, out):.3f} | {row_disagreement(z):.3f} / "
              f"{row_disagreement(out):.3f} | {' / '.join(map(str, straight_cuts(z, pos)))} | "
              f"{regions(pos)[0]} |", flush=True)


if __name__ == "__main__":
    main()

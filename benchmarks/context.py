"""What every benchmark section gets: the textures, timing with peak memory, quality, pictures."""

from __future__ import annotations

import csv
import statistics
import time
import tracemalloc
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from texsynth import metrics
from texsynth.io import read_image, write_png

REPO = Path(__file__).resolve().parent.parent
SHARED_TEXTURES = REPO.parent / "shared" / "textures"
SAMPLE = REPO / "samples" / "pool_water.png"
QUICK_TEXTURES = ("trigger-rally/pool_water.png", "extremetuxracer/pebbles01.png",
                  "gimp-data/bark.png")
CELL = 128  # contact-sheet cell side, pixels


@dataclass(frozen=True)
class Texture:
    name: str  # path below shared/textures, e.g. "gimp-data/bark.png"
    image: np.ndarray  # float32 (H, W, 3), sRGB-encoded values in [0, 1]
    category: str
    license: str

    @property
    def short(self) -> str:
        return Path(self.name).stem


@dataclass(frozen=True)
class Measurement:
    median_s: float
    min_s: float
    max_s: float
    peak_mib: float  # largest tracemalloc peak over the repeats (numpy buffers included)
    result: object


def _rgb(image: np.ndarray) -> np.ndarray:
    image = image[:, :, :3]
    return np.repeat(image, 3, axis=2) if image.shape[2] == 1 else np.ascontiguousarray(image)


def load_textures(quick: bool) -> list[Texture]:
    """Every texture of shared/textures (MANIFEST order), or the bundled sample without it."""
    manifest = SHARED_TEXTURES / "MANIFEST.tsv"
    if not manifest.exists():
        return [Texture("samples/pool_water.png", _rgb(read_image(SAMPLE)), "stochastic",
                        "CC0")]
    with manifest.open() as f:
        rows = list(csv.DictReader(f, delimiter="\t"))
    if quick:
        rows = [r for r in rows if r["file"] in QUICK_TEXTURES]
    return [Texture(r["file"], _rgb(read_image(SHARED_TEXTURES / r["file"])), r["category"],
                    r["license"]) for r in rows]


def _fit_cell(image: np.ndarray, side: int) -> np.ndarray:
    """Downscale by an integer block mean to fit ``side``, then pad with mid-grey to a square."""
    image = _rgb(np.atleast_3d(np.asarray(image, np.float32)))
    factor = max(1, int(np.ceil(max(image.shape[:2]) / side)))
    if factor > 1:
        h, w = (image.shape[0] // factor) * factor, (image.shape[1] // factor) * factor
        image = image[:h, :w].reshape(h // factor, factor, w // factor, factor, 3).mean(axis=(1, 3))
    cell = np.full((side, side, 3), 0.5, np.float32)
    cell[: image.shape[0], : image.shape[1]] = image[:side, :side]
    return cell


class Context:
    """Shared by the sections of one run."""

    def __init__(self, quick: bool, img_dir: Path):
        self.quick = quick
        self.img_dir = img_dir
        self.textures = load_textures(quick)

    def save_png(self, rel_name: str, image: np.ndarray) -> str:
        path = self.img_dir / rel_name
        path.parent.mkdir(parents=True, exist_ok=True)
        write_png(path, np.clip(image, 0.0, 1.0))
        return f"img/{rel_name}"

    def contact_sheet(self, rel_name: str, columns: list[str], rows: list[list[np.ndarray]],
                      cell: int = CELL) -> str:
        """A grid of images, one column per name in ``columns`` (the caption names them)."""
        gap = 4
        sheet = np.ones((len(rows) * (cell + gap) - gap, len(columns) * (cell + gap) - gap, 3),
                        np.float32)
        for r, row in enumerate(rows):
            for c, image in enumerate(row):
                if image is not None:
                    y, x = r * (cell + gap), c * (cell + gap)
                    sheet[y:y + cell, x:x + cell] = _fit_cell(image, cell)
        return self.save_png(rel_name, sheet)

    @staticmethod
    def measure(fn: Callable[[], object], repeats: int = 3) -> Measurement:
        """Median and range of wall time over ``repeats`` calls, and the peak traced memory."""
        times, peaks, result = [], [], None
        tracemalloc.start()
        try:
            for _ in range(repeats):
                tracemalloc.reset_peak()
                start = time.perf_counter()
                result = fn()
                times.append(time.perf_counter() - start)
                peaks.append(tracemalloc.get_traced_memory()[1])
        finally:
            tracemalloc.stop()
        return Measurement(statistics.median(times), min(times), max(times),
                           max(peaks) / 2**20, result)

    @staticmethod
    def quality(exemplar: np.ndarray, output: np.ndarray) -> dict:
        return metrics.quality(exemplar, output)

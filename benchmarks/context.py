"""What every benchmark section gets: the textures, timing with peak memory, quality, pictures.

Memory is measured two ways in every :meth:`Context.measure`: tracemalloc's peak (Python objects
and numpy buffers, exact, blind to C libraries' own malloc) and the growth of the process's
resident high-water mark (``VmHWM``, reset through ``/proc/self/clear_refs``), which also sees C
code such as Resynthesizer's engine; a subprocess started with :func:`run_child` adds its own
peak RSS. glibc's mmap threshold is pinned so freed large buffers leave the heap at once and the
high-water mark of one call is not hidden by memory a previous call left behind.
"""

from __future__ import annotations

import contextlib
import csv
import ctypes
import os
import re
import statistics
import subprocess
import time
import tracemalloc
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from texsynth import metrics
from texsynth.io import read_photo, write_png

REPO = Path(__file__).resolve().parent.parent
#: ../shared/textures beside the repository; ``TEXSYNTH_SHARED_TEXTURES`` names another place (a
#: worktree one level deeper).
SHARED_TEXTURES = Path(os.environ.get("TEXSYNTH_SHARED_TEXTURES")
                       or REPO.parent / "shared" / "textures")
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
    rss_mib: float = float("nan")  # largest resident-memory growth (C code, subprocesses too)


_HWM = Path("/proc/self/status")
_child_peak_kib = 0


def fmt(x, digits=3) -> str:
    """A figure for a table: ``n/a`` for None or NaN."""
    return "n/a" if x is None or x != x else f"{x:.{digits}f}"


def timed(fn):
    """(seconds, result) of ``fn()``: bare wall time (no tracemalloc, which slows numpy code but
    not the peers' C)."""
    start = time.perf_counter()
    result = fn()
    return time.perf_counter() - start, result


def _pin_mmap_threshold() -> None:
    with contextlib.suppress(OSError, AttributeError):
        libc = ctypes.CDLL("libc.so.6")
        libc.mallopt(-3, 1 << 20)  # M_MMAP_THRESHOLD = 1 MiB, which also stops its adaptation


def status_kib(field: str) -> int:
    try:
        return int(re.search(rf"{field}:\s+(\d+)", _HWM.read_text()).group(1))
    except (OSError, AttributeError):
        return 0


def reset_high_water() -> bool:
    try:
        Path("/proc/self/clear_refs").write_text("5")
        return True
    except OSError:
        return False


def run_child(args: list[str], env: dict | None = None) -> None:
    """Run a subprocess to completion (raising on failure), recording its peak RSS.

    ``env`` entries are added to this process's environment.
    """
    global _child_peak_kib
    proc = subprocess.Popen(args, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
                            env={**os.environ, **(env or {})})
    stderr = proc.stderr.read()
    _, status, usage = os.wait4(proc.pid, 0)
    proc.returncode = os.waitstatus_to_exitcode(status)
    _child_peak_kib = max(_child_peak_kib, usage.ru_maxrss)
    if proc.returncode:
        raise subprocess.CalledProcessError(proc.returncode, args, stderr=stderr)


def _rgb(image: np.ndarray) -> np.ndarray:
    image = image[:, :, :3]
    return np.repeat(image, 3, axis=2) if image.shape[2] == 1 else np.ascontiguousarray(image)


def load_textures(quick: bool) -> list[Texture]:
    """Every texture of shared/textures (MANIFEST order), or the bundled sample without it."""
    manifest = SHARED_TEXTURES / "MANIFEST.tsv"
    if not manifest.exists():
        return [Texture("samples/pool_water.png", _rgb(read_photo(SAMPLE)), "stochastic",
                        "CC0")]
    with manifest.open() as f:
        rows = list(csv.DictReader(f, delimiter="\t"))
    if quick:
        rows = [r for r in rows if r["file"] in QUICK_TEXTURES]
    return [Texture(r["file"], _rgb(read_photo(SHARED_TEXTURES / r["file"])), r["category"],
                    r["license"]) for r in rows]


def _fit_cell(image: np.ndarray, side: int) -> np.ndarray:
    """Downscale (block mean, then bilinear) to fit ``side``; pad with mid-grey to a square."""
    from scipy.ndimage import zoom

    image = _rgb(np.atleast_3d(np.asarray(image, np.float32)))
    factor = int(max(image.shape[:2]) // side)
    if factor > 1:
        h, w = (image.shape[0] // factor) * factor, (image.shape[1] // factor) * factor
        image = image[:h, :w].reshape(h // factor, factor, w // factor, factor, 3).mean(axis=(1, 3))
    if max(image.shape[:2]) > side:
        scale = side / max(image.shape[:2])
        image = zoom(image, (scale, scale, 1), order=1, grid_mode=True, mode="nearest")
    cell = np.full((side, side, 3), 0.5, np.float32)
    cell[: image.shape[0], : image.shape[1]] = image[:side, :side]
    return cell


class Context:
    """Shared by the sections of one run."""

    def __init__(self, quick: bool, img_dir: Path):
        _pin_mmap_threshold()
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
        return self.save_jpeg(rel_name, sheet)

    def save_jpeg(self, rel_name: str, image: np.ndarray) -> str:
        """Pictures for the docs as JPEG (quality 85): a quarter of the PNG's size, seams still
        visible; the name's suffix becomes ``.jpg``."""
        from PIL import Image

        path = (self.img_dir / rel_name).with_suffix(".jpg")
        path.parent.mkdir(parents=True, exist_ok=True)
        pixels = np.rint(np.clip(_rgb(np.atleast_3d(image)), 0.0, 1.0) * 255).astype(np.uint8)
        Image.fromarray(pixels).save(path, quality=85, optimize=True)
        return f"img/{path.relative_to(self.img_dir)}"

    @staticmethod
    def measure(fn: Callable[[], object], repeats: int = 3) -> Measurement:
        """Median and range of wall time over ``repeats`` calls, and the peak memory.

        Timing runs under tracemalloc (about 10 % slower for numpy code, nothing for C code):
        compare times of in-process Python methods with each other, not with bare C timings.
        """
        global _child_peak_kib
        times, peaks, rss, result = [], [], [], None
        tracemalloc.start()
        try:
            for _ in range(repeats):
                result = None
                _child_peak_kib = 0
                hwm = reset_high_water()
                base = status_kib("VmRSS")
                tracemalloc.reset_peak()
                start = time.perf_counter()
                result = fn()
                times.append(time.perf_counter() - start)
                peaks.append(tracemalloc.get_traced_memory()[1])
                grown = status_kib("VmHWM") - base if hwm else float("nan")
                rss.append(max(grown, _child_peak_kib) / 1024)
        finally:
            tracemalloc.stop()
        return Measurement(statistics.median(times), min(times), max(times),
                           max(peaks) / 2**20, result, max(rss))

    @staticmethod
    def quality(exemplar: np.ndarray, output: np.ndarray) -> dict:
        return metrics.quality(exemplar, output)

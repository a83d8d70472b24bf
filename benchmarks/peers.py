"""The tools a user would pick instead, run on the same inputs, sizes and seed.

- ``textbook_hb``: Heeger-Bergen as the textbook builds it (paper 000, Alg. 11.3-11.4) on
  pyrtools' SteerablePyramidFreq, with sort-based histogram matching (both arrays sorted at every
  match), PCA colour and uniform noise: the reference for texsynth's speed-ups;
- ``resynthesizer``: the engine behind GIMP's and Blender's healing / texture tools (PyPI
  ``resynthesizer``), tiling flags on, the exemplar in the corner of a masked canvas;
- ``gmic_random_phase`` / ``gmic_matchpatch``: G'MIC's ``syntexturize`` (random-phase noise) and
  ``syntexturize_matchpatch`` (patch-match), by subprocess: their time includes G'MIC's start and
  the PNG files, and their memory is not traced (``in_process`` is False).

A peer that cannot be installed or run is reported as skipped with the reason.
"""

from __future__ import annotations

import shutil
import subprocess
import tempfile
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from texsynth.color import ColorPCA
from texsynth.io import read_image, write_png


@dataclass(frozen=True)
class Peer:
    name: str
    label: str
    run: Callable[[np.ndarray, int, int, int], np.ndarray]
    missing: str | None  # why it cannot run, or None
    in_process: bool = True


def _sort_match(source: np.ndarray, target: np.ndarray) -> np.ndarray:
    """Algorithm 11.3 by sorting: the k-th smallest source value gets the k-th target quantile."""
    order = np.argsort(source, axis=None)
    values = np.sort(target, axis=None)
    out = np.empty(source.size, np.float64)
    out[order] = np.interp(np.linspace(0, 1, source.size), np.linspace(0, 1, values.size), values)
    return out.reshape(source.shape)


def textbook_hb(exemplar, width, height, seed, scales=4, orientations=4, iterations=15):
    import pyrtools as pt

    pca = ColorPCA.fit(exemplar)
    components = pca.forward(exemplar).astype(np.float64)
    noise = np.random.default_rng(seed).random((height, width, exemplar.shape[2]))
    out = np.empty_like(noise)
    for c in range(exemplar.shape[2]):
        target = components[:, :, c]
        target_bands = pt.pyramids.SteerablePyramidFreq(target, scales, orientations - 1).pyr_coeffs
        image = _sort_match(noise[:, :, c], target)
        for _ in range(iterations):
            pyr = pt.pyramids.SteerablePyramidFreq(image, scales, orientations - 1)
            for key, band in pyr.pyr_coeffs.items():
                pyr.pyr_coeffs[key] = _sort_match(band, target_bands[key])
            image = _sort_match(pyr.recon_pyr(), target)
        out[:, :, c] = image
    result = pca.inverse(out.astype(np.float32))
    return np.clip(result, exemplar.min(axis=(0, 1)), exemplar.max(axis=(0, 1)))


def resynthesizer(exemplar, width, height, seed):
    import resynthesizer as rs
    from PIL import Image

    h, w = exemplar.shape[:2]
    if h > height or w > width:
        raise ValueError("Resynthesizer needs the exemplar to fit in the output canvas")
    canvas = np.zeros((height, width, 3), np.uint8)
    canvas[:h, :w] = np.rint(np.clip(exemplar[:, :, :3], 0, 1) * 255)
    mask = np.full((height, width), 255, np.uint8)
    mask[:h, :w] = 0
    params = rs.getDefaultParams()  # tileable horizontally and vertically
    out = rs.resynthesize(Image.fromarray(canvas), Image.fromarray(mask), params)
    return np.asarray(out, dtype=np.float32) / 255.0


def _gmic(command: str) -> Callable:
    def run(exemplar, width, height, seed):
        with tempfile.TemporaryDirectory() as tmp:
            src, dst = Path(tmp) / "in.png", Path(tmp) / "out.png"
            write_png(src, np.clip(exemplar, 0, 1))
            subprocess.run(["gmic", "-srand", str(seed), "-input", str(src),
                            f"-{command}", f"{width},{height}", "-output", str(dst)],
                           check=True, capture_output=True)
            return read_image(dst)[:, :, :3]
    return run


def _missing_module(name: str) -> str | None:
    try:
        __import__(name)
    except ImportError as error:
        return f"{name} not importable ({error}); pip install -r benchmarks/requirements.txt"
    return None


def peers() -> list[Peer]:
    gmic = None if shutil.which("gmic") else "gmic not on PATH (Debian package gmic)"
    return [
        Peer("textbook_hb", "Heeger-Bergen, textbook (pyrtools + sort)", textbook_hb,
             _missing_module("pyrtools")),
        Peer("resynthesizer", "Resynthesizer engine", resynthesizer,
             _missing_module("resynthesizer") or _missing_module("PIL")),
        Peer("gmic_random_phase", "G'MIC syntexturize (random phase)",
             _gmic("syntexturize"), gmic, in_process=False),
        Peer("gmic_matchpatch", "G'MIC syntexturize_matchpatch", _gmic("syntexturize_matchpatch"),
             gmic, in_process=False),
    ]

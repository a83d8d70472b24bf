"""The tools a user would pick instead, run on the same inputs, sizes and seed.

- ``textbook_hb``: Heeger-Bergen as the textbook builds it on pyrtools (textbook_hb.py);
- ``resynthesizer``: Resynthesizer's engine, tiling flags on (resynth.py);
- ``gmic_random_phase`` / ``gmic_matchpatch``: G'MIC's ``syntexturize`` and
  ``syntexturize_matchpatch`` by subprocess (gmic.py).

Not run (optional in issue 3, off by default): GIMP's texturize plug-in (needs GIMP and a
Script-Fu batch) and plenoptic's Portilla-Simoncelli (needs torch).

A peer that cannot be installed or run is reported as skipped with the reason. Each peer is
``run(exemplar float32 (H, W, 3) in [0, 1], width, height, seed) -> float32 (height, width, 3)``.
"""

from __future__ import annotations

import shutil
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from .gmic import gmic
from .resynth import resynthesizer
from .textbook_hb import textbook_hb

__all__ = ["Peer", "peers", "textbook_hb", "resynthesizer", "gmic"]


@dataclass(frozen=True)
class Peer:
    name: str
    label: str
    run: Callable[[np.ndarray, int, int, int], np.ndarray]
    missing: str | None  # why it cannot run, or None
    in_process: bool = True  # False: a subprocess, its memory is the child's peak RSS


def _missing_module(name: str) -> str | None:
    try:
        __import__(name)
    except ImportError as error:
        return f"{name} not importable ({error}); pip install -r benchmarks/requirements.txt"
    return None


def peers() -> list[Peer]:
    no_gmic = None if shutil.which("gmic") else "gmic not on PATH (Debian package gmic)"
    return [
        Peer("textbook_hb", "Heeger-Bergen, textbook (pyrtools + sort)", textbook_hb,
             _missing_module("pyrtools")),
        Peer("resynthesizer", "Resynthesizer engine", resynthesizer,
             _missing_module("resynthesizer") or _missing_module("PIL")),
        Peer("gmic_random_phase", "G'MIC syntexturize (random phase)", gmic("syntexturize"),
             no_gmic, in_process=False),
        Peer("gmic_matchpatch", "G'MIC syntexturize_matchpatch", gmic("syntexturize_matchpatch"),
             no_gmic, in_process=False),
    ]

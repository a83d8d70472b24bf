"""G'MIC's texture re-synthesis commands, from Debian's ``gmic`` command-line interpreter.

``syntexturize`` is random-phase noise (Galerne, Gousseau, Morel 2011); ``syntexturize_matchpatch``
is a multi-scale patch-match re-synthesis. Both run as a subprocess on a PNG of the exemplar, so
their time includes G'MIC's start-up and the PNG files, and their memory is the child's peak RSS.
G'MIC runs on one thread (``OMP_NUM_THREADS=1``), as texsynth's methods do: on a shared machine its
OpenMP threads otherwise spin-wait for seconds, and only then does ``-srand`` make
``syntexturize_matchpatch`` repeatable.
"""

from __future__ import annotations

import tempfile
from collections.abc import Callable
from pathlib import Path

import numpy as np

from texsynth.io import read_photo, write_png

from ..context import run_child


def gmic(command: str) -> Callable:
    """A peer function ``(exemplar, width, height, seed)`` running ``command`` in G'MIC."""
    def run(exemplar, width, height, seed):
        with tempfile.TemporaryDirectory() as tmp:
            src, dst = Path(tmp) / "in.png", Path(tmp) / "out.png"
            write_png(src, np.clip(exemplar, 0, 1))
            run_child(["gmic", "-srand", str(seed), "-input", str(src),
                       f"-{command}", f"{width},{height}", "-output", str(dst)],
                      env={"OMP_NUM_THREADS": "1"})
            return read_photo(dst)[:, :, :3]
    return run

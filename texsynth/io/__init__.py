"""Image files for the core and for scripts: OpenEXR (exact float32) and PNG (8/16-bit).

Arrays are float32 (H, W, C), top row first, C in 1, 3, 4. EXR holds linear values as they are
(:mod:`texsynth.io.exr`); PNG holds encoded values in [0, 1] (sRGB for colour images), quantized
to 8 or 16 bits (:mod:`texsynth.io.png`). The sRGB transfer lives with the other colour maths in
:mod:`texsynth.blocks.color`.
"""

from __future__ import annotations

import numpy as np

from .exr import read_exr, write_exr
from .files import read_photo, write_image
from .png import SIGNATURE as _PNG_SIGNATURE
from .png import read_png, write_png

__all__ = ["read_image", "read_exr", "write_exr", "read_png", "write_png", "read_photo",
           "write_image"]

_EXR_MAGIC = b"\x76\x2f\x31\x01"


def read_image(path) -> np.ndarray:
    """Read a PNG or OpenEXR file (told apart by content) as float32 (H, W, C)."""
    with open(path, "rb") as f:
        head = f.read(8)
    if head == _PNG_SIGNATURE:
        return read_png(path)
    if head[:4] == _EXR_MAGIC:
        return read_exr(path)
    raise ValueError(f"{path}: not a PNG or OpenEXR file")

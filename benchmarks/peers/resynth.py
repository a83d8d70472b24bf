"""Resynthesizer's engine (PyPI ``resynthesizer``: ctypes around the pure-C port of Paul Harrison's
Resynthesizer, the engine of GIMP's heal-selection and render-texture plug-ins).

The engine fills the masked part of one image from its unmasked part. As texture synthesis: the
exemplar sits in the top-left corner of a canvas of the output size, the rest of the canvas is
masked, and the tiling flags make the fill wrap around the canvas edges, so the whole canvas
(exemplar included, verbatim) tiles. Defaults otherwise (patch size 30, 200 probes). The engine has
no seed parameter; its internal random generator is fixed, so runs repeat.
"""

from __future__ import annotations

import numpy as np


def resynthesizer(exemplar, width, height, seed):
    import resynthesizer as rs
    from PIL import Image

    h, w = exemplar.shape[:2]
    if h >= height or w >= width:
        raise ValueError(f"Resynthesizer needs a canvas larger than the {w} x {h} exemplar")
    canvas = np.zeros((height, width, 3), np.uint8)
    canvas[:h, :w] = np.rint(np.clip(exemplar[:, :, :3], 0, 1) * 255)
    mask = np.full((height, width), 255, np.uint8)
    mask[:h, :w] = 0
    params = rs.getDefaultParams()
    params.isMakeSeamlesslyTileableHorizontally = 1
    params.isMakeSeamlesslyTileableVertically = 1
    out = rs.resynthesize(Image.fromarray(canvas), Image.fromarray(mask), params)
    return np.asarray(out, dtype=np.float32) / 255.0

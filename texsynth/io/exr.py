"""OpenEXR files through the OpenEXR package: float32 channels, bit-exact both ways."""

from __future__ import annotations

import numpy as np

from ..validation import image

__all__ = ["read_exr", "write_exr"]

_LAYOUTS = ("RGBA", "RGB", "YA", "Y")


def write_exr(path, array) -> None:
    """Write float32 channels (Y, RGB or RGBA), ZIP-compressed; reading back gives the same bits."""
    import OpenEXR  # a bundled wheel, loaded when an EXR is first touched

    a = image(array, what="image", min_side=1, finite=False)
    names = {1: "Y", 3: "RGB", 4: "RGBA"}[a.shape[2]]
    channels = {name: np.ascontiguousarray(a[:, :, i]) for i, name in enumerate(names)}
    header = {"compression": OpenEXR.ZIP_COMPRESSION, "type": OpenEXR.scanlineimage}
    with OpenEXR.File(header, channels) as f:
        f.write(str(path))


def read_exr(path) -> np.ndarray:
    """Read R, G, B (and A), or Y (and A), as float32; grey with alpha becomes RGBA."""
    import OpenEXR

    with OpenEXR.File(str(path), separate_channels=True) as f:
        channels = {name: c.pixels for name, c in f.channels().items()}
    for layout in _LAYOUTS:
        if set(layout) <= set(channels):
            planes = [channels[name] for name in layout]
            if layout == "YA":
                planes = [planes[0]] * 3 + [planes[1]]
            return np.stack(planes, axis=2).astype(np.float32)
    raise ValueError(f"{path}: no R, G, B or Y channels (found {', '.join(sorted(channels))})")

"""OpenEXR files through the OpenEXR package: float32 channels, bit-exact both ways."""

from __future__ import annotations

import contextlib
import os
import sys

import numpy as np

from ..validation import image

__all__ = ["read_exr", "write_exr", "exr_size"]

_LAYOUTS = ("RGBA", "RGB", "YA", "Y")


def write_exr(path, array) -> None:
    """Write float32 channels (Y, RGB or RGBA), ZIP-compressed; reading back gives the same bits.

    ``OSError`` naming the file when OpenEXR cannot write it (a missing folder, a full disk)."""
    import OpenEXR  # a bundled wheel, loaded when an EXR is first touched

    a = image(array, what="image", min_side=1, finite=False)
    names = {1: "Y", 3: "RGB", 4: "RGBA"}[a.shape[2]]
    channels = {name: np.ascontiguousarray(a[:, :, i]) for i, name in enumerate(names)}
    header = {"compression": OpenEXR.ZIP_COMPRESSION, "type": OpenEXR.scanlineimage}
    try:
        with OpenEXR.File(header, channels) as f:
            f.write(str(path))
    except RuntimeError as error:  # OpenEXR's C++ exceptions, an I/O failure among them
        raise OSError(f"{path}: OpenEXR could not write the file ({error})") from None


def read_exr(path) -> np.ndarray:
    """Read R, G, B (and A), or Y (and A), as float32; grey with alpha becomes RGBA.

    ``ValueError`` naming the file when OpenEXR cannot read it (damaged, cut short)."""
    import OpenEXR

    try:
        with _library_quiet(), OpenEXR.File(str(path), separate_channels=True) as f:
            channels = {name: c.pixels for name, c in f.channels().items()}
    except (RuntimeError, ValueError, OSError) as error:
        raise ValueError(f"{path}: not a readable OpenEXR file ({error})") from None
    layout = _layout(path, channels)
    planes = [channels[name] for name in layout]
    if layout == "YA":
        planes = [planes[0]] * 3 + [planes[1]]
    return np.stack(planes, axis=2).astype(np.float32)


def exr_size(path) -> tuple[int, int, int]:
    """(width, height, channels as :func:`read_exr` gives them) from the header alone."""
    import OpenEXR

    try:
        with _library_quiet(), OpenEXR.File(str(path), header_only=True) as f:  # f holds header
            low, high = (np.asarray(v) for v in f.header()["dataWindow"])
            names = [c.name for c in f.header()["channels"]]
    except (RuntimeError, ValueError, OSError, KeyError) as error:
        raise ValueError(f"{path}: not a readable OpenEXR file ({error})") from None
    layout = _layout(path, names)
    return int(high[0] - low[0] + 1), int(high[1] - low[1] + 1), {"Y": 1, "RGB": 3}.get(layout, 4)


@contextlib.contextmanager
def _library_quiet():
    """The library's own lines on a damaged file ("Invalid chunk size ..." three times on
    stderr, "Warning: Exception raised reading pixel data" on stdout) silenced: the error raised
    names the file and says it once. Process-wide while it lasts (file descriptors 1 and 2),
    so held only around the library's read."""
    sys.stdout.flush()
    sys.stderr.flush()
    with contextlib.ExitStack() as restore, open(os.devnull, "wb") as null:
        for fd in (1, 2):
            try:
                saved = os.dup(fd)
            except OSError:  # no such stream to silence
                continue
            os.dup2(null.fileno(), fd)
            restore.callback(os.close, saved)
            restore.callback(os.dup2, saved, fd)
        yield


def _layout(path, channels) -> str:
    """The first of RGBA, RGB, YA, Y whose channels the file holds."""
    for layout in _LAYOUTS:
        if set(layout) <= set(channels):
            return layout
    raise ValueError(f"{path}: no R, G, B or Y channels (found {', '.join(sorted(channels))})")

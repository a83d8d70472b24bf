"""Image files as a command line or a pipeline meets them: any photo in, the format by suffix out.

- :func:`read_photo` reads PNG and OpenEXR with the project's own codecs, and JPEG, TIFF, WebP
  and the rest through Pillow when it is installed (never a requirement of the core);
- :func:`write_image` writes PNG (8 or 16 bits) or OpenEXR (float32) as the path's suffix says,
  atomically: the bytes go to a temporary file in the same folder, renamed over the target
  only when complete (``os.replace``), so a reader never sees a partial file and a killed
  writer leaves the old file (or none) and a temporary file named ``.texsynth-tmp-*``
  (:data:`TEMP_PREFIX`);
- :func:`encode` moves colour between the encodings: PNG (and JPEG...) hold sRGB-encoded values,
  OpenEXR linear ones (as Blender reads them).
"""

from __future__ import annotations

import os
import tempfile
from pathlib import Path

import numpy as np

from ..blocks.color import linear_to_srgb, srgb_to_linear
from . import exr, png

__all__ = ["read_photo", "write_image", "png_bits", "is_linear", "encode", "TEMP_PREFIX",
           "SUFFIXES"]

#: Temporary files of :func:`write_image` start with this (a batch removes stale ones).
TEMP_PREFIX = ".texsynth-tmp-"
#: Output suffixes and their formats.
SUFFIXES = {".png": "png", ".exr": "exr"}
_EXR_MAGIC = b"\x76\x2f\x31\x01"
_UMASK = os.umask(0o022)  # read once, at import (os.umask can only be read by setting it)
os.umask(_UMASK)


def read_photo(path) -> np.ndarray:
    """An image file as float32 (H, W, C) in its file's encoding (:func:`is_linear` says which).

    PNG and OpenEXR are read by ``texsynth.io``; other formats (JPEG, TIFF, WebP, ...) need
    Pillow. Raises ``FileNotFoundError`` for a missing file and ``ValueError`` naming the file
    when it cannot be read as an image.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> path = pathlib.Path(tempfile.mkdtemp()) / "a.png"
    >>> write_image(path, np.zeros((4, 6, 3), np.float32))
    >>> read_photo(path).shape
    (4, 6, 3)
    """
    path = Path(path)
    if not path.is_file():
        raise FileNotFoundError(f"{path}: no such file")
    with open(path, "rb") as f:
        head = f.read(8)
    if head == png.SIGNATURE:
        return png.read_png(path)
    if head[:4] == _EXR_MAGIC:
        return exr.read_exr(path)
    try:
        from PIL import Image, UnidentifiedImageError
    except ImportError:
        raise ValueError(f"{path}: not a PNG or OpenEXR file (install Pillow to read JPEG, "
                         "TIFF and WebP photos)") from None
    try:
        with Image.open(path) as im:
            im.load()
            return _from_pillow(im)
    except (UnidentifiedImageError, OSError) as error:
        raise ValueError(f"{path}: not an image file Pillow can read ({error})") from None


def _from_pillow(im) -> np.ndarray:
    """A Pillow image as float32 (H, W, C) in [0, 1]: 16-bit grey kept, the rest as 8-bit."""
    if im.mode in ("I;16", "I;16B", "I;16L", "I"):
        a = np.asarray(im, np.float32) / np.float32(65535)
        return np.clip(a, 0, 1)[:, :, None]
    mode = {"L": "L", "LA": "RGBA", "RGB": "RGB", "RGBA": "RGBA"}.get(im.mode)
    mode = mode or ("RGBA" if "A" in im.getbands() else "RGB")
    a = np.asarray(im.convert(mode), np.float32) / np.float32(255)
    return a if a.ndim == 3 else a[:, :, None]


def is_linear(path) -> bool:
    """True for OpenEXR (linear values), False for the sRGB-encoded formats."""
    return Path(path).suffix.lower() == ".exr"


def png_bits(path) -> int:
    """The bit depth of a PNG file's samples (8 or 16); 16 for any other file (float or
    unknown: a PNG written from it keeps its precision)."""
    with open(path, "rb") as f:
        head = f.read(25)
    if head[:8] == png.SIGNATURE and len(head) == 25:
        return 16 if head[24] == 16 else 8
    return 8 if Path(path).suffix.lower() in (".jpg", ".jpeg", ".webp") else 16


def encode(image: np.ndarray, from_linear: bool, to_linear: bool) -> np.ndarray:
    """Colour moved from one encoding to the other (sRGB <-> linear); alpha stays as it is.

    Examples
    --------
    >>> a = np.full((1, 1, 4), 0.5, np.float32)
    >>> [round(float(v), 3) for v in encode(a, from_linear=False, to_linear=True).ravel()]
    [0.214, 0.214, 0.214, 0.5]
    """
    if from_linear == to_linear:
        return image
    out = image.copy()
    colour = slice(0, 3) if image.shape[2] >= 3 else slice(0, 1)
    convert = linear_to_srgb if from_linear else srgb_to_linear
    out[:, :, colour] = convert(image[:, :, colour])
    return out


def write_image(path, image, bits: int = 8) -> None:
    """Write ``image`` to ``path`` atomically, PNG (``bits`` 8 or 16) or OpenEXR by its suffix.

    Raises ``ValueError`` naming the path for another suffix (nothing is written) and
    ``OSError`` when the folder cannot be written.
    """
    path = Path(path)
    kind = SUFFIXES.get(path.suffix.lower())
    if kind is None:
        raise ValueError(f"{path}: the output's suffix must be one of "
                         f"{', '.join(SUFFIXES)} (PNG 8/16-bit or OpenEXR float)")
    if bits not in (8, 16):
        raise ValueError(f"PNG bit depth must be 8 or 16, got {bits}")
    fd, temp = tempfile.mkstemp(prefix=TEMP_PREFIX + path.stem + "-", suffix=path.suffix,
                                dir=path.parent)
    os.close(fd)
    try:
        if kind == "png":
            png.write_png(temp, image, bits=bits)
        else:
            exr.write_exr(temp, image)
        os.chmod(temp, 0o666 & ~_UMASK)  # mkstemp makes 0600; a plain open() would not
        os.replace(temp, path)
    except BaseException:
        Path(temp).unlink(missing_ok=True)
        raise

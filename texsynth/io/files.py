"""Image files as a command line or a pipeline meets them: any photo in, the format by suffix out.

- :func:`read_photo` is the one reader: PNG, OpenEXR and 8/16-bit TIFF with the project's own
  codecs, JPEG, WebP and the other TIFFs through Pillow; the photo comes out upright (its EXIF
  ``Orientation`` applied, :mod:`texsynth.io.orientation`). It raises ``FileNotFoundError`` for a
  missing file and :class:`ImageReadError` (a ``ValueError``) naming the file for everything
  else: a folder, an unreadable, empty or damaged file, another format, NaN or infinite values;
- :func:`image_size` reads the same answer's size from the headers alone, before any work;
- :func:`write_image` writes PNG (8 or 16 bits), OpenEXR (float32), JPEG (8 bits, quality 95)
  or TIFF (8 or 16 bits) as the path's suffix says (:func:`output_format` checks one first),
  atomically: the bytes go to a temporary file in the same folder, renamed over the target
  only when complete (``os.replace``), so a reader never sees a partial file, a failed write
  (a full disk) leaves the old file (or none) and no temporary file, and only a killed writer
  leaves a temporary file named ``.texsynth-tmp-*`` (:data:`TEMP_PREFIX`);
- :func:`encode` moves colour between the encodings: PNG, JPEG and TIFF hold sRGB-encoded
  values, OpenEXR linear ones (as Blender reads them).
"""

from __future__ import annotations

import os
import tempfile
from pathlib import Path

import numpy as np

from .. import validation
from ..blocks.color import linear_to_srgb, srgb_to_linear
from . import exr, png, tiff
from .orientation import TURNED, exif_orientation, orient

__all__ = ["read_photo", "image_size", "check_finite", "ImageReadError", "ImageWriteError",
           "write_image", "write_images", "output_format", "png_bits", "is_linear", "encode",
           "TEMP_PREFIX", "SUFFIXES", "temp_prefix"]

#: Temporary files of :func:`write_image` start with this (a batch removes stale ones).
TEMP_PREFIX = ".texsynth-tmp-"
#: Output suffixes and their formats.
SUFFIXES = {".png": "png", ".exr": "exr", ".jpg": "jpeg", ".jpeg": "jpeg", ".tif": "tiff",
            ".tiff": "tiff"}
_MAGIC = {b"\x89PNG\r\n\x1a\n": "png", b"\x76\x2f\x31\x01": "exr", b"II*\x00": "tiff",
          b"MM\x00*": "tiff"}
_UMASK = os.umask(0o022)  # read once, at import (os.umask can only be read by setting it)
os.umask(_UMASK)


class ImageReadError(ValueError):
    """A file that is there but cannot be read as an image; the message names the file.

    A folder, a file without read permission, an empty or damaged file, a format nothing here
    reads, NaN or infinite values. A ``ValueError``, so a caller that knows only that still
    reports it; a command maps it to its exit code without matching messages.
    """


class ImageWriteError(OSError):
    """A file of :func:`write_images` that could not be written; the message names the file
    and why (an ``OSError``, as the failures it stands for)."""


def read_photo(path) -> np.ndarray:
    """An image file as float32 (H, W, C), C in 1, 3, 4, upright, in its file's encoding
    (:func:`is_linear` says which); the format told by content, not by suffix.

    Raises ``FileNotFoundError`` for a missing file and :class:`ImageReadError` naming the
    file when it is not an image this reads (see the module notes).

    Examples
    --------
    >>> import tempfile, pathlib
    >>> path = pathlib.Path(tempfile.mkdtemp()) / "a.png"
    >>> write_image(path, np.zeros((4, 6, 3), np.float32))
    >>> read_photo(path).shape
    (4, 6, 3)
    >>> read_photo(path.parent)
    Traceback (most recent call last):
    ...
    texsynth.io.files.ImageReadError: ... is a folder, not an image file
    """
    kind = _kind(path)
    try:
        if kind == "exr":
            return check_finite(exr.read_exr(path), path)  # no EXIF: shown as stored
        a = _own(png.read_png, path) if kind == "png" else tiff.read_tiff(path) \
            if kind == "tiff" else None
        if a is None:
            return _read_pillow(path)
        return np.ascontiguousarray(orient(a, exif_orientation(path)))
    except ImageReadError:
        raise
    except ValueError as error:  # the codecs' messages name the file
        raise ImageReadError(str(error)) from None
    except OSError as error:
        raise ImageReadError(f"{path}: cannot be read ({error.strerror or error})") from None


def image_size(path) -> tuple[int, int, int]:
    """(width, height, channels) of what :func:`read_photo` gives for ``path``, from the
    file's headers alone (a batch checks every photo before any work). The same errors as
    :func:`read_photo` for a missing file, a folder and the like; damage past the headers shows
    only when the pixels are read.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> path = pathlib.Path(tempfile.mkdtemp()) / "a.exr"
    >>> write_image(path, np.zeros((4, 6, 1), np.float32))
    >>> image_size(path)
    (6, 4, 1)
    """
    kind = _kind(path)
    try:
        if kind == "exr":
            return exr.exr_size(path)
        own = _own(png.png_size, path) if kind == "png" else tiff.tiff_size(path) \
            if kind == "tiff" else None
        w, h, c = own or (None, None, None)
        if c is None:  # Pillow's channels, and its size unless a TIFF's IFD gave it: Pillow
            size, c = _pillow_size(path)  # turns a TIFF's size by its tag, as its pixels
            w, h = (w, h) if w else size
        return (h, w, c) if exif_orientation(path) in TURNED else (w, h, c)
    except ImageReadError:
        raise
    except (ValueError, OSError) as error:
        raise ImageReadError(f"{path}: not a readable image file ({error})") from None


def check_finite(image: np.ndarray, path) -> np.ndarray:
    """``image`` itself, or :class:`ImageReadError` naming ``path`` and how many of its values
    are NaN or infinite (a float file may hold them; synthesis may not).

    Examples
    --------
    >>> check_finite(np.array([[[1.0, np.nan]]], np.float32), "a.exr")
    Traceback (most recent call last):
    ...
    texsynth.io.files.ImageReadError: a.exr: 1 of 2 values are NaN or infinite; repair or ...
    """
    # NaN and infinities show in the extremes: two passes, and a mask only when there are some
    if image.size and not (np.isfinite(image.min()) and np.isfinite(image.max())):
        bad = int(image.size - np.count_nonzero(np.isfinite(image)))
        raise ImageReadError(f"{path}: {bad} of {image.size} values are NaN or infinite; "
                             "repair or clamp the file first")
    return image


def _own(decode, path):
    """``decode(path)``, or None for a PNG that Pillow is to read (palette, interlaced...)."""
    try:
        return decode(path)
    except png.UnsupportedPNG:
        return None


def _kind(path) -> str:
    """png, exr, tiff (by content) or other; the errors of :func:`read_photo` for a file that
    is missing, a folder, unreadable or empty."""
    path = Path(path)
    if path.is_dir():
        raise ImageReadError(f"{path} is a folder, not an image file")
    if path.exists() and not path.is_file():  # opening a pipe would wait for a writer
        raise ImageReadError(f"{path}: not a regular file (a pipe, socket or device); give an "
                             "image file")
    try:
        with open(path, "rb") as f:
            head = f.read(8)
    except FileNotFoundError:
        raise FileNotFoundError(f"{path}: no such file") from None
    except PermissionError:
        raise ImageReadError(f"{path}: cannot be read (permission denied)") from None
    except OSError as error:
        raise ImageReadError(f"{path}: cannot be read ({error.strerror or error})") from None
    if not head:
        raise ImageReadError(f"{path}: the file is empty (0 bytes)")
    return _MAGIC.get(head, _MAGIC.get(head[:4], "other"))


def _pillow(path):
    """Pillow's ``Image`` and ``ImageOps`` modules, or :class:`ImageReadError` saying that
    Pillow is needed."""
    try:
        from PIL import Image, ImageOps
    except ImportError:
        raise ImageReadError(f"{path}: not a PNG, OpenEXR or TIFF file that texsynth reads "
                             "itself (install Pillow to read JPEG, WebP and other photos)") \
            from None
    return Image, ImageOps


def _read_pillow(path) -> np.ndarray:
    """A photo read by Pillow as float32 (H, W, C) in [0, 1], upright (Pillow's own
    ``exif_transpose``: Pillow turns some TIFFs as it loads them and then drops their tag, so
    turning by the file's tag once more would turn them twice); 16-bit grey kept, the rest
    as 8 bits."""
    Image, ImageOps = _pillow(path)
    try:
        with Image.open(path) as im:
            upright = ImageOps.exif_transpose(im)  # loads the pixels
            mode = _pillow_mode(upright)
            a = np.asarray(upright if mode == "I" else upright.convert(mode))
    except (*_PILLOW_ERRORS, Image.DecompressionBombError) as error:
        raise ImageReadError(f"{path}: not a readable image file ({error})") from None
    a = a if a.ndim == 3 else a[:, :, None]
    if mode == "I":
        return np.clip(a.astype(np.float32) / np.float32(65535), 0, 1)
    return a.astype(np.float32) / np.float32(255)


def _pillow_size(path) -> tuple[tuple[int, int], int]:
    """Pillow's (width, height) and the channels :func:`_read_pillow` gives, from its lazy
    open (the header only)."""
    Image, _ = _pillow(path)
    try:
        with Image.open(path) as im:
            return im.size, _CHANNELS[_pillow_mode(im)]
    except (*_PILLOW_ERRORS, Image.DecompressionBombError) as error:
        raise ImageReadError(f"{path}: not a readable image file ({error})") from None


# What Pillow raises for a damaged file (its plugins' parsers raise SyntaxError and the like).
_PILLOW_ERRORS = (OSError, ValueError, SyntaxError, EOFError)
_CHANNELS = {"I": 1, "L": 1, "RGB": 3, "RGBA": 4}


def _pillow_mode(im) -> str:
    """The mode a Pillow image is read in: I (16-bit grey), L, RGB or RGBA."""
    if im.mode in ("I;16", "I;16B", "I;16L", "I"):
        return "I"
    mode = {"1": "L", "L": "L", "LA": "RGBA", "RGB": "RGB", "RGBA": "RGBA"}.get(im.mode)
    return mode or ("RGBA" if "A" in im.getbands() else "RGB")


def is_linear(path) -> bool:
    """True for OpenEXR (linear values), False for the sRGB-encoded formats."""
    return Path(path).suffix.lower() == ".exr"


def png_bits(path) -> int:
    """The bit depth (8 or 16) for a PNG or TIFF written from the photo in ``path``: its
    samples' for a PNG or TIFF, 16 for OpenEXR (a float file's precision kept), 8 for the rest
    (JPEG, WebP: 8-bit formats). JPEG output is 8-bit and OpenEXR float whatever this says;
    the errors of :func:`read_photo` for a missing file, a folder and the like.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> path = pathlib.Path(tempfile.mkdtemp()) / "a.tif"
    >>> write_image(path, np.zeros((4, 6, 3), np.float32), bits=16)
    >>> png_bits(path)
    16
    """
    kind = _kind(path)
    if kind == "png":
        with open(path, "rb") as f:
            head = f.read(25)
        return 16 if len(head) == 25 and head[24] == 16 else 8
    if kind == "tiff":
        try:
            return 16 if tiff.tiff_bits(path) > 8 else 8
        except ValueError as error:
            raise ImageReadError(str(error)) from None
    return 16 if kind == "exr" else 8


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


def output_format(path) -> str:
    """The format :func:`write_image` writes ``path`` in, by its suffix: ``"png"``, ``"exr"``,
    ``"jpeg"`` or ``"tiff"``; ``ValueError`` naming the suffix and the choices otherwise (check
    every output with this before any work).

    Examples
    --------
    >>> output_format("out/sand.JPG")
    'jpeg'
    >>> output_format("out/sand.webp")
    Traceback (most recent call last):
    ...
    ValueError: out/sand.webp: texsynth cannot write '.webp' files; the suffix must be one of ...
    """
    suffix = Path(path).suffix.lower()
    if suffix not in SUFFIXES:
        raise ValueError(f"{path}: texsynth cannot write '{suffix or 'suffix-less'}' files; "
                         f"the suffix must be one of {', '.join(SUFFIXES)}")
    return SUFFIXES[suffix]


def write_image(path, image, bits: int = 8, *, atomic: bool = True) -> None:
    """Write ``image`` (H, W, C), C in 1, 3, 4, to ``path`` atomically in the format of its
    suffix (:func:`output_format`); ``atomic=False`` writes ``path`` itself, for a caller that
    writes to a temporary file of its own and renames it (:func:`write_images`).

    - PNG and TIFF: values in [0, 1] (clipped), ``bits`` 8 or 16 per sample, alpha kept;
    - JPEG: 8 bits whatever ``bits`` says, quality 95, no chroma subsampling (a texture's
      colour detail); grey or RGB: JPEG has no alpha, so an alpha channel is dropped and the
      colour written as it is;
    - OpenEXR: float32 as it is (``bits`` does not apply).

    Raises ``ValueError`` for another suffix, a bit depth other than 8 or 16 or an image of
    another shape (nothing is written), ``OSError`` when the file cannot be written (a missing
    or read-only folder, a full disk: no temporary file and no partial target are left).

    Examples
    --------
    >>> import tempfile, pathlib
    >>> path = pathlib.Path(tempfile.mkdtemp()) / "a.jpg"
    >>> write_image(path, np.full((4, 6, 4), 0.5, np.float32))  # RGBA: the alpha is dropped
    >>> read_photo(path).shape
    (4, 6, 3)
    """
    path = Path(path)
    kind = output_format(path)
    if bits not in (8, 16):
        raise ValueError(f"bit depth must be 8 or 16, got {bits}")
    a = validation.image(image, what="image", min_side=1, finite=False)
    if not atomic:
        _write(kind, path, a, bits)
        return
    fd, temp = tempfile.mkstemp(prefix=temp_prefix(path), suffix=path.suffix,
                                dir=path.parent)
    os.close(fd)
    try:
        _write(kind, temp, a, bits)
        os.replace(temp, path)
    except BaseException:
        Path(temp).unlink(missing_ok=True)
        raise


def temp_prefix(path: Path) -> str:
    """The start of the temporary name an output of ``path`` is written under before its
    rename: :data:`TEMP_PREFIX` and its stem cut short (a name near the folder's limit still
    has room for the prefix and the random part).

    Examples
    --------
    >>> temp_prefix(Path("out/" + "a" * 200 + ".png")) == TEMP_PREFIX + "a" * 48 + "-"
    True
    """
    return f"{TEMP_PREFIX}{path.stem[:48]}-"


def write_images(files, bits: int = 8) -> None:
    """Every ``(path, image)`` of ``files`` written to a temporary file beside its path, then
    all renamed over their paths: a failure (a full disk, a folder gone) removes the temporary
    files and leaves the files that were there as they were.

    Raises :class:`ImageWriteError` naming the file whose image could not be written (and
    why), or the ``OSError`` of a temporary file or a rename.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> folder = pathlib.Path(tempfile.mkdtemp())
    >>> grey = np.full((4, 6), 0.5, np.float32)
    >>> write_images([(folder / "a.png", grey), (folder / "b.exr", grey)])
    >>> sorted(p.name for p in folder.iterdir())
    ['a.png', 'b.exr']
    """
    temps = []
    try:
        for path, image in files:
            path = Path(path)
            fd, temp = tempfile.mkstemp(prefix=temp_prefix(path), suffix=path.suffix,
                                        dir=path.parent)
            os.close(fd)
            temps.append(temp)
            try:
                write_image(temp, image, bits=bits, atomic=False)  # this temp is renamed
            except (OSError, ValueError) as error:
                reason = getattr(error, "strerror", None) or error
                raise ImageWriteError(f"{path}: cannot write ({reason})") from None
        for (path, _), temp in zip(files, temps, strict=True):
            os.replace(temp, path)
    finally:
        for temp in temps:
            Path(temp).unlink(missing_ok=True)


def _write(kind: str, path, a: np.ndarray, bits: int) -> None:
    _WRITERS[kind](path, a, bits)
    os.chmod(path, 0o666 & ~_UMASK)  # mkstemp makes 0600; a plain open() would not


def _write_jpeg(path, a: np.ndarray, bits: int) -> None:
    """8-bit JPEG, quality 95, 4:4:4; the alpha channel dropped (``bits`` does not apply)."""
    from PIL import Image  # a dependency of the package (the Blender extension writes no JPEG)

    colour = a[:, :, 0] if a.shape[2] == 1 else a[:, :, :3]
    q = np.rint(np.clip(np.nan_to_num(colour), 0.0, 1.0) * 255).astype(np.uint8)
    Image.fromarray(q).save(path, "JPEG", quality=95, subsampling=0)


_WRITERS = {"png": lambda p, a, bits: png.write_png(p, a, bits=bits),
            "exr": lambda p, a, bits: exr.write_exr(p, a),
            "jpeg": _write_jpeg,
            "tiff": lambda p, a, bits: tiff.write_tiff(p, a, bits=bits)}

"""The focal length of a photo from what the camera wrote into its file (EXIF).

Exif 2.3 (CIPA DC-008) tags, read with ExifRead: ``FocalLength`` (mm) with
``FocalPlaneXResolution`` and ``FocalPlaneResolutionUnit`` (sensor pixels per unit along the
recorded image's width) gives the focal length in pixels of the image as recorded
(``PixelXDimension`` wide); else ``FocalLengthIn35mmFilm``, which CIPA DCG-001 defines by the
diagonal: f_px = f_35 / 43.27 mm x the image's diagonal in pixels. The result is scaled to the
image as stored in the file, which editing software may have resized or turned.

Orientation: pixels are square, so the focal length in pixels is the same whichever way the
image is displayed; the ``Orientation`` tag (5-8: turned by 90 degrees) matters where the
recorded width must be matched to a stored side: when the stored image is the recorded one
turned (a program applied the orientation and kept the camera's sizes), the recorded width is
the stored height.
"""

from __future__ import annotations

import io
import logging
import math
import os
import struct
from pathlib import Path

import exifread

__all__ = ["focal_px_from_file"]

_DIAGONAL_35MM = math.hypot(36.0, 24.0)  # mm: the 35 mm film frame's diagonal (43.27 mm)
_UNIT_MM = {2: 25.4, 3: 10.0, 4: 1.0, 5: 1e-3}  # FocalPlaneResolutionUnit: inch, cm, mm, um
_TURNED = (5, 6, 7, 8)  # Orientation values that turn the image by 90 degrees
_PLAUSIBLE = (0.1, 100.0)  # focal length over the image diagonal (fields of view 0.6 to 157 deg)
# ExifRead warns "PNG file does not have exif data" and the like: here no EXIF is an answer
# (None), not news; set where it is read, so batches' workers and Blender are quiet too
logging.getLogger("exifread").setLevel(logging.ERROR)


def focal_px_from_file(path) -> float | None:
    """Focal length in pixels of the image stored in ``path`` (JPEG, TIFF, PNG, WebP, HEIC), from
    its EXIF; None when the file does not say (no EXIF, or no usable focal length tags).

    Parameters
    ----------
    path : str, bytes or os.PathLike
        The image file.

    Returns
    -------
    float or None
        Pixels of the stored image (see the module notes for the tags and their order).

    Raises
    ------
    ValueError
        When ``path`` is not a path (None, a number...) or not a readable file.

    References
    ----------
    CIPA DC-008 (Exif 2.3) (the tags); CIPA DCG-001 (the 35 mm equivalent);
    Google, "WebP Container Specification", Extended File Format (the EXIF chunk).

    Examples
    --------
    >>> focal_px_from_file("no such photo.jpg")
    Traceback (most recent call last):
    ...
    ValueError: no image file at 'no such photo.jpg'
    """
    try:
        name = os.fsdecode(path)  # str, bytes and os.PathLike; TypeError for anything else
    except TypeError:
        raise ValueError(f"path must be a file path (str, bytes or os.PathLike), got "
                         f"{type(path).__name__}") from None
    try:
        path = Path(name)
        readable = bool(name) and path.is_file() and os.access(path, os.R_OK)
    except (OSError, ValueError):  # a NUL byte, a name too long
        readable = False
    if not readable:
        raise ValueError(f"no image file at '{name}'")
    try:
        with path.open("rb") as handle:
            head = handle.read(12)
            if head[:4] == b"RIFF" and head[8:12] == b"WEBP":
                stored, block = _webp(handle)
                tags = _tags(io.BytesIO(block)) if block else {}
            else:
                tags = _tags(handle)
                stored = _stored_size(handle, tags)
    except OSError as error:
        raise ValueError(f"the image file '{path}' cannot be read: {error.strerror or error}") \
            from None
    if stored is None:
        return None
    width, height = stored
    for focal in (_from_focal_plane(tags, width, height), _from_35mm(tags, width, height)):
        if focal is not None and _PLAUSIBLE[0] <= focal / math.hypot(width, height) \
                <= _PLAUSIBLE[1]:
            return focal
    return None


def _tags(handle) -> dict:
    """ExifRead's tags of the file (or TIFF block) in ``handle``; none from a damaged block."""
    handle.seek(0)
    try:
        return exifread.process_file(handle, details=False, extract_thumbnail=False)
    except Exception:  # noqa: BLE001  (a damaged EXIF block says nothing; the photo is fine)
        return {}


def _webp(handle) -> tuple[tuple[int, int] | None, bytes | None]:
    """The stored (width, height) and the EXIF block (a TIFF structure) of a WebP file, from
    its RIFF chunks: the canvas of ``VP8X``, else the frame header of ``VP8 `` (lossy) or
    ``VP8L`` (lossless); the ``EXIF`` chunk, which the container specification defines as the
    TIFF structure itself (deviation: a leading ``Exif`` and two NUL bytes, as some writers put
    it, are skipped; ExifRead 3.5 skips six bytes always and read the others as no EXIF)."""
    size = block = None
    handle.seek(12)
    while True:
        header = handle.read(8)
        if len(header) < 8:
            break
        fourcc, length = header[:4], struct.unpack("<I", header[4:])[0]
        if fourcc == b"EXIF":
            block = handle.read(length)
            block = block[6:] if block[:6] == b"Exif\x00\x00" else block
        else:
            payload = handle.read(min(length, 10))
            size = size or _webp_size(fourcc, payload)
            handle.seek(length - len(payload), 1)
        handle.seek(length & 1, 1)  # chunks are padded to an even length
    return size, block


def _webp_size(fourcc: bytes, payload: bytes) -> tuple[int, int] | None:
    """(width, height) from a WebP chunk's first bytes, or None when it does not give one."""
    if fourcc == b"VP8X" and len(payload) == 10:
        return (int.from_bytes(payload[4:7], "little") + 1,
                int.from_bytes(payload[7:10], "little") + 1)
    if fourcc == b"VP8 " and len(payload) == 10 and payload[3:6] == b"\x9d\x01\x2a":
        width, height = struct.unpack("<HH", payload[6:10])
        return (width & 0x3FFF, height & 0x3FFF) if width & 0x3FFF and height & 0x3FFF \
            else None
    if fourcc == b"VP8L" and len(payload) >= 5 and payload[0] == 0x2F:
        bits = int.from_bytes(payload[1:5], "little")
        return (bits & 0x3FFF) + 1, ((bits >> 14) & 0x3FFF) + 1
    return None


def _number(tags, name: str) -> float | None:
    """The first value of an EXIF tag (Exif IFD first, then IFD0 as TIFF/EP puts it)."""
    for prefix in ("EXIF", "Image"):
        tag = tags.get(f"{prefix} {name}")
        if tag is not None and tag.values:
            value = tag.values[0]
            try:
                number = float(value)
            except (TypeError, ValueError, ZeroDivisionError):
                return None
            return number if math.isfinite(number) and number > 0 else None
    return None


def _from_focal_plane(tags, width: int, height: int) -> float | None:
    """FocalLength x FocalPlaneXResolution, scaled from the recorded to the stored width."""
    focal_mm = _number(tags, "FocalLength")
    per_unit = _number(tags, "FocalPlaneXResolution")
    unit = _UNIT_MM.get(int(_number(tags, "FocalPlaneResolutionUnit") or 2))
    if focal_mm is None or per_unit is None or unit is None:
        return None
    recorded_w = _number(tags, "ExifImageWidth") or width
    recorded_h = _number(tags, "ExifImageLength") or height
    orientation = int(_number(tags, "Orientation") or 1)
    turned = orientation in _TURNED and (recorded_w > recorded_h) != (width > height)
    stored_side = height if turned else width  # the stored side along the recorded width
    return focal_mm * per_unit / unit * stored_side / recorded_w


def _from_35mm(tags, width: int, height: int) -> float | None:
    """FocalLengthIn35mmFilm by the diagonal convention (turning does not change a diagonal)."""
    focal_35 = _number(tags, "FocalLengthIn35mmFilm")
    return None if focal_35 is None else focal_35 / _DIAGONAL_35MM * math.hypot(width, height)


def _stored_size(handle, tags) -> tuple[int, int] | None:
    """(width, height) of the stored image: JPEG frame header, PNG header or TIFF IFD0 tags;
    the EXIF pixel dimensions for other formats."""
    handle.seek(0)
    head = handle.read(24)
    if head[:2] == b"\xff\xd8":
        return _jpeg_size(handle)
    if head[:8] == b"\x89PNG\r\n\x1a\n" and head[12:16] == b"IHDR":
        return struct.unpack(">II", head[16:24])
    if head[:4] in (b"II*\x00", b"MM\x00*"):
        width, height = tags.get("Image ImageWidth"), tags.get("Image ImageLength")
    else:
        width, height = tags.get("EXIF ExifImageWidth"), tags.get("EXIF ExifImageLength")
    if width is None or height is None:
        return None
    return int(width.values[0]), int(height.values[0])


def _jpeg_size(handle) -> tuple[int, int] | None:
    """Width and height from a JPEG's start-of-frame segment, skipping the segments before it."""
    handle.seek(2)
    while True:
        marker = handle.read(2)
        while marker[:1] == b"\xff" and marker[1:] == b"\xff":  # fill bytes
            marker = marker[1:] + handle.read(1)
        if len(marker) < 2 or marker[0] != 0xFF:
            return None
        header = handle.read(7)
        if len(header) < 2:
            return None
        length = struct.unpack(">H", header[:2])[0]
        if 0xC0 <= marker[1] <= 0xCF and marker[1] not in (0xC4, 0xC8, 0xCC):
            if len(header) < 7:
                return None
            height, width = struct.unpack(">HH", header[3:7])
            return (width, height) if width and height else None
        handle.seek(length - 7, 1)

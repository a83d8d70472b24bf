"""Which way up a photo is shown: the EXIF ``Orientation`` tag (274) and the turn it asks for.

A phone stores a portrait photo as its sensor read it, landscape, and writes ``Orientation`` 6
("turn 90 degrees clockwise to show"); viewers turn it, Blender does not. The tag is read from
the file's headers alone, with no dependency: JPEG's APP1 ``Exif`` segment, PNG's ``eXIf``
chunk, WebP's ``EXIF`` chunk and a TIFF file's first IFD (CIPA DC-008, 4.6.4 A; PNG 1.5
extensions, eXIf; Google's WebP container specification). Deviation: a leading ``Exif`` and
two NUL bytes in a PNG or WebP block, as some writers put them, are skipped.
"""

from __future__ import annotations

import struct

import numpy as np

from .png import SIGNATURE as _PNG_SIGNATURE

__all__ = ["exif_orientation", "orient", "TURNED"]

_TAG = 0x0112
_PREFIX = b"Exif\x00\x00"
_TIFF = {b"II*\x00": "<", b"MM\x00*": ">"}
#: Orientation values that swap width and height.
TURNED = (5, 6, 7, 8)


def exif_orientation(path) -> int:
    """The ``Orientation`` of the image stored in ``path``, 1 to 8; 1 when the file has no EXIF
    or a damaged one (the photo is then shown as stored).

    Examples
    --------
    >>> import tempfile, pathlib
    >>> path = pathlib.Path(tempfile.mkdtemp()) / "a.jpg"
    >>> tiff = b"II*\\x00" + struct.pack("<IHHHIHHI", 8, 1, 0x0112, 3, 1, 6, 0, 0)
    >>> app1 = b"\\xff\\xe1" + struct.pack(">H", 8 + len(tiff)) + b"Exif\\x00\\x00" + tiff
    >>> _ = path.write_bytes(b"\\xff\\xd8" + app1 + b"\\xff\\xd9")
    >>> exif_orientation(path)
    6
    """
    with open(path, "rb") as f:
        head = f.read(12)
        try:
            if head[:2] == b"\xff\xd8":
                base = _jpeg(f)
            elif head[:8] == _PNG_SIGNATURE:
                base = _chunks(f, 8, ">I4s", b"eXIf", b"IEND", pad=False)
            elif head[:4] == b"RIFF" and head[8:12] == b"WEBP":
                base = _chunks(f, 12, "<4sI", b"EXIF", None, pad=True)
            else:
                base = 0 if head[:4] in _TIFF else None
            return 1 if base is None else _tiff_orientation(f, base)
        except (struct.error, OverflowError, ValueError):
            return 1


def _jpeg(f) -> int | None:
    """Where the TIFF structure of a JPEG's APP1 ``Exif`` segment starts (markers before the
    scan only), or None."""
    f.seek(2)
    while True:
        marker = f.read(2)
        if len(marker) < 2 or marker[0] != 0xFF or marker[1] in (0xD9, 0xDA):
            return None  # not a marker, end of image, start of scan: no EXIF before the data
        if marker[1] == 0xFF:
            f.seek(-1, 1)  # a fill byte
            continue
        if marker[1] == 0x01 or 0xD0 <= marker[1] <= 0xD7:
            continue  # markers without a length
        (length,) = struct.unpack(">H", f.read(2))
        start = f.tell()
        if marker[1] == 0xE1 and f.read(6) == _PREFIX:
            return start + 6
        f.seek(start + length - 2)


def _chunks(f, start: int, layout: str, wanted: bytes, last: bytes | None, pad: bool):
    """Where the TIFF structure of a PNG or RIFF file's ``wanted`` chunk starts, or None."""
    f.seek(start)
    while len(header := f.read(8)) == 8:
        fields = struct.unpack(layout, header)
        kind, length = (fields[1], fields[0]) if layout[1] == "I" else fields
        if kind == wanted:
            base = f.tell()
            return base + 6 if f.read(6) == _PREFIX else base
        if kind == last:
            return None
        f.seek(length + (4 if not pad else length & 1), 1)  # a PNG chunk's CRC, RIFF's padding
    return None


def _tiff_orientation(f, base: int) -> int:
    """The ``Orientation`` in IFD0 of the TIFF structure at ``base``; 1 when there is none."""
    f.seek(base)
    head = f.read(8)
    order = _TIFF.get(head[:4])
    if order is None:
        return 1
    f.seek(base + struct.unpack(order + "I", head[4:])[0])
    (count,) = struct.unpack(order + "H", f.read(2))
    entries = f.read(12 * count)
    for i in range(len(entries) // 12):
        tag, kind = struct.unpack_from(order + "HH", entries, 12 * i)
        if tag == _TAG and kind == 3:  # SHORT
            value = struct.unpack_from(order + "H", entries, 12 * i + 8)[0]
            return value if 1 <= value <= 8 else 1
    return 1


def orient(image: np.ndarray, orientation: int) -> np.ndarray:
    """``image`` (H, W, ...) turned and mirrored as ``orientation`` asks, to be shown upright.

    Examples
    --------
    >>> a = np.arange(6).reshape(2, 3)  # stored as the sensor read it
    >>> orient(a, 6).tolist()  # 6: turned 90 degrees clockwise
    [[3, 0], [4, 1], [5, 2]]
    >>> orient(a, 1) is a
    True
    """
    flips = {2: (1,), 3: (0, 1), 4: (0,), 5: (), 6: (1,), 7: (0, 1), 8: (0,)}.get(orientation)
    if flips is None:  # 1, or a value the tag does not define
        return image
    if orientation in TURNED:
        image = np.swapaxes(image, 0, 1)  # 5 is the transpose; 6, 7 and 8 flip it after
    return np.ascontiguousarray(np.flip(image, flips) if flips else image)

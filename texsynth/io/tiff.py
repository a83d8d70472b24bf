"""TIFF files with zlib and numpy alone: 8/16-bit grey, grey + alpha, RGB, RGBA in strips.

Pillow reads a 16-bit RGB TIFF as 8 bits, so the 16-bit files a photo editor exports are read
here: uncompressed or Deflate strips (TIFF 6.0 and its Adobe Deflate supplement), with or
without the horizontal predictor, samples interleaved. :func:`read_tiff` returns None for any
other TIFF (LZW, JPEG-compressed, tiled, planar, palette, float: Pillow's to read).
"""

from __future__ import annotations

import struct
import zlib

import numpy as np

from ..validation import image

__all__ = ["read_tiff", "write_tiff", "tiff_size"]

_ORDER = {b"II*\x00": "<", b"MM\x00*": ">"}
_CODES = {1: "B", 3: "H", 4: "I"}  # BYTE, SHORT, LONG: the integer tags read here
_WIDTH, _HEIGHT, _BITS, _COMPRESSION, _PHOTOMETRIC = 256, 257, 258, 259, 262
_OFFSETS, _SAMPLES, _ROWS, _COUNTS, _PLANAR, _PREDICTOR = 273, 277, 278, 279, 284, 317
_EXTRA, _FORMAT, _TILE_WIDTH = 338, 339, 322


def write_tiff(path, array, bits: int = 8) -> None:
    """Write values in [0, 1] (clipped) as an 8- or 16-bit TIFF, one Deflate strip: grey, RGB
    or RGBA (unassociated alpha)."""
    if bits not in (8, 16):
        raise ValueError(f"TIFF bit depth must be 8 or 16, got {bits}")
    a = image(array, what="image", min_side=1, finite=False)
    h, w, c = a.shape
    top = (1 << bits) - 1
    q = np.rint(np.clip(np.nan_to_num(a), 0.0, 1.0) * top).astype("<u2" if bits == 16 else "u1")
    strip = zlib.compress(q.tobytes(), 6)
    entries = [(_WIDTH, 4, [w]), (_HEIGHT, 4, [h]), (_BITS, 3, [bits] * c),
               (_COMPRESSION, 3, [8]), (_PHOTOMETRIC, 3, [1 if c == 1 else 2]),
               (_OFFSETS, 4, [0]), (_SAMPLES, 3, [c]), (_ROWS, 4, [h]),
               (_COUNTS, 4, [len(strip)]), (_PLANAR, 3, [1])] + \
        ([(_EXTRA, 3, [2])] if c == 4 else [])
    extra_at = 8 + 2 + 12 * len(entries) + 4  # values of more than 4 bytes follow the IFD
    extra = b"".join(struct.pack(f"<{len(v)}H", *v) for t, k, v in entries if len(v) > 2)
    data_at = extra_at + len(extra)
    ifd, at = struct.pack("<H", len(entries)), extra_at
    for tag, kind, values in entries:
        values = [data_at] if tag == _OFFSETS else values
        packed = struct.pack(f"<{len(values)}{_CODES[kind]}", *values)
        if len(packed) > 4:
            field, at = struct.pack("<I", at), at + len(packed)
        else:
            field = packed.ljust(4, b"\x00")
        ifd += struct.pack("<HHI", tag, kind, len(values)) + field
    with open(path, "wb") as f:
        f.write(b"II*\x00" + struct.pack("<I", 8) + ifd + struct.pack("<I", 0) + extra + strip)


def read_tiff(path) -> np.ndarray | None:
    """A TIFF's first image as float32 (H, W, C) in [0, 1] (grey with alpha becomes RGBA), or
    None when it is not one of the kinds this module reads; ``ValueError`` when damaged."""
    with open(path, "rb") as f:
        data = f.read()
    order = _ORDER.get(data[:4])
    if order is None:
        raise ValueError(f"{path}: not a TIFF file")
    try:
        tags = _ifd(data, order, struct.unpack_from(order + "I", data, 4)[0])
        w, h = tags[_WIDTH][0], tags[_HEIGHT][0]
        strips = list(zip(tags[_OFFSETS], tags[_COUNTS], strict=True))
    except (struct.error, KeyError, IndexError, ValueError):
        raise ValueError(f"{path}: the TIFF's image directory is damaged") from None
    bits, channels = set(tags.get(_BITS, [1])), tags.get(_SAMPLES, [1])[0]
    compression, predictor = tags.get(_COMPRESSION, [1])[0], tags.get(_PREDICTOR, [1])[0]
    if (len(bits) != 1 or bits - {8, 16} or channels not in (1, 2, 3, 4)
            or compression not in (1, 8, 32946) or predictor not in (1, 2)
            or tags.get(_PHOTOMETRIC, [1])[0] != (1 if channels <= 2 else 2)
            or tags.get(_PLANAR, [1])[0] != 1 or tags.get(_FORMAT, [1])[0] != 1
            or _TILE_WIDTH in tags):
        return None
    chunks = [data[o:o + n] for o, n in strips]
    try:
        raw = b"".join(zlib.decompress(c) for c in chunks) if compression != 1 else \
            b"".join(chunks)
    except zlib.error as error:
        raise ValueError(f"{path}: TIFF image data is corrupt ({error})") from None
    dtype = np.dtype(order + "u2") if bits == {16} else np.dtype("u1")
    need = h * w * channels * dtype.itemsize
    if len(raw) < need:
        raise ValueError(f"{path}: TIFF image data is truncated")
    q = np.frombuffer(raw[:need], dtype).reshape(h, w, channels)
    if predictor == 2:  # horizontal differencing: each sample from its left neighbour
        q = np.cumsum(q, axis=1, dtype=q.dtype)
    a = q.astype(np.float32) / np.float32(np.iinfo(dtype).max)
    return a[:, :, [0, 0, 0, 1]] if channels == 2 else a


def _ifd(data: bytes, order: str, at: int) -> dict:
    """The tags of the IFD at ``at``: tag -> list of ints (SHORT, LONG and the like only)."""
    (count,) = struct.unpack_from(order + "H", data, at)
    tags = {}
    for i in range(count):
        tag, kind, n, field = struct.unpack_from(order + "HHI4s", data, at + 2 + 12 * i)
        if kind not in _CODES:
            continue
        size = n * struct.calcsize(_CODES[kind])
        if size > 4:
            (offset,) = struct.unpack(order + "I", field)
            field = data[offset:offset + size]
            if len(field) < size:  # outside ``data`` (tiff_size reads the IFD alone)
                continue
        tags[tag] = list(struct.unpack(f"{order}{n}{_CODES[kind]}", field[:size]))
    return tags


def tiff_size(path) -> tuple[int, int, int]:
    """(width, height, channels as read, grey with alpha as RGBA) of a TIFF's first image,
    from its header and first IFD alone (wherever in the file that is)."""
    with open(path, "rb") as f:
        head = f.read(8)
        order = _ORDER.get(head[:4])
        if order is None or len(head) < 8:
            raise ValueError(f"{path}: not a TIFF file")
        f.seek(struct.unpack(order + "I", head[4:])[0])
        count = f.read(2)
        ifd = count + f.read(12 * struct.unpack(order + "H", count)[0]) if len(count) == 2 \
            else b""
    try:
        tags = _ifd(ifd, order, 0)
        w, h = tags[_WIDTH][0], tags[_HEIGHT][0]
    except (struct.error, KeyError, IndexError):
        raise ValueError(f"{path}: the TIFF's image directory is damaged") from None
    channels = tags.get(_SAMPLES, [1])[0]
    return w, h, 4 if channels == 2 else channels

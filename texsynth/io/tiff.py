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

from .png import quantize

__all__ = ["read_tiff", "write_tiff", "tiff_size", "tiff_bits"]

_ORDER = {b"II*\x00": "<", b"MM\x00*": ">"}
_CODES = {1: "B", 3: "H", 4: "I"}  # BYTE, SHORT, LONG: the integer tags read here
_WIDTH, _HEIGHT, _BITS, _COMPRESSION, _PHOTOMETRIC = 256, 257, 258, 259, 262
_OFFSETS, _SAMPLES, _ROWS, _COUNTS, _PLANAR, _PREDICTOR = 273, 277, 278, 279, 284, 317
_EXTRA, _FORMAT, _TILE_WIDTH = 338, 339, 322


def write_tiff(path, array, bits: int = 8) -> None:
    """Write values in [0, 1] (clipped) as an 8- or 16-bit TIFF, one Deflate strip with the
    horizontal predictor (each sample stored as its difference from its left neighbour): grey,
    RGB or RGBA (unassociated alpha)."""
    q = quantize(array, bits, "<u2", "TIFF")
    h, w, c = q.shape
    q[:, 1:] -= q[:, :-1].copy()  # modulo 2^bits, as the predictor is defined
    strip = zlib.compress(q.tobytes(), 6)
    entries = [(_WIDTH, 4, [w]), (_HEIGHT, 4, [h]), (_BITS, 3, [bits] * c),
               (_COMPRESSION, 3, [8]), (_PHOTOMETRIC, 3, [1 if c == 1 else 2]),
               (_OFFSETS, 4, [0]), (_SAMPLES, 3, [c]), (_ROWS, 4, [h]),
               (_COUNTS, 4, [len(strip)]), (_PLANAR, 3, [1]), (_PREDICTOR, 3, [2])] + \
        ([(_EXTRA, 3, [2])] if c == 4 else [])
    packed = [(tag, kind, len(v), struct.pack(f"<{len(v)}{_CODES[kind]}", *v))
              for tag, kind, v in entries]
    at = 8 + 2 + 12 * len(entries) + 4  # values of more than 4 bytes follow the IFD
    extra = b"".join(p for *_, p in packed if len(p) > 4)
    data_at = at + len(extra)  # then the strip
    ifd = struct.pack("<H", len(entries))
    for tag, kind, n, p in packed:
        if len(p) > 4:
            field, at = struct.pack("<I", at), at + len(p)
        else:
            field = (struct.pack("<I", data_at) if tag == _OFFSETS else p).ljust(4, b"\x00")
        ifd += struct.pack("<HHI", tag, kind, n) + field
    with open(path, "wb") as f:
        f.write(b"II*\x00" + struct.pack("<I", 8) + ifd + struct.pack("<I", 0) + extra + strip)


def read_tiff(path) -> np.ndarray | None:
    """A TIFF's first image as float32 (H, W, C) in [0, 1] (grey with alpha becomes RGBA), or
    None when it is not one of the kinds this module reads; ``ValueError`` when damaged."""
    with open(path, "rb") as f:
        order, tags = _first_ifd(f, path)
        if not _readable(tags):
            return None
        chunks = []
        for offset, count in zip(tags[_OFFSETS], tags.get(_COUNTS, []), strict=False):
            f.seek(offset)
            chunks.append(f.read(count))
    try:
        raw = b"".join(zlib.decompress(c) for c in chunks) if tags[_COMPRESSION][0] != 1 else \
            b"".join(chunks)
    except zlib.error as error:
        raise ValueError(f"{path}: TIFF image data is corrupt ({error})") from None
    (w,), (h,), (channels,) = tags[_WIDTH], tags[_HEIGHT], tags[_SAMPLES]
    dtype = np.dtype(order + "u2") if tags[_BITS][0] == 16 else np.dtype("u1")
    need = h * w * channels * dtype.itemsize
    if len(raw) < need:
        raise ValueError(f"{path}: TIFF image data is truncated")
    q = np.frombuffer(raw[:need], dtype).reshape(h, w, channels)
    if tags[_PREDICTOR][0] == 2:  # horizontal differencing: each sample from its left one
        q = np.cumsum(q, axis=1, dtype=q.dtype)
    a = q.astype(np.float32) / np.float32(np.iinfo(dtype).max)
    return a[:, :, [0, 0, 0, 1]] if channels == 2 else a


def tiff_size(path) -> tuple[int, int, int | None]:
    """(width, height, channels as :func:`read_tiff` gives them) of a TIFF's first image, from
    its header and first IFD alone; channels None when :func:`read_tiff` leaves it to Pillow."""
    with open(path, "rb") as f:
        _, tags = _first_ifd(f, path)
    channels = tags[_SAMPLES][0]
    return tags[_WIDTH][0], tags[_HEIGHT][0], \
        (4 if channels == 2 else channels) if _readable(tags) else None


def tiff_bits(path) -> int:
    """The most bits of any sample of a TIFF's first image, from its IFD alone."""
    with open(path, "rb") as f:
        return max(_first_ifd(f, path)[1][_BITS])


_DEFAULTS = {_BITS: [1], _SAMPLES: [1], _COMPRESSION: [1], _PREDICTOR: [1], _PLANAR: [1],
             _FORMAT: [1]}


def _first_ifd(f, path) -> tuple[str, dict]:
    """The byte order and the integer tags (tag -> list of ints, TIFF 6.0's defaults filled
    in) of the first IFD of the TIFF file ``f``, read by seeking: no pixels."""
    head = f.read(8)
    order = _ORDER.get(head[:4])
    if order is None:
        raise ValueError(f"{path}: not a TIFF file")
    tags = dict(_DEFAULTS)
    try:
        f.seek(struct.unpack(order + "I", head[4:])[0])
        (count,) = struct.unpack(order + "H", f.read(2))
        entries = f.read(12 * count)
        for i in range(count):
            tag, kind, n, field = struct.unpack_from(order + "HHI4s", entries, 12 * i)
            if kind not in _CODES:
                continue
            size = n * struct.calcsize(_CODES[kind])
            if size > 4:
                f.seek(struct.unpack(order + "I", field)[0])
                field = f.read(size)
            tags[tag] = list(struct.unpack(f"{order}{n}{_CODES[kind]}", field[:size]))
        if not tags[_WIDTH][0] or not tags[_HEIGHT][0] or _OFFSETS not in tags:
            raise ValueError
    except (struct.error, KeyError, IndexError, ValueError, OverflowError):
        raise ValueError(f"{path}: the TIFF's image directory is damaged") from None
    return order, tags


def _readable(tags: dict) -> bool:
    """Whether :func:`read_tiff` reads this kind: 8 or 16 unsigned bits alike in every sample,
    1 to 4 samples interleaved in strips, grey or RGB, uncompressed or Deflate."""
    channels = tags[_SAMPLES][0]
    return (len(set(tags[_BITS])) == 1 and tags[_BITS][0] in (8, 16)
            and channels in (1, 2, 3, 4) and tags[_COMPRESSION][0] in (1, 8, 32946)
            and tags[_PREDICTOR][0] in (1, 2) and tags[_PLANAR][0] == 1
            and tags[_FORMAT][0] == 1 and _TILE_WIDTH not in tags
            and tags.get(_PHOTOMETRIC, [-1])[0] == (1 if channels <= 2 else 2))

"""PNG files with zlib and numpy alone: non-interlaced 8/16-bit grey, grey + alpha, RGB, RGBA.

Palette, 1/2/4-bit and interlaced files raise :class:`UnsupportedPNG` (a ``ValueError``:
``texsynth.io.read_photo`` reads them with Pillow).
"""

from __future__ import annotations

import struct
import zlib
from pathlib import Path

import numpy as np

from ..validation import image

__all__ = ["read_png", "write_png", "png_size", "quantize", "SIGNATURE", "UnsupportedPNG"]

SIGNATURE = b"\x89PNG\r\n\x1a\n"
# PNG colour type -> channels in the file.
_CHANNELS = {0: 1, 2: 3, 4: 2, 6: 4}


class UnsupportedPNG(ValueError):
    """A sound PNG of a kind this module does not decode (palette, 1/2/4-bit, interlaced)."""


def write_png(path, array, bits: int = 8) -> None:
    """Write values in [0, 1] (clipped) as an 8- or 16-bit PNG: grey, RGB or RGBA."""
    q = quantize(array, bits, ">u2", "PNG")
    h, w, c = q.shape
    rows = q.reshape(h, w * c).view(np.uint8)
    raw = np.hstack([np.zeros((h, 1), np.uint8), rows])  # filter type 0 (None) on every row
    colour_type = {1: 0, 3: 2, 4: 6}[c]
    header = struct.pack(">IIBBBBB", w, h, bits, colour_type, 0, 0, 0)
    with open(path, "wb") as f:
        f.write(SIGNATURE)
        f.write(_png_chunk(b"IHDR", header))
        f.write(_png_chunk(b"IDAT", zlib.compress(raw.tobytes(), 6)))
        f.write(_png_chunk(b"IEND", b""))


def quantize(array, bits: int, wide: str, what: str) -> np.ndarray:
    """Values in [0, 1] (clipped; NaN as 0) as whole numbers of ``bits`` (8 or 16) bits: uint8,
    or the 16-bit dtype ``wide`` (the file's byte order), (H, W, C); ``what`` names the format
    in the error for another depth.

    Examples
    --------
    >>> quantize(np.array([[0.0, 0.5, 2.0]]), 8, ">u2", "PNG").ravel().tolist()
    [0, 128, 255]
    """
    if bits not in (8, 16):
        raise ValueError(f"{what} bit depth must be 8 or 16, got {bits}")
    a = image(array, what="image", min_side=1, finite=False)
    top = (1 << bits) - 1
    return np.rint(np.clip(np.nan_to_num(a), 0.0, 1.0) * top).astype(wide if bits == 16 else "u1")


def _png_chunk(kind: bytes, data: bytes) -> bytes:
    return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))


def read_png(path) -> np.ndarray:
    """Read a PNG as float32 (H, W, C) in [0, 1]; grey with alpha becomes RGBA.

    ``ValueError`` naming the file when it is damaged: a chunk cut short or failing its CRC,
    image data that does not inflate to the image's size, an unknown row filter."""
    data = Path(path).read_bytes()
    if data[:8] != SIGNATURE:
        raise ValueError(f"{path}: not a PNG file")
    header, idat, pos = None, [], 8
    while pos + 8 <= len(data):
        length, kind = struct.unpack(">I4s", data[pos:pos + 8])
        body = data[pos + 8:pos + 8 + length]
        crc = data[pos + 8 + length:pos + 12 + length]
        if len(crc) < 4:
            raise ValueError(f"{path}: PNG is truncated (its {kind!r} chunk is cut short)")
        if struct.unpack(">I", crc)[0] != zlib.crc32(kind + body):
            raise ValueError(f"{path}: PNG is damaged (its {kind!r} chunk fails its CRC)")
        if kind == b"IHDR":
            header = struct.unpack(">IIBBBBB", body) if length == 13 else None
        elif kind == b"IDAT":
            idat.append(body)
        elif kind == b"IEND":
            break
        pos += 12 + length
    if header is None or not idat:
        raise ValueError(f"{path}: PNG has no IHDR or IDAT chunk")
    w, h, bits, colour_type, _, _, interlace = header
    if colour_type not in _CHANNELS or bits not in (8, 16) or interlace:
        raise UnsupportedPNG(
            f"{path}: unsupported PNG (colour type {colour_type}, {bits}-bit, interlace "
            f"{interlace}); supported: non-interlaced 8/16-bit grey, grey+alpha, RGB, RGBA"
        )
    channels = _CHANNELS[colour_type]
    bpp = channels * bits // 8
    try:
        raw = np.frombuffer(zlib.decompress(b"".join(idat)), np.uint8)
    except zlib.error as error:
        raise ValueError(f"{path}: PNG image data is truncated or corrupt ({error})") from None
    if raw.size != h * (1 + w * bpp):
        raise ValueError(f"{path}: PNG image data is truncated or corrupt")
    try:
        rows = _unfilter(raw.reshape(h, 1 + w * bpp), bpp)
    except ValueError as error:
        raise ValueError(f"{path}: {error}") from None
    dtype = ">u2" if bits == 16 else "u1"
    a = rows.view(dtype).reshape(h, w, channels).astype(np.float32) / np.float32((1 << bits) - 1)
    if channels == 2:
        a = a[:, :, [0, 0, 0, 1]]
    return a


def png_size(path) -> tuple[int, int, int]:
    """(width, height, channels as :func:`read_png` gives them) from the IHDR chunk alone."""
    with open(path, "rb") as f:
        head = f.read(33)
    if len(head) < 33 or head[:8] != SIGNATURE or head[12:16] != b"IHDR":
        raise ValueError(f"{path}: not a PNG file, or its IHDR chunk is cut short")
    w, h, bits, colour_type, _, _, interlace = struct.unpack(">IIBBBBB", head[16:29])
    if colour_type not in _CHANNELS or bits not in (8, 16) or interlace:
        raise UnsupportedPNG(f"{path}: unsupported PNG (colour type {colour_type}, {bits}-bit, "
                             f"interlace {interlace})")
    return w, h, {0: 1, 2: 3, 4: 4, 6: 4}[colour_type]


def _unfilter(scanlines: np.ndarray, bpp: int) -> np.ndarray:
    """Undo the per-row PNG filters (None, Sub, Up, Average, Paeth)."""
    h, n = scanlines.shape[0], scanlines.shape[1] - 1
    out = np.zeros((h, n), np.uint8)
    prior = np.zeros(n, np.uint8)
    for y in range(h):
        kind, line = scanlines[y, 0], scanlines[y, 1:]
        if kind == 0:
            row = line.copy()
        elif kind == 1:
            row = _undo_sub(line, bpp)
        elif kind == 2:
            row = line + prior
        elif kind in (3, 4):
            row = _undo_average_or_paeth(line, prior, bpp, paeth=kind == 4)
        else:
            raise ValueError(f"PNG is damaged: unknown filter type {kind} on row {y}")
        out[y] = prior = row
    return out


def _undo_sub(line: np.ndarray, bpp: int) -> np.ndarray:
    padded = np.zeros(-(-line.size // bpp) * bpp, np.uint64)
    padded[: line.size] = line
    return (np.cumsum(padded.reshape(-1, bpp), axis=0) % 256).astype(np.uint8).ravel()[: line.size]


def _undo_average_or_paeth(line: np.ndarray, prior: np.ndarray, bpp: int, paeth: bool):
    # Each byte depends on the already-decoded byte to its left: a sequential loop.
    row = bytearray(line.tobytes())
    up = prior.tobytes()
    for i in range(len(row)):
        a = row[i - bpp] if i >= bpp else 0
        b = up[i]
        if paeth:
            c = up[i - bpp] if i >= bpp else 0
            pa, pb, pc = abs(b - c), abs(a - c), abs(a + b - 2 * c)
            pred = a if pa <= pb and pa <= pc else (b if pb <= pc else c)
        else:
            pred = (a + b) >> 1
        row[i] = (row[i] + pred) & 0xFF
    return np.frombuffer(bytes(row), np.uint8)

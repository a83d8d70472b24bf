"""Image files for the core and for scripts: OpenEXR (exact float32) and PNG (8/16-bit).

Arrays are float32 (H, W, C), top row first, C in 1, 3, 4. EXR holds linear values as they are;
PNG holds encoded values in [0, 1] (sRGB for colour images), quantized to 8 or 16 bits. PNG is
read and written with zlib and numpy alone: non-interlaced greyscale, grey + alpha, RGB and RGBA
at 8 or 16 bits. Palette, 1/2/4-bit and interlaced files raise ``ValueError``.
"""

from __future__ import annotations

import struct
import zlib
from pathlib import Path

import numpy as np

__all__ = [
    "read_image",
    "read_exr",
    "write_exr",
    "read_png",
    "write_png",
    "srgb_to_linear",
    "linear_to_srgb",
    "tile_preview",
]

_PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"
_EXR_MAGIC = b"\x76\x2f\x31\x01"
# PNG colour type -> channels in the file.
_PNG_CHANNELS = {0: 1, 2: 3, 4: 2, 6: 4}
_EXR_LAYOUTS = ("RGBA", "RGB", "YA", "Y")


def _as_image(array) -> np.ndarray:
    a = np.asarray(array, dtype=np.float32)
    if a.ndim == 2:
        a = a[:, :, None]
    if a.ndim != 3 or a.shape[2] not in (1, 3, 4) or 0 in a.shape[:2]:
        raise ValueError(f"image must be (H, W) or (H, W, C) with C in 1, 3, 4; got {a.shape}")
    return a


def read_image(path) -> np.ndarray:
    """Read a PNG or OpenEXR file (told apart by content) as float32 (H, W, C)."""
    with open(path, "rb") as f:
        head = f.read(8)
    if head == _PNG_SIGNATURE:
        return read_png(path)
    if head[:4] == _EXR_MAGIC:
        return read_exr(path)
    raise ValueError(f"{path}: not a PNG or OpenEXR file")


# --- OpenEXR ------------------------------------------------------------------------------


def write_exr(path, array) -> None:
    """Write float32 channels (Y, RGB or RGBA), ZIP-compressed; reading back gives the same bits."""
    import OpenEXR

    a = _as_image(array)
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
    for layout in _EXR_LAYOUTS:
        if set(layout) <= set(channels):
            planes = [channels[name] for name in layout]
            if layout == "YA":
                planes = [planes[0]] * 3 + [planes[1]]
            return np.stack(planes, axis=2).astype(np.float32)
    raise ValueError(f"{path}: no R, G, B or Y channels (found {', '.join(sorted(channels))})")


# --- PNG ----------------------------------------------------------------------------------


def write_png(path, array, bits: int = 8) -> None:
    """Write values in [0, 1] (clipped) as an 8- or 16-bit PNG: grey, RGB or RGBA."""
    if bits not in (8, 16):
        raise ValueError(f"PNG bit depth must be 8 or 16, got {bits}")
    a = _as_image(array)
    h, w, c = a.shape
    top = (1 << bits) - 1
    q = np.rint(np.clip(np.nan_to_num(a), 0.0, 1.0) * top).astype(">u2" if bits == 16 else "u1")
    rows = q.reshape(h, w * c).view(np.uint8)
    raw = np.hstack([np.zeros((h, 1), np.uint8), rows])  # filter type 0 (None) on every row
    colour_type = {1: 0, 3: 2, 4: 6}[c]
    header = struct.pack(">IIBBBBB", w, h, bits, colour_type, 0, 0, 0)
    with open(path, "wb") as f:
        f.write(_PNG_SIGNATURE)
        f.write(_png_chunk(b"IHDR", header))
        f.write(_png_chunk(b"IDAT", zlib.compress(raw.tobytes(), 6)))
        f.write(_png_chunk(b"IEND", b""))


def _png_chunk(kind: bytes, data: bytes) -> bytes:
    return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))


def read_png(path) -> np.ndarray:
    """Read a PNG as float32 (H, W, C) in [0, 1]; grey with alpha becomes RGBA."""
    data = Path(path).read_bytes()
    if data[:8] != _PNG_SIGNATURE:
        raise ValueError(f"{path}: not a PNG file")
    header, idat, pos = None, [], 8
    while pos + 8 <= len(data):
        length, kind = struct.unpack(">I4s", data[pos:pos + 8])
        body = data[pos + 8:pos + 8 + length]
        if kind == b"IHDR":
            header = struct.unpack(">IIBBBBB", body)
        elif kind == b"IDAT":
            idat.append(body)
        elif kind == b"IEND":
            break
        pos += 12 + length
    if header is None or not idat:
        raise ValueError(f"{path}: PNG has no IHDR or IDAT chunk")
    w, h, bits, colour_type, _, _, interlace = header
    if colour_type not in _PNG_CHANNELS or bits not in (8, 16) or interlace:
        raise ValueError(
            f"{path}: unsupported PNG (colour type {colour_type}, {bits}-bit, interlace "
            f"{interlace}); supported: non-interlaced 8/16-bit grey, grey+alpha, RGB, RGBA"
        )
    channels = _PNG_CHANNELS[colour_type]
    bpp = channels * bits // 8
    raw = np.frombuffer(zlib.decompress(b"".join(idat)), np.uint8)
    if raw.size != h * (1 + w * bpp):
        raise ValueError(f"{path}: PNG image data is truncated or corrupt")
    rows = _unfilter(raw.reshape(h, 1 + w * bpp), bpp)
    dtype = ">u2" if bits == 16 else "u1"
    a = rows.view(dtype).reshape(h, w, channels).astype(np.float32) / np.float32((1 << bits) - 1)
    if channels == 2:
        a = a[:, :, [0, 0, 0, 1]]
    return a


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
            raise ValueError(f"corrupt PNG: unknown filter type {kind} on row {y}")
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


# --- colour and previews ------------------------------------------------------------------


def srgb_to_linear(v) -> np.ndarray:
    """The sRGB transfer function (IEC 61966-2-1) decoded; values above 1 follow the power law."""
    v = np.asarray(v, dtype=np.float32)
    return np.where(v <= 0.04045, v / 12.92, ((np.maximum(v, 0.04045) + 0.055) / 1.055) ** 2.4
                    ).astype(np.float32)


def linear_to_srgb(v) -> np.ndarray:
    """Inverse of :func:`srgb_to_linear`."""
    v = np.asarray(v, dtype=np.float32)
    return np.where(v <= 0.0031308, v * 12.92,
                    1.055 * np.maximum(v, 0.0031308) ** (1 / 2.4) - 0.055).astype(np.float32)


def tile_preview(image, nx: int = 2, ny: int = 2) -> np.ndarray:
    """The image repeated ``nx`` times across and ``ny`` times down: a seam shows at once."""
    a = _as_image(image)
    return np.tile(a, (ny, nx, 1))

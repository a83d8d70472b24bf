"""EXIF test files built byte by byte: a TIFF structure, a JPEG holding one in its APP1 segment
with a frame header giving its size, the APP1 segment inserted into any JPEG, and WebP files
(RIFF chunks: a canvas or frame header giving the size, an EXIF chunk)."""

import struct

SHORT, LONG, RATIONAL = 3, 4, 5
ORIENTATION, EXIF_IFD, IMAGE_WIDTH, IMAGE_LENGTH = 0x0112, 0x8769, 0x0100, 0x0101
FOCAL_LENGTH, FOCAL_35MM = 0x920A, 0xA405
PIXEL_X, PIXEL_Y = 0xA002, 0xA003
FOCAL_PLANE_X, FOCAL_PLANE_UNIT = 0xA20E, 0xA210


def tiff(ifd0: dict, exif: dict, order: str = "<") -> bytes:
    """A TIFF structure: IFD0 (with a pointer to the Exif IFD when ``exif``) and the Exif IFD.
    Values are (type, value); rationals are (numerator, denominator)."""
    ifd0 = dict(ifd0)
    if exif:
        ifd0[EXIF_IFD] = (LONG, 0)  # patched below
    size0 = 2 + 12 * len(ifd0) + 4
    exif_at = 8 + size0
    data_at = exif_at + (2 + 12 * len(exif) + 4 if exif else 0)
    data = b""

    def entries(ifd):
        nonlocal data
        out = struct.pack(order + "H", len(ifd))
        for tag in sorted(ifd):
            kind, value = ifd[tag]
            if tag == EXIF_IFD:
                value = exif_at
            if kind == RATIONAL:
                field = struct.pack(order + "I", data_at + len(data))
                data += struct.pack(order + "II", *value)
            elif kind == SHORT:
                field = struct.pack(order + "HH", value, 0)
            else:
                field = struct.pack(order + "I", value)
            out += struct.pack(order + "HHI", tag, kind, 1) + field
        return out + struct.pack(order + "I", 0)

    header = (b"II*\x00" if order == "<" else b"MM\x00*") + struct.pack(order + "I", 8)
    body = entries(ifd0) + (entries(exif) if exif else b"")
    return header + body + data


def jpeg(width: int, height: int, ifd0: dict, exif: dict) -> bytes:
    """SOI, APP1 Exif, a baseline frame header of ``width`` x ``height``, EOI."""
    sof = b"\xff\xc0" + struct.pack(">HBHHB", 11, 8, height, width, 1) + b"\x01\x11\x00"
    return with_exif(b"\xff\xd8" + sof + b"\xff\xd9", ifd0, exif)


def with_exif(jpeg_bytes: bytes, ifd0: dict, exif: dict) -> bytes:
    """A JPEG file's bytes with an APP1 Exif segment inserted after its start marker."""
    payload = b"Exif\x00\x00" + tiff(ifd0, exif, ">")
    return jpeg_bytes[:2] + b"\xff\xe1" + struct.pack(">H", len(payload) + 2) + payload \
        + jpeg_bytes[2:]


def _chunk(fourcc: bytes, payload: bytes) -> bytes:
    """A RIFF chunk, padded to an even length."""
    return fourcc + struct.pack("<I", len(payload)) + payload + b"\x00" * (len(payload) & 1)


def webp(width: int, height: int, ifd0: dict | None = None, exif: dict | None = None, *,
         prefix: bytes = b"", frame: str = "VP8X") -> bytes:
    """A WebP file of ``width`` x ``height``: an extended file (``VP8X`` canvas, then an
    ``EXIF`` chunk holding ``prefix`` and the TIFF structure when ``ifd0`` or ``exif``), or a
    simple one (``frame`` ``"VP8 "`` or ``"VP8L"``: the frame header only, no pixels)."""
    if frame == "VP8X":
        flags = 0x08 if ifd0 or exif else 0
        chunks = _chunk(b"VP8X", bytes([flags, 0, 0, 0]) + (width - 1).to_bytes(3, "little")
                        + (height - 1).to_bytes(3, "little"))
        if ifd0 or exif:
            chunks += _chunk(b"EXIF", prefix + tiff(ifd0 or {}, exif or {}, "<"))
    elif frame == "VP8 ":
        chunks = _chunk(b"VP8 ", b"\x10\x02\x00\x9d\x01\x2a" + struct.pack("<HH", width, height))
    else:
        bits = (width - 1) | (height - 1) << 14
        chunks = _chunk(b"VP8L", b"\x2f" + struct.pack("<I", bits))
    return b"RIFF" + struct.pack("<I", 4 + len(chunks)) + b"WEBP" + chunks

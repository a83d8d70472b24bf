"""The focal length in pixels from a photo's EXIF, as cameras and phones write it.

The files are built here byte by byte (a TIFF structure, or a JPEG holding one in its APP1
segment and a frame header giving its size), so no image library and no shared photo is needed.
"""

import math
import struct

import pytest

import texsynth
from texsynth.plane import focal_px_from_file

SHORT, LONG, RATIONAL = 3, 4, 5
ORIENTATION, EXIF_IFD, IMAGE_WIDTH, IMAGE_LENGTH = 0x0112, 0x8769, 0x0100, 0x0101
FOCAL_LENGTH, FOCAL_35MM = 0x920A, 0xA405
PIXEL_X, PIXEL_Y = 0xA002, 0xA003
FOCAL_PLANE_X, FOCAL_PLANE_UNIT = 0xA20E, 0xA210


def _tiff(ifd0: dict, exif: dict, order: str = "<") -> bytes:
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


def _jpeg(width: int, height: int, ifd0: dict, exif: dict) -> bytes:
    """SOI, APP1 Exif, a baseline frame header of ``width`` x ``height``, EOI."""
    tiff = b"Exif\x00\x00" + _tiff(ifd0, exif, ">")
    app1 = b"\xff\xe1" + struct.pack(">H", len(tiff) + 2) + tiff
    sof = b"\xff\xc0" + struct.pack(">HBHHB", 11, 8, height, width, 1) + b"\x01\x11\x00"
    return b"\xff\xd8" + app1 + sof + b"\xff\xd9"


def test_focal_plane_resolution_gives_the_focal_length_of_the_stored_image(tmp_path):
    # A 4.2 mm lens on a 5.6 mm wide sensor recording 4000 px: f = 3000 px; the file holds the
    # photo resized to 2000 x 1500, so 1500 px.
    exif = {FOCAL_LENGTH: (RATIONAL, (42, 10)), FOCAL_PLANE_X: (RATIONAL, (400000, 56)),
            FOCAL_PLANE_UNIT: (SHORT, 3), PIXEL_X: (LONG, 4000), PIXEL_Y: (LONG, 3000),
            FOCAL_35MM: (SHORT, 99)}  # ignored: the focal plane resolution comes first
    path = tmp_path / "photo.jpg"
    path.write_bytes(_jpeg(4000, 3000, {}, exif))
    assert focal_px_from_file(path) == pytest.approx(3000.0)
    path.write_bytes(_jpeg(2000, 1500, {}, exif))
    assert focal_px_from_file(path) == pytest.approx(1500.0)
    assert texsynth.focal_px_from_file is focal_px_from_file


def test_orientation_matches_the_recorded_width_to_the_stored_side(tmp_path):
    # A portrait photo turned by a program: stored 1500 x 2000, camera sizes 4000 x 3000 kept,
    # Orientation 6 (rotated 90 deg). The recorded width is the stored height.
    exif = {FOCAL_LENGTH: (RATIONAL, (42, 10)), FOCAL_PLANE_X: (RATIONAL, (400000, 56)),
            FOCAL_PLANE_UNIT: (SHORT, 3), PIXEL_X: (LONG, 4000), PIXEL_Y: (LONG, 3000)}
    path = tmp_path / "turned.jpg"
    path.write_bytes(_jpeg(1500, 2000, {ORIENTATION: (SHORT, 6)}, exif))
    assert focal_px_from_file(path) == pytest.approx(1500.0)
    # Without the Orientation tag the sizes are taken as they are: the stored width.
    path.write_bytes(_jpeg(1500, 2000, {}, exif))
    assert focal_px_from_file(path) == pytest.approx(1125.0)


def test_35mm_equivalent_uses_the_diagonal(tmp_path):
    path = tmp_path / "phone.jpg"
    path.write_bytes(_jpeg(4032, 3024, {ORIENTATION: (SHORT, 1)},
                           {FOCAL_LENGTH: (RATIONAL, (399, 100)), FOCAL_35MM: (SHORT, 26)}))
    expected = 26 / math.hypot(36, 24) * math.hypot(4032, 3024)
    assert focal_px_from_file(path) == pytest.approx(expected)


def test_tiff_with_the_tags_in_ifd0(tmp_path):
    path = tmp_path / "scan.tif"
    path.write_bytes(_tiff({IMAGE_WIDTH: (LONG, 3000), IMAGE_LENGTH: (LONG, 2000),
                            FOCAL_35MM: (SHORT, 50)}, {}))
    assert focal_px_from_file(path) == pytest.approx(50 / math.hypot(36, 24)
                                                     * math.hypot(3000, 2000))


def test_files_that_do_not_say_give_none(tmp_path):
    bare = tmp_path / "bare.jpg"
    bare.write_bytes(_jpeg(640, 480, {ORIENTATION: (SHORT, 1)}, {PIXEL_X: (LONG, 640)}))
    assert focal_px_from_file(bare) is None
    absurd = tmp_path / "absurd.jpg"  # a zero focal length and an impossible field of view
    absurd.write_bytes(_jpeg(640, 480, {}, {FOCAL_LENGTH: (RATIONAL, (0, 1)),
                                            FOCAL_PLANE_X: (RATIONAL, (400, 1)),
                                            FOCAL_35MM: (SHORT, 60000)}))
    assert focal_px_from_file(absurd) is None
    png = tmp_path / "image.png"
    png.write_bytes(b"\x89PNG\r\n\x1a\n" + struct.pack(">I", 13) + b"IHDR"
                    + struct.pack(">IIBBBBB", 64, 64, 8, 2, 0, 0, 0))
    assert focal_px_from_file(png) is None


def test_a_missing_file_is_refused(tmp_path):
    with pytest.raises(ValueError, match="no image file"):
        focal_px_from_file(tmp_path / "nope.jpg")

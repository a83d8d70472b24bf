"""The focal length in pixels from a photo's EXIF, as cameras and phones write it.

The files are built byte by byte (tests/_exif.py), so no image library and no shared photo is
needed.
"""

import math
import struct

import pytest
from _exif import (
    FOCAL_35MM,
    FOCAL_LENGTH,
    FOCAL_PLANE_UNIT,
    FOCAL_PLANE_X,
    IMAGE_LENGTH,
    IMAGE_WIDTH,
    LONG,
    ORIENTATION,
    PIXEL_X,
    PIXEL_Y,
    RATIONAL,
    SHORT,
)
from _exif import (
    jpeg as _jpeg,
)
from _exif import (
    tiff as _tiff,
)
from _exif import (
    webp as _webp,
)

import texsynth
from texsynth.plane import focal_px_from_file

#: A NaN or an overflow in the estimate is garbage on its way out (issue 27): an error here.
pytestmark = pytest.mark.filterwarnings("error::RuntimeWarning")


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


def test_files_that_do_not_say_give_none(tmp_path, caplog):
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
    assert not caplog.records  # nothing printed: ExifRead's "no exif data" is not news


def test_a_missing_file_is_refused(tmp_path):
    with pytest.raises(ValueError, match="no image file"):
        focal_px_from_file(tmp_path / "nope.jpg")


@pytest.mark.parametrize("path", [None, 3, True, 1.5, ["a.jpg"], object()])
def test_a_path_that_is_no_path_is_a_value_error_as_promised(path):
    with pytest.raises(ValueError, match="path must be a file path"):
        focal_px_from_file(path)


def test_str_bytes_and_pathlike_paths_read_the_same(tmp_path):
    path = tmp_path / "phone.jpg"
    path.write_bytes(_jpeg(4000, 3000, {}, {FOCAL_35MM: (SHORT, 26)}))
    expected = 26 / math.hypot(36, 24) * 5000
    for given in (path, str(path), bytes(path)):
        assert focal_px_from_file(given) == pytest.approx(expected)
    for empty in ("", b"", str(tmp_path), "a\0b"):
        with pytest.raises(ValueError, match="no image file"):
            focal_px_from_file(empty)


@pytest.mark.parametrize("prefix", [b"", b"Exif\x00\x00"], ids=["spec", "exif-prefix"])
def test_a_webp_with_exif_gives_its_focal_length(tmp_path, prefix):
    # The container specification's EXIF chunk is the TIFF structure itself; some writers put
    # JPEG's "Exif\0\0" before it. Both are read, at the canvas size of the VP8X chunk.
    path = tmp_path / "photo.webp"
    path.write_bytes(_webp(640, 480, {}, {FOCAL_35MM: (SHORT, 26)}, prefix=prefix))
    assert focal_px_from_file(path) == pytest.approx(26 / math.hypot(36, 24) * 800)
    path.write_bytes(_webp(1600, 1200, {}, {FOCAL_LENGTH: (RATIONAL, (4, 1)),
                                            FOCAL_PLANE_X: (RATIONAL, (400, 1)),
                                            FOCAL_PLANE_UNIT: (SHORT, 4), PIXEL_X: (LONG, 3200),
                                            PIXEL_Y: (LONG, 2400)}, prefix=prefix))
    assert focal_px_from_file(path) == pytest.approx(4 * 400 * 1600 / 3200)


@pytest.mark.parametrize("frame", ["VP8X", "VP8 ", "VP8L"])
def test_a_webp_without_exif_gives_none(tmp_path, frame):
    path = tmp_path / "plain.webp"
    path.write_bytes(_webp(640, 480, frame=frame))
    assert focal_px_from_file(path) is None


def test_a_damaged_exif_block_says_nothing(tmp_path):
    good = _jpeg(640, 480, {}, {FOCAL_35MM: (SHORT, 26)})
    path = tmp_path / "damaged.jpg"
    path.write_bytes(good[:30] + b"\xff" * 40 + good[70:])
    assert focal_px_from_file(path) is None

"""texsynth.io's codecs: PNG and OpenEXR files, sRGB transfer, tiled previews (no bpy)."""

import struct
import zlib

import numpy as np
import pytest

from texsynth import io
from texsynth.blocks import color, periodic


def _image(h, w, c, seed=0):
    return np.random.default_rng(seed).random((h, w, c), dtype=np.float32)


@pytest.mark.parametrize("channels", [1, 3, 4])
@pytest.mark.parametrize("bits", [8, 16])
def test_png_round_trip_is_exact_at_its_bit_depth(tmp_path, channels, bits):
    top = (1 << bits) - 1
    a = np.round(_image(7, 11, channels) * top) / top
    path = tmp_path / "a.png"
    io.write_png(path, a, bits=bits)
    b = io.read_png(path)
    assert b.shape == (7, 11, channels) and b.dtype == np.float32
    np.testing.assert_allclose(b, a, atol=1e-7)


def test_png_write_clips_and_quantizes(tmp_path):
    io.write_png(tmp_path / "a.png", np.array([[-1.0, 0.5, 2.0]], np.float32))
    np.testing.assert_allclose(io.read_png(tmp_path / "a.png")[0, :, 0] * 255, [0, 128, 255])


def _png_with_filters(rows: np.ndarray, bpp: int, colour_type: int, bits: int = 8) -> bytes:
    """A PNG whose row y uses filter type y % 5 (a reference encoder, byte by byte)."""
    h, n = rows.shape
    prior = np.zeros(n, np.int64)
    out = bytearray()
    for y in range(h):
        kind, row = y % 5, rows[y].astype(np.int64)
        left = np.concatenate([np.zeros(bpp, np.int64), row[:-bpp]])
        up_left = np.concatenate([np.zeros(bpp, np.int64), prior[:-bpp]])
        if kind == 4:
            p = left + prior - up_left
            pa, pb, pc = abs(p - left), abs(p - prior), abs(p - up_left)
            pred = np.where((pa <= pb) & (pa <= pc), left, np.where(pb <= pc, prior, up_left))
        else:
            pred = [np.zeros(n, np.int64), left, prior, (left + prior) // 2][kind]
        out.append(kind)
        out.extend(((row - pred) % 256).astype(np.uint8).tobytes())
        prior = row
    w = n // bpp
    ihdr = struct.pack(">IIBBBBB", w, h, bits, colour_type, 0, 0, 0)

    def chunk(kind, data):
        crc = struct.pack(">I", zlib.crc32(kind + data))
        return struct.pack(">I", len(data)) + kind + data + crc

    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", ihdr) + chunk(b"IDAT", zlib.compress(bytes(out)))
            + chunk(b"IEND", b""))


@pytest.mark.parametrize("colour_type, channels, bits", [(2, 3, 8), (6, 4, 8), (0, 1, 16)])
def test_png_reader_undoes_every_filter(tmp_path, colour_type, channels, bits):
    h, w = 10, 9
    bpp = channels * bits // 8
    rows = np.random.default_rng(1).integers(0, 256, (h, w * bpp)).astype(np.uint8)
    path = tmp_path / "f.png"
    path.write_bytes(_png_with_filters(rows, bpp, colour_type, bits))
    dtype = ">u2" if bits == 16 else "u1"
    expected = rows.view(dtype).reshape(h, w, channels) / ((1 << bits) - 1)
    np.testing.assert_allclose(io.read_png(path), expected, atol=1e-7)


def test_png_grey_alpha_becomes_rgba(tmp_path):
    rows = np.array([[10, 200, 30, 40]], np.uint8)  # two grey + alpha pixels
    path = tmp_path / "ga.png"
    path.write_bytes(_png_with_filters(rows, 2, colour_type=4))
    np.testing.assert_allclose(io.read_png(path)[0] * 255, [[10, 10, 10, 200], [30, 30, 30, 40]])


def test_png_unsupported_kinds_say_so(tmp_path):
    path = tmp_path / "p.png"
    path.write_bytes(_png_with_filters(np.zeros((2, 2), np.uint8), 1, colour_type=3))
    with pytest.raises(ValueError, match="unsupported PNG.*colour type 3"):
        io.read_png(path)
    path.write_bytes(b"GIF89a")
    with pytest.raises(ValueError, match="not a PNG"):
        io.read_png(path)
    with pytest.raises(ValueError, match="8 or 16"):
        io.write_png(path, np.zeros((2, 2)), bits=4)


@pytest.mark.parametrize("channels", [1, 3, 4])
def test_exr_round_trip_is_bit_exact(tmp_path, channels):
    a = (_image(5, 13, channels) - 0.25) * 40.0  # negative and HDR values too
    io.write_exr(tmp_path / "a.exr", a)
    b = io.read_exr(tmp_path / "a.exr")
    assert b.dtype == np.float32
    np.testing.assert_array_equal(b, a)


def test_a_cut_short_exr_is_one_error_and_no_library_lines(tmp_path, capfd):
    io.write_exr(tmp_path / "a.exr", _image(32, 48, 3))
    (tmp_path / "a.exr").write_bytes((tmp_path / "a.exr").read_bytes()[:400])
    with pytest.raises(ValueError, match="a.exr: not a readable OpenEXR file"):
        io.read_exr(tmp_path / "a.exr")
    assert capfd.readouterr().err == ""  # OpenEXR's C library said it three times on fd 2


def test_read_photo_tells_formats_by_content(tmp_path):
    a = _image(4, 6, 3)
    io.write_exr(tmp_path / "x.png", a)  # misleading extension
    np.testing.assert_array_equal(io.read_photo(tmp_path / "x.png"), a)
    (tmp_path / "y.exr").write_bytes(b"no image at all")
    with pytest.raises(io.ImageReadError, match="y.exr: not a readable image"):
        io.read_photo(tmp_path / "y.exr")


def test_bad_shapes_are_refused(tmp_path):
    for bad in (np.zeros((4, 4, 2)), np.zeros(5), np.zeros((0, 4, 3))):
        with pytest.raises(ValueError, match=r"^image (must be \(H, W\)|must have 1, 3|is 4 x 0)"):
            io.write_exr(tmp_path / "b.exr", bad)


def test_srgb_transfer_round_trip_and_known_values():
    v = np.linspace(0, 4, 401, dtype=np.float32)
    np.testing.assert_allclose(color.linear_to_srgb(color.srgb_to_linear(v)), v, atol=2e-6)
    np.testing.assert_allclose(color.srgb_to_linear([0.0, 0.04045, 0.5, 1.0]),
                               [0.0, 0.04045 / 12.92, 0.21404114, 1.0], rtol=1e-5)


def test_tile_preview_repeats_the_image():
    a = _image(3, 5, 3)
    t = periodic.tile_preview(a, 2, 3)
    assert t.shape == (9, 10, 3)
    np.testing.assert_array_equal(t[6:, 5:], a)
    assert periodic.tile_preview(a[:, :, 0]).shape == (6, 10, 1)

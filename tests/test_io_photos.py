"""texsynth.io as photos come: upright, sizes from headers, clear errors, every output format,
atomic writes (no bpy)."""

import errno
import os

import numpy as np
import pytest
from PIL import Image, ImageOps

from texsynth import io
from texsynth.blocks.resample import resample
from texsynth.io import files, png


def _photo(h=12, w=20, seed=0):
    """8-bit RGB values with a bright top-left corner (where upright shows)."""
    a = np.random.default_rng(seed).integers(0, 200, (h, w, 3)).astype(np.uint8)
    a[:3, :5] = 255
    return a


def _save(path, array, orientation=1, **kwargs):
    exif = Image.Exif()
    if orientation != 1:
        exif[274] = orientation
    Image.fromarray(array).save(path, exif=exif.tobytes(), **kwargs)


def test_portrait_phone_jpeg_reads_upright(tmp_path):
    stored = _photo()  # landscape, as the sensor read it
    path = tmp_path / "IMG_0001.jpg"
    _save(path, stored, orientation=6, quality=95)
    photo = io.read_photo(path)
    assert photo.shape == (20, 12, 3)  # portrait
    # turned clockwise: the stored top rows are the right columns, its left columns the top rows
    assert photo[1:4, -2:].mean() > 0.95 and photo[1:4, :2].mean() < 0.6
    assert io.image_size(path) == (12, 20, 3)


@pytest.mark.parametrize("orientation", range(1, 9))
@pytest.mark.parametrize("suffix, options", [
    (".png", {}), (".tif", {}), (".tif", {"compression": "tiff_lzw"}),  # own codecs; Pillow
    (".webp", {"lossless": True}), (".jpg", {"quality": 95})])
def test_every_orientation_as_pillow_shows_it(tmp_path, orientation, suffix, options):
    stored = _photo(5, 7)
    path = tmp_path / f"o{suffix}"
    _save(path, stored, orientation, **options)
    with Image.open(path) as im:
        shown = np.asarray(ImageOps.exif_transpose(im).convert("RGB"))
    np.testing.assert_array_equal(np.rint(io.read_photo(path) * 255), shown)
    assert io.exif_orientation(path) == orientation
    assert io.image_size(path) == (shown.shape[1], shown.shape[0], 3)


@pytest.mark.parametrize("suffix, channels, bits", [
    (".png", 1, 16), (".png", 4, 8), (".exr", 3, 8), (".tif", 3, 16), (".tiff", 4, 8),
    (".tif", 1, 8), (".jpg", 3, 8), (".jpeg", 1, 8)])
def test_round_trips_by_suffix_and_image_size_agrees(tmp_path, suffix, channels, bits):
    top = (1 << bits) - 1
    a = np.round(np.random.default_rng(1).random((9, 13, channels), np.float32) * top) / top
    path = tmp_path / f"a{suffix}"
    io.write_image(path, a, bits=bits)
    b = io.read_photo(path)
    assert b.shape == a.shape and b.dtype == np.float32 and b.flags.c_contiguous
    assert io.image_size(path) == (13, 9, channels)
    if suffix in (".jpg", ".jpeg"):
        assert np.abs(b - a).mean() < 0.03  # lossy, quality 95
    else:
        np.testing.assert_allclose(b, a, atol=1e-7)
    if suffix != ".exr":
        assert io.png_bits(path) == (8 if suffix in (".jpg", ".jpeg") else bits)


def test_jpeg_drops_alpha_and_tiff_is_read_by_pillow_too(tmp_path):
    a = np.random.default_rng(2).random((6, 8, 4), np.float32)
    io.write_image(tmp_path / "a.jpg", a)
    assert io.read_photo(tmp_path / "a.jpg").shape == (6, 8, 3)
    io.write_image(tmp_path / "a.tif", a, bits=8)
    with Image.open(tmp_path / "a.tif") as im:  # the own TIFF writer, read by libtiff
        np.testing.assert_array_equal(np.asarray(im), np.rint(a * 255))


@pytest.mark.parametrize("name, mode, options", [
    ("palette.png", "P", {}), ("interlaced.png", "RGB", {"interlace": 1}),
    ("lzw.tif", "RGB", {"compression": "tiff_lzw"}), ("cmyk.tif", "CMYK", {}),
    ("grey-alpha.tif", "LA", {}), ("photo.webp", "RGBA", {"lossless": True})])
def test_kinds_the_own_codecs_leave_to_pillow(tmp_path, name, mode, options):
    path = tmp_path / name
    Image.fromarray(_photo(6, 9)).convert(mode).save(path, **options)
    a = io.read_photo(path)
    assert io.image_size(path) == (a.shape[1], a.shape[0], a.shape[2])
    assert a.shape[:2] == (6, 9) and a.dtype == np.float32


def test_16_bit_tiff_with_predictor_is_read_exactly(tmp_path):
    q = np.random.default_rng(3).integers(0, 65536, (5, 6)).astype(np.uint16)
    Image.fromarray(q).save(tmp_path / "p.tif", compression="tiff_adobe_deflate", predictor=2)
    np.testing.assert_array_equal(io.read_photo(tmp_path / "p.tif")[:, :, 0] * 65535, q)


def _truncated_png(path):
    io.write_image(path, _photo() / 255.0)
    data = path.read_bytes()
    path.write_bytes(data[:len(data) - 30])


def _bad_chunk_png(path):
    io.write_image(path, _photo() / 255.0)
    data = bytearray(path.read_bytes())
    data[45] ^= 0xFF  # a byte of the IDAT chunk: its CRC no longer holds
    path.write_bytes(bytes(data))


def _png_bad_zlib(path):
    ihdr = png.struct.pack(">IIBBBBB", 2, 2, 8, 2, 0, 0, 0)
    path.write_bytes(png.SIGNATURE + png._png_chunk(b"IHDR", ihdr)
                     + png._png_chunk(b"IDAT", b"not zlib") + png._png_chunk(b"IEND", b""))


def _truncated_jpeg(path):
    _save(path, _photo(64, 64))
    data = path.read_bytes()
    path.write_bytes(data[:len(data) // 2])


DAMAGED = {
    "zero-byte.png": (lambda p: p.write_bytes(b""), "empty"),
    "truncated.png": (_truncated_png, "truncated"),
    "bad-chunk.png": (_bad_chunk_png, "CRC"),
    "bad-zlib.png": (_png_bad_zlib, "corrupt"),
    "magic-only.exr": (lambda p: p.write_bytes(b"\x76\x2f\x31\x01"), "OpenEXR"),
    "truncated.jpg": (_truncated_jpeg, "readable"),
    "not-an-image.jpg": (lambda p: p.write_text("hello"), "readable"),
    "header-only.tif": (lambda p: p.write_bytes(b"II*\x00"), "damaged"),
}


@pytest.mark.parametrize("name", DAMAGED)
def test_damaged_files_raise_image_read_error_naming_the_file(tmp_path, name):
    make, says = DAMAGED[name]
    path = tmp_path / name
    make(path)
    with pytest.raises(io.ImageReadError, match=f"{name}.*{says}") as caught:
        io.read_photo(path)
    assert isinstance(caught.value, ValueError)


def test_missing_folder_unreadable_and_nan(tmp_path, monkeypatch):
    with pytest.raises(FileNotFoundError, match="no.png: no such file"):
        io.read_photo(tmp_path / "no.png")
    with pytest.raises(FileNotFoundError):
        io.image_size(tmp_path / "no.png")
    with pytest.raises(io.ImageReadError, match="is a folder, not an image file"):
        io.read_photo(tmp_path)
    with pytest.raises(io.ImageReadError, match="is a folder"):
        io.image_size(tmp_path)
    path = tmp_path / "locked.png"
    io.write_image(path, np.zeros((2, 2, 3), np.float32))

    def refuse(*args, **kwargs):
        raise PermissionError(errno.EACCES, "Permission denied")

    with monkeypatch.context() as m:  # as root, chmod 000 would not refuse
        m.setattr("builtins.open", refuse)
        with pytest.raises(io.ImageReadError, match="locked.png: cannot be read"):
            io.read_photo(path)
    a = np.ones((3, 4, 3), np.float32)
    a[0, 0, 0], a[1, 2, 1] = np.nan, np.inf
    io.write_exr(tmp_path / "nan.exr", a)
    with pytest.raises(io.ImageReadError, match="nan.exr: 2 of 36 values are NaN or infinite"):
        io.read_photo(tmp_path / "nan.exr")


def test_output_format_is_checked_before_any_work(tmp_path):
    assert [io.output_format(f"a{s}") for s in (".PNG", ".exr", ".jpg", ".TIFF")] == \
        ["png", "exr", "jpeg", "tiff"]
    with pytest.raises(ValueError, match=r"'\.webp'.*\.png, \.exr, \.jpg, \.jpeg, \.tif"):
        io.write_image(tmp_path / "a.webp", np.zeros((2, 2, 3)))
    assert not list(tmp_path.iterdir())


@pytest.mark.parametrize("suffix, codec", [(".png", "png.write_png"), (".tif", "tiff.write_tiff"),
                                           (".exr", "exr.write_exr")])
def test_a_full_disk_leaves_no_temporary_file_and_the_old_target(tmp_path, monkeypatch,
                                                                 suffix, codec):
    target = tmp_path / f"out{suffix}"
    io.write_image(target, np.zeros((4, 4, 3), np.float32))
    before = target.read_bytes()
    module, name = codec.split(".")

    def full_disk(path, *args, **kwargs):
        with open(path, "wb") as f:
            f.write(b"partial")
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))

    monkeypatch.setattr(getattr(files, module), name, full_disk)
    with pytest.raises(OSError) as caught:
        io.write_image(target, np.ones((4, 4, 3), np.float32))
    assert caught.value.errno == errno.ENOSPC
    assert [p.name for p in tmp_path.iterdir()] == [target.name]
    assert target.read_bytes() == before


def test_exr_write_errors_are_os_errors(tmp_path):
    with pytest.raises(OSError, match="OpenEXR could not write"):
        io.write_exr(tmp_path / "missing folder" / "a.exr", np.zeros((2, 2, 3)))



@pytest.mark.parametrize("channels", [1, 2, 4])
@pytest.mark.parametrize("size", [(50, 37), (23, 71), (160, 90)])  # smaller, mixed, larger
def test_resample_keeps_the_mean_and_the_channels(channels, size):
    a = np.random.default_rng(4).random((60, 80, channels), np.float32) * 3.0
    b = resample(a, *size)
    assert b.shape == (size[1], size[0], channels) and b.dtype == np.float32
    np.testing.assert_allclose(b.mean(axis=(0, 1)), a.mean(axis=(0, 1)), rtol=1e-5)
    np.testing.assert_allclose(resample(a, 40, 30), a.reshape(30, 2, 40, 2, channels)
                               .mean(axis=(1, 3)), rtol=1e-5)  # a whole factor: block means
    assert b.min() >= a.min() - 1e-6 and b.max() <= a.max() + 1e-6  # averages: no ringing

"""Image files for the core and for scripts: one reader, one writer, and the codecs under them.

Arrays are float32 (H, W, C), top row first, C in 1, 3, 4. :func:`read_photo` reads any photo
upright (PNG, OpenEXR, TIFF, JPEG, WebP...), :func:`image_size` its size from the headers,
:func:`write_image` writes PNG, OpenEXR, JPEG or TIFF by suffix, atomically
(:mod:`texsynth.io.files`). EXR holds linear values as they are (:mod:`texsynth.io.exr`); PNG
and TIFF hold encoded values in [0, 1] (sRGB for colour images), quantized to 8 or 16 bits
(:mod:`texsynth.io.png`, :mod:`texsynth.io.tiff`). The EXIF orientation is
:mod:`texsynth.io.orientation`; the sRGB transfer lives with the other colour maths in
:mod:`texsynth.blocks.color`.
"""

from .exr import read_exr, write_exr
from .files import (
    SUFFIXES,
    TEMP_PREFIX,
    ImageReadError,
    ImageWriteError,
    check_finite,
    encode,
    image_size,
    is_linear,
    output_format,
    png_bits,
    read_photo,
    temp_prefix,
    write_image,
    write_images,
)
from .orientation import exif_orientation, orient
from .png import read_png, write_png

__all__ = ["read_photo", "image_size", "check_finite", "ImageReadError", "ImageWriteError",
           "write_image", "write_images", "output_format", "png_bits", "is_linear", "encode",
           "SUFFIXES", "TEMP_PREFIX", "exif_orientation", "orient", "read_exr", "write_exr",
           "read_png", "write_png", "temp_prefix"]

"""The new image datablock: packed into the .blend, or saved as OpenEXR or PNG and loaded.

Files are written by ``texsynth.io`` (OpenEXR: exact float32; PNG: 8-bit) under a name that
exists nowhere yet, so no file, least of all the source image's, is ever overwritten.
"""

import os
from dataclasses import dataclass

import bpy
import numpy as np

from ..texsynth import io
from . import pixels

EXTENSIONS = {"EXR": ".exr", "PNG": ".png"}


@dataclass(frozen=True)
class Target:
    """Where a result goes: ``output`` is 'PACK', 'EXR' or 'PNG'."""

    output: str
    directory: str  # absolute; unused for 'PACK'
    relative: bool  # store the image's path relative to the .blend
    stem: str  # base of the image and file names


def plan(output: str, output_dir: str, image_name: str, method: str, seed: int) -> Target:
    """Check the output settings before any work; raises ``ValueError`` with what to fix."""
    stem = f"{bpy.path.clean_name(os.path.splitext(image_name)[0])}_{method}_{seed}"
    if output == "PACK":
        return Target(output, "", False, stem)
    relative = not output_dir or output_dir.startswith("//")
    if relative and not bpy.data.filepath:
        raise ValueError("The output directory is relative to the .blend file, which is not saved "
                         "yet: save it first or choose an absolute directory")
    directory = bpy.path.abspath(output_dir or "//")
    if os.path.exists(directory) and not os.path.isdir(directory):
        raise ValueError(f"Output directory '{directory}' is a file")
    return Target(output, directory, relative, stem)


def create_image(result: np.ndarray, encoding: pixels.Encoding, target: Target):
    """A new image holding ``result``; the file (if any) is written before any datablock."""
    as_float = target.output == "EXR" or (target.output == "PACK" and encoding.is_float)
    values, colorspace = (pixels.as_float if as_float else pixels.as_bytes)(result, encoding)
    if target.output == "PACK":
        return _packed_image(target.stem, values, as_float, colorspace)
    os.makedirs(target.directory, exist_ok=True)
    path = _free_path(os.path.join(target.directory, target.stem), EXTENSIONS[target.output])
    stored = values if (values[:, :, 3] < 1).any() else values[:, :, :3]  # alpha only if used
    if target.output == "EXR":
        io.write_exr(path, stored)
    else:
        io.write_png(path, stored, bits=8)
    image = bpy.data.images.load(path, check_existing=False)
    if colorspace:
        image.colorspace_settings.name = colorspace
    if target.relative:
        image.filepath = bpy.path.relpath(path)
    return image


def _packed_image(name, values, as_float, colorspace):
    height, width = values.shape[:2]
    image = bpy.data.images.new(name, width, height, alpha=True, float_buffer=as_float)
    if colorspace:
        image.colorspace_settings.name = colorspace
    pixels.set_pixels(image, values)
    image.pack()
    return image


def _free_path(base: str, extension: str) -> str:
    path, n = base + extension, 1
    while os.path.exists(path):
        path, n = f"{base}_{n}{extension}", n + 1
    return path

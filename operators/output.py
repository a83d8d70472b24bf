"""The new image datablock: packed into the .blend, or saved as OpenEXR or PNG and loaded.

Files are written by ``texsynth.io`` (OpenEXR: exact float32; PNG: 8-bit) under a name that
exists nowhere yet, so no file, least of all the source image's, is ever overwritten.
"""

import os
from dataclasses import dataclass

import bpy
import numpy as np

from ..texsynth import budget, io
from . import pixels

EXTENSIONS = {"EXR": ".exr", "PNG": ".png"}
#: Seconds per megapixel on the reference machine (``texsynth.budget``) of Blender's side of
#: a run: reading the source's pixels, and encoding and storing the result (Blender's PNG
#: compression for a packed image, ``texsynth.io`` for files). Measured on a 4000 x 3000 photo:
#: 0.4-0.6 s to read, 3.5-4.6 s to pack, 4.4-6 s for a PNG, 6-9 s for an OpenEXR file.
READ_SECONDS = 0.05
STORE_SECONDS = {"PACK": 0.35, "PNG": 0.45, "EXR": 0.6}


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


def predict_seconds(source_pixels: int, result_pixels: int, output: str) -> float:
    """Seconds on this machine to read a source of ``source_pixels`` out of Blender and store a
    result of ``result_pixels`` in ``output``: what a run takes besides the core's work."""
    return (READ_SECONDS * source_pixels + STORE_SECONDS[output] * result_pixels) / 1e6 \
        * budget.machine_factor()


def create_image(result: np.ndarray, encoding: pixels.Encoding, target: Target):
    """A new image holding ``result``; the file (if any) is written before any datablock."""
    as_float = target.output == "EXR" or (target.output == "PACK" and encoding.is_float)
    if target.output == "PACK":
        return _packed_image(target.stem, result, encoding, as_float)
    os.makedirs(target.directory, exist_ok=True)
    path = _free_path(os.path.join(target.directory, target.stem), EXTENSIONS[target.output])
    alpha = result.shape[2] == 4 and bool((result[:, :, 3] < 1).any())  # alpha only if used
    values = np.empty(result.shape[:2] + (4 if alpha else 3,), np.float32)
    colorspace = pixels.encode(result, encoding, as_float, values)
    if target.output == "EXR":
        io.write_exr(path, values)
    else:
        io.write_png(path, values, bits=8)
    del values
    image = bpy.data.images.load(path, check_existing=False)
    if colorspace:
        image.colorspace_settings.name = colorspace
    if target.relative:
        image.filepath = bpy.path.relpath(path)
    return image


def _packed_image(name, result, encoding, as_float):
    """A new image packed into the .blend, its pixels encoded straight into Blender's order."""
    height, width = result.shape[:2]
    flat, values = pixels.blender_order(height, width)
    colorspace = pixels.encode(result, encoding, as_float, values)
    # Without alpha in the result, Blender packs RGB only: a quarter less to compress.
    image = bpy.data.images.new(name, width, height, alpha=result.shape[2] == 4,
                                float_buffer=as_float)
    if colorspace:
        image.colorspace_settings.name = colorspace
    image.pixels.foreach_set(flat)
    del flat, values
    image.pack()
    return image


def _free_path(base: str, extension: str) -> str:
    path, n = base + extension, 1
    while os.path.exists(path):
        path, n = f"{base}_{n}{extension}", n + 1
    return path

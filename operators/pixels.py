"""Blender image pixels to and from the arrays texsynth works on.

How Blender hands out ``Image.pixels`` decides the colour handling:

* byte images (8-bit files): the stored values / 255, still encoded in the image's colour space
  (an sRGB photo gives sRGB-encoded values), alpha straight;
* float images (16-bit PNG, EXR, HDR, float buffers): scene-linear values with the colour space
  already applied on load (raw values for Non-Color data), colour premultiplied by alpha.

texsynth synthesizes the values as Blender hands them out, so the result has the source's
encoding and looks the same. Grey images (R = G = B) are synthesized as one channel, and an
opaque alpha is dropped and restored. A result is stored either as bytes (same colour space as
a byte source; float sources are encoded to sRGB, or kept as they are when Non-Color) or as
floats (scene-linear, premultiplied: sRGB bytes are decoded on the way; bytes in another colour
space, Non-Color included, keep their values and their colour-space tag, so Blender converts
them on load).

Images of many megapixels: Blender hands out and takes pixels as one flat float32 array,
bottom row first, through ``foreach_get``/``foreach_set``. Each way makes that one array and
no other of the image's size: the exemplar is turned top row first and cut to its channels in
place, and a result is encoded into the array Blender takes, a block of rows at a time (the
colour maths' temporaries are a block's, not an image's).
"""

from dataclasses import dataclass

import numpy as np

from ..texsynth.blocks import color

SUPPORTED_SOURCES = {"FILE", "GENERATED"}
#: Values per block of rows when pixels are turned or encoded (about 1 MB of float32).
BLOCK = 1 << 18


@dataclass(frozen=True)
class Encoding:
    """How an exemplar's values relate to colour."""

    is_float: bool  # scene-linear premultiplied floats; otherwise stored byte values
    colorspace: str  # the source image's colour space name
    is_data: bool  # Non-Color data: never converted


def read_exemplar(image) -> tuple[np.ndarray, Encoding]:
    """The image's pixels as float32 (H, W, C), top row first, C in 1, 3, 4.

    Raises ``ValueError`` when the image has no pixel data (a missing file) or is not a still.
    """
    if image.source not in SUPPORTED_SOURCES:
        raise ValueError(f"Image '{image.name}' is a {image.source.lower()}; "
                         "only single still images can be synthesized from")
    width, height = image.size  # reading the size loads the pixels if needed
    if not image.has_data or width * height == 0:
        where = f" (file '{image.filepath}' missing or unreadable)" if image.filepath else ""
        raise ValueError(f"Image '{image.name}' has no pixel data{where}")
    buffer = np.empty(len(image.pixels), np.float32)
    image.pixels.foreach_get(buffer)
    keep = _significant_channels(buffer.reshape(height, width, -1))
    encoding = Encoding(bool(image.is_float), image.colorspace_settings.name,
                        bool(image.colorspace_settings.is_data))
    return _top_first(buffer, height, width, keep), encoding


def _significant_channels(pixels: np.ndarray) -> int:
    """How many channels carry information: 4 with a varying alpha, 1 for grey, else 3."""
    channels = pixels.shape[2]
    if channels == 4 and not (pixels[:, :, 3] == 1).all():
        return 4
    if channels == 1 or (np.array_equal(pixels[:, :, 0], pixels[:, :, 1])
                         and np.array_equal(pixels[:, :, 0], pixels[:, :, 2])):
        return 1
    return min(channels, 3)


def _top_first(buffer: np.ndarray, height: int, width: int, keep: int) -> np.ndarray:
    """``buffer``'s bottom-row-first pixels as C-contiguous (H, W, keep), top row first, made
    inside ``buffer`` (rows swapped in blocks, then channels packed forward: each block's
    values land at or before where they were read, behind the blocks still to read) and
    ``buffer`` shrunk to them."""
    rows = buffer.reshape(height, -1)
    step = max(1, BLOCK // rows.shape[1])
    half = height // 2
    for top in range(0, half, step):
        end = min(top + step, half)
        upper = rows[top:end].copy()
        rows[top:end] = rows[height - end:height - top][::-1]
        rows[height - end:height - top] = upper[::-1]
    channels = rows.shape[1] // width
    if keep < channels:
        pixels = rows.reshape(height, width, channels)
        packed = buffer[:height * width * keep].reshape(height, width, keep)
        for top in range(0, height, step):
            packed[top:top + step] = pixels[top:top + step, :, :keep]  # numpy handles overlap
        del rows, pixels, packed  # no view may outlive the shrink
        buffer.resize(height * width * keep, refcheck=False)
    return buffer.reshape(height, width, keep)


def blender_order(height: int, width: int) -> tuple[np.ndarray, np.ndarray]:
    """A flat float32 array for ``foreach_set`` of an (H, W) RGBA image, and its (H, W, 4)
    top-row-first view to write into."""
    flat = np.empty(height * width * 4, np.float32)
    return flat, flat.reshape(height, width, 4)[::-1]


def encode(result: np.ndarray, encoding: Encoding, as_float: bool, out: np.ndarray) -> str | None:
    """Write ``result`` (H, W, C), C in 1, 3, 4, into ``out`` (H, W, 3 or 4, any strides) as a
    float image's values (premultiplied, scene-linear: ``as_float``) or a byte image's (straight
    alpha, encoded, in [0, 1]); returns the new image's colour space (None: scene linear).

    Grey is repeated into R, G, B; a missing alpha is opaque; ``out`` without alpha takes the
    colour only.
    """
    step = max(1, BLOCK // (result.shape[1] * 4))
    for top in range(0, result.shape[0], step):
        rows = result[top:top + step]
        rgb = rows[:, :, :1] if rows.shape[2] == 1 else rows[:, :, :3]
        alpha = rows[:, :, 3:] if rows.shape[2] == 4 else np.float32(1.0)
        rgb, alpha, colorspace = (_as_float if as_float else _as_bytes)(rgb, alpha, encoding)
        out[top:top + step, :, :3] = rgb
        if out.shape[2] == 4:
            out[top:top + step, :, 3:] = alpha
    return colorspace


def _as_float(rgb, alpha, encoding):
    """Premultiplied scene-linear colour of one block, its alpha and the colour space."""
    if encoding.is_float:
        return rgb, alpha, "Non-Color" if encoding.is_data else None
    rgb, alpha = np.clip(rgb, 0.0, 1.0), np.clip(alpha, 0.0, 1.0)
    if encoding.colorspace == "sRGB":
        rgb, colorspace = color.srgb_to_linear(rgb), None
    else:
        colorspace = encoding.colorspace
    return rgb * alpha, alpha, colorspace


def _as_bytes(rgb, alpha, encoding):
    """Straight-alpha encoded colour of one block in [0, 1], its alpha and the colour space."""
    if not encoding.is_float:
        return np.clip(rgb, 0.0, 1.0), np.clip(alpha, 0.0, 1.0), encoding.colorspace
    if np.ndim(alpha):
        rgb = np.divide(rgb, alpha, out=np.zeros(np.broadcast_shapes(rgb.shape, alpha.shape),
                                                 np.float32), where=alpha > 0)
    if encoding.is_data:
        colorspace = "Non-Color"
    else:
        rgb, colorspace = color.linear_to_srgb(np.maximum(rgb, 0.0)), "sRGB"
    return np.clip(rgb, 0.0, 1.0), np.clip(alpha, 0.0, 1.0), colorspace

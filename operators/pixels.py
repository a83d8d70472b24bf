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
"""

from dataclasses import dataclass

import numpy as np

from ..texsynth.blocks import color

SUPPORTED_SOURCES = {"FILE", "GENERATED"}


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
    pixels = buffer.reshape(height, width, -1)[::-1]
    encoding = Encoding(bool(image.is_float), image.colorspace_settings.name,
                        bool(image.colorspace_settings.is_data))
    return np.ascontiguousarray(_significant_channels(pixels)), encoding


def _significant_channels(pixels: np.ndarray) -> np.ndarray:
    channels = pixels.shape[2]
    if channels == 4 and not (pixels[:, :, 3] == 1).all():
        return pixels
    if channels == 1 or (np.array_equal(pixels[:, :, 0], pixels[:, :, 1])
                         and np.array_equal(pixels[:, :, 0], pixels[:, :, 2])):
        return pixels[:, :, :1]
    return pixels[:, :, :3]


def to_rgba(result: np.ndarray) -> np.ndarray:
    """(H, W, C) with C in 1, 3, 4 as (H, W, 4): grey repeated, missing alpha opaque."""
    rgb = np.repeat(result[:, :, :1], 3, axis=2) if result.shape[2] == 1 else result[:, :, :3]
    if result.shape[2] == 4:
        alpha = result[:, :, 3:]
    else:
        alpha = np.ones(result.shape[:2] + (1,), np.float32)
    return np.concatenate([rgb, alpha], axis=2).astype(np.float32)


def as_float(result: np.ndarray, encoding: Encoding) -> tuple[np.ndarray, str | None]:
    """Premultiplied floats for a float image, and its colour space (None: scene linear)."""
    rgba = to_rgba(result)
    if encoding.is_float:
        return rgba, "Non-Color" if encoding.is_data else None
    rgba = np.clip(rgba, 0.0, 1.0)
    if encoding.colorspace == "sRGB":
        rgba[:, :, :3] = color.srgb_to_linear(rgba[:, :, :3])
        colorspace = None
    else:
        colorspace = encoding.colorspace
    rgba[:, :, :3] *= rgba[:, :, 3:]
    return rgba, colorspace


def as_bytes(result: np.ndarray, encoding: Encoding) -> tuple[np.ndarray, str]:
    """Straight-alpha encoded values in [0, 1] for a byte image or PNG, and its colour space."""
    rgba = to_rgba(result)
    if not encoding.is_float:
        return np.clip(rgba, 0.0, 1.0), encoding.colorspace
    alpha = rgba[:, :, 3:]
    rgb = np.divide(rgba[:, :, :3], alpha, out=np.zeros_like(rgba[:, :, :3]), where=alpha > 0)
    if encoding.is_data:
        colorspace = "Non-Color"
    else:
        rgb, colorspace = color.linear_to_srgb(np.maximum(rgb, 0.0)), "sRGB"
    rgba = np.concatenate([rgb, alpha], axis=2)
    return np.clip(rgba, 0.0, 1.0), colorspace


def set_pixels(image, rgba: np.ndarray) -> None:
    """Write (H, W, 4) top-row-first values into an image of that size."""
    image.pixels.foreach_set(np.ascontiguousarray(rgba[::-1], np.float32).ravel())

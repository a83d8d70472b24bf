"""The maps of ``texsynth.break_repetition`` copied out of Blender, checked, as its shaders
read them: byte sRGB images decoded to scene-linear, float images as Blender holds them,
Non-Color data as stored; which of them are tangent-space normal maps."""

import numpy as np

from ... import texsynth
from ...texsynth.blocks.color import srgb_to_linear
from ...texsynth.norepeat import predict_memory
from .. import pixels


def check_opaque(image, values):
    """``values`` (``pixels.read_exemplar``'s), or ``ValueError`` for a varying alpha."""
    if values.shape[2] == 4:
        raise ValueError(f"Image '{image.name}' has a varying alpha; Break Repetition handles "
                         "opaque textures only")
    return values


def shader_values(image, values, encoding):
    """``values`` (``pixels.read_exemplar``'s) as the shader reads them, (H, W, 3): scene-linear
    colour or data; ``ValueError`` for what the precomputation cannot take."""
    check_opaque(image, values)
    if not encoding.is_float and not encoding.is_data:
        if encoding.colorspace != "sRGB":
            raise ValueError(f"Image '{image.name}' is in colour space '{encoding.colorspace}'; "
                             "set it to sRGB or Non-Color, or use a float image")
        values = srgb_to_linear(values).astype(np.float32)
    return values


def looks_like_normals(values):
    """A tangent-space normal map's content: 3 channels whose decoded vectors ``2 v - 1`` are
    about unit long, pointing out of the surface (blue above 1/2) and tilted both ways on
    average (red and green about 1/2)."""
    if values.shape[2] != 3:
        return False
    n = 2.0 * values.reshape(-1, 3)[::max(1, values.shape[0] * values.shape[1] // 65536)] - 1.0
    return bool(np.median(np.abs(np.linalg.norm(n, axis=1) - 1.0)) < 0.1
                and np.median(n[:, 2]) > 0.3 and np.all(np.abs(n[:, :2].mean(axis=0)) < 0.2))


def shader_maps(nodes):
    """Every node's image as the shader reads it, ``[(node name, (H, W, 3))]``, and whether each
    is a normal map; ``ValueError`` when the precomputation would not fit the memory budget or
    an image is below 2 x 2."""
    need = 0.0
    for node in nodes:
        w, h = node.image.size
        need = max(need, predict_memory((h, w, 3)) + 32.0 * w * h)
    texsynth.validation.check_memory(need, "Break Repetition", "use smaller images")
    maps, normals = [], []
    for node in nodes:
        values, encoding = pixels.read_exemplar(node.image)
        if min(values.shape[:2]) < 2:
            raise ValueError(f"Image '{node.image.name}' is {values.shape[1]} x "
                             f"{values.shape[0]} pixels; it needs at least 2 x 2")
        maps.append((node.name, shader_values(node.image, values, encoding)))
        normals.append(encoding.is_data and looks_like_normals(values))
    return maps, normals

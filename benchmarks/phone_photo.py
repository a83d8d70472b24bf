"""A phone photo made reproducibly: a 12 MP JPEG of a paved floor seen at a slant, under a
window's light, with the EXIF focal length a phone writes (../shared holds no camera photo).

The granite setts photo (0ad-data, CC-BY-SA-3.0, 2048 x 2048, tiling) is laid on a plane seen
at ``SLANT`` degrees receding upward through a 26 mm (35 mm equivalent) lens, 4000 x 3000
pixels, one texture pixel per photo pixel at the centre (``texsynth.plane.geometry``'s maps,
bilinear, the texture wrapped); the light: a ramp across the frame from a window (``RAMP``) and
cos^4 vignetting; written as sRGB JPEG quality 90 with ``FocalLengthIn35mmFilm``.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import scipy.ndimage as ndi
from PIL import Image

from texsynth.io import read_photo
from texsynth.plane.geometry import image_to_plane

from .context import REPO, SHARED_TEXTURES

SOURCE = SHARED_TEXTURES / "large" / "0ad-data" / "granite_setts_grass.png"
SHAPE = (3000, 4000)
SLANT, TILT = 30.0, 90.0  # degrees: the floor recedes upward in the picture
FOCAL_35MM = 26  # mm, a phone's main camera
RAMP = (1.0, 0.55)  # the light's factor at the left and the right edge
FILE = REPO / "build" / "material" / "phone_setts_4000x3000.jpg"


def focal_px(shape=SHAPE) -> float:
    """The focal length in pixels the EXIF gives (CIPA DCG-001: by the diagonal)."""
    return FOCAL_35MM / math.hypot(36.0, 24.0) * math.hypot(*shape)


def phone_photo(path: Path = FILE, shape=SHAPE, source: Path = SOURCE) -> Path:
    """Write the phone photo to ``path`` once (kept), and return ``path``."""
    if path.exists():
        return path
    texture = read_photo(source)[:, :, :3].astype(np.float32)
    th, tw = texture.shape[:2]
    h, w = shape
    f = focal_px(shape)
    light = np.empty((h, w), np.float32)
    out = np.empty((h, w, 3), np.uint8)
    for r0 in range(0, h, 500):  # in strips: the coordinates of 12 MP at once are 200 MB
        rows = np.arange(r0, min(h, r0 + 500))
        xs, ys = np.meshgrid(np.arange(w) - (w - 1) / 2, (h - 1) / 2 - rows)
        u = image_to_plane(np.stack([xs, ys], axis=-1), SLANT, TILT, f)
        u *= math.cos(math.radians(SLANT))  # one texture pixel per photo pixel at the centre
        coords = np.stack([(th / 2 - u[..., 1]) % th, (u[..., 0] + tw / 2) % tw])
        ramp = RAMP[0] + (RAMP[1] - RAMP[0]) * (xs + w / 2) / w
        vignette = (f * f / (f * f + xs * xs + ys * ys)) ** 2
        light[rows] = ramp * vignette
        for c in range(3):
            value = ndi.map_coordinates(texture[:, :, c], coords, order=1, mode="grid-wrap")
            out[rows, :, c] = np.clip(value * light[rows] * 255 + 0.5, 0, 255).astype(np.uint8)
    image = Image.fromarray(out)
    exif = image.getexif()
    exif.get_ifd(0x8769)[0xA405] = FOCAL_35MM
    path.parent.mkdir(parents=True, exist_ok=True)
    partial = path.with_name("partial" + path.suffix)
    image.save(partial, quality=90, exif=exif)
    partial.replace(path)
    return path


if __name__ == "__main__":
    print(phone_photo())

"""make_tileable on photos lit from one side (a cheap check, not a section): the ramp photos of
tests/_images.py (noise on a ramp twice its range) and smooth noise lit from the left
(brightness falling by 30 or 50 % across), 64-256 px, 2 photos x 3 seeds each. Prints the
spreads of the photo's seam ratio, the result's, the result's high-passed at a quarter band
averaged over the lines across the band (a step anywhere in the band shows; the ramp's turn
back within it does not), and band sharpness. ``python -m benchmarks.ramp_check``; with
PYTHONPATH at another checkout it measures that one's code."""

import sys
from pathlib import Path

import numpy as np
from scipy.ndimage import gaussian_filter

import texsynth
from texsynth.metrics import band_sharpness, seam_ratio
from texsynth.tileable import default_band

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
from _images import ramp_photo, smooth_noise  # noqa: E402

SHAPES = ((64, 64), (80, 96), (128, 160), (256, 256))


def across(image, band):
    """The seam ratio averaged over every line within ``band / 2`` of the wrap."""
    return float(np.mean([seam_ratio(np.roll(image, (k, k), axis=(0, 1)))
                          for k in range(-band // 2, band // 2)]))


def high_pass(image, band):
    return image - gaussian_filter(image, (band / 4, band / 4, 0), mode="wrap")


def lit(shape, seed, strength):
    """Smooth noise lit from the left: brightness falls by ``strength`` across the width."""
    h, w = shape
    texture = smooth_noise((h + 40, w + 40), seed=seed, sigma=1.5)[17:17 + h, 23:23 + w]
    light = np.linspace(1.0, 1.0 - strength, w, dtype=np.float32)[None, :, None]
    return (texture * light).astype(np.float32)


def main():
    for kind in ("ramp", "lit 0.3", "lit 0.5"):
        for shape in SHAPES:
            band = default_band(shape)
            rows = []
            for photo_seed in range(2):
                photo = (ramp_photo(shape, seed=photo_seed) if kind == "ramp"
                         else lit(shape, photo_seed, float(kind[4:])))
                for seed in range(3):
                    out = texsynth.make_tileable(photo, seed=seed)
                    rows.append((seam_ratio(photo), seam_ratio(out),
                                 across(high_pass(out, band), band), band_sharpness(out, band)))
            r = np.array(rows)
            spread = [f"{r[:, k].min():.2f}-{r[:, k].max():.2f}" for k in range(4)]
            print(f"{kind:8s} {shape}: photo {spread[0]}, seam {spread[1]}, high-passed across "
                  f"the band {spread[2]}, band sharpness {spread[3]}", flush=True)


if __name__ == "__main__":
    main()

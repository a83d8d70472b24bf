"""texsynth.stack.btf.align on Cycles renders of a displaced plane (Neubeck et al. 2004 section
2.2).

A textured height field (mean height known) is rendered with orthographic cameras from several
directions, each view rectified to the frontal grid for the plane z = 0 with the known camera
geometry (benchmarks/btf_renders.py); the alignment height chosen must be close to the surface's
mean height.
"""

import numpy as np
from scipy.ndimage import gaussian_filter

from benchmarks.btf_renders import GRID, rectified_views
from texsynth.stack import btf


def test_alignment_recovers_the_mean_height_of_a_rendered_surface(addon, tmp_path):
    rng = np.random.default_rng(1)
    albedo = gaussian_filter(rng.random((GRID, GRID)), 1.0, mode="wrap")
    albedo = (albedo - albedo.min()) / np.ptp(albedo)
    relief = gaussian_filter(rng.standard_normal((GRID, GRID)), 6, mode="wrap")
    height = 4.0 + 1.5 * (relief - relief.mean()) / relief.std()  # pixels, about 8 px deep
    slant = np.radians([0, 20, 20, 20, 20])
    tilt = np.radians([0, 0, 90, 180, 270])
    world = np.stack([np.sin(slant) * np.cos(tilt), np.sin(slant) * np.sin(tilt),
                      np.cos(slant)], axis=1)
    stack, dirs = rectified_views(albedo, height, world, tmp_path)
    heights = np.arange(-2.0, 10.01, 0.5)
    best, curve, _ = btf.align(stack, dirs, heights)
    assert abs(best - height.mean()) <= 1.0, (best, curve)
    assert curve[0] > 1.5 * curve.min()

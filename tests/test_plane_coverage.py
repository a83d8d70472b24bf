"""The stated uncertainty covers the error (issue 27): with the focal length known, a texture
whose contrast varies in patches across the plane (lighting, stains, wear) breaks the
homogeneity the slant is read from; the estimate must say so by its uncertainty, not claim a
3-degree precision and miss by 10.
"""

import math

import numpy as np
import pytest
import scipy.ndimage as ndi
from _planes import noise_texture, normal_error, photograph

from texsynth.plane import estimate_plane

pytestmark = pytest.mark.filterwarnings("error::RuntimeWarning")

COVER_80 = math.sqrt(math.log(5.0))  # the normal's error is within this many sigmas on 80 %


def patchy_texture(seed, n=512, depth=0.9):
    """Isotropic noise whose contrast varies by exp(+-0.9) in patches about 40 texels across."""
    rng = np.random.default_rng(seed + 100)
    field = ndi.gaussian_filter(rng.standard_normal((n, n)), 40, mode="wrap")
    return noise_texture(seed, n) * np.exp(depth * field / field.std())


def test_the_uncertainty_covers_the_error_on_patchy_textures():
    """Six views (three textures, two views each): the error within the 80 % radius of the
    stated normal sigma on at least four (the old sigma, 3.4-3.9 deg, covered three), and the
    sigma still a measurement (median under 12 deg), not a shrug."""
    covered, sigmas = [], []
    for seed in range(3):
        texture = patchy_texture(seed)
        for slant, tilt in ((40.0, 60.0), (25.0, 200.0)):
            result = estimate_plane(photograph(texture, slant, tilt, 300.0), focal_px=300.0)
            error = normal_error((slant, tilt), (result.slant, result.tilt),
                                 mod180=result.tilt_ambiguous_180)
            covered.append(error <= COVER_80 * result.normal_uncertainty)
            sigmas.append(result.normal_uncertainty)
    assert sum(covered) >= 4, (covered, sigmas)
    assert np.median(sigmas) < 12.0, sigmas

import numpy as np

from texsynth.blocks import fft
from texsynth.blocks.periodic import periodic_component, periodic_spectrum
from texsynth.metrics import seam_ratio

from _images import ramp_photo


def test_periodic_component_of_a_photo_tiles():
    photo = ramp_photo((96, 128))
    assert seam_ratio(photo) > 3
    p = periodic_component(photo)
    assert p.dtype == np.float32 and p.shape == photo.shape
    assert seam_ratio(p) < 1.5
    np.testing.assert_allclose(p.mean(axis=(0, 1)), photo.mean(axis=(0, 1)), atol=1e-5)


def test_smooth_component_is_harmonic_inside():
    """Moisan's s solves a Poisson equation whose source lives on the border only."""
    photo = ramp_photo((64, 64))[:, :, 0]
    s = photo - periodic_component(photo)
    laplacian = sum(np.roll(s, k, axis=a) for k in (1, -1) for a in (0, 1)) - 4 * s
    assert np.abs(laplacian[1:-1, 1:-1]).max() < 1e-4
    assert np.abs(laplacian[0]).max() > 0.1


def test_the_periodic_spectrum_is_the_transform_of_the_periodic_component():
    rng = np.random.default_rng(5)
    for shape in [(31, 40), (64, 64), (65, 33)]:
        u = (rng.random(shape) + np.linspace(0, 3, shape[1])[None]).astype(np.float32)
        expected = fft.rfft2(periodic_component(u))
        np.testing.assert_allclose(periodic_spectrum(u), expected,
                                   atol=1e-6 * np.abs(expected).max())

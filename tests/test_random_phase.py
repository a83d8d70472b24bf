"""Random phase noise: the exemplar's spectrum, mean and deviation, one phase for all channels."""

import numpy as np
import pytest

import texsynth
from tests._images import ramp_photo, smooth_noise
from texsynth.blocks.periodic import periodic_component
from texsynth.metrics import power_spectrum_correlation, seam_ratio


def _photo():
    """Oriented grain (anisotropic smoothing) under a ramp: a photo that does not tile."""
    rng = np.random.default_rng(4)
    noise = rng.standard_normal((96, 80)).astype(np.float32)
    grain = sum(np.roll(noise, k, axis=1) for k in range(6)) / 6
    photo = ramp_photo((96, 80), seed=2)
    photo += 0.15 * grain[:, :, None] * np.array([1.0, 0.8, 0.5], np.float32)
    return photo


@pytest.mark.parametrize("size", [(96, 80), (200, 150), (48, 300)])
def test_keeps_the_power_spectrum_mean_and_deviation_at_any_size(size):
    photo = _photo()
    width, height = size
    out = texsynth.synthesize(photo, width, height, method="random_phase", seed=3)
    # one wrap line of 48-300 values is a noisy sample: a photo's seam scores 2 to 20
    assert out.shape == (height, width, 3) and 0.7 < seam_ratio(out) < 1.4
    assert power_spectrum_correlation(photo, out) >= 0.95
    span = photo.max(axis=(0, 1)) - photo.min(axis=(0, 1))
    assert np.all(np.abs(out.mean(axis=(0, 1)) - photo.mean(axis=(0, 1))) < 0.03 * span)
    assert np.all(np.abs(out.std(axis=(0, 1)) - photo.std(axis=(0, 1))) < 0.03 * span)
    assert np.all(out.min(axis=(0, 1)) >= photo.min(axis=(0, 1)))
    assert np.all(out.max(axis=(0, 1)) <= photo.max(axis=(0, 1)))


def test_the_same_size_keeps_the_periodic_components_fourier_modulus():
    photo = 0.5 + 0.05 * smooth_noise((64, 64), seed=1)       # far from clipping
    photo[:, :, 0] += np.linspace(0, 0.2, 64, dtype=np.float32)  # and not tiling
    out = texsynth.synthesize(photo, 64, 64, method="random_phase", seed=0)
    inside = (out > photo.min(axis=(0, 1))) & (out < photo.max(axis=(0, 1)))
    assert inside.mean() > 0.99
    for c in range(3):
        a = np.abs(np.fft.fft2(periodic_component(photo[:, :, c])))
        b = np.abs(np.fft.fft2(out[:, :, c]))
        assert np.corrcoef(a.ravel()[1:], b.ravel()[1:])[0, 1] > 0.98


def test_one_phase_for_all_channels_keeps_the_colours_related():
    grey = 0.3 + 0.4 * smooth_noise((64, 64), seed=5, channels=1)[:, :, 0]
    photo = np.stack([grey, 0.5 * grey + 0.2, 0.9 - 0.5 * grey], axis=2)  # one line of colours
    out = texsynth.synthesize(photo, 100, 90, method="random_phase", seed=1)
    # independent phases would scatter the colours off the line (correlation near 0)
    assert np.corrcoef(out[:, :, 0].ravel(), out[:, :, 1].ravel())[0, 1] > 0.99
    assert np.corrcoef(out[:, :, 0].ravel(), out[:, :, 2].ravel())[0, 1] < -0.99

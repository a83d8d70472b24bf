"""The real FFTs that write into given buffers give scipy.fft's results bit for bit, with
scipy's pocketfft binding and without it."""

import numpy as np
import pytest
import scipy.fft as sfft

from texsynth.blocks import fft


@pytest.fixture(params=["binding", "public"])
def path(request, monkeypatch):
    if request.param == "public":
        monkeypatch.setattr(fft, "_pocketfft", None)
    return request.param


@pytest.mark.parametrize("shape", [(64, 48), (37, 53), (5, 7)])
def test_transforms_are_scipys_bit_for_bit_into_the_given_buffers(path, shape):
    image = np.random.default_rng(3).random(shape, dtype=np.float32)
    spectrum = sfft.rfft2(image)
    out = np.empty_like(spectrum)
    assert fft.rfft2(image, out=out) is out
    np.testing.assert_array_equal(out, spectrum)
    np.testing.assert_array_equal(fft.rfft2(image), spectrum)

    inverse = sfft.irfft(sfft.ifft(spectrum, axis=0), n=shape[1], axis=1)
    pixels = np.empty(shape, np.float32)
    assert fft.irfft2(spectrum.copy(), shape, out=pixels) is pixels
    np.testing.assert_array_equal(pixels, inverse)
    assert pixels.dtype == np.float32
    assert np.abs(pixels - image).max() < 1e-5

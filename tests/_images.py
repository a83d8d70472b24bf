"""Synthetic test images with known structure (no files needed)."""

import numpy as np


def smooth_noise(shape, seed=0, sigma=2.0, channels=3):
    """Band-limited noise with channel correlation, like a photographed stochastic texture."""
    from scipy.ndimage import gaussian_filter

    rng = np.random.default_rng(seed)
    base = gaussian_filter(rng.standard_normal(shape), sigma, mode="wrap")
    layers = [0.6 * base
              + 0.4 * gaussian_filter(rng.standard_normal(shape), sigma / 2, mode="wrap")
              for _ in range(channels)]
    img = np.stack(layers, axis=2)
    img = (img - img.min()) / np.ptp(img)
    return img.astype(np.float32)


def ramp_photo(shape, seed=0):
    """A non-periodic image: noise plus a strong left-to-right ramp (wrap seam is obvious)."""
    img = smooth_noise(shape, seed, channels=3)
    img += np.linspace(0.0, 2.0, shape[1], dtype=np.float32)[None, :, None]
    return img / img.max()


def wasserstein(a, b):
    """The worst channel's 1-Wasserstein distance between two images' pixel values (their
    quantiles at 256 levels)."""
    p = (np.arange(256) + 0.5) / 256
    return max(float(np.abs(np.quantile(a[..., k], p) - np.quantile(b[..., k], p)).mean())
               for k in range(a.shape[2]))

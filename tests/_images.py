"""Synthetic test images with known structure (no files needed)."""

import numpy as np

from texsynth.metrics import luminance


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


def isolated(image, spread, labels=None):
    """Share of the pixels whose luminance lies beyond every one of their 8 neighbours' by more
    than ``spread`` (salt and pepper); with ``labels``, of the pixels whose 8 neighbours are all
    of their class."""
    y = luminance(image)
    ring = [(dy, dx) for dy in (-1, 0, 1) for dx in (-1, 0, 1) if dy or dx]
    around = np.stack([np.roll(y, d, (0, 1)) for d in ring])
    lone = (y < around.min(axis=0) - spread) | (y > around.max(axis=0) + spread)
    if labels is None:
        return float(lone.mean())
    inside = np.all([np.roll(labels, d, (0, 1)) == labels for d in ring], axis=0)
    return float(lone[inside].mean())


def half_iqr(image):
    """Half the interquartile range of an image's luminance."""
    return 0.5 * float(np.subtract(*np.percentile(luminance(image), [75, 25])))


def running_bond(shape, seed, *, course, brick, joint, tint, shade, grain, mortar,
                 speckle):
    """A wall laid in running bond: courses ``course`` px tall of bricks ``brick`` px long, each
    course shifted half a brick, joints ``joint`` px wide. Each brick is ``tint`` (RGB) times
    its own shade, uniform in ``shade`` (low, width), plus smooth grain of amplitude ``grain``;
    each joint pixel ``mortar`` (RGB) plus uniform noise up to ``speckle``. Returns the image
    and the mask of the joints."""
    rng = np.random.default_rng(seed)
    i, j = np.mgrid[:shape[0], :shape[1]]
    row = i // course
    along = j + brick // 2 * (row % 2)
    grey = shade[0] + shade[1] * rng.random((row.max() + 1, (along // brick).max() + 1))
    img = grey[row, along // brick][:, :, None] * np.asarray(tint, np.float32)
    img = img + grain * (smooth_noise(shape, seed, sigma=1.0, channels=3) - 0.5)
    joints = (i % course < joint) | (along % brick < joint)
    img[joints] = np.asarray(mortar) + speckle * rng.random((joints.sum(), 1))
    return img.astype(np.float32), joints

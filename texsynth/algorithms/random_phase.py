"""Random phase noise (RPN): the exemplar's Fourier modulus under a uniformly random phase.

Galerne, Gousseau & Morel 2011 ("Random phase textures: theory and synthesis", IEEE TIP 20(1);
with its IPOL companion "Micro-texture synthesis by phase randomization"): a micro-texture is
characterised by its Fourier modulus, so a new sample is the exemplar's transform with a random
phase added. Their three practical steps are all here:

- the periodic component p of the exemplar (Moisan 2011, ``texsynth.blocks.periodic``), so the
  border jump of a photo puts no bright cross into the spectrum (their section on artefacts of
  non-periodicity);
- colour: one random phase theta added to the phase of every channel, so the channels keep
  their phase differences and the colours stay the photo's (their colour RPN);
- any output size (their extension to arbitrary sizes): the zero-mean spot s = p - m of
  M x N is embedded in an M' x N' image of zeros and scaled by sqrt(M' N' / (M N)) (the ADSN
  normalisation), so that the output keeps p's variance; the covariance of the output is the
  spot's non-periodic autocorrelation.

    m = mean of p (per channel); s~ = sqrt(M'N' / MN) (p - m) embedded in M' x N' zeros;
    theta = the phase of the transform of a white noise W (Hermitian, so the output is real:
            0 or pi on the frequencies that are their own opposites, 0 at the origin);
    out_c = m_c + F^-1(F(s~_c) e^(i theta)).

The output is periodic by construction (an inverse DFT). Deviations, one line each:
- an output axis shorter than the exemplar's takes a centred crop of the exemplar on that axis
  (the paper extends, it does not shrink; a crop is a sample of the same texture);
- the result is clipped to the exemplar's per-channel range (Gaussian tails would leave it; a
  varying alpha stays within its own range);
- theta is drawn once, as the phase of the real FFT of a float32 uniform white noise (any white
  noise's phase is uniform; uniform samples are the generator's cheapest).
"""

from __future__ import annotations

import numpy as np

from ..blocks import fft
from ..blocks.periodic import periodic_component
from ..registry import Method, register

__all__ = ["random_phase", "METHOD"]


def random_phase(exemplar, width, height, rng, progress):
    """Synthesize (height, width, C) from ``exemplar`` (H, W, C float32) by random phase noise.

    Parameters
    ----------
    exemplar : float32 array (H, W, C)
    width, height : int
        The output size, larger or smaller than the exemplar.
    rng : numpy.random.Generator
    progress : texsynth.progress.Progress

    Returns
    -------
    float32 array (height, width, C), periodic, with the spectrum modulus and the per-channel
    mean and variance of the exemplar's periodic component.

    References
    ----------
    Galerne, Gousseau & Morel 2011, colour RPN and the extension to arbitrary sizes;
    Moisan 2011, section 2 (periodic component).

    Examples
    --------
    >>> import numpy as np, texsynth
    >>> photo = np.random.default_rng(0).random((32, 48, 3), dtype=np.float32)
    >>> texsynth.synthesize(photo, 64, 40, method="random_phase", seed=1).shape
    (40, 64, 3)
    """
    h, w, channels = exemplar.shape
    m_, n_ = min(h, height), min(w, width)             # the spot's size M x N
    y, x = (h - m_) // 2, (w - n_) // 2
    crop = exemplar[y:y + m_, x:x + n_]
    progress(0.0, "the exemplar's periodic component")
    p = periodic_component(crop)
    m = p.mean(axis=(0, 1), dtype=np.float64)
    lo, hi = exemplar.min(axis=(0, 1)), exemplar.max(axis=(0, 1))
    gain = np.float32(np.sqrt(width * height / (m_ * n_)))
    progress(0.1, "drawing the random phase")
    spectrum = fft.rfft2(rng.random((height, width), dtype=np.float32))
    spectrum[0, 0] = 1.0                               # theta(0) = 0: the mean is m
    np.divide(spectrum, np.abs(spectrum), out=spectrum, where=spectrum != 0)  # e^(i theta)
    spot = np.zeros((height, width), np.float32)
    out = np.empty((height, width, channels), np.float32)
    for c in range(channels):
        spot[:m_, :n_] = p[:, :, c] - np.float32(m[c])
        spot[:m_, :n_] *= gain
        modulated = fft.rfft2(spot)
        modulated *= spectrum
        image = fft.irfft2(modulated, (height, width))
        image += np.float32(m[c])
        np.clip(image, lo[c], hi[c], out=out[:, :, c])
        progress(0.1 + 0.9 * (c + 1) / channels, f"channel {c + 1}/{channels}")
    return out


def _memory(shape, width, height, params):
    """The crop's periodic component and its float64 temporaries (the photo's size at most),
    the noise, the phase and one channel's spectrum (complex64 on the real-FFT grid: 4 B a
    pixel each), the spot, one channel's image and the output (C floats)."""
    h, w, c = shape
    crop = min(h, height) * min(w, width)
    return crop * (4 * c + 40) + width * height * (4 + 4 + 4 + 4 + 4 + 4 * c + 8) + 2 ** 20


def _cost(shape, width, height, params):
    """Seconds on the reference machine: the periodic component of the crop (C channels), the
    noise's transform, and per channel a forward and an inverse transform of the output's size
    (about 3e-8 s a pixel each at 2048^2, n log n taken as flat)."""
    h, w, c = shape
    crop = min(h, height) * min(w, width)
    return 0.01 + 6e-8 * crop * c + 3e-8 * width * height * (2 + 2 * c)


METHOD = register(Method(
    name="random_phase",
    label="Random Phase Noise",
    description="Keep the photo's Fourier modulus, randomise its phase (Galerne, Gousseau & "
                "Morel 2011): the fastest model of micro-textures such as sand, plaster, "
                "fabric grain; loses edges and shapes",
    function=random_phase,
    params=(),
    min_exemplar=8,
    memory=_memory,
    cost=_cost,
))

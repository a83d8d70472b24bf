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
- each channel's values are then matched to the photo's histogram (``texsynth.blocks.histogram``,
  on a regular sample of at most ``SAMPLES`` of its values), in place of RPN's near-Gaussian
  marginal: the output keeps the photo's mean, deviation and range (a varying alpha stays in
  its own), which clipping to the range did not on saturated photos (deviation off by up to 7 %
  of the range on ink clouds); on the six textures tried the spectrum correlation moved by at
  most 0.001, and the order of values, hence the shared phase's colour relations, is kept;
- theta is drawn once, as the phase of the real FFT of a float32 uniform white noise (any white
  noise's phase is uniform; uniform samples are the generator's cheapest).

References
----------
Galerne, Gousseau & Morel 2011 (random phase noise, its colour version, any size);
Moisan 2011 (the periodic component).
"""

from __future__ import annotations

import time

import numpy as np

from ..blocks import fft
from ..blocks.histogram import TargetHistogram, match, sample_step
from ..blocks.periodic import periodic_component, periodic_spectrum
from ..registry import Method, register

__all__ = ["random_phase", "METHOD"]

#: Values of a channel the histogram matching keeps (every one up to a 1024^2 photo).
SAMPLES = 1 << 20
#: A channel's time in its transforms' (CPU clock, buffers touched beforehand; medians of 5-9
#: warm runs at 128^2 -> 1024^2, 256^2 -> 2048^2, 512^2 -> 1024^2, 1024^2 -> 2048^2): the random
#: phase's draw and transform take PHASE of a channel's transforms (1.4, 1.16, 1.5, 0.93 with
#: the modulus in a new array; in the noise's pages, issue 40: 0.84, 0.92, 0.89, 0.87, medians
#: of 3 at 256^2 -> 512^2, -> 1024^2, -> 2048^2, 512^2 -> 2048^2), its histogram matching
#: (1.25, 0.49, 1.3, 0.67 of them) a pass over the output's pixels, the sort of the sample
#: and the tables: MATCH_PIXEL + (MATCH_SAMPLE samples + MATCH_FIXED) / pixels.
PHASE, MATCH_PIXEL, MATCH_SAMPLE, MATCH_FIXED = 0.9, 0.31, 1.16, 6.3e5
#: Bytes between the writes that touch every page of a new buffer (the smallest page).
PAGE = 4096


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
    float32 array (height, width, C), periodic, with the spectrum modulus of the exemplar's
    periodic component and the exemplar's values (per channel).

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
    whole = (m_, n_) == (height, width)                # the spot fills the output: s~ = p - m
    start = time.process_time()
    progress(0.0, "the exemplar's periodic component")
    if not whole:
        p = periodic_component(crop)
        m = p.mean(axis=(0, 1), dtype=np.float64)
        gain = np.float32(np.sqrt(width * height / (m_ * n_)))
        spot = np.zeros((height, width), np.float32)  # never written but its corner: zero pages
    step = sample_step(h * w, w, SAMPLES)
    values = exemplar.reshape(-1, channels)[::step]
    if step > 1:  # a sample spread over a large photo: read from it once, not once a channel
        values = np.ascontiguousarray(values)
    # Every large buffer once, its pages touched here: the noise (then each channel's image),
    # the phase, a channel's spectrum and the output. A new page costs from a tenth of a
    # millisecond a MiB to twenty times that (a virtual machine's host giving back memory it had
    # reclaimed), so this step's share is measured, not fixed: its CPU time against the phase's
    # that follows it (PHASE of a channel's transforms).
    image = np.empty((height, width), np.float32)
    spectrum = np.empty((height, width // 2 + 1), np.complex64)
    modulated = None if whole else np.empty_like(spectrum)
    out = np.empty((height, width, channels), np.float32)
    for buffer in (image, spectrum, modulated, out):
        if buffer is not None:
            buffer.reshape(-1).view(np.uint8)[::PAGE] = 0
    touched = time.process_time()
    rng.random(dtype=np.float32, out=image)
    fft.rfft2(image, out=spectrum)
    spectrum[0, 0] = 1.0                               # theta(0) = 0: the mean is m
    # e^(i theta), the modulus in the noise's touched pages: a new array's first touch had made
    # this step slower than PHASE of a channel, the more so after other runs (issue 40: 256 ->
    # 2048 after the time-left benchmark's eight runs, told 1.4-1.8x at 10 % and 50 %); a zero
    # stays zero
    modulus = np.abs(spectrum, out=image.reshape(-1)[:spectrum.size].reshape(spectrum.shape))
    np.divide(spectrum, np.maximum(modulus, np.finfo(np.float32).tiny, out=modulus),
              out=spectrum)
    now = time.process_time()
    # Fractions: the steps so far by their time, then each channel's transforms and matching
    # by their shares of a channel (the phase's time over PHASE, a channel's transforms).
    matching = MATCH_PIXEL + (MATCH_SAMPLE * len(values) + MATCH_FIXED) / (width * height)
    channel = max(now - touched, 1e-9) / PHASE * (1.0 + matching)
    begun = (now - start) / (now - start + channels * channel)
    shares = np.cumsum([1.0, matching] * channels) / (channels * (1.0 + matching))
    steps = begun + (1.0 - begun) * shares
    progress(begun, "random phase drawn")
    for c in range(channels):
        if whole:  # F(p) from u's transform and the border's 1-D ones; frequency 0 is m M N
            modulated = periodic_spectrum(crop[:, :, c])
            mean = np.float32(modulated[0, 0].real / (m_ * n_))
            modulated[0, 0] = 0.0
        else:
            mean = np.float32(m[c])
            spot[:m_, :n_] = p[:, :, c] - mean
            spot[:m_, :n_] *= gain
            fft.rfft2(spot, out=modulated)
        modulated *= spectrum
        fft.irfft2(modulated, (height, width), out=image)
        image += mean
        progress(steps[2 * c], f"channel {c + 1}/{channels}: matching its histogram")
        out[:, :, c] = match(image, TargetHistogram(values[:, c]), out=image)
        progress(steps[2 * c + 1], f"channel {c + 1}/{channels}")
    return out


def _memory(shape, width, height, params):
    """The larger of two phases (tracemalloc at 256^2 -> 512^2, 1024^2 -> 1024^2, 256^2 and
    1024^2 -> 2048^2: 15, 44, 123 and 134 MiB, the estimate 1.1-1.5x that): the periodic
    component of the crop (C floats and one channel's float64 temporaries, 28 B a pixel); then
    the noise (then each channel's image, matched in place), the phase and one channel's
    spectrum (complex64 on the real-FFT grid: 4 B a pixel each), the spot, 4 B a pixel to
    spare and the output (C floats) of the output's size, with the periodic component, the
    sampled values and one channel's sorted copy, and 7 MiB for the matching's tables and
    steps."""
    h, w, c = shape
    crop = min(h, height) * min(w, width)
    values = min(h * w, 2 * SAMPLES)
    periodic = crop * (4 * c + 28)
    synthesis = width * height * (20 + 4 * c) + crop * 4 * c + values * (4 * c + 8) + 7 * 2 ** 20
    return max(periodic, synthesis) + 2 ** 20


def _cost(shape, width, height, params):
    """Seconds on the reference machine: a pass over the photo's values (the checks before the
    run, the sample's gather), the sorts of the sampled values, and per channel the output's
    transforms and histogram matching (the spot's periodic component counted in them: n log n
    taken as flat). Fitted by least squares to quiet runs from crops of 256^2 to 2048^2 and
    from the 12 MP setts, to 512^2-2048^2 (0.03-0.5 s), the constant raised by the first
    call's start-up in a fresh process (the photos section's runs). The output's term as
    n log2 n (issue 45: linear, 16384 x 64 had been told 2.1x its quiet 0.06 s, 4096^2 from
    32^2 0.77x its 1.73 s), its constant to 0.02 s; its coefficient 3.87e-9 -> 3.1e-9 (the
    quiet predictions table: 2048^2, 16384 x 64 and 4096^2 read 0.85, 0.99, 0.63 of its
    median seconds over cost; CPU time over cost 0.55, 0.80, 0.49 at load 12)."""
    h, w, c = shape
    sampled = c * -(-h * w // sample_step(h * w, w, SAMPLES))
    pixels = width * height
    return 0.02 + 5e-9 * h * w * c + 5.5e-8 * sampled + 3.1e-9 * pixels * np.log2(
        max(pixels, 2)) * c


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

"""Quality measures a user would notice, usable on any image arrays.

- ``seam_ratio``: does it tile? Mean absolute jump across the wrap-around edges over the mean
  absolute difference between interior neighbours, on luminance. A periodic texture scores about
  1; a photograph that does not tile scores 2 to 20. Read it two-sided: 0.5 is a soft line
  across the wrap, as visible as 1.5 is a hard one.
- ``seam_ratio_in_phase``: the same question for a regular texture (bricks, pavers, setts),
  whose own lines jump more or less according to where they fall in its rhythm: the jump across
  the wrap over the jumps across the image's own lines that sit where it sits (joint with
  joint, through bricks with through bricks), each direction on its own.
- ``dead_end_ratio``: are the elements of a man-made surface (bricks, setts) whole? The joint
  network's dead ends (a joint that stops inside an element) per 1000 px of joint, output over
  photo, the joints read by one rule fixed on the photo (``texsynth.blocks.joints``).
- ``gradient_ratio``: is it as sharp as the photo? Mean gradient magnitude of the output over
  the photo's; under 0.9 the output is smoother (blurred), over 1.1 it is noisier.
- ``band_sharpness``: for a photo made tileable, the mean gradient in the middle of the band
  across the wrap over that of the kept part; under 0.9 the band shows as a soft cross.
- ``subband_distance``: do the filter statistics match (what Heeger-Bergen optimises)? 1-D
  Wasserstein distances between exemplar and output coefficients of every steerable-pyramid band,
  each over the exemplar band's standard deviation, averaged.
- ``patch_distance``: does it look locally like the exemplar, and does it copy? For sampled
  output patches, the distance to the nearest exemplar patch over the patch's own variance energy;
  the median, and the share of near-exact copies.
- ``structure_distance``: a measure no method optimises: total-variation distance between the
  histograms of structure-tensor coherence (how locally oriented the image is) at two scales.
- ``autocorrelation_error``: is the quasi-periodic structure kept (what Portilla-Simoncelli
  constrains)? RMS difference of the central (2L+1) x (2L+1) lags of the normalised
  autocorrelations of the exemplar's periodic component and of the output.
- ``power_spectrum_correlation``: is the power spectrum kept (what random phase noise keeps)?
  Correlation of the radially averaged log power spectra.
- ``repetition_peak``: does it repeat? The largest peak of the luminance's autocorrelation at a
  shift of at least 24 px (every direction, not only at a known period): about 1 for a texture
  laid side by side, the photo's own for an output that repeats no more than its photo.
- ``anisotropy``: has it kept its direction? The image-wide structure tensor's anisotropy, 0
  for a texture with no direction, towards 1 for stripes.
- ``self_distance``: the same three distances between the two halves of the exemplar, the natural
  variation a good synthesis cannot be expected to beat.

All work on luminance (Rec. 709 weights) except ``patch_distance``, which compares all channels.
"""

from __future__ import annotations

import numpy as np
from numpy.lib.stride_tricks import sliding_window_view
from scipy.ndimage import gaussian_filter, maximum_filter

from .blocks.joints import Joints
from .blocks.periodic import periodic_component
from .blocks.pyramid import SteerablePyramid, max_scales

__all__ = [
    "luminance",
    "course_period",
    "course_steps",
    "seam_ratio",
    "seam_ratio_in_phase",
    "dead_ends",
    "dead_end_ratio",
    "mean_gradient",
    "gradient_ratio",
    "band_sharpness",
    "subband_distance",
    "patch_distance",
    "structure_distance",
    "self_distance",
    "quality",
    "autocorrelation",
    "autocorrelation_error",
    "power_spectrum_correlation",
    "repetition_peak",
    "anisotropy",
    "COPY_THRESHOLD",
]

#: Normalised patch distance below which a patch counts as copied verbatim.
COPY_THRESHOLD = 0.01


def luminance(image: np.ndarray) -> np.ndarray:
    """Rec. 709 luma of an (H, W, C) or (H, W) array; alpha is ignored; float64."""
    a = np.asarray(image, dtype=np.float64)
    if a.ndim == 2:
        return a
    if a.shape[2] >= 3:
        return a[:, :, :3] @ np.array([0.2126, 0.7152, 0.0722])
    return a[:, :, 0]


def seam_ratio(image: np.ndarray) -> float:
    """Mean |jump| across the wrap edges over mean |interior neighbour difference| (luminance)."""
    y = luminance(image)
    if min(y.shape) < 3:
        raise ValueError(f"seam_ratio needs at least 3 x 3 pixels, got {y.shape[1]} x {y.shape[0]}")
    seam = np.concatenate([np.abs(y[:, 0] - y[:, -1]), np.abs(y[0, :] - y[-1, :])]).mean()
    interior = np.concatenate([np.abs(np.diff(y, axis=1)).ravel(),
                               np.abs(np.diff(y, axis=0)).ravel()]).mean()
    if interior == 0:
        return 1.0 if seam == 0 else float("inf")
    return float(seam / interior)


#: Lines either side of a line that describe where it sits in the texture's rhythm.
PHASE_LINES = 8
#: Share of the image's lines (at least ``PHASE_NEAREST``) the wrap is compared with.
PHASE_SHARE, PHASE_NEAREST = 0.01, 4


#: Rows of the image differenced at a time: the jumps are read in blocks, not on copies of the
#: whole image (issue 40: eight float64 copies of a 1536^2 photo, first touched in a fresh
#: process on this VM, took 0.3-0.97 s of make_tileable's 2.2 s before its first report).
JUMP_ROWS = 64


def _jumps(y: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The mean |jump| across each line between rows r and r + 1 of ``y`` (H,), and between
    columns c and c + 1 (W,), the last across the wrap."""
    h, w = y.shape
    across_rows, across_cols = np.empty(h), np.zeros(w)
    for r0 in range(0, h, JUMP_ROWS):
        block = y[r0:r0 + JUMP_ROWS]
        below = y[(np.arange(r0, r0 + len(block)) + 1) % h]
        across_rows[r0:r0 + len(block)] = np.abs(below - block).mean(axis=1)
        across_cols[:-1] += np.abs(block[:, 1:] - block[:, :-1]).sum(axis=0)
        across_cols[-1] += np.abs(block[:, 0] - block[:, -1]).sum()
    return across_rows, across_cols / h


def _wrap_and_peers(jump: np.ndarray, line_means: np.ndarray) -> tuple[float, float]:
    """The mean |jump| across the wrap (``jump[-1]``; ``jump[r]`` across the line between rows r
    and r + 1, ``line_means[r]`` row r's mean), and the mean |jump| across the interior lines
    whose surroundings are nearest the wrap's."""
    h = len(jump)
    half = max(1, min(PHASE_LINES, h // 8))
    r = np.arange(h)[:, None]
    rows = (r + np.arange(1 - half, half + 1)) % h
    lines = (r + np.r_[np.arange(-half, 0), np.arange(1, half + 1)]) % h
    means = line_means[rows]
    surroundings = np.concatenate([means - means.mean(axis=1, keepdims=True), jump[lines]],
                                  axis=1)
    distance = np.linalg.norm(surroundings - surroundings[-1], axis=1)
    apart = np.minimum(r[:, 0] + 1, h - 1 - r[:, 0]) >= 2 * half  # shares no row with the wrap's
    n = max(PHASE_NEAREST, int(PHASE_SHARE * apart.sum()))
    peers = np.argsort(np.where(apart, distance, np.inf), kind="stable")[:min(n, apart.sum())]
    return float(jump[-1]), float(jump[peers].mean())


def seam_ratio_in_phase(image: np.ndarray) -> float:
    """Does a regular texture tile? The mean |jump| across the wrap edges over the mean |jump|
    across the image's own lines that sit at the same place in its rhythm (luminance).

    The plain :func:`seam_ratio` divides by the mean jump between all neighbours; on a regular
    texture a line's jump depends on where it falls: the lines along a mortar joint's edge jump
    1.4-4 times the mean, the lines through the bricks 0.6-0.8, and the vertical lines of a
    brick wall 0.6 everywhere. A wrap that falls where the texture's rhythm puts a joint then
    reads 1.5-2.5 though no seam shows, and one through the bricks 0.7. Here each line between
    neighbouring rows (and columns) is described by its surroundings: the mean luminance of
    the ``2 PHASE_LINES`` rows around it (less their mean) and the mean jumps across the
    ``PHASE_LINES`` lines either side, its own jump left out. The wrap's jump is compared with
    the mean jump across the interior lines whose surroundings are nearest the wrap's (the
    ``PHASE_SHARE`` nearest, at least ``PHASE_NEAREST``; lines sharing rows with the wrap's
    surroundings left out), rows and columns each on their own, the two summed as
    :func:`seam_ratio` sums them. A seam is a jump its surroundings do not explain, and
    reads as high as before; about 1 on a texture with no rhythm.

    Examples
    --------
    >>> x = np.arange(96)
    >>> joints = np.tile((x % 16 < 4).astype(float)[:, None], (1, 64))  # every 16 rows
    >>> joints += np.random.default_rng(0).normal(0, 0.05, joints.shape)  # periodic
    >>> round(seam_ratio(joints), 1), round(seam_ratio_in_phase(joints), 1)  # wrap on a joint
    (3.8, 1.0)
    >>> shaded = np.roll(joints, 3, axis=0) + np.linspace(0, 0.3, 96)[:, None]  # a real seam
    >>> round(seam_ratio(shaded), 1), round(seam_ratio_in_phase(shaded), 1)
    (1.3, 2.6)
    """
    y = luminance(image)
    if min(y.shape) < 3:
        raise ValueError(f"seam_ratio_in_phase needs at least 3 x 3 pixels, got {y.shape[1]} "
                         f"x {y.shape[0]}")
    jump_rows, jump_cols = _jumps(y)
    (across_rows, rows_peers), (across_cols, cols_peers) = \
        _wrap_and_peers(jump_rows, y.mean(axis=1)), _wrap_and_peers(jump_cols, y.mean(axis=0))
    h, w = y.shape
    expected = w * rows_peers + h * cols_peers
    seam = w * across_rows + h * across_cols
    if expected == 0:
        return 1.0 if seam == 0 else float("inf")
    return float(seam / expected)


def dead_ends(image: np.ndarray, joints: Joints, wrap: bool = True) -> float:
    """Dead ends of ``image``'s joint network per 1000 pixels of joint (both counted on the
    skeleton at the working scale of ``joints``, ``texsynth.blocks.joints.Joints``), read on
    the torus when ``wrap`` (a tiling output; a photo mirrored at its edges otherwise).

    Examples
    --------
    >>> from texsynth.blocks.joints import Joints
    >>> i, j = np.mgrid[:128, :192]
    >>> wall = np.where((i % 16 < 3) | ((j + 16 * (i // 16 % 2)) % 32 < 3), 0.2, 0.7)
    >>> joints = Joints.fit(wall, sigma=1.5)
    >>> dead_ends(wall, joints)  # every joint meets another
    0.0
    >>> cut = wall.copy(); cut[46:53, 104:110] = 0.7  # a bed joint cut through
    >>> bool(dead_ends(cut, joints) > 0)
    True
    """
    skeleton, end = joints.skeleton(image, wrap)
    length = int(skeleton.sum())
    return 1000.0 * float(end.sum()) / length if length else 0.0


def dead_end_ratio(photo: np.ndarray, output: np.ndarray, sigma: float,
                   joints: Joints | None = None) -> float:
    """The joint network's dead ends per 1000 px of joint (:func:`dead_ends`), ``output`` (read
    on the torus) over ``photo`` (mirrored at its edges), the joints of half width ``sigma``
    read by the rule ``Joints.fit`` fixes on the photo (or the ``joints`` given): 1 when the
    output's elements are as whole as the photo's, above when joints stop inside elements.

    Examples
    --------
    >>> i, j = np.mgrid[:128, :192]
    >>> wall = np.where((i % 16 < 3) | ((j + 16 * (i // 16 % 2)) % 32 < 3), 0.2, 0.7)
    >>> wall += np.random.default_rng(0).normal(0, 0.02, wall.shape)
    >>> cut = wall.copy(); cut[:, 96:] = np.roll(wall[:, 96:], 8, axis=0)  # courses out of line
    >>> bool(dead_end_ratio(wall, cut, 1.5) > 1.5 * dead_end_ratio(wall, wall, 1.5))
    True
    """
    joints = Joints.fit(photo, sigma) if joints is None else joints
    reference = dead_ends(photo, joints, wrap=False)
    found = dead_ends(output, joints, wrap=True)
    if reference == 0:
        return 1.0 if found == 0 else float("inf")
    return found / reference


def mean_gradient(image: np.ndarray, wrap: bool = True) -> float:
    """Mean gradient magnitude of the luminance, by forward differences (wrapping around the
    edges when ``wrap``, as for a periodic texture; within the image otherwise).

    Examples
    --------
    >>> ramp = np.tile(np.arange(8.0), (8, 1))
    >>> round(mean_gradient(ramp, wrap=False), 3)
    1.0
    """
    y = luminance(image)
    if wrap:
        gx, gy = np.roll(y, -1, axis=1) - y, np.roll(y, -1, axis=0) - y
    else:
        gx, gy = np.diff(y, axis=1)[:-1], np.diff(y, axis=0)[:, :-1]
    return float(np.hypot(gx, gy).mean())


def gradient_ratio(photo: np.ndarray, output: np.ndarray) -> float:
    """Mean gradient of ``output`` (periodic) over that of ``photo`` (not periodic): 1 when the
    output is as sharp as the photo, under 0.9 blurred, over 1.1 noisier. Two-sided, as the
    seam ratio.

    References
    ----------
    The measure the texture optimisation literature warns of: Kwatra et al. 2005, 4 (blurring
    by averaging overlapping patches) and Kaspar et al. 2015, 4.

    Examples
    --------
    >>> from scipy.ndimage import gaussian_filter, maximum_filter
    >>> noise = np.random.default_rng(0).random((64, 64))
    >>> round(gradient_ratio(noise, noise), 2)
    1.0
    >>> bool(gradient_ratio(noise, gaussian_filter(noise, 1.0, mode="wrap")) < 0.5)
    True
    """
    reference = mean_gradient(photo, wrap=False)
    if reference == 0:
        return 1.0 if mean_gradient(output) == 0 else float("inf")
    return mean_gradient(output) / reference


def band_sharpness(image: np.ndarray, band: int) -> float:
    """Mean gradient in the middle half of the re-synthesized band over that of the kept part,
    for ``image`` made tileable with a band of ``band`` pixels (the band straddles the wrap:
    its middle half is within ``band / 4`` of the edges, the kept part farther than
    ``band / 2``). 1 when the band is as sharp as the photo; under 0.9 it shows as a soft cross.

    Examples
    --------
    >>> noise = np.random.default_rng(0).random((128, 128))
    >>> round(band_sharpness(noise, 32), 1)
    1.0
    """
    y = luminance(image)
    h, w = y.shape
    if not 4 <= band <= min(h, w) // 2:
        raise ValueError(f"band must be from 4 to {min(h, w) // 2} pixels, got {band}")
    g = np.hypot(np.roll(y, -1, axis=1) - y, np.roll(y, -1, axis=0) - y)
    i = np.minimum(np.arange(h), h - 1 - np.arange(h))[:, None]  # distance to the wrap, rows
    j = np.minimum(np.arange(w), w - 1 - np.arange(w))[None, :]
    middle = (i < band // 4) | (j < band // 4)
    kept = (i >= band // 2 + 1) & (j >= band // 2 + 1)
    reference = g[kept].mean()
    return float(g[middle].mean() / reference) if reference > 0 else 1.0


def _wasserstein_1d(a: np.ndarray, b: np.ndarray, quantiles: int = 512) -> float:
    """W1 between two samples of any sizes: the mean gap between their quantile functions."""
    p = (np.arange(quantiles) + 0.5) / quantiles
    return float(np.abs(np.quantile(a, p) - np.quantile(b, p)).mean())


def subband_distance(exemplar: np.ndarray, output: np.ndarray, scales: int = 4,
                     orientations: int = 4) -> float:
    """Mean over pixels and every subband (residuals included) of W1 / exemplar band std.

    The exemplar is made periodic first (periodic + smooth split) so its border jump does not
    count as texture; the depth is capped by the smaller image.
    """
    ex = periodic_component(luminance(exemplar).astype(np.float32))
    out = luminance(output).astype(np.float32)
    depth = min(scales, max_scales(ex.shape), max_scales(out.shape))
    bands_ex = SteerablePyramid(ex.shape, depth, orientations).analyze(ex).arrays()
    bands_out = SteerablePyramid(out.shape, depth, orientations).analyze(out).arrays()
    pairs = [(ex, out), *zip(bands_ex, bands_out, strict=True)]
    return float(np.mean([_wasserstein_1d(e, o) / max(float(e.std()), 1e-8) for e, o in pairs]))


def patch_distance(exemplar: np.ndarray, output: np.ndarray, size: int = 8,
                   samples: int = 1000, seed: int = 0) -> dict:
    """Nearest-exemplar-patch distance of sampled output patches.

    Returns ``{"median": m, "copy_share": s}``: ``m`` is the median over sampled output patches of
    min over exemplar patches of ||p - q||^2 / ||p - mean(p)||^2 (all channels; the mean is taken
    per channel); ``s`` the share of patches under :data:`COPY_THRESHOLD` (verbatim copies).
    Output patches may wrap (outputs are periodic); exemplar patches do not. The search is exact
    and brute force: ||q||^2 - 2 p.q as one float32 matrix product per block of samples against
    every exemplar patch (about 2 s for 1000 samples against a 256 x 256 RGB exemplar here),
    then the exact distance of the winner.
    """
    ex = np.asarray(exemplar, np.float32)
    out = np.asarray(output, np.float32)
    ex = ex[:, :, None] if ex.ndim == 2 else ex
    out = out[:, :, None] if out.ndim == 2 else out
    if ex.shape[2] != out.shape[2]:
        raise ValueError(f"exemplar has {ex.shape[2]} channels, output {out.shape[2]}")
    if min(ex.shape[:2]) < size:
        raise ValueError(f"exemplar smaller than the {size} x {size} patch")
    bank = np.ascontiguousarray(
        sliding_window_view(ex, (size, size), axis=(0, 1)).reshape(-1, ex.shape[2] * size * size))
    rng = np.random.default_rng(seed)
    n = min(samples, out.shape[0] * out.shape[1])
    rows = rng.integers(0, out.shape[0], n)[:, None] + np.arange(size)
    cols = rng.integers(0, out.shape[1], n)[:, None] + np.arange(size)
    window = out[(rows % out.shape[0])[:, :, None], (cols % out.shape[1])[:, None, :]]
    probe = np.ascontiguousarray(window.transpose(0, 3, 1, 2).reshape(n, -1))  # as the bank

    bank_sq = np.einsum("ij,ij->i", bank, bank)
    nearest = np.empty(n, np.int64)
    for start in range(0, n, 256):
        scores = probe[start:start + 256] @ bank.T
        scores *= -2.0
        scores += bank_sq
        nearest[start:start + 256] = scores.argmin(axis=1)
    full = ((bank[nearest] - probe) ** 2).sum(axis=1)
    per_channel = probe.reshape(n, ex.shape[2], -1)
    energy = ((per_channel - per_channel.mean(axis=2, keepdims=True)) ** 2).sum(axis=(1, 2))
    ratio = full / np.maximum(energy, 1e-8)
    return {"median": float(np.median(ratio)), "copy_share": float((ratio < COPY_THRESHOLD).mean())}


def _coherence_histogram(y: np.ndarray, sigma: float, bins: int = 32) -> np.ndarray:
    gy = (np.roll(y, -1, axis=0) - np.roll(y, 1, axis=0)) / 2
    gx = (np.roll(y, -1, axis=1) - np.roll(y, 1, axis=1)) / 2
    jxx = gaussian_filter(gx * gx, sigma, mode="wrap")
    jyy = gaussian_filter(gy * gy, sigma, mode="wrap")
    jxy = gaussian_filter(gx * gy, sigma, mode="wrap")
    coherence = np.sqrt((jxx - jyy) ** 2 + 4 * jxy**2) / np.maximum(jxx + jyy, 1e-12)
    hist = np.histogram(coherence, bins=bins, range=(0.0, 1.0))[0].astype(np.float64)
    return hist / hist.sum()


def structure_distance(exemplar: np.ndarray, output: np.ndarray,
                       sigmas: tuple[float, ...] = (1.5, 4.0)) -> float:
    """Total-variation distance (0..1) of structure-tensor coherence histograms, mean over scales.

    Coherence ``sqrt((Jxx - Jyy)^2 + 4 Jxy^2) / (Jxx + Jyy)`` is 0 for isotropic texture and 1 for
    straight edges and stripes; its distribution says how much line-like structure an image has.
    Both images are taken periodic (the exemplar through its periodic component).
    """
    ex = periodic_component(luminance(exemplar).astype(np.float32)).astype(np.float64)
    out = luminance(output)
    return float(np.mean([0.5 * np.abs(_coherence_histogram(ex, s) - _coherence_histogram(out, s))
                          .sum() for s in sigmas]))


def self_distance(exemplar: np.ndarray) -> dict:
    """The distances between the exemplar's two halves (split across its longer side)."""
    ex = np.asarray(exemplar, np.float32)
    axis = 1 if ex.shape[1] >= ex.shape[0] else 0
    half = ex.shape[axis] // 2
    a, b = np.split(ex[:, : 2 * half] if axis else ex[: 2 * half], 2, axis=axis)
    b_periodic = periodic_component(b)  # as a synthesized output would be
    patches = patch_distance(a, b_periodic)
    return {
        "subband_distance": subband_distance(a, b_periodic),
        "patch_distance": patches["median"],
        "copy_share": patches["copy_share"],
        "structure_distance": structure_distance(a, b_periodic),
    }


def quality(exemplar: np.ndarray, output: np.ndarray) -> dict:
    """Every measure above for one output, as a flat dict."""
    patches = patch_distance(exemplar, output)
    return {
        "seam_ratio": seam_ratio(output),
        "subband_distance": subband_distance(exemplar, output),
        "patch_distance": patches["median"],
        "copy_share": patches["copy_share"],
        "structure_distance": structure_distance(exemplar, output),
    }


def autocorrelation(image: np.ndarray, lags: int = 7) -> np.ndarray:
    """The circular autocorrelation of the luminance's periodic component, zero-mean, divided
    by its variance: (2 lags + 1) x (2 lags + 1), lag 0 at the centre.

    Examples
    --------
    >>> import numpy as np
    >>> a = autocorrelation(np.random.default_rng(0).random((32, 32)), lags=2)
    >>> a.shape, float(a[2, 2])
    ((5, 5), 1.0)
    """
    y = periodic_component(luminance(image))
    y = y - y.mean()
    power = np.abs(np.fft.fft2(y)) ** 2
    c = np.real(np.fft.ifft2(power))
    c = np.fft.fftshift(c / c[0, 0])
    h, w = c.shape
    return c[h // 2 - lags:h // 2 + lags + 1, w // 2 - lags:w // 2 + lags + 1]


def autocorrelation_error(exemplar: np.ndarray, output: np.ndarray, lags: int = 7) -> float:
    """RMS difference of the central lags of :func:`autocorrelation` (15 x 15 by default; the
    centre, 1 on both sides, counts too): 0 for the same structure, about 0.1-0.3 for a texture
    whose periodicities are lost.

    Examples
    --------
    >>> import numpy as np
    >>> stripes = np.tile(np.sin(np.arange(64) * 2 * np.pi / 8), (64, 1))
    >>> autocorrelation_error(stripes, stripes) < 1e-6
    True
    """
    return float(np.sqrt(np.mean((autocorrelation(exemplar, lags)
                                  - autocorrelation(output, lags)) ** 2)))


def _radial_log_power(image: np.ndarray, bins: int) -> np.ndarray:
    """Mean power per pixel of the luminance's periodic component in ``bins`` rings of radius
    (cycles per pixel, 0 excluded, up to 0.5), log10; NaN for an empty ring."""
    y = periodic_component(luminance(image))
    power = np.abs(np.fft.rfft2(y - y.mean())) ** 2 / y.size
    fy = np.fft.fftfreq(y.shape[0])[:, None]
    fx = np.fft.rfftfreq(y.shape[1])[None, :]
    ring = np.floor(np.hypot(fx, fy) / 0.5 * bins).astype(int).ravel()
    keep = (ring < bins) & (ring >= 0)
    keep[0] = False                                          # the mean
    total = np.bincount(ring[keep], power.ravel()[keep], bins)
    count = np.bincount(ring[keep], minlength=bins)
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.log10(total / count + 1e-20)


def power_spectrum_correlation(exemplar: np.ndarray, output: np.ndarray, bins: int = 32) -> float:
    """Pearson correlation of the radially averaged log power spectra of the two images'
    luminance (periodic components; rings on the radius in cycles per pixel, so sizes may
    differ); 1 for the same spectrum.

    Examples
    --------
    >>> import numpy as np
    >>> noise = np.random.default_rng(0).random((64, 64))
    >>> round(power_spectrum_correlation(noise, noise), 6)
    1.0
    """
    a, b = _radial_log_power(exemplar, bins), _radial_log_power(output, bins)
    both = np.isfinite(a) & np.isfinite(b)
    return float(np.corrcoef(a[both], b[both])[0, 1])


def course_period(image: np.ndarray) -> int:
    """The course height of an image of rows (bricks, setts): the first peak of the
    autocorrelation of its row profile (each row's mean luminance), between 8 px and a quarter
    of the height.

    Examples
    --------
    >>> rows = np.repeat((np.arange(128) % 20 < 3)[:, None], 64, axis=1).astype(np.float32)
    >>> course_period(rows)
    20
    """
    p = luminance(image).mean(axis=1)
    p = p - p.mean()
    a = np.correlate(p, p, "full")[len(p) - 1:]
    return 8 + int(np.argmax(a[8:max(9, len(p) // 4)]))


def course_steps(image: np.ndarray, period: int, strip: int = 32, wrap: bool = True) -> float:
    """Where do the courses of a wall step? The share of places, per pair of neighbouring
    column strips (``strip`` px; across the wrap too when ``wrap``) and window of two courses
    (one every course), at which the vertical shift that best correlates the two strips' row
    profiles, within half a course either way, is a quarter course or more: 0 for straight
    courses, whatever their slope of under a quarter course a strip.

    Examples
    --------
    >>> rows = np.repeat((np.arange(128) % 16 < 3)[:, None], 64, axis=1).astype(np.float32)
    >>> course_steps(rows, 16)
    0.0
    >>> rows[:, 32:] = np.roll(rows[:, 32:], 8, axis=0)  # the right half half a course off
    >>> course_steps(rows, 16)
    1.0
    """
    y = luminance(image)
    h, w = y.shape
    n = w // strip
    prof = y[:, :n * strip].reshape(h, n, strip).mean(axis=2)
    left, right = (prof, np.roll(prof, -1, axis=1)) if wrap else (prof[:, :-1], prof[:, 1:])
    half = period // 2
    shifts = np.arange(-half, half + 1)
    starts = np.arange(half, h - 2 * period - half, period)
    rows = starts[:, None] + np.arange(2 * period)[None, :]  # (windows, 2 T)

    def standard(a):  # (windows, 2 T, strips): each window's profile centred, unit norm
        a = a - a.mean(axis=1, keepdims=True)
        return a / np.maximum(np.sqrt((a * a).sum(axis=1, keepdims=True)), 1e-6)

    a = standard(left[rows])
    corr = np.stack([(a * standard(right[rows + d])).sum(axis=1) for d in shifts])
    best = shifts[corr.argmax(axis=0)]  # (windows, strips)
    return float((np.abs(best) >= period / 4).mean())


def repetition_peak(image: np.ndarray, min_shift: float = 24.0) -> float:
    """The largest peak of the luminance's autocorrelation at a shift of at least
    ``min_shift`` pixels (Euclidean length), over every shift up to half the image across and
    down: about 1 when the image shows a texture laid side by side, about the photo's own
    for a synthesis that repeats no more than its photo.

    The autocorrelation is the zero-mean luminance's, linear (zero-padded: the image need not
    tile), each shift's sum over its overlap's pixels and over the variance; a peak is a shift
    at least as high as its 8 neighbours (the tail of the central lobe is none).

    References
    ----------
    Lefebvre & Hoppe 2005, 4 (repetition seen as the autocorrelation's off-centre peaks).

    Examples
    --------
    >>> tile = np.random.default_rng(0).random((32, 32))
    >>> round(repetition_peak(np.tile(tile, (4, 4))), 2)
    1.0
    >>> bool(repetition_peak(np.random.default_rng(1).random((128, 128))) < 0.1)
    True
    """
    y = luminance(image)
    y = y - y.mean()
    h, w = y.shape
    var = float((y * y).mean())
    if var <= 0.0:
        return 0.0
    spectrum = np.fft.rfft2(y, s=(2 * h, 2 * w))
    c = np.fft.fftshift(np.fft.irfft2(np.abs(spectrum) ** 2, s=(2 * h, 2 * w)))
    dy, dx = np.arange(-(h // 2), h // 2 + 1), np.arange(-(w // 2), w // 2 + 1)
    c = c[h + dy[:, None], w + dx[None, :]]
    r = c / ((h - np.abs(dy))[:, None] * (w - np.abs(dx))[None, :]) / var
    peak = r >= maximum_filter(r, size=3, mode="nearest")
    far = np.hypot(dy[:, None], dx[None, :]) >= min_shift
    found = r[peak & far]
    return float(found.max()) if found.size else 0.0


def anisotropy(image: np.ndarray, sigma: float = 1.0, weights: np.ndarray | None = None
               ) -> float:
    """The anisotropy of the structure tensor summed over the whole image, ``(l1 - l2) / (l1 +
    l2)`` of its eigenvalues: 0 when no gradient direction prevails (gravel; a texture
    turned every way), towards 1 for parallel stripes (layers, courses, streaks).

    Gradients are Gaussian derivatives (``sigma`` pixels) of the luminance. ``weights`` (H,
    W), non-negative: the tensor summed with these weights (each pixel counted as often as
    it is weighted), not uniformly.

    References
    ----------
    Bigun & Granlund 1987 (the structure tensor); Jahne 2005, 13.3 (its coherence).

    Examples
    --------
    >>> x = np.arange(64)
    >>> stripes = np.tile(np.sin(x / 3.0), (64, 1))
    >>> noise = np.random.default_rng(0).random((64, 64))
    >>> round(anisotropy(stripes), 2), bool(anisotropy(noise) < 0.1)
    (1.0, True)
    >>> half = np.concatenate([stripes[:32], noise[32:]])
    >>> on_stripes = np.repeat([1.0, 0.0], 32)[:, None] * np.ones(64)
    >>> a = [anisotropy(half, weights=w) for w in (on_stripes, None, 1 - on_stripes)]
    >>> bool(a[0] > a[1] > a[2])
    True
    """
    y = luminance(image)
    w = 1.0 if weights is None else np.broadcast_to(weights, y.shape)
    gx = gaussian_filter(y, sigma, order=(0, 1))
    gy = gaussian_filter(y, sigma, order=(1, 0))
    jxx, jyy, jxy = (w * gx * gx).sum(), (w * gy * gy).sum(), (w * gx * gy).sum()
    trace = jxx + jyy
    return float(np.sqrt((jxx - jyy) ** 2 + 4 * jxy ** 2) / trace) if trace > 0 else 0.0

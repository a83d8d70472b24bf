"""Steerable pyramid built in the frequency domain, periodic by construction.

Simoncelli and Freeman's steerable pyramid as used by Heeger and Bergen (Forsyth & Ponce, sections
11.2.3 and 11.3.2; Van De Ville et al. 2009, section 2.1, eq. 1): a high-pass residual, ``scales``
levels of ``K = orientations`` oriented band-pass subbands, and a low-pass residual. Every filter is
a polar-separable mask on the discrete Fourier grid, so the transform is circular (the output of a
synthesis tiles) and works for any image size, not only powers of two.

The band-pass filters of level j are B_m(w) = (-i)^(K-1) alpha_K cos^(K-1)(theta - theta_m) *
H_j(|w|), theta_m = m pi / K (eq. 1 of Van De Ville et al. 2009), and the radial masks are square
roots of raised cosines on log2 |w| so that ``H_j^2 + L_j^2 = 1`` and the pyramid is a tight frame:
synthesis is the adjoint of analysis and reconstructs exactly (to float32 rounding).

Deviations from pyrtools' ``SteerablePyramidFreq`` (same filters otherwise):
- real FFTs (``rfft2``) and float32 / complex64 throughout (the masks are built in float64,
  cos(theta - theta_m) as the projection of the unit frequency, no arctan2, and stored float32;
  the band filters complex64 with their phase);
- the inverse transforms of all subbands of an analysis, and the forward transforms of a
  synthesis (a level's bands two by two), run side by side on every core
  (``texsynth.blocks.parallel``), one core each, and are combined in a fixed order, so results
  do not depend on the number of cores; the spectra and products live in work arrays kept from
  call to call, and the transforms write into them (``texsynth.blocks.fft``);
- radii are measured in cycles per pixel of the *full-resolution* grid, and each decimation crops
  the spectrum and rescales it by the ratio of sizes, so band values are samples of the same
  band-limited function whatever the image size. An exemplar and an output of different sizes
  then have directly comparable subband statistics.
"""

from __future__ import annotations

import math
import threading
from dataclasses import dataclass, field

import numpy as np

from . import fft
from .parallel import run

__all__ = ["SteerablePyramid", "LaplacianPyramid", "Coefficients", "max_scales", "pyramid_depth"]


def max_scales(shape: tuple[int, int]) -> int:
    """Deepest pyramid an image of ``shape`` supports (coarsest band keeps >= 4 pixels a side)."""
    return max(0, int(math.floor(math.log2(min(shape)))) - 2)


def pyramid_depth(exemplar_shape, width: int, height: int, scales: int) -> int:
    """``scales`` capped so that both the exemplar's and the output's pyramids exist."""
    return min(scales, max_scales(exemplar_shape[:2]), max_scales((height, width)))


def _check_scales(shape: tuple[int, int], scales: int) -> None:
    if not 0 <= scales <= max_scales(shape):
        raise ValueError(f"an image of {shape[1]} x {shape[0]} supports at most "
                         f"{max_scales(shape)} scales, {scales} were asked for")


def _grid(shape_level: tuple[int, int], shape_full: tuple[int, int],
          rows: slice = slice(None)):
    """Radius (cycles per full-resolution pixel, Nyquist = 1) on ``rows`` of a level's rfft grid,
    and the frequency's two components fx, fy (float64)."""
    h, w = shape_level
    ky = (np.fft.fftfreq(h) * h)[rows]
    kx = np.fft.rfftfreq(w) * w
    fy = (2.0 * ky / shape_full[0])[:, None]
    fx = (2.0 * kx / shape_full[1])[None, :]
    radius = np.sqrt(fx * fx + fy * fy)
    return radius, fx, fy


#: Rows of a spectrum per block of the elementwise passes run on the cores (cache-sized), and
#: of the frequency grid while masks are built (their float64 temporaries stay in cache).
ROWS, MASK_ROWS = 128, 32


def _by_rows(function, rows: int, size: int = ROWS) -> None:
    """``function(slice)`` on blocks of ``size`` rows, on every core (elementwise work: the
    split changes nothing)."""
    run(function, [slice(a, min(a + size, rows)) for a in range(0, rows, size)])


def _masks_by_rows(shape_level, shape_full, count: int, fill) -> list[np.ndarray]:
    """``count`` float32 masks on a level's rfft grid, each (h, w // 2 + 1), filled block of
    rows by block: ``fill(radius, fx, fy)`` gives the block's ``count`` masks."""
    h, w = shape_level
    out = [np.empty((h, w // 2 + 1), np.float32) for _ in range(count)]

    def block(rows: slice) -> None:
        for k, mask in enumerate(fill(*_grid(shape_level, shape_full, rows))):
            out[k][rows] = mask

    _by_rows(block, h, MASK_ROWS)
    return out


def _radial_masks(radius: np.ndarray, top: float):
    """(high, low) square-root raised-cosine masks for the octave ``[top/2, top]``."""
    with np.errstate(divide="ignore"):
        t = np.clip(np.log2(radius / top) + 1.0, 0.0, 1.0)
    t *= 0.5 * np.pi
    return np.sin(t), np.cos(t)


def _band_filters(radius, fx, fy, high, orientations: int) -> list[np.ndarray]:
    """The K filters alpha_K cos^(K-1)(theta - theta_m) H_j on a level's grid (float64).
    cos(theta - theta_m) is the unit frequency projected on (cos theta_m, sin theta_m)
    (theta = 0 at the origin, as arctan2(0, 0) gives)."""
    with np.errstate(divide="ignore"):
        inverse = np.where(radius > 0, 1.0 / radius, 0.0)
    ux, uy = fx * inverse, fy * inverse
    ux[radius == 0] = 1.0
    gain = _angular_gain(orientations)

    def band(m: int) -> np.ndarray:
        c = ux * math.cos(np.pi * m / orientations)
        c += uy * math.sin(np.pi * m / orientations)
        f = gain * c if orientations > 1 else np.full_like(c, gain)
        for _ in range(orientations - 2):                  # cos^(K-1)
            f *= c
        f *= high
        return f

    return [band(m) for m in range(orientations)]


def _angular_gain(orientations: int) -> float:
    """alpha_K, making sum_m alpha_K^2 cos^(2(K-1))(theta - theta_m) = 1 for every theta."""
    order = orientations - 1
    return math.sqrt(
        2 ** (2 * order) * math.factorial(order) ** 2
        / (orientations * math.factorial(2 * order))
    )


@dataclass
class Coefficients:
    """Subbands of one image: ``highpass``, ``bands[scale][orientation]``, ``lowpass``."""

    highpass: np.ndarray
    bands: list[list[np.ndarray]] = field(default_factory=list)
    lowpass: np.ndarray | None = None

    def arrays(self) -> list[np.ndarray]:
        """All subbands in a fixed order: high-pass, bands coarse-ward, low-pass."""
        return [self.highpass, *(b for level in self.bands for b in level), self.lowpass]

    def replaced(self, arrays: list[np.ndarray]) -> Coefficients:
        """The same layout filled with ``arrays`` (in the order of :meth:`arrays`)."""
        it = iter(arrays)
        high = next(it)
        bands = [[next(it) for _ in level] for level in self.bands]
        return Coefficients(high, bands, next(it))


class SteerablePyramid:
    """Analysis and synthesis operators for images of one ``shape``.

    Masks and cropping indices are computed once here and reused at every iteration;
    ``progress`` (a ``texsynth.progress.Progress``), if given, hears of each level's masks.
    With ``full`` (a larger shape, ``shape`` one of its pyramid's level shapes), the pyramid is
    that of the levels of ``full``'s pyramid from ``shape``'s down: radii are measured on
    ``full``'s grid, so analysing its low-passed level (the Laplacian pyramid's G_j) gives
    ``full``'s bands of levels j.. (its high-pass mask is 0 there, the low-pass 1) without
    transforming the full-size image.
    """

    def __init__(self, shape: tuple[int, int], scales: int = 4, orientations: int = 4,
                 progress=None, full: tuple[int, int] | None = None):
        if not 1 <= orientations <= 16:
            raise ValueError(f"orientations must be 1..16, got {orientations}")
        _check_scales(shape, scales)
        self.shape = tuple(shape)
        self.scales = scales
        self.orientations = orientations
        self.phase = (-1j) ** (orientations - 1)
        full = tuple(full or shape)
        grid, octave = full, 0                                  # halvings from full to shape
        while grid != self.shape and min(grid) > 1:
            grid, octave = ((grid[0] + 1) // 2, (grid[1] + 1) // 2), octave + 1
        if grid != self.shape:
            raise ValueError(f"{self.shape} is not a pyramid level of {full}")
        self.hi0, self.lo0 = _masks_by_rows(self.shape, full, 2,
                                            lambda radius, fx, fy: _radial_masks(radius, 1.0))
        self.level_shapes = [self.shape]
        self.band_filters: list[list[np.ndarray]] = []          # B_m of eq. 1, complex64
        self.low_masks: list[np.ndarray] = []
        for j in range(scales):
            shape_j = self.level_shapes[-1]

            def fill(radius, fx, fy, top=2.0 ** -(j + 1 + octave)):
                high, low = _radial_masks(radius, top)
                return [*_band_filters(radius, fx, fy, high, orientations), low]

            *filters, low = _masks_by_rows(shape_j, full, orientations + 1, fill)
            # B_m with its phase, complex64: one product a band (phase * F is exact)
            self.band_filters.append([(f * np.complex64(self.phase)).astype(np.complex64)
                                      for f in filters])
            self.level_shapes.append(((shape_j[0] + 1) // 2, (shape_j[1] + 1) // 2))
            # L_j is zero outside the crop (below): only its cropped part is ever used
            n1, n2, columns = self._halves(j)
            self.low_masks.append(np.concatenate([low[:n1, :columns],
                                                  low[shape_j[0] - n2:, :columns]]))
            if progress is not None:
                progress((j + 1) / scales, "building the pyramid's filters")
        self._buffers: dict = {}

    def _buffer(self, name, shape: tuple[int, int], dtype=np.complex64) -> np.ndarray:
        """A work array of ``name`` for the calling thread, kept from call to call: fresh arrays
        of many MB are fresh pages, and zeroing them took a tenth of the transforms' time."""
        key = (name, shape, threading.get_ident())
        buffer = self._buffers.get(key)
        if buffer is None:
            buffer = self._buffers[key] = np.empty(shape, dtype)
        return buffer

    def _halves(self, j: int) -> tuple[int, int, int]:
        """Level j+1's rfft grid inside level j's: its ``n1`` rows of frequencies >= 0 are the
        parent's first, its ``n2`` negative ones the parent's last, its ``columns`` the first."""
        child = self.level_shapes[j + 1]
        return (child[0] + 1) // 2, child[0] // 2, child[1] // 2 + 1

    # The low-pass spectrum of level j is zero beyond half its band, so cropping the rows and
    # columns of the lower frequencies loses nothing; scaling by the size ratio keeps values.
    def _crop(self, spectrum: np.ndarray, j: int) -> np.ndarray:
        """The child's spectrum: ``spectrum`` L_j, cropped and rescaled (a kept buffer)."""
        parent, child = self.level_shapes[j], self.level_shapes[j + 1]
        n1, n2, columns = self._halves(j)
        ratio = np.float32(child[0] * child[1] / (parent[0] * parent[1]))
        cropped = self._buffer("low", (child[0], columns))
        cropped[:n1] = spectrum[:n1, :columns]
        cropped[n1:] = spectrum[parent[0] - n2:, :columns]
        cropped *= self.low_masks[j]
        cropped *= ratio
        return cropped

    def _embed_into(self, total: np.ndarray, spectrum: np.ndarray, j: int,
                    by_rows: bool = False) -> None:
        """The adjoint of :meth:`_crop` added to ``total``: the child's ``spectrum`` (which it
        overwrites) rescaled, times L_j, added at its frequencies (``by_rows``: row blocks on
        the cores)."""
        parent, child = self.level_shapes[j], self.level_shapes[j + 1]
        n1, n2, columns = self._halves(j)
        ratio = np.float32(parent[0] * parent[1] / (child[0] * child[1]))

        def embed(r: slice) -> None:
            block = spectrum[r]
            block *= ratio
            block *= self.low_masks[j][r]
            # child rows r hold the parent's rows r (frequencies >= 0) or r + parent - child
            shift = 0 if r.start < n1 else parent[0] - child[0]
            target = total[r.start + shift:r.stop + shift, :columns]
            np.add(target, block, out=target)

        blocks = [slice(0, n1), slice(n1, child[0])]
        if by_rows:
            blocks = [slice(a, min(a + ROWS, b.stop)) for b in blocks
                      for a in range(b.start, b.stop, ROWS)]
            run(embed, blocks)
        else:
            for block in blocks:
                embed(block)

    def band_shapes(self) -> list[tuple[int, int]]:
        """Shapes of the subbands, in the order of :meth:`Coefficients.arrays`."""
        levels = (s for s in self.level_shapes[:-1] for _ in range(self.orientations))
        return [self.shape, *levels, self.level_shapes[-1]]

    def analyze(self, image: np.ndarray, tick=None, out: Coefficients | None = None,
                each=None) -> Coefficients:
        """Subbands of a 2-D float image of this pyramid's shape; ``tick()`` after each. With
        ``out`` (an earlier analysis of this pyramid), its arrays are overwritten and returned.
        ``each(i, band)``, if given, runs on subband i (the order of
        :meth:`Coefficients.arrays`) in the thread that made it, as soon as it is made."""
        image = np.asarray(image, dtype=np.float32)
        if image.shape != self.shape:
            raise ValueError(f"pyramid built for {self.shape}, image is {image.shape}")
        if out is None:
            k = self.orientations
            arrays = [np.empty(s, np.float32) for s in self.band_shapes()]
            out = Coefficients(arrays[0], [arrays[1 + j * k: 1 + (j + 1) * k]
                                           for j in range(self.scales)], arrays[-1])
        bands = out.arrays()
        spectrum = fft.rfft2(image, out=self._buffer("spectrum", _half(self.shape)))
        # every band's spectrum is a cheap product; their inverse transforms are the work
        jobs = [(spectrum, self.hi0)]
        low = self._buffer("low", _half(self.shape))
        _by_rows(lambda r: np.multiply(spectrum[r], self.lo0[r], out=low[r]), self.shape[0])
        for j in range(self.scales):
            jobs += [(low, f) for f in self.band_filters[j]]
            low = self._crop(low, j)
        jobs.append((low, None))
        run(self._band, [(i, job, band, each) for i, (job, band)
                         in enumerate(zip(jobs, bands, strict=True))], tick)
        return out

    def _band(self, job) -> None:
        """One subband: the spectrum times its filter (if any), back to pixels into the band,
        on one core."""
        i, (spectrum, f), band, each = job
        if f is not None:
            spectrum = np.multiply(spectrum, f, out=self._buffer("product", f.shape))
        fft.irfft2(spectrum, band.shape, out=band, workers=1)
        if each is not None:
            each(i, band)

    def synthesize(self, coeffs: Coefficients, tick=None, out: np.ndarray | None = None
                   ) -> np.ndarray:
        """The image whose analysis gives ``coeffs`` (the adjoint of :meth:`analyze`), into
        ``out`` (float32, this pyramid's shape) or a new array; ``tick()`` after each group of
        subbands."""
        # The adjoint takes conj(B_m) = sign B_m, sign = (-1)^(K-1) (the phase's square): the
        # sums below run on sign times the spectra, the sign applied to the low-pass and at the
        # end (exact).
        sign = np.float32(-1.0 if self.orientations % 2 == 0 else 1.0)
        # jobs: the high-pass, each level's bands two by two (a fixed grouping), the low-pass
        jobs = [([coeffs.highpass], [self.hi0])]
        groups = []
        for level, filters in zip(coeffs.bands, self.band_filters, strict=True):
            pairs = range(0, len(level), 2)
            groups.append(len(pairs))
            jobs += [(level[m:m + 2], filters[m:m + 2]) for m in pairs]
        jobs.append(([coeffs.lowpass], [None]))
        totals = [self._buffer(("total", i), _half(bands[0].shape))
                  for i, (bands, _) in enumerate(jobs)]
        spectra = run(self._filtered_spectrum, zip(jobs, totals, strict=True), tick)
        low, start = spectra[-1], 1 + sum(groups)
        low *= sign
        for j in reversed(range(1, self.scales)):
            start -= groups[j]
            total = spectra[start]
            self._embed_into(total, low, j)
            for partial in spectra[start + 1:start + groups[j]]:
                total += partial
            low = total
        # level 0 and the residuals at full size: one pass, row blocks on the cores
        level = spectra[1:1 + groups[0]] if self.scales else [low]
        total = level[0]
        if self.scales:
            self._embed_into(total, low, 0, by_rows=True)

        def finish(r: slice) -> None:
            block = total[r]
            for partial in level[1:]:
                block += partial[r]
            block *= self.lo0[r]
            if sign < 0:
                np.subtract(spectra[0][r], block, out=block)
            else:
                block += spectra[0][r]

        _by_rows(finish, self.shape[0])
        return fft.irfft2(total, self.shape, out=out)

    def _filtered_spectrum(self, job) -> np.ndarray:
        """Sum of a few subbands' spectra times their filters (``None``: none), into ``total``,
        on one core."""
        (bands, filters), total = job
        for k, (band, f) in enumerate(zip(bands, filters, strict=True)):
            spectrum = fft.rfft2(band, workers=1, out=total if k == 0 else
                                 self._buffer("product", total.shape))
            if f is not None:
                spectrum *= f
            if k:
                total += spectrum
        return total


def _half(shape: tuple[int, int]) -> tuple[int, int]:
    """The rfft grid of an image of ``shape``."""
    return shape[0], shape[1] // 2 + 1


# --- Laplacian pyramid ------------------------------------------------------------------------


class LaplacianPyramid:
    """Burt and Adelson's Laplacian pyramid on the discrete Fourier grid (Forsyth & Ponce, 11.2.1).

    ``G_0`` is the image; ``G_{j+1}`` is ``G_j`` low-passed by the steerable pyramid's radial
    mask ``L_j`` (zero beyond half of level j's band) and decimated by cropping its spectrum, and
    ``P_j = G_j - S_up(G_{j+1}) = (1 - L_j) G_j`` (eq. 11.2.2). Levels are ``[P_0 .. P_{S-1},
    G_S]`` with the shapes, and the sample positions (sample i of level j at 2^j i), of
    :class:`SteerablePyramid`'s levels; filtering is circular, so the pyramid is periodic, and
    synthesis (Algorithm 11.2: upsample, add) reconstructs exactly for any size.

    Deviations: ``S_up`` is band-limited (zero-padded spectrum) rather than pixel replication,
    and the smoothing is the raised-cosine mask, not a Gaussian.
    """

    def __init__(self, shape: tuple[int, int], scales: int = 4):
        _check_scales(shape, scales)
        self.shape = tuple(shape)
        self.scales = scales
        self.level_shapes = [self.shape]
        self.low_masks: list[np.ndarray] = []
        self.crop_rows: list[np.ndarray] = []
        for j in range(scales):
            parent = self.level_shapes[-1]
            self.low_masks += _masks_by_rows(parent, self.shape, 1, lambda radius, fx, fy, j=j:
                                             _radial_masks(radius, 2.0 ** -(j + 1))[1:])
            child = ((parent[0] + 1) // 2, (parent[1] + 1) // 2)
            ky = np.round(np.fft.fftfreq(child[0]) * child[0]).astype(np.int64)
            self.crop_rows.append(np.where(ky >= 0, ky, parent[0] + ky))
            self.level_shapes.append(child)

    def _ratio(self, j: int) -> np.float32:
        parent, child = self.level_shapes[j], self.level_shapes[j + 1]
        return np.float32(child[0] * child[1] / (parent[0] * parent[1]))

    def analyze(self, image: np.ndarray, spectrum: np.ndarray | None = None
                ) -> list[np.ndarray]:
        """``[P_0, .., P_{S-1}, G_S]`` of a 2-D float image of this pyramid's shape (float32);
        ``spectrum``, if given, is the image's :func:`~texsynth.blocks.fft.rfft2` (then
        ``image`` may be None)."""
        if spectrum is None:
            image = np.asarray(image, dtype=np.float32)
            if image.shape != self.shape:
                raise ValueError(f"pyramid built for {self.shape}, image is {image.shape}")
            spectrum = fft.rfft2(image)
        levels = []
        for j in range(self.scales):
            low = spectrum * self.low_masks[j]
            levels.append(fft.irfft2(spectrum - low, self.level_shapes[j]))
            child = self.level_shapes[j + 1]
            spectrum = low[self.crop_rows[j], : child[1] // 2 + 1] * self._ratio(j)
        levels.append(fft.irfft2(spectrum, self.level_shapes[self.scales]))
        return levels

    def synthesize(self, levels: list[np.ndarray], level: int = 0) -> np.ndarray:
        """Algorithm 11.2: from the coarsest level, upsample and add each finer level, down to
        ``G_level`` (``levels`` from ``P_level`` on, or all of them)."""
        levels = levels[len(levels) - (self.scales + 1 - level):]
        spectrum = fft.rfft2(levels[-1])
        for j in reversed(range(level, self.scales)):
            # the coarser spectrum zero-padded and added, in place: no padded copy and sum at
            # the finest size (issue 40: a 2048^2 output's collapse touched 2.5x its share)
            child = self.level_shapes[j + 1]
            finer = fft.rfft2(levels[j - level])
            finer[self.crop_rows[j], : child[1] // 2 + 1] += spectrum / self._ratio(j)
            spectrum = finer
        return fft.irfft2(spectrum, self.level_shapes[level])



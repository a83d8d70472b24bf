"""Periodic + smooth decomposition of an image (Moisan 2011), and a tiled preview.

A photograph is not periodic: its FFT sees a jump where the right edge meets the left one, which
puts a bright cross in the spectrum and oriented energy into every pyramid band. Moisan's
decomposition ``u = p + s`` splits the image into a periodic component ``p`` with the same content
and a smooth component ``s`` that carries the border jump. Frequency-domain analysis of ``p`` sees
the texture only.

Reference: L. Moisan, "Periodic plus smooth image decomposition", J. Math. Imaging Vis. 39 (2011),
section 2, eq. (7): s_hat(q, r) = v_hat(q, r) / (2 cos(2 pi q / M) + 2 cos(2 pi r / N) - 4).
"""

from __future__ import annotations

import numpy as np
import scipy.fft as sfft

from . import fft

__all__ = ["periodic_component", "periodic_spectrum", "boundary_image", "tile_preview"]


def boundary_image(u: np.ndarray) -> np.ndarray:
    """Moisan's v: the jumps across the image border, placed on the border pixels."""
    v = np.zeros_like(u)
    d_rows = u[-1] - u[0]
    v[0] += d_rows
    v[-1] -= d_rows
    d_cols = u[:, -1] - u[:, 0]
    v[:, 0] += d_cols
    v[:, -1] -= d_cols
    return v


def periodic_component(u: np.ndarray) -> np.ndarray:
    """The periodic component p of ``u`` (2-D, or 3-D with channels last); float32.

    ``p`` keeps the mean of ``u``; ``u - p`` is smooth and zero-mean.
    """
    u = np.asarray(u, dtype=np.float32)
    if u.ndim == 3:
        return np.stack([periodic_component(u[:, :, c]) for c in range(u.shape[2])], axis=2)
    m, n = u.shape
    v_hat = sfft.rfft2(boundary_image(u))
    q = np.cos(2 * np.pi * np.fft.fftfreq(m)).astype(np.float32)[:, None]
    r = np.cos(2 * np.pi * np.fft.rfftfreq(n)).astype(np.float32)[None, :]
    denom = 2 * q + 2 * r - 4
    denom[0, 0] = 1.0
    s_hat = v_hat / denom
    s_hat[0, 0] = 0.0
    return (u - sfft.irfft2(s_hat, s=(m, n))).astype(np.float32)


def periodic_spectrum(u: np.ndarray) -> np.ndarray:
    """The real FFT (:func:`texsynth.blocks.fft.rfft2`, complex64) of the periodic component p
    of a 2-D ``u``: u's transform minus s_hat (eq. 7), without transforming p back and forth.

    v is zero but on the border, so v_hat is a sum of 1-D transforms: the row jump
    d = u[-1] - u[0] on rows 0 and M-1 gives rfft(d)[r] (1 - e^(2 pi i q / M)), the column jump
    likewise fft(d')[q] (1 - e^(2 pi i r / N)).
    """
    u = np.asarray(u, dtype=np.float32)
    m, n = u.shape
    spectrum = fft.rfft2(u)
    rows = sfft.rfft(u[-1] - u[0]).astype(np.complex64)
    columns = sfft.fft(u[:, -1] - u[:, 0]).astype(np.complex64)
    q = (1 - np.exp(2j * np.pi * np.fft.fftfreq(m))).astype(np.complex64)[:, None]
    r = (1 - np.exp(2j * np.pi * np.fft.rfftfreq(n))).astype(np.complex64)[None, :]
    denom = (2 * np.cos(2 * np.pi * np.fft.fftfreq(m)).astype(np.float32)[:, None]
             + 2 * np.cos(2 * np.pi * np.fft.rfftfreq(n)).astype(np.float32)[None, :] - 4)
    denom[0, 0] = 1.0
    s_hat = rows[None, :] * q
    s_hat += columns[:, None] * r
    s_hat /= denom
    s_hat[0, 0] = 0.0
    spectrum -= s_hat
    return spectrum


def tile_preview(image: np.ndarray, nx: int = 2, ny: int = 2) -> np.ndarray:
    """The image repeated ``nx`` times across and ``ny`` times down: a seam shows at once."""
    a = np.asarray(image)
    return np.tile(a if a.ndim == 3 else a[:, :, None], (ny, nx, 1))

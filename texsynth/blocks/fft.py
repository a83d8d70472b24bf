"""Real 2-D FFTs (float32 / complex64) that write into the caller's buffers.

``scipy.fft`` has no ``out=``: every transform returns a fresh array. Fresh arrays of many MB
are fresh pages from the kernel (numpy asks for huge pages), and zeroing them was 10 % of the
steerable pyramid's CPU time at 2048^2. The pocketfft binding that ``scipy.fft`` itself calls
(``scipy.fft._pocketfft.pypocketfft``, the same functions and arguments since scipy 1.4) takes
``out=``; without it, the public functions run and their result is copied. Both give scipy's
results bit for bit: the same passes in the same order, unnormalised forward and 1/n inverse.
"""

from __future__ import annotations

import numpy as np
import scipy.fft as sfft

from .parallel import threads

try:
    from scipy.fft._pocketfft import pypocketfft as _pocketfft
except ImportError:                                   # a scipy without it: copies, same results
    _pocketfft = None

__all__ = ["rfft2", "irfft2"]

_INVERSE = 2                                          # pocketfft's ``inorm``: divide by n


def rfft2(image: np.ndarray, out: np.ndarray | None = None,
          workers: int | None = None) -> np.ndarray:
    """The real FFT of a float32 (h, w) image: the rows' real transforms, then the columns'
    complex ones, into ``out`` (complex64, (h, w // 2 + 1)) or a new array; on every core by
    default, on one inside the pool (``texsynth.blocks.parallel.threads``)."""
    image = np.asarray(image, dtype=np.float32)
    workers = workers or threads()
    if _pocketfft is None:
        result = sfft.rfft2(image, workers=workers)
        if out is None:
            return result
        out[...] = result
        return out
    out = _pocketfft.r2c(image, (1,), True, 0, out, workers)
    return _pocketfft.c2c(out, (0,), True, 0, out, workers)


def irfft2(spectrum: np.ndarray, shape: tuple[int, int], out: np.ndarray | None = None,
           workers: int | None = None) -> np.ndarray:
    """The float32 image of ``shape`` whose :func:`rfft2` is ``spectrum``, into ``out`` or a new
    array. The columns' complex transforms run in place: ``spectrum`` is overwritten."""
    workers = workers or threads()
    if _pocketfft is None:
        columns = sfft.ifft(spectrum, axis=0, workers=workers, overwrite_x=True)
        result = sfft.irfft(columns, n=shape[1], axis=1, workers=workers, overwrite_x=True)
        if out is None:
            return result
        out[...] = result
        return out
    _pocketfft.c2c(spectrum, (0,), False, _INVERSE, spectrum, workers)
    return _pocketfft.c2r(spectrum, (1,), shape[1], False, _INVERSE, out, workers)

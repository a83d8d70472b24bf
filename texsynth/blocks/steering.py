"""Steering the oriented subbands of a steerable pyramid (Van De Ville et al. 2009, sections
2.1-2.2).

The K band filters of a level are B_k = (-i)^(K-1) alpha_K cos^(K-1)(theta - theta_k) * radial,
theta = atan2(fy, fx) and theta_k = pi k / K (k = 0..K-1; the paper counts m = 1..K), exactly as
:mod:`.pyramid` builds them. cos^(K-1) is a trigonometric polynomial whose harmonics n
run over N, N-2, ... >= 0 (N = K - 1): K real degrees of freedom, so the K filters span every
rotated copy, and the response of the filter turned to any angle phi is

    r(phi) = sum_k c_k(phi) w_k,   c_k(phi) = (1/K) sum_n eps_n cos(n (phi - theta_k)),       (2)

eps_0 = 1, eps_n = 2 otherwise. c_k is the closed-form solution of eq. 3 (the identity
sum_k c_k(phi) cos^N(theta - theta_k) = cos^N(theta - phi) follows from the orthogonality of
e^(i n theta_k) over the K angles); the steering kernels of eq. 3 are h_{m,k}(phi) =
c_k(phi + theta_m), i.e. channel m of a set steered by phi looks along theta_m + phi.

Computationally a coefficient vector w[k] (one per position of a level) is turned into its
harmonic coefficients a = (A_n, B_n) with r(phi) = sum_n A_n cos n phi + B_n sin n phi; steering
by phi rotates each pair (A_n, B_n) by n phi, and the steered vector is r(theta_m + phi). Steering
by phi then by -phi returns the input exactly (to float32 rounding).

theta_max (eq. 4) maximises r. Its derivative is a homogeneous polynomial of degree K - 1 in
(cos phi, sin phi), i.e. of degree K - 1 in tan phi (the paper's polynomial). With a single
non-constant harmonic (K = 2, 3) the root is in closed form, theta_max = atan2(B_n, A_n) / n.
Deviation: for K >= 4 the root is polished by one Halley step on r' from the best of 6 (K - 1)
samples of a half-turn, vectorised over all positions, instead of solving the polynomial (the
eigenvalues of 512^2 companion matrices of degree 3 alone take 45x longer; the tests compare
against a dense sweep). Where two orientations respond almost equally, the peak nearest the best
sample can be the lower one, by up to the sampling error (at most a few per cent of r; about 0.1%
of the positions of real bands).

Angles are in the pyramid's frequency-plane convention (from +fx towards +fy, rows going down).
theta_max lies in [0, 2 pi) for even K (then r(phi + pi) = -r(phi) and the steered first channel
is >= 0) and in [0, pi) for odd K (r has period pi).
"""

from __future__ import annotations

import numpy as np

from .parallel import small_product

__all__ = ["Steering", "steering_kernels"]

#: Positions per block in the angle search, so that its (M, block) samples stay in cache.
CHUNK = 16384


def _harmonics(orientations: int) -> np.ndarray:
    """Harmonic orders of cos^(K-1): K-1, K-3, ... down to 0 or 1, ascending."""
    return np.arange((orientations - 1) % 2, orientations, 2)


def steering_kernels(orientations: int, phi) -> np.ndarray:
    """h_{m,k}(phi) of eq. 3, shape ``phi.shape + (K, K)``: row m mixes the K bands into the
    filter looking along theta_m + phi."""
    k = orientations
    theta = np.pi * np.arange(k) / k
    phi = np.asarray(phi, np.float64)[..., None, None]
    diff = phi + theta[:, None] - theta[None, :]          # (theta_m + phi) - theta_k
    out = np.zeros(diff.shape, np.float64)
    for n in _harmonics(k):
        out += (1.0 if n == 0 else 2.0) * np.cos(n * diff)
    return out / k


class Steering:
    """Steering of the K oriented subbands of one pyramid level, vectorised over positions.

    Coefficient arrays have the orientations on the first axis: ``w`` is (K, ...) with
    ``w[k]`` the band of filter theta_k = pi k / K.
    """

    def __init__(self, orientations: int):
        if not 1 <= orientations <= 8:
            raise ValueError(f"steering supports 1..8 orientations, got {orientations}")
        k = orientations
        self.orientations = k
        self.harmonics = _harmonics(k)
        self.period = 2 * np.pi if k % 2 == 0 else np.pi
        # columns of the harmonic basis: cos n phi (every n), then sin n phi (n > 0)
        self._sin_n = self.harmonics[self.harmonics > 0]
        first = len(self.harmonics) - len(self._sin_n)
        self._pairs = [(first + j, len(self.harmonics) + j, np.float32(n))
                       for j, n in enumerate(self._sin_n)]       # (cos column, sin column, n)
        theta = np.pi * np.arange(k) / k
        analyse = np.linalg.inv(self._basis(theta))
        self.evaluate = self._basis(theta).astype(np.float32)          # w = E a
        self.analyse = analyse.astype(np.float32)                      # a = E^-1 w
        # M samples of a half-turn: responses r(sample) = _samples @ w; cos, sin of n * sample
        m = 6 * (k - 1)
        self._spacing = np.float32(np.pi / max(m, 1))
        samples = np.pi * np.arange(m) / max(m, 1)
        self._samples = (self._basis(samples) @ analyse).astype(np.float32)         # (M, K)
        self._cos = np.cos(self._sin_n[:, None] * samples).astype(np.float32)        # (n, M)
        self._sin = np.sin(self._sin_n[:, None] * samples).astype(np.float32)

    def _basis(self, phi: np.ndarray) -> np.ndarray:
        """(len(phi), K) matrix B with r(phi) = B a."""
        phi = np.asarray(phi, np.float64)[:, None]
        return np.concatenate([np.cos(self.harmonics * phi), np.sin(self._sin_n * phi)], axis=1)

    def steer(self, w: np.ndarray, phi) -> np.ndarray:
        """The bands turned by ``phi`` (per position): channel m looks along theta_m + phi.

        Each harmonic pair (A_n, B_n) of r is rotated by n phi; ``steer(steer(w, phi), -phi)``
        returns ``w``.
        """
        w = np.asarray(w, np.float32)
        phi = np.broadcast_to(np.asarray(phi, np.float32), w.shape[1:]).reshape(-1)
        a = small_product("mk,kp->mp", self.analyse, w.reshape(self.orientations, -1))
        for ic, is_, n in self._pairs:
            angle = n * phi
            cos_n, sin_n = np.cos(angle), np.sin(angle)
            big_a = a[ic].copy()
            a[ic] *= cos_n
            a[ic] += a[is_] * sin_n
            a[is_] *= cos_n
            a[is_] -= big_a * sin_n
        return small_product("mk,kp->mp", self.evaluate, a).reshape(w.shape)

    def response(self, w: np.ndarray, phi) -> np.ndarray:
        """r(phi): the response of the filter turned to ``phi`` (eq. 2), per position."""
        return self.steer(w, phi)[0]

    def optimal_angle(self, w: np.ndarray) -> np.ndarray:
        """theta_max of eq. 4 for every position of (K, ...) bands, float32 of shape ``...``."""
        w = np.asarray(w, np.float32)
        flat = w.reshape(self.orientations, -1)
        if self.orientations == 1:
            theta = np.zeros(flat.shape[1], np.float32)
        elif len(self._pairs) == 1:                       # K = 2, 3: closed form
            ic, is_, n = self._pairs[0]
            a = small_product("mk,kp->mp", self.analyse[[ic, is_]], flat)
            theta = np.arctan2(a[1], a[0]) / n
        else:                                             # in chunks that stay in cache
            theta = np.empty(flat.shape[1], np.float32)
            for i in range(0, flat.shape[1], CHUNK):
                theta[i:i + CHUNK] = self._halley(flat[:, i:i + CHUNK])
        period = np.float32(self.period)
        theta %= period
        theta[theta >= period] = 0                        # -tiny % period rounds to period
        return theta.reshape(w.shape[1:])

    def _halley(self, w: np.ndarray) -> np.ndarray:
        """Root of r' by one Halley step from the best of M samples of a half-turn.

        For even K the best sample maximises |r|; where r < 0 there, the maximum of r is half a
        turn away, since r(phi + pi) = -r(phi). From within half a sample spacing, Halley's cubic
        convergence leaves an angle error around 1e-3 rad (r within 1e-5 of its peak).
        """
        even = self.orientations % 2 == 0
        samples = small_product("mk,kp->mp", self._samples, w)       # (M, P) responses
        if even:
            np.abs(samples, out=samples)
        best = _argmax_rows(samples, signed=not even).astype(np.intp)
        del samples
        # r and its derivatives at the sample, harmonic by harmonic: with u = A cos + B sin and
        # v = B cos - A sin at n phi, r^(j) sums n^j (u, v, -u, -v)[j]
        a = small_product("mk,kp->mp", self.analyse, w)
        r0, r1, r2, r3 = (np.zeros(w.shape[1], np.float32) for _ in range(4))
        for (ic, is_, n), cos_table, sin_table in zip(self._pairs, self._cos, self._sin,
                                                      strict=True):
            cos, sin = cos_table[best], sin_table[best]
            u = a[ic] * cos
            u += a[is_] * sin
            v = a[is_] * cos
            v -= a[ic] * sin
            r0 += u
            v *= n
            r1 += v
            u *= n * n
            r2 -= u
            v *= n * n
            r3 -= v
        denominator = 2 * r2 * r2 - r1 * r3
        step = r1 * r2
        step *= -2
        np.divide(step, denominator, out=step, where=denominator != 0)
        np.clip(step, -self._spacing, self._spacing, out=step)
        theta = best.astype(np.float32)
        theta *= self._spacing
        theta += step
        if even:                                          # even K has no constant harmonic
            theta += np.float32(np.pi) * (r0 < 0)
        return theta


def _argmax_rows(values: np.ndarray, signed: bool = True) -> np.ndarray:
    """Index of the largest row per column of a float32 (M, P) array, M <= 64; overwrites it.

    The row index is packed into the 6 low mantissa bits of an order-preserving integer view, so
    one ``max`` along the rows finds value and index together (``argmax(axis=0)`` is ~5x slower).
    ``signed=False`` promises values >= 0.
    """
    keys = values.view(np.int32)
    if signed:
        keys ^= (keys >> 31) & 0x7FFFFFFF              # negative floats: reverse their order
    keys &= ~63
    keys |= np.arange(len(keys), dtype=np.int32)[:, None]
    return keys.max(axis=0) & 63

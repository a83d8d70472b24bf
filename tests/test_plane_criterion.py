"""The texture fit's criterion (Forsyth & Ponce sec. 11.4.1, oriented band energies of local
spectra back-projected by a plane hypothesis): binned however the windows are split, the same
numbers as a sample-by-sample reference."""

import math

import numpy as np
import pytest
from _planes import noise_texture, photograph

from texsynth.blocks import parallel
from texsynth.plane import fit, spectra
from texsynth.plane.geometry import gradient, jacobians

#: A NaN or an overflow in the estimate is garbage on its way out (issue 27): an error here.
pytestmark = pytest.mark.filterwarnings("error::RuntimeWarning")

HYPOTHESES = [(0.0, 0.0, None), (40.0, 35.0, 300.0), (65.0, 250.0, 260.0), (30.0, 120.0, None)]


@pytest.fixture(scope="module")
def criterion():
    photo = photograph(noise_texture(), 45.0, 60.0, 300.0)
    small, _ = spectra.downsample(spectra.luminance(photo))
    fine = spectra.spectra(small, spectra.texture_mask(small), fit._MOMENT_W_MAX, fit._WINDOW)
    return spectra.Criterion(fine).band_limited(fit._W_MAX)


def _plane(slant, tilt, focal):
    p = gradient(slant, tilt)
    return p, np.zeros(2) if focal is None else p / focal


@pytest.mark.parametrize("chunk, workers", [(1, 1), (1, 2), (1 << 12, 2), (1 << 30, 1)])
def test_bands_do_not_depend_on_how_the_windows_are_split(criterion, monkeypatch, chunk,
                                                          workers):
    """One window at a time on one thread, or all at once, or in chunks side by side on two:
    the same band energies, noise and validity, to the bit (a window's bands are its own)."""
    expected = [criterion.bands(*_plane(*h)) for h in HYPOTHESES]
    monkeypatch.setattr(spectra, "_CHUNK", chunk)
    monkeypatch.setattr(parallel, "WORKERS", workers)
    for h, want in zip(HYPOTHESES, expected, strict=True):
        got = criterion.bands(*_plane(*h))
        for a, b in zip(got, want, strict=True):
            assert np.array_equal(a, b), h


def _jacobian(centre, p, v):
    """J at a window's centre, held at the depth ratio g = _G_MIN nearer the horizon."""
    jac, g = jacobians(centre[None], p, v)
    return jac[0] * (g[0] / max(g[0], spectra._G_MIN)) ** 2


def _reference_sums(criterion, p, v, window):
    """Sample by sample: each sample's bilinear weights on its four (scale, orientation) cells,
    orientations modulo K, for one window."""
    s = criterion.s
    jac = _jacobian(s.centres[window], p, v)
    nu = np.linalg.inv(jac).T @ s.w  # nu = J^-T w
    k = spectra._ANGLES
    cells = (criterion.scales, k)
    wsum, w2sum, psum = np.zeros(cells), np.zeros(cells), np.zeros(cells)
    for (x, y), power in zip(nu.T, s.psd[window], strict=True):
        r = (0.5 * math.log2(x * x + y * y) - spectra._LOG_RANGE[0]) / spectra._DLOG
        r = min(max(r, 0.0), criterion.scales - 1.001)
        t = (math.atan2(y, x) % math.pi) / (math.pi / k) - 0.5
        r0, t0 = math.floor(r), math.floor(t)
        for dr, dt in ((0, 0), (0, 1), (1, 0), (1, 1)):
            w = (r - r0 if dr else 1 - (r - r0)) * (t - t0 if dt else 1 - (t - t0))
            cell = (r0 + dr, (t0 + dt) % k)
            wsum[cell] += w
            w2sum[cell] += w * w
            psum[cell] += w * power
    return wsum, w2sum, psum


@pytest.mark.parametrize("slant, tilt, focal", HYPOTHESES[1:3])
def test_band_energies_match_a_sample_by_sample_reference(criterion, slant, tilt, focal):
    """The energies and noise the criterion scores are the reference's, cell by cell, across
    the wrap of orientation (pi is 0), from the first scale any window's samples reach."""
    p, v = _plane(slant, tilt, focal)
    energy, noise, valid, _ = criterion.bands(p, v)
    windows = range(len(criterion.s.psd))
    sums = [_reference_sums(criterion, p, v, i) for i in windows]
    first = min(int(np.flatnonzero(wsum.any(axis=1))[0]) for wsum, _, _ in sums)
    rows = slice(first, first + energy.shape[1])
    assert valid.any()
    for i, (wsum, w2sum, psum) in zip(windows, sums, strict=True):
        det = abs(np.linalg.det(_jacobian(criterion.s.centres[i], p, v)))
        ok = valid[i]
        w, w2, pw = (x[rows][ok] for x in (wsum, w2sum, psum))
        assert np.all(w > 0) and not wsum[:first].any()
        # bin positions are float32 in the criterion: 1e-3 of log energy, its noise ~0.1
        np.testing.assert_allclose(energy[i][ok], np.log(pw / w) + math.log(det), rtol=0,
                                   atol=1e-3)
        np.testing.assert_allclose(noise[i][ok], 1.5 * w2 / w ** 2, rtol=1e-3)


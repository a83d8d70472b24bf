"""Portilla-Simoncelli: the projections impose what they promise, and the output keeps a
regular texture's autocorrelation where histogram matching loses it."""

import numpy as np

import texsynth
from texsynth.algorithms import portilla_simoncelli as ps
from texsynth.metrics import autocorrelation_error, seam_ratio


def _weave(side=64, period=8, seed=0):
    """A regular texture: a lattice of blobs (period 8 px) with noise, in colour, not tiling."""
    rng = np.random.default_rng(seed)
    yy, xx = np.mgrid[:side, :side].astype(np.float32)
    lattice = np.cos(2 * np.pi * xx / period) * np.cos(2 * np.pi * yy / period)
    grey = 0.5 + 0.3 * lattice + 0.05 * rng.standard_normal((side, side)).astype(np.float32)
    grey += np.float32(0.1) * xx / side                          # the photo does not tile
    return np.stack([grey, 0.8 * grey + 0.1, 0.6 * grey + 0.2], axis=2).astype(np.float32)


def test_a_covariance_and_a_cross_covariance_are_imposed_exactly():
    rng = np.random.default_rng(0)
    x, y = rng.standard_normal((3, 5000)), rng.standard_normal((2, 5000))
    a = rng.standard_normal((3, 3))
    cx, cxy = a @ a.T + np.eye(3), 0.3 * rng.standard_normal((3, 2))
    out = ps._adjust_covariance(x.astype(np.float32), cx, y.astype(np.float32), cxy)
    assert np.allclose(ps._gram(out, out), cx, atol=1e-3)
    assert np.allclose(ps._gram(out, y.astype(np.float32)), cxy, atol=1e-3)
    alone = ps._adjust_covariance(x.astype(np.float32), cx)
    assert np.allclose(ps._gram(alone, alone), cx, atol=1e-3)


def test_the_central_autocorrelation_is_imposed():
    source = np.random.default_rng(1).standard_normal((64, 64)).astype(np.float32)
    target = ps._autocorrelation(_weave()[:, :, 0], 3)
    before = np.abs(ps._autocorrelation(source, 3) - target).max()
    after = np.abs(ps._autocorrelation(ps._impose_autocorrelation(source, target), 3) - target)
    assert after.max() < 0.1 * before


def test_keeps_a_regular_textures_autocorrelation_better_than_heeger_bergen():
    weave = _weave()
    out = texsynth.synthesize(weave, 80, 72, method="portilla_simoncelli", seed=0,
                              iterations=10)
    hb = texsynth.synthesize(weave, 80, 72, method="heeger_bergen", seed=0)
    assert out.shape == (72, 80, 3) and 0.8 < seam_ratio(out) < 1.25
    assert autocorrelation_error(weave, out) < 0.5 * autocorrelation_error(weave, hb)
    assert np.all(out >= weave.min(axis=(0, 1))) and np.all(out <= weave.max(axis=(0, 1)))
    # the colours stay on the photo's line of colours (one PCA component carries them)
    assert np.corrcoef(out[:, :, 0].ravel(), out[:, :, 1].ravel())[0, 1] > 0.95

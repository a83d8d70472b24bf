"""De Bonet's parent-structure sampling (Forsyth & Ponce, section 11.3.3, Algorithm 11.5)."""

import numpy as np
import pytest
from scipy.ndimage import gaussian_filter

import texsynth
from texsynth.algorithms.de_bonet import (
    BallSampler,
    de_bonet,
    parent_structure,
    pyramid_features,
    sample_pyramid,
)
from texsynth.blocks.periodic import periodic_component
from texsynth.blocks.pyramid import LaplacianPyramid, SteerablePyramid
from texsynth.progress import Progress


def _photo(size=48, channels=3, seed=0):
    """Smooth blobs plus a ramp: a texture that does not tile."""
    rng = np.random.default_rng(seed)
    noise = gaussian_filter(rng.random((size, size, channels)), (2, 2, 0), mode="reflect")
    ramp = np.linspace(0, 0.5, size)[None, :, None]
    return ((noise - noise.min()) / np.ptp(noise) * 0.5 + ramp).astype(np.float32)


def _spots_on_lines(size=64, period=8, seed=3):
    """Bright 2 x 2 spots at random places along horizontal lines ``period`` rows apart."""
    rng = np.random.default_rng(seed)
    image = np.zeros((size, size), np.float32)
    for y in range(0, size, period):
        for x in rng.choice(size // 4, size // 16, replace=False) * 4:
            image[y:y + 2, x:x + 2] = 1.0
    return image


def _line_alignment(image):
    """Mean over all lags of the normalised autocorrelation along the rows (the line
    direction): the variance of the row means over the pixel variance. Spots on rows keep it
    high; spots placed independently of one another drive it towards 0."""
    y = image[:, :, 0] if image.ndim == 3 else image
    return float(y.mean(axis=1).var() / y.var())


def test_threshold_zero_copies_only_identical_parent_structures():
    exemplar = _photo(size=64)
    pyramid = LaplacianPyramid((64, 64), 3)
    features = pyramid_features(periodic_component(exemplar), SteerablePyramid((64, 64), 3, 4),
                                pyramid)
    sources = sample_pyramid(features, pyramid.level_shapes, 0.0, 2,
                             np.random.default_rng(3), Progress())
    flat = [f.reshape(-1, f.shape[2]) for f in features]
    identity = [np.arange(f.shape[0] * f.shape[1]).reshape(f.shape[:2]) for f in features]
    scale = dict.fromkeys(range(len(features)), 1.0)
    for level in range(len(features) - 1):
        shape = pyramid.level_shapes[level]
        rows = np.arange(shape[0] * shape[1])
        output = parent_structure(flat, sources, level, 2, scale, shape, rows)
        chosen = parent_structure(flat, identity, level, 2, scale, shape,
                                  sources[level].ravel())
        np.testing.assert_array_equal(output, chosen)
    # ... which, with every parent structure distinct, reproduces the exemplar, shifted
    out = de_bonet(exemplar, 64, 64, np.random.default_rng(3), Progress(), threshold=0.0,
                   depth=2, scales=3)
    p = np.clip(periodic_component(exemplar), exemplar.min(axis=(0, 1)),
                exemplar.max(axis=(0, 1)))
    shift = divmod(int(np.argmin([np.abs(np.roll(p, divmod(i, 64), (0, 1)) - out).mean()
                                  for i in range(64 * 64)])), 64)
    np.testing.assert_allclose(np.roll(p, shift, (0, 1)), out, atol=1e-5)


def test_spots_on_lines_stay_on_lines_where_heeger_bergen_scatters_them():
    exemplar = _spots_on_lines()
    target = _line_alignment(exemplar)
    hb = texsynth.synthesize(exemplar, 128, 128, method="heeger_bergen", seed=0, iterations=5)
    assert _line_alignment(hb) < 0.1 * target                  # measured 0.08
    for threshold in (0.5, 1.0):                                # measured 0.88, 0.60
        db = texsynth.synthesize(exemplar, 128, 128, method="de_bonet", seed=0,
                                 threshold=threshold)
        assert _line_alignment(db) > 0.5 * target


def test_ball_sampler_is_uniform_over_every_point_in_the_ball_and_nearest_outside():
    grid = np.stack(np.meshgrid(np.arange(20.0), np.arange(20.0)), -1).reshape(-1, 2)
    query = np.array([[9.5, 9.3]])
    inside = np.flatnonzero(np.hypot(*(grid - query).T) <= 3.2)
    assert len(inside) > BallSampler.ladder[0]     # the ball needs the second rung
    for ladder in (BallSampler.ladder, (2, 4)):    # (2, 4): rejection sampling does it
        sampler = BallSampler(grid)
        sampler.ladder = ladder
        sampler.radius = 3.2
        rng = np.random.default_rng(0)
        draws = sampler.draw(np.repeat(query, 20 * len(inside), 0), rng)
        counts = np.bincount(draws, minlength=len(grid))
        assert set(np.flatnonzero(counts)) == set(inside)
        assert counts[inside].min() > 5 and counts[inside].max() < 40   # mean 20
    sampler.radius = 0.1
    far = sampler.draw(np.array([[30.0, 4.2], [9.5, 9.3]]), rng)
    assert grid[far[0]].tolist() == [19.0, 4.0]
    assert np.hypot(*(grid[far[1]] - [9.5, 9.3])) < 0.6   # a nearest point, none within 0.1


@pytest.mark.parametrize("params, message", [
    ({"threshold": -0.1}, "threshold"),
    ({"depth": 0}, "depth"),
    ({"threshold": "low"}, "threshold"),
    ({"radius": 2}, "no parameter"),
])
def test_bad_parameters_raise(params, message):
    with pytest.raises(ValueError, match=message):
        texsynth.synthesize(_photo(), 32, 32, method="de_bonet", **params)


def test_too_small_an_exemplar_raises():
    with pytest.raises(ValueError, match="at least 16"):
        texsynth.synthesize(np.zeros((12, 40, 3)), 32, 32, method="de_bonet")



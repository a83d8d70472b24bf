"""The periodic, frequency-domain Laplacian pyramid (Forsyth & Ponce, section 11.2.1, Alg.
11.1-11.2)."""

import numpy as np
import pytest

from texsynth.blocks.pyramid import LaplacianPyramid, SteerablePyramid


@pytest.mark.parametrize("shape, scales", [((64, 64), 4), ((37, 50), 3), ((33, 17), 2),
                                           ((16, 16), 0)])
def test_synthesis_reconstructs_exactly_at_any_size(shape, scales):
    image = np.random.default_rng(0).random(shape).astype(np.float32)
    pyramid = LaplacianPyramid(shape, scales)
    levels = pyramid.analyze(image)
    assert [level.shape for level in levels] == pyramid.level_shapes
    assert pyramid.level_shapes == SteerablePyramid(shape, scales, 4).level_shapes
    np.testing.assert_allclose(pyramid.synthesize(levels), image, atol=2e-6)


def test_levels_are_band_pass_and_the_top_keeps_values():
    pyramid = LaplacianPyramid((64, 64), 3)
    levels = pyramid.analyze(np.full((64, 64), 0.7, np.float32))
    assert all(np.abs(level).max() < 1e-6 for level in levels[:-1])
    np.testing.assert_allclose(levels[-1], 0.7, atol=1e-6)
    # a period of 16 pixels lies wholly in the band of level 2 (radius 1/8 of Nyquist)
    x = np.cos(2 * np.pi * np.arange(64) / 16).astype(np.float32)
    levels = pyramid.analyze(np.tile(x, (64, 1)))
    assert [round(float(np.abs(level).max()), 3) for level in levels] == [0, 0, 1, 0]


def test_analysis_is_circular():
    image = np.random.default_rng(1).random((48, 40)).astype(np.float32)
    pyramid = LaplacianPyramid((48, 40), 3)
    shifted = pyramid.analyze(np.roll(image, (8, -16), (0, 1)))
    for j, (a, b) in enumerate(zip(pyramid.analyze(image), shifted, strict=True)):
        np.testing.assert_allclose(np.roll(a, (8 >> j, -16 >> j), (0, 1)), b, atol=1e-5)


def test_too_many_scales_raise():
    with pytest.raises(ValueError, match="at most"):
        LaplacianPyramid((16, 16), 3)

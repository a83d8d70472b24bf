"""Heeger-Bergen from a photo larger than the output: statistics of the whole photo."""

import numpy as np

import texsynth
from tests._images import smooth_noise
from texsynth.algorithms import heeger_bergen as hb
from texsynth.metrics import mean_gradient, seam_ratio


def test_tiles_cover_the_photo_and_own_an_equal_partition_of_it():
    for length, size in [(4000, 2048), (3000, 2048), (1000, 1000), (1001, 250), (700, 64)]:
        tiles = hb._tiles(length, size)
        assert len(tiles) == -(-length // size)
        owned = []
        for start, a, b in tiles:
            assert 0 <= start and start + size <= length and 0 <= a <= b <= size
            owned += range(start + a, start + b)
        assert owned == list(range(length))                 # each pixel counted once


def test_a_photo_larger_than_the_output_gives_its_whole_statistics():
    # fine grain on the left half, coarse on the right: a crop of either is not the photo
    fine, coarse = smooth_noise((64, 128), seed=1, sigma=1.0), smooth_noise((64, 128), 2, 6.0)
    photo = np.concatenate([fine, 0.5 + 0.5 * coarse], axis=1)
    out = texsynth.synthesize(photo, 64, 64, method="heeger_bergen", seed=0, iterations=5)
    assert out.shape == (64, 64, 3) and 0.8 < seam_ratio(out) < 1.25
    # as sharp as the whole photo: from the fine half's tile alone it was 2.4 times sharper
    assert 0.75 < mean_gradient(out) / mean_gradient(photo, wrap=False) < 1.35
    for q in (0.1, 0.5, 0.9):                               # the values of both halves
        np.testing.assert_allclose(np.quantile(out, q), np.quantile(photo, q), atol=0.04)


def test_large_photos_are_sampled_and_the_models_follow():
    shape, params = (3000, 4000, 3), hb.METHOD.resolve({})
    tile, tiles, own, values = hb._analysed(shape, 2048, 2048, params)
    assert (tile, tiles, own) == (2048 * 2048, 4, False)
    assert values < 25 * hb.SAMPLES                         # not the photo's 75 M a channel
    assert hb._memory(shape, 2048, 2048, params) < 1.5 * hb._memory((1024, 1024, 3), 2048,
                                                                      2048, params)

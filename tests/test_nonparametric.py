"""Efros-Leung and the multiscale MRF: tiling, determinism, position maps, errors, cancel."""

import numpy as np
import pytest

import texsynth
from texsynth.blocks.search import PatchMatrix, sample_near_best, sparse_subset, square_offsets
from texsynth.metrics import seam_ratio

from _images import smooth_noise

#: Small settings that keep each run well under a second.
METHODS = {
    "efros_leung": {"window": 5},
    "multiscale_mrf": {"levels": 2},
}


@pytest.fixture(scope="module")
def noise():
    return smooth_noise((40, 40), seed=4, sigma=1.5)


@pytest.mark.parametrize("method", METHODS)
def test_position_map_reproduces_the_output_and_carries_other_maps(method, noise):
    out, positions = texsynth.synthesize_positions(noise, 48, 40, method=method, seed=2,
                                                   **METHODS[method])
    assert positions.shape == (40, 48, 2) and positions.dtype == np.int32
    assert np.array_equal(out, texsynth.synthesize(noise, 48, 40, method=method, seed=2,
                                                   **METHODS[method]))
    assert np.array_equal(texsynth.apply_positions(positions, noise), out)
    height_map = (np.arange(40 * 40, dtype=np.uint16).reshape(40, 40) * 37)
    moved = texsynth.apply_positions(positions, height_map)
    assert moved.dtype == np.uint16
    assert np.array_equal(moved, height_map[positions[:, :, 0], positions[:, :, 1]])
    picture = texsynth.positions_image(positions, noise.shape)
    assert np.allclose(picture[:, :, 0], positions[:, :, 1] / 39)
    assert np.allclose(picture[:, :, 1], positions[:, :, 0] / 39)


def test_position_maps_are_refused_where_there_are_none(noise):
    with pytest.raises(ValueError, match="position map"):
        texsynth.synthesize_positions(noise, 32, 32, method="heeger_bergen")
    with pytest.raises(ValueError, match="exemplar's size"):
        texsynth.apply_positions(np.full((4, 4, 2), 50, np.int32), noise)


@pytest.mark.parametrize("method", METHODS)
def test_flat_patches_give_only_exemplar_colours(method):
    colours = np.array([[0.9, 0.1, 0.1], [0.1, 0.8, 0.2], [0.2, 0.2, 0.9], [0.9, 0.9, 0.2]],
                       np.float32)
    labels = np.zeros((32, 32), int)
    labels[:, 16:] = 1
    labels[16:, :] += 2
    exemplar = colours[labels]
    out = texsynth.synthesize(exemplar, 48, 48, method=method, seed=1, **METHODS[method])
    found = np.unique(out.reshape(-1, 3), axis=0)
    assert len(found) >= 2
    assert all((np.abs(colours - c).max(axis=1) == 0).any() for c in found)


def test_small_exemplars_are_refused_with_a_clear_error():
    small = smooth_noise((9, 12), seed=1)
    with pytest.raises(ValueError, match="smaller than the 11 x 11 window"):
        texsynth.synthesize(small, 32, 32, method="efros_leung")
    with pytest.raises(ValueError, match="smaller than the neighbourhood"):
        texsynth.synthesize(small, 32, 32, method="multiscale_mrf", radius=5)
    with pytest.raises(ValueError, match="odd"):
        texsynth.synthesize(smooth_noise((32, 32)), 32, 32, method="efros_leung", window=6)


@pytest.mark.parametrize("method", METHODS)
@pytest.mark.parametrize("size", [(5, 3), (37, 53)])
def test_odd_and_tiny_sizes(method, size, noise):
    width, height = size
    out = texsynth.synthesize(noise, width, height, method=method, **METHODS[method])
    assert out.shape == (height, width, 3) and np.isfinite(out).all()


def test_tileable_exemplar_windows_wrap(noise):
    periodic = smooth_noise((24, 24), seed=9)  # smooth_noise is periodic by construction
    out = texsynth.synthesize(periodic, 32, 32, method="efros_leung", window=7,
                              exemplar_tiles=True)
    assert seam_ratio(out) < 1.3


# --- the search helpers -------------------------------------------------------------------


def test_patch_matrix_distances_are_the_weighted_ssd():
    rng = np.random.default_rng(0)
    exemplar = rng.random((12, 10, 3), dtype=np.float32)
    offsets = square_offsets(3)
    patches = PatchMatrix(exemplar, offsets)
    assert len(patches.positions) == 10 * 8
    queries = rng.random((4, 9, 3), dtype=np.float32)
    weights = rng.random((4, 9), dtype=np.float32) * (rng.random((4, 9)) > 0.4)
    d, _ = patches.distances(queries, weights)
    p = patches.positions
    windows = exemplar[p[:, None, 0] + offsets[:, 0], p[:, None, 1] + offsets[:, 1]]
    expected = (weights[:, None, :, None] * (windows[None] - queries[:, None]) ** 2).sum((2, 3))
    assert np.allclose(d, expected, atol=1e-5)


def test_sample_near_best_keeps_to_the_epsilon_rule():
    rng = np.random.default_rng(1)
    d = np.array([[1.0, 1.05, 1.2, 3.0, 1.09]] * 4000, np.float32)
    pick, best = sample_near_best(d, 0.1, rng)
    assert np.all(best == 1.0)
    assert set(np.unique(pick)) == {0, 1, 4}
    counts = np.bincount(pick, minlength=5)[[0, 1, 4]]
    assert counts.min() > 1100  # uniform among the three


def test_sparse_subset_spacing_on_the_torus():
    rng = np.random.default_rng(2)
    shape = (30, 22)
    rows, cols = np.nonzero(rng.random(shape) < 0.5)
    priority = rng.random(len(rows))
    keep = sparse_subset(rows, cols, priority, shape, 4, rng)
    r, c = rows[keep], cols[keep]
    assert keep.sum() > 10
    dy = np.abs(r[:, None] - r[None]) % shape[0]
    dx = np.abs(c[:, None] - c[None]) % shape[1]
    cheb = np.maximum(np.minimum(dy, shape[0] - dy), np.minimum(dx, shape[1] - dx))
    np.fill_diagonal(cheb, 99)
    assert cheb.min() >= 4

"""The multiscale MRF on exemplars too large for whole tables (issue 25: camera photos).

Small images stand in for a 12 MP photo by lowering ``TABLE_ROWS``, so the lattice tables and
the on-demand windows of the finest levels run here as they do on the photo.
"""

import tracemalloc

import numpy as np
import pytest

import texsynth
import texsynth.algorithms.multiscale_mrf as mrf
import texsynth.blocks.period as period
from texsynth.blocks.multigrid import random_positions
from texsynth.blocks.search import Rows, WindowRows, best_candidate, disk_offsets, neighbour_table
from texsynth.metrics import gradient_ratio, seam_ratio

from _images import smooth_noise


@pytest.fixture
def small_tables(monkeypatch):
    """Tables of at most 32 x 32 positions: a 128 px exemplar takes the lattice of every 4th
    pixel on levels 2 and up, and whole-exemplar windows on levels 0 and 1; a 96 x 80 output
    refines on level 0 (coherent candidates only), as a 2048 output does."""
    monkeypatch.setattr(mrf, "TABLE_ROWS", 32 * 32)
    monkeypatch.setattr(mrf, "REFINE_PIXELS", 48 * 40)


@pytest.mark.parametrize("wrap", [False, True])
@pytest.mark.parametrize("step", [1, 2])
def test_windows_are_the_table_rows(wrap, step):
    rng = np.random.default_rng(0)
    image = rng.random((13, 17, 3), dtype=np.float32) - 0.5
    offsets = disk_offsets(2)
    k = len(offsets)
    table = neighbour_table(image, offsets, step, wrap, 7.0)[:-1]
    rows = WindowRows(image, 4, wrap, 7.0).at(offsets, step)[np.arange(13 * 17)]
    rows = rows.reshape(-1, k, 4)
    assert np.array_equal(rows[:, :, :3].reshape(-1, 3 * k), table[:, :3 * k])
    assert np.allclose(rows[:, :, 3], table[:, 3 * k:], rtol=1e-6)
    if not wrap:  # a corner pixel's neighbours up and left are outside: zero and D
        assert (rows[0][offsets.min(axis=1) < 0, 3] == 7.0).all()


def test_best_candidate_takes_the_nearest_and_keeps_a_better_current():
    table = Rows(np.array([[0.0], [1.0], [2.0], [3.0], [0.0]], np.float32))  # row 4: none
    z = np.ones((3, 1), np.float32)  # distance = the row's value
    cand = np.array([[3, 1, 4, 1], [4, 4, 4, 4], [2, 3, 2, 4]])
    current = np.array([2, 3, 0])
    assert best_candidate(table, cand, z, current, 4).tolist() == [1, 3, 0]


def test_random_starts_come_from_the_pool_without_repeats():
    rng = np.random.default_rng(1)
    pool = np.arange(0, 4000, 4)
    start = random_positions((20, 30), 4000, rng, pool)
    assert np.isin(start, pool).all() and len(np.unique(start)) == 600
    assert np.bincount(random_positions((40, 40), 100, rng).ravel()).min() == 16


def test_a_sample_measures_the_texel_of_a_large_photo(monkeypatch):
    y, x = np.mgrid[:1100, :1000]
    rng = np.random.default_rng(2)
    bricks = (((y % 40) < 4) | (((x + (y // 40) % 2 * 60) % 120) < 4)).astype(np.float32)
    photo = np.repeat((bricks + 0.3 * rng.random(bricks.shape))[:, :, None], 3, axis=2)
    sampled = period.texel_size(photo)
    monkeypatch.setattr(period, "SAMPLE_PIXELS", photo.shape[0] * photo.shape[1])
    assert abs(sampled - period.texel_size(photo)) <= 0.1 * sampled


def test_a_photo_beyond_the_tables_is_synthesized_from_all_of_it(small_tables):
    exemplar = smooth_noise((128, 128), seed=5, sigma=2.0)
    assert mrf.lattice_stride(exemplar.shape) == 4
    out, positions = texsynth.synthesize_positions(exemplar, 96, 80, seed=3, levels=4)
    again = texsynth.synthesize(exemplar, 96, 80, method="multiscale_mrf", seed=3, levels=4)
    assert np.array_equal(out, again)
    rows, cols = positions[:, :, 0], positions[:, :, 1]
    # every quarter of the photo is shown, and pixels off the coarse lattice too
    assert len(np.unique(2 * (rows // 64) + cols // 64)) == 4
    assert ((rows % 4 != 0) | (cols % 4 != 0)).mean() > 0.5
    assert 0.9 <= gradient_ratio(exemplar, out) <= 1.1
    assert 0.8 <= seam_ratio(out) <= 1.25


def test_the_memory_estimate_covers_the_windows_path(small_tables):
    exemplar = smooth_noise((128, 128), seed=6)
    record = texsynth.get_method("multiscale_mrf")
    estimate = record.memory(exemplar.shape, 96, 80, record.resolve({"levels": 4}))
    texsynth.synthesize(exemplar, 96, 80, method="multiscale_mrf", levels=4)
    tracemalloc.start()
    try:
        texsynth.synthesize(exemplar, 96, 80, method="multiscale_mrf", levels=4)
        _, peak = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    assert peak <= estimate

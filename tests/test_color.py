"""Heeger-Bergen keeps the exemplar's joint colour distribution (issue 17): no colours the photo
never had, and the sliced transport that ensures it."""

from pathlib import Path

import numpy as np
import pytest
from scipy.spatial import cKDTree

import texsynth
from texsynth.blocks.color import sliced_transfer
from texsynth.io import read_photo
from texsynth.metrics import subband_distance

SAMPLE = Path(__file__).resolve().parent.parent / "samples" / "pool_water.png"


def _off_palette(exemplar, output, tolerance=0.12):
    """Share of output pixels farther than ``tolerance`` (RGB) from every exemplar colour."""
    distance, _ = cKDTree(exemplar.reshape(-1, 3)).query(output.reshape(-1, 3))
    return float((distance > tolerance).mean())


@pytest.fixture(scope="module")
def pool_water():
    return read_photo(SAMPLE)[:, :, :3].astype(np.float32)


def test_heeger_bergen_on_pool_water_invents_no_colours(pool_water):
    out = texsynth.synthesize(pool_water, 192, 192, seed=0)
    assert _off_palette(pool_water, out) <= 0.002
    assert subband_distance(pool_water, out) < 0.06  # the bands still match (0.063 without OT)


def test_sliced_transfer_moves_a_cloud_onto_another():
    rng = np.random.default_rng(0)
    # Target: two saturated colours with noise; source: the axis-aligned box around them, whose
    # corners hold colours the target never had.
    centres = np.array([[0.9, 0.1, 0.8], [0.1, 0.8, 0.2]], np.float32)
    y = centres[rng.integers(0, 2, 4000)] + 0.02 * rng.standard_normal((4000, 3)).astype(np.float32)
    x = rng.random((6000, 3), dtype=np.float32)
    before = x.copy()
    moved = sliced_transfer(x, y, np.random.default_rng(1), 40)
    assert np.array_equal(x, before)  # input untouched
    assert moved.dtype == np.float32 and moved.shape == x.shape
    assert _off_palette(y, x, 0.1) > 0.9
    assert _off_palette(y, moved, 0.1) < 0.01
    again = sliced_transfer(x, y, np.random.default_rng(1), 40)
    assert np.array_equal(moved, again)

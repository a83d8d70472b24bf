"""texsynth.make_tileable: the photo itself made to tile, its centre kept, the band across the
wrap re-synthesized from its own pixels, the other maps following the same positions."""

import numpy as np
import pytest

import texsynth
from texsynth.metrics import seam_ratio

from _images import smooth_noise


@pytest.fixture(scope="module")
def photo():
    """A crop of a larger texture: it does not tile (its opposite edges differ)."""
    big = smooth_noise((160, 200), seed=3, sigma=2.0)
    return np.ascontiguousarray(big[13:109, 27:155])  # 128 x 96


def test_result_tiles_and_keeps_the_photo_where_it_can(photo):
    before = photo.copy()
    out = texsynth.make_tileable(photo, seed=0)
    assert np.array_equal(photo, before)  # input untouched
    assert out.shape == photo.shape and out.dtype == np.float32
    assert seam_ratio(photo) > 2.5
    assert seam_ratio(out) < 1.3
    assert seam_ratio(np.tile(out, (2, 2, 1))) < 1.3
    same = (out == photo).all(axis=2)
    assert same.mean() >= 0.5
    h, w = photo.shape[:2]
    assert same[h // 4:3 * h // 4, w // 4:3 * w // 4].all()  # the centre, untouched


def test_changed_pixels_are_photo_pixels_and_other_maps_follow(photo):
    out, positions = texsynth.make_tileable_positions(photo, seed=1)
    assert np.array_equal(texsynth.apply_positions(positions, photo), out)
    # Kept pixels map to themselves.
    h, w = photo.shape[:2]
    i, j = np.mgrid[:h, :w]
    same = (out == photo).all(axis=2)
    assert (positions[same, 0] == i[same]).all() and (positions[same, 1] == j[same]).all()
    # A second map of the material (here a height map of the same size) tiles the same way.
    height = photo.mean(axis=2)
    moved = texsynth.apply_positions(positions, height)
    assert seam_ratio(height) > 2.5 and seam_ratio(moved) < 1.3


def test_same_seed_same_result_and_bytes_are_read_as_fractions(photo):
    a = texsynth.make_tileable(photo, seed=4)
    b = texsynth.make_tileable(photo, seed=4)
    assert np.array_equal(a, b)
    as_bytes = np.rint(photo * 255).astype(np.uint8)
    c = texsynth.make_tileable(as_bytes, seed=4)
    assert c.dtype == np.float32 and 0.0 <= c.min() and c.max() <= 1.0


@pytest.mark.parametrize("band", [16, 32])
def test_changes_stay_inside_the_band_across_the_edges(photo, band):
    out = texsynth.make_tileable(photo, band=band)
    changed = (out != photo).any(axis=2)
    h, w = photo.shape[:2]
    i, j = np.mgrid[:h, :w]
    # Distance to the nearest edge, counted from the seam between the last and first pixel.
    to_edge = np.minimum(np.minimum(i + 0.5, h - 0.5 - i), np.minimum(j + 0.5, w - 0.5 - j))
    assert changed.any()
    assert not changed[to_edge > band / 2 + 0.5].any()


@pytest.mark.parametrize("kwargs, message", [
    ({"band": 80}, "more than half"),
    ({"band": 4}, "patch size"),
    ({"band": 2.5}, "whole number"),
    ({"seed": -1}, "seed"),
    ({"patch_size": 2}, "patch_size"),
])
def test_bad_input_says_what_to_change(photo, kwargs, message):
    with pytest.raises(ValueError, match=message):
        texsynth.make_tileable(photo, **kwargs)


def test_a_photo_smaller_than_two_patches_is_refused():
    with pytest.raises(ValueError, match="at least 16 x 16"):
        texsynth.make_tileable(np.zeros((12, 40, 3), np.float32))

"""texsynth.norepeat.tiles: Wang tiles made from a photo (Cohen et al. 2003). What a user would
notice: tiles that may meet continue each other across their shared edge (no seam at any cell
edge), a brick wall's courses stay in rows across cells, the same seed gives the same tiles,
and bad input is refused naming the argument."""

import tracemalloc

import numpy as np
import pytest

import texsynth
from texsynth.norepeat import (
    WangTiles,
    edge_colours,
    photo_use,
    predict_tiles_memory,
    repetition_peak,
    wang_tiles,
    wang_tiling,
    wang_tiling_positions,
)
from texsynth.norepeat.tiles import BAND

from _images import smooth_noise

COURSE, LENGTH, JOINT = 12, 28, 3


def bricks(shape=(160, 176), seed=0, course=COURSE):
    """A running-bond wall drawn by code: bricks of their own colour and grain, grey mortar
    (green channel above 0.5 only there); its size is no whole number of courses or bricks
    (``course`` may be a fraction of a pixel, as a photo's)."""
    rng = np.random.default_rng(seed)
    h, w = shape
    i, j = np.mgrid[:h, :w] + 5
    row = (i // course).astype(int)
    col = (j + (row % 2) * LENGTH // 2) // LENGTH
    colours = rng.uniform([0.45, 0.15, 0.1], [0.8, 0.35, 0.25], (row.max() + 1, col.max() + 2, 3))
    wall = colours[row, col] + 0.06 * smooth_noise(i.shape, seed=seed, sigma=1.0) - 0.03
    mortar = (i % course < JOINT) | ((j + (row % 2) * LENGTH // 2) % LENGTH < JOINT)
    wall[mortar] = 0.62 + 0.03 * rng.standard_normal((mortar.sum(), 1))
    return wall.astype(np.float32)


@pytest.fixture(scope="module")
def wall():
    return bricks()


@pytest.fixture(scope="module")
def tiles(wall):
    before = wall.copy()
    made = wang_tiles(wall, tile=72, colours=2, gutter=4, seed=3)
    assert np.array_equal(wall, before)  # the input is untouched
    return made


def _tile(tiles, n, e, s, w, gutter=False):
    """The tile's positions (T, T, 2), with its gutter when asked."""
    r, c = tiles.slot(n, e, s, w)
    g = tiles.gutter if gutter else 0
    return tiles.positions[r - g:r + tiles.tile + g, c - g:c + tiles.tile + g]


def test_the_atlas_holds_every_tile_with_its_photo_positions(wall, tiles):
    t, g = tiles.tile, tiles.gutter
    assert tiles.atlas.shape == (4 * (t + 2 * g),) * 2 + (3,)
    assert tiles.atlas.dtype == np.float32 and tiles.positions.dtype == np.int32
    assert np.array_equal(texsynth.apply_positions(tiles.positions, wall), tiles.atlas)
    slots = {tiles.slot(*nesw) for nesw in np.ndindex(2, 2, 2, 2)}
    assert len(slots) == 16  # one slot per tile


@pytest.mark.parametrize("across", [True, False])
def test_tiles_that_may_meet_continue_each_other_across_their_edge(tiles, across):
    """Left tile's east column and right tile's west column are photo neighbours (rows 1 to
    T - 2: a corner pixel belongs to the other edge), and its gutter is what the right tile
    shows wherever the cuts cannot reach (farther than BAND * T + gutter from the diagonals):
    the same holds down, between a tile and the one below it."""
    t, g = tiles.tile, tiles.gutter
    inner = slice(int(BAND * t) + g + 1, t - int(BAND * t) - g - 1)
    pairs = 0
    for a in np.ndindex(2, 2, 2, 2):
        for b in np.ndindex(2, 2, 2, 2):
            n, e, s, w = a
            if across and b[3] == e:  # b to the right of a
                first, second = _tile(tiles, *a), _tile(tiles, *b)
                gutter = _tile(tiles, *a, gutter=True)[g:g + t, g + t:]
                step = (0, 1)
            elif not across and b[0] == s:  # b below a
                first = _tile(tiles, *a).transpose(1, 0, 2)
                second = _tile(tiles, *b).transpose(1, 0, 2)
                gutter = _tile(tiles, *a, gutter=True)[g + t:, g:g + t].transpose(1, 0, 2)
                step = (1, 0)
            else:
                continue
            pairs += 1
            assert np.array_equal(first[1:-1, -1] + step, second[1:-1, 0])
            assert np.array_equal(gutter[inner], second[inner, :g])
    assert pairs == 128


def test_a_tiling_has_no_seam_at_any_cell_edge(wall, tiles):
    t = tiles.tile
    image, at = wang_tiling_positions(tiles, 6 * t, 5 * t, cells=(6, 5), seed=2, wrap=False)
    assert image.shape == (5 * t, 6 * t, 3) and at.dtype == np.int32
    assert np.array_equal(texsynth.apply_positions(at, wall), image)
    # Across every cell edge the photo continues (the corner pixels belong to the other edge).
    rows, cols = np.arange(5 * t) % t, np.arange(6 * t) % t
    inner_rows, inner_cols = (rows > 0) & (rows < t - 1), (cols > 0) & (cols < t - 1)
    for x in range(t, 6 * t, t):
        assert np.array_equal(at[inner_rows, x - 1] + (0, 1), at[inner_rows, x])
    for y in range(t, 5 * t, t):
        assert np.array_equal(at[y - 1, inner_cols] + (1, 0), at[y, inner_cols])


def test_the_courses_stay_in_rows_across_cells(tiles):
    """On the generated wall, rows that are mortar from side to side come every course as in
    the photo: the diamonds were placed in phase, so no cell shifts its courses."""
    t = tiles.tile
    image = wang_tiling(tiles, 6 * t, 6 * t, cells=6, seed=1)
    mortar = (image[:, :, 1] > 0.5).mean(axis=1)
    assert 0.8 * JOINT / COURSE < (mortar > 0.8).mean() <= 1.2 * JOINT / COURSE


def test_the_default_tile_is_whole_courses_and_keeps_them_in_rows():
    """Issue 41: courses of 11.6 px, and the default tile side (fitted to the photo's repeat
    alone it was 94 px, 8.1 courses, and a fifth of the mortar rows broke across cells) is a
    whole number of courses, every copy in phase: mortar rows from side to side come every
    course."""
    course = 11.6
    tiles = wang_tiles(bricks((200, 208), course=course), colours=2, gutter=4)
    off = tiles.tile / course - round(tiles.tile / course)
    image = wang_tiling(tiles, 6 * tiles.tile, 6 * tiles.tile, cells=6, seed=1)
    mortar = (image[:, :, 1] > 0.5).mean(axis=1)
    assert abs(off) <= 1 / 16
    assert 0.9 * JOINT / course < (mortar > 0.8).mean() <= 1.1 * JOINT / course


def test_every_tile_has_a_middle_of_its_own(tiles):
    """Issue 41: with the diamonds alone a shift of one cell showed the same diamond half the
    time (and the tiles' centres only 2 colours x 2 directions of photo pixels); each tile's
    centre now shows its own part of the photo, apart from every other tile's."""
    t = tiles.tile
    centres = np.array([_tile(tiles, *nesw)[t // 2, t // 2]
                        for nesw in np.ndindex(*(tiles.colours,) * 4)])
    apart = np.abs(centres[:, None] - centres[None, :]).max(axis=-1)
    np.fill_diagonal(apart, t)
    assert apart.min() >= t // 4


def test_the_default_tiling_repeats_at_no_shift():
    """Issue 41: laid 12 x 12 cells and seen at half the texels (as a render of the plane sees
    it), the default tile set's autocorrelation stays at most 0.3 at every shift of 24 px or
    more, cell shifts included (2 colours and a round middle of radii 0.22-0.44 read 0.41
    here: the diamonds repeated at whole cells)."""
    photo = smooth_noise((128, 128), seed=4, sigma=1.5, channels=3)
    tiles = wang_tiles(photo, gutter=4, seed=0)
    out = wang_tiling(tiles, 12 * tiles.tile, 12 * tiles.tile, cells=12, wrap=False)
    seen = out.reshape(out.shape[0] // 2, 2, out.shape[1] // 2, 2, 3).mean(axis=(1, 3))
    assert repetition_peak(seen, 24) <= 0.3


def test_photo_use_is_how_often_a_tiling_shows_each_photo_pixel(wall, tiles):
    """Issue 41: a Tile Set render is compared with the plain one weighted by photo_use; laid
    over many cells the tiling shows each photo pixel about that often, the photo's middle
    most and its outermost rows never."""
    use = photo_use(tiles)
    _, at = wang_tiling_positions(tiles, 40 * tiles.tile, 40 * tiles.tile, cells=40)
    shown = np.bincount(np.ravel_multi_index(at.reshape(-1, 2).T, wall.shape[:2]),
                        minlength=wall.shape[0] * wall.shape[1]).reshape(wall.shape[:2])
    assert use.shape == wall.shape[:2] and np.isclose(use.sum(), 1.0)
    assert np.corrcoef(use.ravel(), shown.ravel())[0, 1] > 0.95
    assert use[0].sum() == use[-1].sum() == 0 < use[len(use) // 2].sum()


def test_same_seed_same_tiles_and_another_seed_others(wall, tiles):
    again = wang_tiles(wall, tile=72, gutter=4, colours=2, seed=3)
    assert np.array_equal(again.atlas, tiles.atlas)
    other = wang_tiles(wall, tile=72, gutter=4, colours=2, seed=4)
    assert not np.array_equal(other.centres, tiles.centres)
    a = wang_tiling(tiles, 144, 144, cells=2, seed=0)
    assert np.array_equal(a, wang_tiling(tiles, 144, 144, cells=2, seed=0))
    layouts = {wang_tiling(tiles, 288, 288, cells=4, seed=s).tobytes() for s in range(3)}
    assert len(layouts) == 3


def test_a_wrapped_tiling_tiles_at_its_size_and_an_unwrapped_one_need_not(tiles):
    t = tiles.tile
    out, at = wang_tiling_positions(tiles, 4 * t, 3 * t, cells=(4, 3), seed=5)
    rows = np.arange(3 * t) % t
    inner = (rows > 0) & (rows < t - 1)
    assert np.array_equal(at[inner, -1] + (0, 1), at[inner, 0])  # the wrap is a cell edge
    cols = np.arange(4 * t) % t
    inner_cols = (cols > 0) & (cols < t - 1)
    assert np.array_equal(at[-1, inner_cols] + (1, 0), at[0, inner_cols])
    unwrapped = [wang_tiling_positions(tiles, 4 * t, 3 * t, cells=(4, 3), seed=s, wrap=False)[1]
                 for s in range(4)]
    assert not all(np.array_equal(a[inner, -1] + (0, 1), a[inner, 0]) for a in unwrapped)


def test_edge_colours_are_uniform_over_the_colours():
    x, y = np.meshgrid(np.arange(64), np.arange(64))
    for colours in (2, 3):
        h, v = edge_colours(x, y, colours, seed=9)
        for c in (h, v):
            share = np.bincount(c.ravel(), minlength=colours) / c.size
            assert np.allclose(share, 1 / colours, atol=0.03)


@pytest.mark.parametrize("channels", [1, 4])
def test_grey_and_rgba_photos_keep_their_channels(channels):
    photo = smooth_noise((96, 96), seed=1, channels=channels)
    tiles = wang_tiles(photo[:, :, 0] if channels == 1 else photo, tile=32, gutter=2)
    assert tiles.atlas.shape[2] == channels
    assert wang_tiling(tiles, 64, 64, cells=2).shape == (64, 64, channels)


def test_the_default_tile_is_about_half_the_photo():
    tiles = wang_tiles(bricks((128, 144)), gutter=4)
    assert 0.75 * 64 <= tiles.tile <= 64 and tiles.tile % 2 == 0


def test_cancel_returns_nothing(wall):
    calls = []

    def stop(fraction, message):
        calls.append(fraction)
        return len(calls) < 3

    with pytest.raises(texsynth.Cancelled):
        wang_tiles(wall, tile=64, progress=stop)


def test_the_memory_prediction_covers_the_peak():
    photo = smooth_noise((256, 320), seed=2)
    tracemalloc.start()
    wang_tiles(photo, tile=128, colours=2, gutter=8)
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    predicted = predict_tiles_memory(photo.shape, 128, 2, 8)
    assert peak <= predicted <= 1.5 * peak


@pytest.mark.parametrize("call, message", [
    (lambda w: wang_tiles(np.zeros(40)), "photo must be"),
    (lambda w: wang_tiles(np.zeros((40, 40, 2))), "channels"),
    (lambda w: wang_tiles(np.full((40, 40), np.nan)), "NaN"),
    (lambda w: wang_tiles(np.zeros((20, 20))), "too small"),
    (lambda w: wang_tiles(w, colours=1), "colours"),
    (lambda w: wang_tiles(w, colours=5), "colours"),
    (lambda w: wang_tiles(w, tile=33), "even"),
    (lambda w: wang_tiles(w, tile=8), "tile"),
    (lambda w: wang_tiles(w, tile=400), "tile"),
    (lambda w: wang_tiles(w, gutter=-1), "gutter"),
    (lambda w: wang_tiles(w, tile=32, gutter=12), "gutter"),
    (lambda w: wang_tiles(w, seed=-1), "seed"),
    (lambda w: wang_tiling("tiles", 64, 64), "tiles must be"),
])
def test_bad_input_is_refused_naming_the_argument(wall, call, message):
    before = wall.copy()
    with pytest.raises(ValueError, match=message):
        call(wall)
    assert np.array_equal(wall, before)


@pytest.mark.parametrize("keywords, message", [
    ({"width": 0}, "width"), ({"cells": 0}, "cells"), ({"cells": (2, 0)}, "cells"),
    ({"seed": 1.5}, "seed"), ({"wrap": "yes"}, "wrap"),
])
def test_bad_tiling_arguments_are_refused(tiles, keywords, message):
    arguments = {"width": 64, "height": 64} | keywords
    with pytest.raises(ValueError, match=message):
        wang_tiling(tiles, arguments.pop("width"), arguments.pop("height"), **arguments)
    assert isinstance(tiles, WangTiles)

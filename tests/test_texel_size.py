"""The texel size block and the multiscale MRF's automatic level count that follows from it."""

import numpy as np

import texsynth
from texsynth.algorithms.multiscale_mrf import MIN_LEVELS, auto_levels
from texsynth.blocks.period import texel_size

from _images import smooth_noise


def _bricks(side=192, brick=48, course=16, seed=0):
    """Running-bond bricks: mortar lines along every course, joints offset by half a brick."""
    rng = np.random.default_rng(seed)
    y, x = np.mgrid[:side, :side]
    row = y // course
    joint = ((x + (row % 2) * brick // 2) % brick) < 2
    mortar = ((y % course) < 2) | joint
    shade = rng.uniform(0.4, 0.7, (side // course + 1, side // brick + 2))
    image = np.where(mortar, 0.9, shade[row, (x + (row % 2) * brick // 2) // brick])
    image = image + rng.normal(0, 0.02, image.shape)
    return np.repeat(image[:, :, None], 3, axis=2).astype(np.float32)


def test_long_lines_measure_longer_than_grain():
    grain = texel_size(smooth_noise((192, 192), seed=1, sigma=1.0))
    assert 2 <= grain <= 8
    assert texel_size(_bricks()) >= 8 * grain


def test_a_flat_exemplar_has_the_smallest_texel():
    assert texel_size(np.full((64, 64, 3), 0.5, np.float32)) == 2.0


def test_auto_levels_reach_the_bricks_and_keep_the_floor_on_grain():
    assert auto_levels(smooth_noise((192, 192), seed=1, sigma=1.0), radius=3) == MIN_LEVELS
    assert auto_levels(_bricks(), radius=3) > MIN_LEVELS


def _wrap_continuity(positions):
    """How often neighbours across the wrap edges show neighbouring exemplar pixels, over how
    often interior neighbours do: about 1 on a periodic map, about 0 on a crop."""
    down = (np.roll(positions, -1, axis=0) - positions == (1, 0)).all(axis=2)
    right = (np.roll(positions, -1, axis=1) - positions == (0, 1)).all(axis=2)
    wrap = np.r_[down[-1], right[:, -1]].mean()
    return wrap / np.r_[down[:-1].ravel(), right[:, :-1].ravel()].mean()


def test_default_levels_tile_and_repeat():
    bricks = _bricks(side=96, brick=32, course=12)
    a, s = texsynth.synthesize_positions(bricks, 80, 64, method="multiscale_mrf", seed=3,
                                         visits=1)
    b = texsynth.synthesize(bricks, 80, 64, method="multiscale_mrf", seed=3, visits=1)
    assert a.shape == (64, 80, 3) and np.array_equal(a, b)
    # The wrap continues the copies as the interior does (seeds 0-39: 0.71 or more; their
    # crops 0.15 or less). Not seam_ratio: where the wrap runs along a mortar edge (64 rows
    # hold 5 1/3 courses) it reads 1.7-4.6 on rows that continue (6-8 of those 40 seeds).
    assert _wrap_continuity(s) > 0.5
    assert _wrap_continuity(s[8:56, 8:72]) < 0.2  # a crop's wrap is a seam

"""Metrics with known answers: what the benchmark's figures mean rests on these."""

import numpy as np
import pytest
from scipy.ndimage import gaussian_filter

from texsynth import metrics
from texsynth.blocks.joints import Joints

from _images import ramp_photo, running_bond, smooth_noise


def stripes(shape, period=8.0, angle=0.3):
    yy, xx = np.mgrid[: shape[0], : shape[1]]
    return (0.5 + 0.5 * np.sin(2 * np.pi * (xx * np.cos(angle) + yy * np.sin(angle)) / period)
            ).astype(np.float32)


def test_seam_ratio_is_one_for_periodic_and_large_for_a_photo():
    assert metrics.seam_ratio(smooth_noise((64, 64))) == pytest.approx(1.0, abs=0.2)
    assert metrics.seam_ratio(ramp_photo((64, 64))) > 3
    with pytest.raises(ValueError, match="3 x 3"):
        metrics.seam_ratio(np.zeros((2, 9)))


def periodic_bricks(courses=8, bricks=6, seed=0):
    """A running-bond wall that tiles: courses of 16 rows, bricks of 32 columns, 4-pixel grey
    joints, each brick its own shade, fine grain."""
    rng = np.random.default_rng(seed)
    i, j = np.mgrid[:16 * courses, :32 * bricks]
    row, shifted = i // 16, j + (i // 16 % 2) * 16
    shade = rng.uniform(0.3, 0.5, (courses, bricks))[row, shifted // 32 % bricks]
    wall = np.where((i % 16 < 4) | (shifted % 32 < 4), 0.75, shade)
    return (wall + rng.normal(0, 0.03, wall.shape)).astype(np.float32)


@pytest.mark.parametrize("shift", [0, 2, 5, 9, 12])
def test_seam_ratio_in_phase_reads_a_tiling_wall_as_tiling_wherever_its_wrap_falls(shift):
    wall = np.roll(periodic_bricks(), (shift, 2 * shift), axis=(0, 1))
    plain = metrics.seam_ratio(wall)
    assert 0.9 <= metrics.seam_ratio_in_phase(wall) <= 1.1
    # What the plain measure misreads: a wrap on a joint's edge (0, 12) or through the bricks.
    assert not 0.9 <= plain <= 1.1


@pytest.mark.parametrize("shift", [0, 2, 5, 9, 12])
def test_seam_ratio_in_phase_still_sees_a_real_seam(shift):
    wall = np.roll(periodic_bricks(), (shift, 2 * shift), axis=(0, 1))
    shaded = wall + np.linspace(0, 0.15, wall.shape[0], dtype=np.float32)[:, None]
    assert not 0.8 <= metrics.seam_ratio_in_phase(shaded) <= 1.2
    assert metrics.seam_ratio_in_phase(ramp_photo((64, 64))) > 3
    with pytest.raises(ValueError, match="3 x 3"):
        metrics.seam_ratio_in_phase(np.zeros((9, 2)))


def test_a_shifted_copy_is_a_copy():
    image = smooth_noise((64, 64), seed=1)
    shifted = np.roll(image, (11, 23), axis=(0, 1))
    result = metrics.patch_distance(image, shifted)
    assert result["median"] < 1e-6
    assert result["copy_share"] > 0.7  # (57/64)^2 of the patches do not cross a seam


def test_every_patch_of_a_wrapped_shift_is_found_in_the_tiled_exemplar():
    tile = smooth_noise((40, 40), seed=3)
    exemplar = np.tile(tile, (2, 2, 1))  # holds every wrapped patch of the tile
    result = metrics.patch_distance(exemplar, np.roll(tile, (7, 13), axis=(0, 1)))
    assert result["copy_share"] == 1.0
    assert result["median"] < 1e-6


def test_patch_distance_grows_with_the_departure_from_the_exemplar():
    exemplar = smooth_noise((64, 64), seed=1)
    rng = np.random.default_rng(0)
    slight = np.clip(exemplar + 0.01 * rng.standard_normal(exemplar.shape), 0, 1)
    strong = np.clip(exemplar + 0.1 * rng.standard_normal(exemplar.shape), 0, 1)
    d = [metrics.patch_distance(exemplar, x)["median"] for x in (exemplar, slight, strong)]
    assert d[0] < 1e-6 < d[1] < 0.1 < d[2]


def test_fresh_noise_is_not_a_copy():
    a = smooth_noise((64, 64), seed=1)
    b = smooth_noise((64, 64), seed=2)
    result = metrics.patch_distance(a, b)
    assert result["copy_share"] == 0.0
    assert result["median"] > 0.05


def test_subband_distance_orders_same_texture_before_other_texture():
    a = smooth_noise((96, 96), seed=1, sigma=2.0)
    b = smooth_noise((96, 96), seed=2, sigma=2.0)
    coarse = smooth_noise((96, 96), seed=3, sigma=6.0)
    same = metrics.subband_distance(a, b)
    other = metrics.subband_distance(a, coarse)
    assert same < 0.2 and other > 3 * same


def test_structure_distance_tells_lines_from_blobs():
    rng = np.random.default_rng(0)
    blobs = gaussian_filter(rng.standard_normal((96, 96)), 2, mode="wrap")
    other_blobs = gaussian_filter(rng.standard_normal((96, 96)), 2, mode="wrap")
    lines = stripes((96, 96)) + 0.05 * blobs
    assert metrics.structure_distance(blobs, other_blobs) < 0.1
    assert metrics.structure_distance(blobs, lines) > 0.5


def test_self_distance_reports_the_natural_variation():
    image = smooth_noise((64, 128), seed=4)
    result = metrics.self_distance(image)
    assert set(result) == {"subband_distance", "patch_distance", "copy_share", "structure_distance"}
    assert result["copy_share"] == 0.0
    assert result["structure_distance"] < 0.15


def test_quality_bundles_every_measure():
    image = smooth_noise((48, 48), seed=5)
    q = metrics.quality(image, np.roll(image, 5, axis=1))
    assert q["seam_ratio"] == pytest.approx(1.0, abs=0.2)
    assert q["copy_share"] > 0.6
    assert set(q) == {"seam_ratio", "subband_distance", "patch_distance", "copy_share",
                      "structure_distance"}


def test_dead_ends_read_a_wall_with_joints_cut_mid_brick_higher_than_the_whole_one():
    """Bricks pasted over pieces of the bed joints (a course's joint stopping mid-brick, as a
    band cut across a wall leaves them): more dead ends per joint length than the whole wall,
    whose every joint meets another."""
    wall, joint = running_bond((192, 256), 0, course=16, brick=40, joint=3,
                               tint=(0.9, 0.5, 0.4), shade=(0.5, 0.3), grain=0.1,
                               mortar=(0.15, 0.15, 0.15), speckle=0.04)
    broken = wall.copy()
    rng = np.random.default_rng(1)
    for course in rng.choice(np.arange(1, 11), 6, replace=False):
        x = int(rng.integers(20, 220))
        # a piece of the brick below laid over the joint and 4 rows either side
        broken[16 * course - 4:16 * course + 7, x:x + 14] = wall[16 * course + 5, x:x + 14]
    assert np.count_nonzero(broken != wall) < 0.03 * wall.size
    joints = Joints.fit(wall, 1.5)
    whole, cut = (metrics.dead_ends(w, joints, wrap=False) for w in (wall, broken))
    assert whole < 1.0  # per 1000 px of joint: a stray end or two in 4000 px
    assert cut > whole + 2.0  # 6 cuts, 12 ends
    assert metrics.dead_end_ratio(wall, broken, 1.5) > 3

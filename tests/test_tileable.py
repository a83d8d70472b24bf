"""texsynth.make_tileable: the photo itself made to tile, its centre kept, the band across the
wrap quilted from its own pixels (as sharp as the photo) and its level corrected (no step where
the light differs), the other maps following the same way."""

from pathlib import Path

import numpy as np
import pytest
from scipy.ndimage import gaussian_filter

import texsynth
from texsynth.blocks.joints import Joints
from texsynth.io import read_photo
from texsynth.metrics import (
    band_sharpness,
    dead_ends,
    gradient_ratio,
    mean_gradient,
    seam_ratio,
    seam_ratio_in_phase,
)
from texsynth.tileable import default_band, follow, predict

from _images import ramp_photo, running_bond, smooth_noise

SAMPLE = Path(__file__).resolve().parents[1] / "samples" / "pool_water.png"


def cracked(shape=(320, 384), seed=0):
    """Smooth noise crossed by sharp dark cracks, cropped from a larger canvas (it does not
    tile)."""
    rng = np.random.default_rng(seed)
    h, w = shape
    canvas = smooth_noise((h + 40, w + 40), seed=seed, sigma=2.0) * 0.6 + 0.3
    t = np.linspace(0.0, 1.0, 600)[:, None]
    for _ in range(14):
        start = rng.uniform(0, [h + 40, w + 40])
        angle = rng.uniform(0, np.pi)
        length = rng.uniform(40, 120)
        points = start + t * length * np.array([np.sin(angle), np.cos(angle)])
        r, c = np.rint(points).astype(int).T
        inside = (r >= 0) & (r < h + 40) & (c >= 0) & (c < w + 40)
        canvas[r[inside], c[inside]] = 0.05
    return np.ascontiguousarray(canvas[17:17 + h, 23:23 + w]).astype(np.float32)


def bricks(shape=(320, 384), seed=0):
    """A running-bond brick wall drawn by code: bricks of their own colour and grain, grey
    mortar joints; its height is not a whole number of courses (it does not tile)."""
    rng = np.random.default_rng(seed)
    h, w = shape
    course, length, joint = 14, 30, 3
    i, j = np.mgrid[:h + 30, :w + 60]
    row = i // course
    col = (j + (row % 2) * length // 2) // length
    colours = rng.uniform([0.45, 0.15, 0.1], [0.8, 0.35, 0.25], (row.max() + 1, col.max() + 2, 3))
    wall = colours[row, col] + 0.06 * smooth_noise(i.shape, seed=seed, sigma=1.0) - 0.03
    mortar = (i % course < joint) | ((j + (row % 2) * length // 2) % length < joint)
    wall[mortar] = 0.6 + 0.04 * rng.standard_normal((mortar.sum(), 1))
    return np.ascontiguousarray(wall[11:11 + h, 7:7 + w]).astype(np.float32)


def pool_water():
    """The sample's top right 120 x 120: the sample tiles as it is (a game's texture), its crop
    does not."""
    return read_photo(SAMPLE)[:120, 8:, :3].astype(np.float32)


PHOTOS = {"cracked": cracked, "bricks": bricks, "pool_water": pool_water}


@pytest.fixture(scope="module", params=sorted(PHOTOS))
def made(request):
    photo = PHOTOS[request.param]()
    before = photo.copy()
    out, positions = texsynth.make_tileable_positions(photo, seed=0)
    assert np.array_equal(photo, before)  # input untouched
    return request.param, photo, out, positions


#: Two-sided bounds of the seam ratio and band sharpness on these small images: the measures
#: vary that much on the photos themselves, taken at random crosses inside them (5-95 %:
#: 0.85-1.19 for the cracks, 0.87-1.14 for the bricks, 0.88-1.22 for pool_water).
LOW, HIGH = 0.85, 1.15


def _across_band(image, band):
    """The seam ratio averaged over every line within ``band / 2`` of the wrap: 1 when the band
    holds no extra line (a cut) and no soft stripe, whatever the wrap line itself crosses."""
    return float(np.mean([seam_ratio(np.roll(image, (k, k), axis=(0, 1)))
                          for k in range(-band // 2, band // 2)]))


def test_the_result_tiles_without_a_line_across_the_wrap(made):
    name, photo, out, _ = made
    assert out.shape == photo.shape and out.dtype == np.float32
    band = default_band(photo.shape)
    assert seam_ratio(photo) > 2
    assert 0.9 <= _across_band(out, band) <= 1.1
    if name == "bricks":
        # The wrap lies where the courses put it, inside bricks (the plain measure reads 0.5
        # there, as on any line through the bricks): against the wall's own lines at the
        # same place in its rhythm, two-sided.
        assert LOW <= seam_ratio_in_phase(out) <= HIGH
    else:
        # Two-sided: a soft line shows as much as a hard one.
        assert LOW <= seam_ratio(out) <= HIGH
        assert LOW <= seam_ratio(np.tile(out, (2, 2, 1))) <= HIGH


def test_the_band_is_as_sharp_as_the_photo(made):
    _, photo, out, _ = made
    band = default_band(photo.shape)
    assert LOW <= band_sharpness(out, band) <= HIGH
    assert 0.95 <= gradient_ratio(photo, out) <= 1.05


def _kept(shape, band):
    """The pixels farther than ``band / 2`` from the photo's edges."""
    h, w = shape[:2]
    i, j = np.mgrid[:h, :w]
    # Distance to the nearest edge, counted from the seam between the last and first pixel.
    to_edge = np.minimum(np.minimum(i + 0.5, h - 0.5 - i), np.minimum(j + 0.5, w - 0.5 - j))
    return to_edge > band / 2 + 0.5


def test_the_rest_is_the_photo_and_the_band_its_pieces_levelled_smoothly(made):
    _, photo, out, positions = made
    h, w = photo.shape[:2]
    i, j = np.mgrid[:h, :w]
    kept = _kept(photo.shape, default_band(photo.shape))
    assert np.array_equal(out[kept], photo[kept])
    assert (positions[kept, 0] == i[kept]).all() and (positions[kept, 1] == j[kept]).all()
    same = (out == photo).all(axis=2)
    assert same.mean() >= 0.5
    assert not same[~kept].all()  # the band did change
    # The correction of the pieces' level is smooth: no detail of its own (a tenth of the
    # photo's gradient at most; 0.02-0.07 on these).
    pieces = photo[positions[:, :, 0], positions[:, :, 1]]
    assert mean_gradient(out - pieces) < 0.1 * mean_gradient(photo)


def _high_pass(image, band):
    """``image`` less its blur at a quarter of the band: a step survives, the band's smooth
    change of level (a photo lit from one side must turn back from one edge's level to the
    other's within the band) does not."""
    return image - gaussian_filter(image, (band / 4, band / 4, 0), mode="wrap")


@pytest.mark.parametrize("seed", range(4))
def test_a_photo_lit_from_one_side_tiles_without_a_step(seed):
    """Noise on a ramp twice its own range (left to right): the pieces continuing each side of
    the band still met with a step at the cuts (high-passed, across the band 2.0-2.1 on these
    before the band's level was corrected). The ramp itself must turn back within the band
    whatever is done there (the kept photo is fixed): the plain seam ratio reads that turn
    (1.4-1.6 here), a step-free band reads 1 once it is high-passed."""
    photo = ramp_photo((128, 160), seed=seed % 2)
    band = default_band(photo.shape)
    out = texsynth.make_tileable(photo, seed=seed)
    kept = _kept(photo.shape, band)
    assert np.array_equal(out[kept], photo[kept])
    assert seam_ratio(photo) > 10
    detail = _high_pass(out, band)
    assert LOW <= _across_band(detail, band) <= HIGH  # 1.06-1.08
    assert 0.9 <= band_sharpness(detail, band) <= 1.1  # 0.96-1.02


@pytest.mark.parametrize("seed", range(4))
@pytest.mark.parametrize("edge", ["bottom", "right"])
def test_a_ledge_along_an_edge_leaves_no_trace(edge, seed):
    """The brick wall photo has a dark ledge along its bottom edge, reaching into the band's
    outer quarter, whose rows the patches are matched to: patches chosen to continue it
    squashed a course, and the cuts kept pieces of it (before the band's rows unlike the
    photo were left unmatched: dark pixels left in 4 of these 8 runs). Here a ledge 18
    pixels deep: the band is 40, its outer quarter the 10 rows 10-20 from the edge."""
    photo = bricks(seed=seed)
    h, w = photo.shape[:2]
    ledge = (slice(h - 18, h), slice(None)) if edge == "bottom" else (slice(None),
                                                                       slice(w - 18, w))
    photo[ledge] = 0.22 + 0.02 * np.random.default_rng(seed).standard_normal(
        photo[ledge].shape[:2] + (1,))
    out = texsynth.make_tileable(photo, seed=seed)
    dark = out.max(axis=2) < 0.34
    assert not dark.any(), f"{dark.sum()} ledge pixels left at {np.argwhere(dark)[:3]}"


@pytest.mark.parametrize("seed", range(4))
@pytest.mark.parametrize("edge", ["bottom", "right"])
def test_a_ledge_deeper_than_the_band_is_replaced_wherever_the_band_reaches(edge, seed):
    """A ledge 22 pixels deep, past the band's edge (20 pixels in from the photo's): its 2
    rows outside the band stay (the photo is kept there), and within the band none of it
    may stay. The cuts with the photo in the band's outer quarter used to pass beyond the
    ledge's first rows where the patches fitted the photo badly there, keeping pieces of it
    in the band (1000-2800 dark pixels in each of these 8 runs, about 700 outside it)."""
    photo = bricks(seed=seed)
    h, w = photo.shape[:2]
    band = default_band(photo.shape)
    ledge = (slice(h - 22, h), slice(None)) if edge == "bottom" else (slice(None),
                                                                       slice(w - 22, w))
    photo[ledge] = 0.22 + 0.02 * np.random.default_rng(seed).standard_normal(
        photo[ledge].shape[:2] + (1,))
    out = texsynth.make_tileable(photo, seed=seed)
    dark = out.max(axis=2) < 0.34
    inside = dark[h - band // 2:] if edge == "bottom" else dark[:, w - band // 2:]
    assert not inside.any(), f"{inside.sum()} ledge pixels left in the band"
    assert dark.any()  # the ledge's rows outside the band are the photo's, kept


def _wall(shape):
    """A running-bond wall, courses of 16 px, bricks of 40: it tiles when its height is a
    multiple of 32 and its width of 40."""
    return running_bond(shape, 0, course=16, brick=40, joint=3, tint=(0.9, 0.5, 0.4),
                        shade=(0.5, 0.3), grain=0.1, mortar=(0.15, 0.15, 0.15), speckle=0.04)[0]


@pytest.mark.parametrize("photo", ["sample", "wall"])
def test_a_photo_that_already_tiles_comes_back_as_it_is(photo):
    image = (read_photo(SAMPLE)[:, :, :3].astype(np.float32) if photo == "sample"
             else np.roll(_wall((192, 240)), (5, 11), axis=(0, 1)))  # the wrap mid-course
    out, positions = texsynth.make_tileable_positions(image, seed=3)
    assert np.array_equal(out, image)
    assert (positions == np.moveaxis(np.indices(image.shape[:2]), 0, 2)).all()
    other = np.random.default_rng(0).random(image.shape[:2] + (1,)).astype(np.float32)
    assert np.array_equal(follow(positions, other), other)


def test_the_same_wall_cut_from_a_larger_one_is_made_to_tile():
    # 192 x 240 again, the courses in phase across the wrap, but other bricks meet there
    photo = _wall((192 + 20, 240 + 24))[7:199, 9:249]
    assert seam_ratio_in_phase(photo) > 1.5
    out = texsynth.make_tileable(photo, seed=3)
    assert not np.array_equal(out, photo)
    assert 0.8 <= seam_ratio_in_phase(out) <= 1.2


@pytest.mark.parametrize("seed", [0, 1])
def test_a_wall_cut_out_of_phase_keeps_whole_bricks_across_the_wrap(seed):
    """Courses of 24 px, the photo 200 px high: the band's patches are taken in phase with the
    courses (``blocks.rhythm``), so no joint stops inside a brick where the arms cross (out of
    phase: 1-3 dead ends on seeds 0-3)."""
    wall = running_bond((300, 332), 0, course=24, brick=64, joint=3, tint=(0.9, 0.5, 0.4),
                        shade=(0.5, 0.3), grain=0.1, mortar=(0.15, 0.15, 0.15), speckle=0.04)[0]
    photo = np.ascontiguousarray(wall[5:205, 3:235])
    joints = Joints.fit(photo, 1.5)
    assert dead_ends(photo, joints, wrap=False) == 0
    out = texsynth.make_tileable(photo, seed=seed)
    assert dead_ends(out, joints, wrap=True) == 0
    assert 0.8 <= seam_ratio_in_phase(out) <= 1.2


@pytest.mark.parametrize("seed", [2, 3])
def test_the_vertical_arm_keeps_the_bed_joints_in_line_where_the_courses_fit_the_height(seed):
    """Four courses of 48 px in a 192 px high photo of grainy pavers with thin joints: the
    vertical arm's pieces come from rows a whole number of courses from where they go (within
    the search's block and its refinement, 2 px), so the bed joints beside it run on without
    a step (taken by colour alone: 4 px steps on seeds 2 and 3)."""
    wall = running_bond((232, 296), 1, course=48, brick=112, joint=2, tint=(0.6, 0.6, 0.6),
                        shade=(0.6, 0.1), grain=0.4, mortar=(0.2, 0.2, 0.2), speckle=0.05)[0]
    photo = np.ascontiguousarray(wall[7:199, 29:265])
    band = default_band(photo.shape)
    _, positions = texsynth.make_tileable_positions(photo, seed=seed)
    rows = np.arange(band // 2, 192 - band // 2)  # the vertical arm beyond the horizontal one
    source = positions[rows][:, (np.arange(band) - band // 2) % 236, 0]
    step = (source - rows[:, None]) % 48
    assert np.minimum(step, 48 - step).max() <= 2


def mixture(shape=(256, 256), seed=0):
    """Smooth ground (faint, broad noise) and rough gravel (strong, fine noise), half and
    half, in blobs."""
    rng = np.random.default_rng(seed)
    region = gaussian_filter(rng.standard_normal(shape), 24)
    rough = region > np.median(region)
    ground = 0.45 + 0.03 * (smooth_noise(shape, seed, sigma=6.0) - 0.5)
    gravel = 0.15 + 0.7 * smooth_noise(shape, seed + 1, sigma=1.2)
    return (np.where(rough[:, :, None], gravel, ground) * np.float32([1.0, 0.9, 0.75])
            ).astype(np.float32)


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_a_mixtures_band_is_not_quilted_from_its_smooth_part(seed):
    """By SSD alone the smooth ground matches any overlap best (the gravel's own patches
    differ from each other by twice its variance, the ground from the gravel by once): the
    band was quilted from the ground, a soft cross (band sharpness 0.03-0.22)."""
    photo = mixture()
    out = texsynth.make_tileable(photo, seed=seed)
    assert 0.6 <= band_sharpness(out, default_band(photo.shape)) <= 1.5


def test_other_maps_of_the_material_follow():
    photo = cracked()
    out, positions = texsynth.make_tileable_positions(photo, seed=1)
    height = photo.mean(axis=2) ** 2  # a second map of the same material
    moved = follow(positions, height)
    assert moved.shape == height.shape + (1,) and moved.dtype == np.float32
    assert seam_ratio(height) > 2 and LOW <= seam_ratio(moved) <= HIGH
    kept = _kept(photo.shape, default_band(photo.shape))
    assert np.array_equal(moved[kept, 0], height[kept])
    assert np.array_equal(follow(positions, photo), out)  # the photo follows into its result
    with pytest.raises(ValueError, match="positions"):
        follow(positions, height[:, :-1])


def test_the_seed_chooses_the_patches_and_repeats_exactly():
    photo = cracked(seed=2)
    a = texsynth.make_tileable(photo, seed=4)
    assert np.array_equal(a, texsynth.make_tileable(photo, seed=4))
    assert not np.array_equal(a, texsynth.make_tileable(photo, seed=5))


@pytest.mark.parametrize("kind", ["uint8", "uint16", "grey", "rgba"])
def test_bytes_grey_and_alpha(kind):
    photo = bricks((96, 128), seed=3)
    given = {"uint8": np.rint(photo * 255).astype(np.uint8),
             "uint16": np.rint(photo * 65535).astype(np.uint16),
             "grey": photo.mean(axis=2),
             "rgba": np.concatenate([photo, np.ones_like(photo[:, :, :1])], axis=2)}[kind]
    out, positions = texsynth.make_tileable_positions(given, seed=0)
    channels = {"grey": 1, "rgba": 4}.get(kind, 3)
    assert out.shape == (*photo.shape[:2], channels) and out.dtype == np.float32
    scale = {"uint8": 255, "uint16": 65535}.get(kind, 1)
    source = np.asarray(given, np.float32).reshape(out.shape) / scale
    assert np.array_equal(out, follow(positions, given))
    kept = _kept(photo.shape, default_band(photo.shape))
    assert np.array_equal(out[kept], source[kept])
    assert seam_ratio(out) <= HIGH
    if kind == "rgba":
        assert (out[:, :, 3] == 1).all()


def test_progress_rises_and_cancel_stops_it():
    photo = cracked()
    fractions = []
    texsynth.make_tileable(photo, progress=lambda f, message: fractions.append(f))
    assert fractions[0] == 0.0 and fractions[-1] == 1.0
    assert fractions == sorted(fractions) and len(fractions) > 10
    calls = []

    def cancel(fraction, message):
        calls.append(fraction)
        return len(calls) < 5

    with pytest.raises(texsynth.Cancelled):
        texsynth.make_tileable(photo, progress=cancel)
    assert len(calls) == 5


@pytest.mark.parametrize("kwargs, message", [
    ({"band": 120}, "more than half"),
    ({"band": 4}, "between 8 and"),
    ({"band": 2.5}, "whole number"),
    ({"seed": -1}, "seed"),
])
def test_bad_input_says_what_to_change_and_changes_nothing(kwargs, message):
    photo = cracked()
    before = photo.copy()
    with pytest.raises(ValueError, match=message):
        texsynth.make_tileable(photo, **kwargs)
    assert np.array_equal(photo, before)


def test_a_photo_smaller_than_16_pixels_is_refused():
    with pytest.raises(ValueError, match="at least 16 x 16"):
        texsynth.make_tileable(np.zeros((12, 40, 3), np.float32))


@pytest.mark.parametrize("shape", [(24, 24), (16, 200), (27, 27)])
def test_a_photo_too_small_for_any_band_is_refused_saying_so(shape):
    """The narrowest band would change more than half of these: the message said the band
    "must be between 8 and 7 pixels"."""
    with pytest.raises(ValueError, match="too small to make tileable.*28 x 28"):
        texsynth.make_tileable(np.random.default_rng(0).random(shape), band=8)
    assert texsynth.make_tileable(np.random.default_rng(0).random((28, 28))).shape == (28, 28, 1)


def test_a_camera_photo_fits_the_default_budgets():
    """A 4000 x 3000 photo (12 MP) was refused as needing 37 GiB; its cost follows the band."""
    seconds, peak = predict((3000, 4000, 3))
    assert 0.3 * 2**30 < peak < 2 * 2**30  # the result, its positions and the band's strips
    assert seconds < 600


def test_a_photo_that_already_tiles_is_predicted_as_the_check_and_a_copy():
    """Such a photo comes back unchanged after one check: a 1024 photo was told 0.7 s and
    62 MiB for a run of 0.03 s and 28 MiB. The same photo with a ramp across is quilted."""
    photo = smooth_noise((256, 256), seed=1, sigma=2.0)
    ramp = photo + np.linspace(0, 1, 256, dtype=np.float32)[None, :, None]
    assert texsynth.tileable.tiles(photo) and not texsynth.tileable.tiles(ramp)
    tiled, quilted = predict(photo.shape, photo=photo), predict(ramp.shape, photo=ramp)
    assert quilted == predict(ramp.shape)
    assert tiled[0] < quilted[0] / 5 and tiled[1] < quilted[1] / 2


@pytest.mark.filterwarnings("error::RuntimeWarning")
@pytest.mark.parametrize("scale", [1e30, 1e-30, 3e38, 1e-42])
def test_huge_and_tiny_values_tile_as_ordinary_ones(scale):
    """Squared differences of values near 1e30 overflow float32: the photo is quilted and
    corrected at an exact power-of-two scale, so it tiles as its ordinary copy does, its kept
    pixels its own. Denormal values (1e-42) take a scale beyond float32's range: brought back
    in float64 (numpy 2 cast the scale to float32's inf, a warning and a band of zeros)."""
    photo = smooth_noise((104, 120), seed=3, sigma=2.5)[17:81, 23:103] * 0.8 + 0.1  # no wrap
    huge = (photo.astype(np.float64) * scale).astype(np.float32)
    tile, positions = texsynth.make_tileable_positions(huge, seed=2)
    power = texsynth.validation.magnitude_scale(huge)  # exact: a power of two
    ordinary, expected = texsynth.make_tileable_positions(
        (huge.astype(np.float64) * power).astype(np.float32), seed=2)
    assert np.array_equal(positions, expected) and np.isfinite(tile).all()
    kept = _kept(photo.shape, default_band(photo.shape))
    assert np.array_equal(tile[kept], huge[kept])
    back = (tile.astype(np.float64) * power).astype(np.float32)
    # Exact, but denormals hold the band to their last bit (2^-149, at the ordinary scale).
    assert np.abs(back - ordinary).max() <= (2.0 ** -149 * power if scale < 1e-37 else 0.0)
    assert seam_ratio(huge / np.float32(scale)) > 2 and seam_ratio(tile / np.float32(scale)) < 1.3


@pytest.mark.parametrize("seed", [0, 1])
def test_the_vertical_arm_keeps_the_head_joints_where_the_bricks_stand_in_a_lattice(seed):
    """Pavers in running bond (``blocks.rhythm.bond``: their head joints recur a brick on and
    half a brick a course on): the vertical arm's pieces are copied by whole lattice steps,
    so every head joint in the arm's middle is where the lattice of the photo left of the wrap
    puts it (its width is no whole number of bricks: the cut with the right side takes the
    rest). Free along the courses, the arm lost a head joint there (a paver twice as long) or
    held two, on the pavers' crop."""
    wall = running_bond((232, 296), 1, course=48, brick=112, joint=2, tint=(0.6, 0.6, 0.6),
                        shade=(0.6, 0.1), grain=0.4, mortar=(0.2, 0.2, 0.2), speckle=0.05)[0]
    photo = np.ascontiguousarray(wall[7:199, 29:265])
    band = default_band(photo.shape)
    _, positions = texsynth.make_tileable_positions(photo, seed=seed)
    rows = np.arange(band // 2, 192 - band // 2)[:, None]  # beyond the horizontal arm
    cols = 236 + np.arange(-band // 4, band // 4)[None, :]  # the middle, as the left runs on
    dy, dx = (positions[rows, cols % 236] - np.stack(np.broadcast_arrays(rows, cols), 2)).T
    assert (dy % 48 == 0).all()
    assert ((dx - dy // 48 * 56) % 112 == 0).all()


def test_a_cut_between_neighbours_passes_beside_a_head_joint_not_along_it():
    """Where the photo has courses across the arm, the cut through two neighbouring patches'
    overlap keeps a head joint whole from one of them: by the colours alone it runs along the
    joint, where the two agree best, and a joint a pixel apart in the two breaks there (the
    benchmark's generated wall, seeds 2 and 3: head joints broken where they meet the bed
    joint 12 px below the wrap)."""
    from types import SimpleNamespace

    from texsynth.blocks.quilting import min_error_path
    from texsynth.tileable import _beside

    rng = np.random.default_rng(0)
    patch, template = (0.4 + 0.1 * rng.random((2, 40, 12, 3))).astype(np.float32)
    patch[:, 5:8] = template[:, 5:8] = 0.9  # the head joint, alike in both
    e = np.einsum("ijc,ijc->ij", patch - template, patch - template)
    assert set(min_error_path(e)) <= {5, 6, 7}
    beside = min_error_path(_beside(e, patch, template, SimpleNamespace(period=24)))
    assert not set(beside) & {5, 6, 7}
    assert (_beside(e, patch, template, SimpleNamespace(period=None)) == e).all()


def test_the_middle_cut_passes_a_head_joint_the_two_rows_hold_apart_along_the_bed_joint():
    """Where the courses run on in phase across the wrap, the two rows of patches may hold a
    course's head joints apart (the pavers' centre 512: 10 px): the middle cut passes beside
    both, along the bed joint, and keeps one of them whole (by the colours alone it crossed
    them, where the two rows' course agrees best); the grain's odd pixels, which ``_across``
    finds too, bar nothing (``_runs``)."""
    from texsynth.tileable import _across, _cut, _runs

    rng = np.random.default_rng(0)
    first, second = (0.5 + 0.02 * rng.standard_normal((2, 24, 96, 3))).astype(np.float32)
    first[:13] += 0.1 * rng.standard_normal((13, 96, 3)).astype(np.float32)  # other stones
    first[10:13] -= 0.4  # the bed joint, in line in both (its moss not)
    second[10:13] -= 0.4
    second[18:] = first[18:]  # the course below, alike in both but for its edge and ...
    first[13:, 40:43] = second[13:, 50:53] = 0.4  # ... its head joint, 10 px apart
    first[3, 70] = second[20, 20] = 0.95  # the grain's odd pixels
    barred = _runs(_across(first) | _across(second), 6)
    assert barred[13:, 40:43].all() and barred[13:, 50:53].all()
    assert not barred[3, 70] and not barred[20, 20]
    assert (_cut(first, second, 0, 24)[38:56] > 13).all()  # both joints' parts kept
    rows = _cut(first, second, 0, 24, barred)  # the second's course at both: one joint
    assert (rows[40:43] <= 13).all() and (rows[50:53] <= 13).all()

"""Texture optimisation (Kwatra et al. 2005) with PatchMatch and uniform patch usage: it tiles,
keeps long structures, returns its position map, and says what to change on bad input."""

import numpy as np
import pytest

import texsynth
from texsynth.blocks.patchmatch import PatchFeatures, patchmatch
from texsynth.blocks.recut import straight_runs
from texsynth.metrics import patch_distance, seam_ratio, structure_distance

from _images import ramp_photo, smooth_noise


def bricks(shape=(64, 64), seed=0):
    """Rows of bricks 8 px tall and 16 px long, joints offset every other row, dark mortar,
    noisy faces: long straight lines a pixel sampler breaks."""
    rng = np.random.default_rng(seed)
    h, w = shape
    img = 0.6 + 0.08 * smooth_noise(shape, seed, sigma=1.0, channels=3)
    img *= np.array([1.0, 0.75, 0.6], np.float32)
    i, j = np.mgrid[:h, :w]
    mortar = (i % 8 == 0) | ((j + 8 * ((i // 8) % 2)) % 16 == 0)
    img[mortar] = 0.15 + 0.03 * rng.random((mortar.sum(), 1))
    return img.astype(np.float32)


def setts(shape=(96, 96), seed=0):
    """Granite setts 13 px square in rows, every other row offset by half a sett, 3 px grass
    joints, each sett its own grey with grain; and the stone mask (True off the joints)."""
    rng = np.random.default_rng(seed)
    h, w = shape
    i, j = np.mgrid[:h, :w]
    row = i // 16
    col = (j + 8 * (row % 2)) // 16
    grey = 0.45 + 0.25 * rng.random((row.max() + 1, col.max() + 1))
    img = grey[row, col][:, :, None] * np.array([1.0, 0.97, 0.92], np.float32)
    img = img + 0.12 * (smooth_noise(shape, seed, sigma=1.0, channels=3) - 0.5)
    joint = (i % 16 < 3) | ((j + 8 * (row % 2)) % 16 < 3)
    img[joint] = np.array([0.2, 0.3, 0.12]) + 0.05 * rng.random((joint.sum(), 1))
    return img.astype(np.float32), ~joint


def test_output_tiles_and_is_made_of_exemplar_pixels():
    photo = ramp_photo((48, 56), seed=2)
    assert seam_ratio(photo) > 3
    out, positions = texsynth.synthesize_positions(photo, 72, 64, method="texture_optimization",
                                                   seed=1, levels=2)
    assert out.shape == (64, 72, 3) and out.dtype == np.float32
    assert seam_ratio(out) < 1.3
    assert seam_ratio(np.roll(out, (23, 31), axis=(0, 1))) < 1.3
    assert np.array_equal(texsynth.apply_positions(positions, photo), out)


def test_long_structures_survive_where_pixel_samplers_break_them():
    """Against Heeger-Bergen's statistics; the multiscale MRF, which broke the rows here too
    (7 of 12 mortar rows, structure distance 0.34 against 0.16), keeps them since its copies
    slide into phase (issue 25: 12 of 12, 0.24)."""
    ex = bricks()
    out = texsynth.synthesize(ex, 96, 96, method="texture_optimization", seed=0)
    hb = texsynth.synthesize(ex, 96, 96, method="heeger_bergen", seed=0, iterations=5)
    assert structure_distance(ex, out) < 0.3 * structure_distance(ex, hb)
    assert patch_distance(ex, out, samples=300)["median"] < 0.05

    def mortar_rows(image):
        """Rows more than half mortar: the horizontal lines that carry on (12 in 96 rows)."""
        return int(((image.mean(axis=2) < 0.3).mean(axis=1) > 0.5).sum())

    assert mortar_rows(out) >= 8 > mortar_rows(hb)


def test_same_seed_same_output_other_seed_other_output():
    ex = smooth_noise((40, 40), seed=4, sigma=1.5)
    a = texsynth.synthesize(ex, 48, 40, method="texture_optimization", seed=7, levels=2)
    b = texsynth.synthesize(ex, 48, 40, method="texture_optimization", seed=7, levels=2)
    c = texsynth.synthesize(ex, 48, 40, method="texture_optimization", seed=8, levels=2)
    assert np.array_equal(a, b) and not np.array_equal(a, c)


def test_uniform_usage_term_spreads_the_copies_over_the_exemplar():
    ex = smooth_noise((48, 48), seed=1, sigma=1.5)

    def used(uniformity):  # one level: the usage term alone, without the copies' moves
        _, pos = texsynth.synthesize_positions(ex, 96, 96, method="texture_optimization",
                                               seed=2, uniformity=uniformity, levels=1)
        counts = np.bincount((pos[:, :, 0] * 48 + pos[:, :, 1]).ravel(), minlength=48 * 48)
        return (counts > 0).mean()

    assert used(4.0) > used(0.0) + 0.05


def test_whole_material_follows_the_positions():
    colour = bricks((48, 48), seed=3)
    height_map = colour.mean(axis=2)
    views = texsynth.synthesize_stack([colour, height_map], 64, 64, method="texture_optimization",
                                      mode="column", seed=0, levels=2)
    assert np.allclose(views[0].mean(axis=2), views[1].reshape(64, 64), atol=1e-6)


def test_patchmatch_finds_the_exemplar_in_itself():
    ex = smooth_noise((48, 48), seed=5, sigma=1.0)
    rng = np.random.default_rng(0)
    features = PatchFeatures(ex, 8, rng)
    rows = cols = np.arange(0, 48, 2)
    nnf = np.stack([rng.integers(0, 41, (24, 24)), rng.integers(0, 41, (24, 24))],
                   axis=2).astype(np.int32)
    target = features.describe(ex, *np.meshgrid(rows, cols, indexing="ij")).reshape(-1, 32)
    patchmatch(features, target, nnf, rows, cols, (48, 48), rng, 4)
    inside = rows <= 40  # patches that do not wrap are found exactly
    assert (nnf[inside][:, inside, 0] == rows[inside, None]).mean() > 0.95
    assert (nnf[inside][:, inside, 1] == cols[None, inside]).mean() > 0.95


@pytest.mark.parametrize("kwargs, message", [
    ({"patch_size": 16}, "smaller than the patch"),
    ({"patch_size": 4, "width": 3}, "output"),
    ({"uniformity": -1.0}, "uniformity"),
])
def test_bad_input_says_what_to_change(kwargs, message):
    ex = smooth_noise((12, 12), seed=0)
    width = kwargs.pop("width", 32)
    with pytest.raises(ValueError, match=message):
        texsynth.synthesize(ex, width, 32, method="texture_optimization", **kwargs)


def test_patchmatch_on_a_lattice_finds_the_lattice_patches():
    ex = smooth_noise((48, 48), seed=5, sigma=1.0)
    rng = np.random.default_rng(0)
    features = PatchFeatures(ex, 8, rng, stride=2)
    assert features.shape == (21, 21)
    rows = cols = np.arange(0, 48, 2)
    nnf = 2 * np.stack([rng.integers(0, 21, (24, 24)), rng.integers(0, 21, (24, 24))],
                       axis=2).astype(np.int32)
    target = features.describe(ex, *np.meshgrid(rows, cols, indexing="ij")).reshape(-1, 32)
    patchmatch(features, target, nnf, rows, cols, (48, 48), rng, 4)
    assert (nnf % 2 == 0).all()  # matches stay on the lattice
    inside = rows <= 40
    assert (nnf[inside][:, inside, 0] == rows[inside, None]).mean() > 0.95
    assert (nnf[inside][:, inside, 1] == cols[None, inside]).mean() > 0.95


def test_a_large_photo_searched_on_a_lattice_still_keeps_rows_and_reaches_every_pixel(
        monkeypatch):
    from texsynth.algorithms import texture_optimization as method
    monkeypatch.setattr(method, "SOURCES", 1000)  # the 64 x 64 bricks count as a large photo
    ex = bricks()
    out, positions = texsynth.synthesize_positions(ex, 96, 96, method="texture_optimization",
                                                   seed=0)
    assert np.array_equal(texsynth.apply_positions(positions, ex), out)
    # Lattice patches start on even pixels, yet their pixels cover odd rows and columns too.
    assert (positions[:, :, 0] % 2).mean() > 0.3 and (positions[:, :, 1] % 2).mean() > 0.3
    assert ((out.mean(axis=2) < 0.3).mean(axis=1) > 0.5).sum() >= 8  # mortar rows carry on


def test_setts_are_not_cut_along_straight_lines():
    """Where two copies meet along a straight line 16 px or longer, both sides stone: a sett
    cut in two, or two setts run together without a joint (seeds 0-2: 237 pixels before
    straight cuts were re-cut, 84 after)."""
    ex, stone = setts()
    cut_through = 0
    for seed in range(3):
        _, pos = texsynth.synthesize_positions(ex, 128, 128, method="texture_optimization",
                                               seed=seed)
        for p, s in ((pos, stone), (pos.transpose(1, 0, 2)[:, :, ::-1], stone.T)):  # | then -
            after = np.roll(p, -1, axis=1)
            both = s[p[:, :, 0], p[:, :, 1]] & s[after[:, :, 0], after[:, :, 1]]
            for j, first, last in straight_runs(p, 16):
                cut_through += int(both[first:last + 1, j].sum())
    assert cut_through < 140


def test_a_stochastic_photo_does_not_come_out_with_a_region_twice():
    """Issue 41: the coarsest exemplar spans four largest patches (before, 32 px against 16:
    a few large copies covered the output, two of one region; seed 0 peak 0.51, photo 0.16)."""
    from texsynth.metrics import repetition_peak
    ex = smooth_noise((128, 128), 0, sigma=4.0)
    out = texsynth.synthesize(ex, 256, 256, method="texture_optimization", seed=0)
    assert repetition_peak(out) < repetition_peak(ex) + 0.1


def test_the_photos_own_dead_ends_are_copied_less(monkeypatch):
    """Six gaps cut in a running bond's bed joints (12 dead ends in the photo): left free, the
    synthesis copies each stub's pixel 1.31 times as often as a photo pixel on average (seed 0);
    with ``DEAD_END_COST`` 0.64 times (1.25 at 16; the cost on the fine levels only,
    ``DEAD_END_SHARE``: the layout is kept), never with it on every level."""
    from texsynth.algorithms import texture_optimization as to
    from texsynth.blocks import feature_distance, joint_repair
    from texsynth.blocks.joints import luma

    from _images import running_bond

    wall, _ = running_bond((192, 256), 0, course=24, brick=56, joint=3, tint=(0.9, 0.5, 0.4),
                           shade=(0.6, 0.4), grain=0.1, mortar=(0.85, 0.85, 0.8), speckle=0.1)
    for r in (49, 97, 145):  # bed joints' middle rows
        for x in (40, 150):
            wall[r - 2:r + 3, x:x + 8] = wall[r + 8:r + 13, x:x + 8]  # brick over the joint
    ends = joint_repair.photo_ends(luma(wall), feature_distance.fit(wall, 0.0, to.FEATURE_WEIGHT))

    def copies():
        _, p = texsynth.synthesize_positions(wall, 384, 384, method="texture_optimization",
                                               seed=0)
        use = np.zeros(wall.shape[:2])
        np.add.at(use, (p[..., 0].ravel(), p[..., 1].ravel()), 1)
        return use[ends].mean() / use.mean()

    assert ends.sum() == 12
    kept = copies()
    monkeypatch.setattr(to, "DEAD_END_SHARE", 1.0)  # the cost on every level too
    assert copies() < 0.5
    monkeypatch.setattr(to, "DEAD_END_COST", 0.0)
    assert kept < copies()

"""Composite textures (Zalesny et al. 2002, sections 1, 3, 4): segmentation, label texture, fill,
errors."""

import numpy as np
import pytest
from scipy import ndimage

import texsynth
from texsynth.algorithms.composite import segmentation
from texsynth.algorithms.composite import synthesis as composite
from texsynth.algorithms.composite.segmentation import label_colours, labels_from_image, segment
from texsynth.algorithms.cooccurrence import cliques
from texsynth.metrics import seam_ratio

from _images import half_iqr, isolated, smooth_noise

FAST = {"max_cliques": 6, "sweeps": 8}
RED, BLUE = np.array([0.8, 0.25, 0.2]), np.array([0.2, 0.35, 0.85])


def _two_colours(shape=(48, 48), seed=0, noise=0.05):
    """Blobs of blue noise on red noise, and their true labels."""
    rng = np.random.default_rng(seed)
    h, w = shape
    y, x = np.mgrid[0:h, 0:w]
    truth = (((y % 24 - 12) ** 2 + (x % 24 - 10) ** 2) < 49).astype(np.int32)
    truth |= (np.abs(y - 40) < 3) & (x < 30)
    img = np.where(truth[:, :, None] == 1, BLUE, RED) + rng.normal(0, noise, (h, w, 3))
    return np.clip(img, 0, 1).astype(np.float32), truth


@pytest.fixture(scope="module")
def scene():
    return _two_colours()


def test_segmentation_finds_two_classes_without_being_told(scene):
    img, truth = scene
    labels = segment(img)
    assert labels.max() == 1
    agree = max((labels == truth).mean(), (labels != truth).mean())
    assert agree > 0.97


def test_automatic_contrast_splits_a_low_contrast_mixture():
    """Two greys 9 Lab units apart: one class at contrast 6, two with the automatic default."""
    rng = np.random.default_rng(2)
    truth = (np.arange(64)[:, None] // 16 + np.arange(64)[None, :] // 16) % 2
    img = np.where(truth[:, :, None] == 1, 0.50, 0.58) + rng.normal(0, 0.01, (64, 64, 3))
    img = np.clip(img, 0, 1).astype(np.float32)
    assert segment(img, contrast=6.0).max() == 0
    labels = segment(img)
    assert labels.max() == 1
    assert max((labels == truth).mean(), (labels != truth).mean()) > 0.95


def test_segmentation_of_a_uniform_texture_gives_one_class():
    rng = np.random.default_rng(1)
    img = np.clip(0.5 + rng.normal(0, 0.03, (40, 40, 3)), 0, 1).astype(np.float32)
    assert segment(img).max() == 0


def test_painted_label_image_with_antialiased_edges():
    _, truth = _two_colours()
    painted = np.where(truth[:, :, None] == 1, [0.0, 1.0, 0.0], [1.0, 0.0, 1.0])
    painted[10, 10] = [0.5, 0.5, 0.5]  # an anti-aliased pixel joins the nearest colour
    labels = labels_from_image(painted)
    assert labels.max() == 1
    assert (labels == truth).all() or (labels != truth).all()


def _regions_keep_their_colours(image, out_labels):
    red_side = image[:, :, 0] > image[:, :, 2]
    return (red_side == (out_labels == 0)).mean()


@pytest.mark.parametrize("fill", ["cooccurrence", "heeger_bergen"])
def test_each_subtexture_fills_only_its_own_regions(scene, fill):
    img, truth = scene
    layout = np.zeros((40, 56), np.int32)
    layout[8:30, 5:25] = 1
    layout[:, 40:50] = 1
    params = {"fill_params": {"iterations": 3}} if fill != "cooccurrence" else {}
    if fill != "cooccurrence":  # a class exemplar must hold a square of MIN_SQUARE pixels
        truth = np.zeros((64, 64), np.int32)
        truth[:, 30:] = 1
        img = np.where(truth[:, :, None] == 1, BLUE, RED).astype(np.float32)
        img += np.random.default_rng(0).normal(0, 0.05, img.shape).astype(np.float32)
    r = composite.compose(img, 56, 40, labels=truth, output_labels=layout, fill=fill, seed=1,
                          **FAST, **params)
    assert np.array_equal(r.output_labels, layout)
    assert r.fallbacks == ()
    assert _regions_keep_their_colours(r.image, layout) > 0.99


def test_composite_output_and_its_label_map_tile_and_are_deterministic(scene):
    img, truth = scene
    a = composite.compose(img, 64, 48, labels=truth, seed=3, **FAST)
    b = composite.compose(img, 64, 48, labels=truth, seed=3, **FAST)
    assert np.array_equal(a.image, b.image) and np.array_equal(a.output_labels, b.output_labels)
    assert a.image.shape == (48, 64, 3) and a.output_labels.shape == (48, 64)
    assert seam_ratio(a.image) < 1.3
    assert seam_ratio(a.output_labels.astype(np.float32)) < 1.5
    assert set(np.unique(a.output_labels)) == {0, 1}
    assert composite.class_proportion_error(truth, a.output_labels) < 0.15
    assert _regions_keep_their_colours(a.image, a.output_labels) > 0.99


def test_registered_method_segments_automatically(scene):
    img, _ = scene
    out = texsynth.synthesize(img, 40, 32, method="composite", seed=2, **FAST)
    again = texsynth.synthesize(img, 40, 32, method="composite", seed=2, **FAST)
    assert out.shape == (32, 40, 3) and np.array_equal(out, again)
    assert seam_ratio(out) < 1.3


def test_output_label_map_painted_in_the_segmentation_colours(scene):
    img, truth = scene
    layout = np.zeros((32, 32), np.int32)
    layout[:, 16:] = 1
    painted = label_colours(layout)
    r = composite.compose(img, 32, 32, labels=truth, output_labels=painted, seed=0, **FAST)
    assert np.array_equal(r.output_labels, layout)


def test_entropy_order_puts_the_flat_class_first():
    rng = np.random.default_rng(0)
    img = np.zeros((32, 32, 3), np.float32)
    labels = np.zeros((32, 32), np.int32)
    labels[:, 16:] = 1
    img[:, 16:] = 0.5  # flat
    img[:, :16] = rng.random((32, 16, 3))  # busy
    assert composite.complexity_order(img, labels) == [1, 0]


def test_bad_input_is_refused_clearly(scene):
    img, truth = scene
    with pytest.raises(ValueError, match="label image is 40 x 48 pixels; it must be 48 x 48"):
        composite.compose(img, 32, 32, labels=truth[:, :40])
    with pytest.raises(ValueError, match="single class"):
        composite.compose(img, 32, 32, labels=np.zeros((48, 48), np.int32))
    with pytest.raises(ValueError, match="output label map is 16 x 16 pixels"):
        composite.compose(img, 32, 32, labels=truth, output_labels=np.zeros((16, 16)))
    with pytest.raises(ValueError, match="labels are 0..1"):
        composite.compose(img, 16, 16, labels=truth, output_labels=np.full((16, 16), 3))
    with pytest.raises(ValueError, match="single-texture"):
        composite.compose(img, 16, 16, labels=truth, fill="composite")
    with pytest.raises(ValueError, match="'fill' must be one of"):
        composite.compose(img, 16, 16, labels=truth, fill="nope")
    flat = np.full((32, 32, 3), 0.5, np.float32)
    with pytest.raises(ValueError, match="single class"):
        texsynth.synthesize(flat, 16, 16, method="composite")


def test_the_method_is_compose_and_its_image():
    """One path: texsynth.synthesize(method="composite") is compose's work (from a generator
    seeded by one draw of the seed's), its image, not a second synthesis."""
    img, _ = _two_colours((32, 32))
    out = texsynth.synthesize(img, 24, 16, method="composite", seed=5, **FAST)
    drawn = int(np.random.default_rng(5).integers(2**31))
    assert np.array_equal(out, composite.compose(img, 24, 16, seed=drawn, **FAST).image)


def test_large_outputs_fill_from_a_half_size_composite_and_still_tile(monkeypatch):
    img, truth = _two_colours((64, 64))
    direct = composite.compose(img, 96, 64, labels=truth, seed=3, **FAST)
    monkeypatch.setattr(composite, "COARSE_PIXELS", 40 * 40)  # 96 x 64 is "production size"
    a = composite.compose(img, 96, 64, labels=truth, seed=3, **FAST)
    b = composite.compose(img, 96, 64, labels=truth, seed=3, **FAST)
    assert np.array_equal(a.image, b.image) and not np.array_equal(a.image, direct.image)
    assert a.image.shape == (64, 96, 3) and seam_ratio(a.image) < 1.3
    assert _regions_keep_their_colours(a.image, a.output_labels) > 0.99


def _discs(side=128, seed=0):
    """Two classes: 14 discs of radius 8 to 19 on a torus (mean run length about 27 pixels)."""
    rng = np.random.default_rng(seed)
    y, x = np.mgrid[0:side, 0:side]
    labels = np.zeros((side, side), np.int32)
    for _ in range(14):
        cy, cx, r = rng.integers(0, side), rng.integers(0, side), rng.integers(8, 20)
        dy, dx = np.abs(y - cy), np.abs(x - cx)
        labels[np.minimum(dy, side - dy) ** 2 + np.minimum(dx, side - dx) ** 2 < r * r] = 1
    return labels


@pytest.mark.parametrize("label_scale", [3, 4])
def test_label_map_modelled_at_a_reduced_scale_changes_class_across_the_wrap_as_inside(
        label_scale):
    """Class changes between the last and first row (and column) are as frequent as between
    interior neighbours, over seeds: no seam in the layout (issue 18; it was 3x)."""
    labels = _discs()
    wrap = inside = 0.0
    for seed in range(16):
        out = composite.synthesize_labels(labels, 256, 256, seed=seed, label_scale=label_scale,
                                          max_cliques=6, sweeps=8)
        wrap += np.concatenate([out[0] != out[-1], out[:, 0] != out[:, -1]]).mean()
        inside += np.concatenate([(np.diff(out, axis=0) != 0).ravel(),
                                  (np.diff(out, axis=1) != 0).ravel()]).mean()
    assert 0.75 < wrap / inside < 1.33


def test_boundaries_off_the_even_grid_keep_their_colours_in_the_half_size_fill(monkeypatch):
    """Pixels along the boundaries of a painted layout, all on odd rows and columns (each 2 x 2
    block of the half-size fill straddles them), take their own region's colour."""
    img, truth = _two_colours((64, 64))
    layout = np.zeros((64, 96), np.int32)
    layout[9:31, 5:27] = 1
    layout[:, 41:55] = 1
    layout[45:, 61:91] = 1
    monkeypatch.setattr(composite, "COARSE_PIXELS", 40 * 40)
    r = composite.compose(img, 96, 64, labels=truth, output_labels=layout, seed=1, **FAST)
    edge = ndimage.binary_dilation(layout == 1) & ndimage.binary_dilation(layout == 0)
    red_side = r.image[:, :, 0] > r.image[:, :, 2]
    assert (red_side == (layout == 0))[edge].mean() > 0.98


def test_a_large_photo_is_segmented_and_modelled_from_samples_of_all_of_it(monkeypatch):
    """Above the sample sizes (lowered here so that a 96 x 96 photo is "large"), the
    segmentation still labels every pixel as a full analysis would, and the subtextures,
    counted on sampled rows, keep their colours in their own regions, deterministically."""
    img, truth = _two_colours((96, 96))
    full = segment(img)
    monkeypatch.setattr(segmentation, "SAMPLE_PIXELS", 96 * 96 // 8)
    monkeypatch.setattr(composite, "SAMPLE_PIXELS", 96 * 96 // 8)
    monkeypatch.setattr(cliques, "ANCHORS", 96 * 32)
    sampled = segment(img)
    assert (sampled == full).mean() > 0.99
    assert max((sampled == truth).mean(), (sampled != truth).mean()) > 0.97
    a = composite.compose(img, 64, 48, seed=3, **FAST)
    b = composite.compose(img, 64, 48, seed=3, **FAST)
    assert np.array_equal(a.image, b.image) and a.labels.shape == (96, 96)
    assert _regions_keep_their_colours(a.image, a.output_labels) > 0.99
    assert seam_ratio(a.image) < 1.3


def test_features_in_bands_are_those_of_the_whole_image():
    img = np.random.default_rng(0).random((600, 70, 3), dtype=np.float32)
    for texture in (False, True):
        assert np.array_equal(segmentation.features(img, texture),
                              segmentation._features(img, texture))


def _three_stripes():
    rng = np.random.default_rng(0)
    x = rng.random((32, 32, 3)).astype(np.float32)
    x[:, 11:22] *= 0.3
    return x, (np.arange(32)[None, :] * 3 // 32).repeat(32, 0)


@pytest.mark.parametrize("one", [0, 1, 2])
def test_an_output_map_of_one_class_is_filled_with_that_class_texture(one):
    """Each class's model keeps the cliques it shares with its neighbours; an output label map
    without those neighbours (one class) once indexed past the classes it held."""
    x, labels = _three_stripes()
    out = composite.compose(x, 24, 24, labels=labels, output_labels=np.full((24, 24), one),
                            seed=0, max_cliques=3, sweeps=2).image
    own = x[labels == one]
    assert out.shape == (24, 24, 3) and np.isfinite(out).all()
    assert abs(out.mean() - own.mean()) < 0.05 and 0.7 < out.std() / own.std() < 1.3


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_a_one_pixel_composite(seed):
    x, _ = _three_stripes()
    out = composite.compose(x, 1, 1, seed=seed, max_cliques=3, sweeps=2).image
    assert out.shape == (1, 1, 3) and np.isfinite(out).all()


def test_a_label_image_of_too_many_classes_is_the_promised_value_error():
    """labels_from_image's docstring promises ValueError above MAX_CLASSES classes."""
    many = np.arange(segmentation.MAX_CLASSES + 1).repeat(4).reshape(-1, 4)
    with pytest.raises(ValueError, match=f"{segmentation.MAX_CLASSES + 1} classes; at most"):
        labels_from_image(many)
    assert labels_from_image(many[:-1]).max() == segmentation.MAX_CLASSES - 1


def test_a_large_composite_of_smooth_subtextures_has_no_salt_and_pepper(monkeypatch):
    """Filled from a half-size composite, no pixel inside a region jumps far from all its
    neighbours: on smooth subtextures (none of the exemplar's pixels lies half its
    interquartile range beyond all 8 neighbours), unbounded refining proposals left 2.3-2.6%
    of the regions' inner pixels so (speckle), now 0.5-0.6%."""
    _, truth = _two_colours((64, 64))
    photo = (0.6 * np.where(truth[:, :, None] == 1, BLUE, RED)
             + 0.4 * smooth_noise((64, 64), seed=3, sigma=2.0)).astype(np.float32)
    monkeypatch.setattr(composite, "COARSE_PIXELS", 48 * 48)
    out = composite.compose(photo, 128, 128, labels=truth, seed=1, **FAST)
    assert isolated(photo, half_iqr(photo), truth) == 0
    assert isolated(out.image, half_iqr(photo), out.output_labels) < 0.012
    assert seam_ratio(out.image) < 1.3

import numpy as np
import pytest

from texsynth.blocks import parallel
from texsynth.blocks.pyramid import LaplacianPyramid, SteerablePyramid, max_scales


@pytest.mark.parametrize("shape", [(64, 64), (37, 53), (200, 300), (128, 96)])
@pytest.mark.parametrize("orientations", [1, 2, 4, 6, 8])
def test_analysis_then_synthesis_reconstructs(shape, orientations):
    x = np.random.default_rng(1).standard_normal(shape).astype(np.float32)
    pyr = SteerablePyramid(shape, max_scales(shape), orientations)
    coeffs = pyr.analyze(x)
    y = pyr.synthesize(coeffs)
    assert y.dtype == np.float32 and y.shape == shape
    assert np.abs(y - x).max() < 1e-5


def test_tight_frame_preserves_energy():
    shape = (96, 80)
    x = np.random.default_rng(2).standard_normal(shape)
    pyr = SteerablePyramid(shape, 3, 4)
    coeffs = pyr.analyze(x)
    pixels = x.size
    energy = sum((a.astype(np.float64) ** 2).sum() * pixels / a.size for a in coeffs.arrays())
    assert energy == pytest.approx((x**2).sum(), rel=1e-5)


def test_layout_and_level_sizes():
    pyr = SteerablePyramid((300, 201), 3, 5)
    coeffs = pyr.analyze(np.zeros((300, 201), np.float32))
    assert coeffs.highpass.shape == (300, 201)
    assert [b[0].shape for b in coeffs.bands] == [(300, 201), (150, 101), (75, 51)]
    assert all(len(level) == 5 for level in coeffs.bands)
    assert coeffs.lowpass.shape == (38, 26)
    assert len(coeffs.arrays()) == 1 + 3 * 5 + 1


def test_bands_are_shift_equivariant_so_the_transform_is_periodic():
    x = np.random.default_rng(3).standard_normal((64, 48)).astype(np.float32)
    pyr = SteerablePyramid((64, 48), 2, 4)
    a = pyr.analyze(x)
    b = pyr.analyze(np.roll(x, (5, -7), axis=(0, 1)))
    np.testing.assert_allclose(np.roll(a.bands[0][1], (5, -7), axis=(0, 1)), b.bands[0][1],
                               atol=1e-5)
    np.testing.assert_allclose(np.roll(a.highpass, (5, -7), axis=(0, 1)), b.highpass, atol=1e-5)


def test_orientation_selectivity():
    """Stripes varying along x excite the band tuned to theta = 0 most, its orthogonal least."""
    n = 64
    xx = np.arange(n)[None, :].repeat(n, axis=0)
    stripes = np.cos(2 * np.pi * xx * 12 / n).astype(np.float32)  # 0.375 cycles/px: level 0
    pyr = SteerablePyramid((n, n), 2, 4)
    energies = [float((b**2).sum()) for b in pyr.analyze(stripes).bands[0]]
    assert int(np.argmax(energies)) == 0
    assert energies[2] < 1e-6 * energies[0]


def test_depth_is_bounded_by_the_image_size():
    assert max_scales((8, 8)) == 1
    assert max_scales((256, 300)) == 6
    assert max_scales((4, 100)) == 0
    with pytest.raises(ValueError, match="at most 1 scales"):
        SteerablePyramid((8, 12), 2, 4)
    with pytest.raises(ValueError, match="pyramid built for"):
        SteerablePyramid((16, 16), 1, 4).analyze(np.zeros((16, 17), np.float32))


def test_same_subbands_as_pyrtools_up_to_the_decimation_gain():
    """Dev-only reference: pyrtools' SteerablePyramidFreq (installed by benchmarks/requirements).

    pyrtools crops the spectrum without rescaling, so its level-j values are 4^j times ours.
    """
    pt = pytest.importorskip("pyrtools")
    x = np.random.default_rng(5).standard_normal((64, 64))
    reference = pt.pyramids.SteerablePyramidFreq(x, height=3, order=3).pyr_coeffs
    ours = SteerablePyramid((64, 64), 3, 4).analyze(x.astype(np.float32))
    np.testing.assert_allclose(ours.highpass, reference["residual_highpass"], atol=1e-4)
    for j in range(3):
        for m in range(4):
            np.testing.assert_allclose(ours.bands[j][m] * 4.0**j, reference[(j, m)], atol=1e-4)
    np.testing.assert_allclose(ours.lowpass * 64.0, reference["residual_lowpass"], atol=1e-3)


def test_analysis_and_synthesis_do_not_depend_on_the_number_of_threads(monkeypatch):
    image = np.random.default_rng(5).random((96, 80), dtype=np.float32)
    pyramid = SteerablePyramid(image.shape, 3, 4)
    monkeypatch.setattr(parallel, "WORKERS", 3)
    split = pyramid.analyze(image)
    again = pyramid.synthesize(split)
    monkeypatch.setattr(parallel, "WORKERS", 1)
    alone = pyramid.analyze(image)
    for a, b in zip(split.arrays(), alone.arrays(), strict=True):
        np.testing.assert_array_equal(a, b)
    np.testing.assert_array_equal(pyramid.synthesize(alone), again)


def test_analysis_into_earlier_arrays_with_a_hook_on_each_band():
    rng = np.random.default_rng(6)
    first, second = (rng.random((200, 150), dtype=np.float32) for _ in range(2))
    pyramid = SteerablePyramid(first.shape, 3, 4)
    kept = pyramid.analyze(first)
    seen = {}
    again = pyramid.analyze(second, out=kept, each=lambda i, band: seen.setdefault(i, band))
    assert again is kept
    fresh = pyramid.analyze(second)
    assert sorted(seen) == list(range(len(fresh.arrays())))
    for i, (a, b) in enumerate(zip(again.arrays(), fresh.arrays(), strict=True)):
        assert seen[i] is a
        np.testing.assert_array_equal(a, b)
    image = np.empty(first.shape, np.float32)
    assert pyramid.synthesize(fresh, out=image) is image
    np.testing.assert_array_equal(image, pyramid.synthesize(fresh))
    assert np.abs(image - second).max() < 1e-5


@pytest.mark.parametrize("shape", [(301, 403), (128, 96)])
def test_a_pyramid_of_the_coarser_levels_gives_the_full_pyramids_bands(shape):
    # De Bonet's oriented features from the Laplacian's G_1, without the full-size transform
    image = np.random.default_rng(4).random(shape, dtype=np.float32)
    full = SteerablePyramid(shape, 3, 4).analyze(image)
    laplacian = LaplacianPyramid(shape, 3)
    g1 = laplacian.synthesize(laplacian.analyze(image), 1)
    below = SteerablePyramid(laplacian.level_shapes[1], 2, 4, full=shape).analyze(g1)
    for j in (1, 2):
        for ours, theirs in zip(below.bands[j - 1], full.bands[j], strict=True):
            np.testing.assert_allclose(ours, theirs, atol=1e-5 * np.abs(theirs).max())
    with pytest.raises(ValueError, match="not a pyramid level"):
        SteerablePyramid((100, 100), 1, 4, full=shape)

"""Stacks of registered maps (Neubeck et al. 2004 sec. 2.3, 3.2) and the BTF alignment plane (sec.
2.2)."""

import numpy as np
import pytest
from scipy.ndimage import gaussian_filter, map_coordinates

import texsynth
from texsynth.metrics import luminance, seam_ratio
from texsynth.stack import btf

from _images import ramp_photo, smooth_noise

FAST = {"levels": 2}


def shading(colour):
    """A second map that is a known pixelwise function of the first (a shading of luminance)."""
    return (0.1 + 0.8 * luminance(colour) ** 2)[:, :, None].astype(np.float32)


def relation_error(out):
    """Mean |B - f(A)| relative to mean |B|: 0 when the synthesized maps keep the relation."""
    return float(np.abs(out[1] - shading(out[0])).mean() / np.abs(out[1]).mean())


@pytest.fixture(scope="module")
def colour():
    return ramp_photo((40, 40), seed=6)


@pytest.fixture(scope="module")
def guided(colour):
    return texsynth.synthesize_stack([colour, shading(colour)], 56, 48, seed=2, **FAST)


def test_guided_keeps_the_relation_independent_synthesis_does_not(colour, guided):
    a = texsynth.synthesize(colour, 56, 48, "multiscale_mrf", seed=2, **FAST)
    b = texsynth.synthesize(shading(colour), 56, 48, "multiscale_mrf", seed=3, **FAST)
    independent = relation_error([a, b])
    assert relation_error(guided) < 0.05
    assert independent > 4 * relation_error(guided)


def test_column_mode_reproduces_the_relation_exactly(colour):
    out = texsynth.synthesize_stack([colour, shading(colour)], 56, 48, seed=2, mode="column",
                                    **FAST)
    np.testing.assert_allclose(out[1], shading(out[0]), atol=1e-6)


def test_support_is_the_single_view_synthesis(colour, guided):
    alone = texsynth.synthesize(colour, 56, 48, "multiscale_mrf", seed=2, **FAST)
    assert np.array_equal(guided[0], alone)


def test_every_view_tiles_and_has_its_shape_and_channels(guided):
    assert [v.shape for v in guided] == [(48, 56, 3), (48, 56, 1)]
    for view in guided:
        assert view.dtype == np.float32
        assert seam_ratio(view) < 1.3
        assert seam_ratio(np.roll(view, (13, 21), axis=(0, 1))) < 1.3


def test_array_stack_other_support_and_four_channels():
    base = smooth_noise((32, 32), seed=1)
    rgba = np.concatenate([base, base[:, :, :1]], axis=2)
    stack = np.stack([rgba, 1.0 - rgba, rgba[:, :, ::-1]])
    for mode in ("guided", "column"):
        out = texsynth.synthesize_stack(stack, 40, 36, support=2, seed=0, mode=mode, **FAST)
        assert isinstance(out, np.ndarray) and out.shape == (3, 36, 40, 4)
        assert all(seam_ratio(v[:, :, :3]) < 1.3 for v in out)
        assert np.abs(out[0] - (1.0 - out[1])).mean() < 0.05


def test_same_seed_same_stack(colour):
    stack = [colour, shading(colour)]
    a = texsynth.synthesize_stack(stack, 32, 32, seed=4, **FAST)
    b = texsynth.synthesize_stack(stack, 32, 32, seed=4, **FAST)
    assert all(np.array_equal(x, y) for x, y in zip(a, b, strict=True))


@pytest.mark.parametrize("stack, support, message", [
    ([np.zeros((32, 32, 3)), np.zeros((32, 30, 1))], 0, "same size"),
    ([np.zeros((32, 32, 3))] * 2, 2, "support"),
    ([np.zeros((32, 32, 3))] * 2, -3, "support"),
    ([], 0, "no views"),
    ([np.zeros((32, 32, 3)), np.zeros((32, 32, 2))], 0, "view 1"),
])
def test_bad_stacks_raise_clear_errors(stack, support, message):
    with pytest.raises(ValueError, match=message):
        texsynth.synthesize_stack(stack, 32, 32, support=support)


def test_bad_mode_and_c():
    stack = [np.zeros((32, 32, 3))] * 2
    with pytest.raises(ValueError, match="mode"):
        texsynth.synthesize_stack(stack, 32, 32, mode="columns")
    with pytest.raises(ValueError, match="c must"):
        texsynth.synthesize_stack(stack, 32, 32, c=2.0)


def test_guided_over_the_memory_budget_says_so(colour, monkeypatch):
    monkeypatch.setenv("TEXSYNTH_MEMORY_BUDGET", str(1 << 20))
    with pytest.raises(ValueError, match="mode='column'"):
        texsynth.synthesize_stack([colour, shading(colour)], 256, 256)


def test_cancel_stops_the_stack(colour):
    def cancel(fraction, message):
        return fraction < 0.6

    with pytest.raises(texsynth.Cancelled):
        texsynth.synthesize_stack([colour, shading(colour)], 32, 32, progress=cancel, **FAST)


def parallel_views(albedo, height, view_dirs):
    """Parallel projections of a textured height field, rectified for height 0 (to first order
    in the height slope: the view shows at x the surface point x + h(x) d_xy / d_z)."""
    rows, cols = np.mgrid[:albedo.shape[0], :albedo.shape[1]].astype(np.float64)
    views = []
    for d in view_dirs:
        r = rows + height * d[1] / d[2]
        c = cols + height * d[0] / d[2]
        views.append(map_coordinates(albedo, [r, c], order=1, mode="wrap"))
    return np.stack(views)


def test_alignment_finds_the_mean_height_of_the_surface():
    rng = np.random.default_rng(0)
    albedo = gaussian_filter(rng.random((64, 64)), 1.0, mode="wrap")
    mean_height = 3.0
    height = mean_height + 0.8 * gaussian_filter(rng.standard_normal((64, 64)), 4, mode="wrap")
    slant = np.radians([0, 15, 15, 15, 15, 30, 30])
    tilt = np.radians([0, 0, 90, 180, 270, 45, 225])
    dirs = np.stack([np.sin(slant) * np.cos(tilt), np.sin(slant) * np.sin(tilt),
                     np.cos(slant)], axis=1)
    stack = parallel_views(albedo, height, dirs)
    heights = np.arange(-2.0, 8.01, 0.5)
    best, curve, realigned = btf.align(stack, dirs, heights)
    assert abs(best - mean_height) <= 0.5
    assert curve.shape == heights.shape and curve[0] > 2 * curve.min()
    assert realigned.shape == stack.shape + (1,)


def test_alignment_bad_input():
    stack = np.zeros((3, 16, 16))
    dirs = np.array([[0, 0, 1], [0.1, 0, 1], [0, 0.1, 1]])
    with pytest.raises(ValueError, match="view_dirs"):
        btf.align(stack, dirs[:2], [0.0])
    with pytest.raises(ValueError, match="too much"):
        btf.align(stack, dirs, [100.0])
    with pytest.raises(ValueError, match="lighting"):
        btf.align(stack, dirs, [0.0], lights=[0, 1, 2])

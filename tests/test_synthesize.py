"""The core API as a script or the operator uses it: texsynth.synthesize and the registry."""

import numpy as np
import pytest

import texsynth
from texsynth.blocks import parallel
from texsynth.blocks.pyramid import SteerablePyramid
from texsynth.metrics import seam_ratio

from _images import ramp_photo, smooth_noise

FAST = {"iterations": 3}


@pytest.fixture(scope="module")
def photo():
    return ramp_photo((64, 80), seed=3)


def test_output_tiles_although_the_exemplar_does_not(photo):
    assert seam_ratio(photo) > 3
    out = texsynth.synthesize(photo, 128, 96, seed=1, **FAST)
    assert seam_ratio(out) < 1.3
    tiled = np.tile(out, (2, 2, 1))
    assert seam_ratio(tiled) < 1.3


@pytest.mark.parametrize("size", [(300, 200), (37, 53), (64, 64), (16, 24), (5, 3)])
def test_any_output_size(photo, size):
    width, height = size
    out = texsynth.synthesize(photo, width, height, **FAST)
    assert out.shape == (height, width, 3) and out.dtype == np.float32
    assert np.isfinite(out).all()


def test_the_number_of_cores_does_not_change_the_output(photo, monkeypatch):
    """Matching, transforms and colour steps run on every core: the same seed must still give
    the same pixels on a machine with one core or many."""
    monkeypatch.setattr(parallel, "WORKERS", 3)
    assert len(parallel.ranges(384 * 352)) > 1          # the matches are split too
    split = texsynth.synthesize(photo, 384, 352, seed=2, **FAST)
    monkeypatch.setattr(parallel, "WORKERS", 1)
    np.testing.assert_array_equal(texsynth.synthesize(photo, 384, 352, seed=2, **FAST), split)


def test_constant_alpha_is_kept_exactly(photo):
    rgba = np.concatenate([photo, np.full(photo.shape[:2] + (1,), 0.75, np.float32)], axis=2)
    out = texsynth.synthesize(rgba, 40, 40, **FAST)
    assert out.shape == (40, 40, 4)
    assert np.all(out[:, :, 3] == np.float32(0.75))
    rgb = texsynth.synthesize(photo, 40, 40, **FAST)
    assert np.array_equal(out[:, :, :3], rgb)


def test_integer_images_are_scaled_to_unit_range(photo):
    as_uint8 = np.round(photo * 255).astype(np.uint8)
    as_uint16 = np.round(photo * 65535).astype(np.uint16)
    for image, top in ((as_uint8, 255), (as_uint16, 65535)):
        out = texsynth.synthesize(image, 32, 32, **FAST)
        expected = texsynth.synthesize(image.astype(np.float32) / top, 32, 32, **FAST)
        np.testing.assert_array_equal(out, expected)
        assert 0 <= out.min() and out.max() <= 1


def test_output_keeps_the_exemplar_statistics():
    exemplar = smooth_noise((96, 96), seed=4, sigma=1.5)
    out = texsynth.synthesize(exemplar, 128, 128, seed=2, iterations=10)
    np.testing.assert_allclose(out.mean(axis=(0, 1)), exemplar.mean(axis=(0, 1)), atol=0.02)
    np.testing.assert_allclose(out.std(axis=(0, 1)), exemplar.std(axis=(0, 1)), rtol=0.1)
    # subband energies (what the eye reads as texture scale and orientation) are kept
    ex_bands = SteerablePyramid((96, 96), 3, 4).analyze(exemplar[:, :, 0]).bands
    out_bands = SteerablePyramid((128, 128), 3, 4).analyze(out[:, :, 0]).bands
    for ex_level, out_level in zip(ex_bands, out_bands, strict=True):
        for e, o in zip(ex_level, out_level, strict=True):
            assert o.std() == pytest.approx(e.std(), rel=0.25)


def test_progress_reports_increasing_fractions_and_finishes(photo):
    seen = []
    texsynth.synthesize(photo, 32, 32, progress=lambda f, m: seen.append((f, m)), **FAST)
    fractions = [f for f, _ in seen]
    assert fractions[0] == 0.0 and fractions[-1] == 1.0
    assert np.all(np.diff(fractions) >= 0)
    assert len(seen) >= 3 * FAST["iterations"]
    assert all(isinstance(m, str) and m for _, m in seen)


@pytest.mark.parametrize("how", ["return_false", "raise"])
def test_cancelling_raises_cancelled(photo, how):
    calls = []

    def progress(fraction, message):
        calls.append(fraction)
        if fraction > 0.3:
            if how == "raise":
                raise texsynth.Cancelled()
            return False
        return True

    with pytest.raises(texsynth.Cancelled):
        texsynth.synthesize(photo, 64, 64, progress=progress, **FAST)
    assert calls[-1] < 1.0


def test_registry_describes_heeger_bergen():
    names = [m.name for m in texsynth.methods()]
    assert "heeger_bergen" in names
    hb = texsynth.get_method("heeger_bergen")
    params = {p.name: p for p in hb.params}
    assert {"scales", "orientations", "iterations"} <= set(params)
    assert (params["scales"].default, params["orientations"].default,
            params["iterations"].default) == (4, 4, 15)
    assert all(p.type in (int, float, bool, str) and p.description for p in params.values())


@pytest.mark.parametrize(
    ("exemplar", "kwargs", "message"),
    [
        (np.zeros((1, 1, 3)), {}, "at least 8 x 8"),
        (np.zeros((7, 30, 3)), {}, "at least 8 x 8"),
        (np.zeros((16, 16, 2)), {}, "1, 3 or 4 channels"),
        (np.zeros((2, 16, 16, 3)), {}, r"\(H, W\) or \(H, W, C\)"),
        (np.array([["a"] * 16] * 16), {}, "numeric"),
        (np.full((16, 16, 3), np.nan), {}, "NaN or infinite"),
        (np.pad(np.zeros((15, 16, 3)), ((0, 1), (0, 0), (0, 0)), constant_values=np.inf), {},
         "NaN or infinite"),
        (np.zeros((16, 16, 3)), {"width": 0}, "width must be between 1"),
        (np.zeros((16, 16, 3)), {"height": -5}, "height must be between 1"),
        (np.zeros((16, 16, 3)), {"width": 10**6}, "width must be between 1"),
        (np.zeros((16, 16, 3)), {"width": 32.5}, "whole number"),
        (np.zeros((16, 16, 3)), {"method": "nope"}, "unknown method 'nope'"),
        (np.zeros((16, 16, 3)), {"scales": 0}, "'scales' must be >= 1"),
        (np.zeros((16, 16, 3)), {"iterations": 2.5}, "whole number"),
        (np.zeros((16, 16, 3)), {"orientations": "four"}, "must be a number"),
        (np.zeros((16, 16, 3)), {"smoothness": 3}, "has no parameter 'smoothness'"),
        (np.zeros((16, 16, 3)), {"seed": -1}, "seed must be"),
    ],
)
def test_bad_input_gives_a_clear_error(exemplar, kwargs, message):
    args = {"width": 32, "height": 32, **kwargs}
    with pytest.raises(ValueError, match=message):
        texsynth.synthesize(exemplar, **args)


def test_memory_budget_is_checked_before_allocating(monkeypatch, photo):
    monkeypatch.setenv("TEXSYNTH_MEMORY_BUDGET", str(64 << 20))
    monkeypatch.setenv("TEXSYNTH_TIME_BUDGET", "1e9")  # the memory budget's refusal, at any load
    with pytest.raises(ValueError, match="over the budget of"):
        texsynth.synthesize(photo, 16384, 16384)
    texsynth.synthesize(photo, 64, 64, **FAST)  # small work still fits


def test_methods_keep_their_places_so_saved_scenes_keep_their_method():
    """Blender saves a scene's method by its index in this list: new methods go at the end."""
    names = [m.name for m in texsynth.methods()]
    assert names[:7] == ["heeger_bergen", "efros_leung", "multiscale_mrf", "de_bonet",
                         "cooccurrence", "texture_optimization", "composite"]

"""texsynth.norepeat: the Gaussianised texture and its table (Heitz & Neyret 2018; Deliot &
Heitz 2019; Burley 2019), and tiling and blending in numpy: what a user would notice is that
the texture keeps its look (histogram, sharpness) and stops repeating."""

import importlib.util
import tracemalloc
from pathlib import Path

import numpy as np
import pytest

from texsynth.io import read_photo
from texsynth.metrics import gradient_ratio
from texsynth.norepeat import (
    gaussianize,
    period_correlation,
    predict_blend_memory,
    predict_memory,
    tile_and_blend,
    triangle_grid,
)
from texsynth.norepeat.blend import SKEW

from _images import smooth_noise, wasserstein

SAMPLE = Path(__file__).resolve().parents[1] / "samples" / "pool_water.png"


@pytest.fixture(scope="module")
def photo():
    return read_photo(SAMPLE)[:, :, :3].astype(np.float32)


def test_the_gaussian_texture_is_a_truncated_gaussian_and_the_table_gives_the_photo_back(photo):
    g = gaussianize(photo)
    assert g.gaussian.shape == photo.shape and g.gaussian.dtype == np.float32
    assert g.lut.shape == (3, 4096, 3) and g.lut.dtype == np.float32
    assert 0.0 <= g.gaussian.min() and g.gaussian.max() <= 1.0
    assert np.allclose(g.gaussian.mean(axis=(0, 1)), 0.5, atol=1e-3)
    assert np.allclose(g.gaussian.std(axis=(0, 1)), 1 / 6, rtol=0.03)
    assert np.abs(g.look_up(g.gaussian) - photo).max() < 2 / 255


def test_correlated_colours_are_decorrelated_first_when_asked():
    exemplar = smooth_noise((128, 128), seed=4)  # channels correlated by about 0.35
    before = np.corrcoef(exemplar.reshape(-1, 3), rowvar=False)
    g = gaussianize(exemplar, decorrelate=True)
    assert np.abs(g.look_up(g.gaussian) - exemplar).max() < 2 / 255
    after = np.corrcoef(g.gaussian.reshape(-1, 3), rowvar=False)
    off = ~np.eye(3, dtype=bool)
    assert np.abs(before[off]).min() > 0.3 and np.abs(after[off]).max() < 0.05


def test_grey_images_have_one_channel_and_the_input_is_untouched(photo):
    grey = photo[:, :, :1].copy()
    kept = grey.copy()
    g = gaussianize(grey)
    assert g.gaussian.shape == grey.shape and g.lut.shape == (1, 4096, 1)
    assert np.array_equal(grey, kept)


@pytest.mark.parametrize("exemplar, keywords, message", [
    (np.zeros(16), {}, "exemplar must be"),
    (np.zeros((16, 16, 5)), {}, "channels"),
    (np.full((16, 16, 3), np.nan), {}, "NaN"),
    (np.zeros((16, 16, 3)), {"lut_size": 3}, "lut_size"),
    (np.zeros((1, 16, 3)), {}, "at least"),
    (np.zeros((16, 16, 3)), {"decorrelate": "yes"}, "decorrelate"),
])
def test_bad_input_is_refused_naming_the_argument(exemplar, keywords, message):
    with pytest.raises(ValueError, match=message):
        gaussianize(exemplar, **keywords)


def test_a_texture_over_the_memory_budget_is_refused_before_any_work(monkeypatch):
    monkeypatch.setenv("TEXSYNTH_MEMORY_BUDGET", str(1 << 20))
    with pytest.raises(ValueError, match="budget"):
        gaussianize(np.zeros((512, 512, 3), np.float32))


def test_the_memory_prediction_is_within_1_5x_of_the_peak():
    exemplar = smooth_noise((384, 512), seed=1)
    tracemalloc.start()
    gaussianize(exemplar)
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    assert peak <= predict_memory(exemplar.shape) <= 1.5 * peak


@pytest.mark.parametrize("channels", [1, 3])
def test_the_blend_memory_prediction_is_within_1_5x_of_the_peak(photo, channels):
    g = gaussianize(photo[:, :, :channels])
    tracemalloc.start()
    tile_and_blend(g, 320, 192)
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    assert peak <= predict_blend_memory(320, 192, channels) <= 1.5 * peak


def test_a_blend_over_the_memory_budget_is_refused_before_any_work(photo, monkeypatch):
    g = gaussianize(photo)
    monkeypatch.setenv("TEXSYNTH_MEMORY_BUDGET", str(1 << 20))
    with pytest.raises(ValueError, match="budget"):
        tile_and_blend(g, 4096, 4096)


def test_the_example_writes_the_images_for_other_engines(tmp_path):
    spec = importlib.util.spec_from_file_location(
        "break_repetition", SAMPLE.parents[1] / "examples" / "break_repetition.py")
    example = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(example)
    example.main([str(SAMPLE), "--srgb", "--preview", "2", "--out", str(tmp_path)])
    gaussian = read_photo(tmp_path / "pool_water_tnb_gaussian.exr")
    table = read_photo(tmp_path / "pool_water_tnb_table.exr")
    preview = read_photo(tmp_path / "pool_water_tnb_preview.png")
    assert gaussian.shape[:2] == (128, 128) and table.shape[:2] == (3, 4096)
    assert preview.shape[:2] == (256, 256)
    assert abs(period_correlation(preview, 128)) < 0.3


def test_each_point_lies_in_its_triangle():
    uv = np.random.default_rng(0).random((500, 2)) * 3
    w, v = triangle_grid(uv, 2.0)
    assert (w >= 0).all() and np.allclose(w.sum(-1), 1.0)
    skewed = uv * 2.0 @ SKEW.T
    assert np.allclose((w[..., None] * v).sum(axis=1), skewed)


def test_tiling_and_blending_stops_the_repeat_and_keeps_the_look(photo):
    g = gaussianize(photo)
    h, w = photo.shape[:2]
    out = tile_and_blend(g, 4 * w, 4 * h, seed=1)
    assert out.shape == (4 * h, 4 * w, 3) and out.dtype == np.float32
    assert period_correlation(np.tile(photo, (4, 4, 1)), w) > 0.99
    assert abs(period_correlation(out, w)) < 0.3
    assert wasserstein(photo, out) < 0.03
    assert 0.85 < gradient_ratio(photo, out) < 1.15


def test_same_seed_same_texture_another_seed_another(photo):
    g = gaussianize(photo)
    a, b = tile_and_blend(g, 64, 48, seed=2), tile_and_blend(g, 64, 48, seed=2)
    assert np.array_equal(a, b)
    assert not np.array_equal(a, tile_and_blend(g, 64, 48, seed=3))


@pytest.mark.parametrize("keywords, message", [({"seed": -1}, "seed"), ({"scale": 0}, "scale")])
def test_tile_and_blend_checks_its_arguments(photo, keywords, message):
    with pytest.raises(ValueError, match=message):
        tile_and_blend(gaussianize(photo), 32, 32, **keywords)


def test_the_period_must_fit_the_image():
    with pytest.raises(ValueError, match="period"):
        period_correlation(np.zeros((16, 16)), 20)

"""texsynth.norepeat.hex: hex tiling (Mikkelsen 2022) in numpy. What a user would notice: the
texture stops repeating and keeps its look, the brighter copy wins at the seams, a normal map's
normals turn with its cells, the same seed gives the same image, bad input is refused."""

import tracemalloc
from pathlib import Path

import numpy as np
import pytest
from scipy.ndimage import gaussian_filter

from texsynth.io import read_photo
from texsynth.metrics import anisotropy, gradient_ratio
from texsynth.norepeat import (
    hex_tile,
    hex_weights,
    period_correlation,
    predict_hex_memory,
    rotation_symmetry,
)

from _images import wasserstein

SAMPLE = Path(__file__).resolve().parents[1] / "samples" / "pool_water.png"


@pytest.fixture(scope="module")
def photo():
    return read_photo(SAMPLE)[:, :, :3].astype(np.float32)


def test_hex_tiling_stops_the_repeat_and_keeps_the_look(photo):
    """At the texture's own pixel size, without rotation (a turned copy is resampled, which
    softens it at 1:1; see the rotation test)."""
    h, w = photo.shape[:2]
    out = hex_tile(photo, 4 * w, 4 * h, seed=1, rotation=0.0)
    assert out.shape == (4 * h, 4 * w, 3) and out.dtype == np.float32
    assert period_correlation(np.tile(photo, (4, 4, 1)), w) > 0.99
    assert abs(period_correlation(out, w)) < 0.3
    assert wasserstein(photo, out) < 0.03
    assert 0.85 < gradient_ratio(photo, out) < 1.15


def test_the_cells_turn_a_texture_with_a_direction():
    """Horizontal stripes: without rotation the image varies along y only; with rotation its
    x gradients grow to about the y ones."""
    y = np.arange(64)[:, None] * np.ones((1, 64))
    stripes = (0.5 + 0.4 * np.sin(2 * np.pi * y / 8))[:, :, None].astype(np.float32)

    def gx_over_gy(a):
        a = a[..., 0]
        return np.abs(np.diff(a, axis=1)).mean() / np.abs(np.diff(a, axis=0)).mean()

    assert gx_over_gy(hex_tile(stripes, 256, 256, rotation=0.0)) < 0.1
    assert gx_over_gy(hex_tile(stripes, 256, 256, rotation=1.0, turns=0)) > 0.5


def test_the_brighter_copy_wins_where_the_barycentric_weights_tie():
    w = hex_weights(np.full(3, 1 / 3), np.array([0.1, 0.8, 0.4]))
    assert np.isclose(w.sum(), 1.0) and w[1] > w[2] > w[0]
    flat = hex_weights(np.array([0.6, 0.3, 0.1]), np.ones(3))
    assert flat[0] > 0.99  # sharpness 7: the nearest cell dominates
    assert np.allclose(hex_weights(np.array([0.6, 0.3, 0.1]), np.ones(3), sharpness=1.0),
                       [0.6, 0.3, 0.1])


def _normals(height):
    """A tangent-space normal map (OpenGL: green up, rows top first) of a height field."""
    gy, gx = np.gradient(height)
    n = np.stack([-gx, gy, np.ones_like(height)], -1)  # -dh/dy up = +dh/drow
    n /= np.linalg.norm(n, axis=-1, keepdims=True)
    return (0.5 * n + 0.5).astype(np.float32)


def test_a_normal_maps_normals_turn_with_its_cells():
    """The hex-tiled normal map agrees with the normals of the equally hex-tiled height field
    (same cells and weights); left unturned, it would not."""
    rng = np.random.default_rng(3)
    height = gaussian_filter(rng.standard_normal((64, 64)), 3, mode="wrap") * 20
    height = height.astype(np.float32)
    normals = _normals(height)
    settings = {"seed": 2, "rotation": 1.0, "sharpness": 40.0, "weight_by": height}
    tiled = hex_tile(height, 256, 256, **settings)[..., 0]
    turned = hex_tile(normals, 256, 256, normal=True, **settings)
    kept = hex_tile(normals, 256, 256, **settings)
    expected = 2.0 * _normals(tiled) - 1.0

    def agreement(n):
        return float(((2.0 * n - 1.0)[..., :2] * expected[..., :2]).sum(-1).mean()
                     / (expected[..., :2] ** 2).sum(-1).mean())

    assert agreement(turned) > 0.7
    assert agreement(kept) < 0.5
    assert np.allclose(np.linalg.norm(2.0 * turned - 1.0, axis=-1), 1.0, atol=1e-3)


def test_same_seed_same_texture_another_seed_another(photo):
    a, b = hex_tile(photo, 64, 48, seed=2), hex_tile(photo, 64, 48, seed=2)
    assert np.array_equal(a, b)
    assert not np.array_equal(a, hex_tile(photo, 64, 48, seed=3))


@pytest.mark.parametrize("keywords, message", [
    ({"seed": -1}, "seed"), ({"scale": 0}, "scale"), ({"rotation": 2.0}, "rotation"),
    ({"contrast": -0.1}, "contrast"), ({"sharpness": 0.5}, "sharpness"),
    ({"normal": "yes"}, "normal"), ({"weight_by": np.zeros(5)}, "weight_by"),
])
def test_bad_arguments_are_refused_naming_them(photo, keywords, message):
    with pytest.raises(ValueError, match=message):
        hex_tile(photo, 32, 32, **keywords)


def test_a_grey_normal_map_is_refused(photo):
    with pytest.raises(ValueError, match="normal map needs 3 channels"):
        hex_tile(photo[:, :, :1], 32, 32, normal=True)


def test_a_hex_tiling_over_the_memory_budget_is_refused(photo, monkeypatch):
    monkeypatch.setenv("TEXSYNTH_MEMORY_BUDGET", str(1 << 20))
    with pytest.raises(ValueError, match="budget"):
        hex_tile(photo, 4096, 4096)


@pytest.mark.parametrize("channels", [1, 3])
def test_the_memory_prediction_is_within_1_5x_of_the_peak(photo, channels):
    texture = photo[:, :, :channels].copy()
    tracemalloc.start()
    hex_tile(texture, 320, 192)
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    assert peak <= predict_hex_memory(320, 192, channels) <= 1.5 * peak


def test_by_default_the_cells_keep_the_photos_direction():
    """Issue 41: turned every way, layers and courses lost their direction (anisotropy 0.22-0.44
    -> 0.02-0.03); by default a photo with a direction turns by half turns only, which keep
    it, and a square grid by quarter turns."""
    rng = np.random.default_rng(0)
    layers = gaussian_filter(rng.standard_normal((128, 128)), (1.0, 6.0), mode="wrap")
    layers = np.repeat(((layers - layers.min()) / np.ptp(layers))[:, :, None], 3, 2)
    plain = anisotropy(np.tile(layers, (2, 2, 1)))
    assert rotation_symmetry(layers) == 2
    assert 0.75 < anisotropy(hex_tile(layers, 256, 256, seed=1)) / plain < 1.33
    assert anisotropy(hex_tile(layers, 256, 256, seed=1, turns=0)) / plain < 0.5
    x = np.arange(64)
    assert rotation_symmetry(np.sin(x / 3.0)[:, None] + np.sin(x / 3.0)[None, :]) == 4

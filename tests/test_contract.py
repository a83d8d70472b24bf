"""What every registered method owes its users, checked for each entry of texsynth.methods().

A method added under texsynth/algorithms/ is held to this contract without a line added here:
the size, channels and dtype asked for; an output that tiles although the exemplar does not;
bit-identical output for a seed; the input left untouched; grey, RGB and RGBA exemplars with
constant alpha passed through and varying alpha synthesized; progress that can cancel; and a
memory estimate that is not below the peak actually allocated.
"""

import tracemalloc

import numpy as np
import pytest

import texsynth

from _images import ramp_photo, smooth_noise

METHODS = [m.name for m in texsynth.methods()]


def _exemplar(channels=3, side=40):
    """A photo that does not tile (a ramp under the noise) with two subtextures (composite)."""
    image = ramp_photo((side, side), seed=3)
    image[side // 2:, : side // 2] = 0.3 * smooth_noise((side // 2, side // 2), seed=8) + 0.7
    if channels == 1:
        return image[:, :, :1].copy()
    if channels == 4:
        return np.concatenate([image, np.full((side, side, 1), 1.0, np.float32)], axis=2)
    return image


@pytest.fixture(scope="module")
def exemplar():
    return _exemplar()


def _line_jumps(image, axis):
    """Mean absolute step between neighbouring rows (axis 0) or columns (axis 1), the last one
    across the wrap (from the last line back to the first)."""
    lum = image.mean(axis=2)
    return np.abs(lum - np.roll(lum, -1, axis=axis)).mean(axis=1 - axis)


def _wrap_is_like_the_interior(image):
    """Tiled, the image shows no seam: the step across the wrap is no larger than the largest
    step between neighbouring lines inside (with a quarter of margin), both ways."""
    return all(jumps[-1] <= 1.25 * jumps[:-1].max()
               for jumps in (_line_jumps(image, 0), _line_jumps(image, 1)))


@pytest.mark.parametrize("method", METHODS)
def test_size_channels_dtype_and_tiling(method, exemplar):
    assert not _wrap_is_like_the_interior(exemplar)
    out = texsynth.synthesize(exemplar, 56, 44, method=method, seed=1)
    assert out.shape == (44, 56, 3) and out.dtype == np.float32 and np.isfinite(out).all()
    assert _wrap_is_like_the_interior(out)


@pytest.mark.parametrize("method", METHODS)
def test_same_seed_same_output_and_input_untouched(method, exemplar):
    before = exemplar.copy()
    a = texsynth.synthesize(exemplar, 24, 20, method=method, seed=5)
    b = texsynth.synthesize(exemplar, 24, 20, method=method, seed=5)
    c = texsynth.synthesize(exemplar, 24, 20, method=method, seed=6)
    assert np.array_equal(a, b) and not np.array_equal(a, c)
    assert np.array_equal(exemplar, before)


@pytest.mark.parametrize("method", METHODS)
@pytest.mark.parametrize("channels", [1, 4])
def test_grey_and_constant_alpha(method, channels):
    image = _exemplar(channels)
    out = texsynth.synthesize(image, 24, 20, method=method, seed=2)
    assert out.shape == (20, 24, channels)
    if channels == 4:
        assert np.all(out[:, :, 3] == np.float32(1.0))
        rgb = texsynth.synthesize(image[:, :, :3], 24, 20, method=method, seed=2)
        assert np.array_equal(out[:, :, :3], rgb)


@pytest.mark.parametrize("method", METHODS)
def test_varying_alpha_is_synthesized_within_its_range(method):
    image = _exemplar(4)
    image[:, :, 3] = 0.2 + 0.6 * smooth_noise(image.shape[:2], seed=4, channels=1)[:, :, 0]
    out = texsynth.synthesize(image, 24, 20, method=method, seed=2)
    alpha = out[:, :, 3]
    assert alpha.std() > 0.01
    assert image[:, :, 3].min() - 1e-6 <= alpha.min() and alpha.max() <= image[:, :, 3].max() + 1e-6


@pytest.mark.parametrize("method", METHODS)
def test_progress_rises_and_cancelling_stops(method, exemplar):
    seen = []
    texsynth.synthesize(exemplar, 24, 20, method=method, progress=lambda f, m: seen.append(f))
    assert seen[0] == 0.0 and seen[-1] == 1.0 and np.all(np.diff(seen) >= 0) and len(seen) > 3
    calls = []

    def cancel_after_start(fraction, message):
        calls.append(fraction)
        return len(calls) < 3

    with pytest.raises(texsynth.Cancelled):
        texsynth.synthesize(exemplar, 24, 20, method=method, progress=cancel_after_start)
    assert len(calls) == 3


@pytest.mark.parametrize("method", METHODS)
def test_memory_estimate_is_not_below_the_measured_peak(method):
    image = _exemplar(3)
    width, height = 96, 80
    record = texsynth.get_method(method)
    estimate = record.memory(image.shape, width, height, record.resolve({}))
    # one run first: lazy imports and the FFT plan cache are the process's, not the method's
    texsynth.synthesize(image, width, height, method=method, seed=0)
    tracemalloc.start()
    try:
        texsynth.synthesize(image, width, height, method=method, seed=0)
        _, peak = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    assert peak <= estimate, f"{method}: peak {peak / 2**20:.1f} MiB, estimate " \
                             f"{estimate / 2**20:.1f} MiB"

"""Steered and multidimensional histogram matching (Van De Ville et al. 2009)."""

import math

import numpy as np
import pytest
import scipy.fft as sfft

import texsynth
from texsynth.blocks.histogram import JointTarget, JointWork, TargetHistogram, match, match_joint
from texsynth.blocks.pyramid import SteerablePyramid
from texsynth.blocks.steering import Steering, steering_kernels
from texsynth.metrics import seam_ratio

from _images import smooth_noise

FAST = {"iterations": 3, "scales": 3}


@pytest.fixture
def rng():
    return np.random.default_rng(11)


def edges_image(shape=(96, 96)):
    """Oriented structure: bars at several angles plus a little noise."""
    y, x = np.mgrid[: shape[0], : shape[1]].astype(np.float32)
    img = np.zeros(shape, np.float32)
    for angle, period in ((0.3, 17), (1.2, 11), (2.4, 23)):
        img += np.sign(np.sin(2 * np.pi * (x * np.cos(angle) + y * np.sin(angle)) / period))
    return img + 0.1 * np.random.default_rng(0).standard_normal(shape).astype(np.float32)


def level_bands(image, orientations, level=0):
    pyr = SteerablePyramid(image.shape, 2, orientations)
    return pyr, np.stack(pyr.analyze(image).bands[level])


@pytest.mark.parametrize("k", range(1, 9))
def test_steering_by_an_angle_and_back_returns_the_bands(rng, k):
    steering = Steering(k)
    w = rng.standard_normal((k, 20, 30)).astype(np.float32)
    phi = rng.uniform(-7, 7, (20, 30)).astype(np.float32)
    steered = steering.steer(w, phi)
    np.testing.assert_allclose(steering.steer(steered, -phi), w, atol=2e-5)
    if k > 1:
        assert np.abs(steered - w).max() > 0.1


@pytest.mark.parametrize("k", range(1, 9))
def test_steering_kernels_solve_eq3_and_steer_mixes_with_them(rng, k):
    theta = np.linspace(-np.pi, np.pi, 97)
    phi = rng.uniform(0, 2 * np.pi, 5)
    h = steering_kernels(k, phi)                                   # (5, K, K)
    theta_k = np.pi * np.arange(k) / k
    basis = np.cos(theta[:, None] - theta_k[None, :]) ** (k - 1)  # (angle, k)
    turned = np.cos(theta[None, :, None] - phi[:, None, None] - theta_k) ** (k - 1)
    np.testing.assert_allclose(np.einsum("pmk,ak->pam", h, basis), turned, atol=1e-10)
    w = rng.standard_normal((k, 5)).astype(np.float32)
    np.testing.assert_allclose(Steering(k).steer(w, phi.astype(np.float32)),
                               np.einsum("pmk,kp->mp", h, w), atol=1e-5)


@pytest.mark.parametrize("k", [2, 3, 4, 6])
def test_steered_band_equals_the_band_of_the_rotated_pyramid_filter(k):
    """The pyramid's own filters: (-i)^(K-1) alpha cos^(K-1)(atan2(fy, fx) - theta_m) radial."""
    image = smooth_noise((64, 48), seed=2, sigma=1.0, channels=1)[:, :, 0]
    pyr = SteerablePyramid(image.shape, 1, k)
    bands = np.stack(pyr.analyze(image).bands[0])
    filters = (np.stack(pyr.band_filters[0]) / pyr.phase).real.astype(np.float64)
    radial = np.sqrt((filters ** 2).sum(axis=0))            # sum_m alpha^2 cos^2N = 1
    n = k - 1
    alpha = np.sqrt(4.0 ** n * math.factorial(n) ** 2 / (k * math.factorial(2 * n)))
    fy = np.fft.fftfreq(image.shape[0])[:, None]
    fx = np.fft.rfftfreq(image.shape[1])[None, :]
    angle = np.arctan2(fy + 0 * fx, fx + 0 * fy)
    np.testing.assert_allclose(alpha * np.cos(angle) ** n * radial, filters[0], atol=1e-6)
    spectrum = sfft.rfft2(image) * pyr.lo0
    for phi in (0.4, 2.0, -1.1):
        turned = alpha * np.cos(angle - phi) ** n * radial * pyr.phase
        band = sfft.irfft2(spectrum * turned, s=image.shape)
        steered = Steering(k).steer(bands, np.float32(phi))[0]
        assert np.abs(steered - band).max() < 1e-5 * np.abs(band).max()


@pytest.mark.parametrize("k", [2, 3, 4, 5, 8])
def test_steered_first_channel_is_the_maximum_over_a_dense_sweep(k):
    steering = Steering(k)
    _, bands = level_bands(edges_image(), k)
    w = bands.reshape(k, -1)
    theta = steering.optimal_angle(w)
    top = steering.steer(w, theta)[0]
    sweep = np.linspace(0, 2 * np.pi, 1440, endpoint=False, dtype=np.float32)
    best = np.max([steering.response(w, np.full(w.shape[1], p, np.float32)) for p in sweep],
                  axis=0)
    scale = np.abs(w).max()
    assert np.all(top >= best - 1e-4 * scale - 0.05 * np.abs(best))   # never far below
    exact = top >= best - 1e-4 * scale                                  # sweep spacing: 0.25 deg
    if k <= 3:                                                          # closed form
        assert exact.all()
    else:                                          # nearest peak can lose a near tie
        assert exact.mean() > 0.99
    if k % 2 == 0:
        assert top.min() >= -1e-6 * scale and theta.max() < 2 * np.pi
    else:
        assert theta.max() < np.pi
    assert theta.min() >= 0


def test_two_orientations_leave_nothing_in_the_second_steered_channel(rng):
    steering = Steering(2)
    _, bands = level_bands(edges_image(), 2)
    steered = steering.steer(bands, steering.optimal_angle(bands))
    assert np.abs(steered[1]).max() < 1e-5 * np.abs(bands).max()
    np.testing.assert_allclose(steered[0], np.hypot(bands[0], bands[1]), rtol=1e-4, atol=1e-7)


def ring(rng, n):
    t = rng.uniform(0, 2 * np.pi, n)
    radius = 1 + 0.1 * rng.standard_normal(n)
    return np.stack([radius * np.cos(t), radius * np.sin(t)]).astype(np.float32)


def joint_histogram(values, edges):
    return np.histogram2d(values[0], values[1], bins=[edges, edges])[0] / values.shape[1]


def test_joint_matching_reproduces_a_2d_histogram_that_marginal_matching_misses(rng):
    target = ring(rng, 40_000)
    source = rng.standard_normal((2, 30_000)).astype(np.float32)
    joint = match_joint(source, JointTarget(target, bins=50))
    marginal = np.stack([match(s, TargetHistogram(t)) for s, t in zip(source, target, strict=True)])
    edges = np.linspace(-1.5, 1.5, 13)
    expected = joint_histogram(target, edges)
    assert np.abs(joint_histogram(joint, edges) - expected).sum() < 0.05      # binning error
    assert np.abs(joint_histogram(marginal, edges) - expected).sum() > 0.5
    # the first dimension is plain 1-D matching; each marginal is the target's
    np.testing.assert_allclose(joint[0], match(source[0], TargetHistogram(target[0]), exact=True),
                               atol=1e-5)
    p = np.linspace(0.02, 0.98, 25)
    np.testing.assert_allclose(np.quantile(joint[1], p), np.quantile(target[1], p), atol=0.02)


@pytest.mark.parametrize("bins", [1, 3, 50, 1000])
def test_joint_matching_of_the_target_to_itself_keeps_it(rng, bins):
    target = np.stack([rng.laplace(size=3000), rng.standard_normal(3000),
                       rng.exponential(size=3000)]).astype(np.float32)
    target[2] += target[0] ** 2
    out = match_joint(target, JointTarget(target, bins))
    np.testing.assert_allclose(out, target, atol=1e-5)


def test_joint_matching_with_fewer_target_samples_than_cells(rng):
    """Tiny target cells (c < bins) are cut into c bins: no empty bin, no invented values."""
    target = rng.standard_normal((4, 300)).astype(np.float32)
    source = rng.standard_normal((4, 5000)).astype(np.float32)
    out = match_joint(source, JointTarget(target, bins=50))
    assert np.isfinite(out).all()
    for dim in range(4):
        assert out[dim].min() >= target[dim].min() and out[dim].max() <= target[dim].max()


def test_reused_work_arrays_give_the_same_result(rng):
    target = JointTarget(rng.laplace(size=(3, 4000)).astype(np.float32), bins=20)
    work = JointWork(5000)
    for size in (5000, 1200):
        source = rng.standard_normal((3, size)).astype(np.float32)
        reused = match_joint(source, target, work)
        np.testing.assert_array_equal(reused, match_joint(source, target))
    with pytest.raises(ValueError, match="work arrays hold 5000"):
        match_joint(rng.standard_normal((3, 6000)), target, work)


def test_joint_matching_rejects_mismatched_dimensions(rng):
    with pytest.raises(ValueError, match="dimensions"):
        match_joint(rng.standard_normal((3, 10)), JointTarget(rng.standard_normal((2, 10))))


@pytest.fixture(scope="module")
def sample():
    return smooth_noise((64, 64), seed=5, sigma=1.5)


@pytest.mark.parametrize(("steered", "joint", "k"),
                         [(True, False, 4), (False, True, 4), (True, True, 4), (True, True, 3),
                          (True, True, 2), (True, True, 1)])
def test_steered_and_joint_outputs_tile_and_repeat(sample, steered, joint, k):
    kwargs = {"steered": steered, "joint": joint, "orientations": k, **FAST}
    out = texsynth.synthesize(sample, 72, 56, method="heeger_bergen", seed=4, **kwargs)
    assert out.shape == (56, 72, 3) and out.dtype == np.float32
    assert seam_ratio(out) < 1.3
    np.testing.assert_array_equal(out, texsynth.synthesize(sample, 72, 56, seed=4, **kwargs))
    assert not np.array_equal(out, texsynth.synthesize(sample, 72, 56, seed=5, **kwargs))


def test_steering_changes_the_result_and_keeps_the_colours(sample):
    plain = texsynth.synthesize(sample, 64, 64, seed=1, **FAST)
    both = texsynth.synthesize(sample, 64, 64, seed=1, steered=True, joint=True, bins=20, **FAST)
    assert np.abs(both - plain).mean() > 0.01
    np.testing.assert_allclose(both.mean(axis=(0, 1)), sample.mean(axis=(0, 1)), atol=0.03)


def test_registry_lists_steered_joint_and_bins():
    params = {p.name: p for p in texsynth.get_method("heeger_bergen").params}
    assert (params["steered"].type, params["steered"].default) == (bool, False)
    assert (params["joint"].type, params["joint"].default) == (bool, False)
    assert (params["bins"].type, params["bins"].default) == (int, 50)
    with pytest.raises(ValueError, match="'bins' must be >= 2"):
        texsynth.synthesize(np.zeros((16, 16, 3)), 16, 16, joint=True, bins=1)

import numpy as np
import pytest

from texsynth.blocks.histogram import TargetHistogram, match


@pytest.fixture
def rng():
    return np.random.default_rng(7)


def test_exact_matching_of_equal_sizes_reproduces_the_target_values(rng):
    target = rng.laplace(size=(64, 64)).astype(np.float32)
    source = rng.standard_normal((64, 64)).astype(np.float32)
    out = match(source, TargetHistogram(target), exact=True)
    np.testing.assert_array_equal(np.sort(out, axis=None), np.sort(target, axis=None))
    # monotone: the source's order is kept
    order = np.argsort(source, axis=None, kind="stable")
    assert np.all(np.diff(out.ravel()[order]) >= 0)


def test_fast_matching_agrees_with_the_sort_based_one(rng):
    target = TargetHistogram(rng.laplace(size=(256, 256)).astype(np.float32) ** 3)
    source = rng.standard_normal((300, 200)).astype(np.float32)
    fast = match(source, target)
    exact = match(source, target, exact=True)
    w1 = np.abs(np.sort(fast, axis=None) - np.sort(exact, axis=None)).mean()
    assert w1 < 1e-3 * exact.std()
    order = np.argsort(source, axis=None, kind="stable")
    assert np.all(np.diff(fast.ravel()[order]) >= -1e-6)


def test_different_sizes_match_by_quantiles(rng):
    target_values = rng.exponential(size=10_000).astype(np.float32)
    out = match(rng.random(40_000, dtype=np.float32), TargetHistogram(target_values))
    p = np.linspace(0.01, 0.99, 25)
    np.testing.assert_allclose(np.quantile(out, p), np.quantile(target_values, p),
                               rtol=0.02, atol=0.01)
    assert out.min() >= target_values.min() and out.max() <= target_values.max()


def test_constant_source_goes_to_the_target_median():
    out = match(np.full((5, 5), 3.0), TargetHistogram(np.arange(11, dtype=np.float32)))
    assert np.all(out == 5.0)


def test_empty_target_is_refused():
    with pytest.raises(ValueError, match="empty"):
        TargetHistogram(np.array([], np.float32))

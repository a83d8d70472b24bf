import numpy as np
import pytest

from texsynth.blocks import parallel
from texsynth.blocks.histogram import SAMPLED, TargetHistogram, match, match_many, sample_step


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


def test_fast_matching_of_a_large_heavy_tailed_band_stays_close_to_the_exact_one(rng):
    """Pyramid bands are heavy-tailed (Laplacian-like): the fine bins near zero are crowded."""
    source = rng.laplace(size=(1024, 1024)).astype(np.float32)
    target = TargetHistogram(rng.laplace(size=(512, 512)).astype(np.float32) ** 3)
    fast, exact = match(source, target), match(source, target, exact=True)
    # measured 3.3e-3 (2.6e-5 counting every value, not a third): a cubed target's tails
    # turn small rank errors into large value errors
    assert np.abs(fast - exact).mean() < 5e-3 * exact.std()
    assert np.abs(fast - exact).mean() > 0  # (not the sort-based path)


@pytest.mark.parametrize("shape", [(700, 500), (1100, 1000)])  # counted whole, sampled
def test_fast_matching_does_not_depend_on_the_number_of_threads(rng, monkeypatch, shape):
    source = rng.laplace(size=shape).astype(np.float32) ** 3
    target = TargetHistogram(rng.standard_normal(10_000).astype(np.float32))
    monkeypatch.setattr(parallel, "WORKERS", 3)
    assert len(parallel.ranges(source.size)) == 3
    split = match(source, target)
    monkeypatch.setattr(parallel, "WORKERS", 1)
    np.testing.assert_array_equal(match(source, target), split)


def test_matching_in_place():
    source = np.linspace(-1.0, 1.0, 101, dtype=np.float32)
    target = TargetHistogram(np.linspace(0.0, 10.0, 11, dtype=np.float32))
    expected = match(source, target)
    assert match(source, target, out=source) is source
    np.testing.assert_array_equal(source, expected)


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


def test_large_sources_are_counted_on_a_lattice_not_on_columns():
    assert sample_step(2 * SAMPLED - 1, 1024) == 1
    for n, width in [(1 << 20, 1024), (1 << 22, 2048), (1 << 24, 4096), (3000 * 2000, 3000)]:
        k = sample_step(n, width)
        assert k >= n // SAMPLED and np.gcd(k, width) == 1
        assert n // k >= SAMPLED // 2


def test_matches_together_are_the_matches_alone(rng):
    sources = [rng.laplace(size=shape).astype(np.float32) for shape in [(300, 200), (40, 30)]]
    sources.append(np.full((50, 50), 2.0, np.float32))
    targets = [TargetHistogram(rng.standard_normal(size).astype(np.float32) ** 3)
               for size in (5000, 700, 90)]
    outs = [np.empty_like(s) for s in sources]
    match_many(sources, targets, outs)
    for source, target, out in zip(sources, targets, outs, strict=True):
        np.testing.assert_array_equal(out, match(source, target))
    assert np.all(outs[2] == targets[2].quantile(0.5))

import numpy as np
import pytest
from scipy import stats

from agents.evaluation.stats import iqm, normalized_score, stratified_bootstrap_ci, wilson_interval


def test_wilson_matches_scipy_binomtest():
    for k, n in [(0, 10), (7, 10), (198, 200), (200, 200)]:
        lo, hi = wilson_interval(k, n)
        ref = stats.binomtest(k, n).proportion_ci(0.95, method="wilson")
        assert lo == pytest.approx(ref.low, abs=1e-9) and hi == pytest.approx(ref.high, abs=1e-9)
    with pytest.raises(ValueError):
        wilson_interval(11, 10)


def test_iqm_trims_quartiles():
    assert iqm(np.arange(8.0)) == pytest.approx(np.mean([2, 3, 4, 5]))
    assert iqm(np.array([0, 0, 0, 100.0])) == pytest.approx(0.0)


def test_bootstrap_interval_contains_estimate_and_is_deterministic():
    rng = np.random.default_rng(0)
    scores = rng.normal(0.5, 0.1, size=(5, 20))
    est, lo, hi = stratified_bootstrap_ci(scores, reps=500, seed=1)
    assert lo <= est <= hi
    assert stratified_bootstrap_ci(scores, reps=500, seed=1) == (est, lo, hi)
    const = np.full((4, 3), 0.7)
    assert stratified_bootstrap_ci(const, reps=100) == pytest.approx((0.7, 0.7, 0.7))


def test_normalized_score():
    assert normalized_score(0.5, 0.0, 1.0) == 0.5
    assert np.isnan(normalized_score(0.5, 1.0, 1.0))


def test_bootstrap_iqm_fast_path_equals_the_generic_one():
    """The IQM's vectorized bootstrap gives the same estimate and interval as calling the
    statistic on each replicate."""
    rng = np.random.default_rng(3)
    for shape in [(5, 1), (4, 3), (2, 1), (9, 2)]:
        x = rng.random(shape)
        fast = stratified_bootstrap_ci(x, iqm, seed=7)
        slow = stratified_bootstrap_ci(x, lambda r: iqm(r), seed=7)
        assert np.allclose(fast, slow, rtol=0, atol=1e-12)

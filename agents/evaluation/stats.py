"""Statistics for policy evaluation: binomial confidence intervals, the
interquartile mean and stratified bootstrap intervals (the rliable method,
Agarwal et al. 2021), implemented with numpy and scipy."""

from __future__ import annotations

import numpy as np
from scipy import stats

__all__ = ["iqm", "normalized_score", "stratified_bootstrap_ci", "wilson_interval"]


def wilson_interval(successes: float, n: int, confidence: float = 0.95) -> tuple[float, float]:
    """Wilson score interval for a success rate; returns ``(low, high)`` in [0, 1].
    ``successes`` may be an effective (fractional) count, e.g. a rate measured over
    repeated episodes times the number ``n`` of distinct ones.

    ``(0.0, 1.0)`` when ``n == 0``.
    """
    if n <= 0:
        return 0.0, 1.0
    if not 0 <= successes <= n:
        raise ValueError(f"successes must be in [0, n], got {successes} of {n}")
    z = float(stats.norm.ppf(0.5 + confidence / 2))
    p = successes / n
    denom = 1 + z * z / n
    centre = (p + z * z / (2 * n)) / denom
    half = z * np.sqrt(p * (1 - p) / n + z * z / (4 * n * n)) / denom
    return max(0.0, centre - half), min(1.0, centre + half)


def iqm(x: np.ndarray) -> float:
    """Interquartile mean: the mean of the middle 50% of the values (25% trimmed
    at each end, scipy.stats.trim_mean)."""
    x = np.asarray(x, dtype=float).ravel()
    if x.size == 0:
        return float("nan")
    return float(stats.trim_mean(x, 0.25))


def stratified_bootstrap_ci(
    scores: np.ndarray,
    statistic=iqm,
    *,
    reps: int = 2000,
    confidence: float = 0.95,
    seed: int = 0,
) -> tuple[float, float, float]:
    """Point estimate and percentile interval of ``statistic`` over runs.

    ``scores`` is (n_runs, n_tasks) (e.g. training seeds x evaluation episodes
    or scenes); each bootstrap replicate resamples runs with replacement
    *within each task* (stratified), as in rliable.  Returns
    ``(estimate, low, high)``.
    """
    scores = np.asarray(scores, dtype=float)
    if scores.ndim == 1:
        scores = scores[:, None]
    n_runs, n_tasks = scores.shape
    rng = np.random.default_rng(seed)
    idx = rng.integers(0, n_runs, size=(reps, n_runs, n_tasks))
    resampled = scores[idx, np.arange(n_tasks)]  # [r, i, t] = scores[idx[r, i, t], t]
    if statistic is iqm:  # one vectorized call over the replicates (each flattened, as iqm does)
        values = stats.trim_mean(resampled.reshape(reps, -1), 0.25, axis=1)
    else:
        values = np.array([statistic(r) for r in resampled])
    alpha = (1 - confidence) / 2
    low, high = np.quantile(values, [alpha, 1 - alpha])
    return float(statistic(scores)), float(low), float(high)


def normalized_score(agent: float, random: float, oracle: float) -> float:
    """(agent - random) / (oracle - random); NaN when oracle equals random."""
    span = oracle - random
    if abs(span) < 1e-12:
        return float("nan")
    return float((agent - random) / span)

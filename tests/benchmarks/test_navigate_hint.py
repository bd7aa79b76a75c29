"""``benchmarks.navigate_hint``: the path ratio over episodes both solve, and the fragment."""

from __future__ import annotations

from benchmarks import navigate_hint


def _pol(success, path):
    return {"per_episode": {"success": success, "path_length": path}}


def test_path_ratio_counts_episodes_both_solve():
    oracle = _pol([True, True, False, True], [2.0, 4.0, 9.0, 1.0])
    pol = _pol([True, False, True, True], [3.0, 99.0, 1.0, 2.0])
    assert navigate_hint.path_ratio(pol, oracle) == (3.0 + 2.0) / (2.0 + 1.0)
    assert navigate_hint.path_ratio(_pol([False] * 4, [1.0] * 4), oracle) is None


def test_fragment_shows_success_and_path():
    rows = [
        {"split": "test", "policy": "a", "successes": 9, "episodes": 10, "distinct": 10,
         "ci95": [0.6, 0.98], "path_ratio": 1.25},
        {"split": "test", "policy": "oracle", "successes": 10, "episodes": 10, "distinct": 10,
         "ci95": [0.72, 1.0], "path_ratio": None},
    ]  # fmt: skip
    text = navigate_hint.render(
        {"policies": ["a", "oracle"], "rows": rows, "command": "python -m x", "seconds": 1.0}
    )
    assert "| test | 0.90 [0.60, 0.98], path 1.25× | 1.00 [0.72, 1.00] |" in text


def test_fragment_shows_the_iqm_over_seeds_and_each_seeds_path():
    rows = [
        {"split": "test", "policy": "a", "successes": 9, "episodes": 10, "distinct": 10,
         "ci95": [0.6, 0.98], "path_ratio": 1.25},
    ]  # fmt: skip
    seeds = [
        {"split": "test", "policy": n, "train_seed": s, "success_rate": r, "path_ratio": p}
        for n, s, r, p in (("a", 0, 0.9, 1.25), ("a1", 1, 0.8, 1.1), ("a2", 2, None, None))
    ]
    seeds[2]["success_rate"] = 0.7
    iqm = [{"split": "test", "config": "ppo+dagger", "runs": 3, "train_seeds": [0, 1, 2],
            "iqm": 0.8, "ci95": [0.7, 0.9]}]  # fmt: skip
    text = navigate_hint.render(
        {"policies": ["a"], "rows": rows, "iqm": iqm, "seeds": seeds, "command": "python -m x",
         "seconds": 1.0}
    )  # fmt: skip
    assert "`a`'s recipe over 3 training seeds (0, 1, 2)" in text
    assert "| test | 0.80 [0.70, 0.90] | 0.90 0.80 0.70 | 1.25× 1.10× – |" in text
    # Recognize (no path target): the seeds' table has no path column
    for r in (*rows, *seeds):
        r["path_ratio"] = None
    text = navigate_hint.render(
        {"policies": ["a"], "rows": rows, "iqm": iqm, "seeds": seeds, "command": "python -m x",
         "seconds": 1.0}
    )  # fmt: skip
    assert "| test | 0.80 [0.70, 0.90] | 0.90 0.80 0.70 |\n" in text and "path" not in text

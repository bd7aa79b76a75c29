"""``benchmarks.navigate_hint``: the path ratio over episodes both solve, and the fragment."""

from __future__ import annotations

import pytest

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


def _row(split, policy, k):
    return {"split": split, "policy": policy, "successes": k, "episodes": 10, "distinct": 10,
            "ci95": [0.5, 1.0], "path_ratio": None}  # fmt: skip


def test_keep_takes_rows_and_seeds_from_the_tracked_run(monkeypatch):
    """``--keep``: the named policies' rows and their configs' seeds come from the tracked
    data, in its order; other episodes, an unknown policy or a policy both played and kept
    are refused."""
    tracked = {
        "command": "python -m benchmarks.navigate_hint --episodes 10",
        "seconds": 5.0,
        "policies": ["new", "old", "hint-rule", "oracle"],
        "rows": [_row(s, p, 9) for s in ("test", "ood:lab") for p in ("new", "old", "oracle")],
        "iqm": [{"split": "test", "config": "ppo", "runs": 2, "train_seeds": [0, 1],
                 "iqm": 0.85, "ci95": [0.8, 0.9], "policies": ["old", "old1"]}],
        "seeds": [{"split": "test", "config": "ppo", "policy": p, "train_seed": i,
                   "success_rate": 0.8 + 0.1 * i, "path_ratio": None}
                  for i, p in enumerate(("old", "old1"))],
    }  # fmt: skip
    monkeypatch.setattr(navigate_hint._results, "load", lambda name: tracked)
    kept = navigate_hint._kept("navigate_hint", ["old"], 10, 0)
    assert [r["policy"] for r in kept["rows"]] == ["old", "old"] and len(kept["seeds"]) == 2
    run = {
        "command": "python -m benchmarks.navigate_hint --episodes 10 --keep old",
        "seconds": 1.0,
        "policies": ["new", "oracle"],
        "rows": [_row(s, p, 10) for s in ("test", "ood:lab") for p in ("new", "oracle")],
        "iqm": [],
        "seeds": [],
    }
    data = navigate_hint._merge(run, kept)
    assert data["policies"] == ["new", "old", "oracle"]
    assert [(r["split"], r["policy"], r["successes"]) for r in data["rows"]] == [
        ("test", "new", 10), ("test", "old", 9), ("test", "oracle", 10),
        ("ood:lab", "new", 10), ("ood:lab", "old", 9), ("ood:lab", "oracle", 10),
    ]  # fmt: skip
    text = navigate_hint.render(data)
    assert "`old`'s recipe over 2 training seeds" in text
    assert "kept from the earlier run `python -m benchmarks.navigate_hint --episodes 10`" in text
    # keeping again from that merged data names the run that played them
    monkeypatch.setattr(navigate_hint._results, "load", lambda name: data)
    again = navigate_hint._kept("navigate_hint", ["old"], 10, 0)
    assert again["from"]["command"] == tracked["command"]
    monkeypatch.setattr(navigate_hint._results, "load", lambda name: tracked)
    with pytest.raises(ValueError, match="played 10 episodes from seed 0"):
        navigate_hint._kept("navigate_hint", ["old"], 100, 0)
    with pytest.raises(ValueError, match="no policy nope"):
        navigate_hint._kept("navigate_hint", ["nope"], 10, 0)
    with pytest.raises(ValueError, match="both played in this run and kept"):
        navigate_hint._merge({**run, "policies": ["old", "oracle"]}, kept)

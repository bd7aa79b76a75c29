"""Consecutive ``sensorplan evaluate`` runs with the default output folder never overwrite
each other: the second run writes to ``<default>.2``."""

from __future__ import annotations

import json

from agents.evaluation.evaluate import evaluate, fresh_dir


def test_fresh_dir_counts_up(tmp_path):
    base = tmp_path / "eval_navigate_s0"
    assert fresh_dir(base) == base
    base.mkdir()
    assert fresh_dir(base) == tmp_path / "eval_navigate_s0.2"
    (tmp_path / "eval_navigate_s0.2").mkdir()
    assert fresh_dir(base) == tmp_path / "eval_navigate_s0.3"


def test_consecutive_evaluate_runs_get_distinct_folders(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    kw = dict(episodes=1, seed=0, plot=False, verbose=False)
    first = evaluate("sensorplan/Placement-v0", ["random"], **kw)
    second = evaluate(
        "sensorplan/Placement-v0", ["random"], seed=0, episodes=2, plot=False, verbose=False
    )
    d1 = tmp_path / "runs" / "eval_placement_s0"
    d2 = tmp_path / "runs" / "eval_placement_s0.2"
    assert first["files"]["json"] == str(d1.relative_to(tmp_path) / "results.json")
    assert second["files"]["json"] == str(d2.relative_to(tmp_path) / "results.json")
    assert json.loads((d1 / "results.json").read_text())["episodes"] == 1
    assert json.loads((d2 / "results.json").read_text())["episodes"] == 2

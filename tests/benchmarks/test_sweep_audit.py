"""``benchmarks.sweep_audit``: the dense-in-time audit finds the shadow the sweep missed on fuzz
seed 202333 (mixed 5.2) while a trace of another configuration stood in for a continuation,
and none on the sweep as it is; its table counts by width."""

from __future__ import annotations

import json

from benchmarks import sweep_audit
from geometry._sweep import wedges as W
from geometry._sweep.cover import Coverage
from tests.geometry.test_sweep_events import _scene


def test_the_audit_finds_the_miss_only_where_any_holder_stood_in(monkeypatch):
    monkeypatch.setattr(W, "WEDGE_RULE", True)
    scene = _scene("fuzz:202333")
    assert sweep_audit.widest_miss(scene, "recognizable", 41) <= 1e-5
    monkeypatch.setattr(
        Coverage, "_unheld", lambda self, todo, q0, dq: [(e, t) for e, t, hs in todo if not hs]
    )
    assert sweep_audit.widest_miss(_scene("fuzz:202333"), "recognizable", 41) > 1e-3


def test_runs_and_renders(tmp_path):
    sweep_audit.main(["--n", "2", "--seed", "202333", "--times", "9", "--out", str(tmp_path)])
    data = json.loads((tmp_path / "sweep_audit.json").read_text())
    assert data["seeds"] == [202333, 202334] and data["times"] == 9
    assert data["queries"] == 3 and sum(data["counts"]["recognizable"]) == 1
    md = (tmp_path / "sweep_audit.md").read_text()
    assert md == sweep_audit.render(data)
    assert "| recognizable | 1 |" in md and "No miss wider than `tol`." in md


def test_summary_keeps_the_misses_and_the_failures():
    rows = [
        {"seed": 1, "query": "swept", "widest": 2e-3, "seconds": 1.0},
        {"seed": 2, "query": "swept", "widest": 1e-9, "seconds": 1.0},
        {"seed": 3, "query": "recognizable", "widest": 5e-5, "seconds": 1.0},
        {"seed": 4, "query": "swept", "widest": None, "error": "E: x", "seconds": 1.5},
    ]
    data = {"seeds": [1, 4], "times": 41, **sweep_audit.summarize(rows)}
    assert data["counts"] == {"swept": [1, 0, 0, 0, 1], "recognizable": [0, 0, 0, 1, 0]}
    assert [r["seed"] for r in data["misses"]] == [1, 3] and data["seconds"] == 4.5
    md = sweep_audit.render(data)
    assert "Wider than `tol`: seed 1 swept (0.002)." in md
    assert "Queries that failed: seed 4 swept (E: x)." in md

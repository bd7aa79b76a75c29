"""The reference-results grid (benchmarks.reference): its commands are valid ``sensorplan
train`` commands that name their own run folders, and the report computes the IQM,
intervals and normalized scores from benchmark results."""

from __future__ import annotations

import json
import shlex

import pytest

pytest.importorskip("yaml")

from agents.cli import _hp_overrides, build_parser  # noqa: E402
from benchmarks import reference  # noqa: E402


def test_grid_commands_parse_and_match_their_entries():
    parser = build_parser()
    seen, outs = set(), set()
    for e in reference.GRID:
        args = parser.parse_args(shlex.split(e.command(3))[1:])
        assert args.env == e.env_id and args.algo == e.algo and args.seed == 3
        assert args.timesteps == e.timesteps and args.out == str(e.out(3))
        assert args.env_kwargs == e.env_kwargs
        if e.hp:
            assert _hp_overrides(args.hp) == e.hp
        assert (e.key, e.env_id) not in seen
        seen.add((e.key, e.env_id))
        assert str(e.out(3)) not in outs  # every entry trains into its own folders
        outs.add(str(e.out(3)))
        assert e.discrete == (e.env_kwargs.get("action_type") == "discrete")


def test_report_tabulates_iqm_and_normalized_score(tmp_path, monkeypatch):
    monkeypatch.setattr(reference, "OUT", tmp_path)
    monkeypatch.setattr(reference, "RUNS", tmp_path / "runs")
    entry = next(e for e in reference.GRID if e.name == "ppo" and e.env_id == reference.PLACE)
    rates = [0.8, 0.9, 1.0, 0.7]

    def pol(kind, spec, sr):
        return {"kind": kind, "spec": spec, "success_rate": sr, "mean_path_length": 0.0}

    split = {
        "policies": [pol("oracle", "oracle", 1.0), pol("random", "random", 0.2)]
        + [pol("model", str(entry.out(s) / "best_model.zip"), r) for s, r in enumerate(rates)]
    }
    d = tmp_path / "Placement-v0"
    d.mkdir()
    (d / "benchmark.json").write_text(json.dumps({"splits": {"test": split}}))
    text = reference.report()
    row = next(line for line in text.splitlines() if line.startswith("| PPO |"))
    cells = [c.strip() for c in row.strip("|").split("|")]
    assert cells[1] == "4" and cells[2] == "—"  # no training record in this fake
    # IQM of 4 runs = mean of the middle two (0.8, 0.9)
    assert cells[3].startswith("0.85 [")
    # normalized (x - 0.2) / 0.8 -> IQM of the middle two = (0.75 + 0.875) / 2
    assert cells[4].startswith("0.81 [")
    assert "| oracle | — | — | 1.00 | 1.00 |" in text


def test_report_merges_incremental_evaluations(tmp_path, monkeypatch):
    """``evaluate --only/--new`` writes models-<entry>/benchmark.json beside the full
    evaluation; the report adds its models and a newer result replaces an older one."""
    import os

    monkeypatch.setattr(reference, "OUT", tmp_path)
    monkeypatch.setattr(reference, "RUNS", tmp_path / "runs")
    ppo = next(e for e in reference.GRID if e.name == "ppo" and e.env_id == reference.PLACE)
    sac = next(e for e in reference.GRID if e.name == "sac" and e.env_id == reference.PLACE)

    def pol(kind, spec, sr):
        return {"kind": kind, "spec": spec, "success_rate": sr, "mean_path_length": 0.0}

    def spec(e, s):
        return str(e.out(s) / "best_model.zip")

    full = {
        "policies": [pol("oracle", "oracle", 1.0), pol("random", "random", 0.2)]
        + [pol("model", spec(ppo, s), 0.5) for s in range(2)]
    }
    d = tmp_path / "Placement-v0"
    (d / "models-sac").mkdir(parents=True)
    (d / "benchmark.json").write_text(json.dumps({"splits": {"test": full}}))
    newer = {"policies": [pol("model", spec(sac, s), 0.9) for s in range(3)]}
    newer["policies"].append(pol("model", spec(ppo, 1), 0.7))  # re-evaluated: replaces 0.5
    f = d / "models-sac" / "benchmark.json"
    f.write_text(json.dumps({"splits": {"test": newer}}))
    t = (d / "benchmark.json").stat().st_mtime
    os.utime(f, (t + 10, t + 10))
    assert reference._evaluated(reference.PLACE, False) == {
        "oracle",
        "random",
        *(spec(ppo, s) for s in range(2)),
        *(spec(sac, s) for s in range(3)),
    }
    text = reference.report()
    rows = {
        line.split("|")[1].strip(): [c.strip() for c in line.strip("|").split("|")]
        for line in text.splitlines()
        if line.startswith("| ")
    }
    assert rows["SAC"][1] == "3" and rows["SAC"][3].startswith("0.90 [")
    assert rows["PPO"][1] == "2" and rows["PPO"][3].startswith("0.60 [")  # IQM of 0.5, 0.7
    assert "| oracle | — | — | 1.00 |" in text


def test_new_evaluations_never_overwrite_earlier_ones(tmp_path):
    """``evaluate --new`` run twice for one entry (seed 0, later seeds 1-4) keeps both."""
    d = reference._models_dir(tmp_path, "sac-utd1", new=True)
    assert d == tmp_path / "models-sac-utd1"
    d.mkdir()
    (d / "benchmark.json").write_text("{}")
    d2 = reference._models_dir(tmp_path, "sac-utd1", new=True)
    assert d2 == tmp_path / "models-sac-utd1.2"
    d2.mkdir()
    (d2 / "benchmark.json").write_text("{}")
    assert reference._models_dir(tmp_path, "sac-utd1", new=True).name == "models-sac-utd1.3"
    # --only without --new evaluates all the entry's models: it replaces models-<key>
    assert reference._models_dir(tmp_path, "sac-utd1", new=False) == d

"""The reference-results grid (benchmarks.reference): its commands are valid ``sensorplan
train`` commands that name their own run folders; the report computes the IQM, intervals and
normalized scores from the per-run result files alone, and the tracked files give the
committed table; results are written atomically."""

from __future__ import annotations

import json
import shlex

import pytest

pytest.importorskip("yaml")

from agents.cli import _hp_overrides, build_parser  # noqa: E402
from benchmarks import _results, reference  # noqa: E402
from benchmarks import reference_runs as runs  # noqa: E402
from benchmarks import reference_table as table  # noqa: E402


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


def _split(rate: float, path: float = 0.0) -> dict:
    return {
        "episodes": 100,
        "successes": round(100 * rate),
        "success_rate": rate,
        "success_ci95": [0.0, 1.0],
        "mean_return": 0.0,
        "mean_steps": 1.0,
        "mean_path_length": path,
        "start_distance": None,
    }


def _write(path, rec):
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(json.dumps(rec))


def test_report_tabulates_iqm_and_normalized_score_from_run_files(tmp_path):
    entry = next(e for e in reference.GRID if e.key == "ppo" and e.env_id == reference.NAV)
    _write(
        table.baseline_file(tmp_path, reference.NAV, "oracle"),
        {"splits": {"test": _split(1.0, 2.0), "train": _split(1.0, 2.0)}},
    )
    _write(
        table.baseline_file(tmp_path, reference.NAV, "random"),
        {"splits": {"test": _split(0.2, 8.0), "train": _split(0.1, 8.0)}},
    )
    rates = [0.8, 0.9, 1.0, 0.7]
    for s, r in enumerate(rates):
        _write(
            table.run_file(tmp_path, reference.NAV, entry.key, s),
            {
                "train_time_s": 60.0 * (s + 1),
                "splits": {"test": _split(r, 3.0 + s), "ood:lab": _split(1.0)},
            },
        )
    text = reference.report(tmp_path)
    row = next(line for line in text.splitlines() if line.startswith("| PPO |"))
    cells = [c.strip() for c in row.strip("|").split("|")]
    # splits: train, test, then the ood ones; the entry has no train result
    assert "| agent | seeds | train time / seed | train | test | ood:lab |" in text
    assert cells[1] == "4" and cells[2] == "2.5 min"  # median of 1, 2, 3, 4 min
    assert cells[3] == "—"
    assert cells[4].startswith("0.85 [")  # IQM of 4 runs = mean of the middle two (0.8, 0.9)
    assert cells[5] == "1.00 [1.00, 1.00]"
    # normalized (x - 0.2) / 0.8 -> IQM of the middle two = (0.75 + 0.875) / 2
    assert cells[6].startswith("0.81 [")
    assert cells[7] == "2.25 (median of seeds)"  # median path 4.5 over the oracle's 2.0
    assert "| oracle | — | — | 1.00 | 1.00 | nan | 1.00 | 1.00 |" in text
    assert "| random | — | — | 0.10 | 0.20 | nan | 0.00 | 4.00 |" in text
    # one run more changes the row: the report reads the files, nothing else
    _write(table.run_file(tmp_path, reference.NAV, entry.key, 4), {"splits": {"test": _split(0.0)}})
    assert "| PPO | 5 |" in reference.report(tmp_path)


def test_tracked_run_files_give_the_committed_table():
    """``report --update-results`` from the tracked per-run files reproduces the tracked
    data and the committed page fragment exactly."""
    data = reference.report_data()
    tracked = _results.load("reference")
    assert data["envs"] == tracked["envs"]
    fragment = (_results.FRAGMENT_DIR / "reference.md").read_text(encoding="utf-8")
    assert _results.render("reference", {"command": tracked["command"], **data}) == fragment


def test_migration_of_the_earlier_table_is_lossless(tmp_path):
    """The earlier table data split into per-entry files gives the same table back, and a
    row that names no grid entry is an error."""
    tracked = _results.load("reference")
    files = table.migrate_table(tracked, tmp_path, reference.GRID, source="test")
    assert len(files) == sum(len(t["rows"]) for t in tracked["envs"])
    assert reference.report_data(tmp_path)["envs"] == tracked["envs"]
    # per-run files of an entry replace its migrated row
    ppo = next(e for e in reference.GRID if e.key == "ppo" and e.env_id == reference.PLACE)
    _write(table.run_file(tmp_path, ppo.env_id, ppo.key, 0), {"splits": {"test": _split(0.5)}})
    row = next(r for r in reference.report_data(tmp_path)["envs"][0]["rows"] if r["label"] == "PPO")
    assert row["seeds"] == 1 and row["success"]["test"] == {"n": 1, "est": 0.5}
    bad = {"envs": [{**tracked["envs"][0], "rows": [{"label": "nope", "baseline": False}]}]}
    with pytest.raises(ValueError, match="'nope'"):
        table.migrate_table(bad, tmp_path / "x", reference.GRID, source="test")


def test_results_are_written_atomically(tmp_path):
    f = tmp_path / "a" / "seed0.json"
    runs.write_json(f, {"x": 1})
    with pytest.raises(TypeError):
        runs.write_json(f, {"x": object()})  # fails half-way through the dump
    assert json.loads(f.read_text()) == {"x": 1}  # the old file, whole
    assert [p.name for p in f.parent.iterdir()] == ["seed0.json"]  # no temporary left


def test_install_run_replaces_unfinished_folders_only(tmp_path):
    out = tmp_path / "runs" / "ppo_placement_random_s0"
    out.mkdir(parents=True)
    (out / "evaluations.npz").write_bytes(b"left by a killed run")
    (tmp_path / "runs" / "ppo_placement_random_s0.partial").mkdir()  # a killed install
    files = {"final_model.zip": b"z", "best_model.zip": b"b", "best_model.yaml": b"y"}
    runs.install_run(out, files)
    assert sorted(p.name for p in out.iterdir()) == sorted(files)
    assert not (tmp_path / "runs" / "ppo_placement_random_s0.partial").exists()
    with pytest.raises(FileExistsError):
        runs.install_run(out, files)
    with pytest.raises(ValueError, match="final_model.zip"):
        runs.install_run(tmp_path / "other", {"best_model.zip": b"b"})


_DRIVER = """
import json, sys
from benchmarks import reference
e = reference.Entry(*json.loads(sys.argv[1]))
reference.GRID[:] = [e]
sys.exit(reference.main(sys.argv[2:]))
"""

_TINY_ARGS = [
    "ppo",
    "PPO",
    reference.PLACE,
    "ppo",
    128,
    {"scene": "random", "shaping": 1.0},
    {"n_envs": 2, "n_steps": 64, "batch_size": 64, "n_epochs": 1, "eval_freq": 100_000,
     "policy_kwargs": {"net_arch": [16]}},
]  # fmt: skip


@pytest.mark.slow
def test_a_killed_grid_restarts_with_its_unfinished_runs(tmp_path, monkeypatch, capsys):
    """``train`` killed (SIGKILL) right after its first run finished: the finished run is
    whole and kept, a rerun trains only the others and leaves no half-written folder."""
    import os
    import signal
    import subprocess
    import sys

    pytest.importorskip("stable_baselines3")
    root = str(_results.ROOT)
    env = {**os.environ, "PYTHONPATH": root + os.pathsep + os.environ.get("PYTHONPATH", "")}
    monkeypatch.chdir(tmp_path)
    (tmp_path / "driver.py").write_text(_DRIVER)
    argv = [json.dumps(_TINY_ARGS), "train", "--seeds", "0", "1", "2"]
    p = subprocess.Popen(
        [sys.executable, "driver.py", *argv],
        cwd=tmp_path,
        env=env,
        stdout=subprocess.PIPE,
        stderr=subprocess.DEVNULL,
        text=True,
    )
    try:
        for line in p.stdout:
            if line.startswith("trained runs/ppo_placement_random_s0"):
                os.kill(p.pid, signal.SIGKILL)
                break
    finally:
        p.kill()
        p.wait()
    assert p.returncode == -signal.SIGKILL
    tiny = reference.Entry(*_TINY_ARGS)
    finished = [s for s in range(3) if (tiny.out(s) / "final_model.zip").is_file()]
    assert 0 in finished and len(finished) < 3
    assert {f.name for f in tiny.out(0).iterdir()} >= {"best_model.zip", "best_model.yaml"}
    kept = (tiny.out(0) / "final_model.zip").stat().st_mtime_ns

    monkeypatch.setattr(reference, "GRID", [tiny])
    assert reference.main(argv[1:]) == 0
    out = capsys.readouterr().out
    k = len(finished)
    assert f"{k} runs finished before, {3 - k} trained now, 0 failed" in out
    assert all((tiny.out(s) / "final_model.zip").is_file() for s in range(3))
    assert (tiny.out(0) / "final_model.zip").stat().st_mtime_ns == kept
    assert not list((tmp_path / "runs").glob("*.partial"))


def test_import_of_earlier_evaluations(tmp_path, monkeypatch):
    """The evaluations of earlier versions (runs/reference/<Env>/benchmark.json and the
    incremental models-<entry>/benchmark.json) become per-run files; a newer file's result
    of a model replaces an older one's, as the earlier report merged them."""
    import os

    monkeypatch.chdir(tmp_path)
    ppo = next(e for e in reference.GRID if e.key == "ppo" and e.env_id == reference.PLACE)
    sac = next(e for e in reference.GRID if e.key == "sac" and e.env_id == reference.PLACE)

    def pol(kind, spec, sr):
        return {"kind": kind, "spec": spec, **_split(sr)}

    def spec(e, s):
        return str(e.out(s) / "best_model.zip")

    def bench(policies):
        return {"episodes": 100, "seed": 0, "difficulty": {"min_start_distance": None},
                "splits": {"test": {"policies": policies, "start_distance": None}}}  # fmt: skip

    old = tmp_path / "runs" / "reference" / "Placement-v0"
    (old / "models-sac").mkdir(parents=True)
    full = [pol("oracle", "oracle", 1.0), pol("random", "random", 0.2)]
    full += [pol("model", spec(ppo, s), 0.5) for s in range(2)]
    (old / "benchmark.json").write_text(json.dumps(bench(full)))
    newer = [pol("model", spec(sac, s), 0.9) for s in range(3)]
    newer.append(pol("model", spec(ppo, 1), 0.7))  # evaluated again: replaces 0.5
    f = old / "models-sac" / "benchmark.json"
    f.write_text(json.dumps(bench(newer)))
    t = (old / "benchmark.json").stat().st_mtime
    os.utime(f, (t + 10, t + 10))
    res = tmp_path / "res"
    assert reference.main(["import", str(old.parent), "--results", str(res)]) == 0
    assert json.loads(table.run_file(res, ppo.env_id, "ppo", 1).read_text())["seed"] == 1
    text = reference.report(res)
    rows = {
        line.split("|")[1].strip(): [c.strip() for c in line.strip("|").split("|")]
        for line in text.splitlines()
        if line.startswith("| ")
    }
    assert rows["SAC"][1] == "3" and rows["SAC"][3].startswith("0.90 [")
    assert rows["PPO"][1] == "2" and rows["PPO"][3].startswith("0.60 [")  # IQM of 0.5, 0.7
    assert "| oracle | — | — | 1.00 |" in text and "| random | — | — | 0.20 |" in text

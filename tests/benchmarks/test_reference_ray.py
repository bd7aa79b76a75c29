"""The reference grid on Ray (issue 22 item 5): a tiny grid (1 algorithm, 1 env, 2 seeds, 128
training steps) trains and evaluates as Ray tasks on a local ``ray.init(num_cpus=2)`` through
``python -m benchmarks.reference``'s own entry point, the report is regenerated from the
per-run files alone, a second run does nothing, a deleted result or an unfinished run is
redone alone, and the Ray cells give the same numbers as the in-process ones and as a second
driver attached to the running instance with ``--address`` (the existing-cluster path).  Skipped
without the ``multi`` extra (Ray) or the ``rl`` extra."""

from __future__ import annotations

import json

import pytest

ray = pytest.importorskip("ray")
pytest.importorskip("stable_baselines3")
pytest.importorskip("yaml")

from benchmarks import reference  # noqa: E402
from benchmarks.reference_table import baseline_file, run_file  # noqa: E402

TINY = reference.Entry(
    "ppo",
    "PPO",
    reference.PLACE,
    "ppo",
    128,
    {"scene": "random", "shaping": 1.0},
    {
        "n_envs": 2,
        "n_steps": 64,
        "batch_size": 64,
        "n_epochs": 1,
        "eval_freq": 100_000,
        "n_eval_episodes": 2,
        "policy_kwargs": {"net_arch": [16]},
    },
)


def _main(capsys, *argv: str) -> tuple[int, str]:
    rc = reference.main(list(argv))
    return rc, capsys.readouterr().out


@pytest.mark.slow
def test_tiny_grid_on_local_ray_resumes(tmp_path, monkeypatch, capsys):
    """One test, so that pytest-xdist never starts two Ray instances of this module."""
    monkeypatch.chdir(tmp_path)  # runs/ relative to here
    monkeypatch.setattr(reference, "GRID", [TINY])
    res = tmp_path / "res"
    ray_args = ["--backend", "ray", "--num-cpus", "2"]
    evaluate = ["evaluate", "--episodes", "2", "--results", str(res), *ray_args]
    started = not ray.is_initialized()
    try:
        rc, out = _main(capsys, "train", "--seeds", "0", "1", *ray_args)
        assert rc == 0, out
        assert ray.is_initialized()  # the cells ran as Ray tasks
        assert "0 runs finished before, 2 trained now, 0 failed" in out
        for s in (0, 1):
            run = TINY.out(s)
            assert (run / "final_model.zip").is_file() and (run / "best_model.yaml").is_file()
        assert not list((tmp_path / "runs").glob("*.partial"))

        rc, out = _main(capsys, *evaluate)
        assert rc == 0, out
        files = [run_file(res, TINY.env_id, "ppo", s) for s in (0, 1)]
        files += [baseline_file(res, TINY.env_id, b) for b in ("oracle", "random")]
        assert all(f.is_file() for f in files)
        first = {f: json.loads(f.read_text()) for f in files}
        rec = first[files[0]]
        want = ["train", "test", "ood:corridor", "ood:edr", "ood:lab", "ood:warehouse"]
        assert list(rec["splits"]) == want
        assert all(s["episodes"] == 2 for s in rec["splits"].values())
        assert rec["command"] == TINY.command(0) and rec["train_time_s"] > 0
        assert first[files[2]]["splits"]["test"]["success_rate"] == 1.0  # the oracle

        # the report, from the result files alone (the run folders gone)
        for s in (0, 1):
            (TINY.out(s) / "best_model.zip").rename(TINY.out(s) / "moved.zip")
        rc, out = _main(capsys, "report", "--results", str(res), "--out", "table")
        assert rc == 0
        md = (tmp_path / "table" / "reference.md").read_text()
        assert "**Placement-v0**" in md and "| PPO | 2 |" in md and "| oracle |" in md
        for s in (0, 1):
            (TINY.out(s) / "moved.zip").rename(TINY.out(s) / "best_model.zip")

        # a second run does nothing
        rc, out = _main(capsys, "train", "--seeds", "0", "1", *ray_args)
        assert rc == 0 and "2 runs finished before, 0 trained now" in out
        rc, out = _main(capsys, *evaluate)
        assert rc == 0 and "nothing new to evaluate: all 2 finished runs" in out
        stamps = {f: f.stat().st_mtime_ns for f in files}

        # a deleted result is evaluated again, alone, to the same numbers
        files[1].unlink()
        rc, out = _main(capsys, *evaluate)
        assert rc == 0 and out.count("evaluated ->") == 1 and str(files[1]) in out
        assert json.loads(files[1].read_text())["splits"] == first[files[1]]["splits"]
        assert all(f.stat().st_mtime_ns == stamps[f] for f in files if f != files[1])

        # a run killed before it finished (no final model, a half-written copy beside it)
        # is trained again, alone
        (TINY.out(1) / "final_model.zip").unlink()
        TINY.out(1).with_name(TINY.out(1).name + ".partial").mkdir()
        kept = (TINY.out(0) / "final_model.zip").stat().st_mtime_ns
        rc, out = _main(capsys, "train", "--seeds", "0", "1", *ray_args)
        assert rc == 0 and "1 runs finished before, 1 trained now, 0 failed" in out
        assert (TINY.out(1) / "final_model.zip").is_file()
        assert (TINY.out(0) / "final_model.zip").stat().st_mtime_ns == kept
        assert not list((tmp_path / "runs").glob("*.partial"))

        # the in-process backend gives the Ray cells' numbers
        local = tmp_path / "local"
        rc, out = _main(
            capsys, "evaluate", "--episodes", "2", "--results", str(local), "--seeds", "0"
        )
        assert rc == 0
        got = json.loads(run_file(local, TINY.env_id, "ppo", 0).read_text())
        assert got["splits"] == first[files[0]]["splits"]
        oracle = json.loads(baseline_file(local, TINY.env_id, "oracle").read_text())
        assert oracle["splits"] == first[files[2]]["splits"]

        # the same cells against an existing cluster: a separate driver process attaches
        # with --address and ships this checkout with --working-dir
        _attached_evaluation_matches(tmp_path, first[files[0]]["splits"])
    finally:
        if started:
            ray.shutdown()


_DRIVER = """
import json, sys
from benchmarks import reference
reference.GRID[:] = [reference.Entry(*json.loads(sys.argv[1]))]
sys.exit(reference.main(sys.argv[2:]))
"""


def _attached_evaluation_matches(tmp_path, want):
    import dataclasses
    import os
    import subprocess
    import sys

    from benchmarks import _results

    address = ray.get_runtime_context().gcs_address
    (tmp_path / "driver.py").write_text(_DRIVER)
    entry = [getattr(TINY, f.name) for f in dataclasses.fields(TINY)]
    root = str(_results.ROOT)
    env = {**os.environ, "PYTHONPATH": root + os.pathsep + os.environ.get("PYTHONPATH", "")}
    argv = ["evaluate", "--episodes", "2", "--seeds", "0", "--results", "attached"]
    argv += ["--backend", "ray", "--address", address, "--working-dir", root]
    r = subprocess.run(
        [sys.executable, "driver.py", json.dumps(entry), *argv],
        cwd=tmp_path,
        env=env,
        capture_output=True,
        text=True,
        timeout=900,  # minutes on a loaded 2-core machine (108 s alone)
    )
    assert r.returncode == 0, r.stdout[-2000:] + r.stderr[-2000:]
    got = json.loads(run_file(tmp_path / "attached", TINY.env_id, "ppo", 0).read_text())
    assert got["splits"] == want

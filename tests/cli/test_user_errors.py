"""What a user hands the command lines is checked before any work starts, and a mistake gets
one clear line (issue 24, newcomer fixes): unwritable output paths, bad policy paths (all of
them, before any episode, leaving no empty folder), a missing ``multi`` extra, a relative
RLlib checkpoint path, and a reference grid with nothing to evaluate or report."""

from __future__ import annotations

import os
import sys
from pathlib import Path

import pytest

from agents.checks import absolute_path, check_writable_dir, check_writable_file
from agents.cli import main

ENV = "sensorplan/Placement-v0"


@pytest.fixture
def blocked(tmp_path) -> Path:
    """An --out below a regular file: can never be created."""
    f = tmp_path / "a_file"
    f.write_text("x")
    return f / "run"


# ---- agents.checks -------------------------------------------------------------------------


def test_check_writable_dir(tmp_path, blocked, monkeypatch):
    assert check_writable_dir(tmp_path / "new" / "deeper") == tmp_path / "new" / "deeper"
    assert not (tmp_path / "new").exists()  # creates nothing
    with pytest.raises(ValueError, match="is a file, not a folder"):
        check_writable_dir(blocked)
    with pytest.raises(ValueError, match="exists and is not a folder"):
        check_writable_dir(blocked.parent)
    # a folder without write permission (faked: the tests may run as root)
    real = os.access
    monkeypatch.setattr(os, "access", lambda p, m: False if Path(p) == tmp_path else real(p, m))
    with pytest.raises(ValueError, match=r"--out .*new.* is not writable .*permission denied"):
        check_writable_dir(tmp_path / "new")


def test_check_writable_file(tmp_path, blocked):
    assert check_writable_file(tmp_path / "sub" / "x.json") == tmp_path / "sub" / "x.json"
    with pytest.raises(ValueError, match="is a folder, not a file"):
        check_writable_file(tmp_path, what="--json")
    with pytest.raises(ValueError, match="is a file, not a folder"):
        check_writable_file(blocked / "x.json")


def test_absolute_path(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    assert absolute_path("runs/x/checkpoint") == tmp_path / "runs" / "x" / "checkpoint"
    assert absolute_path("~").is_absolute()


# ---- unwritable --out ----------------------------------------------------------------------


@pytest.mark.parametrize(
    "argv",
    [
        ["evaluate", "--env", ENV, "--policies", "random", "--episodes", "1"],
        ["benchmark", "--env", ENV, "--policies", "random", "--episodes", "1"],
        ["record", "--policy", "random", "--max-steps", "2"],
    ],
    ids=["evaluate", "benchmark", "record"],
)
def test_unwritable_out_is_one_clear_line(argv, blocked, capsys):
    rc = main([*argv, "--out", str(blocked)])
    err = capsys.readouterr().err
    assert rc == 2
    assert err.startswith(f"sensorplan {argv[0]}: error: --out ")
    assert str(blocked) in err and "not a folder" in err
    assert "Traceback" not in err and err.count("\n") == 1


def test_train_checks_its_out_before_training(blocked, capsys):
    pytest.importorskip("stable_baselines3")
    rc = main(
        ["train", "--env", ENV, "--algo", "ppo", "--timesteps", "8", "--out", str(blocked),
         "--no-progress", "--no-tensorboard"]
    )  # fmt: skip
    err = capsys.readouterr().err
    assert rc == 2 and "sensorplan train: error: --out" in err and "Traceback" not in err


# ---- every policy path checked before any episode ------------------------------------------


@pytest.mark.parametrize("command", ["evaluate", "benchmark"])
def test_every_policy_is_checked_before_any_episode(command, tmp_path, capsys):
    notzip = tmp_path / "model.zip"
    notzip.write_text("not a zip")
    out = tmp_path / "out"
    rc = main(
        [command, "--env", ENV, "--episodes", "1", "--out", str(out), "--policies",
         "random", str(tmp_path / "missing.zip"), str(notzip)]
    )  # fmt: skip
    cap = capsys.readouterr()
    assert rc == 2
    assert "missing.zip" in cap.err and "is not a zip archive" in cap.err
    assert "success" not in cap.out  # no policy played an episode
    assert not out.exists()  # and no empty folder is left behind


def test_a_missing_model_zip_is_a_file_not_found(tmp_path):
    from agents.evaluation.evaluate import evaluate

    with pytest.raises(FileNotFoundError, match="nothing.zip"):
        evaluate(ENV, ["random", str(tmp_path / "nothing.zip")], episodes=1, out=tmp_path / "o")
    assert not (tmp_path / "o").exists()


# ---- the multi extra -----------------------------------------------------------------------


@pytest.mark.parametrize(
    "argv",
    [
        ["train", "--backend", "rllib", "--iterations", "1"],
        ["evaluate", "--env", ENV, "--policies", "random", "--episodes", "1", "--backend", "ray"],
    ],
    ids=["train-rllib", "evaluate-ray"],
)
def test_missing_multi_extra_gives_the_install_hint(argv, monkeypatch, capsys, tmp_path):
    monkeypatch.setitem(sys.modules, "ray", None)  # import ray now raises ImportError
    rc = main([*argv, "--out", str(tmp_path / "out")])
    err = capsys.readouterr().err
    assert rc == 2
    assert "the Python module 'ray' is missing" in err and 'pip install -e ".[multi]"' in err
    assert "Traceback" not in err and err.count("\n") == 1


def test_watch_evaluation_without_ray_gives_the_install_hint(monkeypatch, capsys):
    from agents.evaluation import watch

    monkeypatch.setitem(sys.modules, "ray", None)
    rc = watch.main(["--scenes", "edr", "--watchers", "1", "--episodes", "1", "--backend", "ray"])
    err = capsys.readouterr().err
    assert rc == 2 and 'pip install -e ".[multi]"' in err and "Traceback" not in err


def test_rllib_module_main_without_ray_gives_the_install_hint(monkeypatch, capsys, tmp_path):
    from agents.learning import rllib_train

    monkeypatch.setitem(sys.modules, "ray", None)
    rc = rllib_train.main(["--iterations", "1", "--out", str(tmp_path / "o")])
    err = capsys.readouterr().err
    assert rc == 2 and 'pip install -e ".[multi]"' in err


# ---- relative RLlib checkpoint paths -------------------------------------------------------


def test_rllib_policy_resolves_a_relative_checkpoint(tmp_path, monkeypatch):
    """RLlib/pyarrow read a bare relative path as a URI ('URI has empty scheme'): the policy
    holds the absolute path (tests/evaluation/test_watch_ray.py plays a real one)."""
    from agents.learning.rllib_train import MODULE_ID, RLlibWatchPolicy

    mod = tmp_path / "runs" / "x" / "checkpoint" / "learner_group" / "learner" / "rl_module"
    (mod / MODULE_ID).mkdir(parents=True)
    monkeypatch.chdir(tmp_path)
    policy = RLlibWatchPolicy("runs/x/checkpoint")
    assert Path(policy.path).is_absolute() and Path(policy.path) == mod / MODULE_ID
    with pytest.raises(FileNotFoundError, match="no RLlib module"):
        RLlibWatchPolicy("runs/y/checkpoint")


def test_watch_evaluation_names_a_missing_checkpoint(tmp_path, monkeypatch, capsys):
    from agents.evaluation import watch

    monkeypatch.chdir(tmp_path)
    rc = watch.main(["--scenes", "edr", "--watchers", "1", "--policy", "runs/none/checkpoint"])
    err = capsys.readouterr().err
    assert rc == 2 and "no RLlib module" in err and "Traceback" not in err


def test_watch_json_must_be_writable(blocked, capsys):
    from agents.evaluation import watch

    rc = watch.main(["--scenes", "edr", "--watchers", "1", "--json", str(blocked / "rows.json")])
    assert rc == 2 and "--json" in capsys.readouterr().err


# ---- the reference grid with nothing to do -------------------------------------------------


def test_reference_evaluate_and_report_say_when_there_is_nothing(tmp_path, monkeypatch, capsys):
    pytest.importorskip("yaml")
    from benchmarks import _results, reference

    monkeypatch.chdir(tmp_path)  # RUNS = runs/ relative to the working folder: empty here
    monkeypatch.setattr(_results, "FRAGMENT_DIR", tmp_path)
    monkeypatch.setattr(_results, "DATA_DIR", tmp_path)
    tracked = tmp_path / "reference.md"
    tracked.write_text("the tracked table\n")
    assert reference.main(["evaluate", "--episodes", "1", "--results", "res"]) == 1
    assert "nothing to evaluate: no finished run" in capsys.readouterr().out
    assert reference.main(["report", "--results", "res", "--update-results"]) == 1
    err = capsys.readouterr().err
    assert "nothing to report" in err and "left as they are" in err
    assert tracked.read_text() == "the tracked table\n"  # not overwritten by an empty table
    assert not (tmp_path / "runs").exists() and not (tmp_path / "res").exists()


def test_reference_evaluate_new_says_when_everything_has_results(tmp_path, monkeypatch, capsys):
    pytest.importorskip("yaml")
    from benchmarks import reference
    from benchmarks.reference_table import run_file

    monkeypatch.chdir(tmp_path)
    e = next(e for e in reference.GRID if e.env_id == reference.PLACE and not e.discrete)
    for f in ("best_model.zip", "final_model.zip"):
        (e.out(0)).mkdir(parents=True, exist_ok=True)
        (e.out(0) / f).write_text("")
    res = tmp_path / "res"
    run_file(res, e.env_id, e.key, 0).parent.mkdir(parents=True)
    run_file(res, e.env_id, e.key, 0).write_text("{}")
    for name in ("oracle", "random"):  # evaluated baselines (a result per split)
        (res / "Placement-v0" / f"{name}.json").write_text('{"splits": {}}')
    argv = ["evaluate", "--envs", reference.PLACE, "--only", e.key, "--results", str(res)]
    assert reference.main(argv) == 0
    assert "nothing new to evaluate: all 1 finished runs" in capsys.readouterr().out

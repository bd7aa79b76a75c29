"""Ray backends (issue 11): the Ray evaluation agrees with the local one for the same seeds,
and a tiny RLlib multi-agent PPO run (shared policy) trains, checkpoints and acts.  One local
Ray instance (``ray.init(num_cpus=2)``) for the module; skipped without the ``multi`` extra."""

from __future__ import annotations

import pytest

ray = pytest.importorskip("ray")
pytest.importorskip("pettingzoo")
pytest.importorskip("ray.rllib")


def test_ray_backends(tmp_path):
    """One test, so that pytest-xdist never starts two Ray instances side by side."""
    started = False
    if not ray.is_initialized():
        ray.init(num_cpus=2, include_dashboard=False, log_to_driver=False)
        started = True
    try:
        _watch_evaluation_matches_local()
        _gym_evaluation_matches_local()
        _rllib_shared_policy_smoke(tmp_path)
    finally:
        if started:
            ray.shutdown()


def _watch_evaluation_matches_local():
    from agents.evaluation.watch import evaluate_watch

    for policy in ("oracle", "random"):
        kw = dict(policy=policy, episodes=4, seed=3, chunk=2)
        local = evaluate_watch(["edr"], [1, 2], backend="local", **kw)
        remote = evaluate_watch(["edr"], [1, 2], backend="ray", **kw)
        for a, b in zip(local, remote, strict=True):
            assert a["per_episode"] == b["per_episode"]
            assert a["per_episode"]["seed"] == [1_000_003 + i for i in range(4)]
    assert all(r["success_rate"] == 1.0 for r in evaluate_watch(["edr"], [1], episodes=2))


def _gym_evaluation_matches_local():
    from agents.evaluation.evaluate import evaluate

    kw = dict(episodes=3, seed=1, plot=False, verbose=False)
    local = evaluate("sensorplan/Navigate-v0", ["oracle", "random"], out=False, **kw)
    remote = evaluate(
        "sensorplan/Navigate-v0", ["oracle", "random"], out=False, backend="ray", **kw
    )
    for a, b in zip(local["policies"], remote["policies"], strict=True):
        assert a["per_episode"] == b["per_episode"], a["name"]
    with pytest.raises(ValueError, match="backend"):
        evaluate("sensorplan/Navigate-v0", ["random"], out=False, backend="dask", **kw)


def _rllib_shared_policy_smoke(tmp_path):
    """``sensorplan train --backend rllib --address ADDR`` attaches to the running Ray
    instance (the existing-cluster path), trains 2 tiny iterations and checkpoints."""
    import json
    import os
    import subprocess
    import sys

    import yaml

    from agents.evaluation.watch import main as watch_main
    from agents.evaluation.watch import run_watch_episodes
    from agents.learning.rllib_train import RLlibWatchPolicy, load_config

    cfg = load_config()
    cfg["env"].update(max_steps=30, move_steps=15)
    cfg["ppo"].update(train_batch_size_per_learner=120, minibatch_size=60, num_epochs=1)
    cfg["model"]["fcnet_hiddens"] = [16]
    (tmp_path / "cfg.yaml").write_text(yaml.safe_dump(cfg))
    address = ray.get_runtime_context().gcs_address
    out = tmp_path / "run"
    cmd = [
        sys.executable,
        "-m",
        "agents.cli",
        "train",
        "--backend",
        "rllib",
        "--config",
        str(tmp_path / "cfg.yaml"),
        "--iterations",
        "2",
        "--out",
        str(out),
        "--address",
        address,
    ]
    proc = subprocess.run(cmd, capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stderr[-3000:]
    progress = [json.loads(line) for line in (out / "progress.jsonl").read_text().splitlines()]
    assert len(progress) == 2 and progress[-1]["env_steps"] >= 240
    saved = yaml.safe_load((out / "config.yaml").read_text())
    assert saved["address"] == address and saved["seed"] == 0
    cwd = os.getcwd()
    os.chdir(tmp_path)
    try:  # a relative checkpoint path, as a user types it (pyarrow once read it as a URI)
        policy = RLlibWatchPolicy("run/checkpoint")
        ep = run_watch_episodes(cfg["env"], policy, [5])
        rc = watch_main(
            ["--scenes", "edr", "--watchers", "2", "--episodes", "1",
             "--policy", "run/checkpoint", "--env-kwargs", json.dumps(cfg["env"])]
        )  # fmt: skip
    finally:
        os.chdir(cwd)
    assert rc == 0
    assert ep["seed"] == [5] and 0.0 <= ep["visible"][0] <= 1.0
    from sensorplan_gym import watch_v0

    env = watch_v0.parallel_env(**cfg["env"])
    obs, _ = env.reset(seed=0)
    acts = policy.act(obs)
    assert set(acts) == set(obs)
    for a, act in acts.items():
        assert env.action_space(a).contains(act)
    with pytest.raises(FileNotFoundError):
        RLlibWatchPolicy(tmp_path / "nothing")

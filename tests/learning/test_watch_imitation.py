"""Watchers that declare (issue 22 item 4): a tiny DAgger of the watch oracle on lab with two
watchers and the evidence observation must learn to declare right -- the untrained policy
does not -- and the saved policy acts as the trained one."""

from __future__ import annotations

import numpy as np
import pytest

pytest.importorskip("stable_baselines3")
torch = pytest.importorskip("torch")

from agents.evaluation.watch import run_watch_episodes  # noqa: E402
from agents.learning.watch_imitation import (  # noqa: E402
    WatchImitationPolicy,
    collect_watch,
    make_env,
    new_policy,
    train_watch_imitation,
)
from agents.planning.watch_expert import WatchExpert  # noqa: E402

ENV = {"scene": "lab", "n_watchers": 2}
TINY = {
    "env_kwargs": ENV,
    "placement": "both",
    "n_envs": 8,
    "policy_kwargs": {"net_arch": [64, 64], "activation_fn": "tanh"},
    "dagger": {"iterations": 4, "episodes": 8, "epochs": 15, "learning_rate": 0.002},
}
SEEDS = [1_000_000 + i for i in range(16)]


class _Untrained:
    def __init__(self, policy):
        self.policy = policy

    def act(self, obs):
        with torch.no_grad():
            x = torch.as_tensor(np.stack(list(obs.values())))
            a = self.policy._predict(x, deterministic=True).numpy().clip(-1, 1)
        return dict(zip(obs, a, strict=True))


def test_tiny_dagger_learns_to_declare(tmp_path):
    rec = train_watch_imitation(TINY, seed=0, out=tmp_path, verbose=False)
    assert [h["beta"] for h in rec["imitation"]] == [1.0, 0.5, 0.25, 0.125]
    pol = WatchImitationPolicy(tmp_path / "final_model.pt")
    assert pol.env_kwargs == {**ENV, "evidence": True}
    learned = run_watch_episodes(pol.env_kwargs, pol, SEEDS)
    fresh = new_policy(make_env(ENV), TINY["policy_kwargs"], seed=0)
    untrained = run_watch_episodes(pol.env_kwargs, _Untrained(fresh), SEEDS)
    right, base = np.mean(learned["watcher_success"]), np.mean(untrained["watcher_success"])
    assert right >= 0.85, (right, rec["imitation"])
    assert base < 0.85, base  # the test can fail: an untrained policy does not declare right
    assert np.mean(learned["visible"]) > 0.6, learned["visible"]


def test_saved_policy_acts_as_trained_and_collect_checks(tmp_path):
    cfg = {**TINY, "dagger": {"iterations": 1, "episodes": 2, "epochs": 1}}
    train_watch_imitation(cfg, seed=1, out=tmp_path, verbose=False)
    pol = WatchImitationPolicy(tmp_path / "final_model.pt")
    env = make_env(ENV)
    obs, _ = env.reset(seed=3)
    a = pol.act(obs)
    ref = torch.load(tmp_path / "final_model.pt", weights_only=False)
    assert set(a) == set(obs) and all(v.shape == (4,) for v in a.values())
    assert "state_dict" in ref
    ex = WatchExpert(env, placement="both")
    with pytest.raises(ValueError, match="beta"):
        collect_watch([env], [ex], None, [0], beta=0.5)
    with pytest.raises(ValueError, match="one expert"):
        collect_watch([env, env], [ex], None, [0, 1])
    with pytest.raises(FileNotFoundError):
        WatchImitationPolicy(tmp_path / "nope.pt")


def test_cli_imitate_watch_v0(tmp_path):
    from agents.cli import main

    tiny = (
        '{"n_envs": 1, "policy_kwargs": {"net_arch": [8]}, '
        '"dagger": {"iterations": 1, "episodes": 1, "epochs": 1}}'
    )
    args = ["imitate", "--env", "watch_v0", "--out", str(tmp_path), "--overrides", tiny]
    assert main(args) == 0
    assert (tmp_path / "final_model.pt").is_file() and (tmp_path / "final_model.yaml").is_file()
    assert main(["imitate", "--env", "watch_v0", "--method", "bc", "--out", str(tmp_path)]) == 2


def test_shipped_team_is_the_current_config_and_declares():
    """agents/pretrained/dagger_watch_lab2.pt: trained with today's config file, and on a few
    evaluation episodes every watcher declares right (the full measurement is
    benchmarks/watch_declare.py)."""
    from pathlib import Path

    from agents.learning.watch_imitation import load_config

    shipped = Path(__file__).resolve().parents[2] / "agents/pretrained/dagger_watch_lab2.pt"
    pol = WatchImitationPolicy(shipped)
    assert pol.record["config"] == load_config()
    ep = run_watch_episodes(pol.env_kwargs, pol, SEEDS[:4])
    assert np.mean(ep["watcher_success"]) == 1.0, ep

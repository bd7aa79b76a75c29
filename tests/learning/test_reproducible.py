"""The shipped policies trained on procedural scenes: they load and act, and their
training config is reproducible -- trained twice (cut to one short update so the test is
quick), it gives bit-identical weights."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("stable_baselines3")
yaml = pytest.importorskip("yaml")

import gymnasium as gym  # noqa: E402
import torch  # noqa: E402

import sensorplan_gym  # noqa: E402,F401
from agents.learning.policies import algo_class, load_policy  # noqa: E402
from agents.learning.train import train  # noqa: E402

PRETRAINED = Path(__file__).resolve().parents[2] / "agents" / "pretrained"
SHIPPED = sorted(PRETRAINED.glob("ppo_*_random.yaml"))


def test_one_shipped_policy_per_env():
    envs = {yaml.safe_load(p.read_text())["env_id"] for p in SHIPPED}
    assert envs == {"sensorplan/Navigate-v0", "sensorplan/Recognize-v0", "sensorplan/Placement-v0"}


@pytest.mark.parametrize("cfg", SHIPPED, ids=lambda p: p.stem)
def test_shipped_policy_loads_and_acts(cfg):
    rec = yaml.safe_load(cfg.read_text())
    assert rec["env_kwargs"]["scene"] == "random"
    eval_kw = {k: v for k, v in rec["env_kwargs"].items() if k not in ("shaping",)}
    eval_kw.update(scene="lab")
    env = gym.make(rec["env_id"], **eval_kw)
    policy = load_policy(str(cfg.with_suffix(".zip")), env)
    obs, _ = env.reset(seed=0)
    a, _ = policy.predict(obs, deterministic=True)
    assert env.action_space.contains(np.asarray(a, dtype=env.action_space.dtype))


@pytest.mark.slow
@pytest.mark.parametrize("cfg", SHIPPED, ids=lambda p: p.stem)
def test_shipped_config_trains_bit_identically_twice(cfg, tmp_path):
    rec = yaml.safe_load(cfg.read_text())
    hp = rec["hyperparams"]
    n_envs = int(rec["n_envs"])
    steps = n_envs * int(hp["n_steps"])  # one rollout, one epoch: the whole pipeline, briefly
    runs = [
        train(
            rec["env_id"],
            rec["algo"],
            config=cfg,
            timesteps=steps,
            seed=rec["seed"],
            out=tmp_path / name,
            hp_overrides={"n_epochs": 1, "eval_freq": 10**9},
            progress_bar=False,
            tensorboard=False,
            verbose=0,
        )
        for name in ("a", "b")
    ]
    cls = algo_class(rec["algo"])
    pa, pb = (cls.load(r["final_model"]).policy.state_dict() for r in runs)
    assert pa.keys() == pb.keys()
    assert all(torch.equal(pa[k], pb[k]) for k in pa)
    # the re-run sees what the shipped policy saw: same env kwargs and preprocessing
    again = yaml.safe_load((tmp_path / "a" / "final_model.yaml").read_text())
    for key in ("env_kwargs", "frame_stack", "normalize", "policy"):
        assert again[key] == rec[key], key
    assert (
        cls.load(runs[0]["final_model"]).observation_space
        == cls.load(str(cfg.with_suffix(".zip"))).observation_space
    )

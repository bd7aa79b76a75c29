"""The SB3 adapter of the batched vector env: same episodes as SB3's DummyVecEnv of single
envs, and PPO trained through either path ends with identical weights."""

from __future__ import annotations

import numpy as np
import pytest

pytest.importorskip("stable_baselines3")

import sensorplan_gym  # noqa: E402, F401


@pytest.mark.parametrize("env_id", ["sensorplan/Navigate-v0", "sensorplan/Recognize-v0"])
def test_batched_vecenv_equals_dummy(env_id):
    import gymnasium as gym
    from stable_baselines3.common.env_util import make_vec_env
    from stable_baselines3.common.vec_env import DummyVecEnv

    from agents.learning.vecenv import make_batched_vec_env

    kw = {"noise": 0.02, "random_start": True}
    n = 3
    a = make_batched_vec_env(env_id, n, seed=4, env_kwargs=kw)
    b = make_vec_env(lambda: gym.make(env_id, **kw), n_envs=n, seed=4, vec_env_cls=DummyVecEnv)
    assert np.array_equal(a.reset(), b.reset())
    rng = np.random.default_rng(1)
    ends = 0
    for _ in range(250):
        act = rng.uniform(-1, 1, (n, *a.action_space.shape)).astype(np.float32)
        if act.shape[1] == 4:
            act[:, 3] = np.where(rng.random(n) < 0.05, np.sign(act[:, 3]), 0.0)
        oa, ra, da, ia = a.step(act)
        ob, rb, db, ib = b.step(act)
        assert np.array_equal(oa, ob) and np.array_equal(ra, rb) and np.array_equal(da, db)
        for x, y in zip(ia, ib, strict=True):
            assert x["is_success"] == y["is_success"]
            if "terminal_observation" in y:
                ends += 1
                assert np.array_equal(x["terminal_observation"], y["terminal_observation"])
                assert x["TimeLimit.truncated"] == y["TimeLimit.truncated"]
    assert ends >= n


def test_train_batched_and_dummy_identical(tmp_path):
    pytest.importorskip("torch")
    import torch
    from stable_baselines3 import PPO

    from agents.learning.train import train

    kw = dict(
        timesteps=256,
        seed=3,
        n_envs=4,
        eval_freq=10**9,
        verbose=0,
        progress_bar=False,
        tensorboard=False,
    )
    ra = train(
        "sensorplan/Navigate-v0", "ppo", out=tmp_path / "a", vec_env="batched", config=None, **kw
    )
    rb = train("sensorplan/Navigate-v0", "ppo", out=tmp_path / "b", vec_env="dummy", **kw)
    assert ra["vec_env"] == "batched" and rb["vec_env"] == "dummy"
    pa = PPO.load(ra["final_model"]).policy.state_dict()
    pb = PPO.load(rb["final_model"]).policy.state_dict()
    assert all(torch.equal(pa[k], pb[k]) for k in pa)

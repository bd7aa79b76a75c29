"""Residual policy learning over the hint rule (agents.learning.residual)."""

from __future__ import annotations

import numpy as np
import pytest

pytest.importorskip("stable_baselines3")
pytest.importorskip("yaml")

import gymnasium as gym  # noqa: E402

import sensorplan_gym  # noqa: E402, F401
from agents.learning.residual import ResidualPolicy, ResidualVecEnv, base_controller  # noqa: E402
from agents.planning.hint_rule import HintRulePolicy  # noqa: E402

KW = {"scene": "lab", "aim_features": True, "view_hint": True, "random_start": True}


class _Zero:
    action_space = None

    def predict(self, obs, state=None, episode_start=None, deterministic=True):
        return np.zeros((*np.shape(obs)[:-1], 3), dtype=np.float32), state


def test_zero_correction_is_the_base_controller():
    """With a zero correction the residual policy and the wrapped env act as the rule."""
    from stable_baselines3.common.vec_env import DummyVecEnv

    env = gym.make("sensorplan/Navigate-v0", **KW)
    obs, _ = env.reset(seed=4)
    pol = ResidualPolicy(_Zero())
    assert np.array_equal(pol.predict(obs)[0], HintRulePolicy().predict(obs)[0])
    sent = []
    venv = DummyVecEnv([lambda: gym.make("sensorplan/Navigate-v0", **KW)])
    venv.seed(4)
    real = venv.step_async
    venv.step_async = lambda a: (sent.append(a), real(a))[1]
    wrapped = ResidualVecEnv(venv, "hint-rule", 0.5)
    o = wrapped.reset()
    wrapped.step(np.ones((1, 3), dtype=np.float32))  # a correction of +0.5 each, clipped
    want = np.clip(HintRulePolicy().predict(o)[0] + 0.5, -1, 1)
    assert np.allclose(sent[0], want)


def test_unknown_base_and_normalize_are_refused():
    with pytest.raises(ValueError, match="unknown base controller 'pid'"):
        base_controller("pid")
    from agents.learning.train import train

    with pytest.raises(ValueError, match="drop normalize"):
        train(
            "sensorplan/Navigate-v0", "ppo", timesteps=64, n_envs=2, env_kwargs=KW,
            hp_overrides={"residual": "hint-rule", "normalize": True, "n_steps": 32},
            tensorboard=False, progress_bar=False, verbose=0,
        )  # fmt: skip


def test_trained_residual_model_is_played_over_the_rule(tmp_path):
    """``sensorplan train --hp residual=hint-rule`` records the base in the config, and
    ``load_policy`` plays the model as a :class:`ResidualPolicy`."""
    from agents.learning.policies import load_policy
    from agents.learning.train import train

    train(
        "sensorplan/Navigate-v0", "ppo", timesteps=256, n_envs=4, env_kwargs=KW,
        hp_overrides={"residual": "hint-rule", "n_steps": 32, "batch_size": 64},
        out=tmp_path, eval_freq=10**9, tensorboard=False, progress_bar=False, verbose=0,
    )  # fmt: skip
    env = gym.make("sensorplan/Navigate-v0", **KW)
    pol = load_policy(str(tmp_path / "final_model.zip"), env)
    assert isinstance(pol, ResidualPolicy) and pol.scale == 0.5
    obs, _ = env.reset(seed=0)
    a, _ = pol.predict(obs)
    assert a.shape == (3,) and np.all(np.abs(a) <= 1)

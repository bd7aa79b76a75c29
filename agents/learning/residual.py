"""Residual policy learning over a fixed controller (Silver et al. 2018; Johannink et al. 2019).

The agent's action is a correction added to a base controller's: the env receives
``clip(base(obs) + scale * a, -1, 1)``.  A policy whose output starts near zero starts as the
base controller and reinforcement learning improves on it where it can.  The base controllers
are the fixed rules of :data:`agents.learning.policies.RULES` (``"hint-rule"``:
:class:`agents.planning.hint_rule.HintRulePolicy`).  ``sensorplan train ... --hp
residual=hint-rule`` trains one (the resolved config records ``residual`` and
``residual_scale``), and ``sensorplan evaluate`` / ``benchmark`` play it as
:class:`ResidualPolicy` from that config.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from stable_baselines3.common.vec_env import VecEnvWrapper

__all__ = ["RESIDUAL_SCALE", "ResidualPolicy", "ResidualVecEnv", "base_controller"]

#: how far the learned correction can move each action component (actions are in [-1, 1])
RESIDUAL_SCALE = 0.5


def base_controller(name: str) -> Any:
    """The fixed controller ``name`` (a rule of :data:`agents.learning.policies.RULES`)."""
    if name == "hint-rule":
        from ..planning.hint_rule import HintRulePolicy

        return HintRulePolicy()
    raise ValueError(f"residual: unknown base controller {name!r} (known: 'hint-rule')")


def _combine(base: np.ndarray, correction: np.ndarray, scale: float) -> np.ndarray:
    out = np.asarray(base, dtype=np.float32) + scale * np.asarray(correction, dtype=np.float32)
    return np.clip(out, -1.0, 1.0)


class ResidualVecEnv(VecEnvWrapper):
    """An SB3 vector env whose actions are corrections to ``base``'s actions (scaled by
    ``scale``); observations, rewards and spaces are the wrapped env's."""

    def __init__(self, venv, base: str = "hint-rule", scale: float = RESIDUAL_SCALE) -> None:
        super().__init__(venv)
        self.base = base_controller(base)
        self.scale = float(scale)
        self._obs: np.ndarray | None = None

    def reset(self) -> np.ndarray:
        self._obs = self.venv.reset()
        return self._obs

    def step_async(self, actions: np.ndarray) -> None:
        base, _ = self.base.predict(self._obs)
        self.venv.step_async(_combine(base, actions, self.scale))

    def step_wait(self):
        obs, rewards, dones, infos = self.venv.step_wait()
        self._obs = obs  # after an episode's end: the next episode's first observation
        return obs, rewards, dones, infos


class ResidualPolicy:
    """A trained correction ``model`` (SB3 ``predict``) played over its base controller:
    actions ``clip(base(obs) + scale * model(obs))``."""

    def __init__(self, model: Any, base: str = "hint-rule", scale: float = RESIDUAL_SCALE):
        self.model = model
        self.base = base_controller(base)
        self.scale = float(scale)
        self.action_space = getattr(model, "action_space", None)

    def predict(
        self,
        observation: np.ndarray,
        state: Any = None,
        episode_start: Any = None,
        deterministic: bool = True,
    ) -> tuple[np.ndarray, Any]:
        corr, state = self.model.predict(
            observation, state=state, episode_start=episode_start, deterministic=deterministic
        )
        base, _ = self.base.predict(observation)
        return _combine(base, corr, self.scale), state

"""A stable-baselines3 ``VecEnv`` over a native Gymnasium vector env of this package.

SB3 does not accept a Gymnasium ``VectorEnv``: it wants its own ``VecEnv`` with same-step
autoreset (the observation returned for a finished sub-env is already the next episode's first
one, the last one goes to ``info["terminal_observation"]``) and a list of info dicts.
:class:`BatchedVecEnv` provides exactly that over the batched core: after a step it resets the
finished sub-envs at once with ``reset(options={"reset_mask": done})``, which draws from each
sub-env's own generator, so sub-env ``i`` plays the same episodes as ``gym.make(id)`` seeded
with ``seed + i``.

>>> venv = make_batched_vec_env("sensorplan/Navigate-v0", n_envs=64, seed=0)  # doctest: +SKIP
>>> model = stable_baselines3.PPO("MlpPolicy", venv)  # doctest: +SKIP
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import gymnasium as gym
import numpy as np
from stable_baselines3.common.vec_env.base_vec_env import VecEnv

__all__ = ["BatchedVecEnv", "make_batched_vec_env"]


class BatchedVecEnv(VecEnv):
    """SB3 ``VecEnv`` view of a :class:`sensorplan_gym.envs.vector.SensorPlanVectorEnv`."""

    def __init__(self, venv: gym.vector.VectorEnv) -> None:
        self.venv = venv
        super().__init__(venv.num_envs, venv.single_observation_space, venv.single_action_space)
        self.render_mode = venv.render_mode
        self._actions: np.ndarray | None = None

    # ---- VecEnv API -------------------------------------------------------------------
    def reset(self) -> np.ndarray:
        seeds = list(self._seeds)
        opts = (
            self._options[0]
            if self._options and all(o == self._options[0] for o in self._options)
            else {}
        )
        obs, _ = self.venv.reset(
            seed=None if all(s is None for s in seeds) else seeds, options=opts or None
        )
        self._reset_seeds()
        self._reset_options()
        return obs

    def step_async(self, actions: np.ndarray) -> None:
        self._actions = np.asarray(actions)

    def step_wait(self):
        obs, rew, term, trunc, info = self.venv.step(self._actions)
        done = term | trunc
        infos = _split(info, self.num_envs)
        if done.any():
            for i in np.flatnonzero(done).tolist():
                infos[i]["terminal_observation"] = obs[i]
                infos[i]["TimeLimit.truncated"] = bool(trunc[i] and not term[i])
            obs = obs.copy()
            new, _ = self.venv.reset(options={"reset_mask": done})
            obs[done] = new[done]
        return obs, rew.astype(np.float32), done, infos

    def close(self) -> None:
        self.venv.close()

    def get_images(self) -> Sequence[np.ndarray | None]:
        return [self.venv.render()] + [None] * (self.num_envs - 1)

    def get_attr(self, attr_name: str, indices=None) -> list[Any]:
        idx = self._get_indices(indices)
        u = self.venv.unwrapped
        v = getattr(u, attr_name) if hasattr(u, attr_name) else getattr(u.batch, attr_name)
        return [v for _ in idx]

    def set_attr(self, attr_name: str, value: Any, indices=None) -> None:
        setattr(self.venv.unwrapped.batch, attr_name, value)

    def env_method(self, method_name: str, *method_args, indices=None, **method_kwargs) -> list:
        fn = getattr(self.venv.unwrapped, method_name)
        return [fn(*method_args, **method_kwargs) for _ in self._get_indices(indices)]

    def env_is_wrapped(self, wrapper_class, indices=None) -> list[bool]:
        return [False for _ in self._get_indices(indices)]


def _split(info: dict[str, Any], n: int) -> list[dict[str, Any]]:
    """Gymnasium's vector info (arrays with ``_key`` masks) -> one dict per sub-env."""
    out: list[dict[str, Any]] = [{} for _ in range(n)]
    for k, v in info.items():
        if k.startswith("_"):
            continue
        mask = info.get("_" + k)
        for i in range(n) if mask is None else np.flatnonzero(mask).tolist():
            x = v[i]
            out[i][k] = x.item() if isinstance(x, np.generic) else x
    return out


def make_batched_vec_env(
    env_id: str, n_envs: int, *, seed: int | None = None, env_kwargs: dict | None = None
) -> BatchedVecEnv:
    """``n_envs`` sub-envs of ``env_id`` in one batch, as an SB3 ``VecEnv``, seeded like
    SB3's ``make_vec_env`` (sub-env ``i`` with ``seed + i``)."""
    import sensorplan_gym  # noqa: F401 - registers the ids

    venv = gym.make_vec(
        env_id, num_envs=n_envs, vectorization_mode="vector_entry_point", **(env_kwargs or {})
    )
    out = BatchedVecEnv(venv)
    if seed is not None:
        out.seed(seed)
    return out

"""Native vector environments: N sub-environments of a task in one batch, one process.

``gym.make_vec(id, num_envs=N, vectorization_mode="vector_entry_point", **kwargs)`` (the
default mode for these ids) returns a :class:`SensorPlanVectorEnv` that steps all N with one
call of the task's batch class -- the same code the single env runs with N = 1 -- so
sub-environment ``i`` seeded with ``seed + i`` produces exactly what ``gym.make(id)`` seeded
with ``seed + i`` produces.

Gymnasium 1.x conventions:

* ``metadata["autoreset_mode"]`` is ``AutoresetMode.NEXT_STEP``: the step after a
  sub-environment terminated or truncated resets it (its action is ignored) and returns its
  first observation with reward 0 and ``terminated = truncated = False``;
* ``reset(seed=s)`` seeds sub-environment ``i`` with ``s + i`` (a list of N seeds is taken as
  is; ``None`` leaves the generators running); ``options={"reset_mask": mask}`` resets only
  the masked sub-environments;
* ``single_observation_space`` / ``single_action_space`` and their batched versions;
* ``info`` holds, per key, an array over sub-environments and a boolean ``_key`` mask of the
  sub-environments that reported it (e.g. ``target_in`` only at the end of an episode);
* ``render()`` draws sub-environment 0.
"""

from __future__ import annotations

from typing import Any

import gymnasium as gym
import numpy as np
from gymnasium.vector import AutoresetMode, VectorEnv
from gymnasium.vector.utils import batch_space

from ..core.rendering import HumanViewer, Renderer
from .base import SensorPlanBatch
from .navigate import NavigateBatch
from .placement import PlacementBatch
from .recognize import RecognizeBatch

__all__ = [
    "NavigateVectorEnv",
    "PlacementVectorEnv",
    "RecognizeVectorEnv",
    "SensorPlanVectorEnv",
]


class SensorPlanVectorEnv(VectorEnv):
    """``num_envs`` sub-environments of ``batch_cls`` stepped as one batch (module docstring).

    Keyword arguments are the single env's (see :mod:`sensorplan_gym.envs.base` and each
    task module), plus ``max_episode_steps`` (what ``make_vec`` passes from the registration:
    the time limit, applied by the batch itself)."""

    metadata = {
        "render_modes": ["rgb_array", "human"],
        "render_fps": 10,
        "autoreset_mode": AutoresetMode.NEXT_STEP,
    }
    batch_cls: type[SensorPlanBatch] = SensorPlanBatch

    def __init__(
        self,
        num_envs: int = 1,
        scene: str | Any = "lab",
        *,
        render_mode: str | None = None,
        max_episode_steps: int | None = None,
        **kwargs: Any,
    ) -> None:
        if not isinstance(num_envs, (int, np.integer)) or num_envs < 1:
            raise ValueError(f"num_envs must be a positive integer, got {num_envs!r}")
        if render_mode is not None and render_mode not in self.metadata["render_modes"]:
            raise ValueError(
                f"render_mode must be None or one of {self.metadata['render_modes']}, "
                f"got {render_mode!r}"
            )
        if max_episode_steps is not None and "max_steps" not in kwargs:
            kwargs["max_steps"] = int(max_episode_steps)
        self.num_envs = int(num_envs)
        self.render_mode = render_mode
        self.batch = self.batch_cls(self.num_envs, scene, **kwargs)
        self.single_observation_space = self.batch.single_observation_space
        self.single_action_space = self.batch.single_action_space
        self.observation_space = batch_space(self.single_observation_space, self.num_envs)
        self.action_space = batch_space(self.single_action_space, self.num_envs)
        self._all = np.arange(self.num_envs)
        self._autoreset = np.zeros(self.num_envs, dtype=bool)
        self._started = False
        self._renderer = Renderer() if render_mode is not None else None
        self._viewer = HumanViewer() if render_mode == "human" else None

    # ---- API --------------------------------------------------------------------------
    def reset(
        self, *, seed: int | list[int | None] | None = None, options: dict | None = None
    ) -> tuple[np.ndarray, dict[str, Any]]:
        options = dict(options or {})
        mask = options.pop("reset_mask", None)
        if mask is None:
            idx = self._all
        else:
            mask = np.asarray(mask, dtype=bool)
            if mask.shape != (self.num_envs,):
                raise ValueError(f"reset_mask must have shape ({self.num_envs},), got {mask.shape}")
            idx = np.flatnonzero(mask)
        seeds: list[int | None]
        if seed is None:
            seeds = [None] * self.num_envs
        elif isinstance(seed, (int, np.integer)):
            seeds = [int(seed) + i for i in range(self.num_envs)]
        else:
            seeds = list(seed)
            if len(seeds) != self.num_envs:
                raise ValueError(f"reset got {len(seeds)} seeds for {self.num_envs} envs")
        if seed is not None:
            self._np_random_seed = seeds[0]
        for i in idx.tolist():
            if seeds[i] is not None:
                self.batch.seed_env(i, seeds[i])
        self.batch.reset_envs(idx, options)
        self._autoreset[idx] = False
        self._started = True
        obs = self.batch.observe(self._all)
        infos = self._merge({}, self.batch.reset_info(idx), idx)
        if self.render_mode == "human":
            self.render()
        return obs, infos

    def step(self, actions) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, dict]:
        if not self._started:
            raise gym.error.ResetNeeded("call reset() before step()")
        act = self.batch.actions.to_array(actions, self.num_envs)
        n = self.num_envs
        rewards = np.zeros(n)
        terms = np.zeros(n, dtype=bool)
        truncs = np.zeros(n, dtype=bool)
        infos: dict[str, Any] = {}
        ar = self._autoreset
        run = self._all if not ar.any() else np.flatnonzero(~ar)
        if len(run):
            r, te, tr, cols = self.batch.step_envs(act[run], run)
            rewards[run], terms[run], truncs[run] = r, te, tr
            infos = self._merge(infos, cols, run)
        if ar.any():
            again = np.flatnonzero(ar)
            self.batch.reset_envs(again)
            infos = self._merge(infos, self.batch.reset_info(again), again)
        self._autoreset = terms | truncs
        obs = self.batch.observe(self._all)
        if self.render_mode == "human":
            self.render()
        return obs, rewards, terms, truncs, infos

    def render(self) -> np.ndarray | None:
        if self.render_mode is None:
            gym.logger.warn(
                "render() called without a render_mode; pass render_mode= to make_vec()"
            )
            return None
        frame = self._renderer.render(self.batch.worlds[0], self.batch.render_state(0))
        if self.render_mode == "rgb_array":
            return frame
        self._viewer.show(frame, self.metadata["render_fps"])
        return None

    def close_extras(self, **kwargs: Any) -> None:
        for part in (getattr(self, "_viewer", None), getattr(self, "_renderer", None)):
            if part is not None:
                part.close()

    # ---- info dicts -------------------------------------------------------------------
    def _merge(self, infos: dict, cols: dict, idx: np.ndarray) -> dict:
        """Write info columns of sub-environments ``idx`` into ``infos`` (arrays over all
        N with ``_key`` masks)."""
        n = self.num_envs
        if not infos and len(idx) == n:  # every sub-environment: the columns themselves
            for key, (vals, m) in cols.items():
                infos[key] = np.array(vals)  # a copy: columns may share arrays
                infos["_" + key] = np.ones(n, dtype=bool) if m is None else np.array(m)
                if m is not None and vals.dtype == object:
                    infos[key][~m] = None
                elif m is not None:
                    infos[key][~m] = 0
            return infos
        for key, (vals, m) in cols.items():
            vals = np.asarray(vals)
            if key not in infos:
                if vals.dtype == object:
                    infos[key] = np.full((n, *vals.shape[1:]), None, dtype=object)
                else:
                    infos[key] = np.zeros((n, *vals.shape[1:]), dtype=vals.dtype)
                infos["_" + key] = np.zeros(n, dtype=bool)
            sel = idx if m is None else idx[m]
            infos[key][sel] = vals if m is None else vals[m]
            infos["_" + key][sel] = True
        return infos


class PlacementVectorEnv(SensorPlanVectorEnv):
    batch_cls = PlacementBatch


class NavigateVectorEnv(SensorPlanVectorEnv):
    batch_cls = NavigateBatch


class RecognizeVectorEnv(SensorPlanVectorEnv):
    batch_cls = RecognizeBatch

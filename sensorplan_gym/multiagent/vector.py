"""``WatchVectorEnv``: ``n_envs`` copies of ``watch_v0`` as one Gymnasium vector env whose
sub-environments are the *watchers* (parameter sharing: one policy acts for every row).

Rows ``e * A .. e * A + A - 1`` are the ``A = n_watchers`` watchers of copy ``e``, so
``num_envs = n_envs * n_watchers``.  Observations, actions and rewards of a row are those of
the watcher in :class:`~.env.WatchParallelEnv` (same spaces, same values): copy ``e`` seeded
``s + e`` steps exactly as ``watch_v0.parallel_env(...)`` seeded ``s + e`` does -- both are
:class:`~.batch.WatchBatch`, of ``n_envs`` copies and of one.

Gymnasium 1.x conventions, as the single-agent vector envs (:mod:`sensorplan_gym.envs.vector`):

* ``metadata["autoreset_mode"]`` is ``NEXT_STEP``: the step after a copy's horizon resets it
  (its rows' actions are ignored; reward 0, ``terminated = truncated = False``);
* ``reset(seed=s)`` seeds copy ``e`` with ``s + e`` (a list of ``n_envs`` seeds is taken as
  is); ``options={"reset_mask": mask}`` (``(n_envs,)`` over copies) resets only those;
* ``info``: per row ``sees``, ``collided``, ``declared`` (0 none, -1 G, +1 H), and at a
  copy's horizon ``is_success``, ``a_ends_in_h`` and ``visible_fraction`` with ``_key``
  masks of the rows that report them.
"""

from __future__ import annotations

from typing import Any

import gymnasium as gym
import numpy as np
from gymnasium import spaces
from gymnasium.vector import AutoresetMode, VectorEnv
from gymnasium.vector.utils import batch_space

from .batch import DECLARE_CODES, WatchBatch

__all__ = ["WatchVectorEnv"]


class WatchVectorEnv(VectorEnv):
    """``n_envs`` copies of the watch task, one row per watcher (see the module docstring);
    keyword arguments as :class:`~.env.WatchParallelEnv` (no rendering)."""

    metadata = {"render_modes": [], "autoreset_mode": AutoresetMode.NEXT_STEP}

    def __init__(self, n_envs: int = 1, scene: Any = "lab", **kwargs: Any) -> None:
        if kwargs.pop("render_mode", None) is not None:
            raise ValueError("WatchVectorEnv does not render; use watch_v0.parallel_env")
        self.batch = WatchBatch(n_envs, scene, **kwargs)
        self.n_envs = self.batch.n_envs
        self.n_watchers = self.batch.n_watchers
        self.num_envs = self.batch.n
        self.render_mode = None
        self.single_observation_space = self.batch.single_observation_space
        self.single_action_space = spaces.Box(-1.0, 1.0, (4,), dtype=np.float32)
        self.observation_space = batch_space(self.single_observation_space, self.num_envs)
        self.action_space = batch_space(self.single_action_space, self.num_envs)
        self._all = np.arange(self.n_envs)
        self._autoreset = np.zeros(self.n_envs, dtype=bool)
        self._started = False

    def reset(
        self, *, seed: int | list[int | None] | None = None, options: dict | None = None
    ) -> tuple[np.ndarray, dict[str, Any]]:
        options = dict(options or {})
        mask = options.pop("reset_mask", None)
        E = self.n_envs
        if mask is None:
            idx = self._all
        else:
            mask = np.asarray(mask, dtype=bool)
            if mask.shape != (E,):
                raise ValueError(
                    f"reset_mask must have shape ({E},) (one per copy), got {mask.shape}"
                )
            idx = np.flatnonzero(mask)
        if seed is None:
            seeds: list[int | None] = [None] * E
        elif isinstance(seed, (int, np.integer)):
            seeds = [int(seed) + e for e in range(E)]
        else:
            seeds = list(seed)
            if len(seeds) != E:
                raise ValueError(f"reset got {len(seeds)} seeds for {E} copies")
        for e in idx.tolist():
            if seeds[e] is not None:
                self.batch.seed_env(e, seeds[e])
        self.batch.reset_envs(idx)
        self._autoreset[idx] = False
        self._started = True
        return self.batch.observe(self._all), self._infos(None)

    def step(self, actions) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, dict]:
        if not self._started:
            raise gym.error.ResetNeeded("call reset() before step()")
        b = self.batch
        act = b.check_actions(actions, self.num_envs)
        A = self.n_watchers
        rewards = np.zeros(self.num_envs)
        terms = np.zeros(self.num_envs, dtype=bool)
        truncs = np.zeros(self.num_envs, dtype=bool)
        ar = self._autoreset
        run = self._all if not ar.any() else np.flatnonzero(~ar)
        done_now = np.zeros(self.n_envs, dtype=bool)
        if len(run):
            rows = b._rows(run)
            rew, done, _ = b.step_envs(act[rows], run)
            rewards[rows] = rew.ravel()
            terms[rows] = np.repeat(done, A)
            done_now[run] = done
        if ar.any():
            b.reset_envs(np.flatnonzero(ar))
        self._autoreset = done_now
        return b.observe(self._all), rewards, terms, truncs, self._infos(done_now)

    def _infos(self, done: np.ndarray | None) -> dict[str, Any]:
        b = self.batch
        n = self.num_envs
        ones = np.ones(n, dtype=bool)
        infos: dict[str, Any] = {
            "sees": b.sees.copy(),
            "_sees": ones,
            "collided": b.collided.copy(),
            "_collided": ones,
            "declared": b.declared.ravel().copy(),
            "_declared": ones,
        }
        if done is not None and done.any():
            rows = np.repeat(done, self.n_watchers)
            t_rows = np.repeat(b.truth, self.n_watchers)
            infos["is_success"] = np.where(rows, b.declared.ravel() == t_rows, False)
            infos["a_ends_in_h"] = np.where(rows, t_rows == DECLARE_CODES["H"], False)
            infos["visible_fraction"] = np.where(rows, b.seen_steps.ravel() / b.max_steps, 0.0)
            for k in ("is_success", "a_ends_in_h", "visible_fraction"):
                infos["_" + k] = rows
        return infos

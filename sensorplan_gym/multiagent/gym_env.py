"""``sensorplan/Watch-v0``: the watch task with one watcher as a Gymnasium env.

Observation, action, reward and episode as :class:`~.env.WatchParallelEnv` with
``n_watchers=1`` (its ``watcher_0``); ``info`` is that watcher's info.  The horizon is part of
the task (``terminated`` at ``max_steps``), so the id is registered without a TimeLimit.
"""

from __future__ import annotations

from typing import Any

import gymnasium as gym

from .env import WatchParallelEnv

__all__ = ["WatchEnv"]


class WatchEnv(gym.Env):
    """One watcher; keyword arguments as :class:`WatchParallelEnv` (``n_watchers`` is 1)."""

    metadata = {"render_modes": ["rgb_array"], "render_fps": 10}

    def __init__(self, render_mode: str | None = None, **kwargs: Any) -> None:
        if kwargs.get("n_watchers", 1) != 1:
            raise ValueError(
                "sensorplan/Watch-v0 has exactly one watcher; use sensorplan_gym.watch_v0."
                f"parallel_env(n_watchers=...) for more (got n_watchers={kwargs['n_watchers']!r})"
            )
        kwargs.pop("n_watchers", None)
        self.par = WatchParallelEnv(n_watchers=1, render_mode=render_mode, **kwargs)
        self.render_mode = render_mode
        self._agent = self.par.possible_agents[0]
        self.observation_space = self.par.observation_space(self._agent)
        self.action_space = self.par.action_space(self._agent)

    def reset(self, *, seed: int | None = None, options: dict | None = None):
        super().reset(seed=seed)
        # the parallel env draws from its own generator, seeded from ours on every reset
        sub = int(self.np_random.integers(2**63 - 1))
        obs, infos = self.par.reset(seed=sub, options=options)
        return obs[self._agent], infos[self._agent]

    def step(self, action):
        obs, rew, term, trunc, infos = self.par.step({self._agent: action})
        a = self._agent
        return obs[a], rew[a], term[a], trunc[a], infos[a]

    def render(self):
        return self.par.render()

    def close(self) -> None:
        self.par.close()

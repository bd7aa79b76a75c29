"""PettingZoo entry points of the watch task, following PettingZoo's module convention::

    from sensorplan_gym import watch_v0

    env = watch_v0.parallel_env(scene="lab", n_watchers=2)   # ParallelEnv
    aec = watch_v0.env(scene="lab", n_watchers=2)            # AEC, via parallel_to_aec
    vec = watch_v0.vector_env(64, scene="lab", n_watchers=2)  # 64 copies: 128 watcher rows

See :mod:`sensorplan_gym.multiagent.env` for the task, its spaces and keyword arguments.
``env()`` needs PettingZoo (extra ``multi``); ``parallel_env()`` works without it.
"""

from __future__ import annotations

from typing import Any

from .multiagent.env import WatchParallelEnv
from .multiagent.vector import WatchVectorEnv

__all__ = ["env", "parallel_env", "vector_env"]


def parallel_env(**kwargs: Any) -> WatchParallelEnv:
    """The watch task as a ``ParallelEnv`` (keyword arguments as :class:`WatchParallelEnv`)."""
    return WatchParallelEnv(**kwargs)


def env(**kwargs: Any):
    """The AEC version: :func:`pettingzoo.utils.parallel_to_aec` of :func:`parallel_env`
    (PettingZoo's AEC wrapper with order enforcing)."""
    from pettingzoo.utils import parallel_to_aec

    return parallel_to_aec(parallel_env(**kwargs))


def vector_env(n_envs: int = 1, **kwargs: Any) -> WatchVectorEnv:
    """``n_envs`` copies of the task as one Gymnasium vector env with a row per watcher
    (:class:`~sensorplan_gym.multiagent.vector.WatchVectorEnv`; copy ``e`` seeded ``s + e``
    equals :func:`parallel_env` seeded ``s + e``)."""
    return WatchVectorEnv(n_envs, **kwargs)

"""Multi-agent sensor planning: watcher robots that keep robot A in view (paper section 1)
and tell whether A's EDR motion ended in G or in H.

* :class:`WatchParallelEnv` -- the PettingZoo ``ParallelEnv`` (``sensorplan_gym.watch_v0``);
* :class:`WatchEnv` -- the one-watcher Gymnasium env ``sensorplan/Watch-v0``;
* :mod:`.world` -- the static scene data, A's configuration space and the exact
  visibility predicate; :mod:`.motion` -- A's scripted motion; :mod:`.rendering`.
"""

from .env import REWARD_MODES, WatchParallelEnv
from .gym_env import WatchEnv

__all__ = ["REWARD_MODES", "WatchEnv", "WatchParallelEnv"]

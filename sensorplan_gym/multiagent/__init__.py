"""Multi-agent sensor planning: watcher robots that keep robot A in view (paper section 1)
and tell whether A's EDR motion ended in G or in H.

* :class:`WatchParallelEnv` -- the PettingZoo ``ParallelEnv`` (``sensorplan_gym.watch_v0``);
* :class:`WatchEnv` -- the one-watcher Gymnasium env ``sensorplan/Watch-v0``;
* :class:`WatchVectorEnv` -- many copies as one vector env, a row per watcher;
* :mod:`.batch` -- :class:`WatchBatch`, the one implementation of the task (the envs above are
  its batch of one and of many); :mod:`.kernels` -- its compiled kernels;
* :mod:`.world` -- the static scene data, A's configuration space and the exact
  visibility predicate; :mod:`.motion` -- A's scripted motion; :mod:`.rendering`.
"""

from .batch import WatchBatch
from .env import REWARD_MODES, WatchParallelEnv
from .gym_env import WatchEnv
from .vector import WatchVectorEnv

__all__ = ["REWARD_MODES", "WatchBatch", "WatchEnv", "WatchParallelEnv", "WatchVectorEnv"]

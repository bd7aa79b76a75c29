"""Gymnasium environments for robust sensor planning (Briggs & Donald).

Importing the package registers ``sensorplan/Placement-v0``, ``sensorplan/Navigate-v0`` and
``sensorplan/Recognize-v0``; ``gym.make("sensorplan_gym:sensorplan/Navigate-v0")`` works
without a prior import.  Rewards are exact: they come from
:func:`geometry.recognizable_region`.

>>> import gymnasium as gym
>>> env = gym.make("sensorplan_gym:sensorplan/Navigate-v0", scene="lab")
>>> obs, info = env.reset(seed=0)
"""

#: the version of the sensorplan-gym distribution (geometry, sensorplan_gym, agents): written
#: here only; pyproject.toml reads it, CHANGELOG.md lists what each version changed
__version__ = "0.1.0"

from .core.scenes import REAL_SCENES  # noqa: E402
from .core.world import BUNDLED_SCENES  # noqa: E402
from .registration import ENV_IDS, register_sensorplan_envs  # noqa: E402

register_sensorplan_envs()

__all__ = ["BUNDLED_SCENES", "ENV_IDS", "REAL_SCENES", "__version__", "register_sensorplan_envs"]

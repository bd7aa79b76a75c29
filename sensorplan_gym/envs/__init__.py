"""The three environments; see each module's docstring for spaces and rewards."""

from .base import SensorPlanEnv
from .navigate import NavigateEnv
from .placement import PlacementEnv
from .recognize import RecognizeEnv

__all__ = ["NavigateEnv", "PlacementEnv", "RecognizeEnv", "SensorPlanEnv"]

"""The three environments; see each module's docstring for spaces and rewards."""

from .base import SensorPlanBatch, SensorPlanEnv
from .navigate import NavigateBatch, NavigateEnv
from .placement import PlacementBatch, PlacementEnv
from .recognize import RecognizeBatch, RecognizeEnv

__all__ = [
    "NavigateBatch",
    "NavigateEnv",
    "PlacementBatch",
    "PlacementEnv",
    "RecognizeBatch",
    "RecognizeEnv",
    "SensorPlanBatch",
    "SensorPlanEnv",
]

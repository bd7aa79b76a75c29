"""Exact sensor-planning geometry after Briggs & Donald, "Robust Geometric
Algorithms for Sensor Planning": complete and partial visibility regions of a
polygonal target (stationary, translating or rotating through a region), with
uncertainty in sensor placement and aim, and recognizability regions that avoid
confusing the goal G with the failure region H.

All functions take a :class:`Scene` and return shapely geometries in world
coordinates; angles are radians.  The package does not depend on Gymnasium.
"""

from .certify import SweptBounds, swept_bounds
from .complete import complete_region
from .partial import partial_region
from .recognize import overlap_segments, recognizable_region
from .scene import Scene, SceneError, SensorSpec
from .sweep import QueryTimeout

__all__ = [
    "QueryTimeout",
    "Scene",
    "SceneError",
    "SensorSpec",
    "SweptBounds",
    "complete_region",
    "overlap_segments",
    "partial_region",
    "recognizable_region",
    "swept_bounds",
]

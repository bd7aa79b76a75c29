"""Oracle agents: analytic placement/motion/aim planning (paper 6.2-6.3) and range-data
recognition (paper 6.4).  Pure numpy/shapely (scipy when available); no Gymnasium imports."""

from .planner import (
    Path,
    Placement,
    best_aim,
    choose_placement,
    grow_free_space,
    shortest_path,
    shrink_region,
)
from .recognition import Decision, classify, fractional_distance, match_distance, target_points

__all__ = [
    "Decision",
    "Path",
    "Placement",
    "best_aim",
    "choose_placement",
    "classify",
    "fractional_distance",
    "grow_free_space",
    "match_distance",
    "shortest_path",
    "shrink_region",
    "target_points",
]

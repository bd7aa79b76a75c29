"""The analytic planner: placement/motion/aim planning (paper 6.2-6.3), range-data recognition
(paper 6.4), the oracle policy that drives the single-robot envs with them (``oracle``), and the
oracle watchers of the multi-agent env (``watch_oracle``, not imported here).  Pure
numpy/shapely (scipy when available); no Gymnasium imports."""

from .oracle import OraclePolicy, ViewpointPlan, plan_viewpoint
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
    "OraclePolicy",
    "Path",
    "Placement",
    "ViewpointPlan",
    "best_aim",
    "choose_placement",
    "classify",
    "fractional_distance",
    "grow_free_space",
    "match_distance",
    "plan_viewpoint",
    "shortest_path",
    "shrink_region",
    "target_points",
]

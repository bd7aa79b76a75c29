"""Agents on top of the envs, by role: ``agents.planning`` (the analytic oracle: placement/motion/
aim planning, paper 6.2-6.3, and range-data recognition, paper 6.4), ``agents.learning`` (SB3
and RLlib training), ``agents.evaluation`` (evaluation, the benchmark protocol, statistics) and,
on top, the ``sensorplan`` CLI (``agents.cli``) and the demo (``agents.demo``).  Importing
``agents`` loads only the planner (numpy/shapely; no Gymnasium imports)."""

from .planning import (
    Decision,
    OraclePolicy,
    Path,
    Placement,
    ViewpointPlan,
    best_aim,
    choose_placement,
    classify,
    fractional_distance,
    grow_free_space,
    match_distance,
    plan_viewpoint,
    shortest_path,
    shrink_region,
    target_points,
)

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

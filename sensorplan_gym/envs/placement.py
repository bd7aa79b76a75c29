"""``sensorplan/Placement-v0`` -- choose one sensor pose that tells G from H.

One decision per episode (a contextual bandit): the agent sees the map and picks a
sensor placement and aim.

Observation
    ``obs_type="vector"``: ``Box(float32, (8 + 2 * n_beams,))`` -- centres and extents
    of G and H and two 360-degree scans of the empty scene from their centres (see
    :mod:`sensorplan_gym.core.observations`); ``"grid"``: ``Box(uint8, (3, S, S))`` with
    channels not-free, G, H.
Action
    ``Box(-1, 1, (3,), float32)`` = ``(x, y, aim)``: ``x`` and ``y`` map linearly onto the
    scene's bounding box (-1 -> min, +1 -> max), ``aim = pi * a[2]`` radians.
    Out-of-range values are clipped to [-1, 1]; NaN/inf or a wrong shape raise
    ``ValueError``.
Reward
    ``1`` when the pose distinguishes "target in G" from "target in H" under the
    configured model: the placement lies in the exact ``recognizable_region`` (computed
    with ``eps_pos``/``eps_aim``) and every aim in ``aim +- eps_aim`` keeps the convex
    hulls of the target swept over G and over H inside the field of view (and within
    ``max_range``); else ``0``.  Optional shaped term ``-shaping * d / diameter``, ``d``
    the distance from the placement to the region (``shaping=0``: off by default).
Termination
    Always ``terminated=True`` after the single step.
Info
    ``is_success``, ``recognizing`` (same as the 0/1 reward), ``in_region``, ``aim_ok``,
    ``distance_to_region``, ``pose`` (commanded) and ``executed_pose`` (perturbed within
    eps_pos/eps_aim; the beams in the rendered frame are cast from it).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from gymnasium import spaces

from .base import SensorPlanEnv

__all__ = ["PlacementEnv"]


class PlacementEnv(SensorPlanEnv):
    obs_kind = "placement"
    needs_start = False

    def __init__(self, scene="lab", *, shaping: float = 0.0, **kwargs) -> None:
        self.shaping = float(shaping)
        super().__init__(scene, **kwargs)
        self.action_space = spaces.Box(-1.0, 1.0, (3,), dtype=np.float32)

    def action_to_pose(self, a: np.ndarray) -> tuple[float, float, float]:
        """The commanded pose of an (already clipped) action."""
        w = self.world
        x = w.lo[0] + 0.5 * (float(a[0]) + 1.0) * (w.hi[0] - w.lo[0])
        y = w.lo[1] + 0.5 * (float(a[1]) + 1.0) * (w.hi[1] - w.lo[1])
        return (float(x), float(y), math.pi * float(a[2]))

    def pose_to_action(self, pose) -> np.ndarray:
        """Inverse of :meth:`action_to_pose` (aim wrapped to [-pi, pi])."""
        w = self.world
        x, y, psi = pose
        ax = 2 * (x - w.lo[0]) / (w.hi[0] - w.lo[0]) - 1
        ay = 2 * (y - w.lo[1]) / (w.hi[1] - w.lo[1]) - 1
        psi = (psi + math.pi) % (2 * math.pi) - math.pi
        return np.array([ax, ay, psi / math.pi], dtype=np.float32)

    def evaluate(self, pose) -> dict[str, Any]:
        """Reward and diagnostics of a commanded pose (no state change, no randomness)."""
        w = self.world
        x, y, psi = pose
        in_region = w.in_region(x, y)
        aim_ok = w.aim_ok(x, y, psi)
        dist = w.distance_to_region(x, y)
        success = in_region and aim_ok
        reward = float(success)
        if self.shaping and math.isfinite(dist):
            reward -= self.shaping * dist / w.diameter
        return {
            "reward": reward,
            "is_success": success,
            "recognizing": success,
            "in_region": in_region,
            "aim_ok": aim_ok,
            "distance_to_region": dist,
        }

    def _reset_episode(self, options: dict) -> None:
        self.pose = None
        self.sensor_pose = None
        self.scan = None
        self._last: dict[str, Any] | None = None

    def _step(self, a: np.ndarray):
        pose = self.action_to_pose(a)
        ev = self.evaluate(pose)
        self.pose = pose
        if self.world.in_free_space(pose[0], pose[1]):
            self._read_sensor(pose)
        else:
            self.sensor_pose, self.scan = pose, None
        info = {k: v for k, v in ev.items() if k != "reward"}
        info["pose"] = pose
        info["executed_pose"] = self.sensor_pose
        self._last = info
        return self._observe(), ev["reward"], True, False, info

    def _observe(self):
        return self._obs(self.world)

    def _info(self) -> dict[str, Any]:
        return {"is_success": False, "recognizing": False, "distance_to_region": math.inf}

"""``sensorplan/Navigate-v0`` -- drive to a pose from which G and H can be told apart.

The section-6 demonstration as a task: like TOMMY, the robot starts where it cannot
recognize whether the target is in G or in H, and drives until its pose does.

Observation
    ``obs_type="vector"``: ``Box(float32, (8 + 3 * n_beams,))`` -- own pose, vectors to G
    and H, range readings with surface normals (see
    :mod:`sensorplan_gym.core.observations`).  ``"grid"``: ``Box(uint8, (5, S, S))``.
    No target is present: beams hit walls and obstacles only.
Action
    ``Box(-1, 1, (3,), float32)`` = ``(forward, lateral, turn)`` scaled by ``max_speed``
    (default 3% of the scene diameter per step) and ``max_turn`` (default pi/8 per step);
    translate first (swept against walls and obstacles: a collision stops the robot at
    the contact), then turn.  Out-of-range values are clipped to [-1, 1]; NaN/inf or a
    wrong shape raise ``ValueError``.
Reward
    ``-step_cost`` (default 0.01) every step, ``+success_bonus`` (default 1.0) on the
    step that reaches a recognizing pose, plus the optional potential-based shaping
    ``shaping * (d_before - d_after) / diameter`` with ``d`` the distance to the
    recognizable region (``shaping=0`` by default).
Termination
    ``terminated`` when the pose recognizes: placement in ``recognizable_region`` and the
    aim (with ``eps_aim``) keeping both swept hulls in the field of view and range.
    ``truncated`` after ``max_episode_steps`` (200, set at registration).
Info
    ``is_success``, ``recognizing``, ``distance_to_region`` (Euclidean, to the exact
    region), ``collided``, ``pose``.
Options
    ``reset(options={"start": (x, y, psi)})`` overrides the start pose (it must be free).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from gymnasium import spaces

from .base import RobotEnv

__all__ = ["NavigateEnv"]


class NavigateEnv(RobotEnv):
    obs_kind = "robot"

    def __init__(
        self,
        scene="lab",
        *,
        step_cost: float = 0.01,
        success_bonus: float = 1.0,
        shaping: float = 0.0,
        **kwargs,
    ) -> None:
        self.step_cost = float(step_cost)
        self.success_bonus = float(success_bonus)
        self.shaping = float(shaping)
        super().__init__(scene, **kwargs)
        self.action_space = spaces.Box(-1.0, 1.0, (3,), dtype=np.float32)
        self._collided = False
        self._success = False

    def _reset_episode(self, options: dict) -> None:
        start = options.get("start")
        if start is not None:
            x, y, psi = (float(v) for v in start)
            if not self.world.in_free_space(x, y):
                raise ValueError(f"options['start'] = {start!r} is not in the robot's free space")
            self.pose = (x, y, psi)
        else:
            self.pose = self._episode_start()
        self._collided = False
        self._success = False
        self._dist = self.world.distance_to_region(self.pose[0], self.pose[1])
        self._read_sensor(self.pose)

    def _step(self, a: np.ndarray):
        self._collided = self._move(a)
        self._read_sensor(self.pose)
        x, y, psi = self.pose
        w = self.world
        recognizing, dist = w.query(x, y, psi)
        reward = -self.step_cost
        if self.shaping and math.isfinite(dist) and math.isfinite(self._dist):
            reward += self.shaping * (self._dist - dist) / w.diameter
        self._dist = dist
        if recognizing:
            reward += self.success_bonus
        self._success = recognizing
        info = self._info(recognizing, dist)
        return self._observe(), reward, recognizing, False, info

    def _info(self, recognizing: bool | None = None, dist: float | None = None) -> dict[str, Any]:
        x, y, psi = self.pose
        if recognizing is None:
            recognizing = self.world.recognizing(x, y, psi)
        if dist is None:
            dist = self._dist
        return {
            "is_success": bool(recognizing),
            "recognizing": bool(recognizing),
            "distance_to_region": float(dist),
            "collided": self._collided,
            "pose": self.pose,
        }

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
    ``truncated`` after ``max_steps`` steps (default 200, also the registered
    ``max_episode_steps``).
Info
    ``is_success``, ``recognizing``, ``distance_to_region`` (Euclidean, to the exact
    region), ``collided``, ``pose``.
Options
    ``reset(options={"start": (x, y, psi)})`` overrides the start pose (it must be free).
Vector env
    ``gym.make_vec("sensorplan/Navigate-v0", num_envs=N, vectorization_mode="vector_entry_point")``
    runs N of these in one batch (:mod:`sensorplan_gym.envs.vector`).
"""

from __future__ import annotations

import numpy as np

from .base import RobotBatch, SensorPlanEnv

__all__ = ["NavigateBatch", "NavigateEnv"]


class NavigateBatch(RobotBatch):
    """Navigate-v0 over N sub-environments (see the module docstring)."""

    obs_kind = "robot"

    def __init__(
        self,
        n: int,
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
        self.success = np.zeros(n, dtype=bool)
        super().__init__(n, scene, **kwargs)

    def _reset_one(self, i: int, options: dict) -> None:
        self._start_from_options(i, options)
        self.success[i] = False

    def _after_reset(self, idx: np.ndarray) -> None:
        super()._after_reset(idx)
        self.dist[idx] = self.query(idx)[3]

    def reset_info(self, idx: np.ndarray) -> dict:
        rec, _, _, dist = self.query(idx)
        return self._cols(idx, rec, dist)

    def _cols(self, idx, rec, dist) -> dict:
        pose = np.stack([self.x[idx], self.y[idx], self.psi[idx]], axis=1)
        return {
            "is_success": (rec, None),
            "recognizing": (rec, None),
            "distance_to_region": (dist, None),
            "collided": (self.collided[idx].copy(), None),
            "pose": (pose, None),
        }

    def step_envs(self, act: np.ndarray, idx: np.ndarray):
        self.elapsed[idx] += 1
        self.move(act, idx)
        rec, _, _, dist = self.query(idx)
        reward = np.full(len(idx), -self.step_cost)
        if self.shaping:
            reward += self.shaping_reward(idx, dist)
        else:
            self.dist[idx] = dist
        reward += np.where(rec, self.success_bonus, 0.0)
        self.success[idx] = rec
        trunc = ~rec & (self.elapsed[idx] >= self.max_steps)
        return reward, rec, trunc, self._cols(idx, rec, dist)


class NavigateEnv(SensorPlanEnv):
    batch_cls = NavigateBatch

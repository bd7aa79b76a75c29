"""``sensorplan/Recognize-v0`` -- the EDR recognition problem as a POMDP.

At reset a hidden target is put in G or in H (probability 1/2 each), uniformly in the
region (the centre for ``motion="stationary"``), at orientation 0 or, for
``motion="rotating"``, uniform in [0, 2 pi).  The agent drives and aims its range sensor,
whose beams are occluded and reflected by the target like any wall, and ends the
episode by declaring G or H.

Observation
    As Navigate-v0 (``vector``: ``8 + 3 * n_beams`` float32; ``grid``: 5 x S x S uint8).
    The target's side and pose are never part of it: only the beams it reflects.
Action
    ``Box(-1, 1, (4,), float32)`` = ``(forward, lateral, turn, decide)``; the first three
    drive as in Navigate-v0 (the target is an obstacle too).  ``decide`` in thirds:
    ``< -1/3`` declares **G**, ``> 1/3`` declares **H**, otherwise continue.  A declaring
    step still moves first, then the declaration ends the episode.  Out-of-range values
    are clipped to [-1, 1]; NaN/inf or a wrong shape raise ``ValueError``.
Reward
    ``-step_cost`` (default 0.01) every step; ``+1`` for a right declaration, ``-1`` for a
    wrong one; the step that hits the time limit without a declaration gets ``-1`` (a
    timeout counts as wrong).
Termination
    ``terminated`` on a declaration; ``truncated`` when ``max_steps`` steps have passed
    (``max_steps=None`` takes ``max_episode_steps`` from the registration, 200).
Info
    ``is_success`` (declared and right), ``declared`` (None, "G" or "H"),
    ``recognizing`` (the pose is in the exact recognizable region with a valid aim),
    ``distance_to_region``, ``collided``, ``pose``; at the end of an episode also
    ``target_in`` ("G" or "H") -- evaluation data, never part of the observation.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import shapely
from gymnasium import spaces

from ..core.sensor import Segments
from ..core.world import _FastDistance
from .base import RobotEnv

__all__ = ["RecognizeEnv"]


class RecognizeEnv(RobotEnv):
    obs_kind = "robot"

    def __init__(
        self, scene="lab", *, step_cost: float = 0.01, max_steps: int | None = None, **kwargs
    ) -> None:
        self.step_cost = float(step_cost)
        if max_steps is not None and (not isinstance(max_steps, int) or max_steps < 1):
            raise ValueError(f"max_steps must be a positive integer or None, got {max_steps!r}")
        self.max_steps = max_steps
        super().__init__(scene, **kwargs)
        self.action_space = spaces.Box(-1.0, 1.0, (4,), dtype=np.float32)
        self._side = "G"
        self._elapsed = 0
        self._declared = None
        self._collided = False

    def _limit(self) -> int | None:
        if self.max_steps is not None:
            return self.max_steps
        spec = self.spec
        return spec.max_episode_steps if spec is not None else None

    def _place_target(self) -> None:
        w = self.world
        rng = self.np_random
        self._side = "G" if rng.random() < 0.5 else "H"
        which = "goal" if self._side == "G" else "failure"
        r = w.robot_radius
        for _ in range(20):
            q = w.sample_in(which, rng)
            th = rng.uniform(0.0, 2 * math.pi) if w.theta is None else 0.0
            c, s = math.cos(th), math.sin(th)
            poly = w.target @ np.array([[c, s], [-s, c]]) + q
            segs = np.concatenate([poly, np.roll(poly, -1, axis=0)], axis=1)
            # keep the robot clear of the target at the start
            if self.pose is None or _clear(self.pose[:2], poly, segs, r):
                break
        self._target_poly = poly
        self._tsegs = segs
        self._segs = w.seg_set + Segments(segs)
        self._extra_clearance = _FastDistance(segs)

    def _reset_episode(self, options: dict) -> None:
        self.pose = self._episode_start()
        self._elapsed = 0
        self._declared = None
        self._collided = False
        self._place_target()
        self._read_sensor(self.pose)

    def _step(self, a: np.ndarray):
        self._elapsed += 1
        self._collided = self._move(a)
        self._read_sensor(self.pose)
        reward = -self.step_cost
        terminated = truncated = False
        d = float(a[3])
        if d < -1 / 3 or d > 1 / 3:
            self._declared = "G" if d < -1 / 3 else "H"
            reward += 1.0 if self._declared == self._side else -1.0
            terminated = True
        else:
            limit = self._limit()
            if limit is not None and self._elapsed >= limit:
                reward -= 1.0
                truncated = True
        info = self._info()
        if terminated or truncated:
            info["target_in"] = self._side
        return self._observe(), reward, terminated, truncated, info

    def _info(self) -> dict[str, Any]:
        x, y, psi = self.pose
        recognizing, dist = self.world.query(x, y, psi)
        return {
            "is_success": self._declared is not None and self._declared == self._side,
            "declared": self._declared,
            "recognizing": recognizing,
            "distance_to_region": dist,
            "collided": self._collided,
            "pose": self.pose,
        }

    def _render_state(self) -> dict[str, Any]:
        st = super()._render_state()
        st["target"] = self._target_poly
        if self._declared:
            st["title"] += f"  declared {self._declared} (target in {self._side})"
        return st


def _clear(p, poly: np.ndarray, segs: np.ndarray, r: float) -> bool:
    """The robot disc at ``p`` does not meet the target polygon."""
    P = shapely.Polygon(poly)
    return P.distance(shapely.Point(p)) > r + 1e-9

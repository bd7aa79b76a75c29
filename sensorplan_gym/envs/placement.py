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

from ..core import fused
from .base import SensorPlanBatch, SensorPlanEnv

__all__ = ["PlacementBatch", "PlacementEnv"]


class PlacementBatch(SensorPlanBatch):
    """Placement-v0 over N sub-environments (see the module docstring)."""

    obs_kind = "placement"
    needs_start = False
    action_task = "placement"
    horizon = 1

    def __init__(self, n: int, scene="lab", *, shaping: float = 0.0, **kwargs) -> None:
        self.shaping = float(shaping)
        self.placed = np.zeros(n, dtype=bool)
        super().__init__(n, scene, **kwargs)
        self.params[fused.P_SHAPING] = self.shaping

    def _has_pose(self, i: int) -> bool:
        return bool(self.placed[i])

    def action_to_pose(self, a: np.ndarray, idx: np.ndarray) -> np.ndarray:
        """Commanded poses ``(k, 3)`` of (clipped) actions ``(k, 3)``: x and y map linearly
        onto the bounding box, aim ``pi * a[2]`` radians."""
        lo, hi = self.lo[idx], self.hi[idx]
        xy = lo + 0.5 * (a[:, :2] + 1.0) * (hi - lo)
        return np.concatenate([xy, math.pi * a[:, 2:3]], axis=1)

    def _reset_one(self, i: int, options: dict) -> None:
        self.placed[i] = False
        self.has_scan[i] = False

    def reset_info(self, idx: np.ndarray) -> dict:
        k = len(idx)
        f = np.zeros(k, dtype=bool)
        return {
            "is_success": (f, None),
            "recognizing": (f.copy(), None),
            "distance_to_region": (np.full(k, math.inf), None),
        }

    def evaluate(self, pose: np.ndarray, idx: np.ndarray) -> tuple[np.ndarray, dict]:
        """Rewards ``(k,)`` and info columns of commanded poses ``(k, 3)`` (no state change,
        no randomness)."""
        rec, inside, aim, dist = self.query(idx, pose[:, 0], pose[:, 1], pose[:, 2])
        reward = rec.astype(np.float64)
        if self.shaping:
            reward -= np.where(np.isfinite(dist), self.shaping * dist / self.diameter[idx], 0.0)
        cols = {
            "is_success": (rec, None),
            "recognizing": (rec.copy(), None),
            "in_region": (inside, None),
            "aim_ok": (aim, None),
            "distance_to_region": (dist, None),
        }
        return reward, cols

    def square_to_box(self, a: np.ndarray, idx: np.ndarray) -> np.ndarray:
        """Actions ``(k, 3)`` whose x and y span the grid observation's square (the bounding
        box fit into it, centred: ``action_type="pixel"``) as actions over the bounding box,
        clipped to it."""
        span = self.hi[idx] - self.lo[idx]
        out = a.copy()
        out[:, :2] = np.clip(a[:, :2] * (span.max(axis=1, keepdims=True) / span), -1.0, 1.0)
        return out

    def step_envs(self, act: np.ndarray, idx: np.ndarray):
        if self.actions.square:
            act = self.square_to_box(act, idx)
        if self.fused:
            return self._step_compiled(act, idx)
        pose = self.action_to_pose(act, idx)
        reward, cols = self.evaluate(pose, idx)
        self.x[idx], self.y[idx], self.psi[idx] = pose.T
        self.placed[idx] = True
        free = self.in_free_space(idx, pose[:, 0], pose[:, 1])
        self.has_scan[idx] = False
        if free.any():
            self.sense(idx[free])
        executed = np.stack([self.sx[idx], self.sy[idx], self.spsi[idx]], axis=1)
        executed[~free] = pose[~free]
        cols["pose"] = (pose, None)
        cols["executed_pose"] = (executed, None)
        k = len(idx)
        return reward, np.ones(k, dtype=bool), np.zeros(k, dtype=bool), cols

    def _step_compiled(self, act: np.ndarray, idx: np.ndarray):
        """:meth:`step_envs` by :func:`.fused.placement_step` (one call; another after
        each refill of a row's pre-drawn numbers)."""
        k = len(idx)
        res = np.empty((12, k))
        if act.dtype != np.float64 or not act.flags.c_contiguous:
            act = np.ascontiguousarray(act, dtype=np.float64)
        args = self._kargs
        if args is None:
            args = self._kargs = (
                self.params,
                self.P,
                self.C,
                self.stochastic,
                self.aim_trivial,
                self.lo,
                self.hi,
                self.region_xy,
                self.region_segs.data,
                self.space_xy,
                self.hulls,
                self.centers,
                self.OFF,
                self.segs.data,
                self._U,
                self._Z,
                self._ptr,
                self.scan_dist,
                self.scan_normal,
                self.scan_hit,
                self.scan_ang,
                self.has_scan,
                self.placed,
            )
        k0 = 0
        while True:
            k0 = fused.placement_step(k0, idx, act, *args, res)
            if k0 == k:
                break
            self._refill(idx[k0 : k0 + 1])
        if self.n_stochastic:
            self._note_used(idx)
        flags = res[1:4] != 0.0
        cols = {
            "is_success": (flags[0], None),
            "recognizing": (flags[0].copy(), None),
            "in_region": (flags[1], None),
            "aim_ok": (flags[2], None),
            "distance_to_region": (res[4], None),
            "pose": (res[6:9].T, None),
            "executed_pose": (res[9:12].T, None),
        }
        return res[0], np.ones(k, dtype=bool), np.zeros(k, dtype=bool), cols


class PlacementEnv(SensorPlanEnv):
    """``sensorplan/Placement-v0``: choose one sensor pose that tells G from H.

    ## Description
    One decision per episode (a contextual bandit).  A hidden target may stand in a region G
    or in a region H of a polygonal map; the agent sees the map and picks a sensor placement
    and aim.  The pose succeeds when it lies in the exact *recognizable region*
    ``R(G) n R(H) - C(G, H)`` of Briggs & Donald (computed exactly, never sampled, with the
    placement and aim uncertainties ``eps_pos``/``eps_aim``) and its aim keeps both swept
    targets in the field of view and range.

    ## Action Space
    ``action_type="continuous"`` (default): ``Box(-1, 1, (3,), float32)``.

    | Index | Action | Min | Max | Commanded pose (world frame)                           |
    |-------|--------|-----|-----|--------------------------------------------------------|
    | 0     | x      | -1  | 1   | ``x_min + (a + 1) / 2 * (x_max - x_min)``, scene units |
    | 1     | y      | -1  | 1   | ``y_min + (a + 1) / 2 * (y_max - y_min)``, scene units |
    | 2     | aim    | -1  | 1   | ``pi * a`` radians, counter-clockwise from +x          |

    over the scene's bounding box.  Out-of-range values are clipped; NaN/inf or a wrong shape
    raise ``ValueError``.  ``action_type="discrete"``: ``Discrete(G * G * A)``, a ``G x G``
    grid of placements (cell centres) times ``A`` aims ``-pi + 2 pi k / A``, ``a = (i * G +
    j) * A + k`` for column ``i`` (x), row ``j`` (y), aim ``k``; ``G = placement_grid`` (16),
    ``A = placement_aims`` (8).  ``action_type="pixel"``: ``Discrete(S * S * A)``, one
    placement per pixel of the grid observation (``S = grid_size``), ``a = (row * S + col) *
    A + k`` (:mod:`sensorplan_gym.core.actions`).  ``env.action_to_pose(a)`` /
    ``env.pose_to_action(pose)`` convert between continuous actions and poses.

    ## Observation Space
    ``obs_type="vector"`` (default): ``Box(float32, (8 + 2 * n,))``, ``n = n_beams``;
    constant for a fixed scene (it describes the map, which matters with ``scene="random"``).

    | Index          | Observation                                 | Min | Max | Units / frame     |
    |----------------|---------------------------------------------|-----|-----|-------------------|
    | 0, 1           | centre of G (x, y)                          | -1  | 1   | world, scaled (1) |
    | 2, 3           | centre of H (x, y)                          | -1  | 1   | world, scaled (1) |
    | 4, 5           | width, height of G's bounding box           | 0   | 1   | / scene's span    |
    | 6, 7           | width, height of H's bounding box           | 0   | 1   | / scene's span    |
    | 8 ... 8+n-1    | 360-degree scan of the empty scene from G's | 0   | 1   | / diameter        |
    |                | centre (n beams evenly spaced, world frame) |     |     |                   |
    | 8+n ... 8+2n-1 | the same scan from H's centre               | 0   | 1   | / diameter        |

    (1) ``2 (x - x_min) / (x_max - x_min) - 1`` over the scene's bounding box (likewise y).
    "Scene's span": the bounding box's width (for widths) and height (for heights).  The
    scans see walls and obstacles only.

    ``obs_type="grid"``: ``Box(uint8, (3, S, S))``, ``S = grid_size`` (default 64), channel
    first, the bounding box fit into the square (aspect kept), row 0 at the top; channels
    0 not free (walls, obstacles, outside), 1 G, 2 H; ``grid_views=True`` adds the free space
    seen from G's and from H's anchor, ``hull_views=True`` the free space seen from every
    corner of K_G and of K_H, ``self_features=True`` two constant planes (field of view / 360
    degrees, reach / diameter, times 255), in that order.

    ## Rewards
    ``1`` when the commanded pose distinguishes "target in G" from "target in H" under the
    configured model: the placement lies in the exact recognizable region and every aim in
    ``aim +- eps_aim`` keeps the convex hulls of the target swept over G and over H inside the
    field of view (and within ``max_range``); else ``0``.  Optional shaped term ``-shaping *
    d / diameter``, ``d`` the distance from the placement to the region (``shaping=0``).

    ## Starting State
    No pose: the episode is the one decision.  ``reset`` returns the map's observation; with
    ``scene="random"`` it draws a scene from the pool first.

    ## Episode End
    * Termination: always, after the single step.
    * Truncation: never (``max_steps`` is 1; no time limit is registered).

    ``info`` after the step: ``is_success``, ``recognizing`` (same as the 0/1 reward),
    ``in_region``, ``aim_ok``, ``distance_to_region`` (scene units), ``pose`` (commanded)
    and ``executed_pose`` (perturbed within ``eps_pos``/``eps_aim``; the beams of the
    rendered frame are cast from it).

    ## Arguments
    ```python
    import gymnasium as gym
    env = gym.make("sensorplan_gym:sensorplan/Placement-v0", scene="edr", model="partial")
    envs = gym.make_vec("sensorplan_gym:sensorplan/Placement-v0", num_envs=64, scene="random",
                        vectorization_mode="vector_entry_point")
    ```

    Placement's own: ``shaping`` (0.0); with ``action_type="discrete"``, ``placement_grid``
    (16) and ``placement_aims`` (8).
    Common to all tasks (details: ``help(sensorplan_gym.envs.base)``):

    * ``scene`` (``"lab"``): a bundled scene (``lab``, ``edr``, ``corridor``, ``warehouse``),
      a scene JSON path, a dict or ``geometry.Scene``, or ``"random"``: each reset draws from
      a seeded pool of procedural scenes (``scene_pool_size`` = 64, ``scene_pool_seed`` = 0,
      ``random_scene_kwargs``; ``min_start_distance``, a fraction of the scene diameter, is
      the difficulty knob of the robot tasks).
    * ``model`` (``"complete"`` | ``"partial"``) and ``motion`` (``"stationary"`` |
      ``"translating"`` | ``"rotating"``): the visibility model and the target's motion in
      G/H of the recognizable region; unsupported pairs raise ``NotImplementedError``.
    * ``eps_pos`` (scene units), ``eps_aim`` (radians, in [0, pi)), ``fov_deg`` (degrees),
      ``max_range`` (scene units; ``math.inf``: unlimited): ``None`` takes the scene's.
    * ``n_beams`` (16), ``noise`` (0, range std in scene units), ``obs_type`` (``"vector"`` |
      ``"grid"``), ``grid_size`` (64), ``robot_radius`` (0: a point robot).
    * ``action_type`` (``"continuous"`` | ``"discrete"``), ``max_steps`` (time limit),
      ``render_mode`` (``None`` | ``"rgb_array"`` | ``"human"``).

    ## Version History
    * v0: the initial version.  Added within v0 (defaults keep the earlier behaviour): the
      batched core, one implementation behind the single env and the native vector env
      (``vector_entry_point``); ``action_type`` (the discrete placement grid);
      ``max_steps``; scene pools (``scene="random"``, ``scene_pool_size``,
      ``scene_pool_seed``).
    """

    batch_cls = PlacementBatch

    def action_to_pose(self, a: np.ndarray) -> tuple[float, float, float]:
        """The commanded pose of an (already clipped) action."""
        p = self.batch.action_to_pose(np.asarray(a, dtype=np.float64)[None], self._ONE)[0]
        return (float(p[0]), float(p[1]), float(p[2]))

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
        r, cols = self.batch.evaluate(np.asarray(pose, dtype=np.float64)[None], self._ONE)
        out = {"reward": float(r[0])}
        out.update(self._info(cols))
        return out

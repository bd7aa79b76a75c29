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
    ``gym.make_vec("sensorplan_gym:sensorplan/Navigate-v0", num_envs=N,
    vectorization_mode="vector_entry_point")`` runs N of these in one batch
    (:mod:`sensorplan_gym.envs.vector`).
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
    """``sensorplan/Navigate-v0``: drive to a pose from which G and H can be told apart.

    ## Description
    The surveillance scenario of Briggs & Donald's section 6 as a task.  A hidden target may
    stand in a region G or in a region H of a polygonal map; like the robot TOMMY, the robot
    starts at a pose from which it cannot tell which, and drives until its sensor pose lies
    in the exact *recognizable region* ``R(G) n R(H) - C(G, H)`` (computed exactly, never
    sampled, with the placement and aim uncertainties ``eps_pos``/``eps_aim``) with an aim
    that keeps both swept targets in the field of view and range.  No target is present in
    this task: the beams hit walls and obstacles only.

    ## Action Space
    ``action_type="continuous"`` (default): ``Box(-1, 1, (3,), float32)``.

    | Index | Action  | Min | Max | Effect                                              |
    |-------|---------|-----|-----|-----------------------------------------------------|
    | 0     | forward | -1  | 1   | ``max_speed * a`` along the heading (robot frame)   |
    | 1     | lateral | -1  | 1   | ``max_speed * a`` to the robot's left (robot frame) |
    | 2     | turn    | -1  | 1   | ``max_turn * a`` radians, counter-clockwise         |

    ``max_speed`` defaults to 3 % of the scene diameter per step, ``max_turn`` to pi/8
    (``speed_limit="disc"`` scales a ``(forward, lateral)`` of norm above 1 to norm 1).  The
    robot translates first, swept against walls and obstacles (a collision stops it at the
    contact, ``info["collided"]``), then turns.  Out-of-range values are clipped; NaN/inf or
    a wrong shape raise ``ValueError``.  ``action_type="discrete"``: ``Discrete(7)``: 0 stay,
    1 forward, 2 backward, 3 left, 4 right (full speed), 5 turn left, 6 turn right.

    ## Observation Space
    ``obs_type="vector"`` (default): ``Box(float32, (8 + 3 * n,))`` with ``n = n_beams``.
    "World frame": the scene's coordinates (scene units; the bundled scenes are in metres),
    angles counter-clockwise from +x.  "Robot frame": x forward along the heading ``psi``,
    y to the robot's left.  ``reach = min(max_range, scene diameter)``.

    | Index           | Observation                               | Min | Max | Units / frame     |
    |-----------------|-------------------------------------------|-----|-----|-------------------|
    | 0               | x position                                | -1  | 1   | world, scaled (1) |
    | 1               | y position                                | -1  | 1   | world, scaled (1) |
    | 2               | cos(psi), heading psi                     | -1  | 1   | world, radians    |
    | 3               | sin(psi)                                  | -1  | 1   | world, radians    |
    | 4, 5            | vector to the centre of G (forward, left) | -1  | 1   | robot, / diameter |
    | 6, 7            | vector to the centre of H (forward, left) | -1  | 1   | robot, / diameter |
    | 8 ... 8+n-1     | beam ranges (beam b: the b-th of the fan) | 0   | 1   | / reach           |
    | 8+n ... 8+2n-1  | surface normal at each hit, x components  | -1  | 1   | robot, unit (2)   |
    | 8+2n ... 8+3n-1 | surface normal at each hit, y components  | -1  | 1   | robot, unit (2)   |
    | 8+3n ... 8+4n-1 | ``map_ranges=True``: range the static map | 0   | 1   | / reach (3)       |
    |                 | predicts for each beam                    |     |     |                   |
    | next n, next n  | ``map_evidence=True``: beam evidence for  | 0   | 1   | 0/1 flags (4)     |
    |                 | G (n flags), then for H (n flags)         |     |     |                   |
    | last            | ``sensor_fov=True``: field of view / 360  | 0   | 1   | fraction of 360   |
    |                 | degrees (the robot's own sensor)          |     |     | degrees           |

    (1) ``2 (x - x_min) / (x_max - x_min) - 1`` over the scene's bounding box, clipped.
    (2) Zero where the beam hit nothing within ``reach``.  The fan: ``n_beams`` beams spread
    evenly over ``fov_deg`` centred on the heading (``2 pi / n`` apart at 360 degrees); ranges
    carry Gaussian ``noise`` (std, scene units) and are read from the *executed* sensor pose.
    (3) From the commanded pose, walls and obstacles only, no noise: what a robot carrying
    the map expects.  Comes after the normals, then the ``map_evidence`` entries, then
    ``sensor_fov``.
    (4) 1 where the beam read shorter than the map predicts (by more than ``3 noise +
    1e-3 reach``) and its end point lies in the hull of the target swept over G (resp. H).

    ``obs_type="grid"``: ``Box(uint8, (5, S, S))``, ``S = grid_size`` (default 64), channel
    first, the scene's bounding box fit into the square (aspect kept), row 0 at the top.
    Channels: 0 not free (walls, obstacles, outside), 1 G, 2 H, 3 the robot (255 at its cell,
    128 two cells ahead along its heading), 4 the current beam hit points (255).

    ## Rewards
    ``-step_cost`` (0.01) every step, ``+success_bonus`` (1.0) on the step that reaches a
    recognizing pose, plus the optional potential-based shaping ``shaping * (d_before -
    d_after) / diameter``, ``d`` the Euclidean distance to the exact recognizable region
    (``shaping=0`` by default; the shipped training configs set it).

    ## Starting State
    The scene's ``start`` pose ``(x, y, psi)`` (world frame, radians), every episode.  When
    that pose already recognizes (e.g. ``warehouse`` with ``model="partial",
    motion="stationary"``) or cannot reach the region, the env uses a start drawn once with a
    fixed generator: a free position outside the region, in a part of the free space that
    reaches it, with a uniform heading.  ``random_start=True`` draws such a start at every
    reset from the env's ``np_random``.  ``reset(options={"start": (x, y, psi)})`` overrides
    the start (it must be free; the heading is wrapped to [-pi, pi]).  With
    ``scene="random"`` each reset draws a scene from the pool and takes its start.

    ## Episode End
    * Termination: the pose recognizes (placement in the recognizable region, aim within
      ``eps_aim`` keeping both swept targets in view).
    * Truncation: ``max_steps`` steps (default 200, also the registered
      ``max_episode_steps``).

    ``info``: ``is_success``, ``recognizing``, ``distance_to_region`` (scene units, to the
    exact region; 0 inside), ``collided``, ``pose`` (commanded, world frame).

    ## Arguments
    ```python
    import gymnasium as gym
    env = gym.make("sensorplan_gym:sensorplan/Navigate-v0", scene="lab", random_start=True)
    envs = gym.make_vec("sensorplan_gym:sensorplan/Navigate-v0", num_envs=64,
                        vectorization_mode="vector_entry_point")
    ```

    Navigate's own: ``step_cost`` (0.01), ``success_bonus`` (1.0), ``shaping`` (0.0),
    ``max_speed`` (scene units per step; ``None``: 3 % of the diameter), ``max_turn`` (pi/8
    radians per step), ``random_start`` (False), ``speed_limit`` (``"box"``: forward and
    lateral each up to ``max_speed``, so diagonals move sqrt(2) times as far; ``"disc"``: at
    most ``max_speed`` in every direction).  ``map_ranges`` / ``map_evidence`` /
    ``sensor_fov`` (False) add the observation entries above (``obs_type="vector"`` only).
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
      (``vector_entry_point``); ``action_type``; ``map_ranges`` and ``map_evidence``;
      ``max_steps``; scene pools (``scene="random"``, ``scene_pool_size``,
      ``scene_pool_seed``, ``min_start_distance``); a drawn start when a fixed scene's own
      start already recognizes.
    """

    batch_cls = NavigateBatch

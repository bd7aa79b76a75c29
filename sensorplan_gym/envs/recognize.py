"""``sensorplan/Recognize-v0`` -- the EDR recognition problem as a POMDP.

At reset a hidden target is put in G or in H (probability 1/2 each), uniformly in the
region (the centre for ``motion="stationary"``), at orientation 0 or, for
``motion="rotating"``, uniform in [0, 2 pi).  The agent drives and aims its range sensor,
whose beams are occluded and reflected by the target like any wall, and ends the
episode by declaring G or H.

Observation
    As Navigate-v0 (``vector``: ``8 + 3 * n_beams`` float32, ``8 + 4 * n_beams`` with
    ``map_ranges=True``: the ranges the static map predicts, so that a reading that differs
    shows the target; ``grid``: 5 x S x S uint8).  The target's side and pose are never part
    of it: only the beams it reflects.
Action
    ``Box(-1, 1, (4,), float32)`` = ``(forward, lateral, turn, decide)``; the first three
    drive as in Navigate-v0 (the target is an obstacle too).  ``decide`` in thirds:
    ``< -1/3`` points at **G**, ``> 1/3`` at **H**, otherwise continue.  A label pointed at
    on ``declare_hold`` consecutive steps (default 1) is declared: a declaring step still
    moves first, then the declaration ends the episode.  ``declare_hold=3`` or more keeps
    an exploring policy (whose ``decide`` crosses +-1/3 at random) from ending episodes by
    accident: it has to mean it.  Out-of-range values are clipped to [-1, 1]; NaN/inf or a
    wrong shape raise ``ValueError``.  ``action_type="discrete"``: ``Discrete(9)``, the
    seven motions of :mod:`sensorplan_gym.core.actions` plus 7 = point at G, 8 = at H.
Reward
    ``-step_cost`` (default 0.01) every step; ``+1`` for a right declaration, ``-1`` for a
    wrong one; the step that hits the time limit without a declaration gets ``-1`` (a
    timeout counts as wrong).  Optional potential-based shaping for training,
    ``shaping * (d_before - d_after) / diameter`` with ``d`` the distance to the exact
    recognizable region (a map quantity: it says nothing about where the target is);
    ``shaping=0`` by default.
Termination
    ``terminated`` on a declaration; ``truncated`` when ``max_steps`` steps have passed
    (default 200, also the registered ``max_episode_steps``); the timeout penalty is
    applied by the env itself, so it holds under ``gym.make``, ``make_vec`` and direct
    construction alike.
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

from ..core import fused
from ..core.segments import SegmentRows, pad_segments, point_segment_distance, segment_normals
from ..core.targets import TargetTables, place_targets, targets_clear
from .base import RobotBatch, SensorPlanEnv

__all__ = ["RecognizeBatch", "RecognizeEnv"]

_NONE, _G, _H = 0, 1, 2
_LABEL = np.array([None, "G", "H"], dtype=object)


class RecognizeBatch(RobotBatch):
    """Recognize-v0 over N sub-environments (see the module docstring)."""

    obs_kind = "robot"
    action_dim = 4
    action_task = "recognize"
    joint_view = False  # the robot may look at G, then at H
    # side: _G or _H, where the hidden target is; hold: consecutive steps pointing at one
    # label; pointing: that label; declared: the declared label (_NONE: none yet)
    I8_NAMES = ("elapsed", "side", "hold", "pointing", "declared")

    def __init__(
        self,
        n: int,
        scene="lab",
        *,
        step_cost: float = 0.01,
        shaping: float = 0.0,
        declare_hold: int = 1,
        **kwargs,
    ) -> None:
        if not isinstance(declare_hold, (int, np.integer)) or declare_hold < 1:
            raise ValueError(f"declare_hold must be a positive integer, got {declare_hold!r}")
        if not isinstance(shaping, (int, float)) or not math.isfinite(shaping):
            raise ValueError(f"shaping must be a finite number, got {shaping!r}")
        self.step_cost = float(step_cost)
        self.shaping = float(shaping)
        self.declare_hold = int(declare_hold)
        self.tsegs = SegmentRows(n)  # the target's edges
        self.tt = TargetTables(n)
        self.placed = np.zeros(n, dtype=bool)
        super().__init__(n, scene, **kwargs)
        self.params[fused.P_DECLARE_HOLD] = self.declare_hold

    def load_world(self, i: int, world, max_speed: float | None = None) -> None:
        if self.worlds[i] is world:
            return
        super().load_world(i, world, max_speed)
        nstat = world.batch_rows()["segs"].shape[1]
        v = len(world.target)
        self.tt.load(i, world, _hidden_target(world), nstat)
        self.segs.reserve(nstat + v)
        self.tsegs.reserve(v)
        self.placed[i] = False

    def _row_arrays(self) -> list[tuple[np.ndarray, int]]:
        T = self.tt
        return super()._row_arrays() + [
            (a, 0)
            for a in (T.tri, T.cum, T.ntri, T.pts, T.tgt, T.nv, T.rot, T.H, T.nh, T.trows, T.nstat)
        ]

    def _rows_loaded(self, rows: np.ndarray) -> None:
        self.placed[rows] = False

    def drop_block(self, i: int) -> None:
        super().drop_block(i)
        self.tt.uptr[i] = self.tt.U.shape[1]  # the target's uniforms too

    @property
    def target_polys(self) -> list[np.ndarray | None]:
        """The hidden target's vertices ``(V, 2)`` (world frame) per row (``None`` before
        the first reset); copies."""
        T = self.tt
        return [T.poly[i, : T.nv[i]].copy() if self.placed[i] else None for i in range(self.n)]

    def _place_targets(self, idx: np.ndarray) -> None:
        """Hide the targets of rows ``idx`` in G or H (:func:`.core.targets.place_targets`)
        and add their edges to the rows' segments."""
        T = self.tt
        T.refill(idx, self.rngs)
        place_targets(
            idx,
            T.U,
            T.uptr,
            self.P,
            self.robot_radius,
            T.tri,
            T.cum,
            T.ntri,
            T.pts,
            T.tgt,
            T.nv,
            T.rot,
            T.H,
            T.nh,
            T.trows,
            T.nstat,
            self.segs.data,
            self.tsegs.data,
            self.side,
            T.poly,
        )
        self.placed[idx] = True
        clear = np.empty(len(idx), dtype=bool)
        targets_clear(idx, self.P, self.robot_radius, T.poly, T.nv, clear)
        for i in idx[~clear].tolist():
            # every draw met the robot (G or H a point whose target covers the start): start
            # elsewhere rather than inside a solid object
            self._start_clear_of(i, shapely.Polygon(T.poly[i, : T.nv[i]]))

    def _start_clear_of(self, i: int, target: shapely.Polygon) -> None:
        """Move sub-environment ``i``'s robot to a start drawn from its generator as
        ``random_start`` draws one (free, outside the region, in a part of the free space
        that reaches it), that also keeps the robot disc clear of ``target``.  Raises
        ``RuntimeError`` when 10,000 draws find none."""
        w = self.worlds[i]
        rng = self.rngs[i]
        comps = shapely.get_parts(w.robot_space)
        space = shapely.union_all(comps[shapely.intersects(comps, w.region)])
        keep = target.buffer(w.robot_radius + 1e-6 * w.diameter)
        for _ in range(10_000):
            x = float(rng.uniform(w.lo[0], w.hi[0]))
            y = float(rng.uniform(w.lo[1], w.hi[1]))
            if (
                shapely.contains_xy(space, x, y)
                and not w.in_region(x, y)
                and not shapely.contains_xy(keep, x, y)
                and self.far_enough(i, x, y)
            ):
                self.set_pose(i, (x, y, float(rng.uniform(-math.pi, math.pi))))
                return
        raise RuntimeError(
            f"scene {w.scene.name!r}: no start outside the region keeps clear of the target"
        )

    def _reset_rows(self, idx: np.ndarray, options: dict) -> None:
        self._reset_starts(idx, {})
        self.declared[idx] = _NONE
        self.hold[idx] = 0
        self.pointing[idx] = _NONE
        self._place_targets(idx)

    def _after_reset(self, idx: np.ndarray) -> None:
        super()._after_reset(idx)
        if self.shaping:
            self.dist[idx] = self.query(idx)[3]

    def _extra_clearance(self, idx, x, y, mask) -> np.ndarray:
        out = np.full(len(idx), np.inf)
        if mask.any():
            j = idx[mask]
            out[mask] = point_segment_distance(x[mask], y[mask], self._rows(self.tsegs, j))
        return out

    def reset_info(self, idx: np.ndarray) -> dict:
        return self._cols(idx, np.zeros(len(idx), dtype=bool))

    def _cols(self, idx: np.ndarray, ended: np.ndarray, q=None) -> dict:
        rec, dist = (self.query(idx)[::3]) if q is None else q
        dec = self.declared[idx]
        return {
            "is_success": ((dec != _NONE) & (dec == self.side[idx]), None),
            "declared": (_LABEL[dec], None),
            "recognizing": (rec, None),
            "distance_to_region": (dist, None),
            "collided": (self.collided[idx], None),
            "pose": (self.P[:3, idx].T, None),
            "target_in": (_LABEL[self.side[idx]], ended),
        }

    def step_envs(self, act: np.ndarray, idx: np.ndarray):
        if self.compiled_step:
            reward, f, dist = self._step_compiled(act, idx, fused.RECOGNIZE)
            return reward, f[0], f[1], self._cols(idx, f[0] | f[1], (f[2], dist))
        self.elapsed[idx] += 1
        self.move(act, idx)
        d = act[:, 3]
        want = np.where(d < -1 / 3, _G, np.where(d > 1 / 3, _H, _NONE)).astype(np.int8)
        same = (want != _NONE) & (want == self.pointing[idx])
        hold = np.where(same, self.hold[idx] + 1, (want != _NONE).astype(np.int64))
        self.hold[idx], self.pointing[idx] = hold, want
        dec = np.where(hold >= self.declare_hold, want, _NONE).astype(np.int8)
        self.declared[idx] = dec
        term = dec != _NONE
        reward = np.full(len(idx), -self.step_cost)
        if self.shaping:
            reward += self.shaping_reward(idx, self.query(idx)[3])
        reward += np.where(term, np.where(dec == self.side[idx], 1.0, -1.0), 0.0)
        trunc = ~term & (self.elapsed[idx] >= self.max_steps)
        reward -= trunc  # a timeout counts as wrong
        return reward, term, trunc, self._cols(idx, term | trunc)

    def render_state(self, i: int) -> dict[str, Any]:
        st = super().render_state(i)
        st["target"] = self.target_polys[i]
        if self.declared[i] != _NONE:
            st["title"] += (
                f"  declared {_LABEL[self.declared[i]]} (target in {_LABEL[self.side[i]]})"
            )
        return st


def _outward(segs: np.ndarray) -> np.ndarray:
    """Unit normals of a polygon's edges ``(T, 4)`` pointing out of it (into free space)."""
    n = segment_normals(segs)
    area2 = float(np.sum(segs[:, 0] * segs[:, 3] - segs[:, 2] * segs[:, 1]))
    return -n if area2 > 0 else n  # counter-clockwise: left normals point inwards


def _hidden_target(w) -> np.ndarray:
    """The target's edges at the origin as ``(6, T)`` rows, normals pointing out of it
    (cached on the world)."""
    k = w._cache.get("hidden_target_rows")
    if k is None:
        poly = np.asarray(w.target, dtype=np.float64)
        segs = np.concatenate([poly, np.roll(poly, -1, axis=0)], axis=1)
        k = w._cache["hidden_target_rows"] = pad_segments(segs, _outward(segs), len(segs))
    return k


class RecognizeEnv(SensorPlanEnv):
    """``sensorplan/Recognize-v0``: find out whether the hidden target is in G or in H.

    ## Description
    The EDR recognition problem of Briggs & Donald as a POMDP.  At reset a hidden target is
    put in G or in H (probability 1/2 each), uniformly in the region (at its centre for
    ``motion="stationary"``), at orientation 0 or, for ``motion="rotating"``, uniform in
    [0, 2 pi).  The agent drives and aims its range sensor, whose beams are occluded and
    reflected by the target like any wall, and ends the episode by declaring G or H.  The
    exact recognizable region ``R(G) n R(H) - C(G, H)`` is where the readings are guaranteed
    to tell the two apart.  The target's side and pose are never part of the observation:
    only the beams it reflects.

    ## Action Space
    ``action_type="continuous"`` (default): ``Box(-1, 1, (4,), float32)``.

    | Index | Action  | Min | Max | Effect                                                 |
    |-------|---------|-----|-----|--------------------------------------------------------|
    | 0     | forward | -1  | 1   | ``max_speed * a`` along the heading (robot frame)      |
    | 1     | lateral | -1  | 1   | ``max_speed * a`` to the robot's left (robot frame)    |
    | 2     | turn    | -1  | 1   | ``max_turn * a`` radians, counter-clockwise            |
    | 3     | decide  | -1  | 1   | ``< -1/3``: point at G, ``> 1/3``: at H, else continue |

    Driving is as in Navigate-v0 (``max_speed`` 3 % of the diameter per step, ``max_turn``
    pi/8; translate swept against walls, obstacles and the target, then turn).  A label
    pointed at on ``declare_hold`` consecutive steps (default 1) is declared: the declaring
    step still moves first, then the declaration ends the episode.  ``declare_hold=3`` or
    more keeps an exploring policy from ending episodes by accident.  Out-of-range values
    are clipped; NaN/inf or a wrong shape raise ``ValueError``.  ``action_type="discrete"``:
    ``Discrete(9)``: 0 stay, 1 forward, 2 backward, 3 left, 4 right, 5 turn left, 6 turn
    right, 7 point at G, 8 point at H.

    ## Observation Space
    As Navigate-v0; the hidden target shows only in the beams it reflects.

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
    ``-step_cost`` (0.01) every step; ``+1`` for a right declaration, ``-1`` for a wrong
    one; the step that reaches the time limit without a declaration gets ``-1`` (a timeout
    counts as wrong; applied by the env itself, so it holds under ``gym.make``, ``make_vec``
    and direct construction alike).  Optional potential-based shaping for training,
    ``shaping * (d_before - d_after) / diameter`` with ``d`` the distance to the exact
    recognizable region (a map quantity: it says nothing about where the target is);
    ``shaping=0`` by default.

    ## Starting State
    The robot starts at the scene's ``start`` pose (world frame, radians); when that pose
    already recognizes or cannot reach the region, at a start drawn once with a fixed
    generator (free, outside the region, reaching it).  ``random_start=True`` draws such a
    start at every reset from the env's ``np_random``.  Then the target is hidden as
    described above (re-drawn up to 20 times to keep clear of the robot).  With
    ``scene="random"`` each reset draws a scene from the pool first.

    ## Episode End
    * Termination: a declaration (G or H).
    * Truncation: ``max_steps`` steps (default 200, also the registered
      ``max_episode_steps``), with the timeout penalty above.

    ``info``: ``is_success`` (declared and right), ``declared`` (``None``, ``"G"`` or
    ``"H"``), ``recognizing`` (the pose is in the exact recognizable region with a valid
    aim), ``distance_to_region`` (scene units), ``collided``, ``pose``; at the end of an
    episode also ``target_in`` (``"G"`` or ``"H"``): evaluation data, never observed.

    ## Arguments
    ```python
    import gymnasium as gym
    env = gym.make(
        "sensorplan_gym:sensorplan/Recognize-v0", scene="lab", map_ranges=True, declare_hold=3
    )
    envs = gym.make_vec("sensorplan_gym:sensorplan/Recognize-v0", num_envs=256, scene="random",
                        vectorization_mode="vector_entry_point")
    ```

    Recognize's own: ``step_cost`` (0.01), ``shaping`` (0.0), ``declare_hold`` (1, a positive
    integer), ``max_speed`` (``None``: 3 % of the diameter per step), ``max_turn`` (pi/8),
    ``random_start`` (False), ``speed_limit`` (``"box"`` | ``"disc"``, as in Navigate-v0).
    ``map_ranges`` / ``map_evidence`` / ``sensor_fov`` (False) add
    the observation entries above (``obs_type="vector"`` only).
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
      ``declare_hold``; potential ``shaping``; ``max_steps``; scene pools
      (``scene="random"``, ``scene_pool_size``, ``scene_pool_seed``,
      ``min_start_distance``); a drawn start when a fixed scene's own start already
      recognizes.
    """

    batch_cls = RecognizeBatch

    @property
    def _side(self) -> str:
        """Where the hidden target is ("G" or "H"): for tests and evaluation only."""
        return _LABEL[self.batch.side[0]]

    @property
    def _target_poly(self) -> np.ndarray | None:
        return self.batch.target_polys[0]

"""The batched watch task: ``E`` copies of ``watch_v0`` with ``A`` watchers each, held in
arrays and stepped by one call.

The watchers are the rows ``i = e * A + a`` of one batch (copy ``e``, watcher ``a``); robot
A of copy ``e`` is an extra moving obstacle of that copy (its edges: row ``e`` of per-copy
segment arrays).  :class:`WatchBatch` owns the per-copy state (A's trajectory, the elapsed
steps, declarations, counters, one random generator per copy) and the mechanics:

* :meth:`WatchBatch.reset_envs` -- A's motion and the watchers' starts (shapely, per copy;
  from the copy's generator, in the order the task documents), then the first reading;
* :meth:`WatchBatch.step_envs` -- A moves along its trajectory; every watcher drives (swept
  against the map and A), senses (ranges against the map and A, the map's prediction) and
  is tested for seeing A; declarations and rewards.

With numba the drive, the casts and the visibility filter are one compiled call
(:mod:`.kernels`, over the single-agent kernels of :mod:`sensorplan_gym.core.fused`); the
"sees A" answers the filter cannot certify (a margin not met, or the partial model) come from
the exact shapely predicate :meth:`~.world.WatchWorld.sees`.  Without numba (or with
``fused = False``) the numpy path runs: the same expressions in the same order (so bitwise
the same ranges, poses and observations) and :meth:`WatchWorld.sees` for every watcher.

The PettingZoo env (:class:`~.env.WatchParallelEnv`) is the batch of one; the vector env
(:class:`~.vector.WatchVectorEnv`) the batch of ``E``.  Copy ``e`` draws only from its own
generator ``rngs[e]`` (A's motion, the random starts, the range noise), so a copy of a
batch seeded ``s`` produces exactly what ``watch_v0.parallel_env`` seeded ``s`` produces.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import shapely
from gymnasium import spaces
from gymnasium.utils import seeding

from ..core import fused as core_fused
from ..core.collision import sweep_batch
from ..core.kernels import cast, libm
from ..core.segments import boundary_segments, segment_normals
from ..core.sensor import RangeSensor, add_noise
from ..core.world import load_scene
from . import kernels as wk
from .motion import MotionConfig, Trajectory, plan_trajectory
from .world import WatchConfig, WatchWorld, get_watch_world

__all__ = ["REWARD_MODES", "WatchBatch", "DECLARE_CODES"]

REWARD_MODES = ("individual", "team")
#: a declaration's code in the observation and the arrays (0: none)
DECLARE_CODES = {None: 0, "G": -1, "H": 1}
_NAMES = {0: None, -1: "G", 1: "H"}
TWO_PI = 2 * math.pi


class WatchBatch:
    """``n_envs`` copies of the watch task (keyword arguments as
    :class:`~.env.WatchParallelEnv`, less ``render_mode``); see the module docstring.

    Arrays (``E`` copies, ``A`` watchers, ``N = E A`` rows, ``B`` beams): ``P (3, N)``
    watcher poses ``x, y, psi`` (world frame, radians); ``Q (E, 2)`` A's reference point;
    ``t (E,)`` elapsed steps; ``declared (E, A)`` codes (:data:`DECLARE_CODES`);
    ``collided``, ``sees``, ``inside`` ``(N,)``; ``scan_dist``, ``scan_hit (N, B)``,
    ``scan_normal (N, B, 2)`` the readings and ``map_dist (N, B)`` the map's prediction.
    """

    def __init__(
        self,
        n_envs: int = 1,
        scene: Any = "lab",
        *,
        n_watchers: int = 1,
        model: str = "complete",
        fov_deg: float | None = None,
        max_range: float | None = None,
        n_beams: int = 16,
        noise: float = 0.0,
        robot_radius: float = 0.0,
        max_speed: float | None = None,
        max_turn: float = math.pi / 8,
        max_steps: int = 100,
        move_steps: int = 50,
        p_fail: float = 0.5,
        drift: float = 0.02,
        speed_noise: float = 0.2,
        reward: str = "individual",
        see_reward: float = 0.01,
        random_start: bool = True,
    ) -> None:
        if not isinstance(n_envs, (int, np.integer)) or n_envs < 1:
            raise ValueError(f"n_envs must be a positive integer, got {n_envs!r}")
        if not isinstance(n_watchers, (int, np.integer)) or n_watchers < 1:
            raise ValueError(f"n_watchers must be a positive integer, got {n_watchers!r}")
        if not isinstance(n_beams, (int, np.integer)) or n_beams < 1:
            raise ValueError(f"n_beams must be a positive integer, got {n_beams!r}")
        if not isinstance(max_steps, (int, np.integer)) or max_steps < 1:
            raise ValueError(f"max_steps must be a positive integer, got {max_steps!r}")
        if reward not in REWARD_MODES:
            raise ValueError(f"reward must be one of {REWARD_MODES}, got {reward!r}")
        for name, v in (
            ("noise", noise),
            ("robot_radius", robot_radius),
            ("see_reward", see_reward),
        ):
            if not isinstance(v, (int, float)) or not math.isfinite(v) or v < 0:
                raise ValueError(f"{name} must be a finite non-negative number, got {v!r}")
        for name, v in (("max_speed", max_speed), ("max_turn", max_turn)):
            if v is not None and (
                not isinstance(v, (int, float)) or not math.isfinite(v) or v <= 0
            ):
                raise ValueError(f"{name} must be a positive number, got {v!r}")
        if not isinstance(random_start, bool):
            raise ValueError(f"random_start must be True or False, got {random_start!r}")
        for name, v in (("fov_deg", fov_deg), ("max_range", max_range)):
            if v is not None and not isinstance(v, (int, float)):
                raise ValueError(f"{name} must be a number or None, got {v!r}")
        self.motion_cfg = MotionConfig(
            move_steps=int(move_steps), p_fail=p_fail, drift=drift, speed_noise=speed_noise
        ).validate()
        if move_steps >= max_steps:
            raise ValueError(
                f"move_steps ({move_steps}) must be smaller than max_steps ({max_steps}): "
                "A must have settled before the verdict is due"
            )
        self.scene = load_scene(scene)
        cfg = WatchConfig(
            model=model,
            fov=None if fov_deg is None else math.radians(float(fov_deg)),
            max_range=None if max_range is None else float(max_range),
        )
        self.world: WatchWorld = get_watch_world(self.scene, cfg)
        self.n_envs = E = int(n_envs)
        self.n_watchers = A = int(n_watchers)
        self.n = N = E * A
        self.n_beams = B = int(n_beams)
        self.noise = float(noise)
        self.robot_radius = float(robot_radius)
        w = self.world
        self.max_speed = float(max_speed) if max_speed is not None else 0.03 * w.diameter
        self.max_turn = float(max_turn)
        self.max_steps = int(max_steps)
        self.move_steps = int(move_steps)
        self.reward_mode = reward
        self.see_reward = float(see_reward)
        self.random_start = random_start
        self.sensor = RangeSensor(B, w.fov, w.reach, self.noise)
        self._robot_space = (
            w.free_space.buffer(-self.robot_radius) if self.robot_radius > 0 else w.free_space
        )
        shapely.prepare(self._robot_space)
        self._fixed_starts: list | None = None
        k = 8 + 4 * B + 3 + 2 * (A - 1)
        low = np.concatenate(
            [
                -np.ones(8),
                np.zeros(B),
                -np.ones(2 * B),
                np.zeros(B),
                [0, 0, -1],
                -np.ones(2 * (A - 1)),
            ]
        ).astype(np.float32)
        self.single_observation_space = spaces.Box(low, np.ones(k, dtype=np.float32))
        self.obs_dim = k
        self._low = low
        #: run the compiled kernels (numba installed); ``False`` forces the numpy path
        self.fused = core_fused.FUSED
        self._build_static()
        # ---- per-copy and per-watcher state ----
        self.rngs: list[np.random.Generator] = [seeding.np_random(None)[0] for _ in range(E)]
        self.trajs: list[Trajectory | None] = [None] * E
        T = self.motion_cfg.move_steps
        self.TRJ = np.zeros((E, T + 1, 2))
        self.t = np.zeros(E, dtype=np.int64)
        self.Q = np.zeros((E, 2))
        self.P = np.zeros((3, N))
        self.declared = np.zeros((E, A), dtype=np.int64)
        #: A's hidden outcome per copy (-1 G, +1 H), set at its reset
        self.truth = np.zeros(E, dtype=np.int64)
        self.collided = np.zeros(N, dtype=bool)
        self.sees = np.zeros(N, dtype=bool)
        self.inside = np.zeros(N, dtype=bool)
        self.code = np.zeros(N, dtype=np.int64)
        self.seen_steps = np.zeros((E, A), dtype=np.int64)
        self.team_seen_steps = np.zeros(E, dtype=np.int64)
        self.scan_dist = np.zeros((N, B))
        self.scan_normal = np.zeros((N, B, 2))
        self.scan_hit = np.zeros((N, B), dtype=bool)
        self.map_dist = np.zeros((N, B))
        self.started = np.zeros(E, dtype=bool)
        self._memo: list[tuple | None] = [None] * N
        self._obs_consts = np.tile(self._consts, (N, 1))
        #: sees-A answers taken from the exact predicate (the filter's UNSURE, or numpy)
        self.n_exact_sees = 0

    # ---- static data ---------------------------------------------------------------------
    def _build_static(self) -> None:
        w = self.world
        E, B = self.n_envs, self.n_beams
        # the map's edges, normals into the free space (exteriors ccw, holes cw): culling
        segs = boundary_segments(shapely.orient_polygons(w.free_space))
        nrm = segment_normals(segs)
        m0 = len(segs)
        self._m0 = m0
        ss = np.zeros((6, 1, m0))
        ss[0, 0], ss[1, 0] = segs[:, 0], segs[:, 1]
        ss[2, 0], ss[3, 0] = segs[:, 2] - segs[:, 0], segs[:, 3] - segs[:, 1]
        ss[4, 0], ss[5, 0] = nrm[:, 0], nrm[:, 1]
        self.SS = ss
        tgt = np.ascontiguousarray(w.target, dtype=np.float64)
        self._tgt = tgt
        K = len(tgt)
        te = np.roll(tgt, -1, axis=0) - tgt
        tn = np.stack([-te[:, 1], te[:, 0]], axis=1)  # left normals
        L = np.hypot(tn[:, 0], tn[:, 1])
        L[L == 0] = 1.0
        tn = tn / L[:, None]
        self._tnrm = np.ascontiguousarray(-tn if _area2(tgt) > 0 else tn)  # out of A
        hull = np.asarray(w.hull, dtype=np.float64)
        self._hull = np.ascontiguousarray(hull if _area2(hull) > 0 else hull[::-1])  # ccw
        self.S = np.zeros((6, E, m0 + K))  # the sweep's: the map, then A
        self.S[:, :, :m0] = ss
        self.SA_out = np.zeros((6, E, K))
        self.SA_in = np.zeros((6, E, K))
        self.AR = np.zeros((4, E, K))
        off = self.sensor.offsets
        self.OFF = np.zeros((3, E, B))
        self.OFF[:] = np.stack([np.cos(off), np.sin(off), off])[:, None, :]
        self.prm = np.zeros(len(wk.W_NAMES))
        self.prm[wk.W_MAX_SPEED] = self.max_speed
        self.prm[wk.W_MAX_TURN] = self.max_turn
        self.prm[wk.W_SKIN] = w.skin
        self.prm[wk.W_REACH] = w.reach
        self.prm[wk.W_EPS] = 1e-9 * w.diameter
        self.prm[wk.W_FOV] = w.fov
        self.prm[wk.W_MAX_RANGE] = w.max_range
        self.prm[wk.W_COMPLETE] = float(w.model == "complete")
        self.prm[wk.W_FULL_FOV] = float(w.full_fov)
        self.prm[wk.W_DRIVE] = float(self.robot_radius == 0.0)
        self._HP = np.zeros((5, len(self._hull) + 2))
        gc = np.asarray(w.goal_geom.centroid.coords[0], dtype=np.float64)
        hc = np.asarray(w.failure_geom.centroid.coords[0], dtype=np.float64)
        span = w.hi - w.lo
        self._consts = np.array(
            [*w.lo, 2.0 / span[0], 2.0 / span[1], 1.0 / w.diameter, 1.0 / w.reach, *gc, *hc]
        )

    # ---- randomness ------------------------------------------------------------------------
    def seed_env(self, e: int, seed: int | None) -> None:
        """Re-seed copy ``e`` (``None``: fresh OS entropy)."""
        self.rngs[e] = seeding.np_random(None if seed is None else int(seed))[0]

    # ---- reset -----------------------------------------------------------------------------
    def reset_envs(self, idx: np.ndarray) -> None:
        """A new episode for the copies ``idx`` (sorted, distinct): A's motion, the
        watchers' starts, the first readings."""
        idx = np.asarray(idx, dtype=np.int64)
        A = self.n_watchers
        w = self.world
        for e in idx.tolist():
            rng = self.rngs[e]
            traj = plan_trajectory(w, self.motion_cfg, rng)
            self.trajs[e] = traj
            self.truth[e] = DECLARE_CODES[traj.outcome]
            self.TRJ[e] = traj.pos
            self.t[e] = 0
            self.Q[e] = traj.pos[0]
            poses = self._start_poses(rng, w.target_at(traj.pos[0]))
            self.P[:, e * A : (e + 1) * A] = np.asarray(poses, dtype=np.float64).T
            self.declared[e] = 0
            self.seen_steps[e] = 0
            self.team_seen_steps[e] = 0
            self.started[e] = True
            for i in range(e * A, (e + 1) * A):
                self._memo[i] = None
        rows = self._rows(idx)
        self.collided[rows] = False
        self._set_a(idx)
        self._move_sense(idx, None)

    def _start_poses(self, rng, a_poly) -> list[tuple[float, float, float]]:
        if not self.random_start:
            if self._fixed_starts is None:
                fixed_rng = np.random.default_rng(12345)
                poses = []
                s = self.scene.start
                if s is not None and shapely.contains_xy(self._robot_space, s[0], s[1]):
                    poses.append((float(s[0]), float(s[1]), float(s[2])))
                while len(poses) < self.n_watchers:
                    poses.append(self.draw_pose(fixed_rng, poses, None))
                self._fixed_starts = poses
            return list(self._fixed_starts)
        poses: list[tuple[float, float, float]] = []
        a_poly = shapely.Polygon(a_poly)
        shapely.prepare(a_poly)
        while len(poses) < self.n_watchers:
            poses.append(self.draw_pose(rng, poses, a_poly))
        return poses

    def draw_pose(self, rng, others, a_poly=None) -> tuple[float, float, float]:
        """A uniform free pose (rejection from the bounding box) away from the poses
        ``others`` and -- unless ``a_poly`` is None -- from A's outline ``a_poly`` (``(K, 2)``
        vertices or a polygon)."""
        w = self.world
        A = a_poly if a_poly is None or isinstance(a_poly, shapely.Geometry) else None
        if A is None and a_poly is not None:
            A = shapely.Polygon(a_poly)
        gap = self.robot_radius + 0.02 * w.diameter
        for _ in range(10_000):
            x = rng.uniform(w.lo[0], w.hi[0])
            y = rng.uniform(w.lo[1], w.hi[1])
            if not shapely.contains_xy(self._robot_space, x, y):
                continue
            if A is not None and A.distance(shapely.Point(x, y)) <= gap:
                continue
            if any(math.hypot(x - o[0], y - o[1]) < 2 * gap for o in others):
                continue
            return (float(x), float(y), float(rng.uniform(-math.pi, math.pi)))
        raise RuntimeError(f"scene {self.scene.name!r}: no free start pose for a watcher")

    # ---- step ------------------------------------------------------------------------------
    def check_actions(self, actions: Any, k: int) -> np.ndarray:
        """``(k, 4)`` float64 actions, validated and clipped to [-1, 1]."""
        try:
            a = np.array(actions, dtype=np.float64)
        except (TypeError, ValueError) as e:
            raise ValueError(
                f"action must be a numeric array of shape (4,), got {actions!r}"
            ) from e
        if a.shape != (k, 4):
            raise ValueError(f"actions must have shape ({k}, 4) (a row per watcher), got {a.shape}")
        if self.fused and core_fused.clip_unit(a):
            return a
        if not np.isfinite(a).all():
            raise ValueError(f"action contains NaN or infinite values: {a.tolist()}")
        return np.clip(a, -1.0, 1.0)

    def step_envs(self, act: np.ndarray, idx: np.ndarray):
        """One step of the copies ``idx`` (sorted, distinct) with the clipped actions ``act
        (len(idx) * A, 4)`` (copy by copy, watcher by watcher).  Returns ``(rewards (k, A),
        done (k,), decl_r (k, A))`` -- ``done``: the horizon is reached (every watcher is
        terminated)."""
        idx = np.asarray(idx, dtype=np.int64)
        A = self.n_watchers
        k = len(idx)
        if self.fused:
            wk.advance(idx, self.t, self.Q, self.TRJ)
            self._set_a(idx)
            self._move_sense(idx, act)
            rew = np.empty((k, A))
            decl_r = np.empty((k, A))
            done = np.empty(k, dtype=bool)
            wk.watch_rules(idx, A, act, self.t, self.max_steps, self.truth, self.declared,
                           self.sees, self.seen_steps, self.team_seen_steps, self.see_reward,
                           rew, decl_r, done)  # fmt: skip
            if self.reward_mode == "team":
                anyone = self.sees[self._rows(idx)].reshape(k, A).any(axis=1)
                r = self.see_reward * anyone + np.mean(decl_r, axis=1)
                rew = np.repeat(r[:, None], A, axis=1)
            return rew, done, decl_r
        sel = slice(None) if len(idx) == self.n_envs else idx  # views when every copy steps
        t = self.t[sel]
        t += 1
        self.t[sel] = t
        self.Q[sel] = self.TRJ[idx, np.minimum(t, self.motion_cfg.move_steps)]
        self._set_a(idx)
        self._move_sense(idx, act)
        d = act[:, 3].reshape(k, A)
        lo, hi = d < -1 / 3, d > 1 / 3
        done = t >= self.max_steps
        decl_r = np.zeros((k, A))
        dec = self.declared[sel]
        if lo.any() or hi.any():
            want = np.where(lo, -1, np.where(hi, 1, 0))
            new = (dec == 0) & (want != 0)
            if new.any():
                dec = np.where(new, want, dec)
                self.declared[sel] = dec
                truth = self.truth[idx][:, None]
                decl_r = np.where(new, np.where(want == truth, 1.0, -1.0), 0.0)
        if done.any():
            decl_r = np.where(done[:, None] & (dec == 0), -1.0, decl_r)
        sees = self.sees[self._rows(idx)].reshape(k, A)
        self.seen_steps[sel] += sees
        anyone = sees.any(axis=1)
        self.team_seen_steps[sel] += anyone
        if self.reward_mode == "individual":
            rew = self.see_reward * sees + decl_r
        else:
            r = self.see_reward * anyone + np.mean(decl_r, axis=1)
            rew = np.repeat(r[:, None], A, axis=1)
        return rew, done, decl_r

    def _rows(self, idx: np.ndarray) -> np.ndarray | slice:
        A = self.n_watchers
        if len(idx) == self.n_envs:
            return slice(None)
        return (idx[:, None] * A + np.arange(A)).ravel()

    def _set_a(self, idx: np.ndarray) -> None:
        if self.fused:
            wk.set_a(idx, self.Q, self._tgt, self._tnrm, self._m0, self.S, self.SA_out,
                     self.SA_in, self.AR)  # fmt: skip
            return
        tgt, m0 = self._tgt, self._m0
        V = tgt[None, :, :] + self.Q[idx][:, None, :]  # (k, K, 2)
        V1 = tgt[None, np.r_[1 : len(tgt), 0], :] + self.Q[idx][:, None, :]
        ex = V1[:, :, 0] - V[:, :, 0]
        ey = V1[:, :, 1] - V[:, :, 1]
        nx = np.broadcast_to(self._tnrm[:, 0], ex.shape)
        ny = np.broadcast_to(self._tnrm[:, 1], ex.shape)
        rows = np.stack([V[:, :, 0], V[:, :, 1], ex, ey, nx, ny])
        self.S[:, idx, m0:] = rows
        self.SA_out[:, idx] = rows
        rows_in = rows.copy()
        rows_in[4:] = -rows_in[4:]
        self.SA_in[:, idx] = rows_in
        self.AR[:, idx] = np.stack([V[:, :, 0], V[:, :, 1], V1[:, :, 0], V1[:, :, 1]])

    def _move_sense(self, idx: np.ndarray, act: np.ndarray | None) -> None:
        """Drive (``act`` not None), sense and sees-A of the watchers of copies ``idx``."""
        rows = self._rows(idx)
        if act is not None and self.robot_radius > 0.0:
            self._drive_disc(idx, act)
        if self.fused:
            prm = self.prm
            if act is None or self.robot_radius > 0.0:
                prm = prm.copy()
                prm[wk.W_DRIVE] = 0.0
            a = act if act is not None else np.zeros((len(idx) * self.n_watchers, 4))
            wk.watch_step(
                idx, self.n_watchers, a, prm, self.P, self.Q, self._tgt, self._hull, self.S,
                self.SA_out, self.SA_in, self.AR, self.SS, self.OFF, self.scan_dist,
                self.scan_normal, self.scan_hit, self.map_dist, self.collided, self.inside,
                self.code, self._HP,
            )  # fmt: skip
        else:
            if act is not None and self.robot_radius == 0.0:
                self._drive_numpy(idx, act, 0.0)
            self._sense_numpy(idx)
        if self.noise > 0:
            self._add_noise(idx, rows)
        self._sees(idx)

    def _env_of(self, idx: np.ndarray) -> np.ndarray:
        return np.repeat(idx, self.n_watchers)

    def _drive_numpy(self, idx, act, radius: float) -> None:
        rows = self._rows(idx)
        envs = self._env_of(idx)
        x, y, psi = self.P[0, rows], self.P[1, rows], self.P[2, rows]
        c, s = libm(math.cos, psi), libm(math.sin, psi)
        v = self.max_speed
        a0, a1 = act[:, 0], act[:, 1]
        dx = v * (c * a0 - s * a1)
        dy = v * (s * a0 + c * a1)
        t = sweep_batch(x, y, dx, dy, _Rows(self.S, envs), radius, np.full(len(x), self.world.skin))
        self.P[0, rows] = x + t * dx
        self.P[1, rows] = y + t * dy
        self.P[2, rows] = (psi + self.max_turn * act[:, 2] + math.pi) % TWO_PI - math.pi
        self.collided[rows] = t < 1.0

    def _drive_disc(self, idx, act) -> None:
        """Disc watchers: the capsule sweep (numpy, both paths)."""
        self._drive_numpy(idx, act, self.robot_radius)

    def _sense_numpy(self, idx: np.ndarray) -> None:
        rows = self._rows(idx)
        envs = self._env_of(idx)
        x, y, psi = self.P[0, rows], self.P[1, rows], self.P[2, rows]
        c, s = libm(math.cos, psi)[:, None], libm(math.sin, psi)[:, None]
        co, so = self.OFF[0][envs], self.OFF[1][envs]
        dx, dy = co * c - so * s, so * c + co * s
        reach = np.full(len(x), self.world.reach)
        ss = self.SS
        dist, hit, gx, gy = cast(x, y, dx, dy, *ss[:, 0][:, None, :], reach, True)
        self.map_dist[rows] = dist
        polys = shapely.polygons(np.moveaxis(self.AR[:2, envs], 0, -1))
        inside = shapely.contains_xy(polys, x, y)
        self.inside[rows] = inside
        SA = np.where(inside[None, :, None], self.SA_in[:, envs], self.SA_out[:, envs])
        ad, ah, agx, agy = cast(x, y, dx, dy, *SA, reach, True)
        take = ah & (~hit | (ad < dist))
        self.scan_dist[rows] = np.where(take, ad, dist)
        self.scan_hit[rows] = hit | ah
        nrm = np.empty((*dist.shape, 2))
        nrm[..., 0] = np.where(take, agx, gx)
        nrm[..., 1] = np.where(take, agy, gy)
        self.scan_normal[rows] = nrm
        self.code[rows] = wk.UNSURE

    def _add_noise(self, idx: np.ndarray, rows) -> None:
        """Range noise from each copy's generator (``A x B`` normals per copy and reading,
        watcher by watcher), truncated and clipped (:func:`.sensor.add_noise`)."""
        z = np.concatenate(
            [self.rngs[e].standard_normal((self.n_watchers, self.n_beams)) for e in idx.tolist()]
        )
        self.scan_dist[rows] = add_noise(
            self.scan_dist[rows], self.scan_hit[rows], z, self.noise, self.world.reach
        )

    def _sees(self, idx: np.ndarray) -> None:
        """``sees`` of the watchers of copies ``idx``: the filter's certain answers, the exact
        predicate for the rest (memoised while neither the watcher nor A moves)."""
        rows = self._rows(idx)
        code = self.code[rows]
        self.sees[rows] = code == wk.SEES_YES
        unsure = np.flatnonzero(code == wk.UNSURE)
        if not len(unsure):
            return
        all_rows = np.arange(self.n)[rows]
        A = self.n_watchers
        w = self.world
        for i in all_rows[unsure].tolist():
            e = i // A
            pose = (float(self.P[0, i]), float(self.P[1, i]), float(self.P[2, i]))
            key = (pose, float(self.Q[e, 0]), float(self.Q[e, 1]))
            memo = self._memo[i]
            if memo is not None and memo[0] == key:
                s = memo[1]
            else:
                s = w.sees(pose, self.Q[e])
                self._memo[i] = (key, s)
                self.n_exact_sees += 1
            self.sees[i] = s

    # ---- observations ----------------------------------------------------------------------
    def observe(self, idx: np.ndarray) -> np.ndarray:
        """Observations ``(len(idx) * A, D)`` float32 of the watchers of copies ``idx``."""
        idx = np.asarray(idx, dtype=np.int64)
        out = np.empty((len(idx) * self.n_watchers, self.obs_dim), dtype=np.float32)
        if self.fused:
            wk.obs_kernel(idx, self.n_watchers, self.P, self._obs_consts, self.scan_dist,
                          self.scan_normal, self.map_dist, self.t, self.declared,
                          self.max_steps, self.move_steps, self._low, out)  # fmt: skip
            return out
        A = self.n_watchers
        tail = np.empty((self.n_envs, 2 + A))
        tail[idx, 0] = self.t[idx] / self.max_steps
        tail[idx, 1] = (self.t[idx] >= self.move_steps).astype(np.float64)
        tail[idx, 2:] = self.declared[idx]
        self._observe_numpy(idx, tail, out)
        return np.clip(out, self._low, 1.0, out=out)

    def _observe_numpy(self, idx, tail, out) -> None:
        """:func:`.kernels.obs_kernel` with numpy (the same expressions; clipped after)."""
        rows = self._rows(idx)
        envs = self._env_of(idx)
        A, B = self.n_watchers, self.n_beams
        K = self._consts
        x, y, psi = self.P[0, rows], self.P[1, rows], self.P[2, rows]
        c, s = libm(math.cos, psi), libm(math.sin, psi)
        out[:, 0] = np.clip((x - K[0]) * K[2] - 1.0, -1.0, 1.0)
        out[:, 1] = np.clip((y - K[1]) * K[3] - 1.0, -1.0, 1.0)
        out[:, 2] = c
        out[:, 3] = s
        for g in range(2):
            gx = K[6 + 2 * g] - x
            gy = K[7 + 2 * g] - y
            out[:, 4 + 2 * g] = (c * gx + s * gy) * K[4]
            out[:, 5 + 2 * g] = (c * gy - s * gx) * K[4]
        sd, sn = self.scan_dist[rows], self.scan_normal[rows]
        cc, ss = c[:, None], s[:, None]
        out[:, 8 : 8 + B] = sd * K[5]
        out[:, 8 + B : 8 + 2 * B] = cc * sn[..., 0] + ss * sn[..., 1]
        out[:, 8 + 2 * B : 8 + 3 * B] = cc * sn[..., 1] - ss * sn[..., 0]
        out[:, 8 + 3 * B : 8 + 4 * B] = self.map_dist[rows] * K[5]
        base = 8 + 4 * B
        out[:, base] = tail[envs, 0]
        out[:, base + 1] = tail[envs, 1]
        out[:, base + 2] = tail[idx, 2:].ravel()
        # the other watchers of the copy, in the watcher's frame / diameter
        X, Y, C, S = (v.reshape(-1, A) for v in (x, y, c, s))
        view = out.reshape(-1, A, self.obs_dim)
        for w_ in range(A):
            j = base + 3
            for o in range(A):
                if o == w_:
                    continue
                gx = X[:, o] - X[:, w_]
                gy = Y[:, o] - Y[:, w_]
                view[:, w_, j] = (C[:, w_] * gx + S[:, w_] * gy) * K[4]
                view[:, w_, j + 1] = (C[:, w_] * gy - S[:, w_] * gx) * K[4]
                j += 2

    # ---- one copy, for the PettingZoo env and rendering -------------------------------------
    def pose(self, i: int) -> tuple[float, float, float]:
        return (float(self.P[0, i]), float(self.P[1, i]), float(self.P[2, i]))

    def info(self, e: int, a: int, final: bool = False) -> dict[str, Any]:
        """The info dict of watcher ``a`` of copy ``e`` (see :mod:`.env`)."""
        i = e * self.n_watchers + a
        dec = _NAMES[int(self.declared[e, a])]
        info = {
            "sees": bool(self.sees[i]),
            "declared": dec,
            "collided": bool(self.collided[i]),
            "pose": self.pose(i),
        }
        if final:
            outcome = self.trajs[e].outcome
            info["is_success"] = dec == outcome
            info["a_ends_in"] = outcome
            info["visible_fraction"] = int(self.seen_steps[e, a]) / self.max_steps
            info["team_visible_fraction"] = int(self.team_seen_steps[e]) / self.max_steps
        return info

    def __setstate__(self, st: dict) -> None:
        self.__dict__.update(st)
        shapely.prepare(self._robot_space)


def _area2(v: np.ndarray) -> float:
    """Twice the signed area of the polygon with vertices ``v (K, 2)`` (> 0: counter-clockwise)."""
    return float(np.sum(v[:, 0] * np.roll(v[:, 1], -1) - np.roll(v[:, 0], -1) * v[:, 1]))


class _Rows:
    """Rows ``envs`` of a ``(6, E, M)`` segment array as :func:`.collision.sweep_batch` reads
    them."""

    __slots__ = ("x0", "y0", "ex", "ey", "nx", "ny")

    def __init__(self, S: np.ndarray, envs: np.ndarray) -> None:
        self.x0, self.y0, self.ex, self.ey, self.nx, self.ny = S[:, envs]

"""``watch_v0``: watcher robots keep robot A in view and tell whether it ended in G or H.

The paper's first motivation (Briggs & Donald, section 1): robot A performs a task, robot B
carries a sensor and must "watch" A; in EDR terms (1.1, 5) B must also tell whether A's
motion plan ended in the goal G or in the failure region H.  Here A is scripted
(:mod:`sensorplan_gym.multiagent.motion`: a plan toward G with bounded drift that sometimes
ends in H) and ``n_watchers`` watcher robots are the agents.

Agents ``watcher_0 .. watcher_{n-1}`` (all act every step; PettingZoo ``ParallelEnv``).

Action (per watcher)
    ``Box(-1, 1, (4,), float32)`` = ``(forward, lateral, turn, decide)`` as in
    ``Recognize-v0``: the watcher translates by ``max_speed * (forward, lateral)`` in its own
    frame (swept against walls, obstacles and A's current outline: it stops at contact),
    then turns by ``max_turn * turn``.  ``decide < -1/3`` declares **G**, ``> 1/3`` declares
    **H**; only a watcher's first declaration counts (later ``decide`` values are ignored);
    a watcher keeps moving and watching after it has declared.  Out-of-range values are
    clipped; NaN/inf, a wrong shape or a missing live agent raise ``ValueError``.
Observation (per watcher, ``Box`` float32, length ``8 + 4 n_beams + 3 + 2 (n_watchers - 1)``)
    As Navigate/Recognize-v0 (position scaled to [-1, 1], ``cos/sin`` heading, vectors to the
    centres of G and H in the watcher's frame / diameter, ``n_beams`` ranges / reach and
    normals in the watcher's frame), then what the **map predicts** for the same beams (the
    ranges to walls and obstacles alone, / reach: a beam reading shorter than its prediction
    hit A), the elapsed fraction ``t / max_steps``, whether A's plan is over (``t >=
    move_steps``: a constant of the task, not of the outcome), the watcher's own declaration
    (0 none, -1 G, +1 H), and the other watchers' positions in its frame / diameter.  A's
    pose and outcome are never part of it: A shows only through the beams it reflects.
    ``evidence=True`` appends 4 entries in [0, 1): what the watcher's own beams have shown
    of A since A's plan is over, ``(seen_G, seen_H, looked_G, looked_H)``
    (:mod:`sensorplan_gym.multiagent.evidence`: saturating counts of the steps on which a
    short beam ended in ``A (+) G`` / ``A (+) H``, and on which a beam crossed them).
Reward (``reward="individual"``, default)
    ``see_reward`` (default 0.01) on every step at whose end the watcher *sees* A under the
    configured model (:meth:`WatchWorld.sees`: exact, from the geometry, with the field of
    view and range), plus +1 / -1 for a right / wrong declaration on the step it is made,
    and -1 at the horizon for a watcher that never declared.
    ``reward="team"``: every watcher gets ``see_reward`` if *some* watcher sees A, plus the
    mean of that step's declaration rewards over the watchers.
Episode
    A fixed horizon of ``max_steps`` steps (default 100) -- the verdict is due then, so every
    watcher is ``terminated`` at step ``max_steps`` (``truncated`` stays False).  A moves for
    ``move_steps`` (default 50) steps and then rests in G or H.
Info (per watcher)
    ``sees``, ``declared`` (None, "G" or "H"), ``collided``, ``pose``; at the end also
    ``is_success`` (declared right), ``a_ends_in`` ("G"/"H") and ``visible_fraction`` (the
    fraction of steps 1..max_steps on which this watcher saw A) and ``team_visible_fraction``.

Keyword arguments: ``scene`` (bundled name, JSON path, dict or Scene), ``n_watchers`` (1),
``model`` ("complete"/"partial"), ``fov_deg``, ``max_range``, ``n_beams`` (16), ``noise``
(range std), ``robot_radius`` (0), ``max_speed`` (None: 3% of the diameter per step),
``max_turn`` (pi/8), ``max_steps`` (100), ``move_steps`` (50), ``p_fail`` (0.5),
``drift`` (0.02 of the diameter), ``speed_noise`` (0.2), ``reward``, ``see_reward``,
``random_start`` (True: watchers start at seeded uniform free positions; False: watcher 0 at
the scene's ``start``, the others at fixed positions), ``render_mode`` (None/"rgb_array"),
``evidence`` (False).
The sensor has no placement/aim uncertainty here (``eps_pos``/``eps_aim`` are not modelled).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import shapely
from gymnasium import spaces
from gymnasium.utils import seeding

from ..core.sensor import RangeSensor, Segments, cast_rays
from ..core.world import load_scene, sweep
from .evidence import N_EVIDENCE, BeamEvidence
from .motion import MotionConfig, Trajectory, plan_trajectory
from .rendering import WatchRenderer
from .world import WatchConfig, WatchWorld, get_watch_world

try:  # PettingZoo is optional (extra "multi"); the env works without it
    from pettingzoo import ParallelEnv as _Base
except ImportError:  # pragma: no cover - exercised only without the extra

    class _Base:  # minimal stand-in with PettingZoo's derived properties
        @property
        def num_agents(self) -> int:
            return len(self.agents)

        @property
        def max_num_agents(self) -> int:
            return len(self.possible_agents)

        @property
        def unwrapped(self):
            return self


__all__ = ["WatchParallelEnv", "REWARD_MODES"]

REWARD_MODES = ("individual", "team")


class WatchParallelEnv(_Base):
    """The watch task as a PettingZoo ``ParallelEnv`` (see the module docstring)."""

    metadata = {
        "render_modes": ["rgb_array"],
        "name": "watch_v0",
        "is_parallelizable": True,
        "render_fps": 10,
    }

    def __init__(
        self,
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
        render_mode: str | None = None,
        evidence: bool = False,
    ) -> None:
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
        if not isinstance(evidence, bool):
            raise ValueError(f"evidence must be True or False, got {evidence!r}")
        if render_mode is not None and render_mode not in self.metadata["render_modes"]:
            raise ValueError(f"render_mode must be None or 'rgb_array', got {render_mode!r}")
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
        self.n_watchers = int(n_watchers)
        self.n_beams = int(n_beams)
        self.noise = float(noise)
        self.robot_radius = float(robot_radius)
        self.max_speed = float(max_speed) if max_speed is not None else 0.03 * self.world.diameter
        self.max_turn = float(max_turn)
        self.max_steps = int(max_steps)
        self.move_steps = int(move_steps)
        self.reward_mode = reward
        self.see_reward = float(see_reward)
        self.random_start = random_start
        self.render_mode = render_mode
        self.sensor = RangeSensor(self.n_beams, self.world.fov, self.world.reach, self.noise)
        self.possible_agents = [f"watcher_{i}" for i in range(self.n_watchers)]
        self.agents: list[str] = []
        w = self.world
        self._robot_space = (
            w.free_space.buffer(-self.robot_radius) if self.robot_radius > 0 else w.free_space
        )
        shapely.prepare(self._robot_space)
        n = self.n_beams
        n_ev = N_EVIDENCE if evidence else 0
        k = 8 + 4 * n + 3 + 2 * (self.n_watchers - 1) + n_ev
        low = np.concatenate(
            [
                -np.ones(8),
                np.zeros(n),
                -np.ones(2 * n),
                np.zeros(n),
                [0, 0, -1],
                -np.ones(2 * (self.n_watchers - 1)),
                np.zeros(n_ev),
            ]
        ).astype(np.float32)
        high = np.ones(k, dtype=np.float32)
        self._obs_space = spaces.Box(low, high, dtype=np.float32)
        self._obs_spaces = {a: self._obs_space for a in self.possible_agents}
        self._act_spaces = {
            a: spaces.Box(-1.0, 1.0, (4,), dtype=np.float32) for a in self.possible_agents
        }
        self.observation_spaces = self._obs_spaces
        self.action_spaces = self._act_spaces
        self.np_random, _ = seeding.np_random(None)
        self._renderer = None
        self.t = 0
        self.traj: Trajectory | None = None
        self.poses: list[tuple[float, float, float]] = []
        self._fixed_starts = None
        self._a_q = None
        self._gc = np.asarray(w.goal_geom.centroid.coords[0], dtype=np.float64)
        self._hc = np.asarray(w.failure_geom.centroid.coords[0], dtype=np.float64)
        span = w.hi - w.lo
        self._obs_consts = (float(w.lo[0]), float(w.lo[1]), 2.0 / span[0], 2.0 / span[1])
        self.evidence = (
            BeamEvidence(w.swept, self.n_watchers, 3 * self.noise + 1e-3 * w.reach)
            if evidence
            else None
        )

    # ---- PettingZoo API --------------------------------------------------------------------
    def observation_space(self, agent: str) -> spaces.Box:
        """The (same, shared) observation space object of every watcher."""
        return self._obs_spaces[agent]

    def action_space(self, agent: str) -> spaces.Box:
        """The action space object of ``agent`` (one object per agent, so seeding one does not
        seed the others)."""
        return self._act_spaces[agent]

    def reset(self, seed: int | None = None, options: dict | None = None):
        if seed is not None:
            self.np_random, _ = seeding.np_random(int(seed))
        rng = self.np_random
        w = self.world
        self.agents = list(self.possible_agents)
        self.t = 0
        self.traj = plan_trajectory(w, self.motion_cfg, rng)
        self._a_q = None
        self._memo = [None] * self.n_watchers
        self._set_a(self.traj.at(0))
        self.poses = self._start_poses(rng)
        self.declared: list[str | None] = [None] * self.n_watchers
        self.collided = [False] * self.n_watchers
        self.seen_steps = [0] * self.n_watchers
        self.team_seen_steps = 0
        self.trail = [self.traj.at(0).copy()]
        if self.evidence is not None:
            self.evidence.reset()
        self._sense()
        obs = {a: self._observe(i) for i, a in enumerate(self.agents)}
        infos = {a: self._info(i) for i, a in enumerate(self.agents)}
        return obs, infos

    def step(self, actions: dict[str, Any]):
        if not self.agents:
            raise RuntimeError("step() called on a finished episode; call reset() first")
        acts = []
        for a in self.agents:
            if a not in actions:
                raise ValueError(f"no action for live agent {a!r}")
            acts.append(self._check_action(actions[a]))
        unknown = set(actions) - set(self.agents)
        if unknown:
            raise ValueError(f"actions for agents that are not live: {sorted(unknown)}")
        self.t += 1
        q = self.traj.at(self.t)
        self._set_a(q)
        self.trail.append(q.copy())
        decl_r = [0.0] * self.n_watchers
        for i, act in enumerate(acts):
            self.collided[i] = self._move(i, act)
            d = act[3]
            if self.declared[i] is None and (d < -1 / 3 or d > 1 / 3):
                self.declared[i] = "G" if d < -1 / 3 else "H"
                decl_r[i] = 1.0 if self.declared[i] == self.traj.outcome else -1.0
        done = self.t >= self.max_steps
        if done:
            for i in range(self.n_watchers):
                if self.declared[i] is None:
                    decl_r[i] = -1.0
        self._sense()
        for i in range(self.n_watchers):
            self.seen_steps[i] += int(self.sees[i])
        any_sees = any(self.sees)
        self.team_seen_steps += int(any_sees)
        if self.reward_mode == "individual":
            rew = [
                self.see_reward * float(self.sees[i]) + decl_r[i] for i in range(self.n_watchers)
            ]
        else:
            r = self.see_reward * float(any_sees) + float(np.mean(decl_r))
            rew = [r] * self.n_watchers
        agents = self.agents
        obs = {a: self._observe(i) for i, a in enumerate(agents)}
        rewards = {a: float(rew[i]) for i, a in enumerate(agents)}
        terms = {a: bool(done) for a in agents}
        truncs = {a: False for a in agents}
        infos = {a: self._info(i, final=done) for i, a in enumerate(agents)}
        if done:
            self.agents = []
        return obs, rewards, terms, truncs, infos

    def render(self):
        if self.render_mode is None:
            import gymnasium

            gymnasium.logger.warn("render() called without a render_mode; pass render_mode=")
            return None
        if self._renderer is None:
            self._renderer = WatchRenderer()
        return self._renderer.render(self)

    def close(self) -> None:
        if self._renderer is not None:
            self._renderer.close()
            self._renderer = None

    def __getstate__(self) -> dict:
        st = self.__dict__.copy()
        st["_renderer"] = None
        return st

    def __setstate__(self, st: dict) -> None:
        self.__dict__.update(st)
        shapely.prepare(self._robot_space)

    # ---- internals ------------------------------------------------------------------------
    @property
    def a_position(self) -> np.ndarray:
        """A's reference point now (world frame) -- for rendering and tests, not observed."""
        return self.traj.at(self.t)

    def _set_a(self, q: np.ndarray) -> None:
        if self._a_q is not None and np.array_equal(q, self._a_q):
            return  # A rests: same outline, same segments
        self._a_q = np.array(q, dtype=np.float64)
        P = self.world.target_at(q)
        segs = np.concatenate([P, np.roll(P, -1, axis=0)], axis=1)
        self._a_poly = P
        self._segs = self.world.seg_set + Segments(segs)

    def _start_poses(self, rng: np.random.Generator) -> list[tuple[float, float, float]]:
        if not self.random_start:
            if self._fixed_starts is None:
                fixed_rng = np.random.default_rng(12345)
                poses = []
                s = self.scene.start
                if s is not None and shapely.contains_xy(self._robot_space, s[0], s[1]):
                    poses.append((float(s[0]), float(s[1]), float(s[2])))
                while len(poses) < self.n_watchers:
                    poses.append(self._draw_pose(fixed_rng, poses, avoid_a=False))
                self._fixed_starts = poses
            return list(self._fixed_starts)
        poses: list[tuple[float, float, float]] = []
        while len(poses) < self.n_watchers:
            poses.append(self._draw_pose(rng, poses, avoid_a=True))
        return poses

    def _draw_pose(self, rng, others, *, avoid_a: bool) -> tuple[float, float, float]:
        w = self.world
        A = shapely.Polygon(self._a_poly)
        gap = self.robot_radius + 0.02 * w.diameter
        for _ in range(10_000):
            x = rng.uniform(w.lo[0], w.hi[0])
            y = rng.uniform(w.lo[1], w.hi[1])
            if not shapely.contains_xy(self._robot_space, x, y):
                continue
            if avoid_a and A.distance(shapely.Point(x, y)) <= gap:
                continue
            if any(math.hypot(x - o[0], y - o[1]) < 2 * gap for o in others):
                continue
            return (float(x), float(y), float(rng.uniform(-math.pi, math.pi)))
        raise RuntimeError(f"scene {self.scene.name!r}: no free start pose for a watcher")

    def _check_action(self, action) -> list[float]:
        try:
            a = np.asarray(action, dtype=np.float64)
        except (TypeError, ValueError) as e:
            raise ValueError(f"action must be a numeric array of shape (4,), got {action!r}") from e
        if a.shape != (4,):
            raise ValueError(f"action must have shape (4,), got shape {a.shape}")
        if not np.all(np.isfinite(a)):
            raise ValueError(f"action contains NaN or infinite values: {a.tolist()}")
        return np.clip(a, -1.0, 1.0).tolist()

    def _move(self, i: int, a: list[float]) -> bool:
        x, y, psi = self.poses[i]
        c, s = math.cos(psi), math.sin(psi)
        v = self.max_speed
        d = (v * (c * a[0] - s * a[1]), v * (s * a[0] + c * a[1]))
        t = sweep((x, y), d, self._segs, self.robot_radius, self.world.skin)
        psi = (psi + self.max_turn * a[2] + math.pi) % (2 * math.pi) - math.pi
        self.poses[i] = (x + t * d[0], y + t * d[1], psi)
        return t < 1.0

    def _sense(self) -> None:
        w = self.world
        q = self.traj.at(self.t)
        self.scans = []
        self.predicted = []
        self.sees = []
        for i, pose in enumerate(self.poses):
            self.scans.append(self.sensor.read(pose, self._segs, self.np_random))
            key = (pose, float(q[0]), float(q[1]))
            memo = self._memo[i]
            if memo is not None and memo[0] == key:  # neither the watcher nor A moved
                pred, sees = memo[1], memo[2]
            else:
                pred, _, _ = cast_rays(
                    pose[0], pose[1], pose[2], self.sensor.dirs, w.seg_set, w.reach
                )
                sees = w.sees(pose, q)
                self._memo[i] = (key, pred, sees)
            self.predicted.append(pred)
            self.sees.append(sees)
            if self.evidence is not None and self.t >= self.move_steps:
                ang = self.sensor.beam_angles(pose[2])
                self.evidence.update(i, pose, ang, self.scans[i][0], pred)

    def _observe(self, i: int) -> np.ndarray:
        w = self.world
        x, y, psi = self.poses[i]
        c, s = math.cos(psi), math.sin(psi)
        inv = 1.0 / w.diameter
        lx, ly, sx, sy = self._obs_consts
        R = np.array([[c, -s], [s, c]])  # world -> robot frame: v @ R
        gh = (np.stack([self._gc, self._hc]) - (x, y)) @ R * inv
        head = np.array(
            [(x - lx) * sx - 1.0, (y - ly) * sy - 1.0, c, s, gh[0, 0], gh[0, 1], gh[1, 0], gh[1, 1]]
        )
        dist, nrm = self.scans[i][0], self.scans[i][1]
        nr = (nrm @ R).T.ravel()
        inv_reach = 1.0 / w.reach
        dec = {None: 0.0, "G": -1.0, "H": 1.0}[self.declared[i]]
        others = [
            ((np.array(self.poses[j][:2]) - (x, y)) @ R) * inv
            for j in range(self.n_watchers)
            if j != i
        ]
        parts = [
            head,
            dist * inv_reach,
            nr,
            self.predicted[i] * inv_reach,
            [self.t / self.max_steps, float(self.t >= self.move_steps), dec],
            *others,
        ]
        if self.evidence is not None:
            parts.append(self.evidence.features(i))
        o = np.concatenate(parts).astype(np.float32)
        return np.clip(o, self._obs_space.low, self._obs_space.high)

    def _info(self, i: int, final: bool = False) -> dict[str, Any]:
        info = {
            "sees": bool(self.sees[i]),
            "declared": self.declared[i],
            "collided": bool(self.collided[i]),
            "pose": self.poses[i],
        }
        if final:
            info["is_success"] = self.declared[i] == self.traj.outcome
            info["a_ends_in"] = self.traj.outcome
            info["visible_fraction"] = self.seen_steps[i] / self.max_steps
            info["team_visible_fraction"] = self.team_seen_steps / self.max_steps
        return info
